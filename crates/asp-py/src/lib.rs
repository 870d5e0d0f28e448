//! The native module `asp._asp` of the `asp` Python package, built by maturin from this crate
//! (`py/pyproject.toml`). It is private: Python code uses the pure-Python package `asp` around
//! it (`py/asp/`), which documents the API, defines the exception types and builds numpy
//! arrays. This is the only crate of the workspace that depends on pyo3.
//!
//! - [`assembly`]: `load` and the `Assembly` handle (owns its data);
//! - [`arrays`]: a state graph's arrays (`GraphArrays`);
//! - [`settings`]: Python keywords into the plan request ([`asp_app::PlanRequest`]);
//! - [`qgraphs`]: the `asp-q/1` graphs of optimiser states (`Assembly.q_graphs`);
//! - [`run`]: the pipeline with the GIL released, interruptible by Ctrl-C;
//! - [`search`]: the stepped optimiser run of `Assembly.search` (online Q-learning);
//! - [`batch`]: the items of `asp.batch` (generation, plans in chunks, collection, benchmarks);
//! - [`errors`]: asp's errors as `asp.errors` exceptions.

pub mod arrays;
pub mod assembly;
pub mod batch;
pub mod errors;
pub mod qgraphs;
pub mod run;
pub mod search;
pub mod settings;

use pyo3::prelude::*;
use pyo3::types::PyDict;

/// The defaults of every keyword of `Assembly.plan`.
#[pyfunction]
fn default_settings(py: Python<'_>) -> PyResult<Bound<'_, PyDict>> {
    settings::default_settings(py)
}

/// The part orderings `order=` accepts (the catalogue's).
#[pyfunction]
fn order_names() -> Vec<&'static str> {
    settings::order_names()
}

/// The names of each closed setting (`order`, `overlaps`, `stability`, `support`, `q_use`), in
/// the order the docs list them: what `asp.settings`' `Literal` types must list.
#[pyfunction]
fn choices() -> std::collections::BTreeMap<&'static str, Vec<&'static str>> {
    use asp_app::settings::{Kind, SETTINGS};
    SETTINGS.iter().filter(|s| s.kind == Kind::Choice).map(|s| (s.key, (s.choices)().into_iter().map(|(n, _)| n).collect())).collect()
}

/// The plan JSON `json` as `asp plan` prints it (`Plan.table()`): the table and, for optimising
/// runs, the optimiser's summary; an `asp.AspError` when `json` is not a plan.
#[pyfunction]
fn plan_text(py: Python<'_>, json: &str) -> PyResult<String> {
    match serde_json::from_str::<asp_search::report::PlanReport>(json) {
        Ok(report) => Ok(report.to_text()),
        Err(e) => Err(errors::Error { kind: errors::Kind::Other, message: format!("plan JSON: not a plan ({e})"), path: None }.into_py(py)),
    }
}

/// asp's native module (private: use the `asp` package).
#[pymodule]
#[pyo3(name = "_asp")]
fn asp_native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add("PLAN_FORMAT_VERSION", asp_search::report::FORMAT_VERSION)?;
    m.add_function(wrap_pyfunction!(assembly::load, m)?)?;
    m.add("STEP_ANGULAR", asp_geom::io::step::DEFAULT_ANGULAR)?;
    m.add("STEP_RELATIVE", asp_geom::io::step::DEFAULT_RELATIVE)?;
    m.add("STEP_CONVERTER", asp_geom::io::step::CONVERTER)?;
    m.add_function(wrap_pyfunction!(default_settings, m)?)?;
    m.add_function(wrap_pyfunction!(order_names, m)?)?;
    m.add_function(wrap_pyfunction!(choices, m)?)?;
    m.add_function(wrap_pyfunction!(plan_text, m)?)?;
    m.add_class::<assembly::PyAssembly>()?;
    m.add_class::<qgraphs::PyQGraphs>()?;
    m.add_class::<search::PySearch>()?;
    m.add_class::<search::EpisodeReport>()?;
    m.add_class::<arrays::GraphArrays>()?;
    m.add_function(wrap_pyfunction!(batch::profile_preset, m)?)?;
    m.add_function(wrap_pyfunction!(batch::generator_canonical, m)?)?;
    m.add_function(wrap_pyfunction!(batch::gen_item, m)?)?;
    m.add_function(wrap_pyfunction!(batch::gen_manifest, m)?)?;
    m.add_function(wrap_pyfunction!(batch::model_items, m)?)?;
    m.add_function(wrap_pyfunction!(batch::plan_items, m)?)?;
    m.add_function(wrap_pyfunction!(batch::collect_item, m)?)?;
    m.add_function(wrap_pyfunction!(batch::collect_index, m)?)?;
    m.add_function(wrap_pyfunction!(batch::bench_item, m)?)?;
    m.add_function(wrap_pyfunction!(batch::bench_table, m)?)?;
    m.add_function(wrap_pyfunction!(batch::mcts_table, m)?)?;
    Ok(())
}
