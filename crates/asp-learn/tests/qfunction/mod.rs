//! Learned Q-functions in the optimiser: a Q model's values are its scores of the state graph,
//! product-of-Q guidance keeps Pareto-MCTS feasible and within 1 % of the exact hypervolume on
//! small instances, and the same seed, threads and model give the same front.
//!
//! The fixtures `random_q_access.onnx` and `random_q_dirchange.onnx` (features `asp-q/1
//! directions=25 neighbours=8`) are written by `python -m asp.train.fixture`: Q networks of the
//! trainer briefly fitted to random targets, so their values are arbitrary but not uniform.

use std::path::PathBuf;
use std::sync::Arc;

use asp_geom::distmap::{DistanceMaps, MapConfig, MapState};
use asp_learn::{epsilon_greedy, GraphModel, ModelKind, OnnxQ, QProduct};
use asp_search::exact::exact_front;
use asp_search::objective::parse_objectives;
use asp_search::policy::{PolicyContext, QFunction, QUse};
use asp_search::qgraph::{direction_history, QGraph, QGraphBuilder};
use asp_search::{Mdp, ParetoMcts};
use rand::SeedableRng;

fn fixture(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data").join(name)
}

fn soma(seed: u64) -> asp_geom::Assembly {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    asp_gen::SomaCube::random(3, &mut rng).unwrap().to_assembly(0.05, "soma")
}

fn problem(assembly: &asp_geom::Assembly, objectives: &str) -> Mdp {
    let config = MapConfig::builder().resolution(5).build().unwrap();
    let maps = Arc::new(DistanceMaps::build(assembly, &config).unwrap());
    Mdp::new(maps, parse_objectives(objectives).unwrap()).unwrap()
}

#[test]
fn q_values_are_the_models_scores_of_the_state_graph() {
    let q = OnnxQ::load(fixture("random_q_access.onnx"), 25).unwrap();
    assert_eq!(q.objective(), "access");
    assert_eq!(q.config().features(), "asp-q/1 directions=25 neighbours=8");
    // maps of another resolution are refused with the file named
    let err = OnnxQ::load(fixture("random_q_access.onnx"), 81).unwrap_err().to_string();
    assert!(err.contains("random_q_access.onnx") && err.contains("25 directions"), "{err}");
    // a removability model is not a Q model
    let err = OnnxQ::load(fixture("random_gnn.onnx"), 25).unwrap_err().to_string();
    assert!(err.contains("asp.kind is 'removability', expected 'q'"), "{err}");

    // the reference path: tract on the full graph (the Rust forward pass is checked against it
    // in `the_rust_forward_pass_gives_tracts_values`)
    let q = q.tract_only();
    let p = problem(&soma(2), "access,dirchange");
    let mut state = MapState::new(p.maps());
    let mut memory = p.initial_memory();
    let mut actions = Vec::new();
    let mut rewards = vec![0.0; 2];
    let mut builder = QGraphBuilder::new(p.maps(), 8);
    let mut graph = QGraph::default();
    let mut distinct = 0;
    loop {
        state.feasible_actions(&mut actions);
        if actions.is_empty() {
            break;
        }
        let mut out = vec![0.0; actions.len()];
        {
            let mut ctx = PolicyContext { state: &mut state, memory: &memory, problem: &p };
            q.q_values(&mut ctx, &actions, &mut out).unwrap();
        }
        builder.build(&mut state, direction_history(&p, &memory), &actions, &mut graph);
        let scores = q.model().score(&graph.x, graph.num_nodes(), &graph.edge_index, graph.num_edges(), &graph.edge_attr).unwrap();
        for (k, &a) in actions.iter().enumerate() {
            let pos = graph.nodes.iter().position(|&i| i == a as i64).unwrap();
            assert_eq!(out[k], f64::from(scores[pos]).max(asp_learn::qfunction::MIN_Q));
        }
        if out.windows(2).any(|w| w[0] != w[1]) {
            distinct += 1;
        }
        p.step(&mut state, &mut memory, actions[0], asp_search::StepKind::Simulation, &mut rewards);
    }
    assert!(distinct > 0, "the fixture's values should tell actions apart");
}

#[test]
fn product_of_q_guidance_stays_feasible_and_near_the_exact_front() {
    let paths = [fixture("random_q_access.onnx"), fixture("random_q_dirchange.onnx")];
    let policy = epsilon_greedy(&paths, &["access", "dirchange"], 0.2, 25, QUse::Rollouts).unwrap();
    // the models must come in the objectives' order
    let err = epsilon_greedy(&paths, &["dirchange", "access"], 0.2, 25, QUse::Rollouts).unwrap_err().to_string();
    assert!(err.contains("random_q_access.onnx") && err.contains("'dirchange'"), "{err}");
    let mut checked = 0;
    for seed in 0..4 {
        let p = problem(&soma(seed), "access,dirchange");
        let exact = exact_front(&p, 2_000_000).unwrap();
        if exact.solutions.is_empty() {
            continue;
        }
        let reference: Vec<f64> = exact.worst.iter().map(|w| w - 1e-3 * w.abs().max(1.0)).collect();
        let run = |threads: usize| {
            ParetoMcts::builder()
                .seed(seed)
                .threads(threads)
                .reference(reference.clone())
                .policy(policy.clone())
                .build()
                .unwrap()
                .solve(&p)
                .unwrap()
        };
        let out = run(1);
        let hv = exact.hypervolume(&reference);
        assert!(out.value >= 0.99 * hv, "soma seed {seed}: {} of exact {hv}", out.value);
        for s in &out.solutions {
            let (values, _) = p.evaluate(&s.sequence).expect("a feasible sequence");
            assert!(values.iter().zip(&s.values).all(|(a, b)| (a - b).abs() <= 1e-9 * a.abs().max(1.0)));
        }
        // same seed, threads and model: the same front
        for threads in [1, 2] {
            let (a, b) = (run(threads), run(threads));
            let key =
                |o: &asp_search::SearchOutcome| o.solutions.iter().map(|s| (s.sequence.clone(), s.values.clone())).collect::<Vec<_>>();
            assert_eq!(key(&a), key(&b), "soma seed {seed}, {threads} threads");
        }
        checked += 1;
    }
    assert!(checked >= 3, "{checked}");
    // the model files are loaded once and shared: the policy holds both
    let _ = GraphModel::open_kind(&paths[1], ModelKind::Q).unwrap();
}

/// Random removal walks on `p` (seeded); calls `visit` on every state with its feasible actions.
fn walk_states(p: &Mdp, walks: u64, mut visit: impl FnMut(&mut MapState<'_>, &[u64], &[usize])) {
    use rand::RngExt;
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
    let mut actions = Vec::new();
    let mut rewards = vec![0.0; p.objectives().len()];
    for _ in 0..walks {
        let mut state = MapState::new(p.maps());
        let mut memory = p.initial_memory();
        loop {
            state.feasible_actions(&mut actions);
            if actions.is_empty() {
                break;
            }
            visit(&mut state, &memory, &actions);
            let a = actions[rng.random_range(0..actions.len())];
            p.step(&mut state, &mut memory, a, asp_search::StepKind::Simulation, &mut rewards);
        }
    }
}

#[test]
fn the_rust_forward_pass_gives_tracts_values() {
    // the fixtures (width 32, 3 layers), on a generated 4×4×4 Soma cube and a double-layer
    // profile assembly, in every state of random removal walks: the Rust forward pass with its
    // per-pair edge cache (one worker for all states, so cached pairs are reused across states)
    // against tract on the graph with its edge attributes
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(4);
    let cube = asp_gen::SomaCube::random(4, &mut rng).unwrap().to_assembly(0.05, "soma4");
    let profiles = asp_gen::ProfileAssembly::generate(&asp_gen::ProfileParams::double_layer(), 901).unwrap().to_assembly("profiles");
    // (`random_q_robot-path.onnx` comes from the trainer whose `QNetwork` composes a
    // `GraphEncoder`: its encoder's parameters are named `encoder.*`, the others' at the top)
    for name in ["random_q_access.onnx", "random_q_dirchange.onnx", "random_q_robot-path.onnx"] {
        let fast = OnnxQ::load(fixture(name), 25).unwrap();
        assert_eq!(fast.rust_forward(), Ok(()), "{name}");
        let tract = fast.clone().tract_only();
        assert!(tract.rust_forward().is_err());
        for assembly in [&cube, &profiles] {
            let p = problem(assembly, "access,dirchange");
            let (mut fast_worker, mut tract_worker) = (fast.for_worker(0).unwrap(), tract.for_worker(0).unwrap());
            let (mut states, mut worst, mut largest_state) = (0, 0.0f64, 0);
            walk_states(&p, 6, |state, memory, actions| {
                let mut a = vec![0.0; actions.len()];
                let mut b = vec![0.0; actions.len()];
                fast_worker.q_values(&mut PolicyContext { state: &mut *state, memory, problem: &p }, actions, &mut a).unwrap();
                tract_worker.q_values(&mut PolicyContext { state: &mut *state, memory, problem: &p }, actions, &mut b).unwrap();
                for (x, y) in a.iter().zip(&b) {
                    worst = worst.max((x - y).abs() / y.abs().max(1.0));
                }
                states += 1;
                largest_state = largest_state.max(state.present().len());
            });
            assert!(states >= 20 && largest_state >= 15, "{name} on {}: {states} states, {largest_state} parts", assembly.parts.len());
            assert!(worst <= 1e-5, "{name} on {} parts: fast and tract differ by {worst}", assembly.parts.len());
        }
    }
}

#[test]
fn a_product_of_q_models_on_one_graph_is_the_product_of_their_values() {
    // two models sharing the state graph (same features) in one worker: each state's values are
    // the product of the models' values evaluated one by one, each at least its floor
    let access = OnnxQ::load(fixture("random_q_access.onnx"), 25).unwrap();
    let dirchange = OnnxQ::load(fixture("random_q_dirchange.onnx"), 25).unwrap();
    let product = QProduct::new(vec![access.clone(), dirchange.clone()]).unwrap();
    assert!(QProduct::new(Vec::new()).is_err());
    let p = problem(&soma(5), "access,dirchange");
    let mut worker = product.for_worker(0).unwrap();
    let mut states = 0;
    walk_states(&p, 4, |state, memory, actions| {
        let mut got = vec![0.0; actions.len()];
        worker.q_values(&mut PolicyContext { state: &mut *state, memory, problem: &p }, actions, &mut got).unwrap();
        let (mut a, mut d) = (vec![0.0; actions.len()], vec![0.0; actions.len()]);
        access.q_values(&mut PolicyContext { state: &mut *state, memory, problem: &p }, actions, &mut a).unwrap();
        dirchange.q_values(&mut PolicyContext { state: &mut *state, memory, problem: &p }, actions, &mut d).unwrap();
        let want: Vec<f64> = a.iter().zip(&d).map(|(x, y)| x * y).collect();
        assert_eq!(got, want);
        states += 1;
    });
    assert!(states >= 10, "{states}");
}

#[test]
fn a_model_the_rust_forward_pass_does_not_know_stays_on_tract() {
    // a Q file whose weights are not under the trainer's names: refused by the Rust forward pass
    // with a reason, and still a working Q-function through tract
    // same-length renaming keeps the protobuf valid: the initialiser and the node inputs naming it
    let mut bytes = std::fs::read(fixture("random_q_access.onnx")).unwrap();
    let (from, to) = (b"phi_e.0.weight", b"phi_x.0.weight");
    let mut renamed = 0;
    for k in 0..bytes.len() - from.len() {
        if &bytes[k..k + from.len()] == from {
            bytes[k..k + to.len()].copy_from_slice(to);
            renamed += 1;
        }
    }
    assert!(renamed >= 2, "{renamed}");
    let model = GraphModel::from_bytes_kind(&bytes, "renamed.onnx", ModelKind::Q).unwrap();
    let q = OnnxQ::new(Arc::new(model), 25).unwrap();
    let why = q.rust_forward().unwrap_err().to_string();
    assert!(why.contains("phi_e.0.weight"), "{why}");
    let reference = OnnxQ::load(fixture("random_q_access.onnx"), 25).unwrap().tract_only();
    let p = problem(&soma(2), "access");
    let mut state = MapState::new(p.maps());
    let memory = p.initial_memory();
    let mut actions = Vec::new();
    state.feasible_actions(&mut actions);
    let (mut a, mut b) = (vec![0.0; actions.len()], vec![0.0; actions.len()]);
    q.q_values(&mut PolicyContext { state: &mut state, memory: &memory, problem: &p }, &actions, &mut a).unwrap();
    reference.q_values(&mut PolicyContext { state: &mut state, memory: &memory, problem: &p }, &actions, &mut b).unwrap();
    assert_eq!(a, b);
}

/// The shipped robot-path Q (`models/q-robot-path.onnx`,
/// `scripts/train-q-robot-path`) is what `asp plan --robot panda --objective robot-path --q` needs:
/// the `robot-path` objective, the default maps' features (resolution 9), and the Rust forward pass
/// (the trainer names its encoder's parameters `encoder.*`), giving tract's values.
#[test]
fn the_shipped_robot_path_q_runs_on_the_rust_forward_pass() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../models/q-robot-path.onnx");
    let q = OnnxQ::load(&path, 81).unwrap();
    assert_eq!(q.objective(), "robot-path");
    assert_eq!(q.config().features(), "asp-q/1 directions=81 neighbours=8");
    assert_eq!(q.rust_forward(), Ok(()));
}
