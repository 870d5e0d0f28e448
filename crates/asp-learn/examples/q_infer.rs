//! Time a learned Q-function per state: the `asp-q/1` graph build and the ONNX inference that
//! `asp plan --q` runs at every guided rollout step.
//!
//! ```text
//! cargo run --release -p asp-learn --example q_infer -- MODEL.glb Q.onnx [STATES [search]]
//! ```
//!
//! Walks random removal sequences on the model's distance maps (resolution from the Q model's
//! features) and prints, by the number of parts present, the mean time per state of the tract
//! path (building the full graph, then scoring it) and of the Q-function as the search calls it
//! (`QWorker::q_values`: the Rust forward pass with its per-pair edge cache, when the model has
//! one), and the largest difference between the two paths' values.
//!
//! With a fourth argument `search`, only the search's path runs (no tract, no comparison), which
//! is what `perf record` of this example should see.

use asp_geom::distmap::{DistanceMaps, MapConfig, MapState};
use asp_learn::OnnxQ;
use asp_search::objective::parse_objectives;
use asp_search::policy::{PolicyContext, QFunction};
use asp_search::qgraph::{direction_history, QGraph, QGraphBuilder};
use asp_search::Mdp;
use std::collections::BTreeMap;
use std::sync::Arc;

/// Seconds this thread has run on a CPU (`/proc/thread-self/schedstat`, Linux; coarse per call,
/// so only means over many states mean something), else wall time since the first call: on a
/// shared machine, wall time also counts the time other processes had the core.
fn cpu_seconds() -> f64 {
    static START: std::sync::OnceLock<std::time::Instant> = std::sync::OnceLock::new();
    match std::fs::read_to_string("/proc/thread-self/schedstat").ok().and_then(|s| s.split_whitespace().next()?.parse::<f64>().ok()) {
        Some(ns) => ns * 1e-9,
        None => START.get_or_init(std::time::Instant::now).elapsed().as_secs_f64(),
    }
}

struct Instant(f64);

impl Instant {
    fn now() -> Self {
        Instant(cpu_seconds())
    }

    fn elapsed(&self) -> Elapsed {
        Elapsed(cpu_seconds() - self.0)
    }
}

struct Elapsed(f64);

impl Elapsed {
    fn as_secs_f64(&self) -> f64 {
        self.0
    }
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [model, q, rest @ ..] = &args[..] else {
        return Err("usage: q_infer MODEL.glb Q.onnx [STATES [search]]".into());
    };
    let states: usize = rest.first().map(|s| s.parse()).transpose()?.unwrap_or(2000);
    let search_only = match rest.get(1).map(String::as_str) {
        None => false,
        Some("search") => true,
        Some(other) => return Err(format!("unknown mode '{other}' (only 'search')").into()),
    };
    let assembly = asp_geom::io::load(std::path::Path::new(model), &Default::default())?;
    let probe = asp_learn::GraphModel::open_kind(q, asp_learn::ModelKind::Q)?;
    let config = asp_learn::qfunction::parse_features(probe.features()).ok_or("not an asp-q/1 model")?;
    let resolution = (config.directions as f64).sqrt().round() as usize;
    let maps = Arc::new(DistanceMaps::build(&assembly, &MapConfig::builder().resolution(resolution).build()?)?);
    let q = OnnxQ::load(q, maps.num_directions())?;
    if let Err(why) = q.rust_forward() {
        eprintln!("no Rust forward pass ({why}): the search column is tract too");
    }
    let mut worker = q.for_worker(0)?;
    let mut values = Vec::new();
    let problem = Mdp::new(maps.clone(), parse_objectives(q.objective())?)?;
    let mut builder = QGraphBuilder::new(&maps, config.neighbours);
    let mut graph = QGraph::default();
    let mut by_size: BTreeMap<usize, (u32, f64, f64, f64)> = BTreeMap::new();
    let mut worst = 0.0f64;
    let mut actions = Vec::new();
    let mut rewards = vec![0.0];
    let mut seed = 1u64;
    let mut done = 0;
    while done < states {
        let mut state = MapState::new(&maps);
        let mut memory = problem.initial_memory();
        loop {
            state.feasible_actions(&mut actions);
            if actions.is_empty() || done >= states {
                break;
            }
            let (mut built, mut scored, mut scores) = (0.0, 0.0, Vec::new());
            if !search_only {
                let t = Instant::now();
                builder.build(&mut state, direction_history(&problem, &memory), &actions, &mut graph);
                built = t.elapsed().as_secs_f64();
                let t = Instant::now();
                scores = q.model().score(&graph.x, graph.num_nodes(), &graph.edge_index, graph.num_edges(), &graph.edge_attr)?;
                scored = t.elapsed().as_secs_f64();
            }
            values.resize(actions.len(), 0.0);
            let t = Instant::now();
            worker.q_values(&mut PolicyContext { state: &mut state, memory: &memory, problem: &problem }, &actions, &mut values)?;
            let search = t.elapsed().as_secs_f64();
            for (v, &a) in values.iter().zip(&actions).filter(|_| !search_only) {
                let k = graph.nodes.iter().position(|&p| p == a as i64).ok_or("action without a node")?;
                let r = f64::from(scores[k]).max(asp_learn::qfunction::MIN_Q);
                worst = worst.max((v - r).abs() / r.abs().max(1.0));
            }
            let e = by_size.entry(state.present().len()).or_default();
            *e = (e.0 + 1, e.1 + built, e.2 + scored, e.3 + search);
            done += 1;
            seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            let a = actions[(seed >> 33) as usize % actions.len()];
            problem.step(&mut state, &mut memory, a, asp_search::StepKind::Simulation, &mut rewards);
        }
    }
    println!("parts  states  tract: graph (ms)  inference (ms)  search's q_values (ms)");
    for (parts, (n, b, s, r)) in by_size {
        let n = f64::from(n);
        println!("{parts:>5}  {n:>6}  {:>17.3}  {:>14.3}  {:>21.4}", 1e3 * b / n, 1e3 * s / n, 1e3 * r / n);
    }
    println!("largest |search - tract| / max(1, |tract|): {worst:.2e}");
    Ok(())
}
