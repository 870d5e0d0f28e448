//! `asp robot`: inspect robots. `asp robot check [URDF]` loads a URDF (default: the shipped panda)
//! and prints its joints and limits, its reach, and an FK/IK round-trip sanity check.

use crate::flags::{CellArgs, CheckArgs, RobotAction, RobotArgs};
use asp_robot::{ChainSpec, IkConfig, IkOutcome, JointKind, Robot};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use std::process::ExitCode;

/// The URDF's file rules from `--package-path` and `--allow-outside-files`.
fn robot_files(package_paths: &[String], allow_outside_files: bool) -> anyhow::Result<asp_robot::RobotFiles> {
    let package_paths = package_paths
        .iter()
        .map(|p| asp_robot::RobotFiles::parse_package_path(p).map_err(anyhow::Error::msg))
        .collect::<anyhow::Result<_>>()?;
    Ok(asp_robot::RobotFiles { package_paths, allow_outside_files })
}

/// Runs `asp robot`.
pub fn run(args: &RobotArgs) -> anyhow::Result<ExitCode> {
    match &args.action {
        RobotAction::Check(a) => check(a),
        RobotAction::Cell(a) => cell(a),
    }
}

fn cell(args: &CellArgs) -> anyhow::Result<ExitCode> {
    let mut map = crate::flags::Map::new();
    args.load.put(&mut map);
    args.robot.put(&mut map);
    if let Some(seed) = args.seed {
        map.insert("seed".into(), seed.into());
    }
    let request = crate::request::request(map, None)?;
    let check = asp_app::cell::check_cell(&args.model, &request).map_err(crate::request::cli_error)?;
    let p3 = |v: [f64; 3]| format!("({:.4}, {:.4}, {:.4})", v[0], v[1], v[2]);
    println!("{}: robot {}, base at {}, drop-off at {} (model units)", check.model, check.robot, p3(check.base), p3(check.drop_off));
    let width = check.parts.iter().map(|p| p.name.chars().count()).max().unwrap_or(4).max(4);
    println!("{:<width$}  {:>6}  alone", "part", "grasps");
    for p in &check.parts {
        let what = match (&p.path_length, &p.lift, &p.detail) {
            (Some(l), Some(d), _) => format!("taken out, path {l:.4} (lift along {})", p3(*d)),
            (_, _, Some(detail)) => detail.clone(),
            _ => p.outcome.to_string(),
        };
        println!("{:<width$}  {:>6}  {what}", p.name, p.grasps);
    }
    let failed: Vec<&str> = check.unreachable().map(|p| p.name.as_str()).collect();
    let total = check.parts.len();
    if failed.is_empty() {
        println!("the cell takes all {total} movable parts out on their own");
    } else {
        println!(
            "the cell cannot take {} of {total} movable parts out even on their own: {} (no plan can; move the base with --robot-base or the drop-off with --drop-off)",
            failed.len(),
            failed.join(", ")
        );
    }
    if let Some(path) = &args.json {
        let json = serde_json::to_string_pretty(&check)? + "\n";
        if path.as_os_str() == "-" {
            print!("{json}");
        } else {
            std::fs::write(path, json).map_err(|e| anyhow::anyhow!("{}: cannot write the check: {e}", path.display()))?;
        }
    }
    Ok(if failed.is_empty() { ExitCode::SUCCESS } else { ExitCode::from(1) })
}

fn check(args: &CheckArgs) -> anyhow::Result<ExitCode> {
    let spec = ChainSpec { base_link: args.base_link.clone(), tip_link: args.tip_link.clone() };
    let robot = match &args.urdf {
        Some(p) => Robot::from_urdf_file_checked(p, &spec, &robot_files(&args.package_path, args.allow_outside_files)?)?,
        None => Robot::from_urdf_str(asp_robot::PANDA_URDF, std::path::Path::new("<builtin panda>"), &spec)?,
    };
    println!("robot {} from {}", robot.name, robot.source.display());
    println!(
        "chain {} -> {}: {} joints, {} movable",
        robot.links()[0].name,
        robot.links().last().map_or("", |l| l.name.as_str()),
        robot.joints().len(),
        robot.dof()
    );
    for j in robot.joints() {
        let (unit, kind) = match j.kind {
            JointKind::Revolute => ("rad", "revolute"),
            JointKind::Prismatic => ("m", "prismatic"),
            JointKind::Fixed => ("", "fixed"),
        };
        if j.kind == JointKind::Fixed {
            println!("  {:<24} {kind}", j.name);
        } else {
            println!("  {:<24} {kind:<9} [{:+.4}, {:+.4}] {unit}", j.name, j.limits.0, j.limits.1);
        }
    }
    println!("gripper: {} fingers, opening up to {:.4} m", robot.fingers().len(), robot.max_opening());
    for n in &robot.notes {
        println!("note: {n}");
    }
    let mut rng = ChaCha8Rng::seed_from_u64(args.seed);
    let base = robot.base_pose().translation;
    let reach = (0..args.samples)
        .map(|_| (robot.tool_pose(&robot.random_configuration(&mut rng)).translation - base).length())
        .fold(0.0f32, f32::max);
    println!("reach: {reach:.4} m (max tool-centre distance from the base over {} sampled configurations)", args.samples);
    let (mut reached, mut worst_p, mut worst_r, mut limits_ok) = (0, 0.0f64, 0.0f64, true);
    let start = std::time::Instant::now();
    for t in 0..args.trials {
        let q = robot.random_configuration(&mut rng);
        let target = robot.tool_pose(&q);
        let cfg = IkConfig { seed: args.seed.wrapping_add(t as u64), ..Default::default() };
        if let IkOutcome::Reached(s) = robot.ik(&target, None, &cfg) {
            reached += 1;
            limits_ok &= robot.within_limits(&s.joints);
            let p = robot.tool_pose(&s.joints);
            worst_p = worst_p.max((p.translation - target.translation).length() as f64);
            worst_r = worst_r.max(p.rotation.angle_between(target.rotation) as f64);
        }
    }
    let per = start.elapsed().as_secs_f64() * 1e3 / args.trials.max(1) as f64;
    println!(
        "fk/ik round trip: {reached}/{} random configurations reached, worst error {:.2e} m, {:.2e} rad, limits {}, {per:.2} ms per pose",
        args.trials,
        worst_p,
        worst_r,
        if limits_ok { "respected" } else { "VIOLATED" }
    );
    let ok = limits_ok && reached * 10 >= args.trials * 9 && worst_p < 1e-4 && worst_r < 1e-3;
    println!("sanity check: {}", if ok { "ok" } else { "FAILED" });
    Ok(if ok { ExitCode::SUCCESS } else { ExitCode::from(1) })
}
