//! The grid planner: interlocking voxel puzzles taken apart by moves of parts and groups on their
//! grid ([`solver`], the search; [`run`], its answer as a plan outcome for the pipeline). The
//! voxel model itself is geometry: `asp_geom::grid::VoxelModel`.

pub mod run;
pub mod solver;

pub use run::GridRun;
pub use solver::{solve, GridConfig, GridMove, GridPlan, GridSolution, GridStatus, GridStep, DIRECTIONS};
