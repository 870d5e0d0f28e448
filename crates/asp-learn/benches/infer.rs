//! Inference time of a removability model per state (3 layers, 64 wide, node_dim 74,
//! edge_dim 152): one plan with symbolic sizes vs. padded buckets with concrete plans, for the
//! ScatterND and the one-hot MatMul aggregations; and the shipped model (`shipped/...`, its own
//! width and layers, buckets).
//!
//! The Q network's Rust forward pass per state (`q/...`): the width-32 fixture on a state graph of
//! 40 and 70 parts, 8 nearest neighbours each plus the context node's edge, edge encodings
//! precomputed as the search's pair cache holds them.
//!
//! `cargo bench -p asp-learn --bench infer`

use std::hint::black_box;
use std::path::PathBuf;

use asp_learn::qnet::GraphView;
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
        group.bench_function(format!("shipped/n{n}_e{e}"), |b| b.iter(|| black_box(shipped.score(black_box(&x), n, &ei, e, &ea).unwrap())));
    }
    group.finish();
}

fn q_forward(c: &mut Criterion) {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data");
    let model = asp_learn::GraphModel::open_kind(dir.join("random_q_access.onnx"), asp_learn::ModelKind::Q).unwrap();
    let net = asp_learn::qnet::QNet::from_model(&model).unwrap();
    let (node_dim, edge_dim, width) = (model.node_dim(), model.edge_dim(), net.width());
    let mut group = c.benchmark_group("q");
    for parts in [40usize, 70] {
        let n = parts + 1; // the context node last
        let mut x: Vec<f32> = (0..n * node_dim).map(|i| ((i * 37) % 101) as f32 / 101.0).collect();
        for k in 0..n {
            x[k * node_dim] = if k < parts { 1.0 } else { 0.0 };
        }
        let (mut sources, mut targets) = (Vec::new(), Vec::new());
        for t in 0..parts as u32 {
            for j in 1..=8 {
                sources.push((t + j) % parts as u32);
                targets.push(t);
            }
            sources.push(parts as u32);
            targets.push(t);
        }
        let (mut edges, mut scratch) = (vec![0.0; sources.len() * width], Vec::new());
        for (k, out) in edges.chunks_exact_mut(width).enumerate() {
            let row: Vec<f32> = (0..edge_dim).map(|i| ((i * 13 + k * 7) % 97) as f32 / 97.0).collect();
            net.encode_edge(&row, out, &mut scratch);
        }
        let wanted: Vec<usize> = (0..parts).collect();
        let (mut out, mut s) = (vec![0.0; parts], asp_learn::qnet::Scratch::default());
        group.bench_function(format!("width{width}/parts{parts}"), |b| {
            b.iter(|| {
                let graph = GraphView { x: black_box(&x), h0: None, n, sources: &sources, targets: &targets, edges: &edges };
                net.forward(graph, &wanted, &mut out, &mut s);
                black_box(out[0])
            })
        });
    }
    group.finish();
}

/// The shipped removability model as `--order gnn` runs it: the Rust forward
/// pass from node and edge encodings cached per graph, per state of 40 and 100 parts with 4 and 5
/// edges per part (the sizes of `shipped/...` above).
fn gnn_state(c: &mut Criterion) {
    use asp_geom::graph::{AssemblyGraph, GraphConfig};
    use std::sync::Arc;
    let shipped = Arc::new(RemovabilityModel::from_bytes(asp_learn::SHIPPED_MODEL, "shipped").unwrap());
    let config = GraphConfig::default();
    let mut group = c.benchmark_group("gnn_state");
    for (n, e) in [(40usize, 160usize), (100, 500)] {
        let (x, ei, _) = graph(n, e, 1);
        let mut edges: Vec<(usize, usize)> = (0..e).map(|k| (ei[k] as usize, ei[e + k] as usize)).collect();
        edges.sort();
        edges.dedup();
        let attr = (0..edges.len() * config.edge_dim()).map(|k| ((k * 37) % 1000) as f32 / 500.0).collect();
        let graph = Arc::new(AssemblyGraph::from_parts(&config, x, edges, attr).unwrap());
        let mut ordering = asp_learn::GnnOrdering::new(graph, shipped.clone()).unwrap();
        assert!(ordering.is_fast());
        let state = asp_geom::PartSet::full(n);
        group.bench_function(format!("shipped/n{n}_e{e}"), |b| b.iter(|| black_box(ordering.scores(black_box(&state)).unwrap()[0])));
    }
    group.finish();
}

criterion_group!(benches, infer, q_forward, gnn_state);
criterion_main!(benches);
