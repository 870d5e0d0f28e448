//! What an extension ([`crate::extension::MdpExtension::describe`]: a robot, held parts) adds
//! to a plan: the robot's entry and, per removal, the robot's grasp and path and the parts held
//! in place. These are plan-format types (`docs/plan-format.md`; [`crate::report`] re-exports
//! them); they live apart from the report so that the extension seam does not depend on it.

use serde::{Deserialize, Serialize};

/// The robot a plan was made for. Since format 1.5.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct RobotEntry {
    /// The robot's name (the URDF's).
    pub name: String,
    /// The URDF file (or `<builtin panda>`).
    pub source: String,
    /// The base link's pose `[x, y, z, qx, qy, qz, qw]`, model units.
    pub base: [f64; 7],
    /// Where the tool centre puts removed parts down, model units.
    pub drop_off: [f64; 3],
    /// The joints' names, in the order of every `joint_trajectory` row.
    pub joints: Vec<String>,
    /// The sum of the steps' `path_length`, model units.
    pub total_path_length: f64,
}

/// How the robot takes one part out (in disassembly direction: from the grasp in the assembled
/// pose, lifted along the removal direction, to the drop-off; assembly runs it backwards).
/// Since format 1.5.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct RobotStepEntry {
    /// The grasp: the tool centre's pose `[x, y, z, qx, qy, qz, qw]` (z the approach, y the
    /// closing direction), model units.
    pub grasp: [f64; 7],
    /// The gripper's opening at the grasp, model units.
    pub grasp_width: f64,
    /// The tool centre's positions along the trajectory, model units.
    pub gripper_path: Vec<[f64; 3]>,
    /// Joint waypoints (radians / metres, in [`RobotEntry::joints`] order); the joints move
    /// linearly between consecutive rows.
    pub joint_trajectory: Vec<Vec<f64>>,
    /// The tool centre's travel (eq. 5.3), model units.
    pub path_length: f64,
}

/// What an extension (a robot, held parts) adds to a plan: the report-level entry and, per
/// removal of the plan outcome (removal order), the step's robot entry and held parts.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct RobotReport {
    /// The robot, if any.
    pub entry: Option<RobotEntry>,
    /// One per removal, in removal order (`None`: not planned for a robot).
    pub steps: Vec<Option<RobotStepEntry>>,
    /// One per removal, in removal order: the parts held in place while the rest stands
    /// without the removed part (empty: none); may be shorter than the removals.
    pub held: Vec<Vec<usize>>,
}
