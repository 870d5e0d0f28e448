//! `asp check`: test a given assembly sequence step by step with the planner's removal tests,
//! print the first failing step and the nearest feasible sequence.

use crate::flags::CheckSeqArgs;
use anyhow::Context;
use std::process::ExitCode;

/// Runs `asp check`: exit 0 when the sequence is feasible, 1 when it is not (with a repair), 2
/// for bad input (the caller prints the error).
pub fn run(args: &CheckSeqArgs) -> anyhow::Result<ExitCode> {
    let mut map = crate::flags::Map::new();
    args.put(&mut map);
    let request = crate::request::request(map, args.settings.as_deref())?;
    let settings = crate::request::resolve(&request)?;
    let text = std::fs::read_to_string(&args.sequence).with_context(|| format!("{}: cannot read the sequence", args.sequence.display()))?;
    let steps = asp_app::check::parse_sequence(&text).map_err(|e| anyhow::anyhow!("{}: {e}", args.sequence.display()))?;
    let report = asp_app::check::check_file(&args.model, &steps, &settings).map_err(|e| match e {
        e @ asp_app::AppError::Setting { .. } if matches!(&e, asp_app::AppError::Setting { key, .. } if key == "sequence") => {
            anyhow::anyhow!("{}: {e}", args.sequence.display())
        }
        other => crate::request::cli_error(other),
    })?;
    if !args.quiet {
        for w in &report.warnings {
            eprintln!("warning: {w}");
        }
    }
    let json = report.to_json();
    if let Some(out) = &args.out {
        std::fs::write(out, &json).with_context(|| format!("{}: cannot write the check report", out.display()))?;
    }
    if args.json {
        print!("{json}");
    } else {
        print!("{}", report.to_text());
    }
    Ok(if report.feasible() { ExitCode::SUCCESS } else { ExitCode::from(1) })
}
