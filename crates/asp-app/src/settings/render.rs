//! The texts rendered from [`SETTINGS`]: Python's `asp/settings.py`, the keywords and docstring
//! of `Assembly.plan` in `asp/assembly.py`, and the key table of `docs/plan-request.md`. A test
//! holds the checked-in files to them; `ASP_REGENERATE=1 cargo test --workspace
//! checked_in_settings` rewrites them.

use super::{Applies, Flag, Kind, Setting, SETTINGS};
use serde_json::Value;

/// The command that rewrites the checked-in files.
pub const REGENERATE: &str = "ASP_REGENERATE=1 cargo test --workspace checked_in_settings";

/// `text` wrapped at `width` columns: the first line after `first`, the others after `indent`.
fn wrap(text: &str, first: &str, indent: &str, width: usize) -> String {
    let mut out = String::new();
    let mut line = first.to_string();
    let mut empty = true;
    for word in text.split_whitespace() {
        if !empty && line.chars().count() + 1 + word.chars().count() > width {
            out.push_str(line.trim_end());
            out.push('\n');
            line = indent.to_string();
            empty = true;
        }
        if !empty {
            line.push(' ');
        }
        line.push_str(word);
        empty = false;
    }
    out.push_str(line.trim_end());
    out.push('\n');
    out
}

/// A help text for reStructuredText: `name` becomes ``name``.
fn rst(text: &str) -> String {
    text.replace('`', "``")
}

/// The default as Python spells it.
fn python_default(s: &Setting) -> String {
    if !s.derived.is_empty() {
        return s.derived.to_string();
    }
    match (s.default)() {
        Value::Null => "none".into(),
        Value::Array(a) if a.is_empty() => "none".into(),
        Value::Bool(b) => if b { "True" } else { "False" }.into(),
        Value::String(v) => format!("``{v}``"),
        other => other.to_string(),
    }
}

/// The choices in words: `` `a`: help; `b`: help``, with `quote` around each name.
fn choices_text(s: &Setting, quote: &str) -> String {
    let list: Vec<String> = (s.choices)().iter().map(|(n, h)| format!("{quote}{n}{quote}: {h}")).collect();
    list.join("; ")
}

/// Python's `asp/settings.py`.
pub fn python_settings() -> String {
    let mut out = String::from(
        r#""""The vocabulary of planning settings: the closed sets as ``Literal`` types and every setting of
:meth:`asp.Assembly.plan` as a :class:`PlanSettings` ``TypedDict``.

Generated from asp's settings table (``crates/asp-app/src/settings/table.rs``), where each
setting is declared once: do not edit; a Rust test fails when this file differs and
``ASP_REGENERATE=1 cargo test --workspace checked_in_settings`` rewrites it. The settings are the
keys of asp's plan request, the same as the command line's flags with ``_`` for ``-``.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from typing import Literal, TypedDict, Union

"#,
    );
    let closed: Vec<&Setting> = SETTINGS.iter().filter(|s| s.kind == Kind::Choice).collect();
    let mut all: Vec<&str> = closed.iter().map(|s| s.python).chain(["PathLike", "PlanSettings", "given"]).collect();
    all.sort_by_key(|n| n.to_lowercase());
    let all: Vec<String> = all.iter().map(|n| format!("\"{n}\"")).collect();
    out.push_str(&format!("__all__ = [{}]\n\n", all.join(", ")));
    out.push_str("#: A path: a string or an ``os.PathLike``.\nPathLike = Union[str, \"os.PathLike[str]\"]\n");
    for s in &closed {
        let names: Vec<String> = (s.choices)().iter().map(|(n, _)| format!("\"{n}\"")).collect();
        out.push_str(&format!("#: The values of ``{}=``.\n{} = Literal[{}]\n", s.key, s.python, names.join(", ")));
    }
    out.push_str(
        "\n\nclass PlanSettings(TypedDict, total=False):\n    \"\"\"Every keyword of :meth:`asp.Assembly.plan` (each optional; see its documentation).\"\"\"\n\n",
    );
    for s in SETTINGS.iter().filter(|s| s.applies != Applies::Load) {
        out.push_str(&format!("    {}: {}\n", s.key, s.python));
    }
    out.push_str(
        r#"

def given(settings: dict) -> dict:
    """The settings that were given (``None`` means "the default": left out)."""
    return {k: v for k, v in settings.items() if v is not None}
"#,
    );
    out
}

/// `Assembly.plan`'s signature and docstring in `asp/assembly.py`: from `    def plan(` to the
/// docstring's closing quotes.
pub fn python_plan() -> String {
    let mut out = String::from("    def plan(\n        self,\n        *,\n");
    let keywords: Vec<&Setting> = SETTINGS.iter().filter(|s| s.applies != Applies::Load).collect();
    for s in &keywords {
        out.push_str(&format!("        {}: {} | None = None,\n", s.key, s.python));
    }
    out.push_str("    ) -> Plan:\n");
    let intro = "Plans an assembly sequence: the pipeline of ``asp plan``, with the same settings under \
        the flags' names (``--max-tests`` is ``max_tests``, ``--no-path-planner`` is ``path_planner=False``). \
        Lengths are in model units. A setting left out (``None``) takes its default (``asp._asp.default_settings()``); \
        a setting of the other search (``timeout`` with ``objective``, ``time_limit`` without) raises \
        :class:`ConfigError` naming the one that applies. The keywords and this list are generated from asp's \
        settings table (``crates/asp-app/src/settings/table.rs``).";
    out.push_str(&wrap(intro, "        \"\"\"", "        ", 100));
    for (applies, title) in [
        (Applies::Feasibility, "The feasibility search (without ``objective``):"),
        (Applies::Both, "Both searches:"),
        (Applies::Optimiser, "The optimiser (with ``objective``):"),
    ] {
        out.push_str(&format!("\n        {title}\n\n"));
        for s in keywords.iter().filter(|s| s.applies == applies) {
            let mut text = rst(s.help);
            if s.kind == Kind::Choice {
                text.push_str(&format!(" Values: {}.", rst(&choices_text(s, "`"))));
            }
            if !s.needs.is_empty() {
                text.push_str(&format!(" Needs {}.", rst(s.needs)));
            }
            text.push_str(&format!(" Default: {}.", python_default(s)));
            out.push_str(&wrap(&text, &format!("        :param {}: ", s.key), "            ", 100));
        }
    }
    out.push_str(
        r#"        :raises ConfigError: a setting is unknown, of the wrong type, out of range or of the
            other search.
        :raises LoadError: the model cannot be planned as given (parts overlapping beyond
            repair, ...).
        :raises KeyboardInterrupt: Ctrl-C while planning or optimising (checked every 50 ms; a
            state whose tests take long, such as a path planner call, delays it until it ends).

        The GIL is released while planning.
        """
"#,
    );
    out
}

/// The rows of `docs/plan-request.md`'s key table (with its header).
pub fn docs_keys() -> String {
    let mut out = String::from("| key | flag | search | default | meaning |\n|---|---|---|---|---|\n");
    for s in SETTINGS {
        let search = match s.applies {
            Applies::Load => "loading (Python: `asp.load`)",
            Applies::Both => "both",
            Applies::Feasibility => "feasibility",
            Applies::Optimiser => "optimiser",
        };
        let search = if s.needs.is_empty() { search.to_string() } else { format!("{search}, with {}", s.needs) };
        let flag = match s.flag {
            Flag::OffOrMode(mode) => format!("`{}`, `--{} {mode}`", s.flag_name(), s.key.replace('_', "-")),
            _ => format!("`{}`", s.flag_name()),
        };
        let default = match (s.derived.is_empty(), (s.default)()) {
            (true, Value::String(v)) => format!("`{v}`"),
            _ => s.default_text(),
        };
        let mut meaning = s.help.replace('|', "\\|");
        if s.kind == Kind::Choice {
            meaning.push_str(&format!(" Values: {}.", choices_text(s, "`")));
        }
        out.push_str(&format!("| `{}` | {flag} | {search} | {default} | {meaning} |\n", s.key));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::PathBuf;

    fn root() -> PathBuf {
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
    }

    /// `file` with the text between `begin` and the first `end` after it (both kept) replaced by
    /// `text`.
    fn replaced(file: &str, begin: &str, end: &str, text: &str) -> String {
        let a = file.find(begin).unwrap_or_else(|| panic!("'{begin}' not found"));
        let b = a + file[a..].find(end).unwrap_or_else(|| panic!("'{end}' not found")) + end.len();
        format!("{}{text}{}", &file[..a], &file[b..])
    }

    /// Each checked-in file is what the table renders (or is rewritten with `ASP_REGENERATE=1`).
    #[test]
    fn checked_in_settings_are_the_tables() {
        let root = root();
        let docs_begin = "<!-- BEGIN keys: generated from crates/asp-app/src/settings/table.rs -->\n";
        let docs_end = "<!-- END keys -->\n";
        type Render<'a> = Box<dyn Fn(&str) -> String + 'a>;
        let files: [(&str, Render); 3] = [
            ("py/asp/settings.py", Box::new(|_| python_settings())),
            ("py/asp/assembly.py", Box::new(|f| replaced(f, "    def plan(\n", "        \"\"\"\n", &python_plan()))),
            (
                "docs/plan-request.md",
                Box::new(move |f| replaced(f, docs_begin, docs_end, &format!("{docs_begin}{}{docs_end}", docs_keys()))),
            ),
        ];
        let regenerate = std::env::var_os("ASP_REGENERATE").is_some();
        let mut stale = Vec::new();
        for (path, render) in &files {
            let file = std::fs::read_to_string(root.join(path)).unwrap();
            let want = render(&file);
            if want != file {
                if regenerate {
                    std::fs::write(root.join(path), want).unwrap();
                } else {
                    stale.push(*path);
                }
            }
        }
        assert!(stale.is_empty(), "{} differ from the settings table: run `{REGENERATE}`", stale.join(", "));
    }

    #[test]
    fn every_setting_is_a_key_once_with_help() {
        let mut keys: Vec<&str> = SETTINGS.iter().map(|s| s.key).collect();
        assert_eq!(keys.len(), 48);
        keys.sort();
        keys.dedup();
        assert_eq!(keys.len(), SETTINGS.len());
        for s in SETTINGS {
            assert!(s.help.ends_with('.') || s.help.ends_with(')'), "{}: {}", s.key, s.help);
            assert_eq!(s.kind == Kind::Choice, !(s.choices)().is_empty(), "{}", s.key);
            assert!(!matches!(s.flag, Flag::On | Flag::Off) || s.kind == Kind::Bool, "{}", s.key);
        }
    }
}
