//! Training data for the removability model (thesis 3.6.1): labelled states from vanilla DFS
//! runs, written in the `asp-removability` format (`docs/learning.md`).
//!
//! For every model, the collision world and the chapter-3 graph (descriptors of every part and
//! contact region) are built once. Then `runs` depth-first searches start from random initial
//! orderings (the thesis' vanilla: `shuffled`, one seed per run) and every state they expand is
//! recorded with the label of every present, non-fixed part: removable (it leaves along a
//! straight candidate direction and the rest stays stable) or not. Runs go in parallel; the
//! output depends only on the models, the settings and the seed.

use crate::error::{AppError, Result};
use crate::pipeline::{self, PlanSettings};
use asp_geom::graph::{AssemblyGraph, GraphConfig};
use asp_geom::{FeasibilityChecker, MotionKind, Outcome, PartSet};
use asp_search::BuiltinOrder;
use asp_search::Dfs;
use asp_search::{Budget, Problem};
use rayon::prelude::*;
use serde::Serialize;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::Duration;

/// The data set's format name.
pub const FORMAT: &str = "asp-removability";
/// The data set's format version.
pub const VERSION: u32 = 1;

/// Settings of a collection.
#[derive(Clone, Debug)]
pub struct CollectSettings {
    /// DFS runs per model, each from its own random initial ordering (thesis: 20).
    pub runs: usize,
    /// Base seed; run `r` of model `m` uses a seed derived from it, `m` and `r`.
    pub seed: u64,
    /// How models are loaded and tested (unit, up, tolerances, stability, path planner).
    pub plan: PlanSettings,
    /// Feature parameters.
    pub graph: GraphConfig,
    /// Removal tests per run before it stops (the states seen so far are kept). Default 20,000:
    /// one unlucky initial ordering can search hundreds of thousands of dead-end states.
    pub max_tests: Option<u64>,
    /// Wall-time cap per run, seconds.
    pub timeout: Option<f64>,
}

impl Default for CollectSettings {
    fn default() -> Self {
        CollectSettings {
            runs: 20,
            seed: 0,
            plan: PlanSettings::default(),
            graph: GraphConfig::default(),
            max_tests: Some(20_000),
            timeout: Some(60.0),
        }
    }
}

/// One model's entry in `index.json`.
#[derive(Clone, Debug, Serialize, serde::Deserialize)]
pub struct CollectedModel {
    /// The model's name (file or folder stem).
    pub name: String,
    /// Its folder in the data set.
    pub dir: String,
    /// Where it came from.
    pub source: String,
    /// Number of parts.
    pub parts: usize,
    /// Directed contact edges.
    pub edges: usize,
    /// States recorded over all runs.
    pub states: usize,
    /// Runs that found a complete sequence.
    pub runs_found: usize,
}

/// What a collection wrote.
#[derive(Clone, Debug, Serialize)]
pub struct Collected {
    /// `asp-removability`.
    pub format: String,
    /// [`VERSION`].
    pub version: u32,
    /// The feature string models must be trained and run on.
    pub features: String,
    /// Node attribute width.
    pub node_dim: usize,
    /// Edge attribute width.
    pub edge_dim: usize,
    /// Base seed.
    pub seed: u64,
    /// Runs per model.
    pub runs: usize,
    /// The checker whose tests labelled the states (`default`, `physics`; see
    /// [`PlanSettings::label_checker`]). A data set written before this key labels for `default`.
    pub checker: String,
    /// The models.
    pub assemblies: Vec<CollectedModel>,
}

#[derive(Serialize)]
struct GraphFile<'a> {
    name: &'a str,
    source: String,
    parts: Vec<PartFile<'a>>,
    edges: Vec<[usize; 2]>,
}

#[derive(Serialize)]
struct PartFile<'a> {
    name: &'a str,
    fixed: bool,
}

#[derive(Serialize, Default)]
struct StateLine {
    run: usize,
    step: usize,
    present: Vec<usize>,
    removable: Vec<usize>,
    /// The labelled parts that are not removable because every straight candidate motion collides.
    collision: Vec<usize>,
    /// The labelled parts that could leave but leave the rest unstable (the stability check of
    /// the data set's checker: contact graph or physics simulation).
    gravity: Vec<usize>,
    /// Under the robot checker: the labelled parts the geometry lets out but the arm cannot take
    /// out, by the arm's reason (its lift collides; no grasp it reaches without collision; no
    /// path to a grasp or to the drop-off). Absent from other checkers' data sets.
    #[serde(skip_serializing_if = "Option::is_none")]
    arm_blocked: Option<Vec<usize>>,
    #[serde(skip_serializing_if = "Option::is_none")]
    arm_no_grasp: Option<Vec<usize>>,
    #[serde(skip_serializing_if = "Option::is_none")]
    arm_no_path: Option<Vec<usize>>,
}

/// The checker whose labels a collection under `plan` records: the robot's with a robot (the
/// arm must also take each part out), else the physics simulation under the physics stability
/// check, else the default checker.
pub fn label_checker(plan: &PlanSettings) -> Result<asp_learn::Checker> {
    let checker = plan.label_checker();
    if checker != asp_learn::Checker::Robot && plan.checker_extension.is_some() {
        return Err(AppError::setting("grippers", "removability labels are collected with one gripper (or a robot), not with held parts"));
    }
    Ok(checker)
}

/// The label of every present, non-fixed part of `state` under `checker` (the run's: the
/// collision world's, or a robot's on top of `plain`), with the reason of each failure. A
/// robot's refusal is told from a collision by `plain`, the collision world's checker under
/// it: a part it lets out that the robot's checker refuses is the arm's failure, by the
/// robot's reason.
fn label_state(checker: &dyn FeasibilityChecker, plain: Option<&dyn FeasibilityChecker>, state: &PartSet) -> StateLine {
    let mut line = StateLine { present: state.iter().collect(), ..StateLine::default() };
    let mut arm: [Vec<usize>; 3] = Default::default();
    for p in state.iter().filter(|&p| !checker.is_fixed(p)) {
        match checker.test_removal(p, state, MotionKind::Linear) {
            Outcome::Removed(_) => line.removable.push(p),
            Outcome::Unstable { .. } => line.gravity.push(p),
            Outcome::Collision { .. } => match plain {
                Some(plain) if !matches!(plain.test_removal(p, state, MotionKind::Linear), Outcome::Collision { .. }) => {
                    // the arm's lists in the robot's reason order (blocked, no grasp, no path)
                    let reason = checker.refusal_reason(p, state);
                    arm[asp_robot::RobotFailure::REASONS.iter().position(|r| Some(*r) == reason).unwrap_or(0)].push(p);
                }
                _ => line.collision.push(p),
            },
        }
    }
    if plain.is_some() {
        let [blocked, no_grasp, no_path] = arm;
        (line.arm_blocked, line.arm_no_grasp, line.arm_no_path) = (Some(blocked), Some(no_grasp), Some(no_path));
    }
    line
}

/// The models named by `paths`: each `.glb`/`.gltf`/`.step`/`.stp` file; a folder holding such
/// files gives each of them (sorted); any other folder (of OBJ/STL parts) is one model.
pub fn model_paths(paths: &[PathBuf]) -> Result<Vec<PathBuf>> {
    let mut out = Vec::new();
    for p in paths {
        if p.is_dir() {
            let entries = std::fs::read_dir(p).map_err(|e| io_error(p, e))?;
            let mut gltf: Vec<PathBuf> = entries
                .filter_map(|e| e.ok().map(|e| e.path()))
                .filter(|f| {
                    let e = f.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
                    matches!(e.as_deref(), Some("glb" | "gltf" | "step" | "stp"))
                })
                .collect();
            gltf.sort();
            if gltf.is_empty() {
                out.push(p.clone());
            } else {
                out.extend(gltf);
            }
        } else {
            out.push(p.clone());
        }
    }
    if out.is_empty() {
        return Err(AppError::config("no models given"));
    }
    Ok(out)
}

pub(crate) fn io_error(path: &Path, e: std::io::Error) -> AppError {
    AppError::from(asp_geom::GeomError::Io { path: path.to_path_buf(), source: e })
}

/// The name of a model: its file stem, or its folder's name.
pub fn model_name(path: &Path) -> String {
    path.file_stem().or_else(|| path.file_name()).map(|s| s.to_string_lossy().into_owned()).unwrap_or_else(|| "model".into())
}

/// The models' names: their [`model_name`]s, with the parent folder's name in front
/// (`p1_profiles_000`) where two models would otherwise share one.
pub fn unique_names(models: &[PathBuf]) -> Vec<String> {
    let plain: Vec<String> = models.iter().map(|p| model_name(p)).collect();
    plain
        .iter()
        .zip(models)
        .map(|(name, path)| {
            if plain.iter().filter(|n| *n == name).count() > 1 {
                let parent = path.parent().and_then(|p| p.file_name()).map(|s| s.to_string_lossy().into_owned());
                parent.map_or_else(|| name.clone(), |p| format!("{p}_{name}"))
            } else {
                name.clone()
            }
        })
        .collect()
}

/// The seed of run `run` of the model at position `model` in a collection with base seed `base`.
pub(crate) fn seed_of(base: u64, model: usize, run: usize) -> u64 {
    asp_search::ordering::state_seed(base, &PartSet::empty(0), ((model as u64) << 32) | run as u64)
}

/// Collects the data set of `models` into `out` (created; existing files of the format are
/// overwritten). `progress` is called after each model with its name and entry.
pub fn collect(
    models: &[PathBuf],
    out: &Path,
    settings: &CollectSettings,
    progress: &(dyn Fn(&CollectedModel) + Sync),
) -> Result<Collected> {
    if settings.runs == 0 {
        return Err(AppError::config("the number of runs must be at least 1"));
    }
    settings.graph.validate()?;
    std::fs::create_dir_all(out).map_err(|e| io_error(out, e))?;
    let mut assemblies = Vec::new();
    for item in model_items(models) {
        let entry = collect_model(&item, out, settings)?;
        progress(&entry);
        assemblies.push(entry);
    }
    write_index(out, settings, assemblies)
}

/// One model of a data set: its file, its position in the list (run seeds derive from it), its
/// unique name and the folder of its files.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ModelItem {
    /// The model's file or folder.
    pub path: PathBuf,
    /// Its position in the list of models.
    pub index: usize,
    /// Its unique name ([`unique_names`]).
    pub name: String,
    /// The folder of its files in the data set: the name with unsafe characters replaced.
    pub dir: String,
}

/// The models of a data set as [`collect`] names and files them.
pub fn model_items(models: &[PathBuf]) -> Vec<ModelItem> {
    let mut used = std::collections::HashSet::new();
    models
        .iter()
        .zip(unique_names(models))
        .enumerate()
        .map(|(index, (path, name))| {
            let mut dir: String = name.chars().map(|c| if c.is_alphanumeric() || c == '-' || c == '_' { c } else { '_' }).collect();
            while !used.insert(dir.clone()) {
                dir.push('_');
            }
            ModelItem { path: path.clone(), index, name, dir }
        })
        .collect()
}

/// Writes the data set's `index.json` for the models collected into `out` (in list order).
pub fn write_index(out: &Path, settings: &CollectSettings, assemblies: Vec<CollectedModel>) -> Result<Collected> {
    let index = Collected {
        format: FORMAT.into(),
        version: VERSION,
        features: settings.graph.features(),
        node_dim: settings.graph.node_dim(),
        edge_dim: settings.graph.edge_dim(),
        seed: settings.seed,
        runs: settings.runs,
        checker: label_checker(&settings.plan)?.name().into(),
        assemblies,
    };
    write_json(&out.join("index.json"), &index)?;
    Ok(index)
}

/// Writes `value` as pretty JSON with a final newline to `path` ([`write_atomic`]): a data set's
/// `index.json`.
pub fn write_json(path: &Path, value: &impl Serialize) -> Result<()> {
    let json = serde_json::to_string_pretty(value).expect("the index serialises");
    write_atomic(path, format!("{json}\n").as_bytes())
}

/// Collects the states of one model into `out/<item.dir>/` (the folder is created): its graph
/// and the labelled states of `settings.runs` DFS runs. Depends only on the item, the settings
/// and the seed, so models can be collected in any order or on other machines (`asp.batch`).
pub fn collect_model(item: &ModelItem, out: &Path, settings: &CollectSettings) -> Result<CollectedModel> {
    if settings.runs == 0 {
        return Err(AppError::config("the number of runs must be at least 1"));
    }
    settings.graph.validate()?;
    label_checker(&settings.plan)?;
    let (path, m, name, dir) = (item.path.as_path(), item.index, item.name.as_str(), item.dir.as_str());
    let assembly = pipeline::load(path, &settings.plan)?;
    let checker = pipeline::checker(assembly, &settings.plan)?;
    let world = checker.world();
    let graph = AssemblyGraph::build(world, &settings.graph)?;
    let n = world.num_parts();
    let budget = Budget { max_tests: settings.max_tests, timeout: settings.timeout.map(Duration::from_secs_f64), ..Budget::default() };
    let robot = match label_checker(&settings.plan)? {
        asp_learn::Checker::Robot => settings.plan.checker_extension.as_ref(),
        _ => None,
    };
    // one run: a DFS from its own initial ordering, then every state it expanded labelled by
    // the same checker (a robot's checker keeps the arm's plans, so the search's tests are
    // not planned twice)
    let run = |r: usize| -> Result<(Vec<StateLine>, bool)> {
        let seed = seed_of(settings.seed, m, r);
        // the thesis' linear sequences: the labelled states are reached one part at a time
        let dfs = Dfs::builder()
            .ordering(BuiltinOrder::Shuffled)
            .path_planner(settings.plan.path_planner)
            .subassemblies(false)
            .seed(seed)
            .build();
        let mut lines = Vec::new();
        let mut search = |c: &dyn FeasibilityChecker| -> asp_search::Result<asp_search::PlanOutcome> {
            let mut states = Vec::new();
            let mut visit = |s: &PartSet| states.push(s.clone());
            let outcome = dfs.solve_visiting(&Problem::full(c), &budget, Some(&mut visit));
            let plain: Option<&dyn FeasibilityChecker> = robot.map(|_| &checker as &dyn FeasibilityChecker);
            lines = states.iter().enumerate().map(|(step, state)| StateLine { run: r, step, ..label_state(c, plain, state) }).collect();
            Ok(outcome)
        };
        let outcome = match robot {
            Some(ext) => ext.solve(&checker, seed, &mut search)?.0,
            None => search(&checker)?,
        };
        Ok((lines, outcome.status == asp_search::Status::Found))
    };
    let runs: Vec<(Vec<StateLine>, bool)> = (0..settings.runs).into_par_iter().map(run).collect::<Result<_>>()?;
    let lines: Vec<&Vec<StateLine>> = runs.iter().map(|(lines, _)| lines).collect();
    let folder = out.join(dir);
    std::fs::create_dir_all(&folder).map_err(|e| io_error(&folder, e))?;
    let assembly = world.assembly();
    let graph_file = GraphFile {
        name,
        source: path.display().to_string(),
        parts: assembly.parts.iter().map(|p| PartFile { name: &p.name, fixed: p.fixed }).collect(),
        edges: graph.edges().iter().map(|&(s, t)| [s, t]).collect(),
    };
    let json = serde_json::to_string(&graph_file).expect("the graph serialises");
    write_atomic(&folder.join("graph.json"), format!("{json}\n").as_bytes())?;
    write_atomic(&folder.join("nodes.npy"), &npy_f32(graph.nodes_flat(), n, graph.node_dim()))?;
    write_atomic(&folder.join("edge_attr.npy"), &npy_f32(graph.edge_attr_flat(), graph.edges().len(), graph.edge_dim()))?;
    let mut text = Vec::new();
    let mut count = 0;
    for line in lines.into_iter().flatten() {
        serde_json::to_writer(&mut text, line).expect("state lines serialise");
        text.push(b'\n');
        count += 1;
    }
    write_atomic(&folder.join("states.jsonl"), &text)?;
    Ok(CollectedModel {
        name: name.into(),
        dir: dir.into(),
        source: path.display().to_string(),
        parts: n,
        edges: graph.edges().len(),
        states: count,
        runs_found: runs.iter().filter(|(_, found)| *found).count(),
    })
}

/// A NumPy `.npy` (version 1.0) file of a C-order float32 matrix.
pub fn npy_f32(data: &[f32], rows: usize, cols: usize) -> Vec<u8> {
    debug_assert_eq!(data.len(), rows * cols);
    let mut header = format!("{{'descr': '<f4', 'fortran_order': False, 'shape': ({rows}, {cols}), }}");
    // magic (6) + version (2) + header length (2) + header + newline, padded to 64 bytes
    let total = 10 + header.len() + 1;
    header.push_str(&" ".repeat((64 - total % 64) % 64));
    header.push('\n');
    let mut out = Vec::with_capacity(10 + header.len() + 4 * data.len());
    out.extend_from_slice(b"\x93NUMPY\x01\x00");
    out.extend_from_slice(&(header.len() as u16).to_le_bytes());
    out.extend_from_slice(header.as_bytes());
    for v in data {
        out.extend_from_slice(&v.to_le_bytes());
    }
    out
}

/// Writes `bytes` to `path` through a temporary file in the same folder and a rename, so a
/// reader never sees half a file.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    write_atomic_with(path, |w| w.write_all(bytes))
}

/// Like [`write_atomic`], with the contents streamed by `write` (buffered).
pub fn write_atomic_with(path: &Path, write: impl FnOnce(&mut dyn Write) -> std::io::Result<()>) -> Result<()> {
    let tmp = path.with_extension(format!("{}.tmp", path.extension().and_then(|e| e.to_str()).unwrap_or("")));
    let run = || -> std::io::Result<()> {
        let mut f = std::io::BufWriter::new(std::fs::File::create(&tmp)?);
        write(&mut f)?;
        let f = f.into_inner().map_err(|e| e.into_error())?;
        f.sync_all()?;
        std::fs::rename(&tmp, path)
    };
    run().map_err(|e| io_error(path, e))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn npy_header_is_aligned_and_parsable() {
        let bytes = npy_f32(&[1.0, 2.0, 3.0, 4.0, 5.0, 6.0], 2, 3);
        assert_eq!(&bytes[..8], b"\x93NUMPY\x01\x00");
        let len = u16::from_le_bytes([bytes[8], bytes[9]]) as usize;
        assert_eq!((10 + len) % 64, 0);
        let header = std::str::from_utf8(&bytes[10..10 + len]).unwrap();
        assert!(header.contains("'shape': (2, 3)") && header.ends_with('\n'), "{header}");
        assert_eq!(bytes.len(), 10 + len + 24);
        assert_eq!(f32::from_le_bytes(bytes[10 + len + 20..].try_into().unwrap()), 6.0);
    }
}
