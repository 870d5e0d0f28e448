//! Temporary measurement harness.
use asp_geom::distmap::{DistanceMaps, MapConfig};
use asp_geom::math::{Axis, Vec3};
use asp_geom::{Assembly, Mesh, Part, Units};
use asp_search::objective::parse_objectives;
use asp_search::{Mdp, ParetoMcts};
use rand::{RngExt, SeedableRng};
use std::sync::Arc;
use std::time::Instant;

fn random_cube(size: i32, seed: u64) -> Assembly {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let idx = |c: [i32; 3]| ((c[2] * size + c[1]) * size + c[0]) as usize;
    let mut owner = vec![usize::MAX; (size * size * size) as usize];
    let mut parts: Vec<Vec<[i32; 3]>> = Vec::new();
    loop {
        let empty: Vec<[i32; 3]> = (0..size * size * size)
            .map(|k| [k % size, (k / size) % size, k / (size * size)])
            .filter(|&c| owner[idx(c)] == usize::MAX)
            .collect();
        if empty.is_empty() {
            break;
        }
        let id = parts.len();
        let mut cells = vec![empty[rng.random_range(0..empty.len())]];
        owner[idx(cells[0])] = id;
        for _ in 0..3 {
            let mut frontier = Vec::new();
            for c in &cells {
                for (axis, step) in [(0, 1), (0, -1), (1, 1), (1, -1), (2, 1), (2, -1)] {
                    let mut n = *c;
                    n[axis] += step;
                    if n.iter().all(|&v| (0..size).contains(&v)) && owner[idx(n)] == usize::MAX {
                        frontier.push(n);
                    }
                }
            }
            if frontier.is_empty() {
                break;
            }
            let n = frontier[rng.random_range(0..frontier.len())];
            owner[idx(n)] = id;
            cells.push(n);
        }
        parts.push(cells);
    }
    let parts = parts
        .iter()
        .enumerate()
        .map(|(i, c)| Part {
            name: format!("p{i}"),
            mesh: Mesh::from_voxels(c, Vec3::splat(0.05), Vec3::ZERO),
            fixed: false,
            extras: serde_json::json!({"asp": {"cells": c}}),
        })
        .collect();
    Assembly { parts, units: Units::metres(), up: Axis::Z, source: "cube".into(), warnings: vec![] }
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let size: i32 = args.get(1).map_or(5, |s| s.parse().unwrap());
    let episodes: usize = args.get(2).map_or(100, |s| s.parse().unwrap());
    let threads: usize = args.get(3).map_or(1, |s| s.parse().unwrap());
    let cube = random_cube(size, 1);
    let t = Instant::now();
    let maps = Arc::new(DistanceMaps::build(&cube, &MapConfig::default()).unwrap());
    println!("{} parts, maps {:.3} s", cube.len(), t.elapsed().as_secs_f64());
    let mdp = Mdp::new(maps, parse_objectives("access,dirchange").unwrap()).unwrap();
    let out = ParetoMcts::builder().episodes(episodes).threads(threads).seed(1).build().unwrap().solve(&mdp).unwrap();
    let s = out.stats;
    println!(
        "episodes {} in {:.3} s: {:.1} eps/s, {:.0} iterations/s, {:.0} rollout steps/s, nodes {}, front {}",
        s.episodes,
        s.seconds,
        s.episodes as f64 / s.seconds,
        s.iterations as f64 / s.seconds,
        s.rollout_steps as f64 / s.seconds,
        s.tree_nodes,
        out.solutions.len()
    );
}
