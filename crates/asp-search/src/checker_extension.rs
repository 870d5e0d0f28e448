//! The feasibility search's seam for decorating checkers (a robot that must also carry each
//! removal out, a second gripper): an extension builds its checker on the collision world's and
//! describes the outcome's steps. The composition crate (asp-app) chooses the extension; the
//! crates that implement it (asp-robot) depend only on this trait.

use crate::error::Result;
use crate::problem::PlanOutcome;
use crate::report::ExtensionReport;
use asp_geom::Checker;

/// Decorates the feasibility planner's checker: [`CheckerExtension::solve`] builds its
/// checker on the collision-world checker, lets the search run on it, and describes the
/// outcome's steps (a robot's grasps and paths).
pub trait CheckerExtension: Send + Sync + std::fmt::Debug {
    /// Builds the decorated checker on `checker`, calls `search` with it (any [`crate::Planner`]
    /// on a problem of that checker), and returns the search's outcome with the extension's
    /// report (or `None`); an error of the search is returned as it is.
    fn solve(
        &self,
        checker: &Checker,
        seed: u64,
        search: &mut dyn FnMut(&dyn asp_geom::FeasibilityChecker) -> Result<PlanOutcome>,
    ) -> Result<(PlanOutcome, Option<ExtensionReport>)>;

    /// Whether the decorated checker has a robot arm check every removal (the run's removals
    /// are then the robot checker's, whose labels a removability model must be trained on).
    fn checks_arm(&self) -> bool {
        false
    }
}
