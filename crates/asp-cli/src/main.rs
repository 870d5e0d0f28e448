//! `asp`: assembly sequence planning from CAD models.
//!
//! The binary is thin: it parses flags, calls the library crates, and formats output.

mod bench_mcts;
mod check;
mod flags;
mod gen;
mod learn;
mod output;
mod plot;
mod request;
mod robot;
mod view;

use flags::{Cli, Command};
use std::process::ExitCode;

fn main() -> ExitCode {
    let cli = flags::parse();
    match run(cli) {
        Ok(code) => code,
        Err(e) => {
            let search = match e.downcast_ref::<asp_app::AppError>() {
                Some(asp_app::AppError::Search(s)) => Some(s),
                _ => e.downcast_ref::<asp_search::SearchError>(),
            };
            let geom = match search {
                Some(asp_search::SearchError::Geom(g)) => Some(g),
                _ => e.downcast_ref::<asp_geom::GeomError>(),
            };
            let hint = match geom {
                Some(asp_geom::GeomError::GrossOverlap { .. }) => " (--tolerance, --overlaps strict|lenient)",
                _ => "",
            };
            eprintln!("error: {e:#}{hint}");
            ExitCode::from(2)
        }
    }
}

fn run(cli: Cli) -> anyhow::Result<ExitCode> {
    match cli.command {
        Command::Plan(args) => output::plan(&args),
        Command::Check(args) => check::run(&args),
        Command::Gen(args) => gen::run(&args),
        Command::Collect(args) => learn::collect(&args),
        Command::Bench(args) => learn::bench(&args),
        Command::View(args) => view::view(&args),
        Command::Render(args) => view::render(&args),
        Command::Plot(args) => plot::run(&args),
        Command::Robot(args) => robot::run(&args),
    }
}
