//! `asp plan`: load, plan, print the table, write the JSON.

use crate::flags::{OrderArg, PlanArgs, StabilityArg};
use anyhow::{bail, Context};
use asp_geom::io::{load, LoadOptions};
use asp_geom::math::Axis;
use asp_geom::physics::PhysicsConfig;
use asp_geom::rrt::RrtConfig;
use asp_geom::{Checker, CheckerConfig, StabilityMode, Units, World, WorldConfig};
use asp_search::report::{MotionEntry, PlanReport};
use asp_search::{Budget, Dfs, Ordering, Planner, Problem, Progress, Status};
use std::io::{IsTerminal, Write};
use std::process::ExitCode;
use std::time::Duration;

pub(crate) fn positive(name: &str, v: f64) -> anyhow::Result<f64> {
    if v > 0.0 && v.is_finite() {
        Ok(v)
    } else {
        bail!("--{name} must be a positive number, got {v}")
    }
}

/// Runs `asp plan`.
pub fn plan(args: &PlanArgs) -> anyhow::Result<ExitCode> {
    let unit = match &args.unit {
        Some(u) => Some(Units::parse(u).with_context(|| format!("--unit: unknown unit '{u}' (use m, cm, mm, in, ft or a number of metres)"))?),
        None => None,
    };
    let up = match &args.up {
        Some(a) => Some(Axis::parse(a).with_context(|| format!("--up: '{a}' is not an axis (use x, y, z, -x, -y, -z)"))?),
        None => None,
    };
    let options = LoadOptions { unit, up, fixed: args.fixed.clone() };
    let assembly = load(&args.model, &options)?;
    if args.optimise.is_active() {
        return crate::optimise::plan(args, assembly);
    }
    let metres = assembly.units.metres;
    let to_m = |name: &str, v: Option<f64>| -> anyhow::Result<Option<f32>> {
        v.map(|v| positive(name, v).map(|v| (v * metres) as f32)).transpose()
    };
    let config = WorldConfig {
        tolerance: to_m("tolerance", args.tolerance)?,
        contact_distance: to_m("contact-distance", args.contact_distance)?,
        normal_clusters: args.normals,
        sphere_directions: args.sphere_directions,
        ignore_overlapping: args.ignore_overlapping,
        ..WorldConfig::default()
    };
    let world = World::new(assembly, &config)?;
    if !args.quiet {
        for w in world.warnings() {
            eprintln!("warning: {}: {w}", args.model.display());
        }
    }
    let stability = match args.stability {
        StabilityArg::Contact => StabilityMode::ContactGraph,
        StabilityArg::Physics => {
            let physics = PhysicsConfig {
                displacement_fraction: positive("physics-threshold", args.physics_threshold)? as f32,
                ..PhysicsConfig::default()
            };
            physics.validate()?;
            StabilityMode::Physics(physics)
        }
    };
    let rrt = RrtConfig {
        max_iterations: args.rrt_iterations,
        max_time: Duration::from_secs_f64(positive("rrt-time", args.rrt_time)?),
        ..RrtConfig::default()
    };
    let checker = Checker::new(world, CheckerConfig { stability, rrt });
    let planner = Dfs::builder()
        .ordering(if args.order == OrderArg::Random { Ordering::Random } else { Ordering::Given })
        .bookkeeping(args.bookkeeping || args.order == OrderArg::Bookkeeping)
        .path_planner(!args.no_path_planner)
        .seed(args.seed)
        .build();
    let budget = Budget {
        max_tests: args.max_tests,
        timeout: args.timeout.map(|t| positive("timeout", t).map(Duration::from_secs_f64)).transpose()?,
    };
    let bar = progress_bar(args.quiet);
    let report_progress = |p: &Progress| {
        if let Some(bar) = &bar {
            bar.set_length(p.total as u64);
            bar.set_position(p.removed as u64);
            bar.set_message(format!("{} tests", p.tests));
        }
    };
    let mut problem = Problem::full(&checker);
    problem.progress = Some(&report_progress);
    let outcome = planner.solve(&problem, &budget);
    if let Some(bar) = bar {
        bar.finish_and_clear();
    }
    let world = checker.world();
    let report = PlanReport::new(world.assembly(), &outcome, world.tolerance(), world.warnings());
    if let Some(path) = &args.mcap {
        asp_viz::mcap::write_plan(path, world.assembly(), &report)?;
    }
    let json = serde_json::to_string_pretty(&report)?;
    if let Some(path) = &args.out {
        std::fs::write(path, format!("{json}\n")).with_context(|| format!("{}: cannot write the plan", path.display()))?;
    }
    let mut stdout = std::io::stdout().lock();
    if args.json {
        writeln!(stdout, "{json}")?;
    } else {
        write_table(&mut stdout, &report)?;
    }
    Ok(match outcome.status {
        Status::Found => ExitCode::SUCCESS,
        _ => ExitCode::from(1),
    })
}

fn progress_bar(quiet: bool) -> Option<indicatif::ProgressBar> {
    if quiet || !std::io::stderr().is_terminal() {
        return None;
    }
    let bar = indicatif::ProgressBar::new(0);
    bar.set_style(
        indicatif::ProgressStyle::with_template("{spinner} removed {pos}/{len} parts on the current branch, {msg} [{elapsed}]")
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_spinner()),
    );
    bar.enable_steady_tick(Duration::from_millis(120));
    Some(bar)
}

/// The human-readable plan: a header, the assembly sequence, and the explanation when stuck.
pub(crate) fn write_table(out: &mut impl Write, r: &PlanReport) -> std::io::Result<()> {
    let s = &r.stats;
    writeln!(
        out,
        "{}: {} in {:.3} s — {} removal tests ({} failed by collision, {} by gravity), {} path planner calls",
        r.model,
        r.status.replace('_', " "),
        s.seconds,
        s.removal_tests,
        s.failed_collision,
        s.failed_gravity,
        s.path_planner_calls
    )?;
    let width = r.parts.iter().map(|p| p.name.len()).max().unwrap_or(4).max(4);
    let fixed: Vec<&str> = r.parts.iter().filter(|p| p.fixed).map(|p| p.name.as_str()).collect();
    if !fixed.is_empty() {
        writeln!(out, "base (fixed): {}", fixed.join(", "))?;
    } else {
        writeln!(out, "base: ground plane under the lowest point (up {})", r.up)?;
    }
    if !r.assembly_sequence.is_empty() {
        writeln!(out, "{:>4}  {:<width$}  motion (insertion, {})", "step", "part", r.units)?;
        for (k, step) in r.assembly_sequence.iter().enumerate() {
            let motion = match &step.motion {
                MotionEntry::Linear { direction: d, distance } => {
                    format!("straight along ({:+.3}, {:+.3}, {:+.3}) over {:.4}", d[0], d[1], d[2], distance)
                }
                MotionEntry::Path { poses, .. } => format!("path of {} poses", poses.len()),
            };
            writeln!(out, "{:>4}  {:<width$}  {motion}", k + 1, step.name)?;
        }
    }
    if !r.explanation.is_empty() {
        writeln!(out, "stuck with {} parts left; none can leave:", r.explanation.len())?;
        for e in &r.explanation {
            let others: Vec<&str> = e.parts.iter().map(|p| p.name.as_str()).collect();
            let why = match e.reason.as_str() {
                "blocked" => format!("blocked by {}", others.join(", ")),
                "unsupported" => format!("would leave {} unsupported", others.join(", ")),
                _ => "can leave, but every state after that is a dead end".into(),
            };
            writeln!(out, "  {:<width$}  {why}", e.name)?;
        }
    }
    if r.status == "budget_exhausted" {
        writeln!(out, "the budget ran out (--max-tests / --timeout) before a plan was found")?;
    }
    Ok(())
}
