//! Every setting of a planning run, declared once (as ripgrep declares each flag once).
//!
//! One entry of the `settings!` table in `settings/table.rs` gives a setting its key,
//! its Rust type (the field of [`PlanRequest`]), its help, its default, its accepted names, the
//! search it applies to and its command-line spelling. Everything else reads that entry:
//!
//! - [`PlanRequest`]'s field (the macro writes the struct, with the help as its doc);
//! - the flags of `asp plan` and the setting flags of `collect`, `bench` and `check` (asp-cli
//!   builds them with clap's builder API from [`SETTINGS`]);
//! - [`crate::resolve::defaults`] and the applicability errors of [`crate::resolve()`];
//! - Python's `asp.settings` (`Literal`s and the `PlanSettings` `TypedDict`) and the keywords and
//!   docstring of `Assembly.plan`, and the key table of `docs/plan-request.md`: rendered by
//!   `settings/render.rs` ([`python_settings`], [`python_plan`], [`docs_keys`]) and held to the
//!   checked-in files by a test (`ASP_REGENERATE=1` rewrites them).
//!
//! What a setting does stays where it is used: [`crate::resolve()`] turns the request into the
//! pipeline's settings.

mod render;
mod table;

pub use render::{docs_keys, python_plan, python_settings, REGENERATE};
pub use table::{PlanRequest, SETTINGS};

use crate::values::Choice;
use serde_json::Value;

/// Which search reads a setting: a setting of the other search is an error naming what applies.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Applies {
    /// Loading a model (`asp.load` in Python, not `Assembly.plan`).
    Load,
    /// Both searches.
    Both,
    /// The feasibility (depth-first) search only: without `objective`.
    Feasibility,
    /// The optimiser only: with `objective`.
    Optimiser,
}

/// Where a setting's flag sits among the command's flags (and its `--help` heading).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Group {
    /// Loading and the removal test: the flags every planning command shares.
    Model,
    /// The feasibility search of `asp plan`.
    Search,
    /// The optimiser (`--help` heading "Optimisation").
    Optimisation,
    /// The robot (`--help` heading "Robot").
    Robot,
}

/// What a setting's value is, on the command line and in Python.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// A non-negative integer.
    Int,
    /// A number.
    Float,
    /// A switch: `true` or `false`.
    Bool,
    /// A string (a name, a path).
    Text,
    /// One of a closed set of names ([`Setting::choices`]).
    Choice,
}

/// How a setting is spelled on the command line (the flag is `--` and the key with `-` for `_`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Flag {
    /// `--key VALUE`.
    Value,
    /// `--key` sets `true`.
    On,
    /// `--no-key` sets `false` (the default is true).
    Off,
    /// `--no-key` sets `false`; `--key MODE` sets the mode, its one value.
    OffOrMode(&'static str),
    /// `--key VALUE`, repeated for several.
    Repeat,
    /// `--key VALUE...`: one or more values.
    Many,
}

/// One setting: everything asp knows about it besides what it does (module documentation).
#[derive(Clone, Copy, Debug)]
pub struct Setting {
    /// The request key (the Python keyword; the flag with `-` for `_`).
    pub key: &'static str,
    /// What it does, one paragraph (`--help`, the docstring, the docs). Names of other settings
    /// are in backticks.
    pub help: &'static str,
    /// Which search reads it.
    pub applies: Applies,
    /// What the other search has instead (`""`: nothing), appended to the applicability error.
    pub instead: &'static str,
    /// What else it needs, in words for the docs (`"with \`robot\`"`); the check is in
    /// [`crate::resolve()`].
    pub needs: &'static str,
    /// Its flag's place.
    pub group: Group,
    /// Its value.
    pub kind: Kind,
    /// Its flag's spelling.
    pub flag: Flag,
    /// The flag's value name in `--help` (`""`: the key in capitals).
    pub value_name: &'static str,
    /// The default as the searches use it (`null`: none, or one [`Setting::derived`] describes).
    pub default: fn() -> Value,
    /// The default in words where it depends on the model or the machine (`""`: [`Setting::default`]
    /// says it all).
    pub derived: &'static str,
    /// The accepted names with one line of help each (empty but for closed sets).
    pub choices: fn() -> Vec<(&'static str, &'static str)>,
    /// Its type in Python (the keyword's, without `| None`).
    pub python: &'static str,
}

fn null() -> Value {
    Value::Null
}

fn no_choices() -> Vec<(&'static str, &'static str)> {
    Vec::new()
}

/// The names and help of a closed set, for [`Setting::choices`].
pub fn choices<T: Choice>() -> Vec<(&'static str, &'static str)> {
    T::CHOICES.iter().map(|(_, name, help)| (*name, *help)).collect()
}

/// The part orderings of the catalogue, for `order`'s [`Setting::choices`].
fn orderings() -> Vec<(&'static str, &'static str)> {
    crate::catalogue::ORDERINGS.iter().map(|o| (o.name, o.help)).collect()
}

impl Setting {
    /// The fields most settings share: a value flag of the feasibility search, no default.
    pub const BASE: Setting = Setting {
        key: "",
        help: "",
        applies: Applies::Feasibility,
        instead: "",
        needs: "",
        group: Group::Search,
        kind: Kind::Text,
        flag: Flag::Value,
        value_name: "",
        default: null,
        derived: "",
        choices: no_choices,
        python: "str",
    };

    /// The setting called `key`.
    pub fn get(key: &str) -> Option<&'static Setting> {
        SETTINGS.iter().find(|s| s.key == key)
    }

    /// Its command-line flag: `--max-tests`, `--no-path-planner`.
    pub fn flag_name(&self) -> String {
        match self.flag {
            Flag::Off | Flag::OffOrMode(_) => format!("--no-{}", self.key.replace('_', "-")),
            _ => format!("--{}", self.key.replace('_', "-")),
        }
    }

    /// The default in words: [`Setting::derived`], else the value (`none` for `null` and `[]`).
    pub fn default_text(&self) -> String {
        if !self.derived.is_empty() {
            return self.derived.to_string();
        }
        match (self.default)() {
            Value::Null => "none".into(),
            Value::Array(a) if a.is_empty() => "none".into(),
            Value::String(s) => s,
            other => other.to_string(),
        }
    }
}

/// Declares the settings: each entry is a field of [`PlanRequest`] (its attributes, its key and
/// type) and the rest of its [`Setting`] (the help first, then any field that differs from
/// [`Setting::BASE`]).
macro_rules! settings {
    ($( $(#[$attr:meta])* $key:ident : $ty:ty { help: $help:literal $(, $field:ident : $value:expr)* $(,)? } )*) => {
        /// Every setting of a planning run (see [`crate::request`]; each field's doc is its help
        /// in [`SETTINGS`]). Lengths are in model units.
        #[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
        #[serde(default, deny_unknown_fields)]
        pub struct PlanRequest {
            $( #[doc = $help] $(#[$attr])* pub $key: $ty, )*
        }

        /// Every setting, in the order the docs list them.
        pub const SETTINGS: &[Setting] = &[
            $( Setting { key: stringify!($key), help: $help $(, $field: $value)*, ..Setting::BASE }, )*
        ];
    };
}
use settings;
