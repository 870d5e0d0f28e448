//! What robot-path MCTS costs, counted: runs the search `asp plan MODEL --robot panda --objective
//! robot-path --episodes E --budget 5 --seed S --threads 1` runs, then prints the wall time, the
//! best total and the robot planner's counters (`asp_robot::PlanStats`: plans, grasps, collision
//! checks and the mean time of one check, sphere and exact, timed on every 32nd check).
//!
//! ```text
//! cargo run --release -p asp-app --example robot_episode -- MODEL.glb [EPISODES] [SEED] [KEY=VALUE ...]
//! ```
//! A `KEY=VALUE` is a robot setting for comparisons: `sphere_check`, `lazy`, `clearance_skipping`
//! (`true`/`false`).

use asp_app::pipeline;
use asp_robot::{RobotExtension, RobotSetup};
use asp_search::extension::MdpExtension;
use std::sync::Arc;
use std::time::Instant;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let Some(model) = args.first() else {
        return Err("usage: robot_episode MODEL [EPISODES] [SEED] [KEY=VALUE ...]".into());
    };
    let numbers: Vec<&String> = args[1..].iter().filter(|a| !a.contains('=')).collect();
    let episodes: usize = numbers.first().map_or(Ok(1), |e| e.parse())?;
    let seed: u64 = numbers.get(1).map_or(Ok(1), |s| s.parse())?;
    let mut setup = RobotSetup::panda();
    for a in args[1..].iter().filter(|a| a.contains('=')) {
        let (key, value) = a.split_once('=').unwrap_or_default();
        let on: bool = value.parse().map_err(|_| format!("{a}: expected true or false"))?;
        match key {
            "sphere_check" => setup.config.sphere_check = on,
            "lazy" => setup.config.rrt.lazy = on,
            "clearance_skipping" => setup.config.clearance_skipping = on,
            _ => return Err(format!("{a}: unknown setting").into()),
        }
    }
    let json =
        format!(r#"{{"objective": "robot-path", "robot": "panda", "episodes": {episodes}, "budget": 5, "seed": {seed}, "threads": 1}}"#);
    let plan = asp_app::resolve(&asp_app::PlanRequest::from_json(&json)?)?;
    let mut o = plan.optimise.clone().ok_or("no optimiser settings")?;
    let ext = Arc::new(RobotExtension::new(setup));
    o.extensions = vec![ext.clone() as Arc<dyn MdpExtension>];
    let assembly = Arc::new(pipeline::load(std::path::Path::new(model), &plan)?);
    let started = Instant::now();
    let result = pipeline::optimise(assembly, &plan, &o)?;
    let seconds = started.elapsed().as_secs_f64();
    let robot = ext.current_model().ok_or("the search built no robot")?;
    let s = robot.planner().stats();
    let report = serde_json::to_value(&result.report)?;
    println!("model {model}: {episodes} episode(s), seed {seed}, {seconds:.2} s wall");
    println!("status {}, robot path {}", report["status"], report["robot"]["total_path_length"]);
    println!(
        "plans {}, grasps examined {} pruned {} planned {}, lift {:.2} s, gripper {:.2} s, ik {:.2} s, reach {:.2} s, drop-off {:.2} s, rrt {:.2} s, re-check {:.2} s, exact {:.2} s ({} refused)",
        s.plans,
        s.grasps_examined,
        s.grasps_pruned,
        s.grasps_planned,
        s.lift_ns as f64 * 1e-9,
        s.gripper_ns as f64 * 1e-9,
        s.ik_ns as f64 * 1e-9,
        s.reach_check_ns as f64 * 1e-9,
        s.drop_off_ns as f64 * 1e-9,
        s.rrt_ns as f64 * 1e-9,
        s.recheck_ns as f64 * 1e-9,
        s.exact_ns as f64 * 1e-9,
        s.exact_refused,
    );
    println!(
        "checks {} ({} exact), held {}, skipped samples {}, re-checks refused {}",
        s.robot_checks, s.exact_checks, s.held_checks, s.skipped_samples, s.rechecks_refused
    );
    let mean = |m: Option<f64>| m.map_or("-".to_string(), |ns| format!("{:.3} us", ns * 1e-3));
    println!(
        "one check: sphere {} ({} timed), exact {} ({} timed)",
        mean(s.sphere_check_mean_ns()),
        s.sphere_checks_timed,
        mean(s.exact_check_mean_ns()),
        s.exact_checks_timed
    );
    Ok(())
}
