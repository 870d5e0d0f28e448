//! The flags of `asp collect` and `asp bench` (learned guidance, thesis chapters 3, 5 and 6).

use super::settings::{MapsGroup, SettingArgs};
use super::ModelArgs;
use clap::{Args, Subcommand};
use std::path::PathBuf;

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
    /// The objectives (comma-separated: access, dirchange, pathlen, robot-path with --robot);
    /// several run Pareto-MCTS.
    #[arg(long, value_name = "LIST")]
    pub objective: String,
    /// MCTS episodes per model (one search per model, one thread).
    #[arg(long, default_value_t = asp_app::collect_q::DEFAULT_EPISODES)]
    pub episodes: usize,
    /// Base seed (the search of model m uses a seed derived from it and m).
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// The optimiser's settings of the distance maps and the search (`--budget`, `--resolution`,
    /// ...), as on `asp plan`.
    #[command(flatten)]
    pub maps: SettingArgs<MapsGroup>,
    /// The most transitions recorded per model (its search goes on without recording beyond it).
    #[arg(long, default_value_t = asp_search::mcts::DEFAULT_RECORD_LIMIT)]
    pub max_transitions: usize,
    /// Loading and testing.
    #[command(flatten)]
    pub load: ModelArgs,
    /// A robot arm that must carry every removal out, as on `asp plan` (`--objective robot-path`
    /// needs one).
    #[command(flatten)]
    pub robot: super::PlanRobotArgs,
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
    /// A robot arm that must also take each part out: the labels of the robot checker, with
    /// the arm's reason for each part the geometry lets out and the arm does not.
    #[command(flatten)]
    pub robot: super::PlanRobotArgs,
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
    Mcts(MctsArgs),
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
    /// gnn, gnn+bk, auto (what `asp plan` orders with by default under the benchmark's checker)
    /// [default: vanilla,bk,random,random+bk, and gnn,gnn+bk when a model is given].
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
    /// A robot that must carry every removal out (Table 3.1 under the robot checker).
    #[command(flatten)]
    pub robot: super::PlanRobotArgs,
}

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
    /// expansions, rollouts stay random), `pretrained-both`, `pretrained-priors` (PUCT priors
    /// at expansions and a greedy seed of the local search, random rollouts) and
    /// `pretrained-seed` (greedy seeds only, then the vanilla search).
    #[arg(long, value_name = "LIST", default_value = "vanilla,pretrained")]
    pub settings: String,
    /// Q models (ONNX), one per objective in `--objective`'s order, for `pretrained`.
    #[arg(long, value_name = "MODELS")]
    pub q: Option<String>,
    /// The probability of a random removal in a guided rollout.
    #[arg(long)]
    pub epsilon: Option<f64>,
    /// Checkpoints, seconds, comma-separated and increasing; each run searches until the last.
    #[arg(long, value_name = "LIST", default_value = "1,2,5,10")]
    pub seconds: String,
    /// Runs per model and setting (seeds 0, 1, ...).
    #[arg(long, default_value_t = 3)]
    pub runs: usize,
    /// Search threads per run.
    #[arg(long, default_value_t = 1)]
    pub threads: usize,
    /// The optimiser's settings of the distance maps and the search (`--budget`, `--resolution`,
    /// ...), as on `asp plan`.
    #[command(flatten)]
    pub maps: SettingArgs<MapsGroup>,
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
