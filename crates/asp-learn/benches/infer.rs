//! Inference time of a removability model per state (3 layers, 64 wide, node_dim 74,
//! edge_dim 152): one plan with symbolic sizes vs. padded buckets with concrete plans, for the
//! ScatterND and the one-hot MatMul aggregations; and the shipped model (`shipped/...`, its own
//! width and layers, buckets).
//!
//! `cargo bench -p asp-learn --bench infer`

use std::hint::black_box;
use std::path::PathBuf;

use asp_learn::{RemovabilityModel, ShapePolicy};
use criterion::{criterion_group, criterion_main, Criterion};

const FEATURES: &str = "asp-graph/2 radius_bins=8 degree=8 points=2048";

fn graph(n: usize, e: usize, seed: u64) -> (Vec<f32>, Vec<i64>, Vec<f32>) {
    let mut s = seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1;
    let mut next = move || {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        s
    };
    let x = (0..n * 74).map(|_| (next() % 1000) as f32 / 500.0).collect();
    let mut src = Vec::with_capacity(2 * e);
    let mut dst = Vec::with_capacity(e);
    for _ in 0..e {
        let a = next() % n as u64;
        src.push(a as i64);
        dst.push(((a + 1 + next() % (n as u64 - 1)) % n as u64) as i64);
    }
    src.extend(dst);
    let attr = (0..e * 152).map(|_| (next() % 1000) as f32 / 500.0).collect();
    (x, src, attr)
}

fn infer(c: &mut Criterion) {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data");
    let mut group = c.benchmark_group("removability");
    for file in ["random_gnn.onnx", "random_gnn_dense.onnx"] {
        let aggregation = if file.contains("dense") { "dense" } else { "scatter" };
        for policy in [ShapePolicy::Symbolic, ShapePolicy::Buckets] {
            let model = RemovabilityModel::load(dir.join(file), FEATURES, 74, 152).unwrap().with_policy(policy);
            for (n, e) in [(40, 160), (100, 500)] {
                let (x, ei, ea) = graph(n, e, 1);
                model.score(&x, n, &ei, e, &ea).unwrap(); // compile the bucket's plan
                group.bench_function(format!("{aggregation}/{policy:?}/n{n}_e{e}"), |b| {
                    b.iter(|| black_box(model.score(black_box(&x), n, &ei, e, &ea).unwrap()))
                });
            }
        }
    }
    let shipped = RemovabilityModel::from_bytes(asp_learn::SHIPPED_MODEL, "shipped").unwrap();
    for (n, e) in [(40, 160), (100, 500)] {
        let (x, ei, ea) = graph(n, e, 1);
        shipped.score(&x, n, &ei, e, &ea).unwrap();
        group.bench_function(format!("shipped/n{n}_e{e}"), |b| {
            b.iter(|| black_box(shipped.score(black_box(&x), n, &ei, e, &ea).unwrap()))
        });
    }
    group.finish();
}

criterion_group!(benches, infer);
criterion_main!(benches);
