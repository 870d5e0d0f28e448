//! The flags of `asp plan`: the models and outputs, then every setting of the plan request
//! (loading and testing, the depth-first search, the optimiser, the robot).

use super::Map;
use super::ModelArgs;
use asp_app::request::{QUse, Support};
use clap::Args;
use std::path::PathBuf;

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
    /// Read the settings from a JSON file of plan-request keys (docs/plan-request.md); flags
    /// given on the command line win.
    #[arg(long, value_name = "FILE")]
    pub settings: Option<PathBuf>,
    /// Loading and testing.
    #[command(flatten)]
    pub load: ModelArgs,
    /// Part ordering of the depth-first search.
    #[arg(long, value_parser = super::order())]
    pub order: Option<String>,
    /// The removability model of `--order gnn` (ONNX, docs/learning.md) [default: the model
    /// shipped with asp, models/removability.onnx].
    #[arg(long, value_name = "FILE")]
    pub model: Option<PathBuf>,
    /// Bookkeeping on top of any ordering (implied by `--order bookkeeping`).
    #[arg(long)]
    pub bookkeeping: bool,
    /// Add the precedence graph of a found plan to the plan JSON: which steps must go in before
    /// which (blocking and, conservatively, support), the levels of steps that may go in in
    /// parallel and the critical path (docs/plan-format.md, "Precedence").
    #[arg(long)]
    pub precedence: bool,
    /// Also write the precedence graph as Graphviz DOT to this file (implies --precedence; one
    /// model only).
    #[arg(long, value_name = "FILE")]
    pub precedence_dot: Option<PathBuf>,
    /// Plan these parts (comma-separated names) as one part, on purpose: a purchased motor, a
    /// pressed-in bearing. The unit goes in whole and the plan is still `found`. Repeat for
    /// several units.
    #[arg(long, value_name = "NAME,NAME...")]
    pub unit_group: Vec<String>,
    /// Seed of every random choice (random order, path planner, optimisation).
    #[arg(long)]
    pub seed: Option<u64>,
    /// Stop the depth-first search after this many removal tests.
    #[arg(long)]
    pub max_tests: Option<u64>,
    /// Stop the depth-first search after this many seconds with the best partial plan (0: no
    /// limit; the optimiser's limit is --time-limit).
    #[arg(long)]
    pub timeout: Option<f64>,
    /// No progress bar, no warnings.
    #[arg(long, short)]
    pub quiet: bool,
    /// Optimisation (`--objective`): MCTS / Pareto-MCTS on distance maps.
    #[command(flatten)]
    pub optimise: OptimiseArgs,
    /// A robot that must carry every removal out (`--robot`, `--robot-base`, `--drop-off`).
    #[command(flatten)]
    pub robot: PlanRobotArgs,
}

/// Flags of `asp plan` that turn it into an optimiser.
#[derive(Args, Debug, Clone, Default)]
pub struct OptimiseArgs {
    /// Optimise the sequence for these objectives (comma-separated): `access` (accessibility
    /// of each part, thesis 6.15), `dirchange` (shared removal directions, fewer direction
    /// changes, 6.16), `pathlen` (straight-line removal path length, minimised), `robot-path`
    /// (the arm's path, with --robot). One objective runs MCTS; several need `--pareto`.
    #[arg(long, value_name = "LIST", help_heading = "Optimisation")]
    pub objective: Option<String>,
    /// Search the Pareto front of the objectives (Pareto-MCTS) and write every non-dominated
    /// sequence to `pareto_front`.
    #[arg(long, help_heading = "Optimisation")]
    pub pareto: bool,
    /// MCTS episodes (each walks from the assembled state to a complete sequence).
    #[arg(long, help_heading = "Optimisation")]
    pub episodes: Option<usize>,
    /// Search budget: MCTS iterations per step of an episode (the thesis uses 5).
    #[arg(long, help_heading = "Optimisation")]
    pub budget: Option<usize>,
    /// Threads, each growing its own tree [default: all cores]. The same seed and thread count
    /// give the same answer.
    #[arg(long, help_heading = "Optimisation")]
    pub threads: Option<usize>,
    /// Stop the search after this many seconds (the answer then depends on timing).
    #[arg(long, value_name = "SECONDS", help_heading = "Optimisation")]
    pub time_limit: Option<f64>,
    /// Write the hypervolume (Pareto) or best value over episodes and seconds as CSV.
    #[arg(long, value_name = "FILE", help_heading = "Optimisation")]
    pub trace: Option<PathBuf>,
    /// Exploration constant c of UCT / MOUCB.
    #[arg(long, help_heading = "Optimisation")]
    pub exploration: Option<f64>,
    /// Local search over the answer's sequences: block moves of 1-3 removals around every
    /// sequence the search finds, taking at most this share of the search's work (0: off).
    #[arg(long, value_name = "SHARE", help_heading = "Optimisation")]
    pub polish: Option<f64>,
    /// Distance map resolution N_M (odd, 3 to 15): N_M × N_M directions on the half sphere.
    #[arg(long, help_heading = "Optimisation")]
    pub resolution: Option<usize>,
    /// Cap d_max of the distance maps, model units [default: the model's diagonal].
    #[arg(long, help_heading = "Optimisation")]
    pub d_max: Option<f64>,
    /// The gravity check of the optimiser.
    #[arg(long, value_parser = super::choice::<Support>(), help_heading = "Optimisation")]
    pub support: Option<Support>,
    /// Learned Q-functions (ONNX, `python -m asp.train q`), one per objective in the order of
    /// `--objective` (comma-separated): rollouts take the removal with the largest Q-value
    /// (the product of the values for several objectives) instead of a random one, except with
    /// probability `--epsilon` (thesis 5.4.5, 6.4.4).
    #[arg(long, value_name = "MODELS", help_heading = "Optimisation")]
    pub q: Option<String>,
    /// The probability of a random removal in a rollout (or expansion) guided by `--q`.
    #[arg(long, help_heading = "Optimisation")]
    pub epsilon: Option<f64>,
    /// Where `--q` guides.
    #[arg(long, value_parser = super::choice::<QUse>(), help_heading = "Optimisation")]
    pub q_use: Option<QUse>,
}

/// The robot flags of `asp plan`.
#[derive(Args, Debug, Clone, Default)]
pub struct PlanRobotArgs {
    /// Plan for a robot arm: `panda` (the shipped Franka-Panda-like arm) or a URDF file. A part
    /// counts as removable only when the arm can grasp it, lift it 5 cm along its removal
    /// direction and carry it to the drop-off without collision (thesis 5.3).
    #[arg(long, value_name = "panda|FILE.urdf", help_heading = "Robot")]
    pub robot: Option<String>,
    /// The robot base's position `X,Y,Z` in model units (default: on the floor, 0.3 m in front of
    /// the model's -x side, centred on it).
    #[arg(long, value_name = "X,Y,Z", help_heading = "Robot")]
    pub robot_base: Option<String>,
    /// Where the gripper puts removed parts down, `X,Y,Z` in model units (default: 0.5 m to the
    /// robot's side, 0.4 m above the floor).
    #[arg(long, value_name = "X,Y,Z", help_heading = "Robot")]
    pub drop_off: Option<String>,
    /// `k`: path plans per grasp, the shortest kept (simulation steps of the optimiser plan once).
    #[arg(long, help_heading = "Robot")]
    pub replans: Option<usize>,
    /// Grippers in all: up to N-1 parts already in place may be held (by a second gripper or a
    /// fixture) while the next part goes in, so states that stand only while held are allowed
    /// (feasibility search only; the plan's steps say which parts are held).
    #[arg(long, value_name = "N", help_heading = "Robot")]
    pub grippers: Option<usize>,
    /// Where the URDF's `package://NAME/` meshes lie (repeatable).
    #[arg(long, value_name = "NAME=DIR", help_heading = "Robot")]
    pub package_path: Vec<String>,
}

impl PlanArgs {
    /// The request keys these flags set (model, search, optimiser and robot flags).
    pub fn put(&self, map: &mut Map) {
        self.load.put(map);
        put!(map, self, order, model, seed, max_tests, timeout);
        if self.bookkeeping {
            map.insert("bookkeeping".into(), true.into());
        }
        if self.precedence || self.precedence_dot.is_some() {
            map.insert("precedence".into(), true.into());
        }
        if !self.unit_group.is_empty() {
            map.insert("unit_group".into(), self.unit_group.clone().into());
        }
        self.optimise.put(map);
        self.robot.put(map);
    }
}

impl OptimiseArgs {
    /// The request keys these flags set.
    pub fn put(&self, map: &mut Map) {
        put!(
            map,
            self,
            objective,
            episodes,
            budget,
            threads,
            time_limit,
            exploration,
            polish,
            resolution,
            d_max,
            support,
            q,
            epsilon,
            q_use
        );
        if self.pareto {
            map.insert("pareto".into(), true.into());
        }
    }
}

impl PlanRobotArgs {
    /// The request keys these flags set.
    pub fn put(&self, map: &mut Map) {
        put!(map, self, robot, robot_base, drop_off, replans, grippers);
        if !self.package_path.is_empty() {
            map.insert("package_path".into(), self.package_path.clone().into());
        }
    }
}
