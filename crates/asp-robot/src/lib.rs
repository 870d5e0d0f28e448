#![doc = include_str!("../README.md")]

pub mod convert;
pub mod error;
pub mod grasp;
pub mod ik;
pub mod robot;
pub mod shape;

pub use error::{Result, RobotError};
pub use grasp::{antipodal_grasps, grasps_from_meta, part_grasps, GraspConfig};
pub use ik::{IkConfig, IkOutcome, IkSolution};
pub use robot::{ChainSpec, Finger, Joint, JointKind, Link, Robot};
pub use shape::{LinkShape, ShapeKind};

/// The URDF of the default robot (a Franka-Panda-like arm with a parallel gripper), embedded.
pub const PANDA_URDF: &str = include_str!("../robots/panda.urdf");
