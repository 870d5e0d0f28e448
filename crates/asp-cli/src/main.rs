//! `asp`: assembly sequence planning from CAD models.
//!
//! The binary is thin: it parses flags, calls the library crates, and formats output.

mod flags;
mod gen;
mod optimise;
mod output;
mod plot;
mod view;

use flags::{Cli, Command};
use std::process::ExitCode;

fn main() -> ExitCode {
    let cli = flags::parse();
    match run(cli) {
        Ok(code) => code,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::from(2)
        }
    }
}

fn run(cli: Cli) -> anyhow::Result<ExitCode> {
    match cli.command {
        Command::Plan(args) => output::plan(&args),
        Command::Gen(args) => gen::run(&args),
        Command::View(args) => view::view(&args),
        Command::Render(args) => view::render(&args),
        Command::Plot(args) => plot::run(&args),
    }
}
