//! What a tree search gives back ([`SearchOutcome`] with its [`SearchStats`], trace and recorded
//! [`Transition`]s) and what the stepped search tells its hook between episodes
//! ([`EpisodeEnd`], [`Next`]).

use crate::error::Result;
use crate::mdp::FilterCount;
use crate::policy::Policy;
use crate::problem::{PlanOutcome, Status};
use crate::step::StepKind;
use asp_geom::{Motion, PartSet};
use std::sync::Arc;

/// One answer: a complete feasible disassembly sequence, its objective vector and its motions.
#[derive(Clone, Debug, PartialEq)]
pub struct Solution {
    /// Objective totals, in the problem's objective order.
    pub values: Vec<f64>,
    /// Part indices in removal order.
    pub sequence: Vec<usize>,
    /// The removal motion of each step (straight lines).
    pub motions: Vec<Motion>,
}

/// One row of the trace: the answer's quality after some episodes and seconds.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct TracePoint {
    /// Episodes finished (all threads).
    pub episode: u64,
    /// Iterations run (all threads).
    pub iterations: u64,
    /// Seconds since the search started.
    pub seconds: f64,
    /// The hypervolume of the merged root fronts (Pareto) or the best total (single objective).
    pub value: f64,
    /// Number of points on the merged front (1 for single objective).
    pub front_size: usize,
}

/// What the search did.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct SearchStats {
    /// Episodes finished.
    pub episodes: u64,
    /// Iterations (selection, expansion, rollout, backpropagation).
    pub iterations: u64,
    /// Removals simulated in rollouts.
    pub rollout_steps: u64,
    /// Rollouts that ended with parts left that could not be removed.
    pub dead_rollouts: u64,
    /// Removability tests on the distance maps ([`asp_geom::distmap::MapCounters`], all
    /// threads): collision tests that found a part blocked plus gravity tests of collision-free
    /// parts. Answers carried over from an earlier state are not tested again.
    pub removal_tests: u64,
    /// Removal tests that found the part blocked in every direction.
    pub failed_collision: u64,
    /// Removal tests of collision-free parts whose removal would leave a part unsupported.
    pub failed_gravity: u64,
    /// Tree nodes (all threads).
    pub tree_nodes: u64,
    /// Wall-clock seconds of the search.
    pub seconds: f64,
    /// Whether the tree was fully explored (the answer is then exact).
    pub exhausted: bool,
    /// Threads used.
    pub threads: usize,
    /// Removals the problem's feasibility filters rejected, by filter and reason (all threads;
    /// empty without filters).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub filtered: Vec<FilterCount>,
    /// Whether a time limit or a stop token ended the search early.
    #[serde(default)]
    pub stopped: bool,
    /// Complete sequences the search found that did not replay ([`Mdp::evaluate`](crate::Mdp::evaluate): a filter
    /// that rejects on replay what a rollout admitted); they are left out of the answer.
    #[serde(default)]
    pub replay_failures: u64,
    /// Removals put to the problem's feasibility filters (all threads; [`FilterCounts::checks`](crate::mdp::FilterCounts::checks)),
    /// recording and the local search included.
    #[serde(default)]
    pub filter_checks: u64,
    /// Work of the local search over the answer's sequences ([`crate::polish`]), in map steps
    /// (all threads).
    #[serde(default)]
    pub polish_steps: u64,
    /// Sequences the local search added to the threads' archives (some were later dominated).
    #[serde(default)]
    pub polished: u64,
}

/// The result of a search.
#[derive(Clone, Debug)]
pub struct SearchOutcome {
    /// The answer in every planner's vocabulary ([`crate::Planner`]; the outcome of
    /// [`MapPlanner`](crate::mcts::MapPlanner)): how the search ended — `Found` (at least one
    /// complete feasible sequence), `NoPlan` (the whole tree was explored and holds none; the
    /// deepest dead end on the maps says what holds each part, [`crate::dead_end`]) or
    /// `BudgetExhausted` (the episodes, the time or a stop ended it first) — the best
    /// sequence's removals (for `NoPlan` those to the dead end), each motion carried the maps'
    /// contact distance further (a plan's removal ends that far beyond the remaining bounds),
    /// and the effort (the maps' test counters, the time, which limit stopped it). See
    /// [`SearchOutcome::status`].
    pub plan: PlanOutcome,
    /// The parts of a `NoPlan`'s dead end that the maps let out but a feasibility filter of the
    /// problem rejected, each with the filter's words ("is rejected by robot: ..."); empty
    /// otherwise.
    pub rejected: Vec<(usize, String)>,
    /// The objectives' names.
    pub objectives: Vec<String>,
    /// The answers: the best sequence (single objective) or the Pareto front, sorted by the first
    /// objective (best first).
    pub solutions: Vec<Solution>,
    /// The hypervolume reference point.
    pub reference: Vec<f64>,
    /// Hypervolume of the front relative to `reference` (single objective: the best total).
    pub value: f64,
    /// Effort.
    pub stats: SearchStats,
    /// Quality over episodes and seconds (a row whenever it changed, and a last row).
    pub trace: Vec<TracePoint>,
    /// The recorded transitions ([`SearchBuilder::record_transitions`](crate::mcts::SearchBuilder::record_transitions); empty without it): each
    /// thread's in the order it took them, threads in order.
    pub transitions: Vec<Transition>,
    /// Whether a thread reached its share of [`SearchBuilder::record_transitions_limit`](crate::mcts::SearchBuilder::record_transitions_limit) and
    /// stopped recording (the search went on).
    pub transitions_capped: bool,
}

/// One removal step the search simulated: from state `s` (`present` with the objectives'
/// `memory`) the part `action` left, earning `rewards`, and led to `s'` (`present` without
/// `action`, with `next_memory`).
#[derive(Clone, Debug, PartialEq)]
pub struct Transition {
    /// The episode (numbered over all threads: thread `t`'s episodes follow those of the
    /// threads before it).
    pub episode: u64,
    /// [`StepKind::Expansion`] (the step became an edge of the search graph, or would have
    /// below the node cap) or [`StepKind::Simulation`] (a rollout step).
    pub kind: StepKind,
    /// The parts of `s`.
    pub present: PartSet,
    /// The memory words of `s` ([`Mdp::memory_range`](crate::Mdp::memory_range) per objective).
    pub memory: Vec<u64>,
    /// The feasible removals of `s` that the step chose from (increasing part order), computed
    /// with the step's kind — except for a rollout's first step from a node just added, which
    /// chooses from the node's feasible set, computed for the expansion.
    pub actions: Vec<usize>,
    /// The part removed.
    pub action: usize,
    /// The raw reward of each objective (in the problem's order).
    pub rewards: Vec<f64>,
    /// The memory words of `s'`.
    pub next_memory: Vec<u64>,
    /// The feasible removals of `s'` with the step's kind (empty: the episode ends there).
    pub next_actions: Vec<usize>,
    /// Whether `s'` holds fixed parts only (every removable part is gone).
    pub complete: bool,
}

/// What the stepped search ([`crate::Mcts::solve_stepped`], [`crate::ParetoMcts::solve_stepped`])
/// tells its hook after each episode.
#[derive(Clone, Debug)]
pub struct EpisodeEnd {
    /// Episodes finished so far.
    pub episodes: u64,
    /// Iterations since the previous report.
    pub iterations: u64,
    /// Seconds since the previous report (the hook's own time included).
    pub seconds: f64,
    /// The front's hypervolume (several objectives) or the best total so far (0 before the first
    /// complete sequence), as the trace reports it.
    pub value: f64,
    /// Points on the front so far.
    pub front_size: usize,
    /// The transitions the episode recorded ([`SearchBuilder::record_transitions`](crate::mcts::SearchBuilder::record_transitions); the limit
    /// holds per episode), in the order it took them.
    pub transitions: Vec<Transition>,
    /// Whether the episode reached the recording limit.
    pub transitions_capped: bool,
    /// The last report: the search ends after it (the hook's answer is ignored).
    pub finished: bool,
    /// Whether every sequence has been explored (the search ends).
    pub exhausted: bool,
    /// Whether a time limit or a stop token stopped the search.
    pub stopped: bool,
}

/// The hook's answer between two episodes of a stepped search.
#[derive(Clone, Debug)]
pub enum Next {
    /// Run the next episode with the same policy.
    Continue,
    /// Run the next episodes with this policy (e.g. Q-functions retrained on the transitions
    /// so far); the tree stays.
    Policy(Arc<dyn Policy>),
    /// End the search now (its answer is that of the episodes run).
    Stop,
}

/// The stepped search's hook: called between episodes with what the last one did. An error
/// ends the search with it.
pub type EpisodeHook<'h> = dyn FnMut(EpisodeEnd) -> Result<Next> + Send + 'h;

impl SearchOutcome {
    /// How the search ended ([`SearchOutcome::plan`]'s status).
    pub fn status(&self) -> &Status {
        &self.plan.status
    }

    /// The first solution (the best one for a single objective).
    pub fn best(&self) -> Option<&Solution> {
        self.solutions.first()
    }

    /// Writes the trace as CSV: `episode,iterations,seconds,value,front_size`.
    pub fn write_trace_csv(&self, mut w: impl std::io::Write) -> std::io::Result<()> {
        writeln!(w, "episode,iterations,seconds,value,front_size")?;
        for t in &self.trace {
            writeln!(w, "{},{},{:.6},{},{}", t.episode, t.iterations, t.seconds, t.value, t.front_size)?;
        }
        Ok(())
    }
}

impl From<SearchOutcome> for PlanOutcome {
    /// The search's answer in every planner's vocabulary ([`SearchOutcome::plan`]).
    fn from(outcome: SearchOutcome) -> PlanOutcome {
        outcome.plan
    }
}
