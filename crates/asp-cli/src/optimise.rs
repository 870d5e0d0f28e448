//! `asp plan --objective ...`: optimising sequences with MCTS or Pareto-MCTS on distance maps.
//! This file only adapts flags and output; the pipeline lives in `asp_search::pipeline`.

use anyhow::{bail, Context};
use asp_geom::distmap::Support;
use asp_search::extension::check_objective_names;
use asp_search::MdpExtension;
use std::sync::Arc;
use asp_search::pipeline::OptimiseSettings;
use asp_search::report::{OptimisationEntry, ParetoEntry};
use asp_search::mcts::{DEFAULT_BUDGET, DEFAULT_EPISODES};
use clap::{Args, ValueEnum};
use std::path::PathBuf;

/// The gravity check of the distance maps.
#[derive(Clone, Copy, Debug, ValueEnum, PartialEq, Eq)]
pub enum SupportArg {
    /// Every part rests on a part or the floor directly beneath it (thesis 6.3.2).
    Below,
    /// Every part is linked through contacts to a fixed part or the floor (like `--stability contact`).
    Contact,
}

/// Flags of `asp plan` that turn it into an optimiser.
#[derive(Args, Debug, Clone)]
pub struct OptimiseArgs {
    /// Optimise the sequence for these objectives (comma-separated): `access` (accessibility
    /// of each part, thesis 6.15), `dirchange` (shared removal directions, fewer direction
    /// changes, 6.16), `pathlen` (straight-line removal path length, minimised). One objective
    /// runs MCTS; several need `--pareto`.
    #[arg(long, value_name = "LIST", help_heading = "Optimisation")]
    pub objective: Option<String>,
    /// Search the Pareto front of the objectives (Pareto-MCTS) and write every non-dominated
    /// sequence to `pareto_front`.
    #[arg(long, help_heading = "Optimisation")]
    pub pareto: bool,
    /// MCTS episodes (each walks from the assembled state to a complete sequence).
    #[arg(long, default_value_t = DEFAULT_EPISODES, help_heading = "Optimisation")]
    pub episodes: usize,
    /// Search budget: MCTS iterations per step of an episode (the thesis uses 5).
    #[arg(long, default_value_t = DEFAULT_BUDGET, help_heading = "Optimisation")]
    pub budget: usize,
    /// Threads, each growing its own tree [default: all cores]. The same seed and thread count
    /// give the same answer.
    #[arg(long, help_heading = "Optimisation")]
    pub threads: Option<usize>,
    /// Stop the search after this many seconds (the answer then depends on timing).
    #[arg(long, value_name = "SECONDS", help_heading = "Optimisation")]
    pub time_limit: Option<f64>,
    /// Write the hypervolume (Pareto) or best value over episodes and seconds as CSV.
    #[arg(long, value_name = "FILE", help_heading = "Optimisation")]
    pub trace: Option<PathBuf>,
    /// Exploration constant c of UCT / MOUCB.
    #[arg(long, default_value_t = std::f64::consts::FRAC_1_SQRT_2, help_heading = "Optimisation")]
    pub exploration: f64,
    /// Local search over the answer's sequences: block moves of 1-3 removals around every
    /// sequence the search finds, taking at most this share of the search's work (0: off).
    #[arg(long, value_name = "SHARE", default_value_t = asp_search::mcts::DEFAULT_POLISH, help_heading = "Optimisation")]
    pub polish: f64,
    /// Distance map resolution N_M (odd, 3 to 15): N_M × N_M directions on the half sphere.
    #[arg(long, default_value_t = asp_geom::distmap::DEFAULT_RESOLUTION, help_heading = "Optimisation")]
    pub resolution: usize,
    /// Cap d_max of the distance maps, model units [default: the model's diagonal].
    #[arg(long, help_heading = "Optimisation")]
    pub d_max: Option<f64>,
    /// The gravity check of the optimiser.
    #[arg(long, value_enum, default_value_t = SupportArg::Below, help_heading = "Optimisation")]
    pub support: SupportArg,
    /// Learned Q-functions (ONNX, `python -m asp.train q`), one per objective in the order of
    /// `--objective` (comma-separated): rollouts take the removal with the largest Q-value
    /// (the product of the values for several objectives) instead of a random one, except with
    /// probability `--epsilon` (thesis 5.4.5, 6.4.4).
    #[arg(long, value_name = "MODELS", help_heading = "Optimisation")]
    pub q: Option<String>,
    /// The probability of a random removal in a rollout (or expansion) guided by `--q`.
    #[arg(long, default_value_t = 0.2, help_heading = "Optimisation")]
    pub epsilon: f64,
    /// Where `--q` guides: `rollouts` (thesis: one evaluation per rollout step), `expansions`
    /// (the Q-values of each state the search adds order its expansions; rollouts stay random:
    /// one evaluation per node) or `both`.
    #[arg(long, value_enum, default_value_t = QUseArg::Rollouts, help_heading = "Optimisation")]
    pub q_use: QUseArg,
}

/// `--q-use`.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum QUseArg {
    /// ε-greedy rollouts.
    Rollouts,
    /// Q-ordered expansions, random rollouts.
    Expansions,
    /// Both.
    Both,
}

impl From<QUseArg> for asp_search::QUse {
    fn from(a: QUseArg) -> Self {
        match a {
            QUseArg::Rollouts => asp_search::QUse::Rollouts,
            QUseArg::Expansions => asp_search::QUse::Expansions,
            QUseArg::Both => asp_search::QUse::Both,
        }
    }
}

impl OptimiseArgs {
    /// The pipeline's optimiser settings, `None` unless `--objective` was given. Flag values
    /// are checked here so that errors name the flags.
    /// `extensions` provide objectives beyond the built-in ones (the robot's `robot-path`).
    pub fn settings(&self, extensions: Vec<Arc<dyn MdpExtension>>) -> anyhow::Result<Option<OptimiseSettings>> {
        let Some(list) = &self.objective else { return Ok(None) };
        if list.split(',').any(|n| n.trim() == asp_robot::ROBOT_PATH) && extensions.is_empty() {
            bail!("--objective {list}: robot-path needs a robot (--robot panda or --robot FILE.urdf)");
        }
        check_objective_names(list, &extensions).context("--objective")?;
        let count = list.split(',').filter(|n| !n.trim().is_empty()).count();
        if count > 1 && !self.pareto {
            bail!("--objective {list}: several objectives need --pareto (or give one objective)");
        }
        if let Some(t) = self.time_limit {
            if !(t > 0.0 && t.is_finite()) {
                bail!("--time-limit must be a positive number of seconds, got {t}");
            }
        }
        if let Some(d) = self.d_max {
            crate::output::positive("d-max", d)?;
        }
        let policy = match &self.q {
            None => None,
            Some(models) => {
                if !(0.0..=1.0).contains(&self.epsilon) {
                    bail!("--epsilon must be in [0, 1], got {}", self.epsilon);
                }
                let paths: Vec<&str> = models.split(',').map(str::trim).filter(|p| !p.is_empty()).collect();
                let objectives: Vec<&str> = list.split(',').map(str::trim).filter(|n| !n.is_empty()).collect();
                let directions = self.resolution * self.resolution;
                Some(asp_learn::epsilon_greedy(&paths, &objectives, self.epsilon, directions, self.q_use.into()).context("--q")?)
            }
        };
        Ok(Some(OptimiseSettings {
            objectives: list.clone(),
            pareto: self.pareto,
            episodes: self.episodes,
            budget: self.budget,
            threads: self.threads,
            time_limit: self.time_limit,
            exploration: self.exploration,
            polish: self.polish,
            resolution: self.resolution,
            d_max: self.d_max,
            support: match self.support {
                SupportArg::Below => Support::Below,
                SupportArg::Contact => Support::ContactGraph,
            },
            extensions,
            policy,
        }))
    }
}

/// Prints the Pareto front (or the best value) under the plan table.
pub fn write_summary(
    out: &mut impl std::io::Write,
    summary: &OptimisationEntry,
    front: Option<&[ParetoEntry]>,
) -> std::io::Result<()> {
    let names = summary.objectives.join(", ");
    writeln!(
        out,
        "{}: {} episodes, {} iterations in {:.3} s ({} threads){}",
        summary.method.replace('_', "-"),
        summary.episodes,
        summary.iterations,
        summary.search_seconds,
        summary.threads,
        if summary.exhaustive { "; the search space was exhausted: the answer is exact" } else { "" }
    )?;
    match front {
        Some(front) => {
            writeln!(
                out,
                "Pareto front ({names}): {} sequences, hypervolume {:.6}",
                front.len(),
                summary.hypervolume.unwrap_or(0.0)
            )?;
            for (k, e) in front.iter().enumerate() {
                let v: Vec<String> = e.objectives.iter().map(|x| format!("{x:.4}")).collect();
                writeln!(out, "{:>4}  ({})  removal order {:?}", k + 1, v.join(", "), e.disassembly_sequence)?;
            }
        }
        None => {
            let v: Vec<String> = summary.values.iter().map(|x| format!("{x:.4}")).collect();
            writeln!(out, "best {names}: {}", v.join(", "))?;
        }
    }
    Ok(())
}

