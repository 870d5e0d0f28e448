#![doc = include_str!("../README.md")]

pub mod dfs;
pub mod error;
pub mod problem;
pub mod report;

pub use dfs::{Dfs, Ordering};
pub use error::{Result, SearchError};
pub use problem::{Budget, PlanOutcome, Problem, Progress, Stats, Status, Step, Stuck, StuckReason};

/// A planner: takes a problem apart within a budget. Every planner runs the same conformance
/// tests (`tests/conformance`).
pub trait Planner {
    /// A short name for reports.
    fn name(&self) -> &'static str;
    /// Searches for a disassembly sequence.
    fn solve(&self, problem: &Problem, budget: &Budget) -> PlanOutcome;
}
