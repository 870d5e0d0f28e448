//! `asp._asp.Assembly`: a loaded model, owned by the handle (no borrow of anything else), and
//! `asp._asp.load`.

use crate::errors::Error;
use crate::{run, settings};
use asp_search::pipeline::{self, PlanSettings};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::path::PathBuf;
use std::sync::Arc;

/// A loaded model: its parts in file order, units, up axis and the load's warnings. Immutable;
/// every plan starts from it afresh.
#[pyclass(frozen, module = "asp._asp", name = "Assembly")]
pub struct PyAssembly {
    inner: Arc<asp_geom::Assembly>,
}

impl PyAssembly {
    /// The Rust assembly.
    pub fn assembly(&self) -> &asp_geom::Assembly {
        &self.inner
    }
}

/// Loads the model at `path` (a `.glb`/`.gltf` file or a folder of `.obj`/`.stl` files, one part
/// each) with an optional unit (`m`, `mm`, ... or metres per unit), up axis (`z`, `-y`, ...) and
/// base part names; errors are `asp.LoadError` (naming the file) or `asp.ConfigError`.
#[pyfunction]
#[pyo3(signature = (path, unit=None, up=None, fixed=Vec::new()))]
pub fn load(py: Python<'_>, path: PathBuf, unit: Option<&str>, up: Option<&str>, fixed: Vec<String>) -> PyResult<PyAssembly> {
    let settings = PlanSettings {
        unit: unit.map(settings::unit).transpose().map_err(|e| e.into_py(py))?,
        up: up.map(settings::axis).transpose().map_err(|e| e.into_py(py))?,
        fixed,
        ..PlanSettings::default()
    };
    let assembly = py.detach(|| pipeline::load(&path, &settings)).map_err(|e| Error::from(e).into_py(py))?;
    Ok(PyAssembly { inner: Arc::new(assembly) })
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
    /// search trace as CSV (as `--trace` writes it). Releases the GIL; Ctrl-C interrupts a
    /// depth-first search.
    fn plan(&self, py: Python<'_>, settings: &Bound<'_, PyDict>) -> PyResult<(String, bool, Option<String>)> {
        let settings = settings::plan_settings(settings).map_err(|e| e.into_py(py))?;
        let result = run::plan(py, (*self.inner).clone(), &settings)?;
        let trace = match &result.search {
            Some(search) => {
                let mut csv = Vec::new();
                search
                    .write_trace_csv(&mut csv)
                    .map_err(|e| Error::config(format!("cannot write the trace: {e}")).into_py(py))?;
                Some(String::from_utf8_lossy(&csv).into_owned())
            }
            None => None,
        };
        Ok((result.report.to_json(), result.found(), trace))
    }

    fn __repr__(&self) -> String {
        format!("<asp._asp.Assembly {} ({} parts, {}, up {})>", self.source(), self.inner.len(), self.units(), self.up())
    }
}
