//! `asp._asp.Assembly`: a loaded model, owned by the handle (no borrow of anything else), and
//! `asp._asp.load`.

use crate::arrays::GraphArrays;
use crate::errors::Error;
use crate::qgraphs::PyQGraphs;
use crate::search::PySearch;
use crate::settings::GraphSettings;
use crate::{run, settings};
use asp_app::pipeline;
use asp_geom::{AssemblyGraph, PartSet, World};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::path::PathBuf;
use std::sync::{Arc, Mutex};

/// A loaded model: its parts in file order, units, up axis and the load's warnings. Immutable;
/// every plan starts from it afresh.
#[pyclass(frozen, module = "asp._asp", name = "Assembly")]
pub struct PyAssembly {
    inner: Arc<asp_geom::Assembly>,
    /// The model's graph for the settings last asked (computed once, states are subgraphs).
    graph: Mutex<Option<(GraphSettings, Arc<AssemblyGraph>)>>,
}

impl PyAssembly {
    /// The Rust assembly.
    pub fn assembly(&self) -> &asp_geom::Assembly {
        &self.inner
    }

    /// The model's graph for `settings`: from the cache, or built (collision world, then
    /// descriptors) and cached.
    pub fn model_graph(&self, settings: &GraphSettings) -> Result<Arc<AssemblyGraph>, Error> {
        let mut cache = self.graph.lock().unwrap_or_else(|e| e.into_inner());
        if let Some((cached, graph)) = cache.as_ref() {
            if cached.same_graph(settings) {
                return Ok(graph.clone());
            }
        }
        let config = pipeline::world_config(&self.inner, &settings.world)?;
        let world = World::new((*self.inner).clone(), &config)?;
        let graph = Arc::new(AssemblyGraph::build(&world, &settings.config)?);
        *cache = Some((settings.clone(), graph.clone()));
        Ok(graph)
    }
}

/// Loads the model at `path` (a `.glb`/`.gltf` file, a `.step`/`.stp` file or a folder of
/// `.obj`/`.stl` files, one part each) with an optional unit (`m`, `mm`, ... or metres per unit),
/// up axis (`z`, `-y`, ...), base part names, STEP tessellation tolerance and whether each body
/// of a part's mesh becomes a part of its own (`split_bodies`), under the caps and
/// the file rule of `docs/security.md`; errors are `asp.LoadError` (naming the file) or
/// `asp.ConfigError`. `step_glb`: the GLB that cascadio made of the STEP file in this process
/// (`asp.load` passes it), read instead of running the converter.
#[pyfunction]
#[pyo3(signature = (path, unit=None, up=None, fixed=Vec::new(), max_triangles=None, max_parts=None, allow_outside_files=None, tessellation=None, split_bodies=None, step_glb=None))]
#[allow(clippy::too_many_arguments)]
pub fn load(
    py: Python<'_>,
    path: PathBuf,
    unit: Option<&str>,
    up: Option<&str>,
    fixed: Vec<String>,
    max_triangles: Option<usize>,
    max_parts: Option<usize>,
    allow_outside_files: Option<bool>,
    tessellation: Option<f64>,
    split_bodies: Option<bool>,
    step_glb: Option<Vec<u8>>,
) -> PyResult<PyAssembly> {
    let request = asp_app::PlanRequest {
        tessellation,
        split_bodies,
        unit: unit.map(String::from),
        up: up.map(String::from),
        fixed,
        max_triangles,
        max_parts,
        allow_outside_files,
        ..Default::default()
    };
    let settings = asp_app::resolve(&request).map_err(|e| Error::from(e).into_py(py))?;
    let load = || -> asp_app::Result<asp_geom::Assembly> {
        let Some(glb) = &step_glb else { return pipeline::load(&path, &settings) };
        let options = pipeline::load_options(&path, &settings)?;
        let step = std::fs::read(&path).map_err(|source| asp_geom::GeomError::Io { path: path.clone(), source })?;
        Ok(asp_geom::io::step::assemble(&path, &step, glb, &options)?)
    };
    let assembly = py.detach(load).map_err(|e| Error::from(e).into_py(py))?;
    Ok(PyAssembly { inner: Arc::new(assembly), graph: Mutex::new(None) })
}

#[pymethods]
impl PyAssembly {
    /// The parts in file order: `(index, name, fixed)`.
    fn parts(&self) -> Vec<(usize, String, bool)> {
        self.inner.parts.iter().enumerate().map(|(i, p)| (i, p.name.clone(), p.fixed)).collect()
    }

    /// The model file or folder, as given to `load`.
    #[getter]
    fn source(&self) -> String {
        self.inner.source.display().to_string()
    }

    /// The model's unit name (`m`, `mm`, ...).
    #[getter]
    fn units(&self) -> String {
        self.inner.units.name.clone()
    }

    /// Metres per model unit.
    #[getter]
    fn metres_per_unit(&self) -> f64 {
        self.inner.units.metres
    }

    /// The up axis (`+z`, `-y`, ...).
    #[getter]
    fn up(&self) -> String {
        self.inner.up.to_string()
    }

    /// Non-fatal problems found while loading, one line each.
    #[getter]
    fn warnings(&self) -> Vec<String> {
        self.inner.warnings.clone()
    }

    fn __len__(&self) -> usize {
        self.inner.len()
    }

    /// Plans with the keyword settings of `asp.Assembly.plan` (a dict; missing keys take the
    /// defaults). Returns `(plan_json, found, trace_csv)`: the plan JSON exactly as
    /// `asp plan --json` prints it, whether a sequence was found, and for optimising runs the
    /// search trace as CSV (as `--trace` writes it). Releases the GIL; Ctrl-C interrupts the
    /// search (see [`run`]).
    fn plan(&self, py: Python<'_>, settings: &Bound<'_, PyDict>) -> PyResult<(String, bool, Option<String>)> {
        let settings = settings::plan_settings(settings).map_err(|e| e.into_py(py))?;
        let result = run::plan(py, (*self.inner).clone(), &settings)?;
        let trace = match &result.search {
            Some(search) => {
                let mut csv = Vec::new();
                search.write_trace_csv(&mut csv).map_err(|e| Error::config(format!("cannot write the trace: {e}")).into_py(py))?;
                Some(String::from_utf8_lossy(&csv).into_owned())
            }
            None => None,
        };
        Ok((result.report.to_json(), result.found(), trace))
    }

    /// Checks a given sequence (the text of a sequence file or a plan JSON, docs/check-format.md)
    /// with the keyword settings of `asp.Assembly.plan` (a dict). Returns `(report_json,
    /// feasible)`: the check report exactly as `asp check --json` prints it. Releases the GIL;
    /// Ctrl-C interrupts the repair search.
    fn check(&self, py: Python<'_>, sequence: &str, settings: &Bound<'_, PyDict>) -> PyResult<(String, bool)> {
        let settings = settings::plan_settings(settings).map_err(|e| e.into_py(py))?;
        let steps = asp_app::check::parse_sequence(sequence).map_err(|e| Error::from(e).into_py(py))?;
        let token = asp_search::StopToken::new();
        let settings = asp_app::PlanSettings { cancel: Some(token.clone()), ..settings };
        let assembly = (*self.inner).clone();
        let result = run::interruptible(py, &token, move || asp_app::check::check_assembly(assembly, &steps, &settings))?;
        let report = result.map_err(|e| Error::from(e).into_py(py))?;
        Ok((report.to_json(), report.feasible()))
    }

    /// The graph of the state `present` (part indices) with the keyword settings of
    /// `asp.Assembly.graph` (a dict), as little-endian buffers ([`GraphArrays`]). The model's
    /// graph is built once per settings (without the GIL) and cached.
    fn graph<'py>(&self, py: Python<'py>, present: Vec<i64>, settings: &Bound<'py, PyDict>) -> PyResult<GraphArrays> {
        let settings = settings::graph_settings(settings).map_err(|e| e.into_py(py))?;
        let n = self.inner.len();
        let mut state = PartSet::empty(n);
        for &p in &present {
            match usize::try_from(p) {
                Ok(i) if i < n => state.insert(i),
                _ => {
                    let message = format!("present: no part {p} (the model has {n} parts, 0 to {})", n.saturating_sub(1));
                    return Err(Error::config(message).into_py(py));
                }
            }
        }
        let (graph, features) = py
            .detach(|| {
                self.model_graph(&settings).map(|model| {
                    let features = model.features();
                    (model.state(&state), features)
                })
            })
            .map_err(|e| e.into_py(py))?;
        Ok(GraphArrays::new(
            py,
            graph.nodes.iter().map(|&i| i as i64),
            &graph.x,
            graph.edge_index.iter().copied(),
            &graph.edge_attr,
            graph.node_dim,
            graph.edge_dim,
            features,
        ))
    }

    /// The distance maps and MDP of this model for the keywords of `asp.Assembly.q_graphs`
    /// (a dict), as a handle that gives the `asp-q/1` graph of any state (built without the GIL).
    fn q_graphs(&self, py: Python<'_>, settings: &Bound<'_, PyDict>) -> PyResult<PyQGraphs> {
        PyQGraphs::build(py, self.inner.clone(), settings)
    }

    /// A stepped optimiser run with the keyword settings of `asp.Assembly.plan` (a dict with an
    /// objective), recording every episode's transitions when `record` is set (see
    /// `crate::search`). The maps are built here, without the GIL.
    fn search(&self, py: Python<'_>, settings: &Bound<'_, PyDict>, record: bool) -> PyResult<PySearch> {
        PySearch::start(py, self.inner.clone(), settings, record)
    }

    fn __repr__(&self) -> String {
        format!("<asp._asp.Assembly {} ({} parts, {}, up {})>", self.source(), self.inner.len(), self.units(), self.up())
    }
}
