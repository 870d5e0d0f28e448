//! Single-objective MCTS (thesis 5.4.2): UCT on the **maximum** return seen below a node
//! rather than the mean (eq. 5.9), normalised to `[0, 1]` with the minimum and maximum of the
//! siblings' maxima as local bounds, or the global bounds of all returns seen while a node has
//! fewer than two valued children (Vodopivec et al.). Expansion, random rollouts, a search
//! budget per step, episodes and transpositions are shared with [`crate::ParetoMcts`] (see
//! [`crate::mcts`]).
//!
//! ```
//! # use asp_search::Mcts;
//! let mcts = Mcts::builder().budget(5).episodes(200).seed(1).build().unwrap();
//! assert_eq!(mcts.settings().budget(), 5);
//! assert!(Mcts::builder().budget(0).build().is_err());
//! ```

use super::graph::{exploration_term, SelectContext, Tree, Variant};
use super::outcome::{EpisodeHook, SearchOutcome};
use super::run::run;
use super::settings::search_type;
use crate::error::{Result, SearchError};
use crate::mdp::Mdp;

search_type!(
    /// Single-objective Monte Carlo tree search with max-backup UCT.
    Mcts,
    MctsBuilder
);

impl Mcts {
    /// Searches for the sequence with the largest total of the problem's single objective.
    pub fn solve(&self, problem: &Mdp) -> Result<SearchOutcome> {
        self.solve_with(problem, None)
    }

    /// [`Mcts::solve`] episode by episode on one thread: `hook` is told what each episode did
    /// and may swap the policy or stop the search between episodes (see [`EpisodeHook`]). With
    /// a hook that always continues the answer is [`Mcts::solve`]'s with one thread.
    pub fn solve_stepped(&self, problem: &Mdp, hook: &mut EpisodeHook<'_>) -> Result<SearchOutcome> {
        self.solve_with(problem, Some(hook))
    }

    fn solve_with(&self, problem: &Mdp, hook: Option<&mut EpisodeHook<'_>>) -> Result<SearchOutcome> {
        if problem.num_objectives() != 1 {
            return Err(SearchError::config(format!(
                "single-objective MCTS needs exactly one objective, got {}; use Pareto-MCTS",
                problem.num_objectives()
            )));
        }
        run::<MaxBackup>(problem, &self.settings, hook)
    }
}

/// The largest suffix return seen from a node (`-inf` before any).
#[derive(Clone, Copy, Debug)]
pub(crate) struct MaxValue(pub f64);

impl Default for MaxValue {
    fn default() -> Self {
        MaxValue(f64::NEG_INFINITY)
    }
}

pub(crate) struct MaxBackup;

impl Variant for MaxBackup {
    type Value = MaxValue;

    #[inline]
    fn record(value: &mut MaxValue, suffix: &[f64]) -> bool {
        if suffix[0] > value.0 {
            value.0 = suffix[0];
        }
        true
    }

    fn select(tree: &Tree<MaxValue>, node: u32, candidates: &[u32], ctx: &SelectContext<'_>) -> usize {
        // Q of an edge: its reward plus the child's best suffix. Local bounds: the siblings'.
        let q = |e: u32| tree.reward(e)[0] + tree.values[tree.edges[e as usize].child as usize].0;
        let (mut lo, mut hi, mut valued) = (f64::INFINITY, f64::NEG_INFINITY, 0);
        for e in tree.edges_of(node) {
            let v = q(e);
            if v.is_finite() {
                lo = lo.min(v);
                hi = hi.max(v);
                valued += 1;
            }
        }
        let local = valued >= 2 && hi > lo;
        let parent_visits = tree.nodes[node as usize].visits;
        let mut best = (f64::NEG_INFINITY, 0);
        for (k, &e) in candidates.iter().enumerate() {
            let v = q(e);
            let q_hat = if !v.is_finite() {
                0.0
            } else if local {
                (v - lo) / (hi - lo)
            } else {
                // global bounds of the whole returns
                ctx.bounds.normalise(0, ctx.prefix[0] + v).clamp(0.0, 1.0)
            };
            let visits = tree.edges[e as usize].visits;
            let mut score = q_hat + exploration_term(ctx.exploration, parent_visits, visits);
            if ctx.priors.is_some() {
                score += ctx.prior_bonus(e, parent_visits, visits);
            }
            if score > best.0 {
                best = (score, k);
            }
        }
        best.1
    }
}
