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
    let o = OptimiseSettings { objectives: "access".into(), episodes: 40, threads: Some(1), ..OptimiseSettings::default() };
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
