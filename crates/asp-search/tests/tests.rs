//! Integration tests of asp-search (one binary; modules in subfolders).

mod conformance;
mod exact;
mod fasteners;
mod fixtures;
mod grid;
mod groups;
mod hypervolume;
mod mcts;
mod objectives;
mod pareto;
mod qgraph;
mod real;
mod seams;
mod verify;
