#![doc = include_str!("../README.md")]

pub mod bench;
pub mod bench_mcts;
pub mod catalogue;
pub mod cell;
pub mod check;
pub mod collect;
pub mod collect_q;
mod cores;
pub mod error;
mod finish;
mod optimise;
pub mod pipeline;
pub mod request;
pub mod resolve;
pub mod settings;
mod setup;
mod stage;
mod stages;
pub mod stepped;
pub mod tree;
pub mod values;
pub mod why;

pub use catalogue::{PolicySource, QPolicy};
pub use error::{AppError, Result};
pub use pipeline::{OptimiseSettings, PlanResult, PlanSettings};
pub use request::PlanRequest;
pub use resolve::resolve;
pub use values::Choice;

use asp_search::{Progress, StopToken};
use std::path::Path;

/// What a caller hands a run besides its settings: a token that stops it from another thread
/// (Ctrl-C, a Python signal, a deadline) and a progress callback of the feasibility search.
#[derive(Default)]
pub struct Hooks<'a> {
    /// Stops the search with the best result so far.
    pub cancel: Option<StopToken>,
    /// Called as the depth-first search goes deeper.
    pub progress: Option<&'a (dyn Fn(&Progress) + Sync)>,
}

/// Plans the model at `path` as `request` asks: [`resolve()`], then the pipeline.
pub fn plan_file(path: &Path, request: &PlanRequest, hooks: Hooks<'_>) -> Result<PlanResult> {
    let mut settings = resolve(request)?;
    settings.cancel = hooks.cancel;
    pipeline::plan_file(path, &settings, hooks.progress)
}
