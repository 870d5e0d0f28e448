//! Storyboards without golden images: size, ink per panel, the new part's colour in its panel
//! and only there, PNG and SVG files that decode.

use crate::common::{planned, stuck_tube};
use asp_geom::fixtures;
use asp_viz::render::{storyboard, write, RenderOptions, Storyboard, BACKGROUND, TITLE_HEIGHT};
use asp_viz::scene::{part_colour, Rgb, STUCK};

/// Pixels of panel `k` below its title that are shades of `colour` (colour × 0.3..1.05).
fn shades_of(board: &Storyboard, k: usize, colour: Rgb) -> usize {
    let p = &board.panels[k];
    let c = colour.map(|v| v as f32);
    let cc: f32 = c.iter().map(|v| v * v).sum();
    let mut n = 0;
    for y in p.y + TITLE_HEIGHT..p.y + p.size - 1 {
        for x in p.x + 1..p.x + p.size - 1 {
            let px = board.pixel(x, y).map(|v| v as f32);
            let s = (px[0] * c[0] + px[1] * c[1] + px[2] * c[2]) / cc;
            if (0.3..=1.05).contains(&s) && (0..3).all(|i| (px[i] - s * c[i]).abs() <= 4.0) {
                n += 1;
            }
        }
    }
    n
}

fn ink(board: &Storyboard, k: usize) -> usize {
    let p = &board.panels[k];
    let mut n = 0;
    for y in p.y + TITLE_HEIGHT..p.y + p.size - 1 {
        for x in p.x + 1..p.x + p.size - 1 {
            if board.pixel(x, y) != BACKGROUND {
                n += 1;
            }
        }
    }
    n
}

#[test]
fn one_panel_per_step_with_the_new_part_in_colour_only_from_its_step_on() {
    let scene = planned(fixtures::tube());
    let board = storyboard(&scene, &RenderOptions { panel: 200, columns: None });
    let n = scene.steps.len();
    assert_eq!(n, 3);
    assert_eq!(board.panels.len(), n);
    assert_eq!((board.width, board.height), (2 * 200, 2 * 200), "3 panels: 2 columns, 2 rows");
    assert_eq!(board.pixels.len(), (board.width * board.height * 3) as usize);
    let body = (200 - TITLE_HEIGHT) * 200;
    for (k, step) in scene.steps.iter().enumerate() {
        assert_eq!(board.panels[k].part, Some(step.part));
        assert!(ink(&board, k) > body as usize / 20, "panel {k} is nearly empty: {} pixels", ink(&board, k));
        let colour = part_colour(step.part);
        assert!(shades_of(&board, k, colour) > 100, "panel {k}: the new part's colour {colour:?} is missing");
        for earlier in 0..k {
            assert!(shades_of(&board, earlier, colour) < 5, "panel {earlier} shows step {k}'s part in colour");
        }
        assert!(board.panels[k].arrow.len() >= 2, "panel {k} has no arrow");
    }
}

#[test]
fn path_motions_are_drawn_as_curves() {
    let scene = planned(fixtures::l_path());
    assert!(matches!(scene.steps[0].motion, Some(asp_viz::Insertion::Path { .. })), "the L needs a path");
    let board = storyboard(&scene, &RenderOptions { panel: 240, columns: None });
    let arrow = &board.panels[0].arrow;
    assert!(arrow.len() > 2, "a path arrow has more than two points");
    // the L: the arrow is not a straight line (some point far from the chord)
    let (a, b) = (arrow[0], *arrow.last().unwrap());
    let chord = ((b.0 - a.0).powi(2) + (b.1 - a.1).powi(2)).sqrt();
    let off = arrow.iter().map(|p| ((b.0 - a.0) * (a.1 - p.1) - (a.0 - p.0) * (b.1 - a.1)).abs() / chord).fold(0.0, f32::max);
    assert!(off > 5.0, "the path's arrow is straight ({off} px off the chord)");
}

#[test]
fn unfinished_plans_open_with_the_stuck_parts_in_red() {
    let scene = stuck_tube();
    let board = storyboard(&scene, &RenderOptions { panel: 200, columns: Some(2) });
    assert_eq!(board.panels.len(), 2, "the never-removed parts, then the handle");
    assert_eq!(board.panels[0].part, None);
    assert!(shades_of(&board, 0, STUCK) > 100, "the stuck stick is not red");
    assert!(shades_of(&board, 1, part_colour(scene.steps[0].part)) > 100);
}

#[test]
fn png_and_svg_files_decode() {
    let scene = planned(fixtures::tube());
    let dir = tempfile::tempdir().unwrap();
    let png_path = dir.path().join("steps.png");
    let board = write(&png_path, &scene, &RenderOptions { panel: 160, columns: Some(3) }).unwrap();
    let decoder = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(&png_path).unwrap()));
    let reader = decoder.read_info().unwrap();
    assert_eq!((reader.info().width, reader.info().height), (3 * 160, 160));
    assert_eq!((board.width, board.height), (480, 160));

    let svg_path = dir.path().join("steps.svg");
    write(&svg_path, &scene, &RenderOptions { panel: 160, columns: Some(3) }).unwrap();
    let text = std::fs::read_to_string(&svg_path).unwrap();
    let doc = roxmltree::Document::parse(&text).unwrap();
    let panels = doc.descendants().filter(|n| n.attribute("class") == Some("panel")).count();
    assert_eq!(panels, 3);
    assert_eq!(doc.descendants().filter(|n| n.has_tag_name("polyline")).count(), 3, "one arrow per step");
    assert!(doc.descendants().any(|n| n.has_tag_name("image")));
}
