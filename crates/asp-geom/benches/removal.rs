//! Criterion benches of the removal test (one part, all straight directions) and the stability
//! check, on the shipped real assemblies and a fixture.
//!
//! `cold`: the first test of a part, which computes and caches its blocking row (every
//! direction × every neighbour: the real geometric work). `warm`: a later test of the same part
//! in another state (bitset work on the cached row).

use asp_geom::io::{load, LoadOptions};
use asp_geom::math::{Axis, Pose};
use asp_geom::physics::{PhysicsConfig, PhysicsStability};
use asp_geom::{fixtures, Assembly, PartSet, Units, World, WorldConfig};
use criterion::{criterion_group, criterion_main, BatchSize, Criterion};
use std::hint::black_box;
use std::path::Path;

fn models() -> Vec<(String, Assembly)> {
    let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tests/data");
    let z = LoadOptions { up: Some(Axis::Z), ..LoadOptions::default() };
    let mut out = vec![("tube".to_string(), fixtures::tube()), ("ball_bearing".to_string(), fixtures::ball_bearing(64, 9, true))];
    out.push(("beam".into(), load(&data.join("beam/beam.glb"), &z).expect("beam")));
    for name in ["bookcase_billy_0191", "chair_bertil_0148", "table_lack_0825", "desk_hannes_0529"] {
        out.push((name.into(), load(&data.join(format!("ikea/{name}.glb")), &z).expect(name)));
    }
    let mm = LoadOptions { unit: Units::parse("mm"), up: Some(Axis::Z), ..LoadOptions::default() };
    out.push(("pump".into(), load(&data.join("pump"), &mm).expect("pump")));
    out
}

fn bench(c: &mut Criterion) {
    for (name, assembly) in models() {
        c.bench_function(&format!("world_build/{name}"), |b| {
            b.iter_batched(
                || assembly.clone(),
                |a| black_box(World::new(a, &WorldConfig::default()).expect("world").num_parts()),
                BatchSize::PerIteration,
            )
        });
        let world = World::new(assembly.clone(), &WorldConfig::default()).expect("world");
        c.bench_function(&format!("bearings/{name}"), |b| {
            b.iter(|| black_box(asp_geom::world::find_bearings(world.shapes(), world.contacts()).len()))
        });
        let n = world.num_parts();
        let full = PartSet::full(n);
        let mut group = c.benchmark_group(format!("removal_test/{name}"));
        group.sample_size(10);
        let mut k = 0;
        group.bench_function("cold", |b| {
            b.iter_batched(
                || {
                    k += 1;
                    (World::new(assembly.clone(), &WorldConfig::default()).expect("world"), k % n)
                },
                |(w, p)| black_box(w.removal().linear(p, &full).is_ok()),
                BatchSize::PerIteration,
            )
        });
        for p in 0..n {
            world.blocking().row(p);
        }
        let mut k = 0;
        group.bench_function("warm", |b| {
            b.iter(|| {
                k += 1;
                black_box(world.removal().linear(k % n, &full).is_ok())
            })
        });
        group.finish();
        // the sweeps of every part's cold row (real neighbours, t_max the model's size) on one thread, by the simultaneous BVH descent and by the
        // per-triangle candidate search it replaced (same pairs, same directions)
        let diag = world.assembly().diagonal();
        let row_sweeps = |reference: bool| {
            let mut blocked = 0;
            for p in 0..n {
                for q in (0..n).filter(|&q| q != p) {
                    let (moving, fixed) = world.blocking().pairs().shapes(p, q);
                    for &dir in world.blocking().directions() {
                        let hit = if reference {
                            asp_geom::sweep::sweep_hits_at_reference(&moving, &Pose::IDENTITY, dir, &fixed, diag)
                        } else {
                            asp_geom::sweep::sweep_hits(&moving, dir, &fixed, diag)
                        };
                        blocked += usize::from(hit);
                    }
                }
            }
            blocked
        };
        assert_eq!(row_sweeps(false), row_sweeps(true), "{name}: the two candidate searches disagree");
        let mut group = c.benchmark_group(format!("all_rows_serial/{name}"));
        group.sample_size(10);
        group.bench_function("bvh_descent", |b| b.iter(|| black_box(row_sweeps(false))));
        group.bench_function("per_triangle", |b| b.iter(|| black_box(row_sweeps(true))));
        group.finish();
        c.bench_function(&format!("stability/{name}"), |b| b.iter(|| black_box(world.contacts().stability(&full))));
        if name == "tube" || name == "table_lack_0825" {
            // the physics check of the state with part 1 removed (rapier, 1 s simulated)
            let physics = PhysicsStability::new(&world, &PhysicsConfig::default());
            let state = full.without(1);
            c.bench_function(&format!("stability_physics/{name}"), |b| b.iter(|| black_box(physics.stability(&world, &state))));
        }
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
