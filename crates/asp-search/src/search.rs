//! The machinery shared by [`crate::Mcts`] and [`crate::ParetoMcts`]: settings and their
//! validating builder, the search graph, episodes with a search budget per step (thesis 5.4.2),
//! root-parallel threads, and the outcome with its trace.
//!
//! # Episodes and steps
//! An *episode* walks from the root to a complete disassembly. At each *search step* it runs
//! `budget` *iterations* from the current node — selection by the tree policy, expansion of one
//! untried removal (chosen by the policy's [`PolicyWorker::expand`]: at random by default), a
//! rollout with the rollout policy until no part can be removed, and backpropagation along the
//! path to the root — and then moves to the child the tree policy picks. The next episode
//! starts again at the root.
//!
//! # Transpositions
//! Removing A then B leaves the same state as B then A. By default every state (present parts
//! and the objectives' memories, e.g. the direction-change objective's `H`) has one node, so the
//! search runs on a graph: node values hold *suffix* returns (from the state to the end, which do
//! not depend on the path), selection adds the edge's reward and the path's returns so far, and
//! at the end the answer is read off the graph's complete paths by dynamic programming and merged
//! with the best complete sequences sampled. `transpositions(false)` grows the thesis' plain tree
//! instead (there a node's suffix values equal its whole returns less a constant).
//!
//! # Solved and dead nodes
//! A node whose removals have all been expanded and whose children are all finished is
//! *solved* (everything below it has been explored) or *dead* (no complete sequence below it).
//! Selection skips finished children; when the root is finished the search stops early and its
//! answer is exact.
//!
//! # Threads
//! Root parallelism: each thread grows its own graph with its own random stream
//! (`seed`, thread index) and its share of the episodes; the answers are merged in thread order.
//! The output depends only on the seed, the settings and the thread count (not on timing)
//! unless a time limit or a [`StopToken`] stops the search. `threads = 1` runs on the calling
//! thread.
//!
//! # Recording transitions
//! With [`SearchBuilder::record_transitions`] every removal step the search simulates — at an
//! expansion or in a rollout — is kept as a [`Transition`] `(s, a, r, s')` for learning
//! Q-functions offline (thesis 5.5.2, 6.5.1). Selection walks edges that were recorded when
//! they were expanded, so expansions and rollouts cover every distinct step. Recording computes
//! the feasible actions of each step's states (with the step's [`StepKind`]) and nothing else
//! that the search reads: the search takes the same steps with or without it. Only
//! [`SearchStats`]' test counters also count the tests recording runs. The outcome holds the
//! transitions per thread in order, threads in order, up to
//! [`SearchBuilder::record_transitions_limit`] (split among the threads).
//!
//! # Stepping
//! `solve_stepped` runs the same loop on one thread with an [`EpisodeHook`] called between
//! episodes: it gets each episode's [`EpisodeEnd`] (its recorded transitions, the front so far)
//! and may go on, swap the policy ([`Next::Policy`]: the tree stays, the thread's
//! [`PolicyWorker`] is rebuilt) or stop. A hook that always goes on changes nothing: the answer
//! is `solve`'s. [`crate::stepped::SteppedSearch`] drives it from another thread (Python's
//! `Assembly.search`, the online Q-learning of thesis 6.5).
//!
//! # Plug-ins
//! The rollout and expansion policy ([`Policy`], one [`PolicyWorker`] per thread), the
//! objectives and the feasibility filters of the [`Mdp`] are the search's plug-ins. One that
//! fails or breaks its contract (a rollout index outside the actions offered) stops the search
//! with an error; a panic in one is reported as an error too, not re-raised.

use crate::error::{Result, SearchError};
use crate::hypervolume::ParetoFront;
use crate::mdp::{FilterCount, FilterCounts, Mdp, MAX_OBJECTIVES};
use crate::step::StepKind;
use crate::policy::{rng_for, Policy, PolicyContext, PolicyWorker, RandomPolicy, SearchRng};
use crate::polish::{Ended, Polisher};
use crate::problem::StopToken;
use asp_geom::distmap::MapState;
use asp_geom::{Motion, PartSet};
use std::collections::HashMap;
use std::hash::{Hash, Hasher};
use std::marker::PhantomData;
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

/// Default iterations per search step (the thesis' search budget of 5, 5.5 and 6.5).
pub const DEFAULT_BUDGET: usize = 5;
/// Default number of episodes (the thesis ran for a fixed time instead).
pub const DEFAULT_EPISODES: usize = 1000;
/// Default exploration constant `c` of UCT / MOUCB (the thesis does not state it): `1/√2`,
/// Kocsis and Szepesvári's choice for rewards in `[0, 1]`.
pub const DEFAULT_EXPLORATION: f64 = std::f64::consts::FRAC_1_SQRT_2;
/// Default cap on tree nodes per thread; beyond it iterations roll out without expanding.
pub const DEFAULT_MAX_NODES: usize = 1_000_000;
/// Default share of a search's work its local search may take ([`SearchBuilder::polish`]).
pub const DEFAULT_POLISH: f64 = 0.25;
/// Default cap on recorded transitions ([`SearchBuilder::record_transitions_limit`]).
pub const DEFAULT_RECORD_LIMIT: usize = 1_000_000;

/// Settings of a tree search. Build with [`crate::Mcts::builder`] or
/// [`crate::ParetoMcts::builder`].
#[derive(Clone, Debug)]
pub struct SearchSettings {
    pub(crate) budget: usize,
    pub(crate) episodes: usize,
    pub(crate) threads: usize,
    pub(crate) seed: u64,
    pub(crate) exploration: f64,
    pub(crate) max_nodes: usize,
    pub(crate) time_limit: Option<Duration>,
    pub(crate) policy: Arc<dyn Policy>,
    pub(crate) reference: Option<Vec<f64>>,
    pub(crate) transpositions: bool,
    pub(crate) stop: Option<StopToken>,
    pub(crate) prior_weight: f64,
    pub(crate) record: bool,
    pub(crate) record_limit: usize,
    pub(crate) lazy_filters: bool,
    pub(crate) polish: f64,
}

impl Default for SearchSettings {
    fn default() -> Self {
        SearchSettings {
            budget: DEFAULT_BUDGET,
            episodes: DEFAULT_EPISODES,
            threads: 1,
            seed: 0,
            exploration: DEFAULT_EXPLORATION,
            max_nodes: DEFAULT_MAX_NODES,
            time_limit: None,
            policy: Arc::new(RandomPolicy),
            reference: None,
            transpositions: true,
            stop: None,
            prior_weight: 0.0,
            record: false,
            record_limit: DEFAULT_RECORD_LIMIT,
            lazy_filters: true,
            polish: DEFAULT_POLISH,
        }
    }
}

impl SearchSettings {
    /// Iterations per search step.
    pub fn budget(&self) -> usize {
        self.budget
    }
    /// Episodes (over all threads).
    pub fn episodes(&self) -> usize {
        self.episodes
    }
    /// Threads (root parallel).
    pub fn threads(&self) -> usize {
        self.threads
    }
    /// Seed of every random choice.
    pub fn seed(&self) -> u64 {
        self.seed
    }
    /// Exploration constant `c`.
    pub fn exploration(&self) -> f64 {
        self.exploration
    }
    /// Cap on tree nodes per thread.
    pub fn max_nodes(&self) -> usize {
        self.max_nodes
    }
    /// Wall-clock limit, if any.
    pub fn time_limit(&self) -> Option<Duration> {
        self.time_limit
    }
    /// Whether states reached along different paths share one node.
    pub fn transpositions(&self) -> bool {
        self.transpositions
    }
    /// The weight of the policy's priors in the tree policy (0: none).
    pub fn prior_weight(&self) -> f64 {
        self.prior_weight
    }
    /// The policy.
    pub fn policy(&self) -> &Arc<dyn Policy> {
        &self.policy
    }
    /// Whether the search records its transitions.
    pub fn records_transitions(&self) -> bool {
        self.record
    }
    /// The cap on recorded transitions (all threads).
    pub fn record_transitions_limit(&self) -> usize {
        self.record_limit
    }
    /// Whether rollouts ask the problem's filters lazily ([`SearchBuilder::lazy_filters`]).
    pub fn lazy_filters(&self) -> bool {
        self.lazy_filters
    }
    /// The share of the search's work its local search may take (0: none).
    pub fn polish(&self) -> f64 {
        self.polish
    }
}

/// A validating builder of a search (`K` is [`crate::Mcts`] or [`crate::ParetoMcts`]).
#[derive(Clone, Debug)]
pub struct SearchBuilder<K> {
    settings: SearchSettings,
    kind: PhantomData<fn() -> K>,
}

impl<K: From<SearchSettings>> Default for SearchBuilder<K> {
    fn default() -> Self {
        SearchBuilder { settings: SearchSettings::default(), kind: PhantomData }
    }
}

impl<K: From<SearchSettings>> SearchBuilder<K> {
    /// Iterations per search step (default 5, ≥ 1).
    pub fn budget(mut self, budget: usize) -> Self {
        self.settings.budget = budget;
        self
    }

    /// Episodes over all threads (default 1000, ≥ 1).
    pub fn episodes(mut self, episodes: usize) -> Self {
        self.settings.episodes = episodes;
        self
    }

    /// Threads, each growing its own tree (default 1; 1..=256).
    pub fn threads(mut self, threads: usize) -> Self {
        self.settings.threads = threads;
        self
    }

    /// Seed of every random choice (default 0).
    pub fn seed(mut self, seed: u64) -> Self {
        self.settings.seed = seed;
        self
    }

    /// Exploration constant `c` (default 1/√2, finite and ≥ 0).
    pub fn exploration(mut self, c: f64) -> Self {
        self.settings.exploration = c;
        self
    }

    /// Cap on tree nodes per thread (default 1,000,000, ≥ 1).
    pub fn max_nodes(mut self, max_nodes: usize) -> Self {
        self.settings.max_nodes = max_nodes;
        self
    }

    /// Stops after this wall-clock time even if episodes remain (breaks reproducibility).
    pub fn time_limit(mut self, limit: Duration) -> Self {
        self.settings.time_limit = Some(limit);
        self
    }

    /// The rollout and expansion policy (default [`RandomPolicy`]).
    pub fn policy(mut self, policy: Arc<dyn Policy>) -> Self {
        self.settings.policy = policy;
        self
    }

    /// Stops the search when `token` is stopped (breaks reproducibility, like a time limit).
    pub fn stop_token(mut self, token: StopToken) -> Self {
        self.settings.stop = Some(token);
        self
    }

    /// The weight `w` of the PUCT bonus `w · P(a) · √N(s) / (1 + N(s, a))` that the policy's
    /// priors ([`PolicyWorker::priors`]) add to the tree policy's score (default 0: priors only
    /// order expansions; finite and ≥ 0).
    pub fn prior_weight(mut self, weight: f64) -> Self {
        self.settings.prior_weight = weight;
        self
    }

    /// The hypervolume reference point (default: every objective's worst possible total).
    pub fn reference(mut self, reference: Vec<f64>) -> Self {
        self.settings.reference = Some(reference);
        self
    }

    /// Whether states reached by different removal orders share one node (default true): the
    /// search runs on a graph of states, node values are about the removals still to come, and
    /// the answer is read off the graph's complete paths at the end. `false` grows the thesis'
    /// plain tree.
    pub fn transpositions(mut self, yes: bool) -> Self {
        self.settings.transpositions = yes;
        self
    }

    /// Records every removal step the search simulates (expansions and rollout steps) as a
    /// [`Transition`] in [`SearchOutcome::transitions`] (default false). The search's answers
    /// are the same either way; recording costs the feasible actions of each step's states and
    /// memory.
    pub fn record_transitions(mut self, yes: bool) -> Self {
        self.settings.record = yes;
        self
    }

    /// Whether rollouts ask the problem's feasibility filters lazily (default true): the rollout
    /// policy draws from the removals the maps allow, the filters are asked about the drawn one
    /// only, and a rejected one is dropped before the policy draws again, so a state costs
    /// filter checks until its first admitted removal instead of one per candidate. A filter
    /// that is expensive (a robot planning a path per removal) makes rollouts that much cheaper.
    /// With `false` every candidate of every rollout state is filtered first and the policy
    /// draws among the admitted ones. Either way the rollout takes an admitted removal, ends
    /// where none is admitted and depends only on the seed; the random policy's draws have the
    /// same distribution, but the random streams differ, so the two give different searches.
    /// Without filters both are the same search. Expansions always filter a new node's
    /// removals (its untried set).
    pub fn lazy_filters(mut self, yes: bool) -> Self {
        self.settings.lazy_filters = yes;
        self
    }

    /// The local search over the answer's sequences ([`crate::polish`]): every complete sequence
    /// that enters a thread's front of sampled sequences is improved by block moves, with at
    /// most `share` map steps of local search per step of the tree search, and `share` filter
    /// checks per check of the tree search, while the search runs (default [`DEFAULT_POLISH`];
    /// 0 turns it off). When the episodes are done (not at a time limit or a stop), the thread
    /// searches on until no sequence is left to search around or its local search has done as
    /// much work as its tree search. Deterministic for a seed like the rest.
    pub fn polish(mut self, share: f64) -> Self {
        self.settings.polish = share;
        self
    }

    /// The most transitions recorded (default 1,000,000, ≥ 1), split among the threads like the
    /// episodes; a thread that reaches its share stops recording and the outcome says so
    /// ([`SearchOutcome::transitions_capped`]).
    pub fn record_transitions_limit(mut self, limit: usize) -> Self {
        self.settings.record_limit = limit;
        self
    }

    /// Checks the settings.
    pub fn build(self) -> Result<K> {
        let s = &self.settings;
        if s.budget == 0 {
            return Err(SearchError::config("the search budget must be at least 1"));
        }
        if s.episodes == 0 {
            return Err(SearchError::config("episodes must be at least 1"));
        }
        if s.threads == 0 || s.threads > 256 {
            return Err(SearchError::config(format!("threads must be in 1..=256, got {}", s.threads)));
        }
        if !(s.exploration.is_finite() && s.exploration >= 0.0) {
            return Err(SearchError::config(format!(
                "the exploration constant must be finite and >= 0, got {}",
                s.exploration
            )));
        }
        if s.max_nodes == 0 {
            return Err(SearchError::config("max_nodes must be at least 1"));
        }
        if s.record_limit == 0 {
            return Err(SearchError::config("the transitions limit must be at least 1"));
        }
        if s.time_limit.is_some_and(|t| t.is_zero()) {
            return Err(SearchError::config("the time limit must be positive"));
        }
        if !(s.prior_weight.is_finite() && s.prior_weight >= 0.0) {
            return Err(SearchError::config(format!(
                "the prior weight must be finite and >= 0, got {}",
                s.prior_weight
            )));
        }
        if !(s.polish.is_finite() && s.polish >= 0.0) {
            return Err(SearchError::config(format!("the local search share must be finite and >= 0, got {}", s.polish)));
        }
        if let Some(r) = &s.reference {
            if r.iter().any(|v| !v.is_finite()) {
                return Err(SearchError::config("the reference point must be finite"));
            }
        }
        Ok(K::from(self.settings))
    }
}

/// Declares a search type that a [`SearchBuilder`] builds: the struct holding its
/// [`SearchSettings`], the builder's alias, `builder()` and `settings()`. Each variant adds its
/// own `solve`.
macro_rules! search_type {
    ($(#[$attr:meta])* $name:ident, $builder:ident) => {
        $(#[$attr])*
        #[derive(Clone, Debug)]
        pub struct $name {
            settings: $crate::search::SearchSettings,
        }

        #[doc = concat!("The builder of [`", stringify!($name), "`].")]
        pub type $builder = $crate::search::SearchBuilder<$name>;

        impl From<$crate::search::SearchSettings> for $name {
            fn from(settings: $crate::search::SearchSettings) -> Self {
                $name { settings }
            }
        }

        impl $name {
            /// A builder with the defaults (budget 5, 1000 episodes, 1 thread, seed 0, c = 1/√2).
            pub fn builder() -> $builder {
                $crate::search::SearchBuilder::default()
            }

            /// The settings.
            pub fn settings(&self) -> &$crate::search::SearchSettings {
                &self.settings
            }
        }
    };
}
pub(crate) use search_type;

/// How a search ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SearchStatus {
    /// At least one complete feasible sequence was found.
    Found,
    /// The whole tree was explored: no complete feasible sequence exists.
    NoPlan,
    /// The budget ran out before any complete sequence was found.
    BudgetExhausted,
}

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
    /// Complete sequences the search found that did not replay ([`Mdp::evaluate`]: a filter
    /// that rejects on replay what a rollout admitted); they are left out of the answer.
    #[serde(default)]
    pub replay_failures: u64,
    /// Removals put to the problem's feasibility filters (all threads; [`FilterCounts::checks`]),
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
    /// How the search ended.
    pub status: SearchStatus,
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
    /// The recorded transitions ([`SearchBuilder::record_transitions`]; empty without it): each
    /// thread's in the order it took them, threads in order.
    pub transitions: Vec<Transition>,
    /// Whether a thread reached its share of [`SearchBuilder::record_transitions_limit`] and
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
    /// The memory words of `s` ([`Mdp::memory_range`] per objective).
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
    /// The transitions the episode recorded ([`SearchBuilder::record_transitions`]; the limit
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

/// A worker's recording: the transitions so far, the step being recorded (until the feasible
/// actions of its `s'` are known) and scratch.
struct Recorder {
    transitions: Vec<Transition>,
    limit: usize,
    capped: bool,
    /// The current episode's number.
    episode: u64,
    pending: Option<Transition>,
    actions: Vec<usize>,
    counts: FilterCounts,
}

impl Recorder {
    /// Whether there is room for another transition (sets `capped` when there is not).
    fn active(&mut self) -> bool {
        if self.transitions.len() >= self.limit {
            self.capped = true;
        }
        !self.capped
    }

    /// Starts recording a step from `s` (before it is taken).
    fn begin(&mut self, kind: StepKind, present: PartSet, memory: &[u64], actions: &[usize], action: usize) {
        self.pending = Some(Transition {
            episode: self.episode,
            kind,
            present,
            memory: memory.to_vec(),
            actions: actions.to_vec(),
            action,
            rewards: Vec::new(),
            next_memory: Vec::new(),
            next_actions: Vec::new(),
            complete: false,
        });
    }

    /// The step's outcome, once taken.
    fn taken(&mut self, rewards: &[f64], next_memory: &[u64], complete: bool) {
        if let Some(t) = &mut self.pending {
            t.rewards = rewards.to_vec();
            t.next_memory = next_memory.to_vec();
            t.complete = complete;
        }
    }

    /// Completes the pending step with the feasible actions of its `s'`.
    fn finish(&mut self, next_actions: &[usize]) {
        if let Some(mut t) = self.pending.take() {
            t.next_actions = next_actions.to_vec();
            self.transitions.push(t);
        }
    }
}

impl SearchOutcome {
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

// ---------------------------------------------------------------------------------------------
// The search graph

pub(crate) const NONE: u32 = u32::MAX;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Status {
    Open,
    Solved,
    Dead,
}

/// A disassembly state: the parts present and the objectives' memory words (kept in
/// [`Tree::memory`]). With transpositions every state has one node however it was reached.
/// What selection reads is here (16 bytes); the node's part sets are in [`Tree::sets`].
#[derive(Clone, Debug)]
pub(crate) struct Node {
    pub first_edge: u32,
    pub visits: u32,
    /// The next node with the same key hash (transposition index chain).
    next_same: u32,
    /// Removals not expanded yet (the size of [`NodeSets::untried`]).
    untried_left: u16,
    pub status: Status,
}

/// The part sets of a node, read when the search expands it.
#[derive(Clone, Debug)]
pub(crate) struct NodeSets {
    present: PartSet,
    /// Parts known to be collision-free here (they stay so in every descendant).
    free: PartSet,
    untried: PartSet,
}

/// A removal from a node: the child it leads to, its rewards (in [`Tree::rewards`]) and visits.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Edge {
    pub child: u32,
    pub next: u32,
    pub visits: u32,
    pub action: u16,
}

/// The search graph (a tree without transpositions). Node values are about *suffixes*: the
/// returns from the node's state to the end, which do not depend on how the state was reached.
pub(crate) struct Tree<V> {
    pub nodes: Vec<Node>,
    sets: Vec<NodeSets>,
    pub values: Vec<V>,
    pub edges: Vec<Edge>,
    rewards: Vec<f64>,
    /// `w` memory words per node.
    memory: Vec<u64>,
    w: usize,
    index: HashMap<u64, u32>,
    pub m: usize,
    /// With a policy that gives priors: per node, its feasible actions' priors (a range of
    /// `node_priors`), and per edge its action's prior.
    prior_spans: Vec<(u32, u32)>,
    node_priors: Vec<(u16, f32)>,
    pub edge_priors: Vec<f32>,
}

impl<V> Tree<V> {
    fn memory(&self, n: u32) -> &[u64] {
        &self.memory[n as usize * self.w..(n as usize + 1) * self.w]
    }

    /// Whether node `n` has priors (it was added while the policy gave priors).
    fn has_priors(&self, n: u32) -> bool {
        self.prior_spans.get(n as usize).is_some_and(|s| s.0 != NONE)
    }

    /// The prior node `n` gave `action` (0 when it gave none).
    fn prior_of(&self, n: u32, action: usize) -> f32 {
        let Some(&(from, to)) = self.prior_spans.get(n as usize).filter(|s| s.0 != NONE) else { return 0.0 };
        self.node_priors[from as usize..to as usize].iter().find(|(a, _)| *a as usize == action).map_or(0.0, |p| p.1)
    }

    /// The rewards of edge `e`.
    pub fn reward(&self, e: u32) -> &[f64] {
        &self.rewards[e as usize * self.m..(e as usize + 1) * self.m]
    }

    /// The edges out of node `n`.
    pub fn edges_of(&self, n: u32) -> EdgeIter<'_, V> {
        EdgeIter { tree: self, next: self.nodes[n as usize].first_edge }
    }

    /// Whether node `n` holds `present` and `memory` (its key words).
    fn is(&self, n: u32, present: &PartSet, memory: &[u64], problem: &Mdp) -> bool {
        self.sets[n as usize].present == *present && problem.key_eq(self.memory(n), memory)
    }
}

/// Iterates the edges out of a node.
pub(crate) struct EdgeIter<'a, V> {
    tree: &'a Tree<V>,
    next: u32,
}

impl<V> Iterator for EdgeIter<'_, V> {
    type Item = u32;
    fn next(&mut self) -> Option<u32> {
        (self.next != NONE).then(|| {
            let e = self.next;
            self.next = self.tree.edges[e as usize].next;
            e
        })
    }
}

/// A hash of a state (present parts and the memories' key words), for the transposition index.
fn state_hash(present: &PartSet, memory: &[u64], problem: &Mdp) -> u64 {
    let mut h = std::collections::hash_map::DefaultHasher::new();
    present.hash(&mut h);
    problem.hash_key(memory, &mut h);
    h.finish()
}

/// Global bounds of the returns seen so far (per objective).
#[derive(Clone, Debug)]
pub(crate) struct Bounds {
    pub lo: [f64; MAX_OBJECTIVES],
    pub hi: [f64; MAX_OBJECTIVES],
}

impl Bounds {
    fn new() -> Self {
        Bounds { lo: [f64::INFINITY; MAX_OBJECTIVES], hi: [f64::NEG_INFINITY; MAX_OBJECTIVES] }
    }

    fn update(&mut self, ret: &[f64]) {
        for (k, &v) in ret.iter().enumerate() {
            self.lo[k] = self.lo[k].min(v);
            self.hi[k] = self.hi[k].max(v);
        }
    }

    /// `v` mapped to `[0, 1]` by the bounds of objective `k` (1 when the range is empty).
    #[inline]
    pub fn normalise(&self, k: usize, v: f64) -> f64 {
        let range = self.hi[k] - self.lo[k];
        if range > 0.0 {
            (v - self.lo[k]) / range
        } else {
            1.0
        }
    }
}

/// What the tree policy needs besides the graph.
pub(crate) struct SelectContext<'a> {
    pub exploration: f64,
    pub bounds: &'a Bounds,
    /// The returns collected on the way to the node selection starts from.
    pub prefix: &'a [f64],
    /// The PUCT weight and the edges' priors, when the policy gives priors and the weight is
    /// positive.
    pub priors: Option<(f64, &'a [f32])>,
}

impl SelectContext<'_> {
    /// The PUCT bonus of edge `e`: `w · P(e) · √N(parent) / (1 + N(e))` (0 without priors).
    #[inline]
    pub fn prior_bonus(&self, e: u32, parent_visits: u32, edge_visits: u32) -> f64 {
        match self.priors {
            None => 0.0,
            Some((w, p)) => w * p[e as usize] as f64 * (parent_visits as f64).sqrt() / (1.0 + edge_visits as f64),
        }
    }
}

/// The variant-specific parts: the node value, its backup and the tree policy.
pub(crate) trait Variant: Send + Sync {
    /// What a node keeps of the suffix returns through it.
    type Value: Default + Send;
    /// Records the suffix return of a complete sequence through the node; false when it
    /// added nothing (without transpositions, backpropagation of values then stops: the node's
    /// ancestors hold something at least as good).
    fn record(value: &mut Self::Value, suffix: &[f64]) -> bool;
    /// The position in `candidates` (edges out of `node`, not empty) the tree policy picks.
    fn select(tree: &Tree<Self::Value>, node: u32, candidates: &[u32], ctx: &SelectContext<'_>) -> usize;
}

/// `c · sqrt(2 ln N(parent) / N(child))`.
#[inline]
pub(crate) fn exploration_term(c: f64, parent_visits: u32, child_visits: u32) -> f64 {
    let n = (parent_visits.max(1)) as f64;
    c * (2.0 * n.ln() / child_visits.max(1) as f64).sqrt()
}

struct Shared {
    front: ParetoFront<()>,
    episodes: u64,
    iterations: u64,
    trace: Vec<TracePoint>,
    last_value: Option<f64>,
}

struct Worker<'p, V: Variant> {
    problem: &'p Mdp,
    settings: &'p SearchSettings,
    m: usize,
    n: usize,
    /// Memory words per state.
    w: usize,
    tree: Tree<V::Value>,
    rng: SearchRng,
    sim: MapState<'p>,
    /// The thread's index.
    thread: usize,
    /// Whether the current policy gives priors.
    priors: bool,
    actions: Vec<usize>,
    candidates: Vec<u32>,
    /// Scratch: a node's untried actions and their priors, and the priors of new nodes.
    untried: Vec<usize>,
    untried_priors: Vec<f64>,
    prior_buf: Vec<f64>,
    /// Scratch: the memory words of the state being simulated.
    memory: Vec<u64>,
    /// The nodes of the current path from the root, the edges between them, and the returns
    /// collected up to each node (`m` per node).
    path: Vec<u32>,
    path_edges: Vec<u32>,
    path_prefix: Vec<f64>,
    sequence: Vec<u16>,
    bounds: Bounds,
    archive: ParetoFront<Vec<u16>>,
    archive_changed: bool,
    stats: SearchStats,
    filtered: FilterCounts,
    deadline: Option<Instant>,
    /// When the search started.
    start: Instant,
    /// The complete sequences' values that entered the archive during the current episode,
    /// with the seconds and the episode's iterations when they did (trace rows inside an
    /// episode).
    found: Vec<(Vec<f64>, f64, u64)>,
    /// Iterations of the current episode so far.
    episode_iterations: u64,
    stopped: bool,
    /// The first plug-in error; it stops this worker, and through `abort` the others.
    error: Option<SearchError>,
    abort: &'p StopToken,
    /// The recording, when the settings ask for it.
    record: Option<Recorder>,
    /// The local search, when the settings ask for one.
    polisher: Option<Polisher<'p>>,
}

impl<'p, V: Variant> Worker<'p, V> {
    fn new(
        problem: &'p Mdp,
        settings: &'p SearchSettings,
        thread: usize,
        start: Instant,
        abort: &'p StopToken,
        first_episode: u64,
    ) -> Result<Self> {
        let m = problem.num_objectives();
        let maps = problem.maps();
        let n = maps.num_parts();
        let memory = problem.initial_memory();
        let w = memory.len();
        let mut sim = MapState::new(maps);
        let mut filtered = problem.filter_counts();
        let mut actions = Vec::with_capacity(n);
        problem.feasible_actions(&mut sim, &memory, StepKind::Expansion, &mut actions, &mut filtered);
        let full = PartSet::full(n);
        let complete = sim.is_complete();
        let root = Node {
            first_edge: NONE,
            visits: 0,
            status: if complete {
                Status::Solved
            } else if actions.is_empty() {
                Status::Dead
            } else {
                Status::Open
            },
            next_same: NONE,
            untried_left: actions.len() as u16,
        };
        let root_sets = NodeSets {
            present: full,
            free: sim.collision_free(),
            untried: PartSet::from_indices(n, actions.iter().copied()),
        };
        let mut tree = Tree {
            nodes: vec![root],
            sets: vec![root_sets],
            values: vec![V::Value::default()],
            edges: Vec::new(),
            rewards: Vec::new(),
            memory: memory.clone(),
            w,
            index: HashMap::new(),
            m,
            prior_spans: Vec::new(),
            node_priors: Vec::new(),
            edge_priors: Vec::new(),
        };
        if settings.transpositions {
            tree.index.insert(state_hash(&tree.sets[0].present, tree.memory(0), problem), 0);
        }
        let worker = Worker {
            problem,
            settings,
            m,
            n,
            w,
            tree,
            rng: rng_for(settings.seed, thread as u64),
            sim,
            thread,
            priors: false,
            actions,
            candidates: Vec::with_capacity(n),
            untried: Vec::with_capacity(n),
            untried_priors: Vec::with_capacity(n),
            prior_buf: Vec::with_capacity(n),
            memory,
            path: Vec::with_capacity(n + 1),
            path_edges: Vec::with_capacity(n),
            path_prefix: Vec::with_capacity((n + 1) * m),
            sequence: Vec::with_capacity(n),
            bounds: Bounds::new(),
            archive: ParetoFront::new(m),
            archive_changed: false,
            stats: SearchStats::default(),
            filtered,
            deadline: settings.time_limit.map(|t| start + t),
            start,
            found: Vec::new(),
            episode_iterations: 0,
            stopped: false,
            error: None,
            abort,
            record: settings.record.then(|| Recorder {
                transitions: Vec::new(),
                limit: share_of(settings.record_limit, settings.threads, thread),
                capped: false,
                episode: first_episode,
                pending: None,
                actions: Vec::with_capacity(n),
                counts: problem.filter_counts(),
            }),
            polisher: (settings.polish > 0.0).then(|| Polisher::new(problem)),
        };
        Ok(worker)
    }

    /// Takes `policy` (this thread's worker of the search's policy, or of a policy swapped in
    /// between episodes) as the one the next episodes use. A policy that gives priors asks for
    /// the root's at the start (the simulated state is the root's then); nodes added while the
    /// policy gave none have none ([`Tree::prior_of`]).
    fn adopt(&mut self, policy: &mut dyn PolicyWorker) -> Result<()> {
        self.priors = policy.has_priors();
        if !self.priors {
            return Ok(());
        }
        if self.tree.prior_spans.is_empty() && self.tree.nodes.len() == 1 && self.stats.iterations == 0 {
            return self.record_priors(policy);
        }
        self.tree.prior_spans.resize(self.tree.nodes.len(), (NONE, NONE));
        self.tree.edge_priors.resize(self.tree.edges.len(), 0.0);
        Ok(())
    }

    /// Asks the policy for the priors of `self.actions` in the simulated state (that of the
    /// node just added) and keeps them for that node.
    fn record_priors(&mut self, policy: &mut dyn PolicyWorker) -> Result<()> {
        let count = self.actions.len();
        self.prior_buf.clear();
        self.prior_buf.resize(count, 0.0);
        let mut ctx = PolicyContext { state: &mut self.sim, memory: &self.memory, problem: self.problem };
        policy.priors(&mut ctx, &self.actions, &mut self.prior_buf)?;
        let from = self.tree.node_priors.len() as u32;
        self.tree.node_priors.extend(self.actions.iter().zip(&self.prior_buf).map(|(&a, &p)| (a as u16, p as f32)));
        self.tree.prior_spans.push((from, self.tree.node_priors.len() as u32));
        Ok(())
    }

    fn root_finished(&self) -> bool {
        self.tree.nodes[0].status != Status::Open
    }

    /// Moves the path along edge `e` to its child.
    fn push(&mut self, e: u32) {
        let m = self.m;
        let child = self.tree.edges[e as usize].child;
        let base = self.path_prefix.len() - m;
        for k in 0..m {
            let v = self.path_prefix[base + k] + self.tree.rewards[e as usize * m + k];
            self.path_prefix.push(v);
        }
        self.path.push(child);
        self.path_edges.push(e);
    }

    /// Cuts the path back to its first `len` nodes.
    fn truncate(&mut self, len: usize) {
        self.path.truncate(len);
        self.path_edges.truncate(len - 1);
        self.path_prefix.truncate(len * self.m);
    }

    /// Whether the time limit or the stop token says to stop.
    #[inline]
    fn should_stop(&self) -> bool {
        self.deadline.is_some_and(|d| Instant::now() >= d)
            || self.settings.stop.as_ref().is_some_and(StopToken::is_stopped)
            || self.abort.is_stopped()
    }

    /// One episode: search steps from the root down to a complete sequence.
    fn episode(&mut self, policy: &mut dyn PolicyWorker) {
        self.episode_iterations = 0;
        self.path.clear();
        self.path_edges.clear();
        self.path_prefix.clear();
        self.path.push(0);
        self.path_prefix.extend(std::iter::repeat_n(0.0, self.m));
        loop {
            let current = *self.path.last().expect("the path starts at the root");
            let node = &self.tree.nodes[current as usize];
            if node.status == Status::Dead || (node.status == Status::Solved && node.first_edge == NONE) {
                break;
            }
            for _ in 0..self.settings.budget {
                if self.tree.nodes[current as usize].status != Status::Open {
                    break;
                }
                if let Err(e) = self.iterate(policy) {
                    self.error = Some(e);
                    self.stopped = true;
                    return;
                }
                self.stats.iterations += 1;
                self.episode_iterations += 1;
                if self.should_stop() {
                    self.stopped = true;
                    return;
                }
            }
            match self.commit(current) {
                Some(e) => self.push(e),
                None => break,
            }
        }
    }

    /// The tree policy's context at the end of the path.
    fn select_context(&self) -> SelectContext<'_> {
        let m = self.m;
        SelectContext {
            exploration: self.settings.exploration,
            bounds: &self.bounds,
            prefix: &self.path_prefix[self.path_prefix.len() - m..],
            priors: (self.priors && self.settings.prior_weight > 0.0)
                .then_some((self.settings.prior_weight, &self.tree.edge_priors[..])),
        }
    }

    /// The edge the tree policy takes at the end of a search step (to any child that is not
    /// dead).
    fn commit(&mut self, node: u32) -> Option<u32> {
        self.candidates.clear();
        for e in self.tree.edges_of(node) {
            let child = self.tree.edges[e as usize].child;
            if self.tree.nodes[child as usize].status != Status::Dead {
                self.candidates.push(e);
            }
        }
        if self.candidates.is_empty() {
            return None;
        }
        let k = V::select(&self.tree, node, &self.candidates, &self.select_context());
        Some(self.candidates[k])
    }

    /// Selection, expansion, rollout and backpropagation from the end of the path.
    fn iterate(&mut self, policy: &mut dyn PolicyWorker) -> Result<()> {
        let m = self.m;
        let w = self.w;
        let base = self.path.len();
        // Selection: descend through fully expanded nodes.
        loop {
            let node = *self.path.last().expect("path");
            let nd = &self.tree.nodes[node as usize];
            if nd.status != Status::Open {
                self.truncate(base);
                return Ok(());
            }
            if nd.untried_left != 0 {
                break;
            }
            self.candidates.clear();
            for e in self.tree.edges_of(node) {
                let child = self.tree.edges[e as usize].child;
                if self.tree.nodes[child as usize].status == Status::Open {
                    self.candidates.push(e);
                }
            }
            if self.candidates.is_empty() {
                self.refresh_path_status();
                self.truncate(base);
                return Ok(());
            }
            let k = V::select(&self.tree, node, &self.candidates, &self.select_context());
            let e = self.candidates[k];
            self.push(e);
        }

        // Expansion: an untried removal, chosen by the policy (at random by default).
        let parent = *self.path.last().expect("path");
        let ps = &self.tree.sets[parent as usize];
        self.sim.reset_with_free(&ps.present, &ps.free);
        self.memory.copy_from_slice(self.tree.memory(parent));
        let mut ret = [0.0f64; MAX_OBJECTIVES];
        ret[..m].copy_from_slice(&self.path_prefix[self.path_prefix.len() - m..]);
        self.untried.clear();
        self.untried.extend(self.tree.sets[parent as usize].untried.iter());
        let untried_priors = if self.priors && self.tree.has_priors(parent) {
            self.untried_priors.clear();
            for &a in &self.untried {
                self.untried_priors.push(self.tree.prior_of(parent, a) as f64);
            }
            Some(&self.untried_priors[..])
        } else {
            None
        };
        let pick = {
            let mut ctx = PolicyContext { state: &mut self.sim, memory: &self.memory, problem: self.problem };
            policy.expand(&mut ctx, &self.untried, untried_priors, &mut self.rng)?
        };
        let Some(&action) = self.untried.get(pick) else {
            return Err(SearchError::plugin(
                "expansion policy",
                format!("chose untried action {pick} of {}", self.untried.len()),
            ));
        };
        if let Some(rec) = &mut self.record {
            if rec.active() {
                let mut actions = std::mem::take(&mut rec.actions);
                self.problem.feasible_actions(&mut self.sim, &self.memory, StepKind::Expansion, &mut actions, &mut rec.counts);
                rec.begin(StepKind::Expansion, self.sim.present(), &self.memory, &actions, action);
                rec.actions = actions;
            }
        }
        let mut rewards = [0.0f64; MAX_OBJECTIVES];
        self.problem.step(&mut self.sim, &mut self.memory, action, StepKind::Expansion, &mut rewards[..m]);
        for k in 0..m {
            ret[k] += rewards[k];
        }
        if let Some(rec) = &mut self.record {
            rec.taken(&rewards[..m], &self.memory, self.sim.is_complete());
        }
        let present = self.sim.present();
        // The child: an existing node with the same state, or a new one.
        let hash = if self.settings.transpositions { state_hash(&present, &self.memory, self.problem) } else { 0 };
        let mut existing = NONE;
        if self.settings.transpositions {
            let mut c = self.tree.index.get(&hash).copied().unwrap_or(NONE);
            while c != NONE {
                if self.tree.is(c, &present, &self.memory, self.problem) {
                    existing = c;
                    break;
                }
                c = self.tree.nodes[c as usize].next_same;
            }
        }
        let expanded = existing != NONE || self.tree.nodes.len() < self.settings.max_nodes;
        let mut new_child = false;
        if expanded {
            self.tree.sets[parent as usize].untried.remove(action);
            self.tree.nodes[parent as usize].untried_left -= 1;
            let child = if existing != NONE {
                existing
            } else {
                new_child = true;
                self.problem.feasible_actions(
                    &mut self.sim,
                    &self.memory,
                    StepKind::Expansion,
                    &mut self.actions,
                    &mut self.filtered,
                );
                let status = if self.sim.is_complete() {
                    Status::Solved
                } else if self.actions.is_empty() {
                    Status::Dead
                } else {
                    Status::Open
                };
                let id = self.tree.nodes.len() as u32;
                let next_same = if self.settings.transpositions {
                    self.tree.index.insert(hash, id).unwrap_or(NONE)
                } else {
                    NONE
                };
                self.tree.nodes.push(Node {
                    first_edge: NONE,
                    visits: 0,
                    status,
                    next_same,
                    untried_left: self.actions.len() as u16,
                });
                self.tree.sets.push(NodeSets {
                    present,
                    free: self.sim.collision_free(),
                    untried: PartSet::from_indices(self.n, self.actions.iter().copied()),
                });
                self.tree.values.push(V::Value::default());
                self.tree.memory.extend_from_slice(&self.memory[..w]);
                if self.priors {
                    self.record_priors(policy)?;
                }
                id
            };
            let e = self.tree.edges.len() as u32;
            let first = self.tree.nodes[parent as usize].first_edge;
            self.tree.edges.push(Edge { child, next: first, visits: 0, action: action as u16 });
            self.tree.rewards.extend_from_slice(&rewards[..m]);
            if self.priors {
                let p = self.tree.prior_of(parent, action);
                self.tree.edge_priors.push(p);
            }
            self.tree.nodes[parent as usize].first_edge = e;
            self.push(e);
        }

        // The recorded step's s': a new child's feasible actions are in `actions` (the rollout
        // completes the record), the rollout computes them for simulation otherwise, which is
        // the same set unless filters tell the kinds apart.
        if !new_child && !self.problem.filters().is_empty() {
            if let Some(rec) = self.record.as_mut().filter(|r| r.pending.is_some()) {
                let mut actions = std::mem::take(&mut rec.actions);
                self.problem.feasible_actions(&mut self.sim, &self.memory, StepKind::Expansion, &mut actions, &mut rec.counts);
                rec.finish(&actions);
                rec.actions = actions;
            }
        }

        // The sequence so far: the path's removals (and the unexpanded action).
        self.sequence.clear();
        self.sequence.extend(self.path_edges.iter().map(|&e| self.tree.edges[e as usize].action));
        if !expanded {
            self.sequence.push(action as u16);
        }

        // Rollout with the rollout policy (from a transposed child too: more evidence).
        // a new child's feasible removals are in `actions` already. With lazy filters the
        // other states offer the maps' candidates and the filters are asked about the drawn one.
        let lazy = self.settings.lazy_filters && !self.problem.filters().is_empty();
        let mut known = new_child;
        loop {
            let filtered = known || !lazy;
            if !known {
                if lazy {
                    self.problem.candidate_actions(&mut self.sim, &mut self.actions);
                } else {
                    self.problem.feasible_actions(
                        &mut self.sim,
                        &self.memory,
                        StepKind::Simulation,
                        &mut self.actions,
                        &mut self.filtered,
                    );
                }
            }
            known = false;
            // the recording needs the state's admitted removals: with lazy filters it filters
            // them on its own (the filters' verdicts depend on the step only, so the search
            // draws the same removals either way)
            let recording = self.record.as_mut().is_some_and(|r| r.pending.is_some() || r.active());
            let mut admitted = Vec::new();
            if recording && !filtered {
                let rec = self.record.as_mut().expect("recording");
                self.problem.feasible_actions(&mut self.sim, &self.memory, StepKind::Simulation, &mut admitted, &mut rec.counts);
            }
            if let Some(rec) = &mut self.record {
                rec.finish(if filtered { &self.actions } else { &admitted });
            }
            let mut chosen = None;
            while !self.actions.is_empty() {
                let k = {
                    let mut ctx = PolicyContext { state: &mut self.sim, memory: &self.memory, problem: self.problem };
                    policy.choose(&mut ctx, &self.actions, &mut self.rng)?
                };
                let Some(&p) = self.actions.get(k) else {
                    return Err(SearchError::plugin(
                        "rollout policy",
                        format!("chose action {k} of {}", self.actions.len()),
                    ));
                };
                if filtered
                    || self.problem.admits(&mut self.sim, &self.memory, p, StepKind::Simulation, &mut self.filtered)
                {
                    chosen = Some(p);
                    break;
                }
                self.actions.remove(k);
            }
            let Some(p) = chosen else { break };
            if let Some(rec) = &mut self.record {
                if rec.active() {
                    rec.begin(StepKind::Simulation, self.sim.present(), &self.memory, if filtered { &self.actions } else { &admitted }, p);
                }
            }
            self.problem.step(&mut self.sim, &mut self.memory, p, StepKind::Simulation, &mut rewards[..m]);
            if let Some(rec) = &mut self.record {
                rec.taken(&rewards[..m], &self.memory, self.sim.is_complete());
            }
            for k in 0..m {
                ret[k] += rewards[k];
            }
            self.sequence.push(p as u16);
            self.stats.rollout_steps += 1;
        }
        let complete = self.sim.is_complete();
        if complete {
            self.bounds.update(&ret[..m]);
            let seq = &self.sequence;
            if let Some(p) = &mut self.polisher {
                p.seed(&ret[..m], seq);
            }
            if self.archive.insert(&ret[..m], || seq.clone()) {
                self.archive_changed = true;
                let seconds = self.start.elapsed().as_secs_f64();
                self.found.push((ret[..m].to_vec(), seconds, self.episode_iterations + 1));
            }
        } else {
            self.stats.dead_rollouts += 1;
        }

        // Backpropagation along the path: visits everywhere, suffix values until a node adds
        // nothing (without transpositions) or everywhere (with them).
        let mut propagate = complete;
        let mut suffix = [0.0f64; MAX_OBJECTIVES];
        for i in (0..self.path.len()).rev() {
            let node = self.path[i] as usize;
            self.tree.nodes[node].visits += 1;
            if i > 0 {
                self.tree.edges[self.path_edges[i - 1] as usize].visits += 1;
            }
            if propagate {
                for k in 0..m {
                    suffix[k] = ret[k] - self.path_prefix[i * m + k];
                }
                let added = V::record(&mut self.tree.values[node], &suffix[..m]);
                if !added && !self.settings.transpositions {
                    propagate = false;
                }
            }
        }
        let leaf = *self.path.last().expect("path");
        if new_child && self.tree.nodes[leaf as usize].status != Status::Open
            || self.tree.nodes[parent as usize].untried_left == 0
        {
            self.refresh_path_status();
        }
        self.truncate(base);
        Ok(())
    }

    /// Recomputes the status of the path's nodes from their children, from the end up, while
    /// they change.
    fn refresh_path_status(&mut self) {
        for i in (0..self.path.len()).rev() {
            let node = self.path[i];
            let nd = &self.tree.nodes[node as usize];
            if nd.first_edge == NONE {
                continue; // a leaf: its status is its own
            }
            if nd.untried_left != 0 {
                return; // open, and so are its ancestors
            }
            let (mut open, mut solved) = (false, false);
            for e in self.tree.edges_of(node) {
                match self.tree.nodes[self.tree.edges[e as usize].child as usize].status {
                    Status::Open => open = true,
                    Status::Solved => solved = true,
                    Status::Dead => {}
                }
            }
            let status = if open {
                Status::Open
            } else if solved {
                Status::Solved
            } else {
                Status::Dead
            };
            if status == self.tree.nodes[node as usize].status {
                return;
            }
            self.tree.nodes[node as usize].status = status;
        }
    }

    /// Publishes the archive to the shared front and the trace.
    fn sync(&mut self, shared: &Mutex<Shared>, reference: &[f64], start: Instant, iterations: u64, episode: bool) {
        let mut s = shared.lock().unwrap_or_else(|e| e.into_inner());
        // the improvements inside the episode first, each as it was found
        for (point, seconds, at) in std::mem::take(&mut self.found) {
            if !s.front.insert(&point, || ()) {
                continue;
            }
            let value = front_value(&s.front, reference);
            if s.last_value != Some(value) && !s.front.is_empty() && at < iterations {
                s.last_value = Some(value);
                let point = TracePoint {
                    episode: s.episodes + 1,
                    iterations: s.iterations + at,
                    seconds,
                    value,
                    front_size: s.front.len(),
                };
                s.trace.push(point);
            }
        }
        if episode {
            s.episodes += 1;
        }
        s.iterations += iterations;
        if self.archive_changed {
            for (p, _) in self.archive.iter() {
                s.front.insert(p, || ());
            }
            self.archive_changed = false;
        }
        let value = front_value(&s.front, reference);
        if s.last_value != Some(value) && !s.front.is_empty() {
            s.last_value = Some(value);
            let point = TracePoint {
                episode: s.episodes,
                iterations: s.iterations,
                seconds: start.elapsed().as_secs_f64(),
                value,
                front_size: s.front.len(),
            };
            s.trace.push(point);
        }
    }

    /// Runs `episodes` episodes (or until the time limit, a stop or the root is finished) with
    /// the settings' policy. With a `hook` (the stepped search) the hook is asked before every
    /// episode after the first, with what the previous one did, whether to go on, swap the
    /// policy or stop, and once more when the search ends.
    fn run(&mut self, episodes: usize, shared: &Mutex<Shared>, reference: &[f64], start: Instant, mut hook: Option<&mut EpisodeHook<'_>>) {
        let mut current = self.settings.policy.clone();
        let mut policy = match current.for_worker(self.thread) {
            Ok(p) => p,
            Err(e) => return self.fail(e),
        };
        if let Err(e) = self.adopt(&mut *policy) {
            return self.fail(e);
        }
        let mut last = (self.stats.iterations, start.elapsed());
        for k in 0..episodes {
            if self.stopped || self.root_finished() {
                break;
            }
            if self.settings.stop.as_ref().is_some_and(StopToken::is_stopped) || self.abort.is_stopped() {
                self.stopped = true;
                break;
            }
            if let (Some(h), true) = (hook.as_deref_mut(), k > 0) {
                let report = self.report(shared, start, &mut last, false);
                match h(report) {
                    Ok(Next::Continue) => {}
                    Ok(Next::Stop) => break,
                    Ok(Next::Policy(p)) => {
                        drop(policy);
                        current = p;
                        policy = match current.for_worker(self.thread) {
                            Ok(p) => p,
                            Err(e) => return self.fail(e),
                        };
                        if let Err(e) = self.adopt(&mut *policy) {
                            return self.fail(e);
                        }
                    }
                    Err(e) => return self.fail(e),
                }
            }
            let before = self.stats.iterations;
            self.episode(&mut *policy);
            if let Some(rec) = &mut self.record {
                rec.episode += 1;
            }
            if !self.stopped {
                self.stats.episodes += 1;
                self.polish(false);
            }
            self.sync(shared, reference, start, self.stats.iterations - before, true);
        }
        if self.error.is_none() && !self.should_stop() && self.polish(true) {
            self.sync(shared, reference, start, 0, false);
        }
        if let Some(h) = hook {
            let report = self.report(shared, start, &mut last, true);
            if let Err(e) = h(report) {
                return self.fail(e);
            }
        }
        self.finish();
    }

    /// Local search around the archive's sequences not searched yet ([`crate::polish`]), while
    /// its work stays within its share of the tree search's (`last`: up to as much work as the
    /// tree search, when the episodes are done). Returns whether it added anything.
    fn polish(&mut self, last: bool) -> bool {
        let Some(mut polisher) = self.polisher.take() else { return false };
        // its work in both of the search's currencies: map steps, and checks by the problem's
        // feasibility filters (a robot's plans a path; they cost far more than a step)
        let share = if last { self.settings.polish.max(1.0) } else { self.settings.polish };
        let cap = (self.stats.iterations + self.stats.rollout_steps) as f64 * share;
        let check_cap = self.filtered.checks() as f64 * share;
        let filters = !self.problem.filters().is_empty();
        let over_checks = move |checks: u64| filters && checks as f64 >= check_cap;
        let over = move |steps: u64, checks: u64| steps as f64 >= cap || over_checks(checks);
        let (deadline, stop, abort) = (self.deadline, self.settings.stop.as_ref(), self.abort);
        let should_stop = || {
            deadline.is_some_and(|d| Instant::now() >= d) || stop.is_some_and(StopToken::is_stopped) || abort.is_stopped()
        };
        let mut added = 0u64;
        while !over(polisher.steps, polisher.checks()) {
            let Some((seq, seed, from)) = polisher.queue.pop() else { break };
            if !seed && !self.archive.iter().any(|(_, s)| *s == seq) {
                continue; // dominated since the local search found it
            }
            let (found, start) = (&mut self.found, self.start);
            let ended = polisher.search_around(
                &seq,
                from,
                &mut self.archive,
                |values| {
                    added += 1;
                    found.push((values.to_vec(), start.elapsed().as_secs_f64(), u64::MAX));
                },
                // map steps are cheap: a search around a sequence may finish past their limit
                // (it stays deterministic); filter checks may not be
                |_, checks| over_checks(checks) || should_stop(),
            );
            if let Ended::Stopped(at) = ended {
                polisher.queue.push((seq, seed, at));
                break;
            }
        }
        self.stats.polish_steps = polisher.steps;
        self.stats.polished += added;
        self.archive_changed |= added > 0;
        self.polisher = Some(polisher);
        added > 0
    }

    /// Ends the run with a plug-in's (or the hook's) error.
    fn fail(&mut self, e: SearchError) {
        self.error = Some(e);
        self.stopped = true;
        self.finish();
    }

    /// What the episode just run did, for the stepped search's hook: its transitions (taken out
    /// of the recording, whose limit is then per episode), and the front so far.
    fn report(&mut self, shared: &Mutex<Shared>, start: Instant, last: &mut (u64, Duration), last_call: bool) -> EpisodeEnd {
        let (transitions, transitions_capped) = match &mut self.record {
            Some(rec) => {
                let capped = std::mem::replace(&mut rec.capped, false);
                (std::mem::take(&mut rec.transitions), capped)
            }
            None => (Vec::new(), false),
        };
        let s = shared.lock().unwrap_or_else(|e| e.into_inner());
        let now = start.elapsed();
        let report = EpisodeEnd {
            episodes: self.stats.episodes,
            iterations: self.stats.iterations - last.0,
            seconds: (now - last.1).as_secs_f64(),
            value: if s.front.is_empty() { 0.0 } else { s.last_value.unwrap_or(0.0) },
            front_size: s.front.len(),
            transitions,
            transitions_capped,
            finished: last_call,
            exhausted: self.root_finished(),
            stopped: self.stopped,
        };
        *last = (self.stats.iterations, now);
        report
    }

    /// The statistics and the graph's answers at the end of a run.
    fn finish(&mut self) {
        if let Some(p) = &self.polisher {
            self.filtered.add(p.counts());
        }
        self.stats.tree_nodes = self.tree.nodes.len() as u64;
        self.stats.exhausted = self.root_finished();
        let c = self.sim.counters();
        self.stats.removal_tests = c.blocked + c.gravity_tests;
        self.stats.failed_collision = c.blocked;
        self.stats.failed_gravity = c.unsupported;
        self.stats.stopped = self.stopped && self.error.is_none();
        if self.error.is_some() {
            self.abort.stop();
        } else if self.settings.transpositions {
            self.read_graph();
        }
    }

    /// Adds to the archive the non-dominated complete sequences that lie wholly in the graph:
    /// with transpositions the best suffix of a state may have been found after reaching it on
    /// another path, so the archive alone can miss combinations. Dynamic programming over the
    /// graph's complete paths (exact when the root is finished).
    fn read_graph(&mut self) {
        let m = self.m;
        let count = self.tree.nodes.len();
        // fronts[node]: suffix vectors of complete paths in the graph, with (edge, child point)
        let mut fronts: Vec<Option<ParetoFront<(u32, u32)>>> = vec![None; count];
        // post-order without recursion
        let mut stack: Vec<(u32, bool)> = vec![(0, false)];
        let mut point = vec![0.0f64; m];
        while let Some((node, expanded)) = stack.pop() {
            if fronts[node as usize].is_some() {
                continue;
            }
            if !expanded {
                stack.push((node, true));
                for e in self.tree.edges_of(node) {
                    let child = self.tree.edges[e as usize].child;
                    if fronts[child as usize].is_none() {
                        stack.push((child, false));
                    }
                }
                continue;
            }
            let mut front = ParetoFront::new(m);
            let nd = &self.tree.nodes[node as usize];
            if nd.first_edge == NONE && nd.status == Status::Solved {
                front.insert(&vec![0.0; m], || (NONE, NONE));
            }
            for e in self.tree.edges_of(node) {
                let child = self.tree.edges[e as usize].child as usize;
                let Some(cf) = &fronts[child] else { continue };
                for (k, (p, _)) in cf.iter().enumerate() {
                    for j in 0..m {
                        point[j] = self.tree.rewards[e as usize * m + j] + p[j];
                    }
                    front.insert(&point, || (e, k as u32));
                }
            }
            fronts[node as usize] = Some(front);
        }
        let Some(root) = &fronts[0] else { return };
        for (k, (p, _)) in root.iter().enumerate() {
            if self.archive.covers(p) {
                continue;
            }
            let mut seq = Vec::with_capacity(self.n);
            let (mut node, mut at) = (0usize, k);
            loop {
                let &(e, next) = fronts[node].as_ref().expect("computed").payload(at);
                if e == NONE {
                    break;
                }
                seq.push(self.tree.edges[e as usize].action);
                node = self.tree.edges[e as usize].child as usize;
                at = next as usize;
            }
            self.archive.insert(p, || seq);
        }
    }
}

/// The hypervolume of `front` (several objectives) or its best value (one objective).
fn front_value<P>(front: &ParetoFront<P>, reference: &[f64]) -> f64 {
    if front.dim() == 1 {
        front.iter().map(|(p, _)| p[0]).fold(f64::NEG_INFINITY, f64::max)
    } else {
        front.hypervolume(reference)
    }
}

/// What one worker hands back: its archive, statistics, filter counts, root status and
/// recording.
type WorkerResult = Result<(ParetoFront<Vec<u16>>, SearchStats, FilterCounts, Status, Option<Recorder>)>;

/// Thread `t`'s share of `total` episodes (or transitions) over `threads` threads.
fn share_of(total: usize, threads: usize, t: usize) -> usize {
    total / threads + usize::from(t < total % threads)
}

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
            return Err(SearchError::config(format!(
                "the reference point has {} coordinates, the problem {m} objectives",
                r.len()
            )))
        }
        Some(r) => r.clone(),
        None => problem.reference_point(),
    };
    if problem.maps().num_parts() > u16::MAX as usize {
        return Err(SearchError::config("too many parts"));
    }
    let start = Instant::now();
    let shared = Mutex::new(Shared {
        front: ParetoFront::new(m),
        episodes: 0,
        iterations: 0,
        trace: Vec::new(),
        last_value: None,
    });
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
        dead &= *status == Status::Dead;
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
    let status = if !solutions.is_empty() {
        SearchStatus::Found
    } else if dead {
        SearchStatus::NoPlan
    } else {
        SearchStatus::BudgetExhausted
    };
    Ok(SearchOutcome {
        status,
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
