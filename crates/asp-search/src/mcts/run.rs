//! A whole search: the threads' workers, each on its share of the episodes, and their answers
//! merged in thread order into a [`SearchOutcome`].

use super::graph::{Status as NodeStatus, Variant};
use super::outcome::{EpisodeHook, SearchOutcome, SearchStats, Solution, TracePoint};
use super::record::Recorder;
use super::settings::SearchSettings;
use super::worker::{front_value, share_of, Shared, Worker};
use crate::dead_end::{deepest_dead_end, DEAD_END_STATES};
use crate::error::{Result, SearchError};
use crate::hypervolume::ParetoFront;
use crate::mdp::{FilterCounts, Mdp};
use crate::problem::{PlanOutcome, Stats, Status, Step, StopReason, StopToken};
use asp_geom::{CounterSnapshot, Motion, PartSet};
use std::sync::Mutex;
use std::time::Instant;

/// What one worker hands back: its archive, statistics, filter counts, root status and
/// recording.
type WorkerResult = Result<(ParetoFront<Vec<u16>>, SearchStats, FilterCounts, NodeStatus, Option<Recorder>)>;

/// The message of a panic payload.
fn panic_message(payload: &(dyn std::any::Any + Send)) -> String {
    payload
        .downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| payload.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "(no message)".into())
}

/// Runs the search of variant `V` on `problem`; with a `hook`, one thread, episode by episode
/// (see [`EpisodeHook`]).
pub(crate) fn run<V: Variant>(problem: &Mdp, settings: &SearchSettings, hook: Option<&mut EpisodeHook<'_>>) -> Result<SearchOutcome> {
    if hook.is_some() && settings.threads != 1 {
        return Err(SearchError::config(format!(
            "a stepped search runs on one thread, not {} (the policy may change between its episodes)",
            settings.threads
        )));
    }
    // the hook (one thread only) is locked by the thread that runs it; without one no thread
    // may wait on the lock, or the threads would run one after the other
    let stepped = hook.is_some();
    let hook = Mutex::new(hook);
    let m = problem.num_objectives();
    let reference = match &settings.reference {
        Some(r) if r.len() != m => {
            return Err(SearchError::config(format!("the reference point has {} coordinates, the problem {m} objectives", r.len())))
        }
        Some(r) => r.clone(),
        None => problem.reference_point(),
    };
    if problem.maps().num_parts() > u16::MAX as usize {
        return Err(SearchError::config("too many parts"));
    }
    let start = Instant::now();
    let shared = Mutex::new(Shared { front: ParetoFront::new(m), episodes: 0, iterations: 0, trace: Vec::new(), last_value: None });
    let threads = settings.threads;
    let share = |t: usize| share_of(settings.episodes, threads, t);
    let abort = StopToken::new();
    // One worker's search; a panic in a plug-in becomes an error (and stops the others).
    let work = |t: usize| -> WorkerResult {
        let outcome = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
            let first_episode = (0..t).map(share).sum::<usize>() as u64;
            let mut w = Worker::<V>::new(problem, settings, t, start, &abort, first_episode)?;
            let mut guard = stepped.then(|| hook.lock().unwrap_or_else(|e| e.into_inner()));
            w.run(share(t), &shared, &reference, start, guard.as_mut().and_then(|h| h.as_deref_mut()));
            match w.error.take() {
                Some(e) => Err(e),
                None => Ok((w.archive, w.stats, w.filtered, w.tree.nodes[0].status, w.record.take())),
            }
        }));
        match outcome {
            Ok(r) => r,
            Err(payload) => Err(SearchError::plugin(format!("search thread {t}"), format!("panicked: {}", panic_message(&*payload)))),
        }
        .inspect_err(|_| abort.stop())
    };
    let results: Vec<WorkerResult> = if threads == 1 {
        vec![work(0)]
    } else {
        std::thread::scope(|scope| {
            let handles: Vec<_> = (0..threads).map(|t| scope.spawn(move || work(t))).collect();
            handles
                .into_iter()
                .enumerate()
                .map(|(t, h)| {
                    h.join().unwrap_or_else(|p| {
                        Err(SearchError::plugin(format!("search thread {t}"), format!("panicked: {}", panic_message(&*p))))
                    })
                })
                .collect()
        })
    };
    let seconds = start.elapsed().as_secs_f64();
    let results = results.into_iter().collect::<Result<Vec<_>>>()?;

    // Merge in thread order (deterministic).
    let mut merged: ParetoFront<Vec<u16>> = ParetoFront::new(m);
    let mut stats = SearchStats { threads, seconds, exhausted: false, ..Default::default() };
    let mut filtered = problem.filter_counts();
    let mut dead = true;
    let mut transitions = Vec::new();
    let mut transitions_capped = false;
    for (archive, s, f, status, _) in &results {
        for (p, seq) in archive.iter() {
            merged.insert(p, || seq.clone());
        }
        stats.episodes += s.episodes;
        stats.iterations += s.iterations;
        stats.rollout_steps += s.rollout_steps;
        stats.dead_rollouts += s.dead_rollouts;
        stats.removal_tests += s.removal_tests;
        stats.failed_collision += s.failed_collision;
        stats.failed_gravity += s.failed_gravity;
        stats.tree_nodes += s.tree_nodes;
        stats.polish_steps += s.polish_steps;
        stats.polished += s.polished;
        stats.exhausted |= s.exhausted;
        stats.stopped |= s.stopped;
        filtered.add(f);
        dead &= *status == NodeStatus::Dead;
    }
    stats.filtered = problem.report_filtered(&filtered);
    stats.filter_checks = filtered.checks();
    for (.., record) in results {
        if let Some(r) = record {
            transitions.extend(r.transitions);
            transitions_capped |= r.capped;
        }
    }
    let mut solutions = Vec::with_capacity(merged.len());
    for (_, seq) in merged.sorted() {
        let sequence: Vec<usize> = seq.iter().map(|&p| p as usize).collect();
        match problem.evaluate(&sequence) {
            Ok((values, motions)) => solutions.push(Solution { values, sequence, motions }),
            // a filter rejected on replay what a rollout admitted: not an answer
            Err(SearchError::Infeasible { .. }) => stats.replay_failures += 1,
            Err(e) => return Err(e),
        }
    }
    if stats.replay_failures > 0 {
        merged = ParetoFront::new(m);
        for s in &solutions {
            merged.insert(&s.values, || s.sequence.iter().map(|&p| p as u16).collect());
        }
    }
    let value = front_value(&merged, &reference);
    let mut shared = shared.into_inner().unwrap_or_else(|e| e.into_inner());
    let last = TracePoint {
        episode: stats.episodes,
        iterations: stats.iterations,
        seconds,
        value: if merged.is_empty() { 0.0 } else { value },
        front_size: merged.len(),
    };
    shared.trace.push(last);
    // what ended a search without an answer: a stop (the token, else the time limit) or its
    // episodes
    let stopped_by = match (stats.stopped, settings.stop.as_ref().is_some_and(StopToken::is_stopped)) {
        (true, true) => StopReason::Interrupted,
        (true, false) => StopReason::Timeout,
        (false, _) => StopReason::MaxEpisodes,
    };
    let (plan, rejected) = plan_outcome(problem, &solutions, dead, &stats, stopped_by);
    Ok(SearchOutcome {
        plan,
        rejected,
        objectives: problem.objective_names(),
        solutions,
        reference,
        value: if merged.is_empty() { 0.0 } else { value },
        stats,
        trace: shared.trace,
        transitions,
        transitions_capped,
    })
}

/// The search's answer in every planner's vocabulary, and the dead end's parts a filter
/// rejected ([`SearchOutcome::plan`], [`SearchOutcome::rejected`]): `Found` with the best
/// solution's removals when there is one; else `NoPlan` when every root was dead, explained by
/// the deepest dead end on the maps; else `BudgetExhausted`, stopped by `stopped_by`. Motions
/// are carried the maps' contact distance further (the plan format's removal ends that far
/// beyond the remaining bounds).
fn plan_outcome(
    problem: &Mdp,
    solutions: &[Solution],
    dead: bool,
    stats: &SearchStats,
    stopped_by: StopReason,
) -> (PlanOutcome, Vec<(usize, String)>) {
    let maps = problem.maps();
    let margin = maps.contact_distance();
    let with_margin = |part: usize, m: &Motion| {
        Step::single(
            part,
            match m {
                Motion::Linear { direction, distance } => Motion::Linear { direction: *direction, distance: distance + margin },
                other => other.clone(),
            },
        )
    };
    let mut removals: Vec<Step> =
        solutions.first().map(|s| s.sequence.iter().zip(&s.motions).map(|(&part, m)| with_margin(part, m)).collect()).unwrap_or_default();
    let mut rejected = Vec::new();
    let status = if !solutions.is_empty() {
        Status::Found
    } else if dead {
        match deepest_dead_end(problem, DEAD_END_STATES) {
            Some(end) => {
                removals = end.removals.iter().map(|(part, m)| with_margin(*part, m)).collect();
                rejected = end.rejected;
                Status::NoPlan { stuck: end.stuck, state: end.state }
            }
            // the tree search saw no complete sequence where the dead-end search finds one
            // within its bound (it cannot: both walk the same removals): nothing to explain
            None => Status::NoPlan { stuck: Vec::new(), state: PartSet::full(maps.num_parts()) },
        }
    } else {
        Status::BudgetExhausted
    };
    let effort = Stats {
        counters: CounterSnapshot {
            removal_tests: stats.removal_tests,
            failed_collision: stats.failed_collision,
            failed_gravity: stats.failed_gravity,
            // the tree searches move parts along straight lines only
            path_planner_calls: 0,
        },
        seconds: stats.seconds,
        stopped_by: (status == Status::BudgetExhausted).then_some(stopped_by),
        ..Stats::default()
    };
    (PlanOutcome { status, removals, stats: effort }, rejected)
}
