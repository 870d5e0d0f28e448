#![doc = include_str!("../README.md")]

pub mod bench;
pub mod collect;
pub mod dfs;
pub mod error;
pub mod exact;
pub mod hypervolume;
pub mod mcts;
pub mod mdp;
pub mod objective;
pub mod ordering;
pub mod pareto;
pub mod pipeline;
pub mod policy;
pub mod problem;
pub mod report;
pub mod search;

pub use dfs::Dfs;
pub use error::{Result, SearchError};
pub use mcts::Mcts;
pub use mdp::Mdp;
pub use objective::{Accessibility, DirectionChanges, Memory, Objective, PathLength};
pub use ordering::{Bookkeeping, BuiltinOrder, OrderingFactory, OrderingSource, PartOrdering, WithBookkeeping};
pub use pareto::ParetoMcts;
pub use policy::{EpsilonGreedy, Policy, QFunction, RandomPolicy};
pub use problem::{Budget, PlanOutcome, Problem, Progress, Stats, Status, Step, Stuck, StuckReason};
pub use search::{SearchOutcome, SearchStatus, Solution};

/// A planner: takes a problem apart within a budget. Every planner runs the same conformance
/// tests (`tests/conformance`).
pub trait Planner {
    /// A short name for reports.
    fn name(&self) -> &'static str;
    /// Searches for a disassembly sequence.
    fn solve(&self, problem: &Problem, budget: &Budget) -> PlanOutcome;
}
