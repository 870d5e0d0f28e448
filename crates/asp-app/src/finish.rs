//! A feasibility plan's report, from the answer that ends the pipeline's run: a grid search's
//! ([`grid_result`]) or, when no stage ended the run, the last depth-first search's
//! ([`outcome_result`]), each with what every plan on the world carries besides its steps (the
//! overlapping pairs, fits and bearings, the timings, the locked cores' why, the precedence
//! graph).

use crate::error::{AppError, Result};
use crate::setup::{PlanResult, PlanSettings, StabilitySetting};
use crate::stage::Run;
use crate::why::{explain_cores, GridRan};
use asp_geom::{Assembly, Checker, World};
use asp_search::grid::GridRun;
use asp_search::report::{GridEntry, GridReason, PlanReport, PrecedenceEntry, Timings};
use asp_search::{Budget, PlanOutcome, Status};

/// How one locked core is planned as a model of its own (the pipeline's; [`crate::cores`]).
pub(crate) type PlanCore<'a> = &'a dyn Fn(Assembly, &PlanSettings, Budget) -> Result<PlanResult>;

/// Where a feasibility plan's wall time went (loading is timed by the caller).
pub(crate) fn timings(outcome: &PlanOutcome, world_seconds: f64) -> Timings {
    Timings { load: 0.0, world: world_seconds, search: outcome.stats.seconds, path_planner: outcome.stats.path_planner_seconds }
}

/// The plan of `run`'s last depth-first search, when no stage ended the run: its extension's
/// report attached, then, with `plan_core`, the locked cores planned as models of their own
/// ([`crate::cores`]), their why and the precedence graph. `None` when no search ran.
pub(crate) fn outcome_result(run: &mut Run<'_>, plan_core: Option<PlanCore<'_>>) -> Result<Option<PlanResult>> {
    let Some((outcome, robot)) = run.outcome.take() else { return Ok(None) };
    let settings = run.settings;
    let (checker, world_seconds) = run.model.world(settings, &mut run.units)?;
    let world = checker.world();
    let mut report = PlanReport::new(world.assembly(), &outcome, world.shapes().tolerance(), world.warnings());
    if let Some(r) = robot {
        report.attach_robot(r);
    }
    finish_report(&mut report, world, &outcome, world_seconds);
    if let Some(plan_core) = plan_core {
        crate::cores::plan_cores_alone(&mut report, world.assembly(), settings, run.budget, run.started, plan_core)?;
    }
    explain_cores(&mut report, world, settings, run.grid_ran, &run.units);
    attach_precedence(&mut report, world, &outcome, settings);
    Ok(Some(PlanResult { report, status: outcome.status, search: None }))
}

/// [`outcome_result`], for a run on the world, whose depth-first search always runs.
pub(crate) fn world_result(run: &mut Run<'_>, plan_core: Option<PlanCore<'_>>) -> Result<PlanResult> {
    outcome_result(run, plan_core)?.ok_or_else(|| AppError::config("the pipeline ran no search on the world"))
}

/// The plan of a grid search (after the depth-first search's `before`, whose counters and time
/// it keeps).
pub(crate) fn grid_result(
    checker: &Checker,
    settings: &PlanSettings,
    run: &GridRun,
    reason: GridReason,
    before: Option<&PlanOutcome>,
    world_seconds: f64,
) -> PlanResult {
    let world = checker.world();
    let assembly = world.assembly();
    let mut outcome = run.outcome(assembly);
    if let Some(b) = before {
        outcome.stats.add_effort(&b.stats);
    }
    let mut report = PlanReport::new(assembly, &outcome, world.shapes().tolerance(), world.warnings());
    let u = |x: f32| assembly.units.from_metres(x as f64);
    let cell = run.model.cell;
    report.grid = Some(GridEntry {
        cell: [u(cell.x), u(cell.y), u(cell.z)],
        reason,
        states: run.solution.states,
        first_separation_moves: run.solution.first_separation_moves,
        seconds: run.solution.seconds,
    });
    finish_report(&mut report, world, &outcome, world_seconds);
    explain_cores(&mut report, world, settings, GridRan::of(&run.solution.plan), &[]);
    attach_precedence(&mut report, world, &outcome, settings);
    PlanResult { report, status: outcome.status, search: None }
}

/// What every feasibility plan's report on the world carries besides its steps: the
/// overlapping pairs and where the time went (loading is timed by the caller).
fn finish_report(report: &mut PlanReport, world: &World, outcome: &PlanOutcome, world_seconds: f64) {
    report.overlaps = asp_search::report::OverlapsEntry::of(world);
    report.fits = asp_search::report::FitEntry::of(world);
    report.bearings = asp_search::report::BearingEntry::of(world);
    report.components = asp_search::report::ComponentEntry::of(world);
    report.stats.timings = Some(timings(outcome, world_seconds));
}

/// With [`PlanSettings::precedence`], the precedence graph of a found plan (a warning says why
/// another plan has none).
fn attach_precedence(report: &mut PlanReport, world: &World, outcome: &PlanOutcome, settings: &PlanSettings) {
    if !settings.precedence {
        return;
    }
    let physics = matches!(settings.stability, StabilitySetting::Physics { .. });
    report.precedence = if outcome.status == Status::Found && report.status == asp_search::report::PlanStatus::Found {
        PrecedenceEntry::of(world, &outcome.removals, physics)
    } else {
        None
    };
    if report.precedence.is_none() {
        report
            .warnings
            .push(format!("precedence: no graph for a plan that is {} (found plans only, without grid moves)", report.status.as_str()));
    }
}
