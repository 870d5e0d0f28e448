#![doc = include_str!("../README.md")]

pub mod assembly;
pub mod boxes;
pub mod checker;
pub mod distmap;
pub mod erode;
pub mod error;
pub mod fastener;
pub mod feasibility;
pub mod fits;
// test fixtures and puzzle models, public for the other crates' tests and examples
#[doc(hidden)]
pub mod fixtures;
pub mod graph;
pub mod grid;
pub mod io;
pub mod math;
pub mod mesh;
pub mod meta;
pub mod overlap;
pub mod partset;
pub mod physics;
#[doc(hidden)]
pub mod puzzles;
pub mod rrt;
pub mod sample;
pub mod seed;
pub mod surface;
pub mod sweep;
pub mod validate;
pub mod voxel;
pub mod world;

pub use assembly::{Assembly, Part, Units};
pub use checker::{Checker, CheckerConfig, StabilityMode};
pub use error::{GeomError, Result};
pub use feasibility::{CounterSnapshot, FeasibilityChecker, Motion, MotionKind, Outcome, Stability};
pub use graph::{AssemblyGraph, GraphConfig, StateGraph};
pub use mesh::Mesh;
pub use meta::{Grasp, PartMeta};
pub use overlap::OverlapPolicy;
pub use partset::PartSet;
pub use physics::{PhysicsConfig, PhysicsStability};
pub use world::{Bearing, RollingElement, World, WorldConfig};
