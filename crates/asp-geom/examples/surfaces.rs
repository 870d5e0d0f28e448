//! Prints the cylinders asp recognises in each part of a model, and the fits between parts:
//! a diagnostic for models whose fasteners stay locked.
//!
//!     cargo run --release -p asp-geom --example surfaces -- MODEL [--unit mm] [--up z] [PART...]

use asp_geom::io::{load, LoadOptions};
use asp_geom::math::Axis;
use asp_geom::{Units, World, WorldConfig};

fn main() {
    let mut args = std::env::args().skip(1);
    let path = args.next().expect("usage: surfaces MODEL [--unit U] [--up AXIS] [PART...]");
    let (mut options, mut only) = (LoadOptions { up: Some(Axis::Z), ..LoadOptions::default() }, Vec::new());
    while let Some(a) = args.next() {
        match a.as_str() {
            "--unit" => options.unit = Units::parse(&args.next().expect("a unit")),
            "--up" => options.up = Axis::parse(&args.next().expect("an axis")),
            name => only.push(name.to_string()),
        }
    }
    let assembly = load(std::path::Path::new(&path), &options).unwrap_or_else(|e| panic!("{e}"));
    let world = World::new(assembly, &WorldConfig::default()).unwrap_or_else(|e| panic!("{e}"));
    let mm = |m: f32| m * 1000.0;
    for p in 0..world.num_parts() {
        if !only.is_empty() && !only.iter().any(|n| n == world.name(p)) {
            continue;
        }
        let s = world.shapes().surfaces(p);
        println!("{} ({:?}): {} planes, {} cylinders", world.name(p), world.overlaps().fits().role(p), s.planes.len(), s.cylinders.len());
        for c in &s.cylinders {
            println!(
                "  {} r {:.4} mm axis {:.4?} at {:.3?} mm, sagitta {:.4} mm, {} triangles, {:?}",
                if c.convex { "shaft" } else { "hole " },
                mm(c.radius),
                c.axis.to_array(),
                (c.point * 1000.0).to_array(),
                mm(c.tolerance),
                c.triangles.len(),
                c.source
            );
        }
    }
    for ((p, q), fits) in world.overlaps().fits().all() {
        for f in fits {
            println!(
                "fit {} / {}: {} (shaft {:.4}, hole {:.4} mm), turns {:?}",
                world.name(*p),
                world.name(*q),
                f.class.name(),
                mm(f.shaft_radius),
                mm(f.hole_radius),
                f.turns.map(|t| world.name(t))
            );
        }
    }
}
