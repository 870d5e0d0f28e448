//! Pareto-MCTS (thesis 6.4.2, after Perez et al.): every node keeps a local Pareto front of the
//! return vectors of the complete sequences through it (suffixes from its state, see
//! [`crate::mcts`]); selection uses MOUCB, `HV(P(n'))/N(n') + c·sqrt(2 ln N(n) / N(n'))`,
//! with the hypervolume of the child's front as whole returns, in objectives normalised to
//! `[0, 1]` by the global bounds of all returns seen (reference −0.1 in every normalised
//! objective, so the extreme points of a front count); backpropagation adds the vector to each
//! front on the way up — in the plain tree it stops at the first node whose front dominates or
//! equals it, as in the thesis; on the graph of states it continues, since a state's better
//! suffix may have come along another path. The root's front, with the sequences that reached
//! it, is the answer.
//!
//! ```
//! # use asp_search::ParetoMcts;
//! let search = ParetoMcts::builder().episodes(500).threads(2).seed(7).build().unwrap();
//! assert_eq!(search.settings().threads(), 2);
//! assert!(ParetoMcts::builder().exploration(f64::NAN).build().is_err());
//! ```

use super::graph::{exploration_term, SelectContext, Tree, Variant};
use super::outcome::{EpisodeHook, SearchOutcome};
use super::run::run;
use super::settings::search_type;
use crate::error::Result;
use crate::hypervolume::{hypervolume_2d_in_place, ParetoFront};
use crate::mdp::{Mdp, MAX_OBJECTIVES};

/// Reference coordinate of the normalised hypervolume used by MOUCB.
const NORMALISED_REFERENCE: f64 = -0.1;

search_type!(
    /// Multi-objective Monte Carlo tree search over Pareto fronts.
    ParetoMcts,
    ParetoMctsBuilder
);

impl ParetoMcts {
    /// Searches for the Pareto front of the problem's objectives.
    pub fn solve(&self, problem: &Mdp) -> Result<SearchOutcome> {
        run::<FrontBackup>(problem, &self.settings, None)
    }

    /// [`ParetoMcts::solve`] episode by episode on one thread: `hook` is told what each episode
    /// did and may swap the policy or stop the search between episodes (see [`EpisodeHook`]).
    /// With a hook that always continues the answer is [`ParetoMcts::solve`]'s with one thread.
    pub fn solve_stepped(&self, problem: &Mdp, hook: &mut EpisodeHook<'_>) -> Result<SearchOutcome> {
        run::<FrontBackup>(problem, &self.settings, Some(hook))
    }
}

/// A node's local front of suffix return vectors.
#[derive(Clone, Debug, Default)]
pub(crate) struct FrontValue {
    front: Option<ParetoFront<()>>,
}

pub(crate) struct FrontBackup;

impl Variant for FrontBackup {
    type Value = FrontValue;

    #[inline]
    fn record(value: &mut FrontValue, suffix: &[f64]) -> bool {
        let front = value.front.get_or_insert_with(|| ParetoFront::new(suffix.len()));
        front.insert(suffix, || ())
    }

    fn select(tree: &Tree<FrontValue>, node: u32, candidates: &[u32], ctx: &SelectContext<'_>) -> usize {
        let parent_visits = tree.nodes[node as usize].visits;
        let mut best = (f64::NEG_INFINITY, 0);
        for (k, &e) in candidates.iter().enumerate() {
            let visits = tree.edges[e as usize].visits;
            let child = tree.edges[e as usize].child as usize;
            let hv = normalised_hypervolume(tree.values[child].front.as_ref(), tree.reward(e), ctx);
            let mut score = hv / visits.max(1) as f64 + exploration_term(ctx.exploration, parent_visits, visits);
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

/// The hypervolume of the whole returns `prefix + reward + suffix` over a child's suffix front,
/// in objectives normalised by the global bounds (reference −0.1 in each).
fn normalised_hypervolume(front: Option<&ParetoFront<()>>, reward: &[f64], ctx: &SelectContext<'_>) -> f64 {
    let Some(front) = front else { return 0.0 };
    let m = reward.len();
    if m == 2 {
        // the 2-D sweep on a stack buffer (on the heap for fronts of more than 64 points)
        let mut stack = [[0.0f64; 2]; 64];
        let mut heap;
        let pts: &mut [[f64; 2]] = if front.len() <= stack.len() {
            &mut stack[..front.len()]
        } else {
            heap = vec![[0.0f64; 2]; front.len()];
            &mut heap
        };
        for (slot, (p, _)) in pts.iter_mut().zip(front.iter()) {
            for k in 0..2 {
                slot[k] = ctx.bounds.normalise(k, ctx.prefix[k] + reward[k] + p[k]);
            }
        }
        return hypervolume_2d_in_place(pts, [NORMALISED_REFERENCE; 2]);
    }
    let mut norm: ParetoFront<()> = ParetoFront::new(m);
    let mut buf = [0.0f64; MAX_OBJECTIVES];
    for (p, _) in front.iter() {
        for k in 0..m {
            buf[k] = ctx.bounds.normalise(k, ctx.prefix[k] + reward[k] + p[k]);
        }
        norm.insert(&buf[..m], || ());
    }
    let reference = [NORMALISED_REFERENCE; MAX_OBJECTIVES];
    norm.hypervolume(&reference[..m])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::hypervolume::hypervolume_2d;
    use crate::mcts::graph::Bounds;

    #[test]
    fn moucb_hypervolume_counts_every_point_of_a_large_front() {
        // 100 points on the line x + y = 1 in objectives already in [0, 1]
        let mut front = ParetoFront::new(2);
        let pts: Vec<[f64; 2]> = (0..100).map(|k| [k as f64 / 99.0, 1.0 - k as f64 / 99.0]).collect();
        for p in &pts {
            assert!(front.insert(p, || ()));
        }
        let bounds = Bounds { lo: [0.0; MAX_OBJECTIVES], hi: [1.0; MAX_OBJECTIVES] };
        let ctx = SelectContext { exploration: 1.0, bounds: &bounds, prefix: &[0.0, 0.0], priors: None };
        let hv = normalised_hypervolume(Some(&front), &[0.0, 0.0], &ctx);
        let all = hypervolume_2d(&pts, [NORMALISED_REFERENCE; 2]);
        let first_64 = hypervolume_2d(&pts[..64], [NORMALISED_REFERENCE; 2]);
        assert!(all > first_64);
        assert_eq!(hv, all);
    }
}
