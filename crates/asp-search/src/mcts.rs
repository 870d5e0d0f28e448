//! Single-objective MCTS (thesis 5.4.2): UCT on the **maximum** return seen below a node
//! rather than the mean (eq. 5.9), normalised to `[0, 1]` with the minimum and maximum of the
//! siblings' maxima as local bounds, or the global bounds of all returns seen while a node has
//! fewer than two valued children (Vodopivec et al.). Expansion, random rollouts, a search
//! budget per step and episodes are shared with [`crate::ParetoMcts`] (see [`crate::search`]).
//!
//! ```
//! # use asp_search::Mcts;
//! let mcts = Mcts::builder().budget(5).episodes(200).seed(1).build().unwrap();
//! assert_eq!(mcts.settings().budget(), 5);
//! assert!(Mcts::builder().budget(0).build().is_err());
//! ```

use crate::error::{Result, SearchError};
use crate::mdp::Mdp;
use crate::search::{
    exploration_term, run, SearchBuilder, SearchOutcome, SearchSettings, SelectContext, Tree,
    Variant,
};

/// Single-objective Monte Carlo tree search with max-backup UCT.
#[derive(Clone, Debug)]
pub struct Mcts {
    settings: SearchSettings,
}

/// The builder of [`Mcts`].
pub type MctsBuilder = SearchBuilder<Mcts>;

impl From<SearchSettings> for Mcts {
    fn from(settings: SearchSettings) -> Self {
        Mcts { settings }
    }
}

impl Mcts {
    /// A builder with the defaults (budget 5, 1000 episodes, 1 thread, seed 0, c = 1/√2).
    pub fn builder() -> MctsBuilder {
        SearchBuilder::default()
    }

    /// The settings.
    pub fn settings(&self) -> &SearchSettings {
        &self.settings
    }

    /// Searches for the sequence with the largest total of the problem's single objective.
    pub fn solve(&self, problem: &Mdp) -> Result<SearchOutcome> {
        if problem.num_objectives() != 1 {
            return Err(SearchError::config(format!(
                "single-objective MCTS needs exactly one objective, got {}; use Pareto-MCTS",
                problem.num_objectives()
            )));
        }
        run::<MaxBackup>(problem, &self.settings)
    }
}

/// The largest return seen through a node (`-inf` before any).
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
    fn record(value: &mut MaxValue, ret: &[f64]) -> bool {
        if ret[0] > value.0 {
            value.0 = ret[0];
        }
        true
    }

    fn select(
        tree: &mut Tree<MaxValue>,
        parent: u32,
        candidates: &[u32],
        ctx: &SelectContext<'_>,
    ) -> usize {
        // Local bounds: the siblings' maxima.
        let (mut lo, mut hi, mut valued) = (f64::INFINITY, f64::NEG_INFINITY, 0);
        for c in tree.children(parent) {
            let q = tree.values[c as usize].0;
            if q.is_finite() {
                lo = lo.min(q);
                hi = hi.max(q);
                valued += 1;
            }
        }
        if valued < 2 || hi <= lo {
            lo = ctx.bounds.lo[0];
            hi = ctx.bounds.hi[0];
        }
        let parent_visits = tree.nodes[parent as usize].visits;
        let mut best = (f64::NEG_INFINITY, 0);
        for (k, &c) in candidates.iter().enumerate() {
            let q = tree.values[c as usize].0;
            let q_hat = if !q.is_finite() {
                0.0
            } else if hi > lo {
                ((q - lo) / (hi - lo)).clamp(0.0, 1.0)
            } else {
                1.0
            };
            let score = q_hat
                + exploration_term(ctx.exploration, parent_visits, tree.nodes[c as usize].visits);
            if score > best.0 {
                best = (score, k);
            }
        }
        best.1
    }
}
