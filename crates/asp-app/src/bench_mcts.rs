//! `asp bench mcts`: the optimiser's quality over wall time under several rollout policies
//! (thesis Fig. 6.6 / 6.7, Tables 5.1 / 5.2) — for each model and setting, the hypervolume of
//! the root front (Pareto) or the best total (one objective) at fixed checkpoints of one
//! search run for the longest checkpoint, over several seeds.
//!
//! Every setting of a model searches the same problem (maps and objectives built once, so the
//! hypervolume reference point is the same); each run gets the same wall time, so a guided
//! setting pays for its inference inside the budget. The value at a checkpoint is the trace's
//! last value at or before it (`NaN` before the first complete sequence).

use crate::bench::MeanStd;
use crate::catalogue::{FixedPolicy, PolicySource};
use crate::error::{AppError, Result};
use crate::pipeline::{self, OptimiseSettings, PlanSettings};
use asp_search::RandomPolicy;
use asp_search::SearchOutcome;
use asp_search::{Mcts, ParetoMcts};
use serde::Serialize;
use std::path::Path;
use std::sync::Arc;
use std::time::Duration;

/// One setting of the comparison: a rollout policy under a name.
#[derive(Clone, Debug)]
pub struct MctsSetting {
    /// The column's name (`vanilla`, `pretrained`, ...).
    pub name: String,
    /// The policy.
    pub policy: Arc<dyn PolicySource>,
}

impl MctsSetting {
    /// The vanilla setting: uniformly random rollouts.
    pub fn vanilla() -> Self {
        MctsSetting { name: "vanilla".into(), policy: Arc::new(FixedPolicy(Arc::new(RandomPolicy))) }
    }
}

/// One row: a model under one setting.
#[derive(Clone, Debug, Serialize, serde::Deserialize)]
pub struct MctsRow {
    /// The model's name.
    pub model: String,
    /// The setting's name.
    pub setting: String,
    /// What `values` measure: `hypervolume` or the objective's best total.
    pub measure: String,
    /// The checkpoints, seconds.
    pub checkpoints: Vec<f64>,
    /// The measure at each checkpoint over the runs (`NaN` while a run has no sequence yet).
    pub values: Vec<MeanStd>,
    /// Episodes finished by the last checkpoint.
    pub episodes: MeanStd,
    /// Runs (seeds `0..runs`).
    pub runs: usize,
    /// Seconds building the distance maps (once per model, outside the runs).
    pub map_seconds: f64,
}

/// The measure of `outcome`'s trace at each checkpoint.
pub fn values_at(outcome: &SearchOutcome, checkpoints: &[f64]) -> Vec<f64> {
    checkpoints.iter().map(|&t| outcome.trace.iter().take_while(|p| p.seconds <= t).last().map_or(f64::NAN, |p| p.value)).collect()
}

/// Runs every setting `runs` times (seeds `0..runs`) on the model at `path` (reported as
/// `name`) for the last checkpoint's wall time each, with the optimiser's settings `o` (its
/// `time_limit`, `episodes` and `policy` are replaced).
pub fn bench_model(
    path: &Path,
    name: &str,
    plan: &PlanSettings,
    o: &OptimiseSettings,
    settings: &[MctsSetting],
    checkpoints: &[f64],
    runs: usize,
) -> Result<Vec<MctsRow>> {
    if runs == 0 {
        return Err(AppError::config("the number of runs must be at least 1"));
    }
    let Some(&last) = checkpoints.last() else {
        return Err(AppError::config("no checkpoint given"));
    };
    if checkpoints.iter().any(|t| !(t.is_finite() && *t > 0.0)) || checkpoints.windows(2).any(|w| w[0] >= w[1]) {
        return Err(AppError::config(format!("checkpoints must be positive and increasing, got {checkpoints:?}")));
    }
    asp_search::extension::check_objective_names(&o.objectives, &o.extensions)?;
    let pareto = o.pareto || o.objectives.len() > 1;
    let assembly = Arc::new(pipeline::load(path, plan)?);
    let o = OptimiseSettings { pareto, ..o.clone() };
    let problem = pipeline::optimiser_problem(&assembly, plan, &o)?;
    let threads = o.threads.unwrap_or(1);
    let measure = if pareto { "hypervolume".to_string() } else { o.objectives.join(",") };
    let mut rows = Vec::new();
    for setting in settings {
        let policy = setting.policy.prepare(&problem.mdp)?;
        let mut per_checkpoint = vec![Vec::with_capacity(runs); checkpoints.len()];
        let mut episodes = Vec::with_capacity(runs);
        for run in 0..runs {
            macro_rules! configure {
                ($builder:expr) => {{
                    let mut b = $builder
                        .budget(o.budget)
                        .episodes(usize::MAX)
                        .threads(threads)
                        .seed(run as u64)
                        .exploration(o.exploration)
                        .time_limit(Duration::from_secs_f64(last))
                        .policy(policy.clone());
                    if let Some(stop) = &plan.cancel {
                        b = b.stop_token(stop.clone());
                    }
                    b.build()?
                }};
            }
            let outcome = if pareto {
                configure!(ParetoMcts::builder()).solve(&problem.mdp)?
            } else {
                configure!(Mcts::builder()).solve(&problem.mdp)?
            };
            for (k, v) in values_at(&outcome, checkpoints).into_iter().enumerate() {
                per_checkpoint[k].push(v);
            }
            episodes.push(outcome.stats.episodes as f64);
        }
        rows.push(MctsRow {
            model: name.to_string(),
            setting: setting.name.clone(),
            measure: measure.clone(),
            checkpoints: checkpoints.to_vec(),
            values: per_checkpoint.iter().map(|v| MeanStd::of(v)).collect(),
            episodes: MeanStd::of(&episodes),
            runs,
            map_seconds: problem.map_seconds,
        });
    }
    Ok(rows)
}

/// The mean over models of each setting's values at each checkpoint, each model's value divided
/// by the best mean any setting reached on that model by the last checkpoint (so models of
/// different scales weigh alike; for a hypervolume 1 is the best seen). Rows of one objective
/// whose best is not positive are averaged as they are.
pub fn summary(rows: &[MctsRow]) -> Vec<(String, Vec<f64>)> {
    let mut settings: Vec<&str> = Vec::new();
    for r in rows {
        if !settings.contains(&r.setting.as_str()) {
            settings.push(&r.setting);
        }
    }
    settings
        .iter()
        .map(|&s| {
            let mine: Vec<&MctsRow> = rows.iter().filter(|r| r.setting == s).collect();
            let k = mine.first().map_or(0, |r| r.checkpoints.len());
            let means = (0..k)
                .map(|c| {
                    let vals: Vec<f64> = mine
                        .iter()
                        .map(|r| {
                            let best = rows
                                .iter()
                                .filter(|o| o.model == r.model)
                                .filter_map(|o| o.values.last().map(|v| v.mean))
                                .filter(|v| v.is_finite())
                                .fold(f64::NEG_INFINITY, f64::max);
                            let v = r.values[c].mean;
                            if best > 0.0 {
                                v / best
                            } else {
                                v
                            }
                        })
                        .collect();
                    vals.iter().sum::<f64>() / vals.len().max(1) as f64
                })
                .collect();
            (s.to_string(), means)
        })
        .collect()
}

/// The rows as a text table: one line per model and setting, the mean ± std at each checkpoint
/// and the episodes run; then the mean of the normalised values per setting ([`summary`]).
pub fn write_table(out: &mut impl std::io::Write, rows: &[MctsRow]) -> std::io::Result<()> {
    let Some(first) = rows.first() else { return Ok(()) };
    let w = rows.iter().map(|r| r.model.len()).max().unwrap_or(5).max(5);
    let sw = rows.iter().map(|r| r.setting.len()).max().unwrap_or(7).max(7);
    write!(out, "{:<w$}  {:<sw$}", "model", "setting")?;
    for t in &first.checkpoints {
        write!(out, "  {:>21}", format!("{} at {t} s", first.measure))?;
    }
    writeln!(out, "  {:>19}", "episodes")?;
    let mut last = "";
    for r in rows {
        let model = if r.model == last { "" } else { r.model.as_str() };
        last = &r.model;
        write!(out, "{model:<w$}  {:<sw$}", r.setting)?;
        for v in &r.values {
            write!(out, "  {:>21}", format!("{:.4} ± {:.4}", v.mean, v.std))?;
        }
        writeln!(out, "  {:>19}", format!("{:.0} ± {:.0}", r.episodes.mean, r.episodes.std))?;
    }
    let models = {
        let mut m: Vec<&str> = rows.iter().map(|r| r.model.as_str()).collect();
        m.dedup();
        m.len()
    };
    writeln!(out, "mean over {models} model(s), each divided by the best any setting reached on it:")?;
    for (s, means) in summary(rows) {
        write!(out, "{:<w$}  {s:<sw$}", "")?;
        for v in means {
            write!(out, "  {v:>21.4}")?;
        }
        writeln!(out)?;
    }
    Ok(())
}

/// The rows as CSV: `model,setting,seconds,mean,std,episodes`, one line per checkpoint.
pub fn csv(rows: &[MctsRow]) -> String {
    let mut csv = String::from("model,setting,seconds,mean,std,episodes\n");
    for r in rows {
        for (t, v) in r.checkpoints.iter().zip(&r.values) {
            csv.push_str(&format!("{},{},{t},{},{},{}\n", r.model, r.setting, v.mean, v.std, r.episodes.mean));
        }
    }
    csv
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(model: &str, setting: &str, values: &[f64]) -> MctsRow {
        MctsRow {
            model: model.into(),
            setting: setting.into(),
            measure: "hypervolume".into(),
            checkpoints: (1..=values.len()).map(|k| k as f64).collect(),
            values: values.iter().map(|&v| MeanStd { mean: v, std: 0.0 }).collect(),
            episodes: MeanStd::default(),
            runs: 1,
            map_seconds: 0.0,
        }
    }

    #[test]
    fn the_summary_normalises_per_model() {
        let rows = [
            row("a", "vanilla", &[1.0, 2.0]),
            row("a", "pretrained", &[2.0, 4.0]),
            row("b", "vanilla", &[10.0, 10.0]),
            row("b", "pretrained", &[5.0, 5.0]),
        ];
        let s = summary(&rows);
        assert_eq!(s[0].0, "vanilla");
        assert_eq!(s[0].1, vec![(0.25 + 1.0) / 2.0, (0.5 + 1.0) / 2.0]);
        assert_eq!(s[1].1, vec![(0.5 + 0.5) / 2.0, (1.0 + 0.5) / 2.0]);
        let mut text = Vec::new();
        write_table(&mut text, &rows).unwrap();
        let text = String::from_utf8(text).unwrap();
        assert!(text.contains("hypervolume at 2 s") && text.contains("mean over 2 model(s)"), "{text}");
    }
}
