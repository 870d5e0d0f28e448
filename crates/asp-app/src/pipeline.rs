//! The planning pipeline that the CLI and the Python package both call: load, then either the
//! feasibility pipeline — the declared list of stages (`stages.rs`: the voxel fast path,
//! the grid planner, the depth-first search, the grid fallback, the path planner) over a
//! checker source (the voxels, the collision world), the first answer that ends the run its
//! plan — or the optimiser's (distance maps → MCTS / Pareto-MCTS → report).
//!
//! Settings are in the model's units (as a user gives them) and validated here, with messages
//! that name the setting, not a command-line flag. Every step is also public on its own, so a
//! caller that plans many times on one model (data collection, benchmarks) builds the world once.

use crate::error::Result;
use crate::finish::world_result;
use crate::stage::{Decision, Run, Source};
use crate::stages::STAGES;
use asp_geom::Assembly;
use asp_search::{Budget, Progress};
use std::borrow::Cow;
use std::path::Path;
use std::sync::Arc;
use std::time::Instant;

pub use crate::optimise::{optimise, optimise_problem, optimiser_problem, OptimiserProblem};
pub use crate::setup::{
    budget, checker, checker_config, load, load_options, planner, world_config, OptimiseSettings, PlanResult, PlanSettings,
    StabilitySetting, DEFAULT_TIMEOUT,
};

/// Plans the model at `path`: [`load`], then [`plan_assembly`] (the load time in the report's
/// timings).
pub fn plan_file(path: &Path, settings: &PlanSettings, progress: Option<&(dyn Fn(&Progress) + Sync)>) -> Result<PlanResult> {
    let started = Instant::now();
    let assembly = load(path, settings)?;
    let load_seconds = started.elapsed().as_secs_f64();
    let mut result = plan_assembly(assembly, settings, progress)?;
    if let Some(t) = result.report.stats.timings.as_mut() {
        t.load = load_seconds;
    }
    Ok(result)
}

/// Plans `assembly`: a feasible sequence by the feasibility pipeline's stages, or, with
/// [`PlanSettings::optimise`], an optimised one.
pub fn plan_assembly(assembly: Assembly, settings: &PlanSettings, progress: Option<&(dyn Fn(&Progress) + Sync)>) -> Result<PlanResult> {
    if let Some(optimise) = &settings.optimise {
        return self::optimise(Arc::new(assembly), settings, optimise);
    }
    if settings.from_file {
        return crate::tree::plan(assembly, settings, progress, &plan_assembly);
    }
    Ok(feasible(assembly, settings, progress)?.0)
}

/// The feasibility pipeline on `assembly`: every stage of [`STAGES`] in order, and what
/// became of each.
pub(crate) fn feasible(
    assembly: Assembly,
    settings: &PlanSettings,
    progress: Option<&(dyn Fn(&Progress) + Sync)>,
) -> Result<(PlanResult, Vec<(&'static str, Decision)>)> {
    let budget = budget(settings)?;
    let mut run = Run::new(Cow::Owned(assembly), settings, &budget, progress)?;
    let result = match run.run(STAGES)? {
        Some(result) => result,
        None => world_result(&mut run, Some(&plan_core))?,
    };
    Ok((result, run.trace))
}

/// [`plan_assembly`]'s feasibility plan on the collision world, never by the voxel fast path
/// ([`plan_on_voxels`]): what the fast path must equal (`tests/voxel`), and the one plan of
/// every model the fast path declines.
pub fn plan_on_world(assembly: Assembly, settings: &PlanSettings, progress: Option<&(dyn Fn(&Progress) + Sync)>) -> Result<PlanResult> {
    let budget = budget(settings)?;
    let mut run = Run::new(Cow::Owned(assembly), settings, &budget, progress)?;
    match run.run(on(Source::World))? {
        Some(result) => Ok(result),
        None => world_result(&mut run, Some(&plan_core)),
    }
}

/// The voxel fast path alone (the stages on the voxels' source): when every part is a union of
/// boxes on one lattice ([`asp_geom::voxel::VoxelChecker`]) and the settings ask for nothing
/// it cannot answer (contact stability, no extension, no declared units, no precedence graph,
/// the grid planner not in play, an ordering that needs no world), the depth-first search on
/// the voxel checker, with no world built; its plan, when it is found and complete and asked
/// for nothing of the world (the path planner, a subassembly's own plan); otherwise `None`, and
/// the caller plans on the world ([`plan_on_world`]; `tests/voxel` holds the two equal).
/// `budget` is [`budget`]'s of the settings.
pub fn plan_on_voxels(
    assembly: &Assembly,
    settings: &PlanSettings,
    budget: &Budget,
    progress: Option<&(dyn Fn(&Progress) + Sync)>,
) -> Result<Option<PlanResult>> {
    Run::new(Cow::Borrowed(assembly), settings, budget, progress)?.run(on(Source::Voxels))
}

/// The stages on `source`, in the list's order.
fn on(source: Source) -> impl Iterator<Item = &'static crate::stage::Stage> {
    STAGES.iter().filter(move |s| s.source == source)
}

/// A locked core of a plan planned as a model of its own ([`crate::cores`]): `assembly` holds
/// its parts, its base fixed; the declared units that lie wholly in it are kept. It is planned
/// on the world, and its own cores are not planned alone again.
fn plan_core(assembly: Assembly, settings: &PlanSettings, budget: Budget) -> Result<PlanResult> {
    let names: Vec<&str> = assembly.parts.iter().map(|p| p.name.as_str()).collect();
    let groups: Vec<Vec<String>> = settings.unit_groups.iter().filter(|g| g.iter().all(|n| names.contains(&n.as_str()))).cloned().collect();
    let settings = PlanSettings { unit_groups: groups, ..settings.clone() };
    let mut run = Run::new(Cow::Owned(assembly), &settings, &budget, None)?;
    match run.run(on(Source::World))? {
        Some(result) => Ok(result),
        None => world_result(&mut run, None),
    }
}
