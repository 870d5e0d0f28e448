//! `asp plot`: the Pareto front of a plan JSON, or the search's progress from `--trace` CSVs.

use anyhow::bail;
use asp_viz::plot::{is_bench_csv, read_bench, read_front, read_trace, write_front, write_traces, TraceAxis};
use clap::{Args, ValueEnum};
use std::path::PathBuf;
use std::process::ExitCode;

/// The x axis of a progress plot.
#[derive(Clone, Copy, Debug, ValueEnum, PartialEq, Eq)]
pub enum XArg {
    /// Seconds since the search started.
    Seconds,
    /// Episodes finished.
    Episodes,
}

/// Flags of `asp plot`.
#[derive(Args, Debug)]
pub struct PlotArgs {
    /// A plan JSON with a `pareto_front` (the front is plotted), or one or more `--trace` CSVs
    /// (their values over time, on one plot), or an `asp bench mcts --csv` (each setting's value
    /// over wall time as a fraction of the best reached on each model, averaged over models).
    #[arg(required = true, num_args = 1..)]
    pub inputs: Vec<PathBuf>,
    /// The picture to write: `.svg` or `.png`.
    #[arg(long, value_name = "FILE")]
    pub out: PathBuf,
    /// The x axis of a progress plot.
    #[arg(long, value_enum, default_value_t = XArg::Seconds)]
    pub x: XArg,
}

/// Runs `asp plot`.
pub fn run(args: &PlotArgs) -> anyhow::Result<ExitCode> {
    let is_csv = |p: &PathBuf| p.extension().and_then(|e| e.to_str()).is_some_and(|e| e.eq_ignore_ascii_case("csv"));
    let csvs = args.inputs.iter().filter(|p| is_csv(p)).count();
    if csvs == 0 {
        if args.inputs.len() != 1 {
            bail!("give one plan JSON, or one or more trace CSVs");
        }
        let front = read_front(&args.inputs[0])?;
        write_front(&args.out, &front)?;
    } else {
        if csvs != args.inputs.len() {
            bail!("give one plan JSON, or one or more trace CSVs, not both");
        }
        let mut traces = Vec::new();
        for p in &args.inputs {
            if is_bench_csv(p)? {
                traces.extend(read_bench(p)?);
            } else {
                traces.push(read_trace(p)?);
            }
        }
        let axis = match args.x {
            XArg::Seconds => TraceAxis::Seconds,
            XArg::Episodes => TraceAxis::Episodes,
        };
        write_traces(&args.out, &traces, axis)?;
    }
    Ok(ExitCode::SUCCESS)
}
