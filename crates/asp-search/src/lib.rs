#![doc = include_str!("../README.md")]

pub mod annotation;
pub mod checker_extension;
pub mod dead_end;
pub mod dfs;
pub mod error;
pub mod exact;
pub mod extension;
pub mod grid;
pub mod hypervolume;
pub mod mcts;
pub mod mdp;
pub mod objective;
pub mod ordering;
pub mod policy;
pub mod polish;
pub mod problem;
pub mod qcache;
pub mod qgraph;
pub mod report;
pub mod step;
pub mod units;
mod vocabulary;

pub use checker_extension::CheckerExtension;
pub use dfs::Dfs;
pub use error::{Result, SearchError};
pub use extension::{MdpExtension, ModelContext};
pub use mcts::{EpisodeEnd, EpisodeHook, MapPlanner, Mcts, Next, ParetoMcts, SearchOutcome, SearchStats, Solution, Transition};
pub use mdp::{ActionFilter, FilterCount, Mdp, Verdict};
pub use objective::{Accessibility, DirHistory, DirectionChanges, Objective, PathLength};
pub use ordering::{Bookkeeping, BuiltinOrder, OrderingFactory, OrderingSource, PartOrdering, WithBookkeeping};
pub use policy::{EpsilonGreedy, Policy, PolicyContext, PolicyWorker, QFunction, QUse, QWorker, RandomPolicy};
pub use problem::{
    Budget, GroupMove, PlanOutcome, Planner, Problem, Progress, Spent, Stats, Status, Step, StopReason, StopToken, Stuck, StuckReason,
    Subassembly,
};
pub use step::{StepContext, StepKind};
