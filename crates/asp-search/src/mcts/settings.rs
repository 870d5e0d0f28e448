//! The settings of a tree search, their validating builder and the `search_type!` macro that
//! declares [`crate::Mcts`] and [`crate::ParetoMcts`] around them.

use crate::error::{Result, SearchError};
use crate::policy::{Policy, RandomPolicy};
use crate::problem::StopToken;
use std::marker::PhantomData;
use std::sync::Arc;
use std::time::Duration;

/// Default iterations per search step (the thesis' search budget of 5, 5.5 and 6.5).
pub const DEFAULT_BUDGET: usize = 5;
/// Default number of episodes (the thesis ran for a fixed time instead).
pub const DEFAULT_EPISODES: usize = 1000;
/// Default exploration constant `c` of UCT / MOUCB (the thesis does not state it): `1/√2`,
/// Kocsis and Szepesvári's choice for rewards in `[0, 1]`.
pub const DEFAULT_EXPLORATION: f64 = std::f64::consts::FRAC_1_SQRT_2;
/// Default cap on tree nodes per thread; beyond it iterations roll out without expanding.
pub const DEFAULT_MAX_NODES: usize = 1_000_000;
/// Default share of a search's work its local search may take ([`SearchBuilder::polish`](crate::mcts::SearchBuilder::polish)).
pub const DEFAULT_POLISH: f64 = 0.25;
/// Default cap on recorded transitions ([`SearchBuilder::record_transitions_limit`](crate::mcts::SearchBuilder::record_transitions_limit)).
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
    /// Whether rollouts ask the problem's filters lazily ([`SearchBuilder::lazy_filters`](crate::mcts::SearchBuilder::lazy_filters)).
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
    /// priors ([`PolicyWorker::priors`](crate::PolicyWorker::priors)) add to the tree policy's score (default 0: priors only
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
    /// [`Transition`](crate::Transition) in [`SearchOutcome::transitions`](crate::SearchOutcome::transitions) (default false). The search's answers
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
    /// ([`SearchOutcome::transitions_capped`](crate::SearchOutcome::transitions_capped)).
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
            return Err(SearchError::config(format!("the exploration constant must be finite and >= 0, got {}", s.exploration)));
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
            return Err(SearchError::config(format!("the prior weight must be finite and >= 0, got {}", s.prior_weight)));
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

/// Declares a search type that a [`SearchBuilder`](crate::mcts::SearchBuilder) builds: the struct holding its
/// [`SearchSettings`], the builder's alias, `builder()` and `settings()`. Each variant adds its
/// own `solve`.
macro_rules! search_type {
    ($(#[$attr:meta])* $name:ident, $builder:ident) => {
        $(#[$attr])*
        #[derive(Clone, Debug)]
        pub struct $name {
            settings: $crate::mcts::SearchSettings,
        }

        #[doc = concat!("The builder of [`", stringify!($name), "`].")]
        pub type $builder = $crate::mcts::SearchBuilder<$name>;

        impl From<$crate::mcts::SearchSettings> for $name {
            fn from(settings: $crate::mcts::SearchSettings) -> Self {
                $name { settings }
            }
        }

        impl $name {
            /// A builder with the defaults (budget 5, 1000 episodes, 1 thread, seed 0, c = 1/√2).
            pub fn builder() -> $builder {
                $crate::mcts::SearchBuilder::default()
            }

            /// The settings.
            pub fn settings(&self) -> &$crate::mcts::SearchSettings {
                &self.settings
            }
        }
    };
}
pub(crate) use search_type;
