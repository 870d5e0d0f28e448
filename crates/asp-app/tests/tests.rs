//! Integration tests of asp-app (one binary; modules in subfolders).

#[path = "../../asp-search/tests/fixtures/mod.rs"]
#[allow(dead_code)]
mod fixtures;

mod collect;
mod pipeline;
mod request;
mod robot;
mod stepped;
mod transitions;
