#![doc = include_str!("../README.md")]

pub mod assembly;
pub mod error;
pub mod feasibility;
pub mod io;
pub mod math;
pub mod mesh;
pub mod partset;

pub use assembly::{Assembly, Part, Units};
pub use error::{GeomError, Result};
pub use feasibility::{FeasibilityChecker, Motion, MotionKind, Outcome, Stability};
pub use mesh::Mesh;
pub use partset::PartSet;
