//! The optimiser's pipeline: load → distance maps → MCTS (one objective) or Pareto-MCTS
//! (several) → report, from the search's own outcome ([`asp_search::SearchOutcome::plan`]).

use crate::error::{AppError, Result};
use crate::setup::{positive, world_config, OptimiseSettings, PlanResult, PlanSettings};
use asp_geom::distmap::{DistanceMaps, MapConfig};
use asp_geom::{Assembly, World};
use asp_search::extension::resolve_objectives;
use asp_search::report::{Checker as CheckerName, OptimisationEntry, OptimisationMethod, ParetoEntry, PlanReport};
use asp_search::ModelContext;
use asp_search::{EpisodeHook, Mcts, Mdp, ParetoMcts};
use std::sync::Arc;
use std::time::{Duration, Instant};

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
    if o.objectives.len() > 1 && !o.pareto {
        return Err(AppError::config(format!(
            "objectives {}: several objectives need a Pareto search (or give one objective)",
            o.objectives.join(",")
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
