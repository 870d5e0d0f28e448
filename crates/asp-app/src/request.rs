//! The plan request: every setting of a planning run as plain data, serde-(de)serialisable.
//!
//! A request says what its user asked for and nothing more: every field is optional, and a
//! field left out takes the default of the search it belongs to. The defaults live in one place,
//! [`crate::resolve()`] (reading the library constants), and [`crate::resolve::defaults`] lists them.
//! The keys are the Python keywords of `asp.Assembly.plan` and, with `-` for `_`, the flags of
//! `asp plan` (`max_tests` is `--max-tests`; the switches `path_planner`, `subassemblies` and
//! `grid` are `--no-path-planner`, ...). A setting that does not apply to the chosen search (an
//! optimiser setting without `objective`, a feasibility-search setting with one) is an error
//! naming the setting that does, never silently ignored.
//!
//! ```
//! use asp_app::PlanRequest;
//! let r = PlanRequest::from_json(r#"{"objective": "access,dirchange", "pareto": true, "episodes": 50}"#).unwrap();
//! assert_eq!(r.objective.as_deref(), Some(&["access".to_string(), "dirchange".to_string()][..]));
//! let e = PlanRequest::from_json(r#"{"episode": 50}"#).unwrap_err();
//! assert_eq!(e.to_string(), "episode: unknown setting (did you mean `episodes`?)");
//! ```

use crate::error::{AppError, Result};

pub use crate::values::{Choice, Stability, Subassemblies};

pub use crate::settings::PlanRequest;

/// Whether `key` belongs to loading a model only (`asp.load` in Python, not `Assembly.plan`).
pub fn is_load_key(key: &str) -> bool {
    crate::settings::Setting::get(key).is_some_and(|s| s.applies == crate::settings::Applies::Load)
}

impl PlanRequest {
    /// Every key of a request, in alphabetical order.
    pub fn keys() -> Vec<String> {
        let mut keys: Vec<String> = crate::settings::SETTINGS.iter().map(|s| s.key.to_string()).collect();
        keys.sort();
        keys
    }

    /// A request from a JSON object. An unknown key, or a value of the wrong type, is an
    /// [`AppError::Setting`] naming the key.
    pub fn from_json(text: &str) -> Result<PlanRequest> {
        let value: serde_json::Value = serde_json::from_str(text).map_err(|e| AppError::setting("request", format!("not JSON: {e}")))?;
        PlanRequest::from_value(value)
    }

    /// A request from a JSON value (an object of settings; `null` values are left out).
    pub fn from_value(value: serde_json::Value) -> Result<PlanRequest> {
        let serde_json::Value::Object(map) = value else {
            return Err(AppError::setting("request", "settings must be an object of key: value"));
        };
        let keys = PlanRequest::keys();
        let mut request = serde_json::Map::new();
        for (key, v) in map {
            if !keys.contains(&key) {
                let hint = keys
                    .iter()
                    .filter(|k| k.starts_with(key.get(..3).unwrap_or(&key)) || key.starts_with(k.as_str()))
                    .min_by_key(|k| k.len().abs_diff(key.len()));
                return Err(AppError::setting(
                    &key,
                    match hint {
                        Some(h) => format!("unknown setting (did you mean `{h}`?)"),
                        None => "unknown setting".into(),
                    },
                ));
            }
            if v.is_null() {
                continue;
            }
            // one key at a time, so that a type error names its key
            let mut one = serde_json::Map::new();
            one.insert(key.clone(), v.clone());
            serde_json::from_value::<PlanRequest>(serde_json::Value::Object(one))
                .map_err(|e| AppError::setting(&key, type_message(&e.to_string())))?;
            request.insert(key, v);
        }
        serde_json::from_value(serde_json::Value::Object(request)).map_err(|e| AppError::setting("request", e.to_string()))
    }

    /// The request as JSON (only the settings given).
    pub fn to_json(&self) -> String {
        let mut value = serde_json::to_value(self).unwrap_or_default();
        if let serde_json::Value::Object(map) = &mut value {
            map.retain(|_, v| !v.is_null() && !v.as_array().is_some_and(Vec::is_empty));
        }
        value.to_string()
    }

    /// Whether the request asks for the optimiser.
    pub fn optimises(&self) -> bool {
        self.objective.is_some()
    }

    /// The settings given, by key, in alphabetical order (every field that is not left out: not
    /// `None`, not an empty list). Read off the serialised request, so a new field is counted
    /// without being listed here.
    pub fn given(&self) -> Vec<String> {
        match serde_json::to_value(self) {
            Ok(serde_json::Value::Object(map)) => {
                map.into_iter().filter(|(_, v)| !v.is_null() && !v.as_array().is_some_and(Vec::is_empty)).map(|(k, _)| k).collect()
            }
            _ => Vec::new(),
        }
    }
}

/// serde's words for a type error, without its position and in ours where we can.
fn type_message(serde: &str) -> String {
    let text = serde.split(" at line ").next().unwrap_or(serde);
    if let Some(rest) = text.strip_prefix("invalid type: ").or_else(|| text.strip_prefix("invalid value: ")) {
        if let Some((got, want)) = rest.split_once(", expected ") {
            return format!("must be {}, got {}", want_words(want), got_words(got));
        }
    }
    if let Some(rest) = text.strip_prefix("unknown variant ") {
        if let Some((got, want)) = rest.split_once(", expected ") {
            let want = want.trim_start_matches("one of ").replace(" or ", ", ");
            let names: Vec<&str> = want.split(", ").map(|n| n.trim_matches('`')).collect();
            return format!("unknown value '{}' (use {})", got.trim_matches('`'), names.join(", "));
        }
    }
    text.replace('`', "'")
}

/// The value serde saw, as a user wrote it (`integer `-1`` is -1, `string "x"` is 'x').
fn got_words(serde: &str) -> String {
    for prefix in ["integer ", "floating point ", "boolean "] {
        if let Some(v) = serde.strip_prefix(prefix) {
            return v.trim_matches('`').to_string();
        }
    }
    match serde.strip_prefix("string ") {
        Some(s) => format!("'{}'", s.trim_matches('"')),
        None => serde.replace('`', ""),
    }
}

fn want_words(serde: &str) -> &str {
    match serde {
        "u64" | "usize" | "u32" => "a non-negative integer",
        "f64" | "f32" => "a number",
        "a boolean" => "true or false",
        other => other,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::PathBuf;

    #[test]
    fn keys_are_every_field_and_json_round_trips() {
        let keys = PlanRequest::keys();
        assert_eq!(keys.len(), 48, "{keys:?}");
        assert!(keys.iter().any(|k| k == "time_limit") && keys.iter().any(|k| k == "robot_base"));
        let r = PlanRequest {
            objective: Some(vec!["access".into()]),
            q_use: Some(asp_search::QUse::Both),
            overlaps: Some(asp_geom::OverlapPolicy::Lenient),
            robot_base: Some([1.0, 2.0, 3.0]),
            fixed: vec!["base".into()],
            unit_group: vec![vec!["motor".into(), "fan".into()]],
            ..PlanRequest::default()
        };
        assert_eq!(PlanRequest::from_json(&r.to_json()).unwrap(), r);
        assert_eq!(r.given(), ["fixed", "objective", "overlaps", "q_use", "robot_base", "unit_group"]);
    }

    #[test]
    fn bad_settings_name_their_key() {
        let e = |json: &str| PlanRequest::from_json(json).unwrap_err().to_string();
        assert_eq!(e(r#"{"seed": "x"}"#), "seed: must be a non-negative integer, got 'x'");
        assert_eq!(e(r#"{"seed": -1}"#), "seed: must be a non-negative integer, got -1");
        assert_eq!(e(r#"{"bookkeeping": "yes"}"#), "bookkeeping: must be true or false, got 'yes'");
        assert_eq!(e(r#"{"tolerance": "small"}"#), "tolerance: must be a number, got 'small'");
        assert_eq!(e(r#"{"overlaps": "loose"}"#), "overlaps: unknown value 'loose' (use strict, lenient, error)");
        assert_eq!(e(r#"{"stability": "glue"}"#), "stability: unknown value 'glue' (use contact, physics)");
        assert_eq!(e(r#"{"robot_base": "1,2"}"#), "robot_base: must be three finite numbers x,y,z");
        assert_eq!(e(r#"{"colour": 1}"#), "colour: unknown setting");
        assert_eq!(e(r#"{"timeouts": 1}"#), "timeouts: unknown setting (did you mean `timeout`?)");
        assert_eq!(e("[1]"), "request: settings must be an object of key: value");
    }

    #[test]
    fn lists_come_as_strings_or_lists_and_nulls_are_left_out() {
        let r = PlanRequest::from_json(
            r#"{"objective": ["access", "dirchange"], "q": "a.onnx, b.onnx", "robot_base": "1, 2, 3", "timeout": null}"#,
        )
        .unwrap();
        assert_eq!(r.objective, Some(vec!["access".to_string(), "dirchange".to_string()]));
        assert_eq!(r.q, Some(vec![PathBuf::from("a.onnx"), PathBuf::from("b.onnx")]));
        assert_eq!(r.robot_base, Some([1.0, 2.0, 3.0]));
        assert_eq!(r.timeout, None);
        assert_eq!(asp_geom::OverlapPolicy::parse("error"), Some(asp_geom::OverlapPolicy::Error));
        assert_eq!(asp_search::QUse::names(), "rollouts, expansions, both, priors, seed");
        assert_eq!(asp_geom::distmap::Support::ContactGraph.name(), "contact");
    }
}
