//! `asp collect removability` and `asp bench feasible`, and the `--order` flag's orderings
//! (learned guidance, thesis chapter 3).

use crate::flags::{ModelArgs, OrderArg};
use anyhow::{bail, Context};
use asp_search::bench::{self, BenchRow, Method};
use asp_search::collect::{self, CollectSettings};
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
    let CollectKind::Removability(a) = &args.kind;
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
