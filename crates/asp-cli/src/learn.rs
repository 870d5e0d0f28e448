//! `asp collect removability`, `asp collect transitions` and `asp bench feasible`: learned
//! guidance's data and benchmarks (thesis chapters 3, 5 and 6). Flags in `flags::learn`.

use crate::flags::{BenchArgs, BenchKind, CollectArgs, CollectKind, FeasibleArgs, TransitionsArgs};
use crate::request::model_settings;
use anyhow::{bail, Context};
use asp_app::bench::{self, BenchRow, Method};
use asp_app::collect::{self, CollectSettings};
use asp_app::collect_q::{self, TransitionSettings, TransitionsModel};
use indicatif::{ProgressBar, ProgressStyle};
use std::io::{IsTerminal, Write};

/// Runs `asp collect`.
pub fn collect(args: &CollectArgs) -> anyhow::Result<std::process::ExitCode> {
    let a = match &args.kind {
        CollectKind::Removability(a) => a,
        CollectKind::Transitions(a) => return transitions(a),
    };
    let mut robot = crate::flags::Map::new();
    a.robot.put(&mut robot);
    let settings = CollectSettings {
        runs: a.runs,
        seed: a.seed,
        plan: model_settings(&a.load, robot)?,
        max_tests: Some(a.max_tests),
        timeout: Some(positive("timeout", a.timeout)?),
        ..CollectSettings::default()
    };
    if a.runs == 0 {
        bail!("--runs must be at least 1");
    }
    let models = collect::model_paths(&a.models)?;
    let tty = std::io::stderr().is_terminal();
    let total = models.len();
    let done = std::sync::atomic::AtomicUsize::new(0);
    let progress = |m: &collect::CollectedModel| {
        let k = done.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
        if tty {
            eprintln!("[{k}/{total}] {}: {} parts, {} states ({} of {} runs complete)", m.name, m.parts, m.states, m.runs_found, a.runs);
        }
    };
    let index = collect::collect(&models, &a.out, &settings, &progress)?;
    let states: usize = index.assemblies.iter().map(|m| m.states).sum();
    println!(
        "{}: {} models, {} labelled states, features {} ({} node, {} edge attributes)",
        a.out.display(),
        index.assemblies.len(),
        states,
        index.features,
        index.node_dim,
        index.edge_dim
    );
    Ok(std::process::ExitCode::SUCCESS)
}

/// Runs `asp collect transitions`.
fn transitions(a: &TransitionsArgs) -> anyhow::Result<std::process::ExitCode> {
    if a.max_transitions == 0 {
        bail!("--max-transitions must be at least 1");
    }
    let mut extra = crate::flags::Map::new();
    extra.insert("objective".into(), a.objective.clone().into());
    extra.insert("episodes".into(), a.episodes.into());
    if a.objective.split(',').filter(|n| !n.trim().is_empty()).count() > 1 {
        extra.insert("pareto".into(), true.into());
    }
    // the thesis' data: the vanilla search's transitions, without the default guidance's seeds
    extra.insert("q".into(), asp_app::catalogue::NO_Q.into());
    a.maps.put(&mut extra);
    a.robot.put(&mut extra);
    let mut plan = model_settings(&a.load, extra)?;
    let optimise = plan.optimise.take().context("--objective")?;
    let settings = TransitionSettings { seed: a.seed, plan, optimise, limit: a.max_transitions };
    let models = collect::model_paths(&a.models)?;
    let bar = if std::io::stderr().is_terminal() {
        let style =
            ProgressStyle::with_template("{bar:30} {pos}/{len} models {elapsed} {msg}").unwrap_or_else(|_| ProgressStyle::default_bar());
        ProgressBar::new(models.len() as u64).with_style(style)
    } else {
        ProgressBar::hidden()
    };
    let progress = |m: &TransitionsModel| {
        bar.set_message(format!("{}: {} transitions", m.name, m.transitions));
        bar.inc(1);
    };
    let index = collect_q::collect_transitions(&models, &a.out, &settings, &progress);
    bar.finish_and_clear();
    let index = index?;
    let transitions: usize = index.assemblies.iter().map(|m| m.transitions).sum();
    for m in index.assemblies.iter().filter(|m| m.capped) {
        eprintln!("warning: {}: recording stopped at --max-transitions {} before the search ended", m.model, a.max_transitions);
    }
    println!(
        "{}: {} models, {} transitions ({}), features {} ({} node, {} edge attributes)",
        a.out.display(),
        index.assemblies.len(),
        transitions,
        index.objectives.join(", "),
        index.features,
        index.node_dim,
        index.edge_dim
    );
    Ok(std::process::ExitCode::SUCCESS)
}

/// The methods of `asp bench feasible` for the model called `name`.
fn methods(args: &FeasibleArgs, name: &str, checker: asp_learn::Checker) -> anyhow::Result<Vec<Method>> {
    let model = match (&args.model, &args.models_dir) {
        (Some(m), _) => Some(m.clone()),
        (None, Some(dir)) => Some(dir.join(format!("{name}.onnx"))),
        (None, None) => None,
    };
    let list = args.methods.clone().unwrap_or_else(|| bench::default_methods(model.is_some()).to_string());
    bench::parse_methods(&list, model.as_deref(), checker).map_err(crate::request::cli_error).context("--methods")
}

/// Runs `asp bench`.
pub fn bench(args: &BenchArgs) -> anyhow::Result<std::process::ExitCode> {
    let a = match &args.kind {
        BenchKind::Feasible(a) => a,
        BenchKind::Mcts(a) => return crate::bench_mcts::run(a),
    };
    if a.orderings == 0 {
        bail!("--orderings must be at least 1");
    }
    let mut robot = crate::flags::Map::new();
    a.robot.put(&mut robot);
    let mut settings = model_settings(&a.load, robot)?;
    settings.max_tests = a.max_tests;
    settings.timeout = a.timeout.map(|t| positive("timeout", t)).transpose()?;
    let models = collect::model_paths(&a.models)?;
    let tty = std::io::stderr().is_terminal();
    let mut rows: Vec<BenchRow> = Vec::new();
    for (k, (path, name)) in models.iter().zip(collect::unique_names(&models)).enumerate() {
        if tty {
            eprintln!("[{}/{}] {}", k + 1, models.len(), path.display());
        }
        let methods = methods(a, &name, settings.label_checker())?;
        rows.extend(bench::bench_model(path, &name, &settings, &methods, a.orderings)?);
    }
    let mut stdout = std::io::stdout().lock();
    bench::write_table(&mut stdout, &rows)?;
    if let Some(path) = &a.json {
        let json = serde_json::to_string_pretty(&rows)?;
        collect::write_atomic(path, format!("{json}\n").as_bytes())
            .with_context(|| format!("{}: cannot write the benchmark rows", path.display()))?;
    }
    stdout.flush()?;
    Ok(std::process::ExitCode::SUCCESS)
}

/// `v` when it is a positive number, else an error naming `--name`.
pub(crate) fn positive(name: &str, v: f64) -> anyhow::Result<f64> {
    if v > 0.0 && v.is_finite() {
        Ok(v)
    } else {
        bail!("--{name} must be a positive number, got {v}")
    }
}
