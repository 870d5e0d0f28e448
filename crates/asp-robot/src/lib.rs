#![doc = include_str!("../README.md")]

pub mod checker;
pub mod convert;
pub mod error;
pub mod grasp;
pub mod ik;
pub mod removal;
pub mod reuse;
pub mod robot;
pub mod search;
pub mod shape;
pub mod spheres;

pub use checker::{HoldingChecker, RobotChecker};
pub use error::{Result, RobotError};
pub use grasp::{antipodal_grasps, grasps_from_meta, part_grasps, GraspConfig};
pub use ik::{IkConfig, IkOutcome, IkSolution};
pub use removal::{ArmCheck, PlanStats, RemovalConfig, RemovalPlanner, RobotCell, RobotFailure, RobotRemoval};
pub use reuse::PathStore;
pub use robot::{ChainSpec, Finger, Joint, JointKind, Link, Robot, RobotFiles};
pub use search::{CellSetup, RobotExtension, RobotSetup, ROBOT_PATH};
pub use shape::{LinkShape, ShapeKind};
pub use spheres::Sphere;

/// The URDF of the default robot (a Franka-Panda-like arm with a parallel gripper), embedded.
pub const PANDA_URDF: &str = include_str!("../robots/panda.urdf");
