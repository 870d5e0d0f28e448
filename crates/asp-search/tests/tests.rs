//! Integration tests of asp-search (one binary; modules in subfolders).

use asp_check::{fixtures, verify};

mod conformance;
mod exact;
mod fasteners;
mod grid;
mod groups;
mod hypervolume;
mod mcts;
mod objectives;
mod pareto;
mod qgraph;
mod real;
mod seams;
