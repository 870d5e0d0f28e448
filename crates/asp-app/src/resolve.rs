//! From a [`PlanRequest`] to the pipeline's [`PlanSettings`]: every default filled in (this is
//! the one place they are chosen, from the library constants), every value checked, every
//! name looked up in the catalogue, and every setting checked to apply to the search the
//! request asks for. Errors are [`AppError::Setting`]s naming the key.

use crate::catalogue::{self, QPolicy, DEFAULT_EPSILON};
use crate::error::{AppError, Result};
use crate::pipeline::{OptimiseSettings, PlanSettings, StabilitySetting, DEFAULT_TIMEOUT};
use crate::request::{PlanRequest, Stability, Subassemblies};
use crate::settings::{Applies, SETTINGS};
use asp_geom::math::{Axis, Vec3};
use asp_geom::Units;
use asp_search::mcts::{DEFAULT_BUDGET, DEFAULT_EPISODES, DEFAULT_EXPLORATION, DEFAULT_POLISH};
use asp_search::MdpExtension;
use serde_json::Value;
use std::sync::Arc;

/// The physics stability threshold when none is given: the simulation's own default (a part
/// that moves more than 1 % of the model's diagonal has fallen).
pub fn default_physics_threshold() -> f64 {
    asp_geom::PhysicsConfig::default().displacement_fraction as f64
}

/// Each setting does something in the search the request asks for.
fn check_applies(r: &PlanRequest) -> Result<()> {
    let given = r.given();
    let is_given = |key: &str| given.iter().any(|g| g == key);
    let (other, search, switch) = if r.optimises() {
        (Applies::Feasibility, "the feasibility search", "without `objective`")
    } else {
        (Applies::Optimiser, "the optimiser", "with `objective`")
    };
    for setting in SETTINGS.iter().filter(|s| s.applies == other) {
        if is_given(setting.key) {
            let mut reason = format!("applies to {search} only ({switch})");
            if !setting.instead.is_empty() {
                reason.push_str("; ");
                reason.push_str(setting.instead);
            }
            return Err(AppError::setting(setting.key, reason));
        }
    }
    let needs = |key: &str, on: bool, what: &str| -> Result<()> {
        if is_given(key) && !on {
            return Err(AppError::setting(key, format!("needs {what}")));
        }
        Ok(())
    };
    needs("physics_threshold", r.stability == Some(Stability::Physics), "`stability` physics")?;
    needs("epsilon", r.q.is_some(), "learned Q-functions (`q`)")?;
    needs("q_use", r.q.is_some(), "learned Q-functions (`q`)")?;
    needs("unit_group", r.subassemblies != Some(Subassemblies::Off), "`subassemblies` (a unit leaves as one rigid group)")?;
    if r.subassemblies == Some(Subassemblies::FromFile) && !r.unit_group.is_empty() {
        return Err(AppError::setting("unit_group", "does not combine with `subassemblies` from-file (its subassemblies are the units)"));
    }
    for key in ["robot_base", "drop_off", "replans", "package_path"] {
        needs(key, r.robot.is_some(), "a robot (`robot`)")?;
    }
    Ok(())
}

fn positive(key: &str, v: Option<f64>) -> Result<Option<f64>> {
    match v {
        Some(x) if !(x > 0.0 && x.is_finite()) => Err(AppError::setting(key, format!("must be a positive number, got {x}"))),
        v => Ok(v),
    }
}

fn at_least_one(key: &str, v: Option<usize>) -> Result<Option<usize>> {
    match v {
        Some(0) => Err(AppError::setting(key, "must be at least 1")),
        v => Ok(v),
    }
}

/// The unit of `unit` (`m`, `mm`, ... or metres per unit).
pub fn unit(name: &str) -> Result<Units> {
    Units::parse(name)
        .ok_or_else(|| AppError::setting("unit", format!("unknown unit '{name}' (use m, cm, mm, in, ft or a number of metres)")))
}

/// The axis of `up` (`x`, `-z`, ...).
pub fn axis(name: &str) -> Result<Axis> {
    Axis::parse(name).ok_or_else(|| AppError::setting("up", format!("'{name}' is not an axis (use x, y, z, -x, -y, -z)")))
}

/// The pipeline's settings of `request` (see the module documentation). The cancel token and
/// progress are the caller's: set [`PlanSettings::cancel`] on the result.
pub fn resolve(r: &PlanRequest) -> Result<PlanSettings> {
    check_applies(r)?;
    let d = PlanSettings::default();
    let robot = robot(r)?;
    let grippers = at_least_one("grippers", r.grippers)?.unwrap_or(1);
    let extensions: Vec<Arc<dyn MdpExtension>> = match &robot {
        Some(setup) => vec![Arc::new(asp_robot::RobotExtension::new(setup.clone())) as Arc<dyn MdpExtension>],
        None => Vec::new(),
    };
    let optimise = optimise(r, extensions)?;
    let checker_extension: Option<Arc<dyn asp_search::CheckerExtension>> = (optimise.is_none() && (robot.is_some() || grippers > 1))
        .then(|| Arc::new(asp_robot::CellSetup { robot: robot.clone(), grippers }) as Arc<dyn asp_search::CheckerExtension>);
    let order_name = r.order.as_deref().unwrap_or(catalogue::ORDERINGS[0].name);
    let entry = catalogue::ordering(order_name)?;
    if r.model.is_some() && !entry.takes_model {
        return Err(AppError::setting(
            "model",
            format!("the removability model of `order` gnn; it has no effect with `order` {order_name}"),
        ));
    }
    let stability = match r.stability.unwrap_or(Stability::Contact) {
        Stability::Contact => StabilitySetting::Contact,
        Stability::Physics => StabilitySetting::Physics {
            threshold: positive("physics_threshold", r.physics_threshold)?.unwrap_or_else(default_physics_threshold),
        },
    };
    // which checker decides removals: a learned ordering needs a model trained on its labels, and
    // `auto` is learned where that checker's tests are expensive (the arm checks removals in the
    // depth-first search only; an optimiser scores with it)
    let checker = crate::setup::label_checker(checker_extension.as_deref(), &stability);
    let model_error = |e: AppError| match &r.model {
        Some(_) => AppError::setting("model", e.to_string()),
        None => e,
    };
    let order = (entry.build)(r.model.as_deref(), checker).map_err(model_error)?;
    if entry.name == "auto" && !catalogue::auto_is_learned(checker) && r.model.is_some() {
        return Err(AppError::setting(
            "model",
            "the removability model of `order` gnn; `order` auto uses it only where removal tests are expensive (`stability` physics or a `robot`; give `order` gnn to use it here)",
        ));
    }
    let timeout = match r.timeout {
        None => Some(DEFAULT_TIMEOUT),
        Some(0.0) => None,
        t => positive("timeout", t)?,
    };
    Ok(PlanSettings {
        unit: r.unit.as_deref().map(unit).transpose()?,
        up: r.up.as_deref().map(axis).transpose()?,
        fixed: r.fixed.clone(),
        allow_outside_files: r.allow_outside_files.unwrap_or(false),
        limits: limits(r)?,
        tessellation: positive("tessellation", r.tessellation)?,
        split_bodies: r.split_bodies.unwrap_or(false),
        tolerance: positive("tolerance", r.tolerance)?,
        contact_distance: positive("contact_distance", r.contact_distance)?,
        normals: r.normals.unwrap_or(d.normals),
        sphere_directions: r.sphere_directions.unwrap_or(d.sphere_directions),
        overlaps: r.overlaps.unwrap_or_default(),
        stability,
        order,
        bookkeeping: r.bookkeeping.unwrap_or(false) || (entry.bookkeeping)(checker),
        seed: r.seed.unwrap_or(0),
        path_planner: r.path_planner.unwrap_or(d.path_planner),
        subassemblies: r.subassemblies.map_or(d.subassemblies, Subassemblies::allowed),
        from_file: r.subassemblies == Some(Subassemblies::FromFile),
        unit_groups: unit_groups(&r.unit_group)?,
        grid: r.grid.unwrap_or(d.grid),
        rrt_iterations: at_least_one("rrt_iterations", r.rrt_iterations)?.unwrap_or(d.rrt_iterations),
        rrt_time: positive("rrt_time", r.rrt_time)?.unwrap_or(d.rrt_time),
        max_tests: r.max_tests,
        timeout,
        optimise,
        cancel: None,
        checker_extension,
        precedence: r.precedence.unwrap_or(false),
    })
}

/// The unit groups, checked: each of at least two names, no name twice.
fn unit_groups(groups: &[Vec<String>]) -> Result<Vec<Vec<String>>> {
    let mut seen: Vec<&str> = Vec::new();
    for g in groups {
        if g.len() < 2 {
            return Err(AppError::setting("unit_group", format!("a unit needs at least two parts, got [{}]", g.join(", "))));
        }
        for name in g {
            if seen.contains(&name.as_str()) {
                return Err(AppError::setting("unit_group", format!("part '{name}' is named twice (a part belongs to one unit at most)")));
            }
            seen.push(name);
        }
    }
    Ok(groups.to_vec())
}

/// The loaders' caps.
fn limits(r: &PlanRequest) -> Result<asp_geom::io::Limits> {
    let d = asp_geom::io::Limits::default();
    Ok(asp_geom::io::Limits {
        max_triangles: at_least_one("max_triangles", r.max_triangles)?.unwrap_or(d.max_triangles),
        max_parts: at_least_one("max_parts", r.max_parts)?.unwrap_or(d.max_parts),
    })
}

/// The robot of the request, if any: its URDF's meshes found under the rules of
/// `package_path` and `allow_outside_files`, and refused when it has no gripper to take a part.
pub fn robot(r: &PlanRequest) -> Result<Option<asp_robot::RobotSetup>> {
    let Some(name) = &r.robot else { return Ok(None) };
    let package_paths = r
        .package_path
        .iter()
        .map(|p| {
            asp_robot::RobotFiles::parse_package_path(p).map_err(|_| AppError::setting("package_path", format!("'{p}' is not NAME=DIR")))
        })
        .collect::<Result<_>>()?;
    let files = asp_robot::RobotFiles { package_paths, allow_outside_files: r.allow_outside_files.unwrap_or(false) };
    let robot = catalogue::robot(name, &files).map_err(|e| AppError::setting("robot", e.to_string()))?;
    robot.check_can_grasp().map_err(|e| AppError::setting("robot", e.to_string()))?;
    let replans = at_least_one("replans", r.replans)?.unwrap_or(asp_robot::RemovalConfig::default().replans);
    let to_vec = |p: [f64; 3]| Vec3::new(p[0] as f32, p[1] as f32, p[2] as f32);
    Ok(Some(asp_robot::RobotSetup {
        robot,
        base: r.robot_base.map(to_vec),
        drop_off: r.drop_off.map(to_vec),
        config: asp_robot::RemovalConfig { replans, ..Default::default() },
    }))
}

/// The optimiser's settings, `None` without `objective`.
fn optimise(r: &PlanRequest, extensions: Vec<Arc<dyn MdpExtension>>) -> Result<Option<OptimiseSettings>> {
    let Some(names) = &r.objective else { return Ok(None) };
    if names.is_empty() {
        return Err(AppError::setting("objective", "no objective given"));
    }
    let list = names.join(",");
    if names.iter().any(|n| n == asp_robot::ROBOT_PATH) && extensions.is_empty() {
        return Err(AppError::setting("objective", format!("{list}: robot-path needs a robot (`robot` panda or a URDF file)")));
    }
    asp_search::extension::check_objective_names(names, &extensions).map_err(|e| AppError::setting("objective", e.to_string()))?;
    let pareto = r.pareto.unwrap_or(false);
    if names.len() > 1 && !pareto {
        return Err(AppError::setting("objective", format!("{list}: several objectives need `pareto` (or give one objective)")));
    }
    let resolution = r.resolution.unwrap_or(asp_geom::distmap::DEFAULT_RESOLUTION);
    let objectives: Vec<&str> = names.iter().map(String::as_str).collect();
    let policy = match &r.q {
        Some(paths) if paths.len() == 1 && paths[0].as_os_str() == catalogue::NO_Q => {
            if let Some(key) =
                [("q_use", r.q_use.is_some()), ("epsilon", r.epsilon.is_some())].iter().find_map(|(k, set)| set.then_some(*k))
            {
                return Err(AppError::setting(key, format!("needs Q-functions; `q` {} turns them off", catalogue::NO_Q)));
            }
            None
        }
        None => catalogue::default_guidance(&objectives, resolution)?.map(|q| Arc::new(q) as Arc<dyn catalogue::PolicySource>),
        Some(paths) => {
            let uses = r.q_use.unwrap_or_default();
            let q = QPolicy::new(paths, &objectives, r.epsilon.unwrap_or(DEFAULT_EPSILON), uses)?;
            Some(Arc::new(q) as Arc<dyn catalogue::PolicySource>)
        }
    };
    let polish = r.polish.unwrap_or(DEFAULT_POLISH);
    if !(polish >= 0.0 && polish.is_finite()) {
        return Err(AppError::setting("polish", format!("must be a share of the search's work (0 or more), got {polish}")));
    }
    let exploration = r.exploration.unwrap_or(DEFAULT_EXPLORATION);
    if !(exploration >= 0.0 && exploration.is_finite()) {
        return Err(AppError::setting("exploration", format!("must be 0 or more, got {exploration}")));
    }
    Ok(Some(OptimiseSettings {
        objectives: names.clone(),
        pareto,
        episodes: at_least_one("episodes", r.episodes)?.unwrap_or(DEFAULT_EPISODES),
        budget: at_least_one("budget", r.budget)?.unwrap_or(DEFAULT_BUDGET),
        threads: at_least_one("threads", r.threads)?,
        time_limit: positive("time_limit", r.time_limit)?,
        exploration,
        polish,
        resolution,
        d_max: positive("d_max", r.d_max)?,
        support: r.support.unwrap_or_default(),
        extensions,
        policy,
        robot_keys: robot_keys(r),
    }))
}

/// The robot's keys of `r` as given (none without `robot`), for [`OptimiseSettings::robot_keys`].
fn robot_keys(r: &PlanRequest) -> serde_json::Map<String, Value> {
    let mut keys = serde_json::Map::new();
    if r.robot.is_none() {
        return keys;
    }
    if let Ok(Value::Object(all)) = serde_json::to_value(r) {
        for key in ["robot", "robot_base", "drop_off", "replans", "package_path", "allow_outside_files"] {
            match all.get(key) {
                None | Some(Value::Null) => {}
                Some(Value::Array(v)) if v.is_empty() => {}
                Some(v) => {
                    keys.insert(key.into(), v.clone());
                }
            }
        }
    }
    keys
}

/// Every setting's default, by key, as the searches use them (`null`: none, or derived from the
/// model: the tolerance is 1e-4 × its diagonal, the threads all cores), read off
/// [`SETTINGS`]. Python's `asp._asp.default_settings()` and the docs show these.
pub fn defaults() -> serde_json::Map<String, Value> {
    SETTINGS.iter().map(|s| (s.key.to_string(), (s.default)())).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn err(json: &str) -> String {
        resolve(&PlanRequest::from_json(json).unwrap()).unwrap_err().to_string()
    }

    #[test]
    fn defaults_name_every_key_once() {
        let keys = PlanRequest::keys();
        let defaults = defaults();
        assert_eq!(defaults.keys().cloned().collect::<std::collections::BTreeSet<_>>(), keys.into_iter().collect());
    }

    #[test]
    fn an_empty_request_is_the_pipelines_default() {
        let s = resolve(&PlanRequest::default()).unwrap();
        let d = PlanSettings::default();
        assert_eq!((s.normals, s.seed, s.timeout, s.bookkeeping, s.grid), (d.normals, d.seed, d.timeout, d.bookkeeping, d.grid));
        assert_eq!(s.order.name(), "given");
        assert!(s.optimise.is_none() && s.checker_extension.is_none());
        // the default `auto`: the learned ordering with bookkeeping only where tests are expensive
        let s = resolve(&PlanRequest::from_json(r#"{"stability": "physics"}"#).unwrap()).unwrap();
        assert!(s.bookkeeping && s.order.name() == "gnn");
        let s = resolve(&PlanRequest::from_json(r#"{"stability": "physics", "order": "given"}"#).unwrap()).unwrap();
        assert!(!s.bookkeeping && s.order.name() == "given");
        // the arm's checks are expensive too: its own shipped model, with bookkeeping
        let s = resolve(&PlanRequest::from_json(r#"{"robot": "panda"}"#).unwrap()).unwrap();
        assert!(s.bookkeeping && s.order.name() == "gnn" && s.label_checker() == asp_learn::Checker::Robot);
        // an optimiser scores with the arm rather than checks with it: the cheap case
        let s = resolve(&PlanRequest::from_json(r#"{"robot": "panda", "objective": "robot-path"}"#).unwrap()).unwrap();
        assert!(!s.bookkeeping && s.order.name() == "given" && s.label_checker() == asp_learn::Checker::Default);
        let o = resolve(&PlanRequest::from_json(r#"{"objective": "access"}"#).unwrap()).unwrap().optimise.unwrap();
        let od = OptimiseSettings::default();
        assert_eq!(
            (o.episodes, o.budget, o.polish, o.resolution, o.exploration),
            (od.episodes, od.budget, od.polish, od.resolution, od.exploration)
        );
    }

    #[test]
    fn settings_of_the_other_search_are_errors_naming_what_applies() {
        assert_eq!(
            err(r#"{"objective": "access", "timeout": 10}"#),
            "timeout: applies to the feasibility search only (without `objective`); the optimiser's limit is `time_limit`"
        );
        assert_eq!(
            err(r#"{"time_limit": 10}"#),
            "time_limit: applies to the optimiser only (with `objective`); the feasibility search's limit is `timeout`"
        );
        assert_eq!(err(r#"{"physics_threshold": 0.1}"#), "physics_threshold: needs `stability` physics");
        assert_eq!(err(r#"{"objective": "access", "epsilon": 0.1}"#), "epsilon: needs learned Q-functions (`q`)");
        assert_eq!(err(r#"{"drop_off": [0, 0, 1]}"#), "drop_off: needs a robot (`robot`)");
        assert_eq!(
            err(r#"{"objective": "access", "grippers": 2}"#),
            "grippers: applies to the feasibility search only (without `objective`)"
        );
    }

    /// Unit groups are lists of names (or comma-separated strings), each of at
    /// least two parts, no part in two, and they need subassemblies.
    #[test]
    fn unit_groups_are_checked() {
        let ok = |json: &str| resolve(&PlanRequest::from_json(json).unwrap()).unwrap().unit_groups;
        assert_eq!(ok(r#"{"unit_group": ["a, b", ["c", "d", "e"]]}"#), [vec!["a", "b"], vec!["c", "d", "e"]]);
        assert_eq!(ok(r#"{"unit_group": "a,b"}"#), [vec!["a", "b"]]);
        assert!(ok("{}").is_empty());
        assert_eq!(err(r#"{"unit_group": ["a"]}"#), "unit_group: a unit needs at least two parts, got [a]");
        assert_eq!(err(r#"{"unit_group": ["a,b", "b,c"]}"#), "unit_group: part 'b' is named twice (a part belongs to one unit at most)");
        assert_eq!(
            err(r#"{"unit_group": ["a,b"], "subassemblies": false}"#),
            "unit_group: needs `subassemblies` (a unit leaves as one rigid group)"
        );
        assert_eq!(
            err(r#"{"unit_group": ["a,b"], "objective": "access"}"#),
            "unit_group: applies to the feasibility search only (without `objective`)"
        );
        let typed = PlanRequest::from_json(r#"{"unit_group": 3}"#).unwrap_err().to_string();
        assert!(typed.starts_with("unit_group: must be a list of groups"), "{typed}");
    }

    #[test]
    fn values_are_checked_with_the_key() {
        assert_eq!(err(r#"{"timeout": -1}"#), "timeout: must be a positive number, got -1");
        assert!(resolve(&PlanRequest::from_json(r#"{"timeout": 0}"#).unwrap()).unwrap().timeout.is_none());
        assert_eq!(
            err(r#"{"order": "sideways"}"#),
            "order: unknown order 'sideways' (use auto, given, shuffled, random, bookkeeping, gnn)"
        );
        assert_eq!(
            err(r#"{"order": "given", "model": "m.onnx"}"#),
            "model: the removability model of `order` gnn; it has no effect with `order` given"
        );
        assert!(err(r#"{"model": "m.onnx"}"#)
            .starts_with("model: the removability model of `order` gnn; `order` auto uses it only where removal tests are expensive"));
        assert!(err(r#"{"stability": "physics", "model": "/no/such.onnx"}"#).starts_with("model: "));
        assert!(err(r#"{"order": "gnn", "model": "/no/such.onnx"}"#).starts_with("model: "));
        assert_eq!(
            err(r#"{"objective": "access,dirchange"}"#),
            "objective: access,dirchange: several objectives need `pareto` (or give one objective)"
        );
        assert!(err(r#"{"objective": "speed"}"#).starts_with("objective: unknown objective 'speed'"));
        assert!(err(r#"{"objective": "robot-path"}"#).contains("robot-path needs a robot"));
        assert_eq!(err(r#"{"objective": "access", "q": "a.onnx", "epsilon": 1.5}"#), "epsilon: must be in [0, 1], got 1.5");
        assert!(err(r#"{"objective": "access", "q": "/no/such/q.onnx"}"#).starts_with("q: /no/such/q.onnx"));
        assert!(err(r#"{"objective": "access", "q": "a.onnx,b.onnx"}"#).contains("2 Q models for 1 objectives"));
        assert_eq!(err(r#"{"unit": "furlong"}"#), "unit: unknown unit 'furlong' (use m, cm, mm, in, ft or a number of metres)");
        assert_eq!(err(r#"{"grippers": 0}"#), "grippers: must be at least 1");
        let s = resolve(&PlanRequest::from_json(r#"{"order": "bookkeeping"}"#).unwrap()).unwrap();
        assert!(s.bookkeeping && s.order.name() == "given");
        let s = resolve(&PlanRequest::from_json(r#"{"robot": "panda", "grippers": 2}"#).unwrap()).unwrap();
        assert!(s.checker_extension.is_some());
    }

    /// Without `q`, objectives that all have a shipped Q on maps of their resolution get the
    /// shipped seeds; `q` none, another resolution or an objective without one get no guidance.
    #[test]
    fn the_default_guidance_is_the_shipped_seeds_where_they_apply() {
        let guidance = |json: &str| {
            let s = resolve(&PlanRequest::from_json(json).unwrap()).unwrap();
            s.optimise.unwrap().policy.and_then(|p| p.guidance())
        };
        let g = guidance(r#"{"objective": "access,dirchange", "pareto": true}"#).expect("the default seeds");
        assert_eq!(g.models, ["shipped:models/q-access.onnx", "shipped:models/q-dirchange.onnx"]);
        assert_eq!((g.q_use.as_str(), g.epsilon), ("seed", None));
        assert_eq!(guidance(r#"{"objective": "pathlen"}"#).unwrap().models, ["shipped:models/q-pathlen.onnx"]);
        assert!(guidance(r#"{"objective": "access,dirchange", "pareto": true, "q": "none"}"#).is_none());
        assert!(guidance(r#"{"objective": "access", "resolution": 7}"#).is_none());
        assert!(guidance(r#"{"objective": "access,robot-path", "pareto": true, "robot": "panda"}"#).is_none());
        // given models keep their q_use
        let g = guidance(r#"{"objective": "access", "q": "shipped", "q_use": "priors"}"#).unwrap();
        assert_eq!(g.q_use, "priors");
        assert_eq!(err(r#"{"objective": "access", "q": "none", "q_use": "priors"}"#), "q_use: needs Q-functions; `q` none turns them off");
    }
}
