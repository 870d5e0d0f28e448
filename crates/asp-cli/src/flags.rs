//! Command-line flags.

use clap::{Args, Parser, Subcommand, ValueEnum};
use std::path::PathBuf;

/// Plan in which order, and along which motions, a product can be put together.
#[derive(Parser, Debug)]
#[command(name = "asp", version, about, long_about = None)]
pub struct Cli {
    /// What to do.
    #[command(subcommand)]
    pub command: Command,
}

/// The subcommands.
#[derive(Subcommand, Debug)]
pub enum Command {
    /// Plan a feasible assembly sequence by taking the model apart (Assembly-by-Disassembly).
    Plan(PlanArgs),
    /// Generate training assemblies (Soma cubes, aluminium profile assemblies).
    Gen(crate::gen::GenArgs),
    /// Collect training data from planning runs (`removability`: labelled states; `transitions`:
    /// MCTS transitions for Q-functions; docs/learning.md).
    Collect(crate::learn::CollectArgs),
    /// Benchmarks (`feasible`: the thesis' Table 3.1 for a folder of models).
    Bench(crate::learn::BenchArgs),
    /// Write a self-contained HTML page that plays a plan step by step (three.js, offline).
    View(crate::view::ViewArgs),
    /// Render a plan's storyboard (PNG or SVG): one panel per step.
    Render(crate::view::RenderArgs),
    /// Plot the Pareto front of a plan JSON, or the search's progress from --trace CSVs.
    Plot(crate::plot::PlotArgs),
    /// Robots (`check`: joints, limits, reach and an FK/IK sanity check of a URDF).
    Robot(crate::robot::RobotArgs),
}

/// Part orderings of the depth-first search.
#[derive(Clone, Copy, Debug, ValueEnum, PartialEq, Eq)]
pub enum OrderArg {
    /// The model's part order.
    Given,
    /// One random order drawn from `--seed` at the start and kept (the thesis' vanilla AbD).
    Shuffled,
    /// A fresh random order in every state (from `--seed` and the state).
    Random,
    /// Given order with bookkeeping: a blocked part is retested only after a blocker is gone.
    Bookkeeping,
    /// Parts in order of the removability a graph neural network predicts (`--model`),
    /// predicted again after each removal (thesis 3.5.3).
    Gnn,
}

/// What to do with parts that overlap in the input (press fits, dowels, screws, slop).
#[derive(Clone, Copy, Debug, ValueEnum, PartialEq, Eq)]
pub enum OverlapsArg {
    /// An overlapping pair separates only along motions that enter no new material of each
    /// other (a dowel leaves along its axis, never sideways).
    Strict,
    /// Shrink one part of the pair in their tests; ignore pairs no shrinking separates.
    Lenient,
    /// Shrink small overlaps; stop with an error on pairs no shrinking separates.
    Error,
}

/// Stability criteria.
#[derive(Clone, Copy, Debug, ValueEnum, PartialEq, Eq)]
pub enum StabilityArg {
    /// Every part linked through contacts to a fixed part.
    Contact,
    /// Simulate what remains under gravity (rapier3d); unstable when a part moves more than
    /// `--physics-threshold`.
    Physics,
}

/// How a model is loaded and its removals tested: shared by `plan`, `collect` and `bench`.
#[derive(Args, Debug, Clone)]
pub struct ModelArgs {
    /// The unit of the model's coordinates: m, cm, mm, in, ft or metres per unit
    /// [default: m, or what the file says].
    #[arg(long)]
    pub unit: Option<String>,
    /// The up axis: x, y, z, -x, -y, -z [default: +y for glTF, +z for OBJ/STL, or what the file says].
    #[arg(long)]
    pub up: Option<String>,
    /// Base parts that stay in place (names). Without any, a ground plane under the lowest point
    /// is the base.
    #[arg(long, num_args = 1.., value_name = "NAME")]
    pub fixed: Vec<String>,
    /// Let the model (and a URDF) read files outside its folder: absolute paths, `..` that
    /// climbs out, symlinks that point out (docs/security.md).
    #[arg(long)]
    pub allow_outside_files: bool,
    /// Most triangles a model may have over all its parts [default: 20000000].
    #[arg(long, value_name = "N")]
    pub max_triangles: Option<usize>,
    /// Most parts a model may have [default: 10000].
    #[arg(long, value_name = "N")]
    pub max_parts: Option<usize>,
    /// Contact tolerance in model units: motions may push a part this deep into another
    /// [default: 1e-4 × the model's diagonal].
    #[arg(long)]
    pub tolerance: Option<f64>,
    /// Parts closer than this (model units) are in contact for stability [default: 1e-3 × diagonal].
    #[arg(long)]
    pub contact_distance: Option<f64>,
    /// Parts that overlap in the input (warned once per pair with the measured depth).
    #[arg(long, value_enum, default_value_t = OverlapsArg::Strict)]
    pub overlaps: OverlapsArg,
    /// Old spelling of `--overlaps lenient`.
    #[arg(long, hide = true)]
    pub ignore_overlapping: bool,
    /// Clustered surface-normal directions tried besides the six axes (each with its opposite).
    #[arg(long, default_value_t = 10)]
    pub normals: usize,
    /// Extra removal directions sampled evenly on the sphere.
    #[arg(long, default_value_t = 0)]
    pub sphere_directions: usize,
    /// Stability criterion.
    #[arg(long, value_enum, default_value_t = StabilityArg::Contact)]
    pub stability: StabilityArg,
    /// Physics stability: how far (fraction of the model's diagonal) a part may move in the
    /// simulation before the state counts as unstable.
    #[arg(long, default_value_t = 0.01)]
    pub physics_threshold: f64,
    /// Never call the path planner (straight lines only).
    #[arg(long)]
    pub no_path_planner: bool,
    /// Never let a group of parts leave together as one rigid subassembly (single parts only).
    #[arg(long)]
    pub no_subassemblies: bool,
    /// Never plan voxel models by grid moves (interlocking puzzles whose parts must slide in
    /// turn before anything can leave).
    #[arg(long)]
    pub no_grid: bool,
    /// Path planner iterations per call.
    #[arg(long, default_value_t = 2000)]
    pub rrt_iterations: usize,
    /// Path planner wall-time safety cap per call, seconds (the iteration budget keeps runs
    /// reproducible; this only guards against pathological models).
    #[arg(long, default_value_t = 5.0)]
    pub rrt_time: f64,
}

/// Flags of `asp plan`.
#[derive(Args, Debug)]
pub struct PlanArgs {
    /// The models: .glb/.gltf files, or folders of .obj/.stl files (one part per file, the
    /// folder is one model). Several models are planned one after another in one process.
    #[arg(required = true, num_args = 1.., value_name = "MODEL")]
    pub models: Vec<PathBuf>,
    /// Each MODEL is a folder of models: every .glb/.gltf file in it, and every subfolder of
    /// .obj/.stl files, is planned on its own.
    #[arg(long)]
    pub each: bool,
    /// Also write the plan as JSON to this file (format: docs/plan-format.md); with several
    /// models, a folder that gets one NAME.json per model.
    #[arg(long, value_name = "PATH")]
    pub out: Option<PathBuf>,
    /// Print the plan JSON on stdout instead of the table (with several models, a JSON array).
    #[arg(long)]
    pub json: bool,
    /// Also write the assembly animated over time as MCAP for Foxglove (docs/pictures.md; one
    /// model only).
    #[arg(long, value_name = "FILE")]
    pub mcap: Option<PathBuf>,
    /// Loading and testing.
    #[command(flatten)]
    pub load: ModelArgs,
    /// Part ordering of the depth-first search.
    #[arg(long, value_enum, default_value_t = OrderArg::Given)]
    pub order: OrderArg,
    /// The removability model of `--order gnn` (ONNX, docs/learning.md) [default: the model
    /// shipped with asp, models/removability.onnx].
    #[arg(long = "model", value_name = "FILE")]
    pub onnx: Option<PathBuf>,
    /// Bookkeeping on top of any ordering (implied by `--order bookkeeping`).
    #[arg(long)]
    pub bookkeeping: bool,
    /// Seed of every random choice (random order, path planner, optimisation).
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Stop after this many removal tests.
    #[arg(long)]
    pub max_tests: Option<u64>,
    /// Stop after this many seconds with the best partial plan (0: no limit).
    #[arg(long, default_value_t = asp_search::pipeline::DEFAULT_TIMEOUT)]
    pub timeout: f64,
    /// No progress bar, no warnings.
    #[arg(long, short)]
    pub quiet: bool,
    /// Optimisation (`--objective`): MCTS / Pareto-MCTS on distance maps.
    #[command(flatten)]
    pub optimise: crate::optimise::OptimiseArgs,
    /// A robot that must carry every removal out (`--robot`, `--robot-base`, `--drop-off`).
    #[command(flatten)]
    pub robot: crate::robot::PlanRobotArgs,
}

/// Parses the process arguments (exits with usage on error).
pub fn parse() -> Cli {
    Cli::parse()
}
