//! The grid planner: interlocking voxel puzzles taken apart by moves of parts and groups on their
//! grid ([`solver`], the search; [`run`], its answer as a plan outcome and the planner behind
//! [`crate::Planner`], [`GridPlanner`]). The
//! voxel model itself is geometry: `asp_geom::grid::VoxelModel`.

pub mod run;
pub mod solver;

pub use run::{GridPlanner, GridRun};
pub use solver::{solve, GridConfig, GridMove, GridPlan, GridSolution, GridStep, DIRECTIONS};
