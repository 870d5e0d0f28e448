//! The setting flags, built from asp-app's settings table ([`asp_app::settings::SETTINGS`]) with
//! clap's builder API: one argument per setting (its flag, help, choices and value name from
//! the table), and the matches read back as request keys. Which settings a command takes is a
//! [`Selection`]: `asp plan` takes every group, `collect` and `bench` the model's and the robot's
//! (and `bench mcts` the optimiser's distance-map settings).

use super::Map;
use asp_app::settings::{Flag, Group, Kind, Setting, SETTINGS};
use clap::builder::{PossibleValue, PossibleValuesParser};
use clap::{Arg, ArgAction, ArgMatches, Args, FromArgMatches};
use std::marker::PhantomData;

/// Which settings a command's flags are.
pub trait Selection: Clone + std::fmt::Debug + Default + Send + Sync + 'static {
    /// Whether the command takes `setting`.
    fn takes(setting: &Setting) -> bool;
}

/// Loading and the removal test (every planning command).
#[derive(Clone, Debug, Default)]
pub struct ModelGroup;
impl Selection for ModelGroup {
    fn takes(s: &Setting) -> bool {
        s.group == Group::Model
    }
}

/// The feasibility search of `asp plan`.
#[derive(Clone, Debug, Default)]
pub struct SearchGroup;
impl Selection for SearchGroup {
    fn takes(s: &Setting) -> bool {
        s.group == Group::Search
    }
}

/// The optimiser of `asp plan`.
#[derive(Clone, Debug, Default)]
pub struct OptimiseGroup;
impl Selection for OptimiseGroup {
    fn takes(s: &Setting) -> bool {
        s.group == Group::Optimisation
    }
}

/// The robot.
#[derive(Clone, Debug, Default)]
pub struct RobotGroup;
impl Selection for RobotGroup {
    fn takes(s: &Setting) -> bool {
        s.group == Group::Robot
    }
}

/// The optimiser's settings that shape the distance maps and the search, which `collect
/// transitions` and `bench mcts` take besides their own (`objective`, `episodes`, `threads`, `q`
/// and `epsilon` mean something of their own there).
#[derive(Clone, Debug, Default)]
pub struct MapsGroup;
impl Selection for MapsGroup {
    fn takes(s: &Setting) -> bool {
        matches!(s.key, "budget" | "exploration" | "polish" | "resolution" | "d_max" | "support")
    }
}

/// The flags of the settings `S` selects, as the request keys given.
#[derive(Clone, Debug, Default)]
pub struct SettingArgs<S: Selection> {
    /// The keys given on the command line, with their values as the request reads them.
    pub map: Map,
    selection: PhantomData<S>,
}

impl<S: Selection> SettingArgs<S> {
    /// Puts the keys given into `map`.
    pub fn put(&self, map: &mut Map) {
        map.extend(self.map.clone());
    }
}

/// The id of the `--no-KEY` switch of a setting that also takes a mode.
fn off_id(key: &str) -> String {
    format!("no_{key}")
}

/// The arguments of `setting`: usually one, two for a switch with a mode.
fn args(s: &Setting) -> Vec<Arg> {
    let long = s.key.replace('_', "-");
    let heading = match s.group {
        Group::Optimisation => Some("Optimisation"),
        Group::Robot => Some("Robot"),
        _ => None,
    };
    // clap's own style: no full stop before the default it appends
    let mut help = match s.flag {
        Flag::Off => format!("Sets `{}` false. {}", s.key, s.help.trim_end_matches('.')),
        _ => s.help.trim_end_matches('.').to_string(),
    };
    if !s.derived.is_empty() {
        help.push_str(&format!(" [default: {}]", s.derived));
    }
    let value_name = if s.value_name.is_empty() { s.key.to_uppercase() } else { s.value_name.to_string() };
    let arg = Arg::new(s.key).long(long.clone()).help(help).help_heading(heading);
    let arg = match s.kind {
        Kind::Int => arg.value_parser(clap::value_parser!(u64)),
        Kind::Float => arg.value_parser(clap::value_parser!(f64)),
        Kind::Choice => arg.value_parser(PossibleValuesParser::new((s.choices)().into_iter().map(|(n, h)| PossibleValue::new(n).help(h)))),
        Kind::Text | Kind::Bool => arg,
    };
    match s.flag {
        Flag::Value => vec![arg.value_name(value_name).action(ArgAction::Set)],
        Flag::On => vec![arg.action(ArgAction::SetTrue)],
        Flag::Off => vec![arg.long(format!("no-{long}")).action(ArgAction::SetTrue)],
        Flag::OffOrMode(mode) => vec![
            Arg::new(off_id(s.key))
                .long(format!("no-{long}"))
                .help(format!("Sets `{}` false. {}", s.key, s.help.split(". ").next().unwrap_or_default()))
                .help_heading(heading)
                .action(ArgAction::SetTrue),
            arg.value_name(value_name).value_parser([mode]).action(ArgAction::Set).conflicts_with(off_id(s.key)),
        ],
        Flag::Repeat => vec![arg.value_name(value_name).action(ArgAction::Append)],
        Flag::Many => vec![arg.value_name(value_name).num_args(1..).action(ArgAction::Append)],
    }
}

/// The request value of `s` in `m`, if given.
fn value(s: &Setting, m: &ArgMatches) -> Option<serde_json::Value> {
    use serde_json::Value;
    match s.flag {
        Flag::On => m.get_flag(s.key).then_some(Value::Bool(true)),
        Flag::Off => m.get_flag(s.key).then_some(Value::Bool(false)),
        Flag::OffOrMode(_) => match m.get_one::<String>(s.key) {
            Some(mode) => Some(Value::String(mode.clone())),
            None => m.get_flag(&off_id(s.key)).then_some(Value::Bool(false)),
        },
        Flag::Repeat | Flag::Many => {
            let v: Vec<Value> = m.get_many::<String>(s.key)?.map(|v| Value::String(v.clone())).collect();
            (!v.is_empty()).then_some(Value::Array(v))
        }
        Flag::Value => match s.kind {
            Kind::Int => m.get_one::<u64>(s.key).map(|v| serde_json::json!(v)),
            Kind::Float => m.get_one::<f64>(s.key).map(|v| serde_json::json!(v)),
            _ => m.get_one::<String>(s.key).map(|v| Value::String(v.clone())),
        },
    }
}

impl<S: Selection> FromArgMatches for SettingArgs<S> {
    fn from_arg_matches(m: &ArgMatches) -> Result<Self, clap::Error> {
        let mut args = SettingArgs::default();
        args.update_from_arg_matches(m)?;
        Ok(args)
    }

    fn update_from_arg_matches(&mut self, m: &ArgMatches) -> Result<(), clap::Error> {
        for s in SETTINGS.iter().filter(|s| S::takes(s)) {
            if let Some(v) = value(s, m) {
                self.map.insert(s.key.to_string(), v);
            }
        }
        Ok(())
    }
}

impl<S: Selection> Args for SettingArgs<S> {
    fn augment_args(cmd: clap::Command) -> clap::Command {
        cmd.args(SETTINGS.iter().filter(|s| S::takes(s)).flat_map(args))
    }

    fn augment_args_for_update(cmd: clap::Command) -> clap::Command {
        Self::augment_args(cmd)
    }
}
