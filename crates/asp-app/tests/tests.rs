//! Integration tests of asp-app (one binary; modules in subfolders).

#[path = "../../asp-search/tests/fixtures/mod.rs"]
#[allow(dead_code)]
mod fixtures;
#[path = "../../asp-search/tests/verify/mod.rs"]
#[allow(dead_code)]
mod verify;

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
