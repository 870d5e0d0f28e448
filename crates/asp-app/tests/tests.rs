//! Integration tests of asp-app (one binary; modules in subfolders).

use asp_check::{fixtures, verify};

mod check;
mod collect;
mod fuzz;
mod pipeline;
mod precedence;
mod request;
mod robot;
mod stepped;
mod stress;
mod transitions;
mod tree;
mod voxel;
