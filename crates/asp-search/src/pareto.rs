//! Pareto-MCTS (thesis 6.4.2, after Perez et al.): every node keeps a local Pareto front of the
//! return vectors of the complete sequences through it; selection uses MOUCB,
//! `HV(P(n'))/N(n') + c·sqrt(2 ln N(n) / N(n'))`, with the hypervolume of the child's front in
//! objectives normalised to `[0, 1]` by the global bounds of all returns seen (reference point
//! −0.1 in every normalised objective, so the extreme points of a front count); backpropagation
//! adds the vector to each front on the way up and stops at the first node whose front dominates
//! or equals it. The root's front, with the sequences that reached it, is the answer.
//!
//! ```
//! # use asp_search::ParetoMcts;
//! let search = ParetoMcts::builder().episodes(500).threads(2).seed(7).build().unwrap();
//! assert_eq!(search.settings().threads(), 2);
//! assert!(ParetoMcts::builder().exploration(f64::NAN).build().is_err());
//! ```

use crate::error::Result;
use crate::hypervolume::ParetoFront;
use crate::mdp::{Mdp, MAX_OBJECTIVES};
use crate::search::{
    exploration_term, run, SearchBuilder, SearchOutcome, SearchSettings, SelectContext, Tree,
    Variant,
};

/// Reference coordinate of the normalised hypervolume used by MOUCB.
const NORMALISED_REFERENCE: f64 = -0.1;

/// Multi-objective Monte Carlo tree search over Pareto fronts.
#[derive(Clone, Debug)]
pub struct ParetoMcts {
    settings: SearchSettings,
}

/// The builder of [`ParetoMcts`].
pub type ParetoMctsBuilder = SearchBuilder<ParetoMcts>;

impl From<SearchSettings> for ParetoMcts {
    fn from(settings: SearchSettings) -> Self {
        ParetoMcts { settings }
    }
}

impl ParetoMcts {
    /// A builder with the defaults (budget 5, 1000 episodes, 1 thread, seed 0, c = 1/√2).
    pub fn builder() -> ParetoMctsBuilder {
        SearchBuilder::default()
    }

    /// The settings.
    pub fn settings(&self) -> &SearchSettings {
        &self.settings
    }

    /// Searches for the Pareto front of the problem's objectives.
    pub fn solve(&self, problem: &Mdp) -> Result<SearchOutcome> {
        run::<FrontBackup>(problem, &self.settings)
    }
}

/// A node's local front and the cached normalised hypervolume.
#[derive(Clone, Debug)]
pub(crate) struct FrontValue {
    front: Option<ParetoFront<()>>,
    hv: f64,
    hv_version: u64,
}

impl Default for FrontValue {
    fn default() -> Self {
        FrontValue { front: None, hv: 0.0, hv_version: u64::MAX }
    }
}

pub(crate) struct FrontBackup;

impl Variant for FrontBackup {
    type Value = FrontValue;

    #[inline]
    fn record(value: &mut FrontValue, ret: &[f64]) -> bool {
        let front = value.front.get_or_insert_with(|| ParetoFront::new(ret.len()));
        let added = front.insert(ret, || ());
        if added {
            value.hv_version = u64::MAX;
        }
        added
    }

    fn select(
        tree: &mut Tree<FrontValue>,
        parent: u32,
        candidates: &[u32],
        ctx: &SelectContext<'_>,
    ) -> usize {
        let parent_visits = tree.nodes[parent as usize].visits;
        let mut best = (f64::NEG_INFINITY, 0);
        for (k, &c) in candidates.iter().enumerate() {
            let visits = tree.nodes[c as usize].visits;
            let v = &mut tree.values[c as usize];
            if v.hv_version != ctx.bounds.version {
                v.hv = normalised_hypervolume(v.front.as_ref(), ctx);
                v.hv_version = ctx.bounds.version;
            }
            let score = v.hv / visits.max(1) as f64
                + exploration_term(ctx.exploration, parent_visits, visits);
            if score > best.0 {
                best = (score, k);
            }
        }
        best.1
    }
}

fn normalised_hypervolume(front: Option<&ParetoFront<()>>, ctx: &SelectContext<'_>) -> f64 {
    let Some(front) = front else { return 0.0 };
    let m = ctx.m;
    let mut norm: ParetoFront<()> = ParetoFront::new(m);
    let mut buf = [0.0f64; MAX_OBJECTIVES];
    for (p, _) in front.iter() {
        for k in 0..m {
            buf[k] = ctx.bounds.normalise(k, p[k]);
        }
        norm.insert(&buf[..m], || ());
    }
    let reference = [NORMALISED_REFERENCE; MAX_OBJECTIVES];
    norm.hypervolume(&reference[..m])
}
