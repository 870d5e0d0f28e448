//! The flags of `asp check`: the model, the sequence and the outputs, then the settings of the
//! removal tests (the same keys as `asp plan`'s).

use super::{Map, ModelArgs};
use clap::Args;
use std::path::PathBuf;

/// Flags of `asp check`.
#[derive(Args, Debug)]
pub struct CheckSeqArgs {
    /// The model (as `asp plan` takes it).
    #[arg(value_name = "MODEL")]
    pub model: PathBuf,
    /// The sequence: a text file of part names in assembly order, one step per line (`#`
    /// comments, `[a, b]` for a subassembly, an optional insertion direction after the name
    /// such as `-z` or `0,0,-1`; the part is removed the opposite way), or a plan JSON written
    /// by `asp plan --out` (docs/check-format.md).
    #[arg(value_name = "SEQUENCE")]
    pub sequence: PathBuf,
    /// Also write the check report as JSON to this file (docs/check-format.md).
    #[arg(long, value_name = "PATH")]
    pub out: Option<PathBuf>,
    /// Print the check report as JSON instead of text.
    #[arg(long)]
    pub json: bool,
    /// Read the settings from a JSON file of plan-request keys (docs/plan-request.md); flags
    /// given on the command line win.
    #[arg(long, value_name = "FILE")]
    pub settings: Option<PathBuf>,
    /// Loading and testing.
    #[command(flatten)]
    pub load: ModelArgs,
    /// Seed of the path planner (and the robot's).
    #[arg(long)]
    pub seed: Option<u64>,
    /// Stop the repair search after this many removal tests.
    #[arg(long)]
    pub max_tests: Option<u64>,
    /// Stop the repair search after this many seconds (0: no limit).
    #[arg(long)]
    pub timeout: Option<f64>,
    /// No warnings.
    #[arg(long, short)]
    pub quiet: bool,
    /// The robot that must carry every step out (as `asp plan --robot`).
    #[command(flatten)]
    pub robot: super::PlanRobotArgs,
}

impl CheckSeqArgs {
    /// The request keys these flags set.
    pub fn put(&self, map: &mut Map) {
        self.load.put(map);
        super::put!(map, self, seed, max_tests, timeout);
        self.robot.put(map);
    }
}
