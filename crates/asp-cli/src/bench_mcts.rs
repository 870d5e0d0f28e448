//! `asp bench mcts`: vanilla against Q-guided MCTS at equal wall time (thesis Fig. 6.6 / 6.7).
//! Flags in `flags::learn`; the benchmark is `asp_app::bench_mcts`.

use crate::flags::MctsArgs;
use anyhow::{bail, Context};
use asp_app::bench_mcts::{self, MctsRow, MctsSetting};
use asp_app::catalogue::{QPolicy, DEFAULT_EPSILON};
use asp_app::collect;
use std::io::{IsTerminal, Write};
use std::sync::Arc;

/// Runs `asp bench mcts`.
pub fn run(a: &MctsArgs) -> anyhow::Result<std::process::ExitCode> {
    if a.runs == 0 {
        bail!("--runs must be at least 1");
    }
    if a.threads == 0 {
        bail!("--threads must be at least 1");
    }
    let checkpoints: Vec<f64> = a
        .seconds
        .split(',')
        .map(|s| s.trim().parse::<f64>().with_context(|| format!("--seconds: '{s}' is not a number of seconds")))
        .collect::<anyhow::Result<_>>()?;
    if checkpoints.is_empty() || checkpoints.iter().any(|t| !(t.is_finite() && *t > 0.0)) || checkpoints.windows(2).any(|w| w[0] >= w[1]) {
        bail!("--seconds must list positive, increasing checkpoints, got {}", a.seconds);
    }
    let mut extra = crate::flags::Map::new();
    extra.insert("objective".into(), a.objective.clone().into());
    extra.insert("threads".into(), a.threads.into());
    if a.objective.split(',').filter(|n| !n.trim().is_empty()).count() > 1 {
        extra.insert("pareto".into(), true.into());
    }
    a.maps.put(&mut extra);
    let mut plan = crate::request::model_settings(&a.load, extra)?;
    let optimise = plan.optimise.take().context("--objective")?;
    let mut settings = Vec::new();
    for name in a.settings.split(',').map(str::trim).filter(|s| !s.is_empty()) {
        settings.push(match name {
            "vanilla" => MctsSetting::vanilla(),
            "pretrained" | "pretrained-expansions" | "pretrained-both" | "pretrained-priors" | "pretrained-seed" => {
                let Some(models) = &a.q else { bail!("--settings {}: {name} needs --q MODELS", a.settings) };
                let uses = match name {
                    "pretrained" => asp_search::QUse::Rollouts,
                    "pretrained-expansions" => asp_search::QUse::Expansions,
                    "pretrained-priors" => asp_search::QUse::Priors,
                    "pretrained-seed" => asp_search::QUse::Seed,
                    _ => asp_search::QUse::Both,
                };
                let paths: Vec<std::path::PathBuf> = models.split(',').map(str::trim).filter(|p| !p.is_empty()).map(Into::into).collect();
                let objectives: Vec<&str> = optimise.objectives.iter().map(String::as_str).collect();
                let policy = QPolicy::new(&paths, &objectives, a.epsilon.unwrap_or(DEFAULT_EPSILON), uses).map_err(crate::request::cli_error)?;
                MctsSetting { name: name.into(), policy: Arc::new(policy) }
            }
            "online" | "retrained" => bail!(
                "--settings: '{name}' trains the Q-functions during the search, which runs from Python: \
                 python -m asp.train bench-mcts {} --objective {} --settings {} --q MODELS --seconds {} (pip install ./py[train])",
                a.models.iter().map(|p| p.display().to_string()).collect::<Vec<_>>().join(" "),
                a.objective,
                a.settings,
                a.seconds
            ),
            other => bail!(
                "--settings: unknown setting '{other}' (vanilla, pretrained, pretrained-expansions, pretrained-both, pretrained-priors, pretrained-seed here; online and retrained from Python: python -m asp.train bench-mcts)"
            ),
        });
    }
    if settings.is_empty() {
        bail!("--settings names no setting");
    }
    let models = collect::model_paths(&a.models)?;
    let tty = std::io::stderr().is_terminal();
    let total = checkpoints.last().copied().unwrap_or(0.0) * (settings.len() * a.runs * models.len()) as f64;
    if tty {
        eprintln!("{} model(s) × {} setting(s) × {} run(s): about {total:.0} s", models.len(), settings.len(), a.runs);
    }
    let mut rows: Vec<MctsRow> = Vec::new();
    for (k, (path, name)) in models.iter().zip(collect::unique_names(&models)).enumerate() {
        if tty {
            eprintln!("[{}/{}] {}", k + 1, models.len(), path.display());
        }
        rows.extend(
            bench_mcts::bench_model(path, &name, &plan, &optimise, &settings, &checkpoints, a.runs).map_err(crate::request::cli_error)?,
        );
    }
    let mut stdout = std::io::stdout().lock();
    bench_mcts::write_table(&mut stdout, &rows)?;
    if let Some(path) = &a.json {
        let json = serde_json::to_string_pretty(&rows)?;
        collect::write_atomic(path, format!("{json}\n").as_bytes())
            .with_context(|| format!("{}: cannot write the benchmark rows", path.display()))?;
    }
    if let Some(path) = &a.csv {
        let csv = bench_mcts::csv(&rows);
        collect::write_atomic(path, csv.as_bytes()).with_context(|| format!("{}: cannot write the CSV", path.display()))?;
    }
    stdout.flush()?;
    Ok(std::process::ExitCode::SUCCESS)
}
