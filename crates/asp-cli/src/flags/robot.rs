//! The flags of `asp robot` (`check`, `cell`).

use clap::{Args, Subcommand};
use std::path::PathBuf;

/// Flags of `asp robot`.
#[derive(Args, Debug)]
pub struct RobotArgs {
    /// What to do.
    #[command(subcommand)]
    pub action: RobotAction,
}

/// The robot actions.
#[derive(Subcommand, Debug)]
pub enum RobotAction {
    /// Joints, limits, reach and an FK/IK round-trip check of a URDF robot (exit 1 if the check fails).
    Check(CheckArgs),
    /// Which parts of a model the robot cell can take out on their own (the only part left
    /// besides the fixed ones): a reachable grasp, the lift and a path to the drop-off. A part
    /// that fails here fails in every state of a search. Exit 1 when some part fails.
    Cell(Box<CellArgs>),
}

/// Flags of `asp robot cell`.
#[derive(Args, Debug)]
pub struct CellArgs {
    /// The model (a glTF/GLB, OBJ or STL file, or a folder of part files).
    pub model: PathBuf,
    /// Write the check as JSON to this file (`-` for standard output) besides the table.
    #[arg(long, value_name = "FILE")]
    pub json: Option<PathBuf>,
    /// Seed of the path planner (as `asp plan --seed`).
    #[arg(long)]
    pub seed: Option<u64>,
    #[command(flatten)]
    #[allow(missing_docs)]
    pub load: super::ModelArgs,
    #[command(flatten)]
    #[allow(missing_docs)]
    pub robot: super::PlanRobotArgs,
}

/// Flags of `asp robot check`.
#[derive(Args, Debug)]
pub struct CheckArgs {
    /// The URDF file; the shipped Franka-Panda-like arm when omitted.
    pub urdf: Option<PathBuf>,
    /// The chain's base link (default: the root link).
    #[arg(long)]
    pub base_link: Option<String>,
    /// The chain's tool-centre link (default: a link named *tcp or *tool0, else the deepest leaf).
    #[arg(long)]
    pub tip_link: Option<String>,
    /// Random configurations sampled for the reach.
    #[arg(long, default_value_t = 5000)]
    pub samples: usize,
    /// Random configurations of the FK/IK round trip.
    #[arg(long, default_value_t = 100)]
    pub trials: usize,
    /// Seed of the sampled configurations and of the IK restarts.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Where the URDF's `package://NAME/` meshes lie (repeatable).
    #[arg(long, value_name = "NAME=DIR")]
    pub package_path: Vec<String>,
    /// Let the URDF name meshes outside its folder.
    #[arg(long)]
    pub allow_outside_files: bool,
}
