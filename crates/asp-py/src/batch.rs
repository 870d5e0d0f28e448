//! The items of `asp.batch` (py/asp/batch/): one generated assembly, one model's collected states,
//! one model's benchmark rows. Each is a function of its own inputs only, so a batch gives the
//! same files whether it runs in a serial loop, as Ray tasks or on other machines, and a resumed
//! batch can skip what is done. Results cross the boundary as JSON strings (the formats of
//! `docs/generators.md` and `docs/learning.md`), which Ray ships between processes as they are.
//! Every item releases the GIL.

use crate::errors::Error;
use crate::settings;
use asp_app::bench::{self, BenchRow};
use asp_app::collect::{self, CollectSettings, CollectedModel, ModelItem};
use asp_app::PlanSettings;
use asp_gen::batch::{self, Batch, Generator};
use asp_gen::manifest::ManifestEntry;
use asp_gen::{GenError, ProfileParams};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::path::{Path, PathBuf};

fn json_error(what: &str, e: serde_json::Error) -> Error {
    Error::config(format!("{what}: {e}"))
}

fn generator(json: &str) -> Result<Generator, Error> {
    let generator: Generator = serde_json::from_str(json).map_err(|e| json_error("generator", e))?;
    generator.validate()?;
    Ok(generator)
}

/// The parameters of a profile-assembly preset (`single-layer`, `double-layer`) as JSON.
#[pyfunction]
pub fn profile_preset(py: Python<'_>, name: &str) -> PyResult<String> {
    let Some(params) = ProfileParams::preset(name) else {
        let message = format!("unknown preset '{name}' (use {})", ProfileParams::PRESETS.join(" or "));
        return Err(Error::config(message).into_py(py));
    };
    Ok(serde_json::to_string(&params).expect("parameters serialise"))
}

/// The generator of `generator_json` checked and in its canonical JSON form (every field, in
/// order), the form a batch records to recognise its own settings when it resumes.
#[pyfunction]
pub fn generator_canonical(py: Python<'_>, generator_json: &str) -> PyResult<String> {
    let g = generator(generator_json).map_err(|e| e.into_py(py))?;
    Ok(serde_json::to_string(&g).expect("generators serialise"))
}

/// Generates assembly `index` of a batch of `count` with batch seed `seed` into `out` (its GLB,
/// written through a temporary file and a rename) and returns its manifest entry as JSON.
#[pyfunction]
pub fn gen_item(py: Python<'_>, generator_json: &str, index: usize, count: usize, seed: u64, out: PathBuf) -> PyResult<String> {
    let g = generator(generator_json).map_err(|e| e.into_py(py))?;
    if index >= count {
        return Err(Error::config(format!("index {index} is not below the count {count}")).into_py(py));
    }
    py.detach(|| -> Result<String, Error> {
        let (generated, entry) = batch::generate_item(&g, index, count, seed)?;
        std::fs::create_dir_all(&out).map_err(|source| GenError::Io { path: out.clone(), source })?;
        let path = out.join(&entry.file);
        let tmp = out.join(format!(".{}.tmp", entry.file));
        asp_geom::io::write_glb(&generated.assembly, &tmp)?;
        std::fs::rename(&tmp, &path).map_err(|source| GenError::Io { path: path.clone(), source })?;
        Ok(serde_json::to_string(&entry).expect("entries serialise"))
    })
    .map_err(|e| e.into_py(py))
}

/// Writes `out/manifest.json` of a batch from the entries [`gen_item`] returned (any order) and
/// returns it as JSON: the same file `asp gen` writes for the same generator, count and seed.
#[pyfunction]
#[pyo3(signature = (generator_json, preset, count, seed, entries, out))]
pub fn gen_manifest(
    py: Python<'_>,
    generator_json: &str,
    preset: Option<String>,
    count: usize,
    seed: u64,
    entries: Vec<String>,
    out: PathBuf,
) -> PyResult<String> {
    let run = || -> Result<String, Error> {
        let generator = generator(generator_json)?;
        let entries = entries
            .iter()
            .map(|e| serde_json::from_str::<ManifestEntry>(e).map_err(|e| json_error("manifest entry", e)))
            .collect::<Result<Vec<_>, _>>()?;
        let manifest = batch::write_manifest(&Batch { generator, preset, count, seed }, entries, &out)?;
        Ok(serde_json::to_string(&manifest).expect("manifests serialise"))
    };
    run().map_err(|e| e.into_py(py))
}

/// The models of `paths` (files, folders of GLB/glTF files, folders of parts) as a data set
/// names them: `(path, index, name, dir)` each.
#[pyfunction]
pub fn model_items(py: Python<'_>, paths: Vec<PathBuf>) -> PyResult<Vec<(String, usize, String, String)>> {
    let models = collect::model_paths(&paths).map_err(|e| Error::from(e).into_py(py))?;
    Ok(collect::model_items(&models).into_iter().map(|m| (m.path.display().to_string(), m.index, m.name, m.dir)).collect())
}

/// Plan settings from `asp.Assembly.plan`'s keywords and `asp.load`'s (`load`: `unit`, `up`,
/// `fixed`, `max_triangles`, `max_parts`, `tessellation`, `split_bodies`).
fn model_settings(dict: &Bound<'_, PyDict>, load: Option<&Bound<'_, PyDict>>) -> Result<PlanSettings, Error> {
    let mut request = settings::request(dict, false)?;
    if let Some(load) = load {
        for key in load.keys() {
            let key = key.to_string();
            if !asp_app::request::is_load_key(&key) {
                return Err(Error::config(format!("load: '{key}' is not a setting of asp.load")));
            }
        }
        let l = settings::request(load, true)?;
        (request.unit, request.up, request.fixed, request.max_triangles, request.max_parts, request.tessellation, request.split_bodies) =
            (l.unit, l.up, l.fixed, l.max_triangles, l.max_parts, l.tessellation, l.split_bodies);
    }
    Ok(asp_app::resolve(&request)?)
}

/// What one model of a plan batch gave: `Ok((status, found, parts, steps, removal_tests,
/// seconds))` (the plan's status as the plan JSON spells it, its assembly steps, the seconds of
/// loading and planning) or `Err(message)`, one line naming the file, as `asp.AspError`'s text.
pub type PlanItem = Result<(String, bool, usize, usize, u64, f64), String>;

/// A [`PlanItem`] as Python gets it: `(error, status, found, parts, steps, removal_tests,
/// seconds)`, the error `None` or the other fields empty.
pub type PlanRow = (Option<String>, String, bool, usize, usize, u64, f64);

fn plan_row(item: PlanItem) -> PlanRow {
    match item {
        Ok((status, found, parts, steps, tests, seconds)) => (None, status, found, parts, steps, tests, seconds),
        Err(message) => (Some(message), String::new(), false, 0, 0, 0, 0.0),
    }
}

/// Writes `bytes` to `.<name>.tmp` beside `path`, then renames it to `path`, as the batch's
/// Python side writes its files: a kill never leaves half a file under the real name. Without
/// the fsync of `asp_geom::io::write_atomic` (a batch's journal, not the disk, says what is
/// done; an fsync per small plan cost more than planning it).
fn write_replacing(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    let tmp = path.with_file_name(format!(".{name}.tmp"));
    std::fs::write(&tmp, bytes)?;
    std::fs::rename(&tmp, path)
}

/// Loads and plans one model as `asp plan` does for each model of `--each` (the load's seconds
/// into the plan's timings) and writes its plan JSON to `file` ([`write_replacing`]): the bytes
/// `asp plan MODEL --json` prints, timings apart.
fn plan_item(model: &Path, file: &Path, settings: &PlanSettings) -> PlanItem {
    let started = std::time::Instant::now();
    let run = || -> Result<_, Error> {
        let assembly = asp_app::pipeline::load(model, settings)?;
        let parts = assembly.len();
        let load_seconds = started.elapsed().as_secs_f64();
        let mut result = asp_app::pipeline::plan_assembly(assembly, settings, None)?;
        if let Some(t) = result.report.stats.timings.as_mut() {
            t.load = load_seconds;
        }
        let report = &result.report;
        write_replacing(file, report.to_json().as_bytes()).map_err(|e| Error {
            kind: crate::errors::Kind::Other,
            message: format!("{}: cannot write the plan ({e})", file.display()),
            path: None,
        })?;
        let status = match serde_json::to_value(report.status) {
            Ok(serde_json::Value::String(s)) => s,
            _ => format!("{:?}", report.status),
        };
        Ok((status, result.found(), parts, report.assembly_sequence.len(), report.stats.removal_tests))
    };
    match run() {
        Ok((status, found, parts, steps, tests)) => Ok((status, found, parts, steps, tests, started.elapsed().as_secs_f64())),
        Err(e) => Err(e.message),
    }
}

/// Plans a chunk of models of a plan batch with the same settings: `models` are
/// `(model path, plan file name)` pairs, each plan written to `out/<file>`. The settings (the
/// keywords of `asp.Assembly.plan`, and `asp.load`'s in `load`) are resolved once for the chunk,
/// and the models planned in parallel on rayon's pool (one thread in a Ray task), the GIL
/// released and Ctrl-C watched as in `Assembly.plan`. One result per model, in order
/// ([`PlanRow`]): a model that cannot be loaded or planned, or settings that are wrong, give
/// their error for that model (for every model, for the settings); only an interrupt raises.
#[pyfunction]
#[pyo3(signature = (models, out, settings, load=None))]
pub fn plan_items(
    py: Python<'_>,
    models: Vec<(PathBuf, String)>,
    out: PathBuf,
    settings: &Bound<'_, PyDict>,
    load: Option<&Bound<'_, PyDict>>,
) -> PyResult<Vec<PlanRow>> {
    let settings = match model_settings(settings, load) {
        Ok(s) => s,
        Err(e) => return Ok(models.iter().map(|_| plan_row(Err(e.message.clone()))).collect()),
    };
    let token = asp_search::StopToken::new();
    let settings = PlanSettings { cancel: Some(token.clone()), ..settings };
    crate::run::interruptible(py, &token, || {
        use rayon::prelude::*;
        models.par_iter().map(|(model, file)| plan_row(plan_item(model, &out.join(file), &settings))).collect()
    })
}

fn collect_settings(runs: usize, seed: u64, max_tests: Option<u64>, timeout: Option<f64>, plan: PlanSettings) -> CollectSettings {
    CollectSettings { runs, seed, plan, max_tests, timeout, ..CollectSettings::default() }
}

/// Collects the labelled states of one model (`asp collect removability`'s work for one model)
/// into `out/<dir>/` and returns its index entry as JSON.
#[pyfunction]
#[pyo3(signature = (path, index, name, dir, out, runs, seed, max_tests, timeout, settings, load=None))]
#[allow(clippy::too_many_arguments)]
pub fn collect_item(
    py: Python<'_>,
    path: PathBuf,
    index: usize,
    name: String,
    dir: String,
    out: PathBuf,
    runs: usize,
    seed: u64,
    max_tests: Option<u64>,
    timeout: Option<f64>,
    settings: &Bound<'_, PyDict>,
    load: Option<&Bound<'_, PyDict>>,
) -> PyResult<String> {
    let plan = model_settings(settings, load).map_err(|e| e.into_py(py))?;
    let settings = collect_settings(runs, seed, max_tests, timeout, plan);
    let item = ModelItem { path, index, name, dir };
    let entry = py.detach(|| collect::collect_model(&item, &out, &settings)).map_err(|e| Error::from(e).into_py(py))?;
    Ok(serde_json::to_string(&entry).expect("entries serialise"))
}

/// Writes the data set's `index.json` from the entries [`collect_item`] returned (in model
/// order) and returns it as JSON. `settings` and `load` are the items' (the index names the
/// checker they labelled for: a physics or robot data set must not read as `default`).
#[pyfunction]
#[pyo3(signature = (out, runs, seed, entries, settings, load=None))]
pub fn collect_index(
    py: Python<'_>,
    out: PathBuf,
    runs: usize,
    seed: u64,
    entries: Vec<String>,
    settings: &Bound<'_, PyDict>,
    load: Option<&Bound<'_, PyDict>>,
) -> PyResult<String> {
    let plan = model_settings(settings, load).map_err(|e| e.into_py(py))?;
    let run = || -> Result<String, Error> {
        let entries = entries
            .iter()
            .map(|e| serde_json::from_str::<CollectedModel>(e).map_err(|e| json_error("index entry", e)))
            .collect::<Result<Vec<_>, _>>()?;
        let settings = collect_settings(runs, seed, None, None, plan);
        let index = collect::write_index(&out, &settings, entries)?;
        Ok(serde_json::to_string(&index).expect("the index serialises"))
    };
    run().map_err(|e| e.into_py(py))
}

/// The benchmark rows of one model (`asp bench feasible`'s work for one model) as JSON.
/// `methods` is the comma-separated list (default: the cheap orderings, and the learned ones
/// when `model` is given); `model` is the ONNX file of the `gnn` methods (default: shipped).
#[pyfunction]
#[pyo3(signature = (path, name, orderings, settings, methods=None, model=None, load=None))]
#[allow(clippy::too_many_arguments)]
pub fn bench_item(
    py: Python<'_>,
    path: PathBuf,
    name: String,
    orderings: usize,
    settings: &Bound<'_, PyDict>,
    methods: Option<String>,
    model: Option<String>,
    load: Option<&Bound<'_, PyDict>>,
) -> PyResult<String> {
    let settings = model_settings(settings, load).map_err(|e| e.into_py(py))?;
    let list = methods.unwrap_or_else(|| bench::default_methods(model.is_some()).to_string());
    let methods =
        bench::parse_methods(&list, model.as_deref().map(Path::new), settings.label_checker()).map_err(|e| Error::from(e).into_py(py))?;
    let rows = py
        .detach(|| bench::bench_model(Path::new(&path), &name, &settings, &methods, orderings))
        .map_err(|e| Error::from(e).into_py(py))?;
    Ok(serde_json::to_string(&rows).expect("rows serialise"))
}

/// The table `asp bench feasible` prints, of rows (JSON lists of rows, concatenated in order).
#[pyfunction]
pub fn bench_table(py: Python<'_>, rows: Vec<String>) -> PyResult<String> {
    let mut all: Vec<BenchRow> = Vec::new();
    for r in &rows {
        let part: Vec<BenchRow> = serde_json::from_str(r).map_err(|e| json_error("benchmark rows", e).into_py(py))?;
        all.extend(part);
    }
    let mut out = Vec::new();
    bench::write_table(&mut out, &all).expect("writing to memory");
    Ok(String::from_utf8_lossy(&out).into_owned())
}

/// The table and CSV `asp bench mcts` writes, of its rows (JSON lists of `MctsRow`s,
/// concatenated in order): `(table, csv)`. `python -m asp.train bench-mcts` measures the
/// settings that train during the search and prints them through this.
#[pyfunction]
pub fn mcts_table(py: Python<'_>, rows: Vec<String>) -> PyResult<(String, String)> {
    let mut all: Vec<asp_app::bench_mcts::MctsRow> = Vec::new();
    for r in &rows {
        let part: Vec<asp_app::bench_mcts::MctsRow> = serde_json::from_str(r).map_err(|e| json_error("benchmark rows", e).into_py(py))?;
        all.extend(part);
    }
    let mut table = Vec::new();
    asp_app::bench_mcts::write_table(&mut table, &all).expect("writing to memory");
    Ok((String::from_utf8_lossy(&table).into_owned(), asp_app::bench_mcts::csv(&all)))
}
