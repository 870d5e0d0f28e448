//! The plan request end to end: a request written as JSON plans the same model to the same
//! bytes as the pipeline's settings built by hand, for the feasibility search and the
//! optimiser; settings that do not apply are refused before any work.

use asp_app::pipeline::{self, OptimiseSettings, PlanSettings};
use asp_app::{Hooks, PlanRequest};
use std::path::PathBuf;

fn data(rel: &str) -> PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tests/data").join(rel)
}

/// The report's JSON without its wall times (the only part that differs run to run).
fn untimed(json: &str) -> serde_json::Value {
    let mut v: serde_json::Value = serde_json::from_str(json).unwrap();
    fn strip(v: &mut serde_json::Value) {
        match v {
            serde_json::Value::Object(map) => {
                map.retain(|k, _| !k.contains("seconds") && k != "timings" && k != "load" && k != "world" && k != "search");
                map.values_mut().for_each(strip);
            }
            serde_json::Value::Array(items) => items.iter_mut().for_each(strip),
            _ => {}
        }
    }
    strip(&mut v);
    v
}

#[test]
fn a_json_request_plans_like_hand_built_settings() {
    let table = data("ikea/table_lack_0825.glb");
    let request = PlanRequest::from_json(r#"{"up": "z", "order": "random", "seed": 7, "bookkeeping": true, "max_tests": 500}"#).unwrap();
    let by_request = asp_app::plan_file(&table, &request, Hooks::default()).unwrap();
    let settings = PlanSettings {
        up: Some(asp_geom::math::Axis::Z),
        order: std::sync::Arc::new(asp_search::BuiltinOrder::Random),
        seed: 7,
        bookkeeping: true,
        max_tests: Some(500),
        ..PlanSettings::default()
    };
    let by_hand = pipeline::plan_file(&table, &settings, None).unwrap();
    assert!(by_request.found());
    assert_eq!(untimed(&by_request.report.to_json()), untimed(&by_hand.report.to_json()));

    let request = PlanRequest::from_json(r#"{"up": "z", "objective": ["access"], "episodes": 40, "threads": 1, "seed": 2}"#).unwrap();
    let by_request = asp_app::plan_file(&table, &request, Hooks::default()).unwrap();
    // without `q`, the request gets the default guidance (the shipped seeds)
    let policy = asp_app::catalogue::default_guidance(&["access"], 9).unwrap().map(|q| std::sync::Arc::new(q) as _);
    assert!(policy.is_some());
    let o = OptimiseSettings { objectives: vec!["access".into()], episodes: 40, threads: Some(1), policy, ..OptimiseSettings::default() };
    let settings = PlanSettings { up: Some(asp_geom::math::Axis::Z), seed: 2, optimise: Some(o), ..PlanSettings::default() };
    let by_hand = pipeline::plan_file(&table, &settings, None).unwrap();
    assert_eq!(untimed(&by_request.report.to_json()), untimed(&by_hand.report.to_json()));
}

#[test]
fn a_setting_of_the_other_search_stops_the_run_before_it_loads() {
    // the model does not exist: the request is refused first, naming the setting
    let request = PlanRequest::from_json(r#"{"objective": "access", "timeout": 10}"#).unwrap();
    let e = asp_app::plan_file(&data("no/such/model.glb"), &request, Hooks::default()).unwrap_err();
    assert_eq!(
        e.render(&|k: &str| format!("--{}", k.replace('_', "-"))),
        "--timeout: applies to the feasibility search only (without --objective); the optimiser's limit is --time-limit"
    );
}

/// A copy of asp-learn's `random_gnn.onnx` fixture (the default features) whose metadata says it
/// was trained on `checker`'s labels: a `metadata_props` entry (ModelProto field 14) appended to
/// the protobuf, which a parser merges into the repeated field.
fn model_of_checker(dir: &std::path::Path, checker: &str) -> PathBuf {
    let mut bytes =
        std::fs::read(std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../asp-learn/tests/data/random_gnn.onnx")).unwrap();
    let (key, value) = (b"asp.checker", checker.as_bytes());
    let mut entry = vec![0x0a, key.len() as u8];
    entry.extend_from_slice(key);
    entry.extend_from_slice(&[0x12, value.len() as u8]);
    entry.extend_from_slice(value);
    bytes.extend_from_slice(&[0x72, entry.len() as u8]);
    bytes.extend_from_slice(&entry);
    let path = dir.join(format!("rem_{checker}.onnx"));
    std::fs::write(&path, bytes).unwrap();
    path
}

/// A model must rank for the checker of the run that uses it; without a file,
/// the run's checker picks the shipped model.
#[test]
fn a_model_of_another_checker_is_refused_and_the_shipped_one_follows_the_checker() {
    let dir = tempfile::tempdir().unwrap();
    let physics = model_of_checker(dir.path(), "physics");
    let request = |json: serde_json::Value| PlanRequest::from_json(&json.to_string()).unwrap();
    let p = physics.to_str().unwrap();
    let e = asp_app::resolve::resolve(&request(serde_json::json!({"order": "gnn", "model": p}))).unwrap_err().to_string();
    assert_eq!(e, format!("model: {p}: trained on labels of the physics checker, this run uses the default checker"));
    // the same file under physics: accepted, by `gnn` and by `auto`
    for order in ["gnn", "auto"] {
        let s = asp_app::resolve::resolve(&request(serde_json::json!({"order": order, "model": p, "stability": "physics"}))).unwrap();
        assert_eq!((s.order.name(), s.label_checker()), ("gnn".to_string(), asp_learn::Checker::Physics));
    }
    // a file without `asp.checker` is the default checker's: refused under physics and the robot
    let plain = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../asp-learn/tests/data/random_gnn.onnx");
    let q = plain.to_str().unwrap();
    let e = asp_app::resolve::resolve(&request(serde_json::json!({"order": "gnn", "model": q, "stability": "physics"}))).unwrap_err();
    assert!(e.to_string().ends_with("trained on labels of the default checker, this run uses the physics checker"), "{e}");
    let e = asp_app::resolve::resolve(&request(serde_json::json!({"order": "gnn", "model": q, "robot": "panda"}))).unwrap_err();
    assert!(e.to_string().ends_with("trained on labels of the default checker, this run uses the robot checker"), "{e}");
    assert!(asp_app::resolve::resolve(&request(serde_json::json!({"order": "gnn", "model": q}))).is_ok());
    // an unknown checker is the file's error
    let bad = model_of_checker(dir.path(), "magic");
    let e = asp_app::resolve::resolve(&request(serde_json::json!({"order": "gnn", "model": bad.to_str().unwrap()}))).unwrap_err();
    assert!(e.to_string().ends_with("asp.checker is 'magic', expected one of default, physics, robot"), "{e}");
    // no file: the shipped model of the run's checker (the default checker's where none is shipped)
    for (json, checker) in [
        (serde_json::json!({"order": "gnn"}), asp_learn::Checker::Default),
        (serde_json::json!({"order": "gnn", "stability": "physics"}), asp_learn::Checker::Physics),
        (serde_json::json!({"stability": "physics"}), asp_learn::Checker::Physics),
        (serde_json::json!({"order": "gnn", "robot": "panda"}), asp_learn::Checker::Robot),
    ] {
        let s = asp_app::resolve::resolve(&request(json.clone())).unwrap();
        assert_eq!(s.label_checker(), checker, "{json}");
        let source = asp_app::catalogue::gnn_source(None, s.label_checker()).unwrap();
        assert_eq!(source.model().path(), format!("{} (shipped)", asp_learn::shipped_model(checker).file));
        // every checker has its own shipped model
        assert_eq!(source.model().checker(), checker, "{json}");
    }
}
