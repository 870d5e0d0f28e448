//! Times the geometry half of planning for many models in one process: load,
//! world build, and the first (cold) removal test of every part in the full assembly.
//!
//! ```text
//! cargo run -p asp-geom --profile test --example world_time -- [--unit mm] MODEL...
//! ```
//!
//! Prints one line per model and the totals; up is +Z.

use asp_geom::io::{load, LoadOptions};
use asp_geom::math::Axis;
use asp_geom::{PartSet, Units, World, WorldConfig};
use std::path::PathBuf;
use std::time::Instant;

fn main() {
    let mut args: Vec<String> = std::env::args().skip(1).collect();
    let mut unit = None;
    if args.first().map(String::as_str) == Some("--unit") && args.len() > 1 {
        unit = Units::parse(&args[1]);
        args.drain(..2);
    }
    let options = LoadOptions { unit, up: Some(Axis::Z), ..LoadOptions::default() };
    let (mut load_s, mut world_s, mut tests_s) = (0.0, 0.0, 0.0);
    let many = args.len() > 3;
    for model in args.iter().map(PathBuf::from) {
        let t = Instant::now();
        let assembly = match load(&model, &options) {
            Ok(a) => a,
            Err(e) => {
                eprintln!("error: {e}");
                continue;
            }
        };
        let (parts, triangles) = (assembly.len(), assembly.parts.iter().map(|p| p.mesh.triangles.len()).sum::<usize>());
        let l = t.elapsed().as_secs_f64();
        let t = Instant::now();
        let world = match World::new(assembly, &WorldConfig::default()) {
            Ok(w) => w,
            Err(e) => {
                eprintln!("error: {e}");
                continue;
            }
        };
        let w = t.elapsed().as_secs_f64();
        let t = Instant::now();
        let full = PartSet::full(parts);
        let free = (0..parts).filter(|&p| world.removal().linear(p, &full).is_ok()).count();
        let r = t.elapsed().as_secs_f64();
        (load_s, world_s, tests_s) = (load_s + l, world_s + w, tests_s + r);
        if !many {
            println!(
                "{}: {parts} parts, {triangles} triangles: load {l:.4} s, world {w:.4} s, cold tests of all parts {r:.4} s ({:.2} ms per part, {free} free)",
                model.display(),
                1e3 * r / parts.max(1) as f64
            );
        }
    }
    let n = args.len().max(1) as f64;
    println!(
        "{} models: load {load_s:.3} s, world {world_s:.3} s, cold tests {tests_s:.3} s; per model {:.2} / {:.2} / {:.2} ms",
        args.len(),
        1e3 * load_s / n,
        1e3 * world_s / n,
        1e3 * tests_s / n
    );
}
