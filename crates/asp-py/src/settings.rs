//! Planning settings from Python: a dict of keyword arguments (as `asp.Assembly.plan` passes
//! them) into [`PlanSettings`], and the part orderings by name.
//!
//! Every key is optional; a missing key or `None` takes the library's default
//! ([`PlanSettings::default`], [`OptimiseSettings::default`]), which are also the CLI's. Unknown
//! keys, values of the wrong type and values out of range are [`Kind::Config`] errors naming the
//! keyword.

use crate::errors::Error;
#[cfg(test)]
use crate::errors::Kind;
use asp_geom::distmap::Support;
use asp_geom::math::Axis;
use asp_geom::{GraphConfig, OverlapPolicy, Units};
use asp_search::pipeline::{OptimiseSettings, PlanSettings, StabilitySetting};
use asp_search::{BuiltinOrder, OrderingSource};
use pyo3::conversion::FromPyObjectOwned;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList, PyString};
use std::sync::Arc;

/// The probability of a random removal in a rollout guided by Q-functions when none is given
/// (the CLI's `--epsilon`, the thesis' 0.2).
pub const DEFAULT_EPSILON: f64 = 0.2;

/// The physics stability threshold when none is given (the CLI's `--physics-threshold`).
pub const DEFAULT_PHYSICS_THRESHOLD: f64 = 0.01;

/// The names `order=` accepts, in the order the docs list them.
pub const ORDER_NAMES: [&str; 5] = ["given", "shuffled", "random", "bookkeeping", "gnn"];

/// The keywords of [`plan_settings`], in the order of `asp.Assembly.plan`'s signature.
pub const PLAN_KEYS: [&str; 31] = [
    "order",
    "model",
    "bookkeeping",
    "seed",
    "tolerance",
    "contact_distance",
    "normals",
    "sphere_directions",
    "overlaps",
    "stability",
    "physics_threshold",
    "path_planner",
    "subassemblies",
    "rrt_iterations",
    "rrt_time",
    "max_tests",
    "timeout",
    "objective",
    "pareto",
    "episodes",
    "budget",
    "threads",
    "time_limit",
    "exploration",
    "polish",
    "resolution",
    "d_max",
    "support",
    "q",
    "epsilon",
    "q_use",
];

/// The ordering source `order=name` stands for, and whether the name implies bookkeeping
/// (`bookkeeping` is the given order with bookkeeping, as on the command line).
///
/// This is the one place where order names meet [`OrderingSource`]s: a learned ordering
/// (`gnn`, from the learned-ordering crate) is added here.
pub fn ordering(name: &str, model: Option<&str>) -> Result<(Arc<dyn OrderingSource>, bool), Error> {
    if model.is_some() && name != "gnn" {
        return Err(Error::config(format!("model: the removability model of order='gnn'; it has no effect with order='{name}'")));
    }
    match name {
        "given" => Ok((Arc::new(BuiltinOrder::Given), false)),
        "bookkeeping" => Ok((Arc::new(BuiltinOrder::Given), true)),
        "shuffled" => Ok((Arc::new(BuiltinOrder::Shuffled), false)),
        "random" => Ok((Arc::new(BuiltinOrder::Random), false)),
        "gnn" => {
            let source = match model {
                Some(path) => asp_learn::GnnSource::load(path, asp_geom::graph::GraphConfig::default()),
                None => asp_learn::GnnSource::shipped(),
            };
            let source = source.map_err(|e| Error::config(format!("model: {e}")))?;
            Ok((Arc::new(source), false))
        }
        other => Err(Error::config(format!("unknown order '{other}' (use {})", ORDER_NAMES.join(", ")))),
    }
}

/// Parses a unit name (`m`, `mm`, ... or metres per unit).
pub fn unit(name: &str) -> Result<Units, Error> {
    Units::parse(name)
        .ok_or_else(|| Error::config(format!("unit: unknown unit '{name}' (use m, cm, mm, in, ft or a number of metres)")))
}

/// Parses an up axis (`x`, `-z`, ...).
pub fn axis(name: &str) -> Result<Axis, Error> {
    Axis::parse(name).ok_or_else(|| Error::config(format!("up: '{name}' is not an axis (use x, y, z, -x, -y, -z)")))
}

/// Reads typed values out of the keyword dict, remembering which keys were used.
struct Keywords<'a, 'py> {
    dict: &'a Bound<'py, PyDict>,
}

impl<'py> Keywords<'_, 'py> {
    /// The value of `key`, `None` when missing or `None`.
    fn get(&self, key: &str) -> Result<Option<Bound<'py, PyAny>>, Error> {
        let value = self.dict.get_item(key).map_err(|e| Error::config(format!("{key}: {e}")))?;
        Ok(value.filter(|v| !v.is_none()))
    }

    fn value<T: FromPyObjectOwned<'py>>(&self, key: &str, what: &str) -> Result<Option<T>, Error> {
        match self.get(key)? {
            None => Ok(None),
            Some(v) => v.extract::<T>().map(Some).map_err(|_| {
                let shown = v.repr().map(|r| r.to_string()).unwrap_or_else(|_| "?".into());
                Error::config(format!("{key} must be {what}, got {shown}"))
            }),
        }
    }

    fn flag(&self, key: &str, default: bool) -> Result<bool, Error> {
        Ok(self.value::<bool>(key, "True or False")?.unwrap_or(default))
    }

    fn count(&self, key: &str) -> Result<Option<usize>, Error> {
        self.value::<usize>(key, "a non-negative integer")
    }

    fn number(&self, key: &str) -> Result<Option<f64>, Error> {
        self.value::<f64>(key, "a number")
    }

    fn positive(&self, key: &str) -> Result<Option<f64>, Error> {
        match self.number(key)? {
            Some(v) if !(v > 0.0 && v.is_finite()) => Err(Error::config(format!("{key} must be a positive number, got {v}"))),
            v => Ok(v),
        }
    }

    fn string(&self, key: &str) -> Result<Option<String>, Error> {
        self.value::<String>(key, "a string")
    }
}

/// The settings of a planning run from `asp.Assembly.plan`'s keywords (load settings — unit, up,
/// fixed parts — belong to `asp.load` and are rejected here like any unknown keyword).
pub fn plan_settings(dict: &Bound<'_, PyDict>) -> Result<PlanSettings, Error> {
    reject_unknown(dict, &PLAN_KEYS)?;
    let k = Keywords { dict };
    let defaults = PlanSettings::default();
    let model = k.string("model")?;
    let (order, implied_bookkeeping) = ordering(&k.string("order")?.unwrap_or_else(|| "given".into()), model.as_deref())?;
    let stability = match k.string("stability")?.as_deref() {
        None | Some("contact") => StabilitySetting::Contact,
        Some("physics") => StabilitySetting::Physics {
            threshold: k.positive("physics_threshold")?.unwrap_or(DEFAULT_PHYSICS_THRESHOLD),
        },
        Some(other) => return Err(Error::config(format!("stability: unknown criterion '{other}' (use contact or physics)"))),
    };
    Ok(PlanSettings {
        unit: None,
        up: None,
        fixed: Vec::new(),
        tolerance: k.positive("tolerance")?,
        contact_distance: k.positive("contact_distance")?,
        normals: k.count("normals")?.unwrap_or(defaults.normals),
        sphere_directions: k.count("sphere_directions")?.unwrap_or(defaults.sphere_directions),
        overlaps: overlap_policy(&k)?,
        stability,
        order,
        bookkeeping: k.flag("bookkeeping", defaults.bookkeeping)? || implied_bookkeeping,
        seed: k.value::<u64>("seed", "a non-negative integer")?.unwrap_or(defaults.seed),
        path_planner: k.flag("path_planner", defaults.path_planner)?,
        subassemblies: k.flag("subassemblies", defaults.subassemblies)?,
        grid: defaults.grid,
        rrt_iterations: k.count("rrt_iterations")?.unwrap_or(defaults.rrt_iterations),
        rrt_time: k.positive("rrt_time")?.unwrap_or(defaults.rrt_time),
        max_tests: k.value::<u64>("max_tests", "a non-negative integer")?,
        timeout: k.positive("timeout")?,
        optimise: optimise_settings(&k)?,
        cancel: None,
        checker_extension: None,
    })
}

/// The optimiser's settings, `None` unless `objective` is given (a comma-separated string or a
/// list of names).
fn optimise_settings(k: &Keywords<'_, '_>) -> Result<Option<OptimiseSettings>, Error> {
    let Some(objective) = k.get("objective")? else { return Ok(None) };
    let objectives = if let Ok(list) = objective.cast::<PyList>() {
        let names: Vec<String> = list
            .iter()
            .map(|n| n.extract::<String>())
            .collect::<PyResult<_>>()
            .map_err(|_| Error::config("objective must be a string or a list of strings"))?;
        names.join(",")
    } else {
        k.string("objective")?.unwrap_or_default()
    };
    if objectives.trim().is_empty() {
        return Err(Error::config("objective: no objective given"));
    }
    let d = OptimiseSettings::default();
    let support = match k.string("support")?.as_deref() {
        None | Some("below") => Support::Below,
        Some("contact") => Support::ContactGraph,
        Some(other) => return Err(Error::config(format!("support: unknown gravity check '{other}' (use below or contact)"))),
    };
    let resolution = k.count("resolution")?.unwrap_or(d.resolution);
    let epsilon = k.number("epsilon")?.unwrap_or(DEFAULT_EPSILON);
    if !(0.0..=1.0).contains(&epsilon) {
        return Err(Error::config(format!("epsilon must be in [0, 1], got {epsilon}")));
    }
    let policy = match k.string("q")? {
        None => None,
        Some(models) => {
            let paths: Vec<&str> = models.split(',').map(str::trim).filter(|p| !p.is_empty()).collect();
            let names: Vec<&str> = objectives.split(',').map(str::trim).filter(|n| !n.is_empty()).collect();
            let uses = match k.string("q_use")?.as_deref() {
                None => asp_search::QUse::default(),
                Some(u) => u.parse().map_err(|e: asp_search::SearchError| Error::config(format!("q_use: {e}")))?,
            };
            Some(asp_learn::epsilon_greedy(&paths, &names, epsilon, resolution * resolution, uses).map_err(|e| Error::config(format!("q: {e}")))?)
        }
    };
    Ok(Some(OptimiseSettings {
        objectives,
        pareto: k.flag("pareto", d.pareto)?,
        episodes: k.count("episodes")?.unwrap_or(d.episodes),
        budget: k.count("budget")?.unwrap_or(d.budget),
        threads: k.count("threads")?,
        time_limit: k.positive("time_limit")?,
        exploration: k.number("exploration")?.unwrap_or(d.exploration),
        polish: k.number("polish")?.unwrap_or(d.polish),
        resolution,
        d_max: k.positive("d_max")?,
        support,
        policy,
        ..d
    }))
}

/// The keywords of [`graph_settings`].
pub const GRAPH_KEYS: [&str; 6] =
    ["tolerance", "contact_distance", "overlaps", "radius_bins", "degree", "points_per_part"];

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

/// The settings of `asp.Assembly.graph`'s keywords (missing keys take the defaults).
pub fn graph_settings(dict: &Bound<'_, PyDict>) -> Result<GraphSettings, Error> {
    reject_unknown(dict, &GRAPH_KEYS)?;
    let k = Keywords { dict };
    let d = GraphConfig::default();
    let config = GraphConfig::builder()
        .radius_bins(k.count("radius_bins")?.unwrap_or(d.radius_bins))
        .degree(k.count("degree")?.unwrap_or(d.degree))
        .points_per_part(k.count("points_per_part")?.unwrap_or(d.points_per_part))
        .build()
        .map_err(Error::from)?;
    let world = PlanSettings {
        tolerance: k.positive("tolerance")?,
        contact_distance: k.positive("contact_distance")?,
        overlaps: overlap_policy(&k)?,
        ..PlanSettings::default()
    };
    Ok(GraphSettings { world, config })
}

/// The keywords of [`q_graph_settings`].
pub const Q_GRAPH_KEYS: [&str; 8] =
    ["objective", "resolution", "d_max", "support", "tolerance", "contact_distance", "overlaps", "neighbours"];

/// The settings of `asp.Assembly.q_graphs`' keywords: the world's (tolerance, contact distance,
/// overlaps), the optimiser's that shape the maps and the MDP (objective, resolution, `d_max`,
/// support), and the neighbours per part node (default 8).
pub fn q_graph_settings(dict: &Bound<'_, PyDict>) -> Result<(PlanSettings, OptimiseSettings, usize), Error> {
    reject_unknown(dict, &Q_GRAPH_KEYS)?;
    let k = Keywords { dict };
    let neighbours = k.count("neighbours")?.unwrap_or(asp_search::qgraph::DEFAULT_NEIGHBOURS);
    if neighbours == 0 {
        return Err(Error::config("neighbours must be at least 1"));
    }
    let mut optimise = optimise_settings(&k)?.ok_or_else(|| Error::config("objective: no objective given"))?;
    optimise.pareto = optimise.objectives.split(',').filter(|n| !n.trim().is_empty()).count() > 1;
    asp_search::extension::check_objective_names(&optimise.objectives, &[]).map_err(Error::from)?;
    let plan = PlanSettings {
        tolerance: k.positive("tolerance")?,
        contact_distance: k.positive("contact_distance")?,
        overlaps: overlap_policy(&k)?,
        ..PlanSettings::default()
    };
    Ok((plan, optimise, neighbours))
}

/// The `overlaps` keyword: `strict` (the default), `lenient` or `error`.
fn overlap_policy(k: &Keywords<'_, '_>) -> Result<OverlapPolicy, Error> {
    match k.string("overlaps")? {
        None => Ok(OverlapPolicy::default()),
        Some(name) => OverlapPolicy::parse(&name)
            .ok_or_else(|| Error::config(format!("overlaps: unknown policy '{name}' (use strict, lenient or error)"))),
    }
}

fn reject_unknown(dict: &Bound<'_, PyDict>, known: &[&str]) -> Result<(), Error> {
    for key in dict.keys() {
        let name = key.cast::<PyString>().map(|s| s.to_string()).unwrap_or_else(|_| key.to_string());
        if !known.contains(&name.as_str()) {
            let hint = match name.as_str() {
                "unit" | "up" | "fixed" => format!("'{name}' is a setting of asp.load"),
                _ => format!("unknown setting '{name}'"),
            };
            return Err(Error::config(hint));
        }
    }
    Ok(())
}

/// The defaults of every keyword of [`plan_settings`] and [`graph_settings`] as a dict (what `asp.Assembly.plan`'s
/// signature must show; a Python test compares the two).
pub fn default_settings(py: Python<'_>) -> PyResult<Bound<'_, PyDict>> {
    let p = PlanSettings::default();
    let o = OptimiseSettings::default();
    let d = PyDict::new(py);
    d.set_item("order", BuiltinOrder::default().as_str())?;
    d.set_item("model", None::<String>)?;
    d.set_item("bookkeeping", p.bookkeeping)?;
    d.set_item("seed", p.seed)?;
    d.set_item("tolerance", p.tolerance)?;
    d.set_item("contact_distance", p.contact_distance)?;
    d.set_item("normals", p.normals)?;
    d.set_item("sphere_directions", p.sphere_directions)?;
    d.set_item("overlaps", p.overlaps.name())?;
    d.set_item("stability", "contact")?;
    d.set_item("physics_threshold", DEFAULT_PHYSICS_THRESHOLD)?;
    d.set_item("path_planner", p.path_planner)?;
    d.set_item("subassemblies", p.subassemblies)?;
    d.set_item("rrt_iterations", p.rrt_iterations)?;
    d.set_item("rrt_time", p.rrt_time)?;
    d.set_item("max_tests", p.max_tests)?;
    d.set_item("timeout", p.timeout)?;
    d.set_item("objective", py.None())?;
    d.set_item("pareto", o.pareto)?;
    d.set_item("episodes", o.episodes)?;
    d.set_item("budget", o.budget)?;
    d.set_item("threads", o.threads)?;
    d.set_item("time_limit", o.time_limit)?;
    d.set_item("exploration", o.exploration)?;
    d.set_item("polish", o.polish)?;
    d.set_item("resolution", o.resolution)?;
    d.set_item("d_max", o.d_max)?;
    d.set_item("support", "below")?;
    d.set_item("q", py.None())?;
    d.set_item("epsilon", DEFAULT_EPSILON)?;
    d.set_item("q_use", asp_search::QUse::default().name())?;
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
    fn order_names_map_to_sources() {
        for name in ["given", "shuffled", "random"] {
            let (source, bookkeeping) = ordering(name, None).unwrap();
            assert_eq!(source.name(), name);
            assert!(!bookkeeping);
        }
        let (source, bookkeeping) = ordering("bookkeeping", None).unwrap();
        assert_eq!((source.name().as_str(), bookkeeping), ("given", true));
    }

    #[test]
    fn gnn_uses_the_shipped_model_and_unknown_orders_are_config_errors() {
        let (source, bookkeeping) = ordering("gnn", None).unwrap();
        assert_eq!((source.name().as_str(), bookkeeping), ("gnn", false));
        let e = ordering("gnn", Some("/no/such/model.onnx")).err().unwrap();
        assert!(e.message.contains("/no/such/model.onnx"), "{}", e.message);
        assert_eq!(kind_of(ordering("given", Some("m.onnx"))), Some(Kind::Config));
        assert_eq!(kind_of(ordering("sideways", None)), Some(Kind::Config));
    }

    #[test]
    fn units_and_axes_parse_like_the_cli() {
        assert_eq!(unit("mm").unwrap().metres, 0.001);
        assert_eq!(axis("-z").unwrap().to_string(), "-z");
        assert_eq!(kind_of(unit("furlong")), Some(Kind::Config));
        assert_eq!(kind_of(axis("w")), Some(Kind::Config));
    }
}
