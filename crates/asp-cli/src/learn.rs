//! `asp collect removability`, `asp collect transitions` and `asp bench feasible`, and the
//! `--order` flag's orderings (learned guidance, thesis chapters 3, 5 and 6).

use crate::flags::{ModelArgs, OrderArg};
use anyhow::{bail, Context};
use asp_search::bench::{self, BenchRow, Method};
use crate::optimise::SupportArg;
use asp_geom::distmap::Support;
use asp_search::collect::{self, CollectSettings};
use asp_search::collect_q::{self, TransitionSettings, TransitionsModel};
use asp_search::extension::check_objective_names;
use asp_search::pipeline::OptimiseSettings;
use indicatif::{ProgressBar, ProgressStyle};
use asp_search::{BuiltinOrder, OrderingSource};
use clap::{Args, Subcommand};
use std::io::{IsTerminal, Write};
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// The ordering source of an `--order` value (`model` is the `--model` ONNX file for `gnn`).
pub fn order_source(order: OrderArg, model: Option<&Path>) -> anyhow::Result<Arc<dyn OrderingSource>> {
    if model.is_some() && order != OrderArg::Gnn {
        bail!("--model is the removability model of --order gnn; it has no effect with --order {order:?}");
    }
    Ok(match order {
        OrderArg::Given | OrderArg::Bookkeeping => Arc::new(BuiltinOrder::Given),
        OrderArg::Shuffled => Arc::new(BuiltinOrder::Shuffled),
        OrderArg::Random => Arc::new(BuiltinOrder::Random),
        OrderArg::Gnn => gnn_source(model)?,
    })
}

/// The learned ordering (`asp-learn`) with the model at `path`, or the shipped one.
fn gnn_source(path: Option<&Path>) -> anyhow::Result<Arc<dyn OrderingSource>> {
    Ok(Arc::new(match path {
        Some(p) => asp_learn::GnnSource::load(p, asp_geom::graph::GraphConfig::default())?,
        None => asp_learn::GnnSource::shipped()?,
    }))
}

/// `asp collect`.
#[derive(Args, Debug)]
pub struct CollectArgs {
    /// What to collect.
    #[command(subcommand)]
    pub kind: CollectKind,
}

/// What `asp collect` collects.
#[derive(Subcommand, Debug)]
pub enum CollectKind {
    /// Labelled states from vanilla DFS runs (thesis 3.6.1), the removability model's training
    /// data (format: docs/learning.md).
    Removability(RemovabilityArgs),
    /// Transitions (s, a, r, s') recorded by MCTS / Pareto-MCTS on distance maps (thesis 5.5.2,
    /// 6.5.1), the Q-functions' training data (format: docs/learning.md).
    Transitions(TransitionsArgs),
}

/// Flags of `asp collect transitions`.
#[derive(Args, Debug)]
pub struct TransitionsArgs {
    /// Models: .glb/.gltf files, folders of them (each file a model), or folders of OBJ/STL parts.
    #[arg(required = true)]
    pub models: Vec<PathBuf>,
    /// The data set folder to write.
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    /// The objectives (comma-separated: access, dirchange, pathlen); several run Pareto-MCTS.
    #[arg(long, value_name = "LIST")]
    pub objective: String,
    /// MCTS episodes per model (one search per model, one thread).
    #[arg(long, default_value_t = asp_search::collect_q::DEFAULT_EPISODES)]
    pub episodes: usize,
    /// Search budget: MCTS iterations per step of an episode (the thesis uses 5).
    #[arg(long, default_value_t = asp_search::mcts::DEFAULT_BUDGET)]
    pub budget: usize,
    /// Base seed (the search of model m uses a seed derived from it and m).
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Distance map resolution N_M (odd, 3 to 15): N_M × N_M directions on the half sphere.
    #[arg(long, default_value_t = asp_geom::distmap::DEFAULT_RESOLUTION)]
    pub resolution: usize,
    /// Cap d_max of the distance maps, model units [default: the model's diagonal].
    #[arg(long)]
    pub d_max: Option<f64>,
    /// The gravity check of the optimiser.
    #[arg(long, value_enum, default_value_t = SupportArg::Below)]
    pub support: SupportArg,
    /// The most transitions recorded per model (its search goes on without recording beyond it).
    #[arg(long, default_value_t = asp_search::mcts::DEFAULT_RECORD_LIMIT)]
    pub max_transitions: usize,
    /// Loading and testing.
    #[command(flatten)]
    pub load: ModelArgs,
}

/// Flags of `asp collect removability`.
#[derive(Args, Debug)]
pub struct RemovabilityArgs {
    /// Models: .glb/.gltf files, folders of them (each file a model), or folders of OBJ/STL parts.
    #[arg(required = true)]
    pub models: Vec<PathBuf>,
    /// The data set folder to write.
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    /// DFS runs per model, each from its own random initial ordering.
    #[arg(long, default_value_t = 20)]
    pub runs: usize,
    /// Base seed (run r of model m uses a seed derived from it).
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Removal tests per run before it stops (its states so far are kept). The default keeps
    /// one unlucky initial ordering, which can search hundreds of thousands of dead-end states,
    /// from swamping the data set.
    #[arg(long, default_value_t = 20_000)]
    pub max_tests: u64,
    /// Seconds per run before it stops (its states so far are kept; the data then depends on timing).
    #[arg(long, default_value_t = 60.0)]
    pub timeout: f64,
    /// Loading and testing.
    #[command(flatten)]
    pub load: ModelArgs,
}

/// `asp bench`.
#[derive(Args, Debug)]
pub struct BenchArgs {
    /// Which benchmark.
    #[command(subcommand)]
    pub kind: BenchKind,
}

/// The benchmarks.
#[derive(Subcommand, Debug)]
pub enum BenchKind {
    /// Time and removal tests of feasible planning under several orderings (thesis Table 3.1).
    Feasible(FeasibleArgs),
    /// The optimiser's hypervolume (or best value) over wall time, vanilla against guided by
    /// learned Q-functions (thesis Fig. 6.6 / 6.7).
    Mcts(crate::bench_mcts::MctsArgs),
}

/// Flags of `asp bench feasible`.
#[derive(Args, Debug)]
pub struct FeasibleArgs {
    /// Models: .glb/.gltf files, folders of them, or folders of OBJ/STL parts.
    #[arg(required = true)]
    pub models: Vec<PathBuf>,
    /// Initial orderings per method (run k of every method uses seed k).
    #[arg(long, default_value_t = 10)]
    pub orderings: usize,
    /// Methods, comma-separated: vanilla (shuffled), bk, random, random+bk, given, given+bk,
    /// gnn, gnn+bk [default: vanilla,bk,random,random+bk, and gnn,gnn+bk when a model is given].
    #[arg(long, value_name = "LIST")]
    pub methods: Option<String>,
    /// The removability model for the gnn methods.
    #[arg(long, value_name = "FILE")]
    pub model: Option<PathBuf>,
    /// Leave-one-out models: `DIR/<model name>.onnx` is used for each model (trained without it;
    /// `python -m asp.train removability --leave-one-out DIR`).
    #[arg(long, value_name = "DIR", conflicts_with = "model")]
    pub models_dir: Option<PathBuf>,
    /// Also write the rows as JSON.
    #[arg(long, value_name = "FILE")]
    pub json: Option<PathBuf>,
    /// Stop each run after this many removal tests.
    #[arg(long)]
    pub max_tests: Option<u64>,
    /// Stop each run after this many seconds.
    #[arg(long)]
    pub timeout: Option<f64>,
    /// Loading and testing.
    #[command(flatten)]
    pub load: ModelArgs,
}

/// Runs `asp collect`.
pub fn collect(args: &CollectArgs) -> anyhow::Result<std::process::ExitCode> {
    let a = match &args.kind {
        CollectKind::Removability(a) => a,
        CollectKind::Transitions(a) => return transitions(a),
    };
    let settings = CollectSettings {
        runs: a.runs,
        seed: a.seed,
        plan: crate::output::model_settings(&a.load)?,
        max_tests: Some(a.max_tests),
        timeout: Some(crate::output::positive("timeout", a.timeout)?),
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
            eprintln!(
                "[{k}/{total}] {}: {} parts, {} states ({} of {} runs complete)",
                m.name, m.parts, m.states, m.runs_found, a.runs
            );
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
    check_objective_names(&a.objective, &[]).context("--objective")?;
    if a.episodes == 0 {
        bail!("--episodes must be at least 1");
    }
    if a.budget == 0 {
        bail!("--budget must be at least 1");
    }
    if a.max_transitions == 0 {
        bail!("--max-transitions must be at least 1");
    }
    if let Some(d) = a.d_max {
        crate::output::positive("d-max", d)?;
    }
    let settings = TransitionSettings {
        seed: a.seed,
        plan: crate::output::model_settings(&a.load)?,
        optimise: OptimiseSettings {
            objectives: a.objective.clone(),
            episodes: a.episodes,
            budget: a.budget,
            resolution: a.resolution,
            d_max: a.d_max,
            support: match a.support {
                SupportArg::Below => Support::Below,
                SupportArg::Contact => Support::ContactGraph,
            },
            ..OptimiseSettings::default()
        },
        limit: a.max_transitions,
    };
    let models = collect::model_paths(&a.models)?;
    let bar = if std::io::stderr().is_terminal() {
        let style = ProgressStyle::with_template("{bar:30} {pos}/{len} models {elapsed} {msg}")
            .unwrap_or_else(|_| ProgressStyle::default_bar());
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
        eprintln!(
            "warning: {}: recording stopped at --max-transitions {} before the search ended",
            m.model, a.max_transitions
        );
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
fn methods(args: &FeasibleArgs, name: &str) -> anyhow::Result<Vec<Method>> {
    let model = match (&args.model, &args.models_dir) {
        (Some(m), _) => Some(m.clone()),
        (None, Some(dir)) => Some(dir.join(format!("{name}.onnx"))),
        (None, None) => None,
    };
    let list = args.methods.clone().unwrap_or_else(|| bench::default_methods(model.is_some()).to_string());
    bench::parse_methods(&list, &|| gnn_source(model.as_deref())).context("--methods")
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
    let mut settings = crate::output::model_settings(&a.load)?;
    settings.max_tests = a.max_tests;
    settings.timeout = a.timeout.map(|t| crate::output::positive("timeout", t)).transpose()?;
    let models = collect::model_paths(&a.models)?;
    let tty = std::io::stderr().is_terminal();
    let mut rows: Vec<BenchRow> = Vec::new();
    for (k, (path, name)) in models.iter().zip(collect::unique_names(&models)).enumerate() {
        if tty {
            eprintln!("[{}/{}] {}", k + 1, models.len(), path.display());
        }
        let methods = methods(a, &name)?;
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
