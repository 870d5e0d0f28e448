//! `asp plan`: load, plan, print the table, write the JSON.

use crate::flags::{ModelArgs, OrderArg, PlanArgs, StabilityArg};
use anyhow::{bail, Context};
use asp_geom::math::Axis;
use asp_geom::Units;
use asp_search::pipeline::{self, PlanSettings, StabilitySetting};
use asp_search::report::{MotionEntry, PlanReport};
use asp_search::Progress;
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

/// The pipeline's loading and testing settings from the flags (flag names in the errors).
pub(crate) fn model_settings(args: &ModelArgs) -> anyhow::Result<PlanSettings> {
    let unit = match &args.unit {
        Some(u) => Some(Units::parse(u).with_context(|| format!("--unit: unknown unit '{u}' (use m, cm, mm, in, ft or a number of metres)"))?),
        None => None,
    };
    let up = match &args.up {
        Some(a) => Some(Axis::parse(a).with_context(|| format!("--up: '{a}' is not an axis (use x, y, z, -x, -y, -z)"))?),
        None => None,
    };
    let check = |name: &str, v: Option<f64>| v.map(|v| positive(name, v)).transpose();
    Ok(PlanSettings {
        unit,
        up,
        fixed: args.fixed.clone(),
        tolerance: check("tolerance", args.tolerance)?,
        contact_distance: check("contact-distance", args.contact_distance)?,
        normals: args.normals,
        sphere_directions: args.sphere_directions,
        ignore_overlapping: args.ignore_overlapping,
        stability: match args.stability {
            StabilityArg::Contact => StabilitySetting::Contact,
            StabilityArg::Physics => {
                StabilitySetting::Physics { threshold: positive("physics-threshold", args.physics_threshold)? }
            }
        },
        path_planner: !args.no_path_planner,
        rrt_iterations: args.rrt_iterations,
        rrt_time: positive("rrt-time", args.rrt_time)?,
        ..PlanSettings::default()
    })
}

/// The pipeline's settings of `asp plan`.
pub(crate) fn settings(args: &PlanArgs) -> anyhow::Result<PlanSettings> {
    let check = |name: &str, v: Option<f64>| v.map(|v| positive(name, v)).transpose();
    Ok(PlanSettings {
        order: crate::learn::order_source(args.order, args.onnx.as_deref())?,
        bookkeeping: args.bookkeeping || args.order == OrderArg::Bookkeeping,
        seed: args.seed,
        max_tests: args.max_tests,
        timeout: check("timeout", args.timeout)?,
        optimise: args.optimise.settings()?,
        ..model_settings(&args.load)?
    })
}

/// Runs `asp plan`.
pub fn plan(args: &PlanArgs) -> anyhow::Result<ExitCode> {
    let settings = settings(args)?;
    let assembly = pipeline::load(&args.model, &settings)?;
    let for_mcap = args.mcap.as_ref().map(|_| assembly.clone());
    let bar = progress_bar(args.quiet || settings.optimise.is_some());
    let report_progress = |p: &Progress| {
        if let Some(bar) = &bar {
            bar.set_length(p.total as u64);
            bar.set_position(p.removed as u64);
            bar.set_message(format!("{} tests", p.tests));
        }
    };
    let result = pipeline::plan_assembly(assembly, &settings, Some(&report_progress));
    if let Some(bar) = bar {
        bar.finish_and_clear();
    }
    let result = result?;
    let report = &result.report;
    if !args.quiet {
        for w in &report.warnings {
            eprintln!("warning: {}: {w}", args.model.display());
        }
    }
    if let (Some(path), Some(search)) = (&args.optimise.trace, &result.search) {
        let file = std::fs::File::create(path).with_context(|| format!("{}: cannot write the trace", path.display()))?;
        search
            .write_trace_csv(std::io::BufWriter::new(file))
            .with_context(|| format!("{}: cannot write the trace", path.display()))?;
    }
    if let (Some(path), Some(assembly)) = (&args.mcap, &for_mcap) {
        asp_viz::mcap::write_plan(path, assembly, report)?;
    }
    let json = report.to_json();
    if let Some(path) = &args.out {
        std::fs::write(path, &json).with_context(|| format!("{}: cannot write the plan", path.display()))?;
    }
    let mut stdout = std::io::stdout().lock();
    if args.json {
        write!(stdout, "{json}")?;
    } else {
        write_table(&mut stdout, report)?;
        if let Some(summary) = &report.optimisation {
            crate::optimise::write_summary(&mut stdout, summary, report.pareto_front.as_deref())?;
        }
    }
    Ok(if result.found() { ExitCode::SUCCESS } else { ExitCode::from(1) })
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
    let steps = |out: &mut dyn Write, sequence: &[asp_search::report::AssemblyStep]| -> std::io::Result<()> {
        writeln!(out, "{:>4}  {:<width$}  motion (insertion, {})", "step", "part", r.units)?;
        for (k, step) in sequence.iter().enumerate() {
            let motion = match &step.motion {
                MotionEntry::Linear { direction: d, distance } => {
                    format!("straight along ({:+.3}, {:+.3}, {:+.3}) over {:.4}", d[0], d[1], d[2], distance)
                }
                MotionEntry::Path { poses, .. } => format!("path of {} poses", poses.len()),
            };
            writeln!(out, "{:>4}  {:<width$}  {motion}", k + 1, step.name)?;
        }
        Ok(())
    };
    if !r.assembly_sequence.is_empty() {
        steps(out, &r.assembly_sequence)?;
    }
    if !r.partial_assembly_sequence.is_empty() {
        let remaining = r.remaining.as_ref().map_or(0, Vec::len);
        writeln!(
            out,
            "partial plan: {} parts come off; in assembly order onto the {remaining} parts that stay:",
            r.partial_assembly_sequence.len()
        )?;
        steps(out, &r.partial_assembly_sequence)?;
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
