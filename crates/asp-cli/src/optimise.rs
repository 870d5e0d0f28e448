//! `asp plan --objective ...`: optimising sequences with MCTS or Pareto-MCTS on distance maps.
//! This file only adapts flags and output; the search lives in `asp_search`.

use anyhow::{bail, Context};
use asp_geom::distmap::{DistanceMaps, MapConfig, Support};
use asp_geom::{Assembly, CounterSnapshot, Motion};
use asp_search::objective::parse_objectives;
use asp_search::report::{OptimisationEntry, ParetoEntry};
use asp_search::search::{SearchOutcome, SearchStatus, DEFAULT_BUDGET, DEFAULT_EPISODES};
use asp_search::{Mcts, Mdp, ParetoMcts, PlanOutcome, Stats, Status, Step};
use clap::{Args, ValueEnum};
use std::path::PathBuf;
use std::sync::Arc;
use std::time::{Duration, Instant};

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
    /// Distance map resolution N_M (odd, 3 to 15): N_M × N_M directions on the half sphere.
    #[arg(long, default_value_t = asp_geom::distmap::DEFAULT_RESOLUTION, help_heading = "Optimisation")]
    pub resolution: usize,
    /// Cap d_max of the distance maps, model units [default: the model's diagonal].
    #[arg(long, help_heading = "Optimisation")]
    pub d_max: Option<f64>,
    /// The gravity check of the optimiser.
    #[arg(long, value_enum, default_value_t = SupportArg::Below, help_heading = "Optimisation")]
    pub support: SupportArg,
}

impl OptimiseArgs {
    /// Whether `asp plan` should optimise rather than only find a feasible sequence.
    pub fn is_active(&self) -> bool {
        self.objective.is_some()
    }
}

/// What `asp plan` needs to write an optimised plan.
#[derive(Debug)]
pub struct Optimised {
    /// The best sequence (single objective) or the front's first point, as a plan outcome.
    pub outcome: PlanOutcome,
    /// Pareto runs: every non-dominated sequence with its objective vector.
    pub pareto_front: Option<Vec<ParetoEntry>>,
    /// The run's settings and results for the plan's `optimisation` key.
    pub summary: OptimisationEntry,
    /// Problems met while building the distance maps (voxels that do not match meshes, open
    /// meshes, overlapping parts).
    pub warnings: Vec<String>,
    /// The contact tolerance the maps used, metres.
    pub tolerance: f32,
}

/// Builds the distance maps of `assembly`, runs the search the flags ask for, writes the trace,
/// and returns the plan data. `tolerance` and `contact_distance` are in metres.
pub fn optimise(
    assembly: &Assembly,
    args: &OptimiseArgs,
    seed: u64,
    tolerance: Option<f32>,
    contact_distance: Option<f32>,
) -> anyhow::Result<Optimised> {
    let list = args.objective.as_deref().unwrap_or_default();
    let objectives = parse_objectives(list).context("--objective")?;
    if objectives.len() > 1 && !args.pareto {
        bail!("--objective {list}: several objectives need --pareto (or give one objective)");
    }
    let metres = assembly.units.metres;
    let mut config = MapConfig::builder().resolution(args.resolution).support(match args.support {
        SupportArg::Below => Support::Below,
        SupportArg::Contact => Support::ContactGraph,
    });
    if let Some(d) = args.d_max {
        config = config.d_max((d * metres) as f32);
    }
    if let Some(t) = tolerance {
        config = config.tolerance(t);
    }
    if let Some(c) = contact_distance {
        config = config.contact_distance(c);
    }
    let config = config.build().context("distance maps")?;
    let started = Instant::now();
    let maps = Arc::new(DistanceMaps::build(assembly, &config)?);
    let map_seconds = started.elapsed().as_secs_f64();
    let mdp = Mdp::new(maps.clone(), objectives)?;
    let threads = match args.threads {
        Some(t) => t,
        None => std::thread::available_parallelism().map_or(1, |n| n.get()),
    };
    macro_rules! configure {
        ($builder:expr) => {{
            let mut b = $builder
                .budget(args.budget)
                .episodes(args.episodes)
                .threads(threads)
                .seed(seed)
                .exploration(args.exploration);
            if let Some(t) = args.time_limit {
                if !(t > 0.0 && t.is_finite()) {
                    bail!("--time-limit must be a positive number of seconds, got {t}");
                }
                b = b.time_limit(Duration::from_secs_f64(t));
            }
            b.build()?
        }};
    }
    let outcome = if args.pareto {
        configure!(ParetoMcts::builder()).solve(&mdp)?
    } else {
        configure!(Mcts::builder()).solve(&mdp)?
    };
    if let Some(path) = &args.trace {
        let file = std::fs::File::create(path)
            .with_context(|| format!("{}: cannot write the trace", path.display()))?;
        outcome
            .write_trace_csv(std::io::BufWriter::new(file))
            .with_context(|| format!("{}: cannot write the trace", path.display()))?;
    }
    let mut optimised = adapt(&maps, &outcome, args, seed, map_seconds);
    optimised.warnings = maps.warnings().to_vec();
    Ok(optimised)
}

/// The search outcome as plan data: motions get the contact margin of the plan format.
fn adapt(
    maps: &DistanceMaps,
    outcome: &SearchOutcome,
    args: &OptimiseArgs,
    seed: u64,
    map_seconds: f64,
) -> Optimised {
    let margin = maps.contact_distance();
    let removals = outcome
        .best()
        .map(|s| {
            s.sequence
                .iter()
                .zip(&s.motions)
                .map(|(&part, m)| Step {
                    part,
                    motion: match m {
                        Motion::Linear { direction, distance } => {
                            Motion::Linear { direction: *direction, distance: distance + margin }
                        }
                        other => other.clone(),
                    },
                })
                .collect()
        })
        .unwrap_or_default();
    let status = match outcome.status {
        SearchStatus::Found => Status::Found,
        SearchStatus::NoPlan => Status::NoPlan { stuck: Vec::new(), state: asp_geom::PartSet::full(maps.num_parts()) },
        SearchStatus::BudgetExhausted => Status::BudgetExhausted,
    };
    let plan = PlanOutcome {
        status,
        removals,
        stats: Stats {
            counters: CounterSnapshot {
                removal_tests: outcome.stats.removal_tests,
                failed_collision: outcome.stats.failed_collision,
                failed_gravity: outcome.stats.failed_gravity,
                path_planner_calls: 0,
            },
            seconds: outcome.stats.seconds,
            states_expanded: 0,
        },
    };
    let pareto_front = args.pareto.then(|| {
        outcome
            .solutions
            .iter()
            .map(|s| ParetoEntry { objectives: s.values.clone(), disassembly_sequence: s.sequence.clone() })
            .collect()
    });
    let s = &outcome.stats;
    let summary = OptimisationEntry {
        method: if args.pareto { "pareto_mcts" } else { "mcts" }.into(),
        objectives: outcome.objectives.clone(),
        values: outcome.best().map(|b| b.values.clone()).unwrap_or_default(),
        hypervolume: args.pareto.then_some(outcome.value),
        reference: outcome.reference.clone(),
        exhaustive: s.exhausted,
        episodes: s.episodes,
        iterations: s.iterations,
        tree_nodes: s.tree_nodes,
        budget: args.budget,
        threads: s.threads,
        seed,
        resolution: maps.hemisphere().resolution(),
        d_max: maps.d_max() as f64,
        map_seconds,
        search_seconds: s.seconds,
    };
    Optimised { outcome: plan, pareto_front, summary, warnings: Vec::new(), tolerance: maps.tolerance() }
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

/// `asp plan MODEL --objective ...`: the optimised plan as a table and JSON, exit 0 when a
/// sequence was found.
pub fn plan(args: &crate::flags::PlanArgs, assembly: Assembly) -> anyhow::Result<std::process::ExitCode> {
    use std::io::Write;
    let metres = assembly.units.metres;
    let to_m = |name: &str, v: Option<f64>| -> anyhow::Result<Option<f32>> {
        v.map(|v| crate::output::positive(name, v).map(|v| (v * metres) as f32)).transpose()
    };
    let tolerance = to_m("tolerance", args.tolerance)?;
    let contact = to_m("contact-distance", args.contact_distance)?;
    let o = optimise(&assembly, &args.optimise, args.seed, tolerance, contact)?;
    let mut warnings = assembly.warnings.clone();
    for w in &o.warnings {
        if !warnings.contains(w) {
            warnings.push(w.clone());
        }
    }
    if !args.quiet {
        for w in &warnings {
            eprintln!("warning: {}: {w}", args.model.display());
        }
    }
    let mut report = asp_search::report::PlanReport::new(&assembly, &o.outcome, o.tolerance, &warnings);
    report.stats.checker = asp_search::report::CHECKER_DISTANCE_MAPS.into();
    report.pareto_front = o.pareto_front;
    report.optimisation = Some(o.summary);
    let json = serde_json::to_string_pretty(&report)?;
    if let Some(path) = &args.out {
        std::fs::write(path, format!("{json}\n"))
            .with_context(|| format!("{}: cannot write the plan", path.display()))?;
    }
    let mut stdout = std::io::stdout().lock();
    if args.json {
        writeln!(stdout, "{json}")?;
    } else {
        crate::output::write_table(&mut stdout, &report)?;
        if let Some(summary) = &report.optimisation {
            write_summary(&mut stdout, summary, report.pareto_front.as_deref())?;
        }
    }
    Ok(match o.outcome.status {
        Status::Found => std::process::ExitCode::SUCCESS,
        _ => std::process::ExitCode::from(1),
    })
}
