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
use serde::{Deserialize, Deserializer, Serialize};
use std::path::PathBuf;

/// A closed set of named values (`overlaps`, `stability`, `support`, `q_use`): the names with
/// one line of help each, for `--help`, Python's `Literal`s and error messages. The library's
/// own enums carry it where they exist (`asp_geom::OverlapPolicy`, `asp_geom::distmap::Support`,
/// `asp_search::QUse`), so a request holds the value the pipeline uses, with no mirror to match.
pub trait Choice: Sized + Copy + PartialEq + 'static {
    /// Every value with its name and its one-line help, in the order the docs list them.
    const CHOICES: &'static [(Self, &'static str, &'static str)];

    /// The value called `name`.
    fn parse(name: &str) -> Option<Self> {
        Self::CHOICES.iter().find(|(_, n, _)| *n == name).map(|(v, _, _)| *v)
    }

    /// The names, comma-separated (for messages).
    fn names() -> String {
        Self::CHOICES.iter().map(|(_, n, _)| *n).collect::<Vec<_>>().join(", ")
    }

    /// The value's name.
    fn name(self) -> &'static str {
        Self::CHOICES.iter().find(|(v, _, _)| *v == self).map(|(_, n, _)| *n).unwrap_or("?")
    }
}

/// Gives a closed set its names and help ([`Choice`]).
macro_rules! choice {
    ($name:ty { $($variant:ident = $text:expr => $help:literal,)+ }) => {
        impl Choice for $name {
            const CHOICES: &'static [(Self, &'static str, &'static str)] = &[$((<$name>::$variant, $text, $help),)+];
        }
    };
}

choice!(asp_geom::OverlapPolicy {
    Strict = "strict" => "an overlapping pair separates only along motions that enter no new material of each other (a dowel leaves along its axis, never sideways)",
    Lenient = "lenient" => "shrink one part of the pair in their tests; ignore pairs no shrinking separates",
    Error = "error" => "shrink small overlaps; stop with an error on pairs no shrinking separates",
});

/// The stability criterion of the feasibility search. The library's
/// [`crate::pipeline::StabilitySetting`] carries the physics threshold, a setting of its own
/// (`physics_threshold`), so the request names the criterion alone.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stability {
    /// Linked through contacts to a fixed part.
    Contact,
    /// Simulated under gravity.
    Physics,
}

choice!(Stability {
    Contact = "contact" => "every part linked through contacts to a fixed part",
    Physics = "physics" => "simulate what remains under gravity (rapier3d); unstable when a part moves more than `physics_threshold`",
});

choice!(asp_geom::distmap::Support {
    Below = "below" => "every part rests on a part or the floor directly beneath it (thesis 6.3.2)",
    ContactGraph = "contact" => "every part linked through contacts to a fixed part or the floor",
});

choice!(asp_search::QUse {
    Rollouts = asp_search::QUse::NAMES[0] => "ε-greedy rollouts (thesis: one evaluation per rollout step)",
    Expansions = asp_search::QUse::NAMES[1] => "the Q-values of each state the search adds order its expansions; rollouts stay random (one evaluation per node)",
    Both = asp_search::QUse::NAMES[2] => "ε-greedy rollouts and Q-ordered expansions",
    Priors = asp_search::QUse::NAMES[3] => "the Q-values of each state the search adds are PUCT priors (expansion order and a bonus in the tree policy), a greedy sequence on them seeds the local search; rollouts stay random (one evaluation per node, cached by state)",
});

/// A closed set's value in a request, by its [`Choice`] name (`#[serde(with = "...choice")]`).
pub(crate) mod choice {
    use super::Choice;
    use serde::{Deserialize, Deserializer, Serializer};

    pub fn serialize<S: Serializer, T: Choice>(v: &Option<T>, s: S) -> Result<S::Ok, S::Error> {
        match v {
            Some(v) => s.serialize_str(v.name()),
            None => s.serialize_none(),
        }
    }

    pub fn deserialize<'de, D: Deserializer<'de>, T: Choice>(d: D) -> Result<Option<T>, D::Error> {
        match Option::<String>::deserialize(d)? {
            None => Ok(None),
            Some(name) => {
                T::parse(&name).map(Some).ok_or_else(|| serde::de::Error::custom(format!("unknown value '{name}' (use {})", T::names())))
            }
        }
    }
}

/// The `subassemblies` setting: on, off, or the file's own product tree.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Subassemblies {
    /// Groups of parts the search finds leave together when no single part can (the default).
    On,
    /// Single parts only.
    Off,
    /// Each subassembly of the file's product tree planned on its own, then the level above with
    /// each as one unit.
    FromFile,
}

impl Subassemblies {
    /// The name of the tree mode, as the flag and the request spell it.
    pub const FROM_FILE: &'static str = "from-file";

    /// Whether groups may leave together (everything but `Off`).
    pub fn allowed(self) -> bool {
        self != Subassemblies::Off
    }
}

impl Serialize for Subassemblies {
    fn serialize<S: serde::Serializer>(&self, s: S) -> std::result::Result<S::Ok, S::Error> {
        match self {
            Subassemblies::On => s.serialize_bool(true),
            Subassemblies::Off => s.serialize_bool(false),
            Subassemblies::FromFile => s.serialize_str(Subassemblies::FROM_FILE),
        }
    }
}

impl<'de> Deserialize<'de> for Subassemblies {
    fn deserialize<D: Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        #[derive(Deserialize)]
        #[serde(untagged)]
        enum Raw {
            Switch(bool),
            Mode(String),
        }
        match Raw::deserialize(d) {
            Ok(Raw::Switch(true)) => Ok(Subassemblies::On),
            Ok(Raw::Switch(false)) => Ok(Subassemblies::Off),
            Ok(Raw::Mode(m)) if m == Subassemblies::FROM_FILE => Ok(Subassemblies::FromFile),
            _ => Err(serde::de::Error::custom("must be true, false or 'from-file'")),
        }
    }
}

/// [`Subassemblies`], optional.
pub(crate) fn subassemblies<'de, D: Deserializer<'de>>(d: D) -> std::result::Result<Option<Subassemblies>, D::Error> {
    Option::<Subassemblies>::deserialize(d)
}

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

/// A comma-separated string or a list of strings, as a list (blank names dropped).
pub(crate) fn names<'de, D: Deserializer<'de>>(d: D) -> std::result::Result<Option<Vec<String>>, D::Error> {
    #[derive(Deserialize)]
    #[serde(untagged)]
    enum OneOrMany {
        One(String),
        Many(Vec<String>),
    }
    let split = |s: &str| s.split(',').map(str::trim).filter(|n| !n.is_empty()).map(String::from).collect::<Vec<_>>();
    Ok(
        match Option::<OneOrMany>::deserialize(d)
            .map_err(|_| serde::de::Error::custom("must be a comma-separated string or a list of strings"))?
        {
            None => None,
            Some(OneOrMany::One(s)) => Some(split(&s)),
            Some(OneOrMany::Many(v)) => Some(v.iter().flat_map(|s| split(s)).collect()),
        },
    )
}

/// Groups of names: a list whose items are each a comma-separated string or a list of names, or
/// one comma-separated string (one group).
pub(crate) fn groups<'de, D: Deserializer<'de>>(d: D) -> std::result::Result<Vec<Vec<String>>, D::Error> {
    #[derive(Deserialize)]
    #[serde(untagged)]
    enum Group {
        Text(String),
        Names(Vec<String>),
    }
    #[derive(Deserialize)]
    #[serde(untagged)]
    enum Groups {
        One(String),
        Many(Vec<Group>),
    }
    let split = |s: &str| s.split(',').map(str::trim).filter(|n| !n.is_empty()).map(String::from).collect::<Vec<_>>();
    let bad = || serde::de::Error::custom("must be a list of groups, each a comma-separated string or a list of part names");
    Ok(match Option::<Groups>::deserialize(d).map_err(|_| bad())? {
        None => Vec::new(),
        Some(Groups::One(s)) => vec![split(&s)],
        Some(Groups::Many(v)) => v
            .into_iter()
            .map(|g| match g {
                Group::Text(s) => split(&s),
                Group::Names(names) => names.into_iter().map(|n| n.trim().to_string()).filter(|n| !n.is_empty()).collect(),
            })
            .collect(),
    })
}

/// [`names`] as paths.
pub(crate) fn paths<'de, D: Deserializer<'de>>(d: D) -> std::result::Result<Option<Vec<PathBuf>>, D::Error> {
    Ok(names(d)?.map(|v| v.into_iter().map(PathBuf::from).collect()))
}

/// Three numbers, as a list or as `"x,y,z"`.
pub(crate) fn point<'de, D: Deserializer<'de>>(d: D) -> std::result::Result<Option<[f64; 3]>, D::Error> {
    #[derive(Deserialize)]
    #[serde(untagged)]
    enum Point {
        Text(String),
        List(Vec<f64>),
    }
    let bad = || serde::de::Error::custom("must be three finite numbers x,y,z");
    let v: Vec<f64> = match Option::<Point>::deserialize(d).map_err(|_| bad())? {
        None => return Ok(None),
        Some(Point::List(v)) => v,
        Some(Point::Text(s)) => s.split(',').map(|x| x.trim().parse::<f64>()).collect::<std::result::Result<_, _>>().map_err(|_| bad())?,
    };
    match v[..] {
        [x, y, z] if v.iter().all(|c| c.is_finite()) => Ok(Some([x, y, z])),
        _ => Err(bad()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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
        assert_eq!(asp_search::QUse::names(), "rollouts, expansions, both, priors");
        assert_eq!(asp_geom::distmap::Support::ContactGraph.name(), "contact");
    }
}
