//! Times a learned Q-function per optimiser state on a real model (the goal: "Q inference
//! per state ≤ 0.2 ms at 30 parts"): the model's robot-path problem as `asp plan --robot panda
//! --objective robot-path` builds it, then one Q evaluation of every feasible removal (the graph
//! built from the maps and the forward pass, as a guided rollout step asks it) in each state of
//! random removal sequences.
//!
//! ```text
//! cargo run --release -p asp-app --example q_state_time -- MODEL.glb Q.onnx [RESOLUTION] [STATES]
//! ```

use asp_app::pipeline;
use asp_geom::distmap::MapState;
use asp_search::policy::{PolicyContext, QFunction};
use std::sync::Arc;
use std::time::Instant;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [model, q, ..] = &args[..] else {
        return Err("usage: q_state_time MODEL Q.onnx [RESOLUTION] [STATES]".into());
    };
    let resolution: usize = args.get(2).map_or(Ok(9), |r| r.parse())?;
    let states: usize = args.get(3).map_or(Ok(2000), |s| s.parse())?;
    let json = format!(r#"{{"objective": "robot-path", "robot": "panda", "resolution": {resolution}}}"#);
    let mut plan = asp_app::resolve(&asp_app::PlanRequest::from_json(&json)?)?;
    let o = plan.optimise.take().ok_or("no optimiser settings")?;
    let assembly = Arc::new(pipeline::load(std::path::Path::new(model), &plan)?);
    let mdp = pipeline::optimiser_problem(&assembly, &plan, &o)?.mdp;
    let q = asp_learn::OnnxQ::load(q, mdp.maps().num_directions())?;
    let mut worker = q.for_worker(0)?;
    let memory = mdp.initial_memory();
    let maps = mdp.maps();
    let (mut seed, mut timed, mut actions_total, mut parts_total) = (1u64, 0usize, 0usize, 0usize);
    let (mut actions, mut out) = (Vec::new(), Vec::new());
    let mut seconds = 0.0;
    while timed < states {
        let mut state = MapState::new(maps);
        loop {
            state.feasible_actions(&mut actions);
            if actions.is_empty() || timed == states {
                break;
            }
            out.resize(actions.len(), 0.0);
            let started = Instant::now();
            let mut ctx = PolicyContext { state: &mut state, memory: &memory, problem: &mdp };
            worker.q_values(&mut ctx, &actions, &mut out)?;
            seconds += started.elapsed().as_secs_f64();
            timed += 1;
            actions_total += actions.len();
            parts_total += state.present().len();
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            state.remove(actions[(seed % actions.len() as u64) as usize]);
        }
    }
    println!(
        "{}: {} parts, {} directions, Rust forward pass: {:?}; {timed} states (mean {:.1} parts present, {:.1} actions): {:.3} ms per state",
        model,
        maps.num_parts(),
        maps.num_directions(),
        q.rust_forward(),
        parts_total as f64 / timed as f64,
        actions_total as f64 / timed as f64,
        seconds / timed as f64 * 1e3
    );
    Ok(())
}
