//! Rollout (default) policies: which feasible removal a simulation takes next (thesis 5.4.2,
//! "Simulation"). The vanilla search uses [`RandomPolicy`]; [`EpsilonGreedy`] is the guided
//! policy of 5.4.5 / 6.4.4 over any [`QFunction`]s (the product of their values for several
//! objectives), so a learned Q-function slots in by implementing that trait.

use crate::objective::Memory;
use crate::mdp::Mdp;
use asp_geom::distmap::MapState;
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

/// What a policy may look at: the state (distance maps, present parts, lazily computed minimum
/// maps), the objectives' memories, and the problem.
#[derive(Debug)]
pub struct PolicyContext<'a, 'm> {
    /// The current state.
    pub state: &'a mut MapState<'m>,
    /// The objectives' memories (e.g. the common directions `H`).
    pub memories: &'a [Memory],
    /// The problem (objectives, maps).
    pub problem: &'a Mdp,
}

/// Chooses one of the feasible `actions` (part indices, never empty) and returns its position
/// in `actions`. Must draw every random choice from `rng`.
pub trait Policy: Send + Sync + Debug {
    /// The index into `actions` of the part to remove next.
    fn choose(&self, ctx: &mut PolicyContext<'_, '_>, actions: &[usize], rng: &mut SearchRng)
        -> usize;
}

/// The default policy: a uniformly random feasible removal.
#[derive(Clone, Copy, Debug, Default)]
pub struct RandomPolicy;

impl Policy for RandomPolicy {
    #[inline]
    fn choose(&self, _: &mut PolicyContext<'_, '_>, actions: &[usize], rng: &mut SearchRng) -> usize {
        rng.random_range(0..actions.len())
    }
}

/// An estimate of the return of removing `action` in the context's state (a learned
/// Q-function, or a heuristic). For products over several objectives values should be
/// positive.
pub trait QFunction: Send + Sync + Debug {
    /// `Q(s, a)`.
    fn q_value(&self, ctx: &mut PolicyContext<'_, '_>, action: usize) -> f64;
}

/// The ε-greedy policy of 5.4.5 / 6.4.4: with probability ε a random removal, otherwise the
/// removal with the largest product of Q-values (ties: the first).
#[derive(Clone, Debug)]
pub struct EpsilonGreedy {
    epsilon: f64,
    q_functions: Vec<Arc<dyn QFunction>>,
}

impl EpsilonGreedy {
    /// ε-greedy over `q_functions` (at least one); ε in `[0, 1]` (the thesis uses 0.2).
    pub fn new(epsilon: f64, q_functions: Vec<Arc<dyn QFunction>>) -> crate::Result<Self> {
        if !(0.0..=1.0).contains(&epsilon) {
            return Err(crate::SearchError::config(format!("epsilon must be in [0, 1], got {epsilon}")));
        }
        if q_functions.is_empty() {
            return Err(crate::SearchError::config("the epsilon-greedy policy needs a Q-function"));
        }
        Ok(EpsilonGreedy { epsilon, q_functions })
    }
}

impl Policy for EpsilonGreedy {
    fn choose(&self, ctx: &mut PolicyContext<'_, '_>, actions: &[usize], rng: &mut SearchRng) -> usize {
        if rng.random::<f64>() <= self.epsilon {
            return rng.random_range(0..actions.len());
        }
        let mut best = (f64::NEG_INFINITY, 0);
        for (k, &a) in actions.iter().enumerate() {
            let v: f64 = self.q_functions.iter().map(|q| q.q_value(ctx, a)).product();
            if v > best.0 {
                best = (v, k);
            }
        }
        best.1
    }
}

/// A myopic Q-function: the immediate reward of one objective (a one-step look-ahead). Useful
/// as a baseline guide and to test guided rollouts.
#[derive(Clone, Copy, Debug)]
pub struct ImmediateReward {
    /// The objective's index in the problem.
    pub objective: usize,
}

impl QFunction for ImmediateReward {
    fn q_value(&self, ctx: &mut PolicyContext<'_, '_>, action: usize) -> f64 {
        let mut memory = ctx.memories[self.objective];
        ctx.problem.objectives()[self.objective].reward(action, ctx.state, &mut memory)
    }
}
