//! What a plan is made of: its settings ([`PlanSettings`], [`OptimiseSettings`]), validated in
//! the model's units with messages that name the setting, and what they build on their own (the
//! loader's options, the collision world's and checker's configurations, the checker, the
//! depth-first planner, the budget), for the pipeline ([`crate::pipeline`]) and every module that
//! plans a part of a model (the product tree, locked cores, explanations, checks).

use crate::catalogue::PolicySource;
use crate::error::{AppError, Result};
use asp_geom::distmap::Support;
use asp_geom::io::LoadOptions;
use asp_geom::math::Axis;
use asp_geom::physics::PhysicsConfig;
use asp_geom::rrt::RrtConfig;
use asp_geom::{Assembly, Checker, CheckerConfig, OverlapPolicy, StabilityMode, Units, World, WorldConfig};
use asp_search::mcts::{DEFAULT_BUDGET, DEFAULT_EPISODES};
use asp_search::report::PlanReport;
use asp_search::Dfs;
use asp_search::{Budget, Status};
use asp_search::{BuiltinOrder, OrderingSource};
use asp_search::{CheckerExtension, MdpExtension};
use asp_search::{SearchOutcome, StopToken};
use std::path::Path;
use std::sync::Arc;
use std::time::Duration;

/// The default time budget of a feasibility search, seconds: long enough for every real model
/// the tests know (the slowest answers in a few seconds), short enough that a model that
/// cannot be answered still gives its best partial plan within a minute.
pub const DEFAULT_TIMEOUT: f64 = 60.0;

/// How the stability of a state is judged.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub enum StabilitySetting {
    /// Every part linked through contacts to a fixed part (thesis 3.3).
    #[default]
    Contact,
    /// Simulated under gravity (rapier3d); unstable when a part moves more than `threshold`
    /// (a fraction of the model's diagonal).
    Physics {
        /// Displacement threshold as a fraction of the model's diagonal (default 0.01).
        threshold: f64,
    },
}

/// Everything `asp plan` can be asked, in the model's units.
#[derive(Clone)]
pub struct PlanSettings {
    /// The unit of the model's coordinates (default: what the file says, else metres).
    pub unit: Option<Units>,
    /// The up axis (default: what the file says, else the format's convention).
    pub up: Option<Axis>,
    /// Names of base parts, on top of those the file marks as fixed.
    pub fixed: Vec<String>,
    /// Whether the model may read files outside its folder (docs/security.md).
    pub allow_outside_files: bool,
    /// Caps on the model's size, checked before its data is read.
    pub limits: asp_geom::io::Limits,
    /// A STEP file's chord tolerance relative to each edge's and face's size (default
    /// [`asp_geom::io::step::DEFAULT_RELATIVE`]); an error for other files.
    pub tessellation: Option<f64>,
    /// Make each separate body of a part's mesh a part of its own (`NAME#1`, `NAME#2`, ...).
    pub split_bodies: bool,
    /// Contact tolerance in model units (default 1e-4 × the model's diagonal).
    pub tolerance: Option<f64>,
    /// Contact distance for stability, model units (default 1e-3 × the diagonal).
    pub contact_distance: Option<f64>,
    /// Clustered surface-normal directions tried besides the six axes.
    pub normals: usize,
    /// Extra removal directions sampled evenly on the sphere.
    pub sphere_directions: usize,
    /// How parts that overlap in the input are tested (default strict: they separate only
    /// along motions that enter no new material of each other).
    pub overlaps: OverlapPolicy,
    /// The stability criterion.
    pub stability: StabilitySetting,
    /// The part ordering of the depth-first search.
    pub order: Arc<dyn OrderingSource>,
    /// Bookkeeping on top of the ordering.
    pub bookkeeping: bool,
    /// Seed of every random choice.
    pub seed: u64,
    /// Fall back to the path planner when no straight line works.
    pub path_planner: bool,
    /// Let groups of parts leave together as rigid subassemblies when no single part can.
    pub subassemblies: bool,
    /// Follow the file's product tree ([`crate::tree`]): each subassembly planned on its own,
    /// then the level above with each as one unit.
    pub from_file: bool,
    /// Groups of parts (by name) planned as one part each, on purpose ([`asp_search::units`]).
    pub unit_groups: Vec<Vec<String>>,
    /// Plan voxel models by moves of parts and groups on their grid ([`asp_search::grid`]) when
    /// several parts must move in turn before anything can leave, or when the depth-first
    /// search finds no plan.
    pub grid: bool,
    /// Path planner iterations per call.
    pub rrt_iterations: usize,
    /// Path planner wall-time cap per call, seconds.
    pub rrt_time: f64,
    /// Stop after this many removal tests.
    pub max_tests: Option<u64>,
    /// Stop after this many seconds ([`DEFAULT_TIMEOUT`]; `None`: no limit).
    pub timeout: Option<f64>,
    /// Optimise instead of finding a feasible sequence.
    pub optimise: Option<OptimiseSettings>,
    /// Stops the search from another thread (a Ctrl-C handler, a Python signal, a caller's
    /// deadline) with the best result so far: the depth-first search ends `interrupted` with its
    /// partial plan, the optimiser returns what it has found, as with its time limit.
    pub cancel: Option<StopToken>,
    /// Wraps the depth-first search's checker (e.g. a robot that must also take each part out).
    pub checker_extension: Option<Arc<dyn CheckerExtension>>,
    /// Add the precedence graph of a found plan to its report ([`PrecedenceEntry`](asp_search::report::PrecedenceEntry)).
    pub precedence: bool,
}

impl PlanSettings {
    /// Which checker decides removals (`robot` with a robot in the feasibility search, else
    /// `physics` under the physics stability check, else `default`): the labels `asp collect
    /// removability` records under these settings, and the checker a removability model must
    /// have been trained on to order this run's search. Derived from the checker extension and
    /// `stability`, so it cannot disagree with them.
    pub fn label_checker(&self) -> asp_learn::Checker {
        label_checker(self.checker_extension.as_deref(), &self.stability)
    }
}

/// [`PlanSettings::label_checker`] of its parts (also what [`crate::resolve()`] orders by, before
/// the settings exist).
pub(crate) fn label_checker(extension: Option<&dyn CheckerExtension>, stability: &StabilitySetting) -> asp_learn::Checker {
    match (extension, stability) {
        (Some(e), _) if e.checks_arm() => asp_learn::Checker::Robot,
        (_, StabilitySetting::Physics { .. }) => asp_learn::Checker::Physics,
        _ => asp_learn::Checker::Default,
    }
}

impl Default for PlanSettings {
    fn default() -> Self {
        PlanSettings {
            unit: None,
            up: None,
            fixed: Vec::new(),
            allow_outside_files: false,
            limits: asp_geom::io::Limits::default(),
            tessellation: None,
            split_bodies: false,
            tolerance: None,
            contact_distance: None,
            normals: WorldConfig::default().normal_clusters,
            sphere_directions: 0,
            overlaps: OverlapPolicy::Strict,
            stability: StabilitySetting::Contact,
            order: Arc::new(BuiltinOrder::Given),
            bookkeeping: false,
            seed: 0,
            path_planner: true,
            subassemblies: true,
            from_file: false,
            unit_groups: Vec::new(),
            grid: true,
            rrt_iterations: RrtConfig::default().max_iterations,
            rrt_time: RrtConfig::default().max_time.as_secs_f64(),
            max_tests: None,
            timeout: Some(DEFAULT_TIMEOUT),
            optimise: None,
            cancel: None,
            checker_extension: None,
            precedence: false,
        }
    }
}

impl std::fmt::Debug for PlanSettings {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("PlanSettings")
            .field("order", &self.order.name())
            .field("bookkeeping", &self.bookkeeping)
            .field("seed", &self.seed)
            .field("optimise", &self.optimise)
            .finish_non_exhaustive()
    }
}

/// The optimiser's settings (`asp plan --objective`).
#[derive(Clone, Debug)]
pub struct OptimiseSettings {
    /// Objective names in order (`access`, `dirchange`, `pathlen`, an extension's), one per
    /// objective: several make a Pareto problem.
    pub objectives: Vec<String>,
    /// Search the Pareto front (several objectives need it).
    pub pareto: bool,
    /// MCTS episodes.
    pub episodes: usize,
    /// MCTS iterations per step.
    pub budget: usize,
    /// Threads (default: all cores).
    pub threads: Option<usize>,
    /// Wall-time limit of the search, seconds.
    pub time_limit: Option<f64>,
    /// Exploration constant of UCT / MOUCB.
    pub exploration: f64,
    /// The share of the search's work its local search over the answer's sequences may take
    /// ([`asp_search::mcts::SearchBuilder::polish`]; 0: none).
    pub polish: f64,
    /// Distance map resolution N_M.
    pub resolution: usize,
    /// Cap of the distance maps, model units (default the model's diagonal).
    pub d_max: Option<f64>,
    /// The optimiser's gravity check.
    pub support: Support,
    /// Objectives and feasibility filters beyond the built-in ones (e.g. a robot's); their
    /// objective names may appear in `objectives`.
    pub extensions: Vec<Arc<dyn MdpExtension>>,
    /// The rollout and expansion policy, made for the problem (default: uniformly random; e.g.
    /// ε-greedy over learned Q-functions, [`crate::catalogue::QPolicy`]).
    pub policy: Option<Arc<dyn PolicySource>>,
    /// The request keys of the robot that `extensions` were built from (`robot`, `robot_base`,
    /// `drop_off`, `replans`, `package_path`, `allow_outside_files`, as given; empty without a
    /// robot): a transitions data set records them, so that `Assembly.q_graphs` rebuilds the
    /// same problem ([`crate::collect_q::MapsArgs`]).
    pub robot_keys: serde_json::Map<String, serde_json::Value>,
}

impl Default for OptimiseSettings {
    fn default() -> Self {
        OptimiseSettings {
            objectives: Vec::new(),
            pareto: false,
            episodes: DEFAULT_EPISODES,
            budget: DEFAULT_BUDGET,
            threads: None,
            time_limit: None,
            exploration: asp_search::mcts::DEFAULT_EXPLORATION,
            polish: asp_search::mcts::DEFAULT_POLISH,
            resolution: asp_geom::distmap::DEFAULT_RESOLUTION,
            d_max: None,
            support: Support::Below,
            extensions: Vec::new(),
            policy: None,
            robot_keys: serde_json::Map::new(),
        }
    }
}

/// What a planning run gives back.
#[derive(Debug)]
pub struct PlanResult {
    /// The plan, as written to the plan JSON.
    pub report: PlanReport,
    /// How the search ended.
    pub status: Status,
    /// The optimiser's outcome (its trace, every solution), for optimising runs.
    pub search: Option<SearchOutcome>,
}

impl PlanResult {
    /// Whether a plan was found that gives every part its own motion (the report's status is
    /// `found`; a `partial` plan, with locked cores, is not).
    pub fn found(&self) -> bool {
        self.report.status == asp_search::report::PlanStatus::Found
    }
}

pub(crate) fn positive(name: &str, v: f64) -> Result<f64> {
    if v > 0.0 && v.is_finite() {
        Ok(v)
    } else {
        Err(AppError::config(format!("{name} must be a positive number, got {v}")))
    }
}

/// Loads the model at `path` with the settings' unit, up axis, fixed parts, file rule
/// ([`PlanSettings::allow_outside_files`]) and caps ([`PlanSettings::limits`]).
pub fn load(path: &Path, settings: &PlanSettings) -> Result<Assembly> {
    Ok(asp_geom::io::load(path, &load_options(path, settings)?)?)
}

/// The loader's options of `settings` for the model at `path`: a tessellation tolerance is an
/// error for a model that is not STEP (it comes as triangles).
pub fn load_options(path: &Path, settings: &PlanSettings) -> Result<LoadOptions> {
    if settings.tessellation.is_some() && !asp_geom::io::step::is_step(path) {
        return Err(AppError::setting("tessellation", format!("applies to STEP files only (.step, .stp), not to {}", path.display())));
    }
    let tessellation = asp_geom::io::Tessellation {
        relative: settings.tessellation.unwrap_or(asp_geom::io::step::DEFAULT_RELATIVE),
        ..asp_geom::io::Tessellation::default()
    };
    tessellation.validate().map_err(|e| AppError::setting("tessellation", e))?;
    Ok(LoadOptions {
        unit: settings.unit.clone(),
        up: settings.up,
        fixed: settings.fixed.clone(),
        allow_outside_files: settings.allow_outside_files,
        limits: settings.limits,
        split_bodies: settings.split_bodies,
        tessellation,
    })
}

/// The collision world's settings, converted to metres.
pub fn world_config(assembly: &Assembly, settings: &PlanSettings) -> Result<WorldConfig> {
    let metres = assembly.units.metres;
    let to_m =
        |name: &str, v: Option<f64>| -> Result<Option<f32>> { v.map(|v| positive(name, v).map(|v| (v * metres) as f32)).transpose() };
    Ok(WorldConfig {
        tolerance: to_m("the tolerance", settings.tolerance)?,
        contact_distance: to_m("the contact distance", settings.contact_distance)?,
        normal_clusters: settings.normals,
        sphere_directions: settings.sphere_directions,
        overlaps: settings.overlaps,
        ..WorldConfig::default()
    })
}

/// The checker's settings (stability, path planner budget).
pub fn checker_config(settings: &PlanSettings) -> Result<CheckerConfig> {
    let stability = match settings.stability {
        StabilitySetting::Contact => StabilityMode::ContactGraph,
        StabilitySetting::Physics { threshold } => {
            let physics =
                PhysicsConfig { displacement_fraction: positive("the physics threshold", threshold)? as f32, ..PhysicsConfig::default() };
            physics.validate()?;
            StabilityMode::Physics(physics)
        }
    };
    let rrt = RrtConfig {
        max_iterations: settings.rrt_iterations,
        max_time: Duration::from_secs_f64(positive("the path planner's time cap", settings.rrt_time)?),
        ..RrtConfig::default()
    };
    Ok(CheckerConfig { stability, rrt })
}

/// Builds the collision world of `assembly` and its checker.
pub fn checker(assembly: Assembly, settings: &PlanSettings) -> Result<Checker> {
    let config = world_config(&assembly, settings)?;
    let world = World::new(assembly, &config)?;
    Ok(Checker::new(world, checker_config(settings)?))
}

/// The depth-first planner the settings ask for, its ordering prepared on `world` (a learned
/// ordering computes the model's graph features here, once).
pub fn planner(settings: &PlanSettings, world: &World) -> Result<Dfs> {
    Ok(dfs(settings, settings.order.prepare(world)?))
}

/// The depth-first planner the settings ask for, with its ordering factory.
pub(crate) fn dfs(settings: &PlanSettings, factory: Arc<dyn asp_search::OrderingFactory>) -> Dfs {
    Dfs::builder()
        .ordering_factory(factory)
        .bookkeeping(settings.bookkeeping)
        .path_planner(settings.path_planner)
        .subassemblies(settings.subassemblies)
        .seed(settings.seed)
        .build()
}

/// The search budget.
pub fn budget(settings: &PlanSettings) -> Result<Budget> {
    Ok(Budget {
        max_tests: settings.max_tests,
        timeout: settings.timeout.map(|t| positive("the timeout", t).map(Duration::from_secs_f64)).transpose()?,
        cancel: settings.cancel.clone(),
        ..Budget::default()
    })
}
