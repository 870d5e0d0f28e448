//! Why each locked core of a feasibility plan is locked (`locked_cores[].why`, plan format 1.9):
//! the geometry's part comes from the plan's own collision world
//! ([`CoreWhy::of`]); what the pipeline knows is added here — whether the grid planner ran, and
//! the core's own plan rerun under `--overlaps lenient`.

use crate::setup::{checker_config, planner, PlanSettings};
use asp_geom::grid::VoxelModel;
use asp_geom::{Assembly, Checker, FeasibilityChecker, PartSet, World};
use asp_search::grid::solver::GridPlan;
use asp_search::report::{CoreGrid, CoreGridReason, CoreLenient, CoreWhy, LenientStatus, PlanReport};
use asp_search::units::UnitChecker;
use asp_search::{Budget, Problem, Status};
use std::time::{Duration, Instant};

/// The longest the lenient reruns of a plan's cores may take together, seconds (less when the
/// plan's own `timeout` is shorter); a rerun that finds the time spent ends `budget_exhausted`.
pub const LENIENT_SECONDS: f64 = 10.0;

/// The most parts the grid planner takes (as [`VoxelModel::of`]).
const GRID_MAX_PARTS: usize = 64;

/// How the grid planner ran on the model, if it did.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum GridRan {
    /// It did not run.
    No,
    /// It ran to the end of its search.
    Finished,
    /// Its state budget or the time ended it.
    Budget,
}

impl GridRan {
    /// How a grid search that ended in `plan` ran.
    pub(crate) fn of(plan: &GridPlan) -> GridRan {
        fn budget(p: &GridPlan) -> bool {
            p.status == Status::BudgetExhausted || p.steps.iter().any(|s| s.plan.as_deref().is_some_and(budget))
        }
        if budget(plan) {
            GridRan::Budget
        } else {
            GridRan::Finished
        }
    }
}

/// Adds `why` to every locked core of `report`, planned in `world` with `settings`.
pub(crate) fn explain_cores(report: &mut PlanReport, world: &World, settings: &PlanSettings, grid: GridRan, units: &[PartSet]) {
    if report.locked_cores.is_empty() {
        return;
    }
    let mut lenient_checker: Option<Option<Checker>> = None;
    let seconds = settings.timeout.map_or(LENIENT_SECONDS, |t| t.min(LENIENT_SECONDS)).max(0.0);
    let deadline = Instant::now() + Duration::from_secs_f64(seconds);
    let mut cores = std::mem::take(&mut report.locked_cores);
    for core in &mut cores {
        let grid = core_grid(world.assembly(), settings, grid, &core.parts);
        let mut lenient = |base: usize, parts: &[usize]| {
            let checker = lenient_checker.get_or_insert_with(|| lenient_world(world, settings));
            match checker {
                Some(c) => rerun(c, settings, base, parts, units, deadline),
                None => CoreLenient { status: LenientStatus::Unknown, frees: 0 },
            }
        };
        core.why = Some(CoreWhy::of(world, core.base, &core.parts, grid, &mut lenient));
    }
    report.locked_cores = cores;
}

/// Whether the grid planner ran on a core of `parts`, and why not.
fn core_grid(assembly: &Assembly, settings: &PlanSettings, ran: GridRan, parts: &[usize]) -> CoreGrid {
    let not_tried = |reason: CoreGridReason, core_on_grid: Option<bool>| CoreGrid { tried: false, reason, core_on_grid };
    match ran {
        GridRan::Finished => return CoreGrid { tried: true, reason: CoreGridReason::Stuck, core_on_grid: None },
        GridRan::Budget => return CoreGrid { tried: true, reason: CoreGridReason::Budget, core_on_grid: None },
        GridRan::No => {}
    }
    if !settings.grid {
        return not_tried(CoreGridReason::Off, None);
    }
    if settings.checker_extension.is_some() {
        return not_tried(CoreGridReason::Robot, None);
    }
    if !settings.unit_groups.is_empty() {
        return not_tried(CoreGridReason::UnitGroups, None);
    }
    let core_on_grid = Some(VoxelModel::of(&assembly.subset(parts)).is_some());
    if assembly.parts.len() > GRID_MAX_PARTS {
        not_tried(CoreGridReason::TooManyParts, core_on_grid)
    } else {
        not_tried(CoreGridReason::NotOnGrid, core_on_grid)
    }
}

/// The plan's collision world under the lenient overlap policy ([`World::lenient`]: the same
/// geometry, nothing measured again), and its checker; `None` if the checker's settings fail.
fn lenient_world(world: &World, settings: &PlanSettings) -> Option<Checker> {
    Some(Checker::new(world.lenient(), checker_config(settings).ok()?))
}

/// The core of `parts` planned on its `base` in the lenient `checker`, as the plan planned it
/// (the same ordering and seed, straight lines and subassemblies, no path planner).
fn rerun(checker: &Checker, settings: &PlanSettings, base: usize, parts: &[usize], units: &[PartSet], deadline: Instant) -> CoreLenient {
    let unknown = CoreLenient { status: LenientStatus::Unknown, frees: 0 };
    let n = checker.num_parts();
    let start = PartSet::from_indices(n + 1, parts.iter().copied().filter(|&p| p < n));
    let with_units = UnitChecker::new(checker, units.to_vec());
    let Some((b, sub)) = with_units.subassembly(&start) else { return unknown };
    let Ok(dfs) = planner(&PlanSettings { path_planner: false, ..settings.clone() }, checker.world()) else { return unknown };
    if b != base {
        return unknown; // the base is the largest part of the group, and so of its core
    }
    let left = deadline.saturating_duration_since(Instant::now());
    let budget = Budget { max_tests: settings.max_tests, timeout: Some(left), cancel: settings.cancel.clone(), ..Budget::default() };
    let plan = dfs.solve(&Problem { checker: &*sub, start, progress: None }, &budget);
    CoreLenient::of(&plan, parts.len())
}
