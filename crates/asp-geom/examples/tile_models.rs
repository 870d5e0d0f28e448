//! Builds a large model from real ones for scale measurements: copies of
//! several models laid side by side on a grid, written as one GLB.
//!
//! ```text
//! cargo run -p asp-geom --example tile_models -- OUT.glb COUNT:MODEL[:UNIT] ...
//! cargo run -p asp-geom --example tile_models -- /tmp/pumps123.glb 3:tests/data/pump:mm 3:tests/data/pump-extension:mm
//! ```
//!
//! Every copy keeps its parts' names with a `copyK/` prefix; the copies stand 20 % of the
//! largest model's size apart, so they never touch and each keeps its own answer. Up is +Z.

use asp_geom::io::{load, write_glb, LoadOptions};
use asp_geom::math::{Axis, Pose, Vec3};
use asp_geom::{Assembly, Part, Units};
use std::path::{Path, PathBuf};

fn main() {
    if let Err(e) = run() {
        eprintln!("error: {e}");
        std::process::exit(2);
    }
}

fn run() -> Result<(), String> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let (out, specs) = args.split_first().ok_or("usage: tile_models OUT.glb COUNT:MODEL[:UNIT] ...")?;
    let mut copies: Vec<Assembly> = Vec::new();
    for spec in specs {
        let mut fields = spec.splitn(3, ':');
        let count: usize = fields.next().and_then(|c| c.parse().ok()).ok_or(format!("{spec}: no count"))?;
        let model = PathBuf::from(fields.next().ok_or(format!("{spec}: no model"))?);
        let unit = fields.next().map(|u| Units::parse(u).ok_or(format!("{spec}: unknown unit {u}"))).transpose()?;
        let options = LoadOptions { unit, up: Some(Axis::Z), ..LoadOptions::default() };
        let assembly = load(&model, &options).map_err(|e| e.to_string())?;
        copies.extend(std::iter::repeat_n(assembly, count));
    }
    let tiled = tile(&copies).ok_or("no models")?;
    let triangles: usize = tiled.parts.iter().map(|p| p.mesh.triangles.len()).sum();
    write_glb(&tiled, Path::new(out)).map_err(|e| e.to_string())?;
    println!("{out}: {} parts, {triangles} triangles", tiled.len());
    Ok(())
}

/// The copies on a square grid in the xy plane, bottoms at z = 0, in metres.
fn tile(copies: &[Assembly]) -> Option<Assembly> {
    let size = copies.iter().filter_map(|a| a.aabb()).map(|b| b.maxs - b.mins).reduce(Vec3::max)?;
    let pitch = size * 1.2;
    let columns = (copies.len() as f64).sqrt().ceil() as usize;
    let mut parts = Vec::new();
    for (k, copy) in copies.iter().enumerate() {
        let b = copy.aabb()?;
        let target = Vec3::new((k % columns) as f32 * pitch.x, (k / columns) as f32 * pitch.y, 0.0);
        let shift = Pose::from_translation(target - b.mins);
        for part in &copy.parts {
            let mesh = part.mesh.transformed(&shift);
            parts.push(Part::new(format!("copy{k}/{}", part.name), mesh, part.fixed, part.extras.clone()));
        }
    }
    Some(Assembly { parts, units: Units::metres(), up: Axis::Z, source: PathBuf::from("tiled"), warnings: Vec::new() })
}
