//! `asp render`: a storyboard of the plan, one panel per step — the parts placed so far in grey,
//! the base in blue-grey, the new part in colour, a dark arrow for its motion. Rendered on the
//! CPU (a z-buffered triangle rasteriser with flat shading from a fixed light, an orthographic
//! isometric-ish camera fitted to the model and every motion), no display needed. PNG, or SVG
//! (the shaded panels as an embedded PNG under vector titles and arrows).

use crate::error::{Result, VizError};
use crate::scene::{part_colour, Rgb, Scene, BASE, GREY, STUCK};
use asp_geom::math::{Axis, Pose, Vec3};
use base64::Engine;
use plotters::prelude::*;
use rayon::prelude::*;
use std::path::Path;

/// The storyboard's background colour.
pub const BACKGROUND: Rgb = [255, 255, 255];
/// The colour of motion arrows.
pub const ARROW: Rgb = [34, 34, 34];
/// The height of a panel's title strip, pixels.
pub const TITLE_HEIGHT: u32 = 26;
const FONT: &[u8] = include_bytes!("../assets/fonts/DejaVuSans.ttf");
/// The family the vendored font is registered as (SVG text names it too).
const FONT_NAME: &str = "sans-serif";

/// How to lay out a storyboard.
#[derive(Clone, Debug)]
pub struct RenderOptions {
    /// Width and height of one panel in pixels (title strip included).
    pub panel: u32,
    /// Panels per row (default: about the square root of the panel count, at most 6).
    pub columns: Option<u32>,
}

impl Default for RenderOptions {
    fn default() -> Self {
        RenderOptions { panel: 320, columns: None }
    }
}

/// One panel of a storyboard.
#[derive(Clone, Debug, PartialEq)]
pub struct Panel {
    /// Left edge, pixels.
    pub x: u32,
    /// Top edge, pixels.
    pub y: u32,
    /// Width and height, pixels.
    pub size: u32,
    /// The part this panel inserts (`None` for the opening panel of an unfinished plan, which
    /// shows the parts never removed).
    pub part: Option<usize>,
    /// The colour the new part is drawn in (before shading).
    pub colour: Rgb,
    /// The title, e.g. `3. Shelf (linear)`.
    pub title: String,
    /// The motion's arrow: points in sheet pixels from the start outside to the part's place.
    pub arrow: Vec<(f32, f32)>,
}

/// A rendered storyboard: an RGB image and where its panels are.
#[derive(Clone, Debug)]
pub struct Storyboard {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Row-major RGB bytes, titles and arrows drawn in.
    pub pixels: Vec<u8>,
    /// The shaded panels alone (no titles, no arrows), for the SVG output.
    shaded: Vec<u8>,
    /// The panels in order.
    pub panels: Vec<Panel>,
}

impl Storyboard {
    /// The colour at pixel `(x, y)`.
    pub fn pixel(&self, x: u32, y: u32) -> Rgb {
        let i = ((y * self.width + x) * 3) as usize;
        [self.pixels[i], self.pixels[i + 1], self.pixels[i + 2]]
    }
}

/// What one panel shows.
struct PanelSpec {
    /// Parts drawn with their colours and poses.
    parts: Vec<(usize, Rgb, Pose)>,
    part: Option<usize>,
    colour: Rgb,
    title: String,
    /// The motion's curve in world coordinates (metres).
    arrow: Vec<Vec3>,
}

/// Renders the storyboard of `scene`.
pub fn storyboard(scene: &Scene, options: &RenderOptions) -> Storyboard {
    let specs = panel_specs(scene);
    let n = specs.len().max(1) as u32;
    let columns = options.columns.unwrap_or_else(|| (n as f32).sqrt().ceil() as u32).clamp(1, 6).min(n);
    let rows = n.div_ceil(columns);
    let size = options.panel.max(64);
    let (width, height) = (columns * size, rows * size);
    let camera = Camera::fitted(scene, size);
    let rendered: Vec<Vec<u8>> = specs.par_iter().map(|spec| camera.render(scene, spec)).collect();
    let mut pixels = vec![255u8; (width * height * 3) as usize];
    let mut panels = Vec::with_capacity(specs.len());
    for (k, (spec, image)) in specs.iter().zip(&rendered).enumerate() {
        let (x, y) = ((k as u32 % columns) * size, (k as u32 / columns) * size);
        for row in 0..size {
            let src = (row * size * 3) as usize;
            let dst = (((y + row) * width + x) * 3) as usize;
            pixels[dst..dst + (size * 3) as usize].copy_from_slice(&image[src..src + (size * 3) as usize]);
        }
        let mut arrow: Vec<(f32, f32)> = spec
            .arrow
            .iter()
            .map(|p| {
                let (sx, sy, _) = camera.project(*p);
                (sx + x as f32, sy + y as f32)
            })
            .collect();
        if let [start, end] = spec.arrow[..] {
            lengthen(&mut arrow, &camera, start, end, size as f32 * MIN_ARROW);
        }
        panels.push(Panel { x, y, size, part: spec.part, colour: spec.colour, title: spec.title.clone(), arrow });
    }
    let shaded = pixels.clone();
    draw_overlay(&mut pixels, width, height, &panels);
    Storyboard { width, height, pixels, shaded, panels }
}

/// The shortest straight arrow, as a fraction of the panel: short motions (a part that only
/// has to clear a touching neighbour) still show their direction.
pub const MIN_ARROW: f32 = 0.16;

/// Makes a straight arrow at least `min_px` long on screen, keeping its end and direction.
fn lengthen(arrow: &mut [(f32, f32)], camera: &Camera, start: Vec3, end: Vec3, min_px: f32) {
    let d = (end - start).normalize_or_zero();
    let (ex, ey, _) = camera.project(end);
    let (bx, by, _) = camera.project(end - d);
    let (dx, dy) = (ex - bx, ey - by);
    let per_metre = (dx * dx + dy * dy).sqrt();
    if per_metre < 1e-6 || arrow.len() != 2 {
        return; // the motion runs along the line of sight
    }
    let len = (end - start).length() * per_metre;
    if len < min_px {
        arrow[0] = (arrow[1].0 - dx / per_metre * min_px, arrow[1].1 - dy / per_metre * min_px);
    }
}

/// Writes the storyboard of `scene` to `path`: SVG when the extension is `.svg`, else PNG.
pub fn write(path: &Path, scene: &Scene, options: &RenderOptions) -> Result<Storyboard> {
    let board = storyboard(scene, options);
    let is_svg = path.extension().and_then(|e| e.to_str()).is_some_and(|e| e.eq_ignore_ascii_case("svg"));
    let bytes = if is_svg { svg(&board, path)?.into_bytes() } else { png_bytes(&board.pixels, board.width, board.height, path)? };
    asp_geom::io::write_atomic(path, &bytes).map_err(|e| VizError::io(path, e))?;
    Ok(board)
}

/// The panels of a plan: for an unfinished plan first the parts never removed (stuck ones in
/// red), then one per step (the state once the step is in, before its grid moves), and when
/// the last step has grid moves, one more of the model in place.
fn panel_specs(scene: &Scene) -> Vec<PanelSpec> {
    let colour_of_placed = |i: usize| {
        if scene.stuck.contains(&i) {
            STUCK
        } else if scene.is_base(i) {
            BASE
        } else {
            GREY
        }
    };
    let mut specs = Vec::new();
    let found = scene.report.status.has_sequence();
    if !found {
        specs.push(PanelSpec {
            parts: scene.initial.iter().map(|&i| (i, colour_of_placed(i), Pose::from_translation(scene.offset(i, 0, 0)))).collect(),
            part: None,
            colour: STUCK,
            title: format!("{}: {} parts left", scene.report.status.as_str().replace('_', " "), scene.initial.len()),
            arrow: Vec::new(),
        });
    }
    let mut placed: Vec<usize> = scene.initial.clone();
    for (k, step) in scene.steps.iter().enumerate() {
        let colour = part_colour(step.part);
        // the state once the step is in, before its moves (grid plans) slide parts on
        let at = |i: usize| scene.pose_during(k, 1.0, i);
        let mut parts: Vec<(usize, Rgb, Pose)> = placed.iter().map(|&i| (i, colour_of_placed(i), at(i))).collect();
        // a subassembly's parts go in together, in the step's colour
        parts.extend(step.parts.iter().map(|&i| (i, colour, at(i))));
        let (kind, arrow) = match &step.motion {
            Some(m) => {
                let centre = scene.assembly.parts[step.part].mesh.aabb().map(|b| (b.mins + b.maxs) / 2.0).unwrap_or(Vec3::ZERO);
                let kind = match m {
                    crate::Insertion::Linear { .. } => "linear",
                    crate::Insertion::Path { .. } => "path",
                };
                let offset = scene.offset(step.part, k, 0);
                (kind, m.trace(centre, 48).into_iter().map(|p| p + offset).collect())
            }
            None => ("motion not recorded", Vec::new()),
        };
        let then = match step.moves.len() {
            0 => String::new(),
            1 => ", then 1 move".to_string(),
            n => format!(", then {n} moves"),
        };
        specs.push(PanelSpec { parts, part: Some(step.part), colour, title: format!("{}. {} ({kind}{then})", k + 1, step.name), arrow });
        placed.extend(&step.parts);
    }
    // a grid plan whose last step slides parts on: one more panel, everything in place
    if let Some(last) = scene.steps.last().filter(|s| !s.moves.is_empty()) {
        let parts = placed.iter().map(|&i| (i, colour_of_placed(i), Pose::IDENTITY)).collect();
        let n = last.moves.len();
        let title = format!("{}. {n} move{} into place", scene.steps.len() + 1, if n == 1 { "" } else { "s" });
        specs.push(PanelSpec { parts, part: None, colour: GREY, title, arrow: Vec::new() });
    }
    specs
}

/// An orthographic camera looking at the model from the side and a little above.
struct Camera {
    right: Vec3,
    up: Vec3,
    forward: Vec3,
    light: Vec3,
    /// Screen offset and scale: pixel = offset + scale * (coordinate - min).
    min: (f32, f32),
    scale: f32,
    offset: (f32, f32),
    size: u32,
}

impl Camera {
    fn fitted(scene: &Scene, size: u32) -> Camera {
        let up = Axis::parse(&scene.report.up).map(|a| a.vector()).unwrap_or(Vec3::Z);
        let side = if up.x.abs() > 0.9 { Vec3::Y } else { Vec3::X };
        let other = up.cross(side);
        let view = (side - other * 0.9 + up * 0.75).normalize();
        let forward = -view;
        let right = forward.cross(up).normalize();
        let screen_up = right.cross(forward);
        let light = (view * 0.55 + screen_up * 0.65 - right * 0.35).normalize();
        let (lo, hi) = scene.bounds();
        let (mut x0, mut x1, mut y0, mut y1) = (f32::INFINITY, f32::NEG_INFINITY, f32::INFINITY, f32::NEG_INFINITY);
        for c in crate::scene::corners(lo, hi) {
            let (x, y) = (c.dot(right), c.dot(screen_up));
            x0 = x0.min(x);
            x1 = x1.max(x);
            y0 = y0.min(y);
            y1 = y1.max(y);
        }
        let margin = size as f32 * 0.06;
        let avail_w = size as f32 - 2.0 * margin;
        let avail_h = size as f32 - TITLE_HEIGHT as f32 - 2.0 * margin;
        let (w, h) = ((x1 - x0).max(1e-9), (y1 - y0).max(1e-9));
        let scale = (avail_w / w).min(avail_h / h);
        let offset = (margin + (avail_w - w * scale) / 2.0, TITLE_HEIGHT as f32 + margin + (avail_h - h * scale) / 2.0);
        Camera { right, up: screen_up, forward, light, min: (x0, y1), scale, offset, size }
    }

    /// Panel pixel coordinates and depth of a world point.
    fn project(&self, p: Vec3) -> (f32, f32, f32) {
        let x = self.offset.0 + (p.dot(self.right) - self.min.0) * self.scale;
        let y = self.offset.1 + (self.min.1 - p.dot(self.up)) * self.scale;
        (x, y, p.dot(self.forward))
    }

    /// The shaded panel (no title, no arrow) as RGB bytes.
    fn render(&self, scene: &Scene, spec: &PanelSpec) -> Vec<u8> {
        let size = self.size as usize;
        let mut colour = vec![255u8; size * size * 3];
        let mut depth = vec![f32::INFINITY; size * size];
        let top = TITLE_HEIGHT as f32;
        for &(i, rgb, pose) in &spec.parts {
            let mesh = &scene.assembly.parts[i].mesh;
            let screen: Vec<(f32, f32, f32)> = mesh.vertices.iter().map(|v| self.project(pose.transform_point(*v))).collect();
            for t in &mesh.triangles {
                let [a, b, c] = [t[0] as usize, t[1] as usize, t[2] as usize];
                if a >= screen.len() || b >= screen.len() || c >= screen.len() {
                    continue;
                }
                let world = |k: usize| pose.transform_point(mesh.vertices[k]);
                let mut normal = (world(b) - world(a)).cross(world(c) - world(a));
                if normal.length_squared() == 0.0 || !normal.is_finite() {
                    continue;
                }
                normal = normal.normalize();
                if normal.dot(self.forward) > 0.0 {
                    normal = -normal; // face the camera: meshes may be open or misoriented
                }
                let shade = 0.38 + 0.62 * normal.dot(self.light).max(0.0);
                let px = [
                    (rgb[0] as f32 * shade).round().min(255.0) as u8,
                    (rgb[1] as f32 * shade).round().min(255.0) as u8,
                    (rgb[2] as f32 * shade).round().min(255.0) as u8,
                ];
                fill_triangle(screen[a], screen[b], screen[c], size, top, &mut depth, &mut colour, px);
            }
        }
        // a thin frame around the panel
        for k in 0..size {
            for (x, y) in [(k, 0), (k, size - 1), (0, k), (size - 1, k)] {
                let i = (y * size + x) * 3;
                colour[i..i + 3].copy_from_slice(&[214, 218, 224]);
            }
        }
        colour
    }
}

/// Rasterises one triangle with a depth test (nearer wins); pixels above `top` are the title's.
#[allow(clippy::too_many_arguments)]
fn fill_triangle(
    a: (f32, f32, f32),
    b: (f32, f32, f32),
    c: (f32, f32, f32),
    size: usize,
    top: f32,
    depth: &mut [f32],
    colour: &mut [u8],
    px: [u8; 3],
) {
    let area = (b.0 - a.0) * (c.1 - a.1) - (b.1 - a.1) * (c.0 - a.0);
    if area.abs() < 1e-12 || !area.is_finite() {
        return;
    }
    let x0 = a.0.min(b.0).min(c.0).floor().max(0.0) as usize;
    let x1 = (a.0.max(b.0).max(c.0).ceil() as isize).min(size as isize - 1);
    let y0 = a.1.min(b.1).min(c.1).floor().max(top) as usize;
    let y1 = (a.1.max(b.1).max(c.1).ceil() as isize).min(size as isize - 1);
    if x1 < 0 || y1 < 0 {
        return;
    }
    for y in y0..=y1 as usize {
        let py = y as f32 + 0.5;
        for x in x0..=x1 as usize {
            let pxf = x as f32 + 0.5;
            let w0 = ((b.0 - pxf) * (c.1 - py) - (b.1 - py) * (c.0 - pxf)) / area;
            let w1 = ((c.0 - pxf) * (a.1 - py) - (c.1 - py) * (a.0 - pxf)) / area;
            let w2 = 1.0 - w0 - w1;
            if w0 < 0.0 || w1 < 0.0 || w2 < 0.0 {
                continue;
            }
            let z = w0 * a.2 + w1 * b.2 + w2 * c.2;
            let i = y * size + x;
            if z < depth[i] {
                depth[i] = z;
                colour[i * 3..i * 3 + 3].copy_from_slice(&px);
            }
        }
    }
}

/// Registers the vendored DejaVu Sans with plotters as `sans-serif` (once).
pub(crate) fn register_font() {
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| {
        // the font is compiled in; a failure here would be a broken build, and text is then skipped
        let _ = plotters::style::register_font(FONT_NAME, FontStyle::Normal, FONT);
    });
}

/// Titles and arrows drawn onto the sheet.
fn draw_overlay(pixels: &mut [u8], width: u32, height: u32, panels: &[Panel]) {
    register_font();
    let root = BitMapBackend::with_buffer(pixels, (width, height)).into_drawing_area();
    let ink = RGBColor(ARROW[0], ARROW[1], ARROW[2]);
    let font = (FONT_NAME, 15).into_font().color(&RGBColor(29, 35, 48));
    for p in panels {
        let swatch = RGBColor(p.colour[0], p.colour[1], p.colour[2]);
        let (x, y) = (p.x as i32, p.y as i32);
        let _ = root.draw(&Rectangle::new([(x + 8, y + 8), (x + 20, y + 20)], swatch.filled()));
        let title = fit_title(&p.title, p.size as usize);
        let _ = root.draw(&Text::new(title, (x + 26, y + 6), font.clone()));
        if p.arrow.len() >= 2 {
            let points: Vec<(i32, i32)> = p.arrow.iter().map(|&(px, py)| (px.round() as i32, py.round() as i32)).collect();
            let _ = root.draw(&PathElement::new(points.clone(), ink.stroke_width(2)));
            if let Some(head) = arrow_head(&p.arrow, p.size as f32 * 0.045) {
                let _ = root
                    .draw(&Polygon::new(head.iter().map(|&(a, b)| (a.round() as i32, b.round() as i32)).collect::<Vec<_>>(), ink.filled()));
            }
            let (sx, sy) = points[0];
            let _ = root.draw(&Circle::new((sx, sy), 3, ink.filled()));
        }
    }
    let _ = root.present();
}

/// A title cut to what fits in a panel (about 8 px per character at 15 px).
fn fit_title(title: &str, width: usize) -> String {
    let max = (width.saturating_sub(34)) / 8;
    if title.chars().count() <= max {
        title.to_string()
    } else {
        let cut: String = title.chars().take(max.saturating_sub(1)).collect();
        format!("{cut}…")
    }
}

/// The triangle of an arrow head at the end of `curve`, `len` pixels long.
fn arrow_head(curve: &[(f32, f32)], len: f32) -> Option<[(f32, f32); 3]> {
    let &(ex, ey) = curve.last()?;
    // the direction from the last point at least `len` pixels back
    let (bx, by) = curve.iter().rev().find(|&&(x, y)| ((x - ex).powi(2) + (y - ey).powi(2)).sqrt() >= len * 0.5).copied()?;
    let (dx, dy) = (ex - bx, ey - by);
    let l = (dx * dx + dy * dy).sqrt();
    if l < 1e-6 {
        return None;
    }
    let (ux, uy) = (dx / l, dy / l);
    let (nx, ny) = (-uy, ux);
    Some([
        (ex, ey),
        (ex - ux * len + nx * len * 0.45, ey - uy * len + ny * len * 0.45),
        (ex - ux * len - nx * len * 0.45, ey - uy * len - ny * len * 0.45),
    ])
}

/// `pixels` (RGB) encoded as PNG.
pub(crate) fn png_bytes(pixels: &[u8], width: u32, height: u32, path: &Path) -> Result<Vec<u8>> {
    let mut out = Vec::new();
    {
        let mut encoder = png::Encoder::new(&mut out, width, height);
        encoder.set_color(png::ColorType::Rgb);
        encoder.set_depth(png::BitDepth::Eight);
        let mut writer = encoder.write_header().map_err(|e| VizError::output(path, format!("png: {e}")))?;
        writer.write_image_data(pixels).map_err(|e| VizError::output(path, format!("png: {e}")))?;
    }
    Ok(out)
}

/// The SVG storyboard: the shaded panels as one embedded PNG, titles, swatches and arrows as
/// vector elements (one `<g class="panel">` per panel).
fn svg(board: &Storyboard, path: &Path) -> Result<String> {
    use std::fmt::Write;
    let png = png_bytes(&board.shaded, board.width, board.height, path)?;
    let data = base64::engine::general_purpose::STANDARD.encode(png);
    let (w, h) = (board.width, board.height);
    let mut s = String::new();
    let _ = writeln!(s, r#"<?xml version="1.0" encoding="UTF-8"?>"#);
    let _ = writeln!(s, r#"<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" viewBox="0 0 {w} {h}">"#);
    let _ = writeln!(s, r#"<image x="0" y="0" width="{w}" height="{h}" href="data:image/png;base64,{data}"/>"#);
    let ink = format!("rgb({},{},{})", ARROW[0], ARROW[1], ARROW[2]);
    for p in &board.panels {
        let part = p.part.map(|i| i.to_string()).unwrap_or_default();
        let _ = writeln!(s, r#"<g class="panel" data-part="{part}">"#);
        let [r, g, b] = p.colour;
        let _ = writeln!(s, r#"<rect x="{}" y="{}" width="12" height="12" fill="rgb({r},{g},{b})"/>"#, p.x + 8, p.y + 8);
        let _ = writeln!(
            s,
            r#"<text x="{}" y="{}" font-family="DejaVu Sans, sans-serif" font-size="15" fill="rgb(29,35,48)">{}</text>"#,
            p.x + 26,
            p.y + 19,
            xml_escape(&p.title)
        );
        if p.arrow.len() >= 2 {
            let points: Vec<String> = p.arrow.iter().map(|(x, y)| format!("{x:.1},{y:.1}")).collect();
            let _ = writeln!(s, r#"<polyline points="{}" fill="none" stroke="{ink}" stroke-width="2"/>"#, points.join(" "));
            if let Some(head) = arrow_head(&p.arrow, p.size as f32 * 0.045) {
                let pts: Vec<String> = head.iter().map(|(x, y)| format!("{x:.1},{y:.1}")).collect();
                let _ = writeln!(s, r#"<polygon points="{}" fill="{ink}"/>"#, pts.join(" "));
            }
            let (x, y) = p.arrow[0];
            let _ = writeln!(s, r#"<circle cx="{x:.1}" cy="{y:.1}" r="3" fill="{ink}"/>"#);
        }
        let _ = writeln!(s, "</g>");
    }
    let _ = writeln!(s, "</svg>");
    Ok(s)
}

fn xml_escape(s: &str) -> String {
    s.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;").replace('"', "&quot;")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn triangles_fill_with_the_nearer_one_on_top() {
        let size = 16;
        let mut depth = vec![f32::INFINITY; size * size];
        let mut colour = vec![255u8; size * size * 3];
        let (a, b, c) = ((0.0, 0.0, 2.0), (16.0, 0.0, 2.0), (0.0, 16.0, 2.0));
        fill_triangle(a, b, c, size, 0.0, &mut depth, &mut colour, [10, 10, 10]);
        fill_triangle((0.0, 0.0, 1.0), (8.0, 0.0, 1.0), (0.0, 8.0, 1.0), size, 0.0, &mut depth, &mut colour, [200, 0, 0]);
        fill_triangle(a, b, c, size, 0.0, &mut depth, &mut colour, [0, 200, 0]); // farther than red: hidden
        let at = |x: usize, y: usize| &colour[(y * size + x) * 3..(y * size + x) * 3 + 3];
        assert_eq!(at(1, 1), [200, 0, 0]);
        assert_eq!(at(10, 2), [10, 10, 10]);
        assert_eq!(at(15, 15), [255, 255, 255]);
    }

    #[test]
    fn arrow_heads_point_along_the_curve() {
        let head = arrow_head(&[(0.0, 0.0), (100.0, 0.0)], 10.0).unwrap();
        assert_eq!(head[0], (100.0, 0.0));
        assert!(head[1].0 < 100.0 && head[2].0 < 100.0);
    }
}
