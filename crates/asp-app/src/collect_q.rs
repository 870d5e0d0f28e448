//! Training data for learned Q-functions (thesis 5.5.2, 6.5.1): the transitions `(s, a, r, s')`
//! that asp's own MCTS / Pareto-MCTS simulates, written in the `asp-transitions` format
//! (`docs/learning.md`, "The transitions data set").
//!
//! For every model the distance maps, objectives and filters are built as the optimiser builds
//! them ([`pipeline::optimiser_problem`]); one search per model (MCTS for one objective,
//! Pareto-MCTS for several) runs `episodes` episodes on one thread with recording on
//! ([`asp_search::mcts::SearchBuilder::record_transitions`]), its seed derived from the base seed
//! and the model's position. Models go in parallel; the output depends only on the models, the
//! settings and the seed. The index records, per model, the keyword arguments of `asp.load`
//! and `Assembly.q_graphs` that rebuild the same maps, so the Python trainer computes each
//! transition's state graphs with the search's own Rust code.

use crate::collect::{self, io_error, ModelItem};
use crate::error::{AppError, Result};
use crate::pipeline::{self, OptimiseSettings, PlanSettings};
use asp_search::mcts::DEFAULT_RECORD_LIMIT;
use asp_search::qgraph::{direction_history, QGraphConfig};
use asp_search::Mdp;
use asp_search::StepKind;
use asp_search::Transition;
use asp_search::{Mcts, ParetoMcts};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// The data set's format name.
pub const FORMAT: &str = "asp-transitions";
/// The data set's format version.
pub const VERSION: u32 = 1;
/// Default episodes per model.
pub const DEFAULT_EPISODES: usize = 200;

/// Settings of a collection of transitions.
#[derive(Clone, Debug)]
pub struct TransitionSettings {
    /// Base seed; model `m`'s search uses a seed derived from it and `m`.
    pub seed: u64,
    /// How models are loaded (unit, up, fixed parts) and the maps' tolerance, contact distance
    /// and overlap policy (model units). Its `seed` is replaced by each model's; its `cancel`
    /// token stops the searches (the transitions so far are kept).
    pub plan: PlanSettings,
    /// The objectives (comma-separated), `episodes` per model, the search `budget`, the
    /// exploration constant and the maps' resolution, cap and gravity check. `pareto` follows
    /// from the number of objectives, `threads` is 1, `time_limit` is ignored.
    pub optimise: OptimiseSettings,
    /// The most transitions recorded per model (the search goes on without recording beyond it;
    /// the model's entry says `capped`).
    pub limit: usize,
}

impl Default for TransitionSettings {
    fn default() -> Self {
        TransitionSettings {
            seed: 0,
            plan: PlanSettings::default(),
            optimise: OptimiseSettings { episodes: DEFAULT_EPISODES, ..OptimiseSettings::default() },
            limit: DEFAULT_RECORD_LIMIT,
        }
    }
}

/// The keyword arguments of `asp.load(model, **load)` that load the model as the collection did.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct LoadArgs {
    /// The unit as given (`mm`, or metres per unit), `null`: what the file says.
    pub unit: Option<String>,
    /// The up axis (`+z`), `null`: what the file says.
    pub up: Option<String>,
    /// Base parts named on top of those the file marks.
    pub fixed: Vec<String>,
}

/// The keyword arguments of `Assembly.q_graphs(**maps)` that rebuild the collection's maps
/// (lengths in model units).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct MapsArgs {
    /// The objectives, comma-separated (as in the index's `objectives`).
    pub objective: String,
    /// Distance map resolution `N_M`.
    pub resolution: usize,
    /// The maps' cap, `null`: the model's diagonal.
    pub d_max: Option<f64>,
    /// The gravity check: `below` or `contact`.
    pub support: String,
    /// Contact tolerance, `null`: the default.
    pub tolerance: Option<f64>,
    /// Contact distance, `null`: the default.
    pub contact_distance: Option<f64>,
    /// The overlap policy: `strict`, `lenient` or `error`.
    pub overlaps: String,
    /// The robot's keys (`robot`, `robot_base`, `drop_off`, `replans`, `package_path`,
    /// `allow_outside_files`) when the search had one (`--robot`): its filter shaped the
    /// recorded actions and `robot-path` needs it. Absent without a robot; a URDF file is named
    /// by its absolute path.
    #[serde(flatten)]
    pub robot: serde_json::Map<String, serde_json::Value>,
}

/// One model's entry in `index.json`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TransitionsModel {
    /// The model's unique name.
    pub name: String,
    /// Its folder in the data set.
    pub dir: String,
    /// The model file (or folder), absolute.
    pub model: String,
    /// How to load it.
    pub load: LoadArgs,
    /// How to rebuild its maps.
    pub maps: MapsArgs,
    /// Number of parts (fixed ones included).
    pub parts: usize,
    /// Number of parts a complete sequence removes (`N_r`).
    pub removable: usize,
    /// Per objective, the bounds `[lo, hi]` of one removal's reward on the model's maps.
    pub reward_ranges: Vec<[f64; 2]>,
    /// Lines of `transitions.jsonl`.
    pub transitions: usize,
    /// Whether recording stopped at the limit before the search ended.
    pub capped: bool,
    /// Episodes the search ran (fewer than asked when it explored every sequence or was stopped).
    pub episodes_run: u64,
}

/// `index.json` of an `asp-transitions` data set.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TransitionsIndex {
    /// `asp-transitions`.
    pub format: String,
    /// [`VERSION`].
    pub version: u32,
    /// The state graph's features string (`asp-q/1 directions=D neighbours=K`).
    pub features: String,
    /// Node attribute width.
    pub node_dim: usize,
    /// Edge attribute width.
    pub edge_dim: usize,
    /// The objectives, in the order of every transition's `rewards`.
    pub objectives: Vec<String>,
    /// Base seed.
    pub seed: u64,
    /// Episodes per model.
    pub episodes: usize,
    /// The models.
    pub assemblies: Vec<TransitionsModel>,
}

/// One line of `transitions.jsonl`.
#[derive(Serialize)]
struct TransitionLine<'a> {
    episode: u64,
    kind: &'static str,
    present: Vec<usize>,
    history: Vec<usize>,
    actions: &'a [usize],
    action: usize,
    rewards: &'a [f64],
    next_history: Vec<usize>,
    next_actions: &'a [usize],
    complete: bool,
}

fn kind_name(kind: StepKind) -> &'static str {
    match kind {
        StepKind::Expansion => "expansion",
        StepKind::Simulation => "simulation",
        StepKind::Replay => "replay",
    }
}

fn history(problem: &Mdp, memory: &[u64]) -> Vec<usize> {
    direction_history(problem, memory).map(|m| m.iter().collect()).unwrap_or_default()
}

/// Checks the settings that do not depend on a model.
fn checked(settings: &TransitionSettings) -> Result<()> {
    if settings.optimise.episodes == 0 {
        return Err(AppError::config("episodes must be at least 1"));
    }
    if settings.optimise.budget == 0 {
        return Err(AppError::config("the search budget must be at least 1"));
    }
    if settings.limit == 0 {
        return Err(AppError::config("the transitions limit must be at least 1"));
    }
    Ok(asp_search::extension::check_objective_names(&settings.optimise.objectives, &settings.optimise.extensions)?)
}

/// Collects the transitions of `models` into `out` (created; files of the format are
/// overwritten): every model in parallel, then `index.json`. `progress` is called after each
/// model with its entry (from the worker thread that collected it).
pub fn collect_transitions(
    models: &[PathBuf],
    out: &Path,
    settings: &TransitionSettings,
    progress: &(dyn Fn(&TransitionsModel) + Sync),
) -> Result<TransitionsIndex> {
    checked(settings)?;
    if models.is_empty() {
        return Err(AppError::config("no models given"));
    }
    std::fs::create_dir_all(out).map_err(|e| io_error(out, e))?;
    let collected: Vec<Result<(TransitionsModel, QGraphConfig, Vec<String>)>> = collect::model_items(models)
        .par_iter()
        .map(|item| {
            let r = collect_one(item, out, settings)?;
            progress(&r.0);
            Ok(r)
        })
        .collect();
    let collected = collected.into_iter().collect::<Result<Vec<_>>>()?;
    let (_, graph, objectives) = collected.first().cloned().expect("at least one model");
    for (entry, g, o) in &collected {
        if *g != graph || *o != objectives {
            return Err(AppError::config(format!(
                "model {}: its state graphs ({}, objectives {}) differ from the first model's ({}, objectives {})",
                entry.model,
                g.features(),
                o.join(","),
                graph.features(),
                objectives.join(",")
            )));
        }
    }
    let assemblies = collected.into_iter().map(|(entry, ..)| entry).collect();
    let index = index_of(&graph, objectives, settings.seed, settings.optimise.episodes, assemblies);
    collect::write_json(&out.join("index.json"), &index)?;
    Ok(index)
}

/// Collects the transitions of one model into `out/<item.dir>/transitions.jsonl` (the folder is
/// created) and returns its index entry. Depends only on the item, the settings and the seed.
pub fn collect_model_transitions(item: &ModelItem, out: &Path, settings: &TransitionSettings) -> Result<TransitionsModel> {
    checked(settings)?;
    collect_one(item, out, settings).map(|r| r.0)
}

fn collect_one(item: &ModelItem, out: &Path, settings: &TransitionSettings) -> Result<(TransitionsModel, QGraphConfig, Vec<String>)> {
    let seed = collect::seed_of(settings.seed, item.index, 0);
    let plan = PlanSettings { seed, ..settings.plan.clone() };
    let o = OptimiseSettings {
        pareto: settings.optimise.objectives.len() > 1,
        threads: Some(1),
        time_limit: None,
        ..settings.optimise.clone()
    };
    let assembly = Arc::new(pipeline::load(&item.path, &plan)?);
    let problem = pipeline::optimiser_problem(&assembly, &plan, &o)?.mdp;
    let (ranges, graph, objectives) = problem_entry(&problem)?;
    macro_rules! configure {
        ($builder:expr) => {{
            let mut b = $builder
                .budget(o.budget)
                .episodes(o.episodes)
                .threads(1)
                .seed(seed)
                .exploration(o.exploration)
                .record_transitions(true)
                .record_transitions_limit(settings.limit);
            if let Some(stop) = &plan.cancel {
                b = b.stop_token(stop.clone());
            }
            b.build()?
        }};
    }
    let outcome =
        if o.pareto { configure!(ParetoMcts::builder()).solve(&problem)? } else { configure!(Mcts::builder()).solve(&problem)? };
    let folder = out.join(&item.dir);
    std::fs::create_dir_all(&folder).map_err(|e| io_error(&folder, e))?;
    write_lines(&folder.join("transitions.jsonl"), &problem, &outcome.transitions)?;
    let mut entry = model_entry(item, &plan, &o, &problem, ranges)?;
    entry.transitions = outcome.transitions.len();
    entry.capped = outcome.transitions_capped;
    entry.episodes_run = outcome.stats.episodes;
    Ok((entry, graph, objectives))
}

/// The reward range of every objective of `problem` (learning normalises rewards by them), its
/// graph configuration and its objectives' names.
fn problem_entry(problem: &Mdp) -> Result<(Vec<[f64; 2]>, QGraphConfig, Vec<String>)> {
    let maps = problem.maps();
    let mut reward_ranges = Vec::with_capacity(problem.num_objectives());
    for objective in problem.objectives() {
        let Some((lo, hi)) = objective.reward_range(maps) else {
            return Err(AppError::config(format!(
                "objective '{}' has no reward range, so its rewards cannot be normalised for learning",
                objective.name()
            )));
        };
        reward_ranges.push([lo, hi]);
    }
    Ok((reward_ranges, QGraphConfig::for_maps(maps), problem.objective_names()))
}

/// The index entry of `item` searched on `problem` (built with `plan` and `o`), without its
/// transitions (`transitions`, `capped` and `episodes_run` are 0 and false).
fn model_entry(
    item: &ModelItem,
    plan: &PlanSettings,
    o: &OptimiseSettings,
    problem: &Mdp,
    reward_ranges: Vec<[f64; 2]>,
) -> Result<TransitionsModel> {
    let maps = problem.maps();
    let model = std::fs::canonicalize(&item.path).map_err(|e| io_error(&item.path, e))?;
    Ok(TransitionsModel {
        name: item.name.clone(),
        dir: item.dir.clone(),
        model: model.display().to_string(),
        load: LoadArgs { unit: plan.unit.as_ref().map(|u| u.name.clone()), up: plan.up.map(|a| a.to_string()), fixed: plan.fixed.clone() },
        maps: MapsArgs {
            objective: problem.objective_names().join(","),
            resolution: maps.hemisphere().resolution(),
            d_max: o.d_max,
            support: crate::request::Choice::name(o.support).into(),
            tolerance: plan.tolerance,
            contact_distance: plan.contact_distance,
            overlaps: plan.overlaps.name().into(),
            robot: robot_keys(o),
        },
        parts: maps.num_parts(),
        removable: problem.removals(),
        reward_ranges,
        transitions: 0,
        capped: false,
        episodes_run: 0,
    })
}

/// The robot's request keys of `o`, a URDF file's path made absolute (the data set is read
/// from another folder).
fn robot_keys(o: &OptimiseSettings) -> serde_json::Map<String, serde_json::Value> {
    let mut keys = o.robot_keys.clone();
    if let Some(serde_json::Value::String(name)) = keys.get("robot") {
        let is_catalogued = crate::catalogue::ROBOTS.iter().any(|r| r.name == name);
        if let (false, Ok(path)) = (is_catalogued, std::fs::canonicalize(name)) {
            keys.insert("robot".into(), path.display().to_string().into());
        }
    }
    keys
}

/// The `index.json` of a data set holding the transitions of one model searched on `problem`
/// (as `asp collect transitions` would write it, with no transitions yet): what a stepped
/// search (`asp.Assembly.search`) tells the online learner, which writes its episodes' lines
/// under `<item.dir>/transitions.jsonl` and keeps the counts up to date.
pub fn stepped_index(
    item: &ModelItem,
    plan: &PlanSettings,
    o: &OptimiseSettings,
    problem: &Mdp,
    episodes: usize,
) -> Result<TransitionsIndex> {
    let (ranges, graph, objectives) = problem_entry(problem)?;
    let entry = model_entry(item, plan, o, problem, ranges)?;
    Ok(index_of(&graph, objectives, plan.seed, episodes, vec![entry]))
}

/// The `index.json` of a data set of `assemblies` whose state graphs are `graph`'s.
fn index_of(
    graph: &QGraphConfig,
    objectives: Vec<String>,
    seed: u64,
    episodes: usize,
    assemblies: Vec<TransitionsModel>,
) -> TransitionsIndex {
    TransitionsIndex {
        format: FORMAT.into(),
        version: VERSION,
        features: graph.features(),
        node_dim: graph.node_dim(),
        edge_dim: graph.edge_dim(),
        objectives,
        seed,
        episodes,
        assemblies,
    }
}

/// Writes `transitions` as lines of `transitions.jsonl` (one JSON object and a newline each).
pub fn write_transition_lines(w: &mut dyn std::io::Write, problem: &Mdp, transitions: &[Transition]) -> std::io::Result<()> {
    for t in transitions {
        let line = TransitionLine {
            episode: t.episode,
            kind: kind_name(t.kind),
            present: t.present.iter().collect(),
            history: history(problem, &t.memory),
            actions: &t.actions,
            action: t.action,
            rewards: &t.rewards,
            next_history: history(problem, &t.next_memory),
            next_actions: &t.next_actions,
            complete: t.complete,
        };
        serde_json::to_writer(&mut *w, &line).map_err(std::io::Error::other)?;
        w.write_all(b"\n")?;
    }
    Ok(())
}

/// Writes one JSON line per transition.
fn write_lines(path: &Path, problem: &Mdp, transitions: &[Transition]) -> Result<()> {
    collect::write_atomic_with(path, |w| write_transition_lines(w, problem, transitions))
}
