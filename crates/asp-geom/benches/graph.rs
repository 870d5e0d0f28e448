//! Criterion benches of the graph features (thesis 3.4): `AssemblyGraph::build` on shipped models
//! and on a synthetic 100-part model of about 200k triangles, and `state_into` on a 40-part state.
//! The collision world is built once, outside the timing.

use asp_geom::fixtures::{assemble, part};
use asp_geom::io::{load, LoadOptions};
use asp_geom::math::{Axis, Vec3};
use asp_geom::{Assembly, AssemblyGraph, GraphConfig, Mesh, PartSet, StateGraph, Units, World, WorldConfig};
use criterion::{criterion_group, criterion_main, Criterion};
use rand::{RngExt, SeedableRng};
use std::hint::black_box;
use std::path::Path;

/// A box from `mins` to `maxs` whose faces are each cut into `n × n` quads (`12 n²` triangles).
fn fine_box(mins: Vec3, maxs: Vec3, n: u32) -> Mesh {
    let mut m = Mesh::default();
    let size = maxs - mins;
    for axis in 0..3 {
        let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
        for positive in [false, true] {
            let base = m.vertices.len() as u32;
            for i in 0..=n {
                for j in 0..=n {
                    let mut p = mins;
                    p[axis] = if positive { maxs[axis] } else { mins[axis] };
                    p[u] += size[u] * i as f32 / n as f32;
                    p[v] += size[v] * j as f32 / n as f32;
                    m.vertices.push(p);
                }
            }
            let at = |i: u32, j: u32| base + i * (n + 1) + j;
            for i in 0..n {
                for j in 0..n {
                    let q = [at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)];
                    let (a, b) = if positive { ([q[0], q[1], q[2]], [q[0], q[2], q[3]]) } else { ([q[0], q[2], q[1]], [q[0], q[3], q[2]]) };
                    m.triangles.push(a);
                    m.triangles.push(b);
                }
            }
        }
    }
    m
}

/// 100 finely meshed boxes (2028 triangles each) in two touching 5 × 10 layers on a fixed slab.
fn grid_100() -> Assembly {
    let mut parts = vec![part("slab", Mesh::cuboid(Vec3::new(-1.0, -1.0, -0.5), Vec3::new(11.0, 6.0, 0.0)), true)];
    for layer in 0..2 {
        for x in 0..10 {
            for y in 0..5 {
                let mins = Vec3::new(x as f32, y as f32, layer as f32);
                parts.push(part(&format!("b{layer}_{x}_{y}"), fine_box(mins, mins + Vec3::ONE, 13), false));
            }
        }
    }
    assemble("grid_100", parts, Axis::Z)
}

fn models() -> Vec<(String, Assembly)> {
    let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tests/data");
    let z = LoadOptions { up: Some(Axis::Z), ..LoadOptions::default() };
    let mm = LoadOptions { unit: Units::parse("mm"), up: Some(Axis::Z), ..LoadOptions::default() };
    vec![
        ("chair_bertil_0148".into(), load(&data.join("ikea/chair_bertil_0148.glb"), &z).expect("chair")),
        ("pump".into(), load(&data.join("pump"), &mm).expect("pump")),
        ("grid_100".into(), grid_100()),
    ]
}

fn bench(c: &mut Criterion) {
    let config = GraphConfig::default();
    let mut grid = None;
    for (name, assembly) in models() {
        let triangles: usize = assembly.parts.iter().map(|p| p.mesh.triangles.len()).sum();
        let world = World::new(assembly, &WorldConfig::default()).expect("world");
        let g = AssemblyGraph::build(&world, &config).expect("graph");
        eprintln!("{name}: {} parts, {triangles} triangles, {} edges", g.num_parts(), g.num_edges());
        let mut group = c.benchmark_group("graph_build");
        group.sample_size(10);
        group.bench_function(&name, |b| b.iter(|| black_box(AssemblyGraph::build(&world, &config).expect("graph"))));
        group.finish();
        if name == "grid_100" {
            grid = Some(g);
        }
    }
    // a 40-part state of the 101-part grid (seeded), into reused buffers and freshly allocated
    let g = grid.expect("grid built");
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(0);
    let mut present = PartSet::empty(g.num_parts());
    while present.len() < 40 {
        present.insert(rng.random_range(0..g.num_parts()));
    }
    let mut out = StateGraph::default();
    g.state_into(&present, &mut out);
    eprintln!("state: {} nodes, {} edges", out.num_nodes(), out.num_edges());
    c.bench_function("graph_state/grid_100_40_parts/reused", |b| {
        b.iter(|| {
            g.state_into(black_box(&present), &mut out);
            black_box(out.num_edges())
        })
    });
    c.bench_function("graph_state/grid_100_40_parts/new", |b| b.iter(|| black_box(g.state(black_box(&present)))));
}

criterion_group!(benches, bench);
criterion_main!(benches);
