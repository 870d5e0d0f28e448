//! What an extension ([`crate::extension::MdpExtension::describe`]: a robot, held parts) adds
//! to a plan: the robot's entry and, per removal, the robot's grasp and path and the parts held
//! in place. These are plan-format types (`docs/plan-format.md`; [`crate::report`] re-exports
//! them); they live apart from the report so that the extension seam does not depend on it.

use crate::vocabulary::vocabulary;
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
pub struct ExtensionReport {
    /// The robot, if any.
    pub entry: Option<RobotEntry>,
    /// One per removal, in removal order (`None`: not planned for a robot).
    pub steps: Vec<Option<RobotStepEntry>>,
    /// One per removal, in removal order: the parts held in place while the rest stands
    /// without the removed part (empty: none); may be shorter than the removals.
    pub held: Vec<Vec<usize>>,
}

/// Why a robot cannot take out a part that the geometry lets out (`explanation[].robot`,
/// format 1.9).
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct RobotRefusal {
    /// The robot's reason.
    pub reason: RobotReason,
    /// What the robot found, one line in words (grasps out of reach, colliding, ...).
    pub detail: String,
}

vocabulary! {
    /// Why a robot cannot take out a part the geometry lets out (`explanation[].robot.reason`;
    /// format 1.9).
    RobotReason {
        /// Lifting the part along its removal direction hits a part.
        BlockedLift => "blocked_lift",
        /// The part leaves only along a path of several moves; the robot lifts along a straight
        /// line.
        NoStraightLift => "no_straight_lift",
        /// No grasp of the part is reachable without collision (out of the arm's reach, or the
        /// gripper or arm collides there).
        NoReachableGrasp => "no_reachable_grasp",
        /// Grasps are reachable, but with none of them can the part be put down at the
        /// drop-off (its pose there is out of reach or collides).
        NoDropOff => "no_drop_off",
        /// Grasps are reachable and the part can be put down at the drop-off, but no
        /// collision-free joint path to it was found.
        NoPath => "no_path",
    }
}

impl RobotReason {
    /// The reason in words, for the text table and the viewer.
    pub fn words(self) -> &'static str {
        match self {
            RobotReason::BlockedLift => "blocked lift",
            RobotReason::NoStraightLift => "no straight lift",
            RobotReason::NoReachableGrasp => "no reachable grasp",
            RobotReason::NoDropOff => "cannot put it down at the drop-off",
            RobotReason::NoPath => "no path to the drop-off",
        }
    }
}
