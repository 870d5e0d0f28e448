//! `asp bench mcts`: vanilla against Q-guided MCTS at equal wall time (thesis Fig. 6.6 / 6.7).
//! Flags and output only; the benchmark is `asp_search::bench_mcts`.

use crate::flags::ModelArgs;
use crate::optimise::SupportArg;
use anyhow::{bail, Context};
use asp_geom::distmap::Support;
use asp_search::bench_mcts::{self, MctsRow, MctsSetting};
use asp_search::collect;
use asp_search::pipeline::OptimiseSettings;
use asp_search::mcts::DEFAULT_BUDGET;
use clap::Args;
use std::io::{IsTerminal, Write};
use std::path::PathBuf;

/// Flags of `asp bench mcts`.
#[derive(Args, Debug)]
pub struct MctsArgs {
    /// Models: .glb/.gltf files, folders of them, or folders of OBJ/STL parts.
    #[arg(required = true)]
    pub models: Vec<PathBuf>,
    /// Objectives, comma-separated (several run Pareto-MCTS).
    #[arg(long, value_name = "LIST")]
    pub objective: String,
    /// Settings, comma-separated: `vanilla` (random rollouts), `pretrained` (ε-greedy
    /// rollouts on the `--q` models), `pretrained-expansions` (the `--q` models order the
    /// expansions, rollouts stay random) and `pretrained-both`.
    #[arg(long, value_name = "LIST", default_value = "vanilla,pretrained")]
    pub settings: String,
    /// Q models (ONNX), one per objective in `--objective`'s order, for `pretrained`.
    #[arg(long, value_name = "MODELS")]
    pub q: Option<String>,
    /// The probability of a random removal in a guided rollout.
    #[arg(long, default_value_t = 0.2)]
    pub epsilon: f64,
    /// Checkpoints, seconds, comma-separated and increasing; each run searches until the last.
    #[arg(long, value_name = "LIST", default_value = "1,2,5,10")]
    pub seconds: String,
    /// Runs per model and setting (seeds 0, 1, ...).
    #[arg(long, default_value_t = 3)]
    pub runs: usize,
    /// Search threads per run.
    #[arg(long, default_value_t = 1)]
    pub threads: usize,
    /// Search budget: MCTS iterations per step.
    #[arg(long, default_value_t = DEFAULT_BUDGET)]
    pub budget: usize,
    /// Exploration constant c of UCT / MOUCB.
    #[arg(long, default_value_t = std::f64::consts::FRAC_1_SQRT_2)]
    pub exploration: f64,
    /// The local search's share of each search's work (`asp plan --polish`; 0: off).
    #[arg(long, value_name = "SHARE", default_value_t = asp_search::mcts::DEFAULT_POLISH)]
    pub polish: f64,
    /// Distance map resolution N_M.
    #[arg(long, default_value_t = asp_geom::distmap::DEFAULT_RESOLUTION)]
    pub resolution: usize,
    /// Cap of the distance maps, model units (default: the model's diagonal).
    #[arg(long)]
    pub d_max: Option<f64>,
    /// The gravity check of the optimiser.
    #[arg(long, value_enum, default_value_t = SupportArg::Below)]
    pub support: SupportArg,
    /// Also write the rows as JSON.
    #[arg(long, value_name = "FILE")]
    pub json: Option<PathBuf>,
    /// Also write the rows as CSV (`model,setting,seconds,mean,std,episodes`).
    #[arg(long, value_name = "FILE")]
    pub csv: Option<PathBuf>,
    /// Loading.
    #[command(flatten)]
    pub load: ModelArgs,
}

/// Runs `asp bench mcts`.
pub fn run(a: &MctsArgs) -> anyhow::Result<std::process::ExitCode> {
    if a.runs == 0 {
        bail!("--runs must be at least 1");
    }
    if a.threads == 0 {
        bail!("--threads must be at least 1");
    }
    if !(0.0..=1.0).contains(&a.epsilon) {
        bail!("--epsilon must be in [0, 1], got {}", a.epsilon);
    }
    let checkpoints: Vec<f64> = a
        .seconds
        .split(',')
        .map(|s| s.trim().parse::<f64>().with_context(|| format!("--seconds: '{s}' is not a number of seconds")))
        .collect::<anyhow::Result<_>>()?;
    if checkpoints.is_empty() || checkpoints.iter().any(|t| !(t.is_finite() && *t > 0.0)) || checkpoints.windows(2).any(|w| w[0] >= w[1]) {
        bail!("--seconds must list positive, increasing checkpoints, got {}", a.seconds);
    }
    if let Some(d) = a.d_max {
        crate::output::positive("d-max", d)?;
    }
    let objectives: Vec<&str> = a.objective.split(',').map(str::trim).filter(|n| !n.is_empty()).collect();
    asp_search::extension::check_objective_names(&a.objective, &[]).context("--objective")?;
    let mut settings = Vec::new();
    for name in a.settings.split(',').map(str::trim).filter(|s| !s.is_empty()) {
        settings.push(match name {
            "vanilla" => MctsSetting::vanilla(),
            "pretrained" | "pretrained-expansions" | "pretrained-both" => {
                let Some(models) = &a.q else { bail!("--settings {}: {name} needs --q MODELS", a.settings) };
                let uses = match name {
                    "pretrained" => asp_search::QUse::Rollouts,
                    "pretrained-expansions" => asp_search::QUse::Expansions,
                    _ => asp_search::QUse::Both,
                };
                let paths: Vec<&str> = models.split(',').map(str::trim).filter(|p| !p.is_empty()).collect();
                let policy = asp_learn::epsilon_greedy(&paths, &objectives, a.epsilon, a.resolution * a.resolution, uses).context("--q")?;
                MctsSetting { name: name.into(), policy }
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
                "--settings: unknown setting '{other}' (vanilla, pretrained, pretrained-expansions, pretrained-both here; online and retrained from Python: python -m asp.train bench-mcts)"
            ),
        });
    }
    if settings.is_empty() {
        bail!("--settings names no setting");
    }
    let plan = crate::output::model_settings(&a.load)?;
    let optimise = OptimiseSettings {
        objectives: a.objective.clone(),
        pareto: objectives.len() > 1,
        budget: a.budget,
        threads: Some(a.threads),
        exploration: a.exploration,
        polish: a.polish,
        resolution: a.resolution,
        d_max: a.d_max,
        support: match a.support {
            SupportArg::Below => Support::Below,
            SupportArg::Contact => Support::ContactGraph,
        },
        ..OptimiseSettings::default()
    };
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
        rows.extend(bench_mcts::bench_model(path, &name, &plan, &optimise, &settings, &checkpoints, a.runs)?);
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
