#![doc = include_str!("../README.md")]

pub mod checker_extension;
pub mod dfs;
pub mod error;
pub mod exact;
pub mod grid;
pub mod hypervolume;
pub mod mcts;
pub mod mdp;
pub mod objective;
pub mod ordering;
pub mod pareto;
pub mod policy;
pub mod polish;
pub mod problem;
pub mod qgraph;
pub mod report;
pub mod search;

pub use checker_extension::CheckerExtension;
pub use dfs::Dfs;
pub use error::{Result, SearchError};
pub use mcts::Mcts;
pub use mdp::{ActionFilter, FilterCount, Mdp, MdpExtension, ModelContext, Verdict};
pub use objective::{Accessibility, DirHistory, DirectionChanges, Objective, PathLength, StepContext, StepKind};
pub use ordering::{Bookkeeping, BuiltinOrder, OrderingFactory, OrderingSource, PartOrdering, WithBookkeeping};
pub use pareto::ParetoMcts;
pub use policy::{EpsilonGreedy, Policy, PolicyContext, PolicyWorker, QFunction, QUse, QWorker, RandomPolicy};
pub use problem::{Budget, GroupMove, PlanOutcome, Problem, Progress, Stats, Status, Step, StopReason, Stuck, StuckReason, Subassembly};
pub use search::{EpisodeEnd, EpisodeHook, Next, SearchOutcome, SearchStats, SearchStatus, Solution, StopToken, Transition};

/// A planner: takes a problem apart within a budget. Every planner runs the same conformance
/// tests (`tests/conformance`).
pub trait Planner {
    /// A short name for reports.
    fn name(&self) -> &'static str;
    /// Searches for a disassembly sequence.
    fn solve(&self, problem: &Problem, budget: &Budget) -> PlanOutcome;
}
