//! The learned part ordering: descending predicted removability, stable ties, in a real DFS.

use std::path::PathBuf;
use std::sync::Arc;

use asp_geom::graph::{AssemblyGraph, GraphConfig};
use asp_geom::{fixtures, Checker, CheckerConfig, PartSet, World, WorldConfig};
use asp_learn::{GnnFactory, GnnOrdering, GnnSource, RemovabilityModel};
use asp_search::{Budget, Dfs, OrderingSource, PartOrdering, Problem, Status};

fn model() -> Arc<RemovabilityModel> {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/random_gnn.onnx");
    let config = GraphConfig::default();
    Arc::new(RemovabilityModel::load(path, &config.features(), config.node_dim(), config.edge_dim()).unwrap())
}

#[test]
fn parts_are_tested_by_descending_score() {
    let world = World::new(fixtures::peg_in_hole(), &WorldConfig::default()).unwrap();
    let graph = Arc::new(AssemblyGraph::build(&world, &GraphConfig::default()).unwrap());
    let model = model();
    let mut ordering = GnnOrdering::new(graph.clone(), model.clone()).unwrap();
    let n = graph.num_parts();
    let state = PartSet::full(n);
    let expected = model.score_graph(&graph.state(&state)).unwrap();
    let scores = ordering.scores(&state).unwrap().to_vec();
    assert_eq!(scores, expected, "all parts present: scores follow part order");
    let mut parts: Vec<usize> = (0..n).rev().collect();
    ordering.order(&state, &mut parts);
    assert_eq!(parts.len(), n);
    for w in parts.windows(2) {
        assert!(scores[w[0]] >= scores[w[1]], "{parts:?} by {scores:?}");
    }
    // a smaller state: absent parts score -inf and the remaining ones are rescored
    let smaller = state.without(parts[0]);
    let s2 = ordering.scores(&smaller).unwrap().to_vec();
    assert_eq!(s2[parts[0]], f32::NEG_INFINITY);
    assert!(s2.iter().filter(|v| v.is_finite()).count() == n - 1);
    assert_eq!(ordering.failures(), 0);
}

#[test]
fn a_single_candidate_costs_no_inference() {
    let world = World::new(fixtures::figure_6_2(1.0), &WorldConfig::default()).unwrap();
    let graph = Arc::new(AssemblyGraph::build(&world, &GraphConfig::default()).unwrap());
    let mut ordering = GnnOrdering::new(graph.clone(), model()).unwrap();
    let state = PartSet::full(graph.num_parts());
    let mut one = vec![1];
    ordering.order(&state, &mut one);
    assert_eq!((one, ordering.skipped()), (vec![1], 1));
    let mut two = vec![0, 1];
    ordering.order(&state, &mut two);
    assert_eq!(ordering.skipped(), 1, "two candidates are ranked");
}

#[test]
fn equal_scores_keep_the_incoming_order() {
    // four isolated parts with identical attributes score the same
    let config = GraphConfig::default();
    let nodes: Vec<f32> = (0..4).flat_map(|_| (0..config.node_dim()).map(|k| (k % 7) as f32 * 0.1)).collect();
    let graph = Arc::new(AssemblyGraph::from_parts(&config, nodes, vec![], vec![]).unwrap());
    let mut ordering = GnnOrdering::new(graph, model()).unwrap();
    let state = PartSet::full(4);
    for incoming in [vec![0, 1, 2, 3], vec![3, 1, 0, 2], vec![2, 3]] {
        let mut parts = incoming.clone();
        ordering.order(&state, &mut parts);
        assert_eq!(parts, incoming);
    }
}

#[test]
fn a_dfs_with_the_learned_ordering_finds_plans() {
    let source = GnnSource::new(model(), GraphConfig::default()).unwrap();
    assert_eq!(source.name(), "gnn");
    for assembly in [fixtures::stacked_boxes(), fixtures::peg_in_hole(), fixtures::arch(), fixtures::tube()] {
        let name = assembly.source.clone();
        let world = World::new(assembly, &WorldConfig::default()).unwrap();
        let factory = source.prepare(&world).unwrap();
        assert_eq!(factory.name(), "gnn");
        let dfs = Dfs::builder().ordering_factory(factory.clone()).build();
        let checker = Checker::new(world, CheckerConfig::default());
        let first = dfs.solve(&Problem::full(&checker), &Budget::default());
        assert_eq!(first.status, Status::Found, "{name:?}");
        // deterministic: the same model gives the same plan
        let again = Dfs::builder().ordering_factory(factory).build().solve(&Problem::full(&checker), &Budget::default());
        let parts = |o: &asp_search::PlanOutcome| o.removals.iter().map(|s| s.part).collect::<Vec<_>>();
        assert_eq!(parts(&first), parts(&again));
    }
}

#[test]
fn other_features_are_refused() {
    let config = GraphConfig::builder().points_per_part(1024).build().unwrap();
    let err = GnnSource::new(model(), config.clone()).unwrap_err().to_string();
    assert!(err.ends_with("trained on features 'asp-graph/2 radius_bins=8 degree=8 points=2048', asp computes 'asp-graph/2 radius_bins=8 degree=8 points=1024'"), "{err}");
    let world = World::new(fixtures::stacked_boxes(), &WorldConfig::default()).unwrap();
    let graph = Arc::new(AssemblyGraph::build(&world, &config).unwrap());
    assert!(GnnFactory::new(graph, model()).is_err());
}

#[test]
fn cached_encodings_score_every_state_as_tract_does() {
    let shipped = Arc::new(RemovabilityModel::from_bytes(asp_learn::SHIPPED_MODEL, "shipped").unwrap());
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data");
    let config = GraphConfig::default();
    let (f, nd, ed) = (config.features(), config.node_dim(), config.edge_dim());
    let random = Arc::new(RemovabilityModel::load(dir.join("random_gnn.onnx"), &f, nd, ed).unwrap());
    let dense = Arc::new(RemovabilityModel::load(dir.join("random_gnn_dense.onnx"), &f, nd, ed).unwrap());
    let mut graphs: Vec<Arc<AssemblyGraph>> = [fixtures::figure_6_2(1.0), fixtures::hooked_bracket(), fixtures::dowel_in_two_boards()]
        .into_iter()
        .map(|a| Arc::new(AssemblyGraph::build(&World::new(a, &WorldConfig::default()).unwrap(), &config).unwrap()))
        .collect();
    // a synthetic 100-part graph: each part touches its next three (both directions)
    let mut s = 7u64;
    let mut next = move || {
        s = s.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        (s >> 40) as f32 / (1u64 << 24) as f32
    };
    let parts = 100;
    let mut edges: Vec<(usize, usize)> =
        (0..parts).flat_map(|i| (1..=3).flat_map(move |d| [(i, (i + d) % parts), ((i + d) % parts, i)])).collect();
    edges.sort();
    edges.dedup();
    let nodes: Vec<f32> = (0..parts * nd).map(|_| 3.0 * next()).collect();
    let attr: Vec<f32> = (0..edges.len() * ed).map(|_| 2.0 * next()).collect();
    graphs.push(Arc::new(AssemblyGraph::from_parts(&config, nodes, edges, attr).unwrap()));
    for model in [&shipped, &random, &dense] {
        for graph in &graphs {
            let mut ordering = GnnOrdering::new(graph.clone(), model.clone()).unwrap();
            assert!(ordering.is_fast());
            let n = graph.num_parts();
            let mut state = PartSet::full(n);
            // the full state, then removals one by one (a part drawn from the present ones)
            for _ in 0..n.min(12) {
                let want = model.score_graph_tract(&graph.state(&state)).unwrap();
                let got = ordering.scores(&state).unwrap().to_vec();
                let present: Vec<usize> = state.iter().filter(|&i| i < n).collect();
                for (&part, &w) in present.iter().zip(&want) {
                    assert!((got[part] - w).abs() <= 1e-4, "{model:?} part {part} of {present:?}: {} vs tract {w}", got[part]);
                }
                // the cached path gives the bits of the uncached Rust pass on a built state graph
                let built = model.score_graph(&graph.state(&state)).unwrap();
                for (&part, &b) in present.iter().zip(&built) {
                    assert_eq!(got[part].to_bits(), b.to_bits());
                }
                assert_eq!(got.iter().filter(|v| v.is_finite()).count(), present.len());
                if present.len() <= 1 {
                    break;
                }
                state = state.without(present[(next() * present.len() as f32) as usize % present.len()]);
            }
        }
    }
}
