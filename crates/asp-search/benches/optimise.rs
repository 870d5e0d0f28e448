//! Criterion benches of the optimiser on random Soma cubes (thesis Algorithm 1): building all
//! distance maps, and Pareto-MCTS episodes (access, dirchange; budget 5) on 1 and 2 threads.
//! Throughput is reported in episodes per second.

use asp_geom::distmap::{DistanceMaps, MapConfig};
use asp_geom::math::{Axis, Vec3};
use asp_geom::{Assembly, Mesh, Part, Units};
use asp_search::objective::parse_objectives;
use asp_search::{Mdp, ParetoMcts};
use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use rand::{RngExt, SeedableRng};
use std::hint::black_box;
use std::sync::Arc;

/// A random `size³` Soma cube of 5 cm cells: pieces of up to four face-connected cells grown
/// from random empty cells, each carrying its cells in `extras.asp.cells`.
pub fn soma_cube(size: i32, seed: u64) -> Assembly {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let idx = |c: [i32; 3]| ((c[2] * size + c[1]) * size + c[0]) as usize;
    let mut owner = vec![usize::MAX; (size * size * size) as usize];
    let mut pieces: Vec<Vec<[i32; 3]>> = Vec::new();
    loop {
        let empty: Vec<[i32; 3]> = (0..size * size * size)
            .map(|k| [k % size, (k / size) % size, k / (size * size)])
            .filter(|&c| owner[idx(c)] == usize::MAX)
            .collect();
        if empty.is_empty() {
            break;
        }
        let id = pieces.len();
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
        pieces.push(cells);
    }
    let parts = pieces
        .iter()
        .enumerate()
        .map(|(i, c)| Part {
            name: format!("piece_{i:02}"),
            mesh: Mesh::from_voxels(c, Vec3::splat(0.05), Vec3::ZERO),
            fixed: false,
            extras: serde_json::json!({ "asp": { "cells": c } }),
        })
        .collect();
    Assembly { parts, units: Units::metres(), up: Axis::Z, source: "soma".into(), warnings: Vec::new() }
}

fn bench(c: &mut Criterion) {
    for size in [5, 6] {
        let cube = soma_cube(size, 1);
        let name = format!("{size}x{size}x{size}_{}_parts", cube.len());
        let mut group = c.benchmark_group(format!("distance_maps/{name}"));
        group.sample_size(10);
        group.bench_function("build", |b| {
            b.iter(|| DistanceMaps::build(black_box(&cube), &MapConfig::default()).expect("maps"))
        });
        group.finish();

        let maps = Arc::new(DistanceMaps::build(&cube, &MapConfig::default()).expect("maps"));
        let mdp = Mdp::new(maps, parse_objectives("access,dirchange").expect("objectives")).expect("mdp");
        let episodes = if size == 5 { 400 } else { 100 };
        let mut group = c.benchmark_group(format!("pareto_mcts/{name}"));
        group.sample_size(10);
        group.throughput(Throughput::Elements(episodes as u64));
        for threads in [1, 2] {
            let search = ParetoMcts::builder()
                .episodes(episodes)
                .threads(threads)
                .seed(1)
                .build()
                .expect("settings");
            group.bench_function(format!("{threads}_threads"), |b| {
                b.iter(|| search.solve(black_box(&mdp)).expect("search"))
            });
        }
        group.finish();
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
