//! `asp plan`: load, plan, print the table, write the JSON.

use crate::flags::PlanArgs;
use anyhow::{bail, Context};
use asp_app::pipeline::{self, PlanSettings};
use asp_search::Progress;
use asp_search::{StopReason, StopToken};
use std::collections::BTreeSet;
use std::io::{IsTerminal, Write};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::OnceLock;
use std::time::{Duration, Instant};

/// The pipeline's settings of `asp plan`: the flags given, over the `--settings` file.
pub(crate) fn settings(args: &PlanArgs) -> anyhow::Result<PlanSettings> {
    let mut map = crate::flags::Map::new();
    args.put(&mut map);
    let request = crate::request::request(map, args.settings.as_deref())?;
    crate::request::resolve(&request)
}

/// How one model's run ended, worst last: the process exits with the worst.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
enum Verdict {
    Found,
    Partial,
    NotFound,
    Error,
    Interrupted,
}

impl Verdict {
    fn code(self) -> ExitCode {
        match self {
            Verdict::Found => ExitCode::SUCCESS,
            Verdict::Partial | Verdict::NotFound => ExitCode::from(1),
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
            let is_parts_folder =
                p.is_dir() && std::fs::read_dir(p).map(|d| d.filter_map(|e| e.ok()).any(|e| is_part(&e.path()))).unwrap_or(false);
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
    if many && args.precedence_dot.is_some() {
        bail!("--precedence-dot writes one model's graph: give one model");
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
    let mut counts = [0usize; 5];
    let mut stdout = std::io::stdout().lock();
    if args.json && many {
        writeln!(stdout, "[")?;
    }
    // The output file of each model, named in model order (as the serial loop named them).
    let outs: Vec<Option<PathBuf>> = models
        .iter()
        .map(|model| match &out_dir {
            Some(dir) => Some(dir.join(format!("{}.json", unique_stem(model, &mut names)))),
            None => args.out.clone(),
        })
        .collect();
    // Several models are planned in parallel (rayon over the models, the world's own parallel
    // loops nested inside), each into its own buffers; the buffers are printed in model order,
    // so the output's order and bytes are the serial loop's.
    let plan_buffered = |model: &PathBuf, out: &Option<PathBuf>| {
        let mut text = Vec::new();
        let mut warnings = Vec::new();
        let verdict = plan_one(args, &settings, model, out.as_deref(), &mut text, &mut warnings, many);
        (verdict, text, warnings)
    };
    let results: Vec<_> = if many {
        use rayon::prelude::*;
        models.par_iter().zip(outs.par_iter()).map(|(m, o)| plan_buffered(m, o)).collect()
    } else {
        models.iter().zip(&outs).map(|(m, o)| plan_buffered(m, o)).collect()
    };
    for (k, (verdict, text, warnings)) in results.into_iter().enumerate() {
        std::io::stderr().write_all(&warnings)?;
        let verdict = match verdict {
            Ok(v) => {
                if printed > 0 {
                    if args.json {
                        write!(stdout, ",")?;
                    } else {
                        writeln!(stdout)?;
                    }
                }
                stdout.write_all(&text)?;
                stdout.flush()?;
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
            "{} models in {:.2} s: {} found, {} partial, {} not found, {} errors{}",
            models.len(),
            started.elapsed().as_secs_f64(),
            counts[Verdict::Found as usize],
            counts[Verdict::Partial as usize],
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

/// Plans one model: prints its table (or JSON) to `stdout` and its warnings to `warnings`, and
/// writes its files. One of `many` models plans without a progress bar (they run in parallel).
fn plan_one(
    args: &PlanArgs,
    settings: &PlanSettings,
    model: &Path,
    out: Option<&Path>,
    stdout: &mut impl Write,
    warnings: &mut impl Write,
    many: bool,
) -> anyhow::Result<Verdict> {
    let load_started = Instant::now();
    let assembly = pipeline::load(model, settings)?;
    let load_seconds = load_started.elapsed().as_secs_f64();
    let for_mcap = args.mcap.as_ref().map(|_| assembly.clone());
    let bar = progress_bar(args.quiet || many || settings.optimise.is_some());
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
    let mut result = result.map_err(crate::request::cli_error)?;
    if let Some(t) = result.report.stats.timings.as_mut() {
        t.load = load_seconds;
    }
    let report = &result.report;
    if !args.quiet {
        for w in &report.warnings {
            writeln!(warnings, "warning: {}: {w}", model.display())?;
        }
    }
    if let (Some(path), Some(search)) = (&args.optimise.trace, &result.search) {
        asp_geom::io::write_atomic_with(path, |file| search.write_trace_csv(std::io::BufWriter::new(file)))
            .with_context(|| format!("{}: cannot write the trace", path.display()))?;
    }
    if let (Some(path), Some(assembly)) = (&args.mcap, &for_mcap) {
        asp_viz::mcap::write_plan(path, assembly, report)?;
    }
    if let (Some(path), Some(graph)) = (&args.precedence_dot, &report.precedence) {
        asp_geom::io::write_atomic(path, graph.to_dot().as_bytes())
            .with_context(|| format!("{}: cannot write the precedence graph", path.display()))?;
    }
    let json = report.to_json();
    if let Some(path) = out {
        asp_geom::io::write_atomic(path, json.as_bytes()).with_context(|| format!("{}: cannot write the plan", path.display()))?;
    }
    if args.json {
        write!(stdout, "{json}")?;
    } else {
        report.write_text(stdout)?;
    }
    // Ctrl-C during any search (the optimiser's too) ends with 130 after its result is written
    let interrupted =
        report.stats.stopped_by == Some(StopReason::Interrupted) || settings.cancel.as_ref().is_some_and(StopToken::is_stopped);
    Ok(if interrupted {
        Verdict::Interrupted
    } else if result.found() {
        Verdict::Found
    } else if report.status == asp_search::report::PlanStatus::Partial {
        Verdict::Partial
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
