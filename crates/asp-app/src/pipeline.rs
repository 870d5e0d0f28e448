//! The planning pipeline that the CLI and the Python package both call:
//! load → collision world → checker → planner → report, and the optimiser's
//! load → distance maps → MCTS / Pareto-MCTS → report.
//!
//! Settings are in the model's units (as a user gives them) and validated here, with messages
//! that name the setting, not a command-line flag. Every step is also public on its own, so a
//! caller that plans many times on one model (data collection, benchmarks) builds the world once.

use crate::error::{AppError, Result};
use crate::why::{explain_cores, GridRan};
use asp_geom::distmap::{DistanceMaps, MapConfig};
use asp_geom::grid::VoxelModel;
use asp_geom::voxel::VoxelChecker;
use asp_geom::{Assembly, Checker, FeasibilityChecker, PartSet, World};
use asp_search::extension::resolve_objectives;
use asp_search::grid::{GridConfig, GridPlanner, GridRun};
use asp_search::report::{
    Checker as CheckerName, GridEntry, GridReason, OptimisationEntry, OptimisationMethod, ParetoEntry, PlanReport, PrecedenceEntry, Timings,
};
use asp_search::units::UnitChecker;
use asp_search::ModelContext;
use asp_search::{Budget, PlanOutcome, Problem, Progress, Status, StuckReason};
use asp_search::{EpisodeHook, StopToken};
use asp_search::{Mcts, Mdp, ParetoMcts, Planner};
use std::path::Path;
use std::sync::Arc;
use std::time::{Duration, Instant};

pub use crate::setup::{
    budget, checker, checker_config, load, load_options, planner, world_config, OptimiseSettings, PlanResult, PlanSettings,
    StabilitySetting, DEFAULT_TIMEOUT,
};
use crate::setup::{dfs, positive};

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

/// Plans `assembly`: a feasible sequence by depth-first AbD, or, with
/// [`PlanSettings::optimise`], an optimised one.
pub fn plan_assembly(assembly: Assembly, settings: &PlanSettings, progress: Option<&(dyn Fn(&Progress) + Sync)>) -> Result<PlanResult> {
    if let Some(optimise) = &settings.optimise {
        return self::optimise(Arc::new(assembly), settings, optimise);
    }
    if settings.from_file {
        return crate::tree::plan(assembly, settings, progress, &plan_assembly);
    }
    let budget = budget(settings)?;
    let units = unit_sets(&assembly, &settings.unit_groups)?;
    let voxels = voxel_model(&assembly, settings, &units);
    // the voxel fast path builds no world, which the precedence graph tests pairs in
    if voxels.is_none() && units.is_empty() && !settings.precedence {
        if let Some(result) = plan_on_voxels(&assembly, settings, &budget, progress)? {
            return Ok(result);
        }
    }
    plan_with_world(assembly, settings, progress, budget, units, voxels, true)
}

/// [`plan_assembly`]'s feasibility plan on the collision world, never by the voxel fast path
/// ([`plan_on_voxels`]): what the fast path must equal (`tests/voxel`), and the one plan of
/// every model the fast path declines.
pub fn plan_on_world(assembly: Assembly, settings: &PlanSettings, progress: Option<&(dyn Fn(&Progress) + Sync)>) -> Result<PlanResult> {
    let budget = budget(settings)?;
    let units = unit_sets(&assembly, &settings.unit_groups)?;
    let voxels = voxel_model(&assembly, settings, &units);
    plan_with_world(assembly, settings, progress, budget, units, voxels, true)
}

/// The voxel view the grid planner takes apart, when it may run: it does not keep declared
/// units together, and a robot checks what the grid cannot.
fn voxel_model(assembly: &Assembly, settings: &PlanSettings, units: &[PartSet]) -> Option<VoxelModel> {
    (settings.grid && settings.checker_extension.is_none() && units.is_empty()).then(|| VoxelModel::of(assembly)).flatten()
}

/// A locked core of a plan planned as a model of its own ([`crate::cores`]): `assembly` holds
/// its parts, its base fixed; the declared units that lie wholly in it are kept. Its own cores
/// are not planned alone again.
pub(crate) fn plan_core(assembly: Assembly, settings: &PlanSettings, budget: Budget) -> Result<PlanResult> {
    let names: Vec<&str> = assembly.parts.iter().map(|p| p.name.as_str()).collect();
    let groups: Vec<Vec<String>> = settings.unit_groups.iter().filter(|g| g.iter().all(|n| names.contains(&n.as_str()))).cloned().collect();
    let settings = PlanSettings { unit_groups: groups, ..settings.clone() };
    let units = unit_sets(&assembly, &settings.unit_groups)?;
    let voxels = voxel_model(&assembly, &settings, &units);
    plan_with_world(assembly, &settings, None, budget, units, voxels, false)
}

/// The feasibility plan on the collision world (after the grid planner on `voxels` when the
/// model needs its moves); with `cores_alone`, the locked cores of the plan are then planned as
/// models of their own ([`crate::cores`]).
fn plan_with_world(
    assembly: Assembly,
    settings: &PlanSettings,
    progress: Option<&(dyn Fn(&Progress) + Sync)>,
    budget: Budget,
    units: Vec<PartSet>,
    voxels: Option<VoxelModel>,
    cores_alone: bool,
) -> Result<PlanResult> {
    let grid_started = Instant::now();
    let probe = voxels.clone().map(|m| GridRun::probe(m, &budget, grid_started));
    let started = Instant::now();
    let checker = checker(assembly, settings)?;
    let world_seconds = started.elapsed().as_secs_f64();
    let units = with_bearings(units, checker.world());
    let grid_planner = voxels.map(|m| GridPlanner::new(checker.world().assembly(), m, GridConfig::default()));
    let mut grid = None;
    if let (Some(planner), true) = (&grid_planner, probe.as_ref().is_some_and(GridRun::needs_moves)) {
        let run = planner.run(&budget, grid_started);
        if run.found() {
            return Ok(grid_result(&checker, settings, &run, GridReason::NeedsMoves, None, world_seconds));
        }
        grid = Some(run);
    }
    // on a voxel model the grid's moves are the exact answer to what the path planner samples
    // for: the depth-first search tries straight lines (and groups) first, then the grid, and
    // only then the path planner (a piece that must turn to come out)
    let grid_first = grid_planner.is_some() && settings.path_planner;
    let run_dfs = |path_planner: bool| -> Result<(PlanOutcome, Option<asp_search::report::RobotReport>)> {
        let dfs = planner(&PlanSettings { path_planner, ..settings.clone() }, checker.world())?;
        let mut run = |c: &dyn FeasibilityChecker| search(&dfs, c, &units, progress, &budget);
        Ok(match &settings.checker_extension {
            Some(e) => e.solve(&checker, settings.seed, &mut run)?,
            None => (run(&checker as &dyn FeasibilityChecker)?, None),
        })
    };
    let (mut outcome, mut robot) = run_dfs(settings.path_planner && !grid_first)?;
    // the grid plan when the depth-first search found no plan, or one with a subassembly it
    // could not take apart (a voxel puzzle lifted off the ground in one piece); not when only
    // gravity stopped it (the grid plan does not test gravity)
    let wants_grid = |outcome: &PlanOutcome| {
        let found = outcome.status == Status::Found;
        let gravity_only = matches!(&outcome.status, Status::NoPlan { stuck, .. }
            if !stuck.is_empty() && stuck.iter().all(|s| matches!(s.reason, StuckReason::WouldLeaveUnsupported(_))));
        (!found && !gravity_only) || (found && !taken_apart(outcome))
    };
    let mut grid_ran = GridRan::No;
    if wants_grid(&outcome) {
        if let Some(planner) = &grid_planner {
            let found = outcome.status == Status::Found;
            let run = grid.unwrap_or_else(|| planner.run(&budget, Instant::now()));
            if (!found && run.found()) || run.solution.complete() {
                return Ok(grid_result(&checker, settings, &run, GridReason::Fallback, Some(&outcome), world_seconds));
            }
            grid_ran = GridRan::of(&run.solution.plan);
            if grid_first && !budget_spent(&outcome) {
                // neither straight lines nor grid moves: the path planner's turn
                (outcome, robot) = run_dfs(true)?;
            }
        }
    }
    let world = checker.world();
    let mut report = PlanReport::new(world.assembly(), &outcome, world.tolerance(), world.warnings());
    if let Some(r) = robot {
        report.attach_robot(r);
    }
    finish_report(&mut report, world, &outcome, world_seconds);
    if cores_alone {
        crate::cores::plan_cores_alone(&mut report, world.assembly(), settings, &budget, grid_started, &plan_core)?;
    }
    explain_cores(&mut report, world, settings, grid_ran, &units);
    attach_precedence(&mut report, world, &outcome, settings);
    Ok(PlanResult { report, status: outcome.status, search: None })
}

/// The fraction of the time budget the voxel fast path may spend before the world plans
/// (`1 / VOXEL_TIME_SHARE`).
const VOXEL_TIME_SHARE: u32 = 10;

/// The voxel fast path: when every part is a union of boxes on one lattice
/// ([`VoxelChecker`]) and the settings ask for nothing it cannot answer (contact stability, no
/// extension, an ordering that needs no world), the depth-first search runs on the voxel
/// checker, which answers every removal test as the collision world would, and no world is
/// built. Its plan is the plan of the world's search, so it is kept only when it is complete
/// and asked for nothing of the world (the path planner, a subassembly's own plan); otherwise
/// `None`, and the caller plans on the world as before ([`plan_on_world`]; `tests/voxel` holds
/// the two equal). `budget` is [`budget`]'s of the settings.
pub fn plan_on_voxels(
    assembly: &Assembly,
    settings: &PlanSettings,
    budget: &Budget,
    progress: Option<&(dyn Fn(&Progress) + Sync)>,
) -> Result<Option<PlanResult>> {
    if settings.checker_extension.is_some() || !matches!(settings.stability, StabilitySetting::Contact) {
        return Ok(None);
    }
    let Some(factory) = settings.order.prepare_without_world() else { return Ok(None) };
    // the world's settings are checked as the world's path checks them
    let config = world_config(assembly, settings)?;
    checker_config(settings)?;
    let started = Instant::now();
    let Some(checker) = VoxelChecker::new(assembly, &config) else { return Ok(None) };
    let world_seconds = started.elapsed().as_secs_f64();
    // the search stops as soon as it asks for the world (its plan would be discarded), and
    // gets a tenth of the time: a model it cannot answer in that is planned on the world with
    // the whole budget, as before, at most a tenth later
    let abort = StopToken::new();
    let share = Budget { timeout: budget.timeout.map(|t| t / VOXEL_TIME_SHARE), cancel: Some(abort.clone()), ..budget.clone() };
    let watch = |p: &Progress| {
        if checker.needs_world() || budget.cancel.as_ref().is_some_and(StopToken::is_stopped) {
            abort.stop();
        }
        if let Some(report) = progress {
            report(p);
        }
    };
    let outcome = search(&dfs(settings, factory), &checker, &[], Some(&watch), &share)?;
    if checker.needs_world() || outcome.status != Status::Found {
        return Ok(None);
    }
    let mut report = PlanReport::new(assembly, &outcome, checker.tolerance(), checker.warnings());
    if !report.locked_cores.is_empty() {
        return Ok(None);
    }
    report.stats.timings = Some(timings(&outcome, world_seconds));
    Ok(Some(PlanResult { report, status: outcome.status, search: None }))
}

/// Runs `planner` through [`Planner`] on `checker` from the assembled state, the declared
/// `units` kept together and `progress` reported: the one feasibility search of every plan,
/// whichever planner and checker (the collision world's, the voxel fast path's, a robot's on
/// either).
fn search(
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

/// Where a feasibility plan's wall time went (loading is timed by the caller).
fn timings(outcome: &PlanOutcome, world_seconds: f64) -> Timings {
    Timings { load: 0.0, world: world_seconds, search: outcome.stats.seconds, path_planner: outcome.stats.path_planner_seconds }
}

/// `units` with every rolling bearing `world` found ([`asp_geom::Bearing`]) as one more unit: a
/// bought unit whose balls never leave their grooves goes in whole. A declared unit that shares
/// a part with a bearing is merged with it (units are disjoint).
fn with_bearings(mut units: Vec<PartSet>, world: &asp_geom::World) -> Vec<PartSet> {
    let n = world.num_parts();
    for b in world.bearings() {
        let mut merged = PartSet::from_indices(n + 1, b.parts());
        units.retain(|u| {
            let meets = u.intersects(&merged);
            if meets {
                merged.union_with(u);
            }
            !meets
        });
        units.push(merged);
    }
    units
}

/// The declared units ([`PlanSettings::unit_groups`]) as sets of part indices.
fn unit_sets(assembly: &Assembly, groups: &[Vec<String>]) -> Result<Vec<PartSet>> {
    let n = assembly.len();
    groups
        .iter()
        .map(|g| {
            let parts = g
                .iter()
                .map(|name| assembly.part_index(name).ok_or_else(|| AppError::setting("unit_group", format!("no part is named '{name}'"))))
                .collect::<Result<Vec<usize>>>()?;
            Ok(PartSet::from_indices(n + 1, parts))
        })
        .collect()
}

/// What every feasibility plan's report carries besides its steps: the overlapping pairs and
/// where the time went (loading is timed by the caller).
fn finish_report(report: &mut PlanReport, world: &asp_geom::World, outcome: &PlanOutcome, world_seconds: f64) {
    report.overlaps = asp_search::report::OverlapsEntry::of(world);
    report.fits = asp_search::report::FitEntry::of(world);
    report.bearings = asp_search::report::BearingEntry::of(world);
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

/// Whether a search ended on its budget (tests, time or a cancel), so that another search
/// would only spend more of it.
fn budget_spent(outcome: &PlanOutcome) -> bool {
    outcome.stats.stopped_by.is_some()
}

/// Whether every subassembly of a found plan was taken apart by its own plan.
fn taken_apart(outcome: &PlanOutcome) -> bool {
    outcome
        .removals
        .iter()
        .all(|s| s.group.as_ref().is_none_or(|g| g.plan.as_ref().is_some_and(|p| p.status == Status::Found && taken_apart(p))))
}

/// The plan of a grid search (after the depth-first search's `before`, whose counters and time
/// it keeps).
fn grid_result(
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
    let mut report = PlanReport::new(assembly, &outcome, world.tolerance(), world.warnings());
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

/// The optimiser's problem on one model: the distance maps, the objectives and the extensions'
/// filters, as [`optimise`] builds them.
#[derive(Clone, Debug)]
pub struct OptimiserProblem {
    /// The problem (it holds the maps and the assembly).
    pub mdp: Mdp,
    /// Seconds spent building the distance maps.
    pub map_seconds: f64,
}

/// Builds the optimiser's problem of `assembly`: distance maps with the settings' resolution,
/// cap, gravity check, tolerance, contact distance and overlap policy, the objectives by name
/// (built-in or from the extensions), the extensions' filters, and `settings.seed` as the
/// problem's seed. Several objectives need `o.pareto`.
pub fn optimiser_problem(assembly: &Arc<Assembly>, settings: &PlanSettings, o: &OptimiseSettings) -> Result<OptimiserProblem> {
    asp_search::extension::check_objective_names(&o.objectives, &o.extensions)?;
    if o.objectives.split(',').filter(|s| !s.trim().is_empty()).count() > 1 && !o.pareto {
        return Err(AppError::config(format!(
            "objectives {}: several objectives need a Pareto search (or give one objective)",
            o.objectives
        )));
    }
    let world = world_config(assembly, settings)?;
    let metres = assembly.units.metres;
    let mut config = MapConfig::builder().resolution(o.resolution).support(o.support).overlaps(settings.overlaps);
    if let Some(d) = o.d_max {
        config = config.d_max((positive("d_max", d)? * metres) as f32);
    }
    if let Some(t) = world.tolerance {
        config = config.tolerance(t);
    }
    if let Some(c) = world.contact_distance {
        config = config.contact_distance(c);
    }
    let config = config.build()?;
    let started = Instant::now();
    // one World per run: the maps of mesh models build it anyway and keep it; with extensions
    // (a robot, which needs a world even on box and voxel models) it is built first and shared
    let maps = if o.extensions.is_empty() {
        Arc::new(DistanceMaps::build(assembly, &config)?)
    } else {
        let world = Arc::new(World::new(assembly.as_ref().clone(), &config.world_config(assembly))?);
        Arc::new(DistanceMaps::build_on(world, &config)?)
    };
    let map_seconds = started.elapsed().as_secs_f64();
    let model = ModelContext { assembly, maps: &maps, seed: settings.seed };
    let objectives = resolve_objectives(&o.objectives, &o.extensions, &model)?;
    let mut mdp = Mdp::new(maps.clone(), objectives)?.with_assembly(assembly.clone()).with_seed(settings.seed);
    for e in &o.extensions {
        for f in e.filters(&model)? {
            mdp = mdp.with_filter(f);
        }
    }
    Ok(OptimiserProblem { mdp, map_seconds })
}

/// Optimises a sequence of `assembly` on distance maps (MCTS for one objective, Pareto-MCTS
/// for several).
pub fn optimise(assembly: Arc<Assembly>, settings: &PlanSettings, o: &OptimiseSettings) -> Result<PlanResult> {
    let problem = optimiser_problem(&assembly, settings, o)?;
    optimise_problem(assembly, settings, o, problem, None, false)
}

/// [`optimise`] on a problem built by [`optimiser_problem`], episode by episode on one thread
/// when a `hook` is given ([`asp_search::Mcts::solve_stepped`]: it sees each episode's transitions,
/// recorded when `record` is set, and may swap the policy between episodes). The one search loop and report of `asp plan
/// --objective`, the stepped search of `asp.Assembly.search` and the online Q-learning.
pub fn optimise_problem(
    assembly: Arc<Assembly>,
    settings: &PlanSettings,
    o: &OptimiseSettings,
    problem: OptimiserProblem,
    hook: Option<&mut EpisodeHook<'_>>,
    record: bool,
) -> Result<PlanResult> {
    let OptimiserProblem { mdp, map_seconds } = problem;
    let maps = mdp.maps_arc().clone();
    let model = ModelContext { assembly: &assembly, maps: &maps, seed: settings.seed };
    let stepped = hook.is_some();
    let policy = o.policy.as_ref().map(|p| p.prepare(&mdp)).transpose()?;
    let threads = match (&hook, o.threads) {
        (Some(_), _) => 1,
        (None, Some(t)) => t,
        (None, None) => std::thread::available_parallelism().map_or(1, |n| n.get()),
    };
    macro_rules! configure {
        ($builder:expr) => {{
            let mut b = $builder
                .budget(o.budget)
                .episodes(o.episodes)
                .threads(threads)
                .seed(settings.seed)
                .exploration(o.exploration)
                .polish(o.polish)
                .record_transitions(stepped && record);
            if let Some(t) = o.time_limit {
                b = b.time_limit(Duration::from_secs_f64(positive("the time limit", t)?));
            }
            if let Some(stop) = &settings.cancel {
                b = b.stop_token(stop.clone());
            }
            if let Some(policy) = &policy {
                b = b.policy(policy.clone());
            }
            b.build()?
        }};
    }
    let outcome = match (o.pareto, hook) {
        (true, None) => configure!(ParetoMcts::builder()).solve(&mdp)?,
        (false, None) => configure!(Mcts::builder()).solve(&mdp)?,
        (true, Some(h)) => configure!(ParetoMcts::builder()).solve_stepped(&mdp, h)?,
        (false, Some(h)) => configure!(Mcts::builder()).solve_stepped(&mdp, h)?,
    };
    let plan = &outcome.plan;
    let mut warnings = assembly.warnings.clone();
    for w in maps.warnings() {
        if !warnings.contains(w) {
            warnings.push(w.clone());
        }
    }
    for (part, why) in &outcome.rejected {
        warnings.push(format!("part '{}' {why} in the deepest dead end", assembly.parts[*part].name));
    }
    let mut report = PlanReport::new(&assembly, plan, maps.tolerance(), &warnings);
    report.stats.checker = CheckerName::DistanceMaps;
    // the optimiser's budget is its episodes and time limit, reported in `optimisation`
    // (`exhaustive`, `episodes`); `stats.stopped_by` belongs to the feasibility search's
    // budget (plan format: `--timeout`, `--max-tests`, Ctrl-C), so it stays out
    report.stats.stopped_by = None;
    if let Some(best) = outcome.best() {
        for e in &o.extensions {
            if let Some(r) = e.describe(&model, &best.sequence)? {
                report.attach_robot(r);
                break;
            }
        }
    }
    report.pareto_front = o.pareto.then(|| {
        outcome.solutions.iter().map(|s| ParetoEntry { objectives: s.values.clone(), disassembly_sequence: s.sequence.clone() }).collect()
    });
    let s = &outcome.stats;
    report.optimisation = Some(OptimisationEntry {
        method: if o.pareto { OptimisationMethod::ParetoMcts } else { OptimisationMethod::Mcts },
        objectives: outcome.objectives.clone(),
        values: outcome.best().map(|b| b.values.clone()).unwrap_or_default(),
        hypervolume: o.pareto.then_some(outcome.value),
        reference: outcome.reference.clone(),
        exhaustive: s.exhausted,
        episodes: s.episodes,
        iterations: s.iterations,
        tree_nodes: s.tree_nodes,
        polish: o.polish,
        polished: s.polished,
        budget: o.budget,
        threads: s.threads,
        seed: settings.seed,
        resolution: maps.hemisphere().resolution(),
        d_max: maps.d_max() as f64,
        map_seconds,
        search_seconds: s.seconds,
        guidance: o.policy.as_ref().and_then(|p| p.guidance()),
    });
    Ok(PlanResult { report, status: plan.status.clone(), search: Some(outcome) })
}
