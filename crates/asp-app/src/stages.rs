//! The feasibility pipeline as a declared list of stages ([`STAGES`]), and what each stage does.
//! The mechanism that runs the list is [`crate::stage`]; the entry points that run it on a
//! model are [`crate::pipeline`]'s. A new planner or checker backend is its implementation (in
//! its crate, behind [`asp_search::Planner`] or [`asp_geom::FeasibilityChecker`]) plus one entry
//! here: when it applies, how it runs (through [`search`], the one feasibility search), and
//! whether its answer ends the run.

use crate::error::Result;
use crate::finish::{grid_result, timings};
use crate::setup::{checker_config, dfs, planner, world_config, PlanResult, PlanSettings, StabilitySetting};
use crate::stage::{Applies, Next, Run, Source, Stage};
use crate::why::GridRan;
use asp_geom::voxel::VoxelChecker;
use asp_geom::{FeasibilityChecker, PartSet};
use asp_search::grid::{GridConfig, GridRun};
use asp_search::report::{GridReason, PlanReport};
use asp_search::units::UnitChecker;
use asp_search::{Budget, PlanOutcome, Planner, Problem, Progress, Status, StopToken, StuckReason};
use std::time::Instant;

/// The feasibility pipeline, in order. The voxel fast path first (no world built); then, on the
/// collision world, the grid planner when parts must move in turn before anything can leave,
/// the depth-first search (straight lines and groups; the path planner too unless the grid
/// comes before it), the grid plan as its fallback, and the depth-first search with the path
/// planner when neither straight lines nor grid moves took the model apart.
pub(crate) const STAGES: &[Stage] = &[
    Stage { name: "voxels", source: Source::Voxels, applies: voxels_apply, run: voxels },
    Stage { name: "grid-first", source: Source::World, applies: grid_first_applies, run: grid_first },
    Stage { name: "depth-first", source: Source::World, applies: |_| Applies::Yes, run: depth_first },
    Stage { name: "grid-fallback", source: Source::World, applies: grid_fallback_applies, run: grid_fallback },
    Stage { name: "path-planner", source: Source::World, applies: path_planner_applies, run: path_planner },
];

/// The fraction of the time budget the voxel fast path may spend before the world plans
/// (`1 / VOXEL_TIME_SHARE`).
const VOXEL_TIME_SHARE: u32 = 10;

/// The voxel fast path applies when the settings ask for nothing only the world answers, and
/// the grid planner is not in play (it plans voxel models on the world).
fn voxels_apply(run: &Run<'_>) -> Applies {
    let s = run.settings;
    if s.precedence {
        Applies::No("the precedence graph is drawn in the collision world")
    } else if !s.unit_groups.is_empty() {
        Applies::No("declared units are kept together on the collision world")
    } else if run.grid.is_ok() {
        Applies::No("the grid planner plans this voxel model, on the collision world")
    } else if s.checker_extension.is_some() {
        Applies::No("a robot checks its removals in the collision world")
    } else if !matches!(s.stability, StabilitySetting::Contact) {
        Applies::No("physics stability is simulated in the collision world")
    } else if s.order.prepare_without_world().is_none() {
        Applies::No("the ordering is prepared on the collision world")
    } else {
        Applies::Yes
    }
}

/// The voxel fast path: when every part is a union of boxes on one lattice ([`VoxelChecker`]),
/// the depth-first search runs on the voxel checker, which answers every removal test as the
/// collision world would, and no world is built. Its plan is the plan of the world's search,
/// so it ends the run only when it is complete and asked for nothing of the world (the path
/// planner, a subassembly's own plan); otherwise the world plans as if it had not run, at most
/// a tenth of the time later (`tests/voxel` holds the two equal).
fn voxels(run: &mut Run<'_>) -> Result<Next> {
    let settings = run.settings;
    let assembly = run.model.assembly()?;
    let Some(factory) = settings.order.prepare_without_world() else { return Ok(Next::Pass("the ordering needs the world")) };
    // the world's settings are checked as the world's path checks them
    let config = world_config(assembly, settings)?;
    checker_config(settings)?;
    let started = Instant::now();
    let Some(checker) = VoxelChecker::new(assembly, &config) else {
        return Ok(Next::Pass("the parts are no unions of boxes on one lattice"));
    };
    let world_seconds = started.elapsed().as_secs_f64();
    // the search stops as soon as it asks for the world (its plan would be discarded), and
    // gets a tenth of the time: a model it cannot answer in that is planned on the world with
    // the whole budget, as before, at most a tenth later
    let budget = run.budget;
    let abort = StopToken::new();
    let share = Budget { timeout: budget.timeout.map(|t| t / VOXEL_TIME_SHARE), cancel: Some(abort.clone()), ..budget.clone() };
    let progress = run.progress;
    let watch = |p: &Progress| {
        if checker.needs_world() || budget.cancel.as_ref().is_some_and(StopToken::is_stopped) {
            abort.stop();
        }
        if let Some(report) = progress {
            report(p);
        }
    };
    let outcome = search(&dfs(settings, factory), &checker, &[], Some(&watch), &share)?;
    if checker.needs_world() {
        return Ok(Next::Pass("the search asked for the world (the path planner or a subassembly's own plan)"));
    }
    if outcome.status != Status::Found {
        return Ok(Next::Pass("no plan of straight lines and groups"));
    }
    let mut report = PlanReport::new(assembly, &outcome, checker.tolerance(), checker.warnings());
    if !report.locked_cores.is_empty() {
        return Ok(Next::Pass("a subassembly it could not take apart"));
    }
    report.stats.timings = Some(timings(&outcome, world_seconds));
    Ok(Next::End(Box::new(PlanResult { report, status: outcome.status, search: None })))
}

/// The grid planner runs first on every model it plans (to probe whether it needs moves).
fn grid_first_applies(run: &Run<'_>) -> Applies {
    match run.grid {
        Ok(_) => Applies::Yes,
        Err(why) => Applies::No(why),
    }
}

/// The grid planner's probe (first separation only, a small budget), then the world; when parts
/// other than the one that then leaves must move first, the whole grid plan: found, it ends the
/// run (`grid.reason = needs_moves`); otherwise the fallback reuses it.
fn grid_first(run: &mut Run<'_>) -> Result<Next> {
    let Ok(model) = &run.grid else { return Ok(Next::Pass("no grid view")) };
    let probe = GridRun::probe(model.clone(), run.budget, run.started);
    let (checker, world_seconds) = run.model.world(run.settings, &mut run.units)?;
    if !probe.needs_moves() {
        return Ok(Next::Pass("the first separation needs no moves of other parts"));
    }
    let grid = GridRun::new(model.clone(), &GridConfig::default(), run.budget, run.started);
    if grid.found() {
        return Ok(Next::End(Box::new(grid_result(checker, run.settings, &grid, GridReason::NeedsMoves, None, world_seconds))));
    }
    run.grid_run = Some(grid);
    Ok(Next::Pass("the grid plan does not take the model apart"))
}

/// The depth-first search on the world (straight lines and groups; the path planner too, unless
/// the grid planner runs: on a voxel model the grid's moves come before the path planner).
fn depth_first(run: &mut Run<'_>) -> Result<Next> {
    let path_planner = run.settings.path_planner && run.grid.is_err();
    search_world(run, path_planner)?;
    Ok(Next::Pass("its plan is the answer unless a later stage finds a better one"))
}

/// The grid plan when the depth-first search found no plan, or one with a subassembly it could
/// not take apart (a voxel puzzle lifted off the ground in one piece); not when only gravity
/// stopped it (the grid plan does not test gravity).
fn grid_fallback_applies(run: &Run<'_>) -> Applies {
    let Err(why) = &run.grid else {
        return match &run.outcome {
            None => Applies::No("no depth-first search ran before it"),
            Some((outcome, _)) => wants_grid(outcome),
        };
    };
    Applies::No(why)
}

/// Whether a depth-first outcome wants the grid plan, and why not.
fn wants_grid(outcome: &PlanOutcome) -> Applies {
    let found = outcome.status == Status::Found;
    let gravity_only = matches!(&outcome.status, Status::NoPlan { stuck, .. }
        if !stuck.is_empty() && stuck.iter().all(|s| matches!(s.reason, StuckReason::WouldLeaveUnsupported(_))));
    if found && taken_apart(outcome) {
        Applies::No("the depth-first plan takes every subassembly apart")
    } else if !found && gravity_only {
        Applies::No("only gravity stopped the depth-first search, which the grid planner does not test")
    } else {
        Applies::Yes
    }
}

/// The grid plan (the grid-first stage's, or a new search): it ends the run when the
/// depth-first search found no plan and it does, or when it takes everything apart.
fn grid_fallback(run: &mut Run<'_>) -> Result<Next> {
    let (Ok(model), Some((outcome, _))) = (&run.grid, &run.outcome) else { return Ok(Next::Pass("no grid view or no search")) };
    let found = outcome.status == Status::Found;
    let grid = match run.grid_run.take() {
        Some(g) => g,
        None => GridRun::new(model.clone(), &GridConfig::default(), run.budget, Instant::now()),
    };
    if (!found && grid.found()) || grid.solution.complete() {
        let (checker, world_seconds) = run.model.world(run.settings, &mut run.units)?;
        return Ok(Next::End(Box::new(grid_result(checker, run.settings, &grid, GridReason::Fallback, Some(outcome), world_seconds))));
    }
    run.grid_ran = GridRan::of(&grid.solution.plan);
    Ok(Next::Pass("the grid plan takes no more apart"))
}

/// The path planner's turn after the grid's, when neither straight lines nor grid moves took the
/// model apart and the budget is not spent.
fn path_planner_applies(run: &Run<'_>) -> Applies {
    if !run.settings.path_planner {
        Applies::No("the path planner is off")
    } else if run.grid.is_err() {
        Applies::No("the depth-first search ran with the path planner")
    } else if run.grid_ran == GridRan::No {
        Applies::No("the grid fallback did not run")
    } else if run.outcome.as_ref().is_some_and(|(o, _)| o.stats.stopped_by.is_some()) {
        Applies::No("the depth-first search spent the budget")
    } else {
        Applies::Yes
    }
}

/// The depth-first search again, with the path planner (a piece that must turn to come out).
fn path_planner(run: &mut Run<'_>) -> Result<Next> {
    search_world(run, true)?;
    Ok(Next::Pass("its plan is the answer"))
}

/// The depth-first planner of the settings (with or without the path planner) on the world's
/// checker, through the checker extension when there is one (a robot), its outcome the run's.
fn search_world(run: &mut Run<'_>, path_planner: bool) -> Result<()> {
    let settings = run.settings;
    let (checker, _) = run.model.world(settings, &mut run.units)?;
    let dfs = planner(&PlanSettings { path_planner, ..settings.clone() }, checker.world())?;
    let (units, progress, budget) = (&run.units, run.progress, run.budget);
    let mut go = |c: &dyn FeasibilityChecker| search(&dfs, c, units, progress, budget);
    run.outcome = Some(match &settings.checker_extension {
        Some(e) => e.solve(checker, settings.seed, &mut go)?,
        None => (go(checker as &dyn FeasibilityChecker)?, None),
    });
    Ok(())
}

/// Whether every subassembly of a found plan was taken apart by its own plan.
fn taken_apart(outcome: &PlanOutcome) -> bool {
    outcome
        .removals
        .iter()
        .all(|s| s.group.as_ref().is_none_or(|g| g.plan.as_ref().is_some_and(|p| p.status == Status::Found && taken_apart(p))))
}

/// Runs `planner` through [`Planner`] on `checker` from the assembled state, the declared
/// `units` kept together and `progress` reported: the one feasibility search of every plan,
/// whichever planner and checker (the collision world's, the voxel fast path's, a robot's on
/// either).
pub(crate) fn search(
    planner: &dyn Planner,
    checker: &dyn FeasibilityChecker,
    units: &[PartSet],
    progress: Option<&(dyn Fn(&Progress) + Sync)>,
    budget: &Budget,
) -> asp_search::Result<PlanOutcome> {
    let with_units;
    let checker: &dyn FeasibilityChecker = if units.is_empty() {
        checker
    } else {
        with_units = UnitChecker::new(checker, units.to_vec());
        &with_units
    };
    let mut problem = Problem::full(checker);
    problem.progress = progress;
    planner.solve(&problem, budget)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::finish::world_result;
    use crate::pipeline::feasible;
    use crate::stage::Decision;
    use std::borrow::Cow;

    /// What became of each stage, by name.
    fn kinds(trace: &[(&'static str, Decision)]) -> Vec<(&'static str, &'static str)> {
        trace
            .iter()
            .map(|(name, d)| {
                (
                    *name,
                    match d {
                        Decision::Skipped(_) => "skipped",
                        Decision::Passed(_) => "passed",
                        Decision::Ended => "ended",
                    },
                )
            })
            .collect()
    }

    #[test]
    fn the_pipeline_is_its_declared_stages_in_order_over_their_sources() {
        let declared: Vec<(&str, Source)> = STAGES.iter().map(|s| (s.name, s.source)).collect();
        assert_eq!(
            declared,
            [
                ("voxels", Source::Voxels),
                ("grid-first", Source::World),
                ("depth-first", Source::World),
                ("grid-fallback", Source::World),
                ("path-planner", Source::World),
            ]
        );
    }

    /// A stage whose answer ends the run is the last that runs: the stages after it are not
    /// even asked whether they apply.
    #[test]
    fn a_stage_that_ends_the_run_is_the_last_to_run() {
        let list = [
            Stage {
                name: "ends",
                source: Source::World,
                applies: |_| Applies::Yes,
                run: |run| {
                    search_world(run, false)?;
                    Ok(Next::End(Box::new(world_result(run, None)?)))
                },
            },
            Stage {
                name: "after",
                source: Source::World,
                applies: |_| panic!("asked after the end"),
                run: |_| panic!("ran after the end"),
            },
        ];
        let settings = PlanSettings::default();
        let budget = crate::setup::budget(&settings).unwrap();
        let mut run = Run::new(Cow::Owned(asp_geom::fixtures::figure_6_2(0.01)), &settings, &budget, None).unwrap();
        let result = run.run(&list).unwrap().expect("the answer of the stage that ended the run");
        assert!(result.found(), "{}", result.report.to_json());
        assert_eq!(run.trace, [("ends", Decision::Ended)]);
    }

    /// A stage that does not apply says why, and does not run; the run goes on to the next.
    #[test]
    fn a_stage_that_does_not_apply_says_why_and_does_not_run() {
        let list = [
            Stage { name: "never", source: Source::World, applies: |_| Applies::No("not for this model"), run: |_| panic!("it ran") },
            Stage { name: "depth-first", source: Source::World, applies: |_| Applies::Yes, run: depth_first },
        ];
        let settings = PlanSettings::default();
        let budget = crate::setup::budget(&settings).unwrap();
        let mut run = Run::new(Cow::Owned(asp_geom::fixtures::figure_6_2(0.01)), &settings, &budget, None).unwrap();
        assert!(run.run(&list).unwrap().is_none(), "no stage ended the run");
        assert_eq!(run.trace[0], ("never", Decision::Skipped("not for this model")));
        assert_eq!(kinds(&run.trace), [("never", "skipped"), ("depth-first", "passed")]);
        assert!(world_result(&mut run, None).unwrap().found(), "the depth-first search's plan is the answer");
    }

    /// Which stages run, and which ends the run, on models that take each way through the list.
    #[test]
    fn each_model_takes_its_way_through_the_stages() {
        let settings = PlanSettings { timeout: Some(30.0), ..PlanSettings::default() };
        let cube = asp_gen::SomaCube::classic().to_assembly(0.05, "classic");
        // a Soma cube on its floor: boxes on a lattice, answered without a world
        let (r, trace) = feasible(cube.clone(), &settings, None).unwrap();
        assert!(r.found());
        assert_eq!(trace, [("voxels", Decision::Ended)]);
        // the precedence graph needs the world: the depth-first search on it is the answer
        let precedence = PlanSettings { precedence: true, ..settings.clone() };
        let (r, trace) = feasible(cube, &precedence, None).unwrap();
        assert!(r.found() && r.report.precedence.is_some());
        assert_eq!(trace[0], ("voxels", Decision::Skipped("the precedence graph is drawn in the collision world")));
        assert_eq!(
            kinds(&trace),
            [
                ("voxels", "skipped"),
                ("grid-first", "skipped"),
                ("depth-first", "passed"),
                ("grid-fallback", "skipped"),
                ("path-planner", "skipped")
            ]
        );
        // an interlocking burr: the grid planner's moves, straight away
        let (r, trace) = feasible(asp_geom::puzzles::burr_level(), &settings, None).unwrap();
        assert!(r.found());
        assert_eq!(kinds(&trace), [("voxels", "skipped"), ("grid-first", "ended")]);
        // the same burr without the grid and the path planner: the voxel search needs the world
        // (the burr lifts off in one piece), and the world's plan is partial
        let off = PlanSettings { grid: false, path_planner: false, ..settings.clone() };
        let (r, trace) = feasible(asp_geom::puzzles::burr_level(), &off, None).unwrap();
        assert!(!r.found());
        assert_eq!(
            kinds(&trace),
            [
                ("voxels", "passed"),
                ("grid-first", "skipped"),
                ("depth-first", "passed"),
                ("grid-fallback", "skipped"),
                ("path-planner", "skipped")
            ]
        );
        assert_eq!(trace[1], ("grid-first", Decision::Skipped("the grid planner is off")));
        assert_eq!(trace[4], ("path-planner", Decision::Skipped("the path planner is off")));
        // a burr the straight lines take apart: the grid probe passes, nothing falls back
        let (r, trace) = feasible(asp_geom::puzzles::burr_key(), &settings, None).unwrap();
        assert!(r.found() && r.report.grid.is_none());
        assert_eq!(trace[1], ("grid-first", Decision::Passed("the first separation needs no moves of other parts")));
        assert_eq!(trace[3], ("grid-fallback", Decision::Skipped("the depth-first plan takes every subassembly apart")));
        assert_eq!(trace[4], ("path-planner", Decision::Skipped("the grid fallback did not run")));
    }
}
