//! Criterion benches of the optimiser on random Soma cubes (thesis Algorithm 1): building all
//! distance maps, and Pareto-MCTS episodes (access, dirchange; budget 5) on 1 and 2 threads.
//! Throughput is reported in episodes per second.

use asp_geom::distmap::{DistanceMaps, MapConfig};
use asp_geom::Assembly;
use asp_search::objective::parse_objectives;
use asp_search::{Mdp, ParetoMcts};
use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use rand::SeedableRng;
use std::hint::black_box;
use std::sync::Arc;

/// A random `size³` Soma cube of 5 cm cells from the generator (thesis Algorithm 1), on its
/// fixed floor slab.
pub fn soma_cube(size: usize, seed: u64) -> Assembly {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    asp_gen::SomaCube::random(size, &mut rng).expect("soma cube").to_assembly(0.05, "soma")
}

fn bench(c: &mut Criterion) {
    for size in [5usize, 6] {
        let cube = soma_cube(size, 1);
        let name = format!("{size}x{size}x{size}_{}_parts", cube.len());
        let mut group = c.benchmark_group(format!("distance_maps/{name}"));
        group.sample_size(10);
        group.bench_function("build", |b| b.iter(|| DistanceMaps::build(black_box(&cube), &MapConfig::default()).expect("maps")));
        group.finish();

        let maps = Arc::new(DistanceMaps::build(&cube, &MapConfig::default()).expect("maps"));
        let mdp = Mdp::new(maps, parse_objectives("access,dirchange").expect("objectives")).expect("mdp");
        let episodes = if size == 5 { 400 } else { 100 };
        let mut group = c.benchmark_group(format!("pareto_mcts/{name}"));
        group.sample_size(10);
        group.throughput(Throughput::Elements(episodes as u64));
        for threads in [1, 2] {
            let search = ParetoMcts::builder().episodes(episodes).threads(threads).seed(1).build().expect("settings");
            group.bench_function(format!("{threads}_threads"), |b| b.iter(|| search.solve(black_box(&mdp)).expect("search")));
        }
        group.finish();
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
