//! Integration tests of asp-search (one binary; modules in subfolders).

mod exact;
mod fixtures;
mod hypervolume;
mod mcts;
mod objectives;
mod pareto;
