//! Settings from Python: a dict of keyword arguments (as `asp.Assembly.plan` passes them) into
//! an [`asp_app::PlanRequest`], whose keys they are. Everything about a setting — its type, its
//! default, which search it applies to, the names it accepts — is the request's and the
//! catalogue's ([`asp_app::resolve()`]); this module only translates Python values into JSON.
//!
//! A key left out or `None` takes the default of the search it belongs to. Unknown keys, values
//! of the wrong type or out of range, and settings of the other search are
//! [`Kind::Config`](crate::errors::Kind::Config) errors naming the keyword.

use crate::errors::Error;
#[cfg(test)]
use crate::errors::Kind;
use asp_app::{PlanRequest, PlanSettings};
use asp_geom::GraphConfig;
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyInt, PyList, PyString, PyTuple};
use serde_json::{Map, Value};

/// The names `order=` accepts, in the order the docs list them (the catalogue's).
pub fn order_names() -> Vec<&'static str> {
    asp_app::catalogue::ORDERINGS.iter().map(|o| o.name).collect()
}

/// A Python value as JSON: `None`, booleans, numbers, strings, path-likes (as strings), lists,
/// tuples and dicts. `key` names the setting in errors.
fn to_json(key: &str, v: &Bound<'_, PyAny>) -> Result<Value, Error> {
    if v.is_none() {
        return Ok(Value::Null);
    }
    if v.is_instance_of::<PyBool>() {
        return Ok(Value::Bool(v.extract::<bool>().unwrap_or_default()));
    }
    if v.is_instance_of::<PyInt>() {
        if let Ok(i) = v.extract::<i64>() {
            return Ok(Value::from(i));
        }
        if let Ok(u) = v.extract::<u64>() {
            return Ok(Value::from(u));
        }
        return Err(Error::config(format!("{key}: out of range")));
    }
    if v.is_instance_of::<PyFloat>() {
        let x = v.extract::<f64>().unwrap_or(f64::NAN);
        return serde_json::Number::from_f64(x)
            .map(Value::Number)
            .ok_or_else(|| Error::config(format!("{key}: must be a finite number, got {x}")));
    }
    if let Ok(s) = v.cast::<PyString>() {
        return Ok(Value::String(s.to_string()));
    }
    if v.is_instance_of::<PyList>() || v.is_instance_of::<PyTuple>() {
        let items: Vec<Bound<'_, PyAny>> = v
            .try_iter()
            .map_err(|e| Error::config(format!("{key}: {e}")))?
            .collect::<PyResult<_>>()
            .map_err(|e| Error::config(format!("{key}: {e}")))?;
        return items.iter().map(|item| to_json(key, item)).collect::<Result<Vec<_>, _>>().map(Value::Array);
    }
    // os.PathLike (pathlib.Path): its path
    if let Ok(fspath) = v.py().import("os").and_then(|os| os.getattr("fspath")) {
        if let Ok(path) = fspath.call1((v,)).and_then(|p| p.extract::<String>()) {
            return Ok(Value::String(path));
        }
    }
    let shown = v.repr().map(|r| r.to_string()).unwrap_or_else(|_| "?".into());
    Err(Error::config(format!("{key}: {shown} is not a setting value (use numbers, strings, booleans, lists)")))
}

/// The dict as a JSON object (keys must be strings).
fn dict_json(dict: &Bound<'_, PyDict>) -> Result<Map<String, Value>, Error> {
    let mut map = Map::new();
    for (key, value) in dict.iter() {
        let key = key
            .cast::<PyString>()
            .map(|s| s.to_string())
            .map_err(|_| Error::config(format!("setting names must be strings, got {key}")))?;
        let value = to_json(&key, &value)?;
        map.insert(key, value);
    }
    Ok(map)
}

/// The request of `Assembly.plan`'s keywords. Loading keys (`unit`, `up`, `fixed`) are
/// `asp.load`'s: refused here unless `load` is set (batches plan files).
pub fn request(dict: &Bound<'_, PyDict>, load: bool) -> Result<PlanRequest, Error> {
    let map = dict_json(dict)?;
    if !load {
        if let Some(key) = map.keys().find(|k| asp_app::request::is_load_key(k)) {
            return Err(Error::config(format!("'{key}' is a setting of asp.load")));
        }
    }
    Ok(PlanRequest::from_value(Value::Object(map))?)
}

/// The pipeline's settings of `Assembly.plan`'s keywords.
pub fn plan_settings(dict: &Bound<'_, PyDict>) -> Result<PlanSettings, Error> {
    Ok(asp_app::resolve(&request(dict, false)?)?)
}

/// The keywords of [`graph_settings`] beyond the request's world keys.
pub const GRAPH_KEYS: [&str; 3] = ["radius_bins", "degree", "points_per_part"];

/// The request keys that shape the collision world a graph is read from.
const WORLD_KEYS: [&str; 3] = ["tolerance", "contact_distance", "overlaps"];

/// What the graph of a model depends on: the collision world's contact settings and the feature
/// parameters (also the key of the graph cache of an assembly handle).
#[derive(Clone, Debug)]
pub struct GraphSettings {
    /// The world's settings (tolerance, contact distance, overlaps; the rest default).
    pub world: PlanSettings,
    /// The feature parameters.
    pub config: GraphConfig,
}

impl GraphSettings {
    /// Whether two settings give the same graph.
    pub fn same_graph(&self, other: &GraphSettings) -> bool {
        let w = (&self.world, &other.world);
        self.config == other.config
            && w.0.tolerance == w.1.tolerance
            && w.0.contact_distance == w.1.contact_distance
            && w.0.overlaps == w.1.overlaps
    }
}

/// Splits `dict` into the request keys of `request_keys` and the rest (which must be in
/// `own_keys`), as JSON.
fn split(dict: &Bound<'_, PyDict>, request_keys: &[&str], own_keys: &[&str]) -> Result<[Map<String, Value>; 2], Error> {
    let (mut request, mut own) = (Map::new(), Map::new());
    for (key, value) in dict_json(dict)? {
        if request_keys.contains(&key.as_str()) {
            request.insert(key, value);
        } else if own_keys.contains(&key.as_str()) {
            own.insert(key, value);
        } else {
            return Err(Error::config(format!("unknown setting '{key}'")));
        }
    }
    Ok([request, own])
}

/// A count of `own` (`None` when missing or null), or a config error naming it.
fn count(own: &Map<String, Value>, key: &str) -> Result<Option<usize>, Error> {
    match own.get(key) {
        None | Some(Value::Null) => Ok(None),
        Some(v) => {
            v.as_u64().map(|n| Some(n as usize)).ok_or_else(|| Error::config(format!("{key} must be a non-negative integer, got {v}")))
        }
    }
}

/// The settings of `asp.Assembly.graph`'s keywords (missing keys take the defaults).
pub fn graph_settings(dict: &Bound<'_, PyDict>) -> Result<GraphSettings, Error> {
    let [request, own] = split(dict, &WORLD_KEYS, &GRAPH_KEYS)?;
    let d = GraphConfig::default();
    let config = GraphConfig::builder()
        .radius_bins(count(&own, "radius_bins")?.unwrap_or(d.radius_bins))
        .degree(count(&own, "degree")?.unwrap_or(d.degree))
        .points_per_part(count(&own, "points_per_part")?.unwrap_or(d.points_per_part))
        .build()
        .map_err(Error::from)?;
    let world = asp_app::resolve(&PlanRequest::from_value(Value::Object(request))?)?;
    Ok(GraphSettings { world, config })
}

/// The request keys of [`q_graph_settings`]: the world's and the optimiser's that shape the
/// maps and the MDP, and the robot's (the objective `robot-path` needs one).
const Q_GRAPH_REQUEST_KEYS: [&str; 13] = [
    "objective",
    "resolution",
    "d_max",
    "support",
    "tolerance",
    "contact_distance",
    "overlaps",
    "robot",
    "robot_base",
    "drop_off",
    "replans",
    "package_path",
    "allow_outside_files",
];

/// The settings of `asp.Assembly.q_graphs`' keywords: the world's (tolerance, contact distance,
/// overlaps), the optimiser's that shape the maps and the MDP (objective, resolution, `d_max`,
/// support), the robot's, and the neighbours per part node (default 8).
pub fn q_graph_settings(dict: &Bound<'_, PyDict>) -> Result<(PlanSettings, asp_app::OptimiseSettings, usize), Error> {
    let [mut request, own] = split(dict, &Q_GRAPH_REQUEST_KEYS, &["neighbours"])?;
    let neighbours = count(&own, "neighbours")?.unwrap_or(asp_search::qgraph::DEFAULT_NEIGHBOURS);
    if neighbours == 0 {
        return Err(Error::config("neighbours must be at least 1"));
    }
    if request.get("objective").is_none_or(Value::is_null) {
        return Err(Error::config("objective: no objective given"));
    }
    // several objectives are one Pareto problem
    request.insert("pareto".into(), Value::Bool(true));
    let mut plan = asp_app::resolve(&PlanRequest::from_value(Value::Object(request))?)?;
    let mut optimise = plan.optimise.take().ok_or_else(|| Error::config("objective: no objective given"))?;
    optimise.pareto = optimise.objectives.len() > 1;
    Ok((plan, optimise, neighbours))
}

/// The defaults of every keyword of [`plan_settings`] and [`graph_settings`] as a dict (what
/// `asp.Assembly.plan` documents; a Python test compares the two).
pub fn default_settings(py: Python<'_>) -> PyResult<Bound<'_, PyDict>> {
    let d = PyDict::new(py);
    let json = py.import("json")?;
    for (key, value) in asp_app::resolve::defaults() {
        if asp_app::request::is_load_key(&key) {
            continue;
        }
        d.set_item(key, json.call_method1("loads", (value.to_string(),))?)?;
    }
    let g = GraphConfig::default();
    d.set_item("radius_bins", g.radius_bins)?;
    d.set_item("degree", g.degree)?;
    d.set_item("points_per_part", g.points_per_part)?;
    Ok(d)
}

/// A [`Kind`] check for the error of a keyword, for tests.
#[cfg(test)]
fn kind_of<T>(r: Result<T, Error>) -> Option<Kind> {
    r.err().map(|e| e.kind)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn settings_errors_are_config_errors_naming_the_keyword() {
        let e = |json: &str| -> Error { PlanRequest::from_json(json).and_then(|r| asp_app::resolve(&r)).map(|_| ()).unwrap_err().into() };
        let err = e(r#"{"order": "sideways"}"#);
        assert_eq!(err.kind, Kind::Config);
        assert_eq!(err.message, "order: unknown order 'sideways' (use auto, given, shuffled, random, bookkeeping, gnn)");
        let err = e(r#"{"objective": "access", "timeout": 5}"#);
        assert_eq!(err.message, "timeout: applies to the feasibility search only (without objective); the optimiser's limit is time_limit");
        assert_eq!(kind_of::<()>(Err(e(r#"{"order": "gnn", "model": "/no/such/model.onnx"}"#))), Some(Kind::Config));
        assert_eq!(order_names(), ["auto", "given", "shuffled", "random", "bookkeeping", "gnn"]);
    }
}
