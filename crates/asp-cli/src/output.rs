//! `asp plan`: load, plan, print the table, write the JSON.

use crate::flags::{ModelArgs, OrderArg, OverlapsArg, PlanArgs, StabilityArg};
use anyhow::{bail, Context};
use asp_geom::math::Axis;
use asp_geom::Units;
use asp_search::pipeline::{self, PlanSettings, StabilitySetting};
use asp_search::report::{AssemblyStep, MotionEntry, PlanReport};
use asp_search::Progress;
use asp_search::{StopReason, StopToken};
use std::collections::BTreeSet;
use std::io::{IsTerminal, Write};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::{Arc, OnceLock};
use std::time::{Duration, Instant};

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
        overlaps: if args.ignore_overlapping {
            asp_geom::OverlapPolicy::Lenient
        } else {
            match args.overlaps {
                OverlapsArg::Strict => asp_geom::OverlapPolicy::Strict,
                OverlapsArg::Lenient => asp_geom::OverlapPolicy::Lenient,
                OverlapsArg::Error => asp_geom::OverlapPolicy::Error,
            }
        },
        stability: match args.stability {
            StabilityArg::Contact => StabilitySetting::Contact,
            StabilityArg::Physics => {
                StabilitySetting::Physics { threshold: positive("physics-threshold", args.physics_threshold)? }
            }
        },
        path_planner: !args.no_path_planner,
        subassemblies: !args.no_subassemblies,
        grid: !args.no_grid,
        rrt_iterations: args.rrt_iterations,
        rrt_time: positive("rrt-time", args.rrt_time)?,
        ..PlanSettings::default()
    })
}

/// The loaders' caps from `--max-triangles` / `--max-parts`.
pub(crate) fn limits(args: &ModelArgs) -> asp_geom::io::Limits {
    let defaults = asp_geom::io::Limits::default();
    asp_geom::io::Limits {
        max_triangles: args.max_triangles.unwrap_or(defaults.max_triangles),
        max_parts: args.max_parts.unwrap_or(defaults.max_parts),
    }
}

/// The pipeline's settings of `asp plan`.
pub(crate) fn settings(args: &PlanArgs) -> anyhow::Result<PlanSettings> {
    let timeout = match args.timeout {
        t if t == 0.0 => None,
        t => Some(positive("timeout", t)?),
    };
    let robot = crate::robot::setup(args)?;
    let extensions: Vec<Arc<dyn asp_search::MdpExtension>> = match &robot {
        Some(r) => vec![Arc::new(asp_robot::RobotExtension::new(r.clone())) as Arc<dyn asp_search::MdpExtension>],
        None => Vec::new(),
    };
    let optimise = args.optimise.settings(extensions)?;
    let grippers = args.robot.grippers;
    if grippers == 0 {
        bail!("--grippers must be at least 1");
    }
    if grippers > 1 && optimise.is_some() {
        bail!("--grippers works with the feasibility search only, not with --objective");
    }
    let checker_extension: Option<Arc<dyn asp_search::pipeline::CheckerExtension>> =
        if optimise.is_none() && (robot.is_some() || grippers > 1) {
            Some(Arc::new(asp_robot::CellSetup { robot: robot.clone(), grippers }) as Arc<dyn asp_search::pipeline::CheckerExtension>)
        } else {
            None
        };
    Ok(PlanSettings {
        order: crate::learn::order_source(args.order, args.onnx.as_deref())?,
        bookkeeping: args.bookkeeping || args.order == OrderArg::Bookkeeping,
        seed: args.seed,
        max_tests: args.max_tests,
        timeout,
        optimise,
        checker_extension,
        ..model_settings(&args.load)?
    })
}

/// How one model's run ended, worst last: the process exits with the worst.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
enum Verdict {
    Found,
    NotFound,
    Error,
    Interrupted,
}

impl Verdict {
    fn code(self) -> ExitCode {
        match self {
            Verdict::Found => ExitCode::SUCCESS,
            Verdict::NotFound => ExitCode::from(1),
            Verdict::Error => ExitCode::from(2),
            Verdict::Interrupted => ExitCode::from(130),
        }
    }
}

/// The Ctrl-C flag, set by the first Ctrl-C (the search then stops and its best result is
/// printed and written); a second Ctrl-C ends the process at once.
fn interrupt_flag() -> StopToken {
    static FLAG: OnceLock<StopToken> = OnceLock::new();
    FLAG.get_or_init(|| {
        let token = StopToken::new();
        let seen = token.clone();
        let installed = ctrlc::set_handler(move || {
            if seen.is_stopped() {
                std::process::exit(130);
            }
            seen.stop();
            eprintln!("interrupted: stopping the search, keeping the best result so far (Ctrl-C again to quit now)");
        });
        if let Err(e) = installed {
            eprintln!("warning: cannot catch Ctrl-C ({e}); it will end the process without output");
        }
        token
    })
    .clone()
}

/// The models to plan: the arguments, or with `--each` the models inside each argument folder.
fn models(args: &PlanArgs) -> anyhow::Result<Vec<PathBuf>> {
    if !args.each {
        return Ok(args.models.clone());
    }
    let mut models = Vec::new();
    for dir in &args.models {
        let entries = std::fs::read_dir(dir).with_context(|| format!("{}: cannot list the folder (--each)", dir.display()))?;
        let mut paths: Vec<PathBuf> = entries.filter_map(|e| e.ok().map(|e| e.path())).collect();
        paths.sort();
        let ext = |p: &Path| p.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
        let is_part = |p: &Path| p.is_file() && matches!(ext(p).as_deref(), Some("obj" | "stl"));
        let before = models.len();
        for p in &paths {
            let is_model_file = p.is_file() && matches!(ext(p).as_deref(), Some("glb" | "gltf"));
            let is_parts_folder = p.is_dir()
                && std::fs::read_dir(p).map(|d| d.filter_map(|e| e.ok()).any(|e| is_part(&e.path()))).unwrap_or(false);
            if is_model_file || is_parts_folder {
                models.push(p.clone());
            }
        }
        if models.len() == before {
            if paths.iter().any(|p| is_part(p)) {
                bail!("{}: holds .obj/.stl parts, so it is one model: plan it without --each", dir.display());
            }
            bail!("{}: no models in it (--each plans every .glb/.gltf file and every folder of .obj/.stl files)", dir.display());
        }
    }
    Ok(models)
}

/// Runs `asp plan` on every model: results per model, the exit code of the worst outcome.
pub fn plan(args: &PlanArgs) -> anyhow::Result<ExitCode> {
    let mut settings = settings(args)?;
    settings.cancel = Some(interrupt_flag());
    let models = models(args)?;
    let many = models.len() > 1;
    if many && args.mcap.is_some() {
        bail!("--mcap writes one model's plan: give one model");
    }
    if many && args.optimise.trace.is_some() {
        bail!("--trace writes one model's search: give one model");
    }
    let out_dir = match (&args.out, many) {
        (Some(dir), true) => {
            std::fs::create_dir_all(dir).with_context(|| format!("{}: cannot create the output folder", dir.display()))?;
            Some(dir.clone())
        }
        _ => None,
    };
    let started = Instant::now();
    let mut names = BTreeSet::new();
    let mut printed = 0;
    let mut worst = Verdict::Found;
    let mut counts = [0usize; 4];
    let mut stdout = std::io::stdout().lock();
    if args.json && many {
        writeln!(stdout, "[")?;
    }
    for (k, model) in models.iter().enumerate() {
        let out = match &out_dir {
            Some(dir) => Some(dir.join(format!("{}.json", unique_stem(model, &mut names)))),
            None => args.out.clone(),
        };
        let verdict = match plan_one(args, &settings, model, out.as_deref(), &mut stdout, printed > 0) {
            Ok(v) => {
                printed += 1;
                v
            }
            Err(e) => {
                eprintln!("error: {e:#}");
                Verdict::Error
            }
        };
        counts[verdict as usize] += 1;
        worst = worst.max(verdict);
        if verdict == Verdict::Interrupted {
            if k + 1 < models.len() {
                eprintln!("interrupted: {} models not planned", models.len() - k - 1);
            }
            break;
        }
    }
    if args.json && many {
        writeln!(stdout, "]")?;
    }
    if many && !args.quiet {
        eprintln!(
            "{} models in {:.2} s: {} found, {} not found, {} errors{}",
            models.len(),
            started.elapsed().as_secs_f64(),
            counts[Verdict::Found as usize],
            counts[Verdict::NotFound as usize],
            counts[Verdict::Error as usize],
            if worst == Verdict::Interrupted { ", interrupted" } else { "" }
        );
    }
    Ok(worst.code())
}

/// A file stem for `model`'s plan in an output folder, distinct from the stems given before.
fn unique_stem(model: &Path, taken: &mut BTreeSet<String>) -> String {
    let stem = model.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_else(|| "model".into());
    let mut name = stem.clone();
    let mut k = 2;
    while !taken.insert(name.clone()) {
        name = format!("{stem}-{k}");
        k += 1;
    }
    name
}

/// Plans one model: prints its table (or JSON) and writes its files.
fn plan_one(
    args: &PlanArgs,
    settings: &PlanSettings,
    model: &Path,
    out: Option<&Path>,
    stdout: &mut impl Write,
    separate: bool,
) -> anyhow::Result<Verdict> {
    let load_started = Instant::now();
    let assembly = pipeline::load_with(model, settings, args.load.allow_outside_files, limits(&args.load))?;
    let load_seconds = load_started.elapsed().as_secs_f64();
    let for_mcap = args.mcap.as_ref().map(|_| assembly.clone());
    let bar = progress_bar(args.quiet || settings.optimise.is_some());
    let report_progress = |p: &Progress| {
        if let Some(bar) = &bar {
            bar.set_length(p.total as u64);
            bar.set_position(p.removed as u64);
            bar.set_message(format!("{} tests", p.tests));
        }
    };
    let result = pipeline::plan_assembly(assembly, settings, Some(&report_progress));
    if let Some(bar) = bar {
        bar.finish_and_clear();
    }
    let mut result = result?;
    if let Some(t) = result.report.stats.timings.as_mut() {
        t.load = load_seconds;
    }
    let report = &result.report;
    if !args.quiet {
        for w in &report.warnings {
            eprintln!("warning: {}: {w}", model.display());
        }
    }
    if let (Some(path), Some(search)) = (&args.optimise.trace, &result.search) {
        asp_geom::io::write_atomic_with(path, |file| search.write_trace_csv(std::io::BufWriter::new(file)))
            .with_context(|| format!("{}: cannot write the trace", path.display()))?;
    }
    if let (Some(path), Some(assembly)) = (&args.mcap, &for_mcap) {
        asp_viz::mcap::write_plan(path, assembly, report)?;
    }
    let json = report.to_json();
    if let Some(path) = out {
        asp_geom::io::write_atomic(path, json.as_bytes()).with_context(|| format!("{}: cannot write the plan", path.display()))?;
    }
    if args.json {
        if separate {
            write!(stdout, ",")?;
        }
        write!(stdout, "{json}")?;
    } else {
        if separate {
            writeln!(stdout)?;
        }
        write_table(stdout, report)?;
        if let Some(summary) = &report.optimisation {
            crate::optimise::write_summary(stdout, summary, report.pareto_front.as_deref())?;
        }
    }
    stdout.flush()?;
    // Ctrl-C during any search (the optimiser's too) ends with 130 after its result is written
    let interrupted = report.stats.stopped_by.as_deref() == Some(StopReason::Interrupted.as_str())
        || settings.cancel.as_ref().is_some_and(StopToken::is_stopped);
    Ok(if interrupted {
        Verdict::Interrupted
    } else if result.found() {
        Verdict::Found
    } else {
        Verdict::NotFound
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
    } else if r.grid.is_some() {
        writeln!(out, "base: none (taken apart in the hand, no gravity; the last part goes down first along -{})", r.up.trim_start_matches(['+', '-']))?;
    } else {
        writeln!(out, "base: ground plane under the lowest point (up {})", r.up)?;
    }
    if let Some(g) = &r.grid {
        let first = g.first_separation_moves.map_or("-".to_string(), |m| m.to_string());
        writeln!(
            out,
            "grid plan ({}): cells of {:.4} x {:.4} x {:.4} {}, {} states in {:.3} s, {first} moves before the first separation",
            g.reason.replace('_', " "),
            g.cell[0],
            g.cell[1],
            g.cell[2],
            r.units,
            g.states,
            g.seconds
        )?;
    }
    if let Some(o) = &r.overlaps {
        writeln!(out, "overlapping in the input ({} pairs, policy {}):", o.pairs.len(), o.policy)?;
        for p in &o.pairs {
            let bound = if p.gross { "more than " } else { "" };
            writeln!(out, "  {} / {}: {}, {bound}{:.4} deep, {}", p.names[0], p.names[1], p.kind, p.depth, p.handling)?;
        }
    }
    if !r.assembly_sequence.is_empty() {
        write_steps(out, r, &r.assembly_sequence, width, "")?;
    }
    if !r.partial_assembly_sequence.is_empty() {
        let remaining = r.remaining.as_ref().map_or(0, Vec::len);
        writeln!(
            out,
            "partial plan: {} steps; in assembly order onto the {remaining} parts that stay:",
            r.partial_assembly_sequence.len()
        )?;
        write_steps(out, r, &r.partial_assembly_sequence, width, "")?;
    }
    if let Some(robot) = &r.robot {
        writeln!(out, "robot {}: total path length {:.3} {}", robot.name, robot.total_path_length, r.units)?;
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
        match r.stats.stopped_by.as_deref() {
            Some("interrupted") => writeln!(out, "interrupted (Ctrl-C) before a plan was found; the best partial plan so far is above")?,
            _ => writeln!(out, "the budget ran out (--max-tests / --timeout) before a plan was found")?,
        }
    }
    Ok(())
}

/// Assembly steps as table rows; a subassembly's own steps follow it, indented.
fn write_steps(out: &mut dyn Write, r: &PlanReport, sequence: &[AssemblyStep], width: usize, indent: &str) -> std::io::Result<()> {
    let name = |i: usize| r.parts.get(i).map_or("?", |p| p.name.as_str());
    let label = |step: &AssemblyStep| match &step.subassembly {
        None => step.name.clone(),
        Some(g) => format!("{} + {} more (subassembly)", step.name, g.parts.len() - 1),
    };
    let width = sequence.iter().map(|s| label(s).len()).fold(width, usize::max);
    if indent.is_empty() {
        writeln!(out, "{:>4}  {:<width$}  motion (insertion, {})", "step", "part", r.units)?;
    }
    for (k, step) in sequence.iter().enumerate() {
        let motion = match &step.motion {
            MotionEntry::Linear { direction: d, distance } => {
                format!("straight along ({:+.3}, {:+.3}, {:+.3}) over {:.4}", d[0], d[1], d[2], distance)
            }
            MotionEntry::Path { poses, .. } => format!("path of {} poses", poses.len()),
            MotionEntry::Screw { direction: d, distance, .. } => {
                format!("screw along ({:+.3}, {:+.3}, {:+.3}) over {:.4}", d[0], d[1], d[2], distance)
            }
        };
        let robot = step.robot.as_ref().map_or(String::new(), |rs| {
            format!("; robot path {:.3}", rs.path_length)
        });
        let robot = if step.held.is_empty() {
            robot
        } else {
            format!("{robot}; holding {}", step.held.iter().map(|&p| name(p)).collect::<Vec<_>>().join(", "))
        };
        writeln!(out, "{indent}{:>4}  {:<width$}  {motion}{robot}", k + 1, label(step))?;
        if let Some(g) = &step.subassembly {
            let inner = format!("{indent}      ");
            let members: Vec<&str> = g.parts.iter().map(|&p| name(p)).collect();
            let how = match g.status.as_str() {
                "found" => "built on its base in this order:".to_string(),
                "no_plan" => "cannot be taken apart (it goes in as one unit):".to_string(),
                "unplanned" => "not planned".to_string(),
                other => format!("{} before its own plan was found; the parts that come off:", other.replace('_', " ")),
            };
            writeln!(out, "{inner}subassembly {} on base {}: {how}", members.join(", "), step.name)?;
            write_steps(out, r, &g.assembly_sequence, width.saturating_sub(6), &inner)?;
            for e in &g.explanation {
                let others: Vec<&str> = e.parts.iter().map(|p| p.name.as_str()).collect();
                writeln!(out, "{inner}  {} {} {}", e.name, e.reason.replace('_', " "), others.join(", "))?;
            }
        }
        if !step.moves.is_empty() {
            writeln!(out, "{indent}      then {} moves:", step.moves.len())?;
        }
        for m in &step.moves {
            let t = m.translation;
            let parts: Vec<&str> = m.parts.iter().map(|&p| name(p)).collect();
            writeln!(out, "{indent}        move {} by ({:+.4}, {:+.4}, {:+.4})", parts.join(" + "), t[0], t[1], t[2])?;
        }
    }
    Ok(())
}
