//! Time a learned Q-function per state: the `asp-q/1` graph build and the ONNX inference that
//! `asp plan --q` runs at every guided rollout step.
//!
//! ```text
//! cargo run --release -p asp-learn --example q_infer -- MODEL.glb Q.onnx [STATES]
//! ```
//!
//! Walks random removal sequences on the model's distance maps (resolution from the Q model's
//! features) and prints the mean time per state of building the graph and of scoring it, by
//! the number of parts present.

use asp_geom::distmap::{DistanceMaps, MapConfig, MapState};
use asp_learn::OnnxQ;
use asp_search::objective::parse_objectives;
use asp_search::qgraph::{direction_history, QGraph, QGraphBuilder};
use asp_search::Mdp;
use std::collections::BTreeMap;
use std::sync::Arc;
use std::time::Instant;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [model, q, rest @ ..] = &args[..] else {
        return Err("usage: q_infer MODEL.glb Q.onnx [STATES]".into());
    };
    let states: usize = rest.first().map(|s| s.parse()).transpose()?.unwrap_or(2000);
    let assembly = asp_geom::io::load(std::path::Path::new(model), &Default::default())?;
    let probe = asp_learn::GraphModel::open_kind(q, asp_learn::ModelKind::Q)?;
    let config = asp_learn::qfunction::parse_features(probe.features()).ok_or("not an asp-q/1 model")?;
    let resolution = (config.directions as f64).sqrt().round() as usize;
    let maps = Arc::new(DistanceMaps::build(&assembly, &MapConfig::builder().resolution(resolution).build()?)?);
    let q = OnnxQ::load(q, maps.num_directions())?;
    let problem = Mdp::new(maps.clone(), parse_objectives(q.objective())?)?;
    let mut builder = QGraphBuilder::new(&maps, config.neighbours);
    let mut graph = QGraph::default();
    let mut by_size: BTreeMap<usize, (u32, f64, f64)> = BTreeMap::new();
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
            let t = Instant::now();
            builder.build(&mut state, direction_history(&problem, &memory), &actions, &mut graph);
            let built = t.elapsed().as_secs_f64();
            let t = Instant::now();
            q.model().score(&graph.x, graph.num_nodes(), &graph.edge_index, graph.num_edges(), &graph.edge_attr)?;
            let scored = t.elapsed().as_secs_f64();
            let e = by_size.entry(graph.num_nodes() - 1).or_default();
            *e = (e.0 + 1, e.1 + built, e.2 + scored);
            done += 1;
            seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            let a = actions[(seed >> 33) as usize % actions.len()];
            problem.step(&mut state, &mut memory, a, asp_search::StepKind::Simulation, &mut rewards);
        }
    }
    println!("parts  states  graph (ms)  inference (ms)");
    for (parts, (n, b, s)) in by_size {
        println!("{parts:>5}  {n:>6}  {:>10.3}  {:>14.3}", 1e3 * b / f64::from(n), 1e3 * s / f64::from(n));
    }
    Ok(())
}
