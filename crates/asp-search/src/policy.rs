//! Rollout and expansion policies: which feasible removal a simulation takes next (thesis 5.4.2,
//! "Simulation"), which untried removal an expansion adds, and optional priors for the tree
//! policy.
//!
//! A [`Policy`] is the shareable description a search is configured with; every search thread
//! asks it for its own [`PolicyWorker`] ([`Policy::for_worker`]), which owns whatever scratch it
//! needs (feature buffers, an inference session) and is never shared between threads. The same
//! holds for [`QFunction`]s and their [`QWorker`]s, which give the Q-values of every feasible
//! action of a state in one call.
//!
//! The vanilla search uses [`RandomPolicy`]; [`EpsilonGreedy`] is the guided policy of 5.4.5 /
//! 6.4.4 over any [`QFunction`]s (the product of their values for several objectives).
//!
//! A policy that returns an index outside the actions offered, or fails, stops the search with
//! a [`SearchError::Plugin`] error; it never panics a worker thread.

use crate::error::{Result, SearchError};
use crate::mdp::Mdp;
use crate::qcache::{QCache, DEFAULT_QCACHE_BYTES};
use crate::step::{StepContext, StepKind};
use asp_geom::distmap::{DistanceMaps, MapState};
use asp_geom::PartSet;
use rand::{RngExt, SeedableRng};
use std::fmt::Debug;
use std::sync::Arc;

/// The random number generator of every search (seeded, reproducible).
pub type SearchRng = rand_chacha::ChaCha8Rng;

/// A generator seeded from `seed` and a stream number (e.g. a thread index), so that
/// independent streams never share state.
pub fn rng_for(seed: u64, stream: u64) -> SearchRng {
    let mut r = SearchRng::seed_from_u64(seed);
    r.set_stream(stream);
    r
}

/// What a policy or Q-function may look at: the state (distance maps, present parts, lazily
/// computed minimum maps and free directions), the objectives' memories (e.g. the direction
/// history `H`), and the problem (objectives, maps, the assembly). Everything a learned
/// Q-function needs to build its state graph (thesis 5.4.3, 6.4.3) is reachable from here
/// without copying maps: part boxes and centres ([`DistanceMaps::part_aabb`]), distance maps
/// ([`DistanceMaps::map`], [`DistanceMaps::blocked`]), minimum maps ([`MapState::min_map`],
/// [`MapState::free_mask`]) and the history ([`PolicyContext::memory`]).
#[derive(Debug)]
pub struct PolicyContext<'a, 'm> {
    /// The current state.
    pub state: &'a mut MapState<'m>,
    /// Every objective's memory words ([`Mdp::memory_range`]).
    pub memory: &'a [u64],
    /// The problem (objectives, maps).
    pub problem: &'a Mdp,
}

impl<'m> PolicyContext<'_, 'm> {
    /// The distance maps.
    #[inline]
    pub fn maps(&self) -> &'m DistanceMaps {
        self.state.maps()
    }

    /// The parts present.
    pub fn present(&self) -> PartSet {
        self.state.present()
    }

    /// Objective `k`'s memory words.
    #[inline]
    pub fn memory(&self, k: usize) -> &[u64] {
        &self.memory[self.problem.memory_range(k)]
    }
}

/// A rollout and expansion policy as a search is configured with it, shared by its threads.
pub trait Policy: Send + Sync + Debug {
    /// The instance search thread `thread` uses (called on that thread, before its first
    /// episode).
    fn for_worker(&self, thread: usize) -> Result<Box<dyn PolicyWorker + '_>>;
}

/// One search thread's policy: owns its scratch, used from that thread only.
pub trait PolicyWorker {
    /// The index into `actions` (the feasible removals of `ctx`'s state, never empty, in
    /// increasing part order) of the part a rollout removes next. Must draw every random choice
    /// from `rng`.
    fn choose(&mut self, ctx: &mut PolicyContext<'_, '_>, actions: &[usize], rng: &mut SearchRng) -> Result<usize>;

    /// The index into `untried` (the removals of `ctx`'s state not yet in the search graph,
    /// never empty, increasing part order) that an expansion adds. `priors` holds this policy's
    /// priors of the untried removals when it gives priors ([`PolicyWorker::has_priors`]).
    /// Default: the largest prior (the first of equals), or a uniformly random one without
    /// priors (thesis 5.4.2).
    fn expand(
        &mut self,
        _ctx: &mut PolicyContext<'_, '_>,
        untried: &[usize],
        priors: Option<&[f64]>,
        rng: &mut SearchRng,
    ) -> Result<usize> {
        Ok(match priors {
            Some(p) => argmax(p),
            None => rng.random_range(0..untried.len()),
        })
    }

    /// Whether this policy gives priors ([`PolicyWorker::priors`]); asked once per search
    /// thread. Default false.
    fn has_priors(&self) -> bool {
        false
    }

    /// Priors (non-negative, e.g. a softmax of Q-values) of the feasible `actions` of a state
    /// the search adds to its graph, written to `out` (as long as `actions`). They order
    /// expansions and, with [`crate::mcts::SearchBuilder::prior_weight`], add a PUCT bonus
    /// `w · P(a) · √N(s) / (1 + N(s, a))` to the tree policy.
    fn priors(&mut self, _ctx: &mut PolicyContext<'_, '_>, _actions: &[usize], out: &mut [f64]) -> Result<()> {
        out.fill(0.0);
        Ok(())
    }

    /// The PUCT weight this policy's priors are meant for, used when the search's own
    /// ([`crate::mcts::SearchBuilder::prior_weight`]) is 0. Default `None` (priors only order
    /// expansions).
    fn prior_weight(&self) -> Option<f64> {
        None
    }

    /// The index into `actions` (the feasible removals of `ctx`'s state, never empty) of the
    /// removal this policy ranks first by its ranking `which` (`0..`[`greedy_rankings`](Self::greedy_rankings)),
    /// without randomness, or `None` when it ranks none (default). A search whose policy ranks
    /// asks it, before its first episode, for one greedy sequence per ranking from the assembled
    /// state, offers each to its archive and gives it to its local search (`--polish`) as a seed.
    fn greedy(&mut self, _ctx: &mut PolicyContext<'_, '_>, _actions: &[usize], _which: usize) -> Result<Option<usize>> {
        Ok(None)
    }

    /// How many rankings [`greedy`](Self::greedy) has (default 1).
    fn greedy_rankings(&self) -> usize {
        1
    }
}

/// The index of the largest value (the first of equals; 0 for an empty or all-NaN slice).
pub fn argmax(values: &[f64]) -> usize {
    let mut best = (f64::NEG_INFINITY, 0);
    for (k, &v) in values.iter().enumerate() {
        if v > best.0 {
            best = (v, k);
        }
    }
    best.1
}

/// The default policy: a uniformly random feasible removal.
#[derive(Clone, Copy, Debug, Default)]
pub struct RandomPolicy;

impl Policy for RandomPolicy {
    fn for_worker(&self, _thread: usize) -> Result<Box<dyn PolicyWorker + '_>> {
        Ok(Box::new(RandomPolicy))
    }
}

impl PolicyWorker for RandomPolicy {
    #[inline]
    fn choose(&mut self, _: &mut PolicyContext<'_, '_>, actions: &[usize], rng: &mut SearchRng) -> Result<usize> {
        Ok(rng.random_range(0..actions.len()))
    }
}

/// An estimate of the return of each removal in a state (a learned Q-function, or a
/// heuristic), shared by a search's threads. For products over several objectives values
/// should be positive.
pub trait QFunction: Send + Sync + Debug {
    /// `Q(s, a)` for every `a` in `actions` (the feasible removals of `ctx`'s state), written
    /// to `out` (as long as `actions`), in one call.
    fn q_values(&self, ctx: &mut PolicyContext<'_, '_>, actions: &[usize], out: &mut [f64]) -> Result<()>;

    /// The evaluator search thread `thread` uses. Default: this function itself; override it to
    /// give each thread its own scratch (an inference session, feature buffers).
    fn for_worker(&self, _thread: usize) -> Result<Box<dyn QWorker + '_>> {
        Ok(Box::new(Shared(self)))
    }
}

/// One search thread's Q-function evaluator.
pub trait QWorker {
    /// `Q(s, a)` for every `a` in `actions`, written to `out`.
    fn q_values(&mut self, ctx: &mut PolicyContext<'_, '_>, actions: &[usize], out: &mut [f64]) -> Result<()>;
}

/// A shared Q-function used as a thread's evaluator.
struct Shared<'q, Q: ?Sized>(&'q Q);

impl<Q: QFunction + ?Sized> QWorker for Shared<'_, Q> {
    fn q_values(&mut self, ctx: &mut PolicyContext<'_, '_>, actions: &[usize], out: &mut [f64]) -> Result<()> {
        self.0.q_values(ctx, actions, out)
    }
}

/// Where a guided search spends its Q-function evaluations.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum QUse {
    /// ε-greedy rollouts (thesis 5.4.5 / 6.4.4): one evaluation per rollout step; expansions
    /// stay uniformly random.
    #[default]
    Rollouts,
    /// Expansions only: the Q-values of a state, evaluated once when the search adds it to its
    /// graph, become its priors (normalised), and an expansion adds the untried removal with the
    /// largest prior (a random one with probability ε); rollouts stay uniformly random. One
    /// evaluation per node instead of one per rollout step.
    Expansions,
    /// Both: ε-greedy rollouts and Q-ordered expansions.
    Both,
    /// PUCT priors: the Q-values of each state the search adds (normalised) order its
    /// expansions and add the bonus `w · P(a) · √N(s) / (1 + N(s, a))` to the tree policy, with
    /// `w` = [`DEFAULT_PRIOR_WEIGHT`] unless the search sets one; rollouts stay random, and a
    /// greedy sequence on the Q-values seeds the local search. One evaluation per node.
    Priors,
    /// Seeds only: before the first episode, greedy sequences on the Q-values (on their
    /// product and, with several objectives, on each objective's own) go to the archive and
    /// seed the local search; the search itself stays vanilla (random expansions and
    /// rollouts). Evaluations: one per step of each seed sequence, then none.
    Seed,
}

/// The PUCT weight of [`QUse::Priors`] (the scale of UCT's exploration term for a
/// unit prior at a node's first visits).
pub const DEFAULT_PRIOR_WEIGHT: f64 = 1.0;

impl QUse {
    /// The names, as the command line and Python take them.
    pub const NAMES: [&'static str; 5] = ["rollouts", "expansions", "both", "priors", "seed"];

    fn rollouts(self) -> bool {
        matches!(self, QUse::Rollouts | QUse::Both)
    }

    fn expansions(self) -> bool {
        matches!(self, QUse::Expansions | QUse::Both | QUse::Priors)
    }

    /// The name ([`QUse::NAMES`]).
    pub fn name(self) -> &'static str {
        Self::NAMES[self as usize]
    }
}

impl std::str::FromStr for QUse {
    type Err = SearchError;

    fn from_str(s: &str) -> Result<Self> {
        match s {
            "rollouts" => Ok(QUse::Rollouts),
            "expansions" => Ok(QUse::Expansions),
            "both" => Ok(QUse::Both),
            "priors" => Ok(QUse::Priors),
            "seed" => Ok(QUse::Seed),
            other => Err(SearchError::config(format!("unknown Q use '{other}' (rollouts, expansions, both, priors or seed)"))),
        }
    }
}

/// The ε-greedy policy of 5.4.5 / 6.4.4: with probability ε a random removal, otherwise the
/// removal with the largest product of Q-values (ties: the first) — in rollouts, in
/// expansions (as priors), or both ([`QUse`]).
#[derive(Clone, Debug)]
pub struct EpsilonGreedy {
    epsilon: f64,
    q_functions: Vec<Arc<dyn QFunction>>,
    uses: QUse,
    cache_bytes: usize,
}

impl EpsilonGreedy {
    /// ε-greedy over `q_functions` (at least one); ε in `[0, 1]` (the thesis uses 0.2).
    pub fn new(epsilon: f64, q_functions: Vec<Arc<dyn QFunction>>) -> Result<Self> {
        if !(0.0..=1.0).contains(&epsilon) {
            return Err(SearchError::config(format!("epsilon must be in [0, 1], got {epsilon}")));
        }
        if q_functions.is_empty() {
            return Err(SearchError::config("the epsilon-greedy policy needs a Q-function"));
        }
        Ok(EpsilonGreedy { epsilon, q_functions, uses: QUse::Rollouts, cache_bytes: DEFAULT_QCACHE_BYTES })
    }

    /// The same policy keeping at most about `bytes` of Q-values by state per search thread
    /// ([`QCache`]; default [`DEFAULT_QCACHE_BYTES`], 0: none). The cache changes no value, only
    /// how often the Q-functions run.
    pub fn cache_bytes(mut self, bytes: usize) -> Self {
        self.cache_bytes = bytes;
        self
    }

    /// The same policy spending its Q evaluations where `uses` says (default: rollouts).
    pub fn using(mut self, uses: QUse) -> Self {
        self.uses = uses;
        self
    }

    /// ε.
    pub fn epsilon(&self) -> f64 {
        self.epsilon
    }

    /// Where the Q-functions are evaluated.
    pub fn uses(&self) -> QUse {
        self.uses
    }
}

impl Policy for EpsilonGreedy {
    fn for_worker(&self, thread: usize) -> Result<Box<dyn PolicyWorker + '_>> {
        let q = self.q_functions.iter().map(|q| q.for_worker(thread)).collect::<Result<Vec<_>>>()?;
        Ok(Box::new(EpsilonGreedyWorker {
            epsilon: self.epsilon,
            uses: self.uses,
            q,
            values: Vec::new(),
            product: Vec::new(),
            cache: None,
            cache_bytes: self.cache_bytes,
        }))
    }
}

/// A thread's [`EpsilonGreedy`].
struct EpsilonGreedyWorker<'q> {
    epsilon: f64,
    uses: QUse,
    q: Vec<Box<dyn QWorker + 'q>>,
    values: Vec<f64>,
    product: Vec<f64>,
    /// Products by state, made for the problem of the first call.
    cache: Option<QCache>,
    cache_bytes: usize,
}

impl EpsilonGreedyWorker<'_> {
    /// The product of the Q-values of `actions` in `self.product` (kept by state, so a state met
    /// again costs a lookup).
    fn evaluate(&mut self, ctx: &mut PolicyContext<'_, '_>, actions: &[usize]) -> Result<()> {
        let n = actions.len();
        self.product.clear();
        self.product.resize(n, 1.0);
        let cache = self.cache.get_or_insert_with(|| QCache::new(ctx.maps().num_parts(), self.cache_bytes));
        let key = QCache::key(ctx.problem, &ctx.present(), ctx.memory, actions);
        if cache.get(&key, &mut self.product) {
            return Ok(());
        }
        self.values.resize(n, 0.0);
        for q in &mut self.q {
            q.q_values(ctx, actions, &mut self.values[..n])?;
            for (p, v) in self.product.iter_mut().zip(&self.values) {
                *p *= v;
            }
        }
        cache.put(&key, &self.product);
        Ok(())
    }
}

impl PolicyWorker for EpsilonGreedyWorker<'_> {
    fn choose(&mut self, ctx: &mut PolicyContext<'_, '_>, actions: &[usize], rng: &mut SearchRng) -> Result<usize> {
        if !self.uses.rollouts() || rng.random::<f64>() <= self.epsilon {
            return Ok(rng.random_range(0..actions.len()));
        }
        self.evaluate(ctx, actions)?;
        Ok(argmax(&self.product))
    }

    fn expand(
        &mut self,
        _ctx: &mut PolicyContext<'_, '_>,
        untried: &[usize],
        priors: Option<&[f64]>,
        rng: &mut SearchRng,
    ) -> Result<usize> {
        Ok(match priors {
            Some(p) if rng.random::<f64>() > self.epsilon => argmax(p),
            _ => rng.random_range(0..untried.len()),
        })
    }

    fn has_priors(&self) -> bool {
        self.uses.expansions()
    }

    fn prior_weight(&self) -> Option<f64> {
        (self.uses == QUse::Priors).then_some(DEFAULT_PRIOR_WEIGHT)
    }

    fn greedy(&mut self, ctx: &mut PolicyContext<'_, '_>, actions: &[usize], which: usize) -> Result<Option<usize>> {
        if !matches!(self.uses, QUse::Priors | QUse::Seed) {
            return Ok(None);
        }
        if which == 0 {
            self.evaluate(ctx, actions)?;
            return Ok(Some(argmax(&self.product)));
        }
        // ranking k > 0: objective k - 1's Q alone
        let Some(q) = self.q.get_mut(which - 1) else { return Ok(None) };
        self.values.resize(actions.len(), 0.0);
        q.q_values(ctx, actions, &mut self.values[..actions.len()])?;
        Ok(Some(argmax(&self.values[..actions.len()])))
    }

    /// Priors: the product's ranking. Seed: the product's and, with several objectives, each
    /// objective's own (the ends of a front the product's sequence lies between).
    fn greedy_rankings(&self) -> usize {
        if self.uses == QUse::Seed && self.q.len() > 1 {
            1 + self.q.len()
        } else {
            1
        }
    }

    /// The Q-value products, normalised to sum 1 (uniform when they are all 0 or not finite).
    fn priors(&mut self, ctx: &mut PolicyContext<'_, '_>, actions: &[usize], out: &mut [f64]) -> Result<()> {
        if actions.is_empty() {
            return Ok(());
        }
        self.evaluate(ctx, actions)?;
        let total: f64 = self.product.iter().filter(|v| v.is_finite() && **v > 0.0).sum();
        for (o, &v) in out.iter_mut().zip(&self.product) {
            *o = if total > 0.0 && v.is_finite() && v > 0.0 {
                v / total
            } else if total > 0.0 {
                0.0
            } else {
                1.0 / actions.len() as f64
            };
        }
        Ok(())
    }
}

/// A myopic Q-function: the immediate reward of one objective (a one-step look-ahead, on a
/// copy of the memory). Useful as a baseline guide and to test guided rollouts.
#[derive(Clone, Copy, Debug)]
pub struct ImmediateReward {
    /// The objective's index in the problem.
    pub objective: usize,
}

impl QFunction for ImmediateReward {
    fn q_values(&self, ctx: &mut PolicyContext<'_, '_>, actions: &[usize], out: &mut [f64]) -> Result<()> {
        let objective = &ctx.problem.objectives()[self.objective];
        let mut memory = ctx.memory(self.objective).to_vec();
        let original = memory.clone();
        for (o, &a) in out.iter_mut().zip(actions) {
            memory.copy_from_slice(&original);
            let mut step = StepContext::new(ctx.problem, ctx.state, a, StepKind::Simulation);
            *o = objective.reward(&mut step, &mut memory);
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn argmax_takes_the_first_of_equals() {
        assert_eq!(argmax(&[1.0, 3.0, 3.0, 2.0]), 1);
        assert_eq!(argmax(&[]), 0);
        assert_eq!(argmax(&[f64::NAN, 0.5]), 1);
    }
}
