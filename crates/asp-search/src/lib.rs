#![doc = include_str!("../README.md")]

pub mod error;
pub mod exact;
pub mod hypervolume;
pub mod mcts;
pub mod objective;
pub mod pareto;
pub mod policy;
pub mod mdp;
pub mod search;

pub use error::{Result, SearchError};
pub use mcts::Mcts;
pub use objective::{Accessibility, DirectionChanges, Memory, Objective, PathLength};
pub use pareto::ParetoMcts;
pub use policy::{EpsilonGreedy, Policy, QFunction, RandomPolicy};
pub use mdp::Mdp;
pub use search::{SearchOutcome, SearchStatus, Solution};
