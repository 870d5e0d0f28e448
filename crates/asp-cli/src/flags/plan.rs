//! The flags of `asp plan`: the models and outputs, then every setting of the plan request
//! (loading and testing, the depth-first search, the optimiser, the robot).

use super::settings::{OptimiseGroup, RobotGroup, SearchGroup, SettingArgs};
use super::Map;
use super::ModelArgs;
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
    /// The feasibility search's settings (`--order`, `--seed`, `--timeout`, ...).
    #[command(flatten)]
    pub search: SettingArgs<SearchGroup>,
    /// Also write the precedence graph as Graphviz DOT to this file (implies --precedence; one
    /// model only).
    #[arg(long, value_name = "FILE")]
    pub precedence_dot: Option<PathBuf>,
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
    /// The optimiser's settings (`--objective`, `--episodes`, ...).
    #[command(flatten)]
    pub settings: SettingArgs<OptimiseGroup>,
    /// Write the hypervolume (Pareto) or best value over episodes and seconds as CSV.
    #[arg(long, value_name = "FILE", help_heading = "Optimisation")]
    pub trace: Option<PathBuf>,
}

/// The robot flags of `asp plan` (and of the commands that plan with a robot).
pub type PlanRobotArgs = SettingArgs<RobotGroup>;

impl PlanArgs {
    /// The request keys these flags set (model, search, optimiser and robot flags).
    pub fn put(&self, map: &mut Map) {
        self.load.put(map);
        self.search.put(map);
        if self.precedence_dot.is_some() {
            map.insert("precedence".into(), true.into());
        }
        self.optimise.settings.put(map);
        self.robot.put(map);
    }
}
