//! `asp bench feasible`: the thesis' Table 3.1 for any set of models — time, removal tests and
//! failed tests (by collision, by gravity) of depth-first AbD under several part orderings, each
//! over the same N initial orderings (seeds `0..N`: every method of run `k` starts from the same
//! shuffled order), as mean ± standard deviation.
//!
//! Each run gets a fresh collision world (built outside the timer), so every method pays for its
//! own first tests of each part: cached blocking rows would otherwise favour later runs.

use crate::error::{AppError, Result};
use crate::pipeline::{self, PlanSettings};
use asp_geom::Checker;
use asp_search::OrderingSource;
use asp_search::Problem;
use asp_search::Status;
use serde::Serialize;
use std::path::Path;
use std::sync::Arc;
use std::time::Instant;

/// One method of the comparison: an ordering, with or without bookkeeping.
#[derive(Clone)]
pub struct Method {
    /// The column's name (`vanilla`, `bk`, `gnn`, `gnn+bk`, ...).
    pub name: String,
    /// The ordering.
    pub order: Arc<dyn OrderingSource>,
    /// Bookkeeping on top.
    pub bookkeeping: bool,
}

/// The methods a benchmark runs when none are named: the four cheap orderings, and the learned
/// ones when a removability model is at hand.
pub fn default_methods(learned: bool) -> &'static str {
    if learned {
        "vanilla,bk,random,random+bk,gnn,gnn+bk"
    } else {
        "vanilla,bk,random,random+bk"
    }
}

/// The methods of a comma-separated list: `vanilla` (the catalogue's `shuffled`), `bk` (vanilla
/// with bookkeeping), or any ordering of the catalogue ([`crate::catalogue::ORDERINGS`]: `random`,
/// `given`, `gnn`, ...), each optionally `+bk`. An ordering that reads a model (`gnn`) gets
/// `model` (the shipped one of `checker` when `None`), loaded only when the list names it; a
/// model trained on another checker's labels than `checker` (the benchmark's
/// [`PlanSettings::label_checker`]) is an error.
pub fn parse_methods(list: &str, model: Option<&Path>, checker: asp_learn::Checker) -> Result<Vec<Method>> {
    let mut out = Vec::new();
    for name in list.split(',').map(str::trim).filter(|s| !s.is_empty()) {
        let (base, bookkeeping) = match name.strip_suffix("+bk") {
            Some(b) => (b, true),
            None if name == "bk" => ("vanilla", true),
            None => (name, false),
        };
        let entry = crate::catalogue::ordering(if base == "vanilla" { "shuffled" } else { base }).map_err(|_| {
            let names: Vec<&str> = crate::catalogue::ORDERINGS.iter().map(|o| o.name).collect();
            AppError::config(format!("unknown method '{base}' (vanilla, bk, {}, each optionally +bk)", names.join(", ")))
        })?;
        let order = (entry.build)(if entry.takes_model { model } else { None }, checker)?;
        out.push(Method { name: name.to_string(), order, bookkeeping: bookkeeping || (entry.bookkeeping)(checker) });
    }
    if out.is_empty() {
        return Err(AppError::config(format!("the method list '{list}' names no method")));
    }
    Ok(out)
}

/// Mean and standard deviation (population) of a measure over the runs. JSON writes a NaN (a
/// measure not reached yet) as `null`, which reads back as NaN.
#[derive(Clone, Copy, Debug, Default, Serialize, serde::Deserialize, PartialEq)]
pub struct MeanStd {
    /// Mean.
    #[serde(deserialize_with = "nan_or_number")]
    pub mean: f64,
    /// Standard deviation.
    #[serde(deserialize_with = "nan_or_number")]
    pub std: f64,
}

/// A number, or NaN for `null`.
fn nan_or_number<'de, D: serde::Deserializer<'de>>(d: D) -> std::result::Result<f64, D::Error> {
    Ok(<Option<f64> as serde::Deserialize>::deserialize(d)?.unwrap_or(f64::NAN))
}

impl MeanStd {
    /// Of `values` (zero for none).
    pub fn of(values: &[f64]) -> Self {
        if values.is_empty() {
            return MeanStd::default();
        }
        let n = values.len() as f64;
        let mean = values.iter().sum::<f64>() / n;
        let var = values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / n;
        MeanStd { mean, std: var.sqrt() }
    }
}

/// One row of the table: a model under one method.
#[derive(Clone, Debug, Serialize, serde::Deserialize)]
pub struct BenchRow {
    /// The model's name.
    pub model: String,
    /// The method's name.
    pub method: String,
    /// Runs (initial orderings).
    pub runs: usize,
    /// Runs that found a complete sequence.
    pub found: usize,
    /// Wall time of the search, seconds.
    pub seconds: MeanStd,
    /// Removal tests.
    pub removal_tests: MeanStd,
    /// Tests failed by collision.
    pub failed_collision: MeanStd,
    /// Tests failed by gravity.
    pub failed_gravity: MeanStd,
    /// Path planner calls.
    pub path_planner_calls: MeanStd,
}

/// Runs every method `orderings` times on the model at `path` (reported as `name`) (seeds `0..orderings`, shared by
/// the methods) and summarises each. `settings` give the model's loading and testing.
pub fn bench_model(path: &Path, name: &str, settings: &PlanSettings, methods: &[Method], orderings: usize) -> Result<Vec<BenchRow>> {
    if orderings == 0 {
        return Err(AppError::config("the number of orderings must be at least 1"));
    }
    let assembly = pipeline::load(path, settings)?;
    let world_config = pipeline::world_config(&assembly, settings)?;
    let checker_config = pipeline::checker_config(settings)?;
    let budget = pipeline::budget(settings)?;
    let mut rows = Vec::new();
    for method in methods {
        let mut m = PlanSettings { order: method.order.clone(), bookkeeping: method.bookkeeping, ..settings.clone() };
        let (mut secs, mut tests, mut coll, mut grav, mut rrt) = (vec![], vec![], vec![], vec![], vec![]);
        let mut found = 0;
        for run in 0..orderings {
            m.seed = run as u64;
            let world = asp_geom::World::new(assembly.clone(), &world_config)?;
            let checker = Checker::new(world, checker_config.clone());
            let dfs = pipeline::planner(&m, checker.world())?;
            let started = Instant::now();
            // with a robot (or held parts) the search runs on the extension's checker, whose
            // refusals count as failed tests, as in `asp plan`
            let outcome = match &settings.checker_extension {
                Some(ext) => ext.solve(&checker, m.seed, &mut |c| Ok(dfs.solve(&Problem::full(c), &budget)))?.0,
                None => dfs.solve(&Problem::full(&checker), &budget),
            };
            secs.push(started.elapsed().as_secs_f64());
            let c = outcome.stats.counters;
            tests.push(c.removal_tests as f64);
            coll.push(c.failed_collision as f64);
            grav.push(c.failed_gravity as f64);
            rrt.push(c.path_planner_calls as f64);
            found += usize::from(outcome.status == Status::Found);
        }
        rows.push(BenchRow {
            model: name.to_string(),
            method: method.name.clone(),
            runs: orderings,
            found,
            seconds: MeanStd::of(&secs),
            removal_tests: MeanStd::of(&tests),
            failed_collision: MeanStd::of(&coll),
            failed_gravity: MeanStd::of(&grav),
            path_planner_calls: MeanStd::of(&rrt),
        });
    }
    Ok(rows)
}

/// The rows as a text table in the thesis' layout (one line per model and method).
pub fn write_table(out: &mut impl std::io::Write, rows: &[BenchRow]) -> std::io::Result<()> {
    let w = rows.iter().map(|r| r.model.len()).max().unwrap_or(5).max(5);
    let mw = rows.iter().map(|r| r.method.len()).max().unwrap_or(6).max(6);
    writeln!(
        out,
        "{:<w$}  {:<mw$}  {:>5}  {:>17}  {:>17}  {:>17}  {:>15}",
        "model", "method", "found", "time (s)", "removal tests", "failed collision", "failed gravity"
    )?;
    let f = |m: &MeanStd, p: usize| format!("{:.p$} ± {:.p$}", m.mean, m.std);
    let mut last = "";
    for r in rows {
        let model = if r.model == last { "" } else { r.model.as_str() };
        last = &r.model;
        writeln!(
            out,
            "{:<w$}  {:<mw$}  {:>5}  {:>17}  {:>17}  {:>17}  {:>15}",
            model,
            r.method,
            format!("{}/{}", r.found, r.runs),
            f(&r.seconds, 4),
            f(&r.removal_tests, 1),
            f(&r.failed_collision, 1),
            f(&r.failed_gravity, 1)
        )?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    const D: asp_learn::Checker = asp_learn::Checker::Default;

    #[test]
    fn method_lists_parse_and_bad_names_are_errors() {
        let methods = parse_methods(default_methods(false), None, D).unwrap();
        let names: Vec<(&str, bool)> = methods.iter().map(|m| (m.name.as_str(), m.bookkeeping)).collect();
        assert_eq!(names, [("vanilla", false), ("bk", true), ("random", false), ("random+bk", true)]);
        assert_eq!(methods[0].order.name(), "shuffled");
        let err = parse_methods("vanilla,gnn+bk", Some(Path::new("/no/such/model.onnx")), D).err().unwrap();
        assert!(err.to_string().contains("/no/such/model.onnx"), "{err}");
        let gnn = parse_methods("gnn+bk", None, D).unwrap();
        assert_eq!((gnn[0].order.name().as_str(), gnn[0].bookkeeping), ("gnn", true));
        // `auto` is what a plan request's default is under the benchmark's checker
        let auto = parse_methods("auto", None, D).unwrap();
        assert_eq!((auto[0].order.name().as_str(), auto[0].bookkeeping), ("given", false));
        for checker in [asp_learn::Checker::Physics, asp_learn::Checker::Robot] {
            let auto = parse_methods("auto", None, checker).unwrap();
            assert_eq!((auto[0].order.name().as_str(), auto[0].bookkeeping), ("gnn", true), "{checker:?}");
        }
        let err = parse_methods("vanilla,fastest", None, D).err().unwrap();
        assert!(err.to_string().contains("unknown method 'fastest'"), "{err}");
        assert!(parse_methods(" , ", None, D).is_err());
    }

    #[test]
    fn mean_and_population_std() {
        let m = MeanStd::of(&[2.0, 4.0, 4.0, 4.0, 5.0, 5.0, 7.0, 9.0]);
        assert_eq!(m, MeanStd { mean: 5.0, std: 2.0 });
        assert_eq!(MeanStd::of(&[]), MeanStd::default());
    }
}
