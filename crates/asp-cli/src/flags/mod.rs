//! Command-line flags: one low layer of clap structs that the commands read. The flags of
//! planning runs are the keys of [`asp_app::PlanRequest`] (`--max-tests` is `max_tests`; the
//! switches `--no-path-planner`, `--no-subassemblies` and `--no-grid` set `path_planner`,
//! `subassemblies` and `grid` to false); their defaults and accepted values come from asp-app
//! (`resolve::defaults()` and the catalogue), so `--help` cannot drift from what runs.

/// Request settings as JSON, by key: what the flags given set.
pub type Map = serde_json::Map<String, serde_json::Value>;

/// Puts each `Some` field of `$args` into `$map` under its name (the request key).
macro_rules! put {
    ($map:expr, $args:expr, $($field:ident),+) => {$(
        if let Some(v) = &$args.$field {
            $map.insert(stringify!($field).into(), serde_json::to_value(v).expect("a setting serialises"));
        }
    )+};
}
pub(crate) use put;

mod check;
mod learn;
mod model;
mod plan;
mod robot;
pub mod settings;

pub use check::CheckSeqArgs;
pub use learn::{BenchArgs, BenchKind, CollectArgs, CollectKind, FeasibleArgs, MctsArgs, TransitionsArgs};
pub use model::ModelArgs;
pub use plan::{PlanArgs, PlanRobotArgs};
pub use robot::{CellArgs, CheckArgs, RobotAction, RobotArgs};

use clap::{CommandFactory, FromArgMatches, Parser, Subcommand};

/// Plan in which order, and along which motions, a product can be put together.
#[derive(Parser, Debug)]
#[command(name = "asp", version, about, long_about = None)]
pub struct Cli {
    /// What to do.
    #[command(subcommand)]
    pub command: Command,
}

/// The subcommands.
#[derive(Subcommand, Debug)]
pub enum Command {
    /// Plan a feasible assembly sequence by taking the model apart (Assembly-by-Disassembly).
    Plan(Box<PlanArgs>),
    /// Check a given assembly sequence: every step with the planner's removal tests, the first
    /// failing step and why, and the nearest feasible sequence (docs/check-format.md). Exit 0
    /// feasible, 1 infeasible, 2 bad input.
    Check(Box<CheckSeqArgs>),
    /// Generate training assemblies (Soma cubes, aluminium profile assemblies).
    Gen(crate::gen::GenArgs),
    /// Collect training data from planning runs (`removability`: labelled states; `transitions`:
    /// MCTS transitions for Q-functions; docs/learning.md).
    Collect(CollectArgs),
    /// Benchmarks (`feasible`: the thesis' Table 3.1 for a folder of models).
    Bench(BenchArgs),
    /// Write a self-contained HTML page that plays a plan step by step (three.js, offline).
    View(crate::view::ViewArgs),
    /// Render a plan's storyboard (PNG or SVG): one panel per step.
    Render(crate::view::RenderArgs),
    /// Plot the Pareto front of a plan JSON, or the search's progress from --trace CSVs.
    Plot(crate::plot::PlotArgs),
    /// Robots (`check`: joints, limits, reach and an FK/IK sanity check of a URDF).
    Robot(RobotArgs),
}

/// The flag of a request key: `max_tests` is `--max-tests`, the switches are `--no-...`.
pub fn flag(key: &str) -> String {
    match asp_app::settings::Setting::get(key) {
        Some(setting) => setting.flag_name(),
        None => format!("--{}", key.replace('_', "-")),
    }
}

/// `help` with the request's default of `key` appended, as clap shows defaults.
fn with_default(help: Option<&clap::builder::StyledStr>, key: &str) -> Option<String> {
    let value = asp_app::resolve::defaults().get(key).cloned()?;
    let shown = match &value {
        serde_json::Value::Null | serde_json::Value::Bool(_) => return None,
        serde_json::Value::String(s) => s.clone(),
        serde_json::Value::Array(a) if a.is_empty() => return None,
        other => other.to_string(),
    };
    Some(format!("{} [default: {shown}]", help.map(|h| h.to_string()).unwrap_or_default()))
}

/// Every argument of `command` (and its subcommands) that is a request key (and passes `keys`)
/// shows the request's default, unless its help already names one.
fn show_defaults(mut command: clap::Command, keys: fn(&str) -> bool) -> clap::Command {
    command = command.mut_args(|arg| {
        let key = arg.get_id().as_str().to_string();
        let help = arg.get_help();
        if !keys(&key) || help.is_some_and(|h| h.to_string().contains("[default:")) || !arg.get_default_values().is_empty() {
            return arg;
        }
        match with_default(help, &key) {
            Some(text) => arg.help(text),
            None => arg,
        }
    });
    let names: Vec<String> = command.get_subcommands().map(|s| s.get_name().to_string()).collect();
    for name in names {
        // `plan` takes the request as it is; `collect` and `bench` set their own budgets
        let keys: fn(&str) -> bool = match name.as_str() {
            "plan" => |_| true,
            "collect" | "bench" => |k| !matches!(k, "timeout" | "max_tests" | "seed" | "episodes" | "threads"),
            _ => keys,
        };
        command = command.mut_subcommand(name, |c| show_defaults(c, keys));
    }
    command
}

/// Parses the process arguments (exits with usage on error).
pub fn parse() -> Cli {
    parse_from(std::env::args_os())
}

/// Parses `args` (the program name first). The defaults shown in `--help` cost a resolved
/// request per flag, so they are put into the command only when clap has something to print
/// (help, version, an error): a run that parses pays for none of them.
pub fn parse_from<I, T>(args: I) -> Cli
where
    I: IntoIterator<Item = T>,
    T: Into<std::ffi::OsString> + Clone,
{
    let args: Vec<std::ffi::OsString> = args.into_iter().map(Into::into).collect();
    if let Ok(mut matches) = Cli::command().try_get_matches_from(&args) {
        if let Ok(cli) = Cli::from_arg_matches_mut(&mut matches) {
            return cli;
        }
    }
    // help, version or a usage error: the command with the defaults prints it
    let mut matches = show_defaults(Cli::command(), |_| false).get_matches_from(&args);
    Cli::from_arg_matches_mut(&mut matches).unwrap_or_else(|e| e.exit())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_flags_parse_and_show_the_requests_defaults() {
        Cli::command().debug_assert();
        let help = show_defaults(Cli::command(), |_| false).find_subcommand_mut("plan").unwrap().render_long_help().to_string();
        for shown in ["[default: 10]", "[default: 60", "[default: 1000]", "[default: 0.2]", "[default: strict]", "[default: auto]"] {
            assert!(help.contains(shown), "{shown} missing from:\n{help}");
        }
        assert_eq!(flag("max_tests"), "--max-tests");
        assert_eq!(flag("path_planner"), "--no-path-planner");
    }

    #[test]
    fn a_run_parses_without_the_help_defaults_and_help_still_shows_them() {
        let cli = parse_from(["asp", "plan", "model.glb", "--max-tests", "7"]);
        let Command::Plan(args) = cli.command else { panic!("plan") };
        assert_eq!(args.models, vec![std::path::PathBuf::from("model.glb")]);
        let plain = Cli::command().find_subcommand_mut("plan").unwrap().render_long_help().to_string();
        assert!(!plain.contains("[default: 1000]"));
        // what an error or --help prints comes from the command with the defaults
        let err = show_defaults(Cli::command(), |_| false).try_get_matches_from(["asp", "plan", "--help"]).unwrap_err();
        assert!(err.to_string().contains("[default: 1000]"), "{err}");
    }
}
