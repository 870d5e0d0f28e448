//! Part orderings of the depth-first search: in which order the parts of a state are tested.
//!
//! An ordering is an open trait ([`PartOrdering`]); a fresh instance is made for every search by
//! an [`OrderingFactory`], so an ordering may keep memory (bookkeeping) or scratch buffers (a
//! learned model) without sharing them between searches. The built-in orderings are
//! [`BuiltinOrder`]: `given` (the model's part order), `shuffled` (the thesis' vanilla AbD: one
//! arbitrary order drawn from the seed at the start of a search and kept) and `random` (a fresh
//! permutation in every state). [`Bookkeeping`] (thesis 3.1.1) decorates any ordering.
//!
//! Every built-in ordering depends only on the seed and the state, never on the path the search
//! took to reach it. So decorating an ordering with bookkeeping changes nothing but which tests
//! are skipped: the search visits the same states in the same order and runs at most as many
//! tests (a test skipped by bookkeeping is one whose answer is known).

use asp_geom::{MotionKind, Outcome, PartSet, World};
use rand::seq::SliceRandom;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use std::fmt;
use std::sync::Arc;

/// The order in which a depth-first search tests the parts of a state.
pub trait PartOrdering: Send {
    /// Reorders `parts` (the present, non-fixed parts of `state`, ascending) into the order in
    /// which they are tested.
    fn order(&mut self, state: &PartSet, parts: &mut Vec<usize>);

    /// Called with the outcome of every removal test the search runs (default: ignored).
    fn observe(&mut self, part: usize, state: &PartSet, kind: MotionKind, outcome: &Outcome) {
        let _ = (part, state, kind, outcome);
    }

    /// `Some(blockers)` when `part` is known to be blocked along every straight line in `state`
    /// without testing it (the search then skips the straight-line test), `None` to test it.
    fn known_blocked(&self, part: usize, state: &PartSet) -> Option<PartSet> {
        let _ = (part, state);
        None
    }
}

/// Makes a fresh [`PartOrdering`] for each search.
pub trait OrderingFactory: Send + Sync {
    /// A short name for reports (`given`, `shuffled`, `gnn`, ...).
    fn name(&self) -> String;
    /// An ordering for a search over `num_parts` parts with the planner's `seed`.
    fn make(&self, num_parts: usize, seed: u64) -> Box<dyn PartOrdering>;
}

/// Where an ordering comes from: prepared once per model (a learned ordering computes the
/// model's graph features and loads its network here), then a factory of per-search orderings.
pub trait OrderingSource: Send + Sync {
    /// A short name for reports.
    fn name(&self) -> String;
    /// The ordering factory for the model of `world`.
    fn prepare(&self, world: &World) -> crate::Result<Arc<dyn OrderingFactory>>;
    /// The ordering factory when it needs nothing of the model (the built-in orderings), for
    /// planners that build no collision world (the voxel checker, `asp_geom::voxel`); `None`
    /// (the default) when it needs the world.
    fn prepare_without_world(&self) -> Option<Arc<dyn OrderingFactory>> {
        None
    }
}

impl OrderingSource for BuiltinOrder {
    fn name(&self) -> String {
        self.as_str().into()
    }

    fn prepare(&self, _world: &World) -> crate::Result<Arc<dyn OrderingFactory>> {
        Ok(Arc::new(*self))
    }

    fn prepare_without_world(&self) -> Option<Arc<dyn OrderingFactory>> {
        Some(Arc::new(*self))
    }
}

/// The orderings that need no model.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum BuiltinOrder {
    /// Index order (the model's part order).
    #[default]
    Given,
    /// One permutation drawn from the seed at the start and kept for the whole search: the
    /// thesis' vanilla AbD with its "arbitrarily predefined" initial orderings.
    Shuffled,
    /// A fresh permutation in every state, drawn from the seed and the state.
    Random,
}

impl BuiltinOrder {
    /// The ordering's name as the CLI spells it.
    pub fn as_str(self) -> &'static str {
        match self {
            BuiltinOrder::Given => "given",
            BuiltinOrder::Shuffled => "shuffled",
            BuiltinOrder::Random => "random",
        }
    }
}

impl OrderingFactory for BuiltinOrder {
    fn name(&self) -> String {
        self.as_str().into()
    }

    fn make(&self, num_parts: usize, seed: u64) -> Box<dyn PartOrdering> {
        match self {
            BuiltinOrder::Given => Box::new(Given),
            BuiltinOrder::Shuffled => Box::new(Shuffled::new(num_parts, seed)),
            BuiltinOrder::Random => Box::new(Reshuffled { seed }),
        }
    }
}

/// Index order.
#[derive(Clone, Copy, Debug, Default)]
pub struct Given;

impl PartOrdering for Given {
    fn order(&mut self, _state: &PartSet, _parts: &mut Vec<usize>) {}
}

/// One fixed permutation of all parts (the rank of each part), applied in every state.
#[derive(Clone, Debug)]
pub struct Shuffled {
    rank: Vec<usize>,
}

impl Shuffled {
    /// The permutation of `num_parts` parts drawn from `seed`.
    pub fn new(num_parts: usize, seed: u64) -> Self {
        let mut perm: Vec<usize> = (0..num_parts).collect();
        perm.shuffle(&mut ChaCha8Rng::seed_from_u64(seed));
        let mut rank = vec![0; num_parts];
        for (r, &p) in perm.iter().enumerate() {
            rank[p] = r;
        }
        Shuffled { rank }
    }

    /// The position of `part` in the permutation (parts beyond it come last).
    pub fn rank(&self, part: usize) -> usize {
        self.rank.get(part).copied().unwrap_or(usize::MAX)
    }
}

impl PartOrdering for Shuffled {
    fn order(&mut self, _state: &PartSet, parts: &mut Vec<usize>) {
        parts.sort_by_key(|&p| (self.rank(p), p));
    }
}

/// A permutation per state: seeded by the planner's seed and the state's bits, so the same state
/// is always tested in the same order however the search reached it.
#[derive(Clone, Copy, Debug)]
struct Reshuffled {
    seed: u64,
}

impl PartOrdering for Reshuffled {
    fn order(&mut self, state: &PartSet, parts: &mut Vec<usize>) {
        parts.shuffle(&mut ChaCha8Rng::seed_from_u64(state_seed(self.seed, state, u64::MAX)));
    }
}

/// The depth-first search's seed of the randomised work on `state` named by `salt` (a part
/// index): [`asp_geom::seed::derive`] in the search's stream.
pub fn state_seed(seed: u64, state: &PartSet, salt: u64) -> u64 {
    asp_geom::seed::derive(seed, asp_geom::seed::Stream::Search, state, salt)
}

/// Bookkeeping (thesis 3.1.1, Dorn et al.): a part whose straight-line test collided is not
/// tested again while every part that blocked it is still present. Exact for straight-line
/// tests, since blocking is a property of part pairs: the skipped test would collide again.
pub struct Bookkeeping {
    inner: Box<dyn PartOrdering>,
    blocked_by: Vec<Option<PartSet>>,
}

impl Bookkeeping {
    /// Bookkeeping on top of `inner` for a search over `num_parts` parts.
    pub fn new(inner: Box<dyn PartOrdering>, num_parts: usize) -> Self {
        Bookkeeping { inner, blocked_by: vec![None; num_parts] }
    }
}

impl PartOrdering for Bookkeeping {
    fn order(&mut self, state: &PartSet, parts: &mut Vec<usize>) {
        self.inner.order(state, parts);
    }

    fn observe(&mut self, part: usize, state: &PartSet, kind: MotionKind, outcome: &Outcome) {
        if kind == MotionKind::Linear {
            if let (Outcome::Collision { blockers }, Some(slot)) = (outcome, self.blocked_by.get_mut(part)) {
                *slot = Some(blockers.clone());
            }
        }
        self.inner.observe(part, state, kind, outcome);
    }

    fn known_blocked(&self, part: usize, state: &PartSet) -> Option<PartSet> {
        match self.blocked_by.get(part) {
            Some(Some(b)) if b.is_subset(state) => Some(b.clone()),
            _ => self.inner.known_blocked(part, state),
        }
    }
}

/// An [`OrderingFactory`] whose orderings are decorated with [`Bookkeeping`].
#[derive(Clone)]
pub struct WithBookkeeping(pub Arc<dyn OrderingFactory>);

impl OrderingFactory for WithBookkeeping {
    fn name(&self) -> String {
        format!("{}+bookkeeping", self.0.name())
    }

    fn make(&self, num_parts: usize, seed: u64) -> Box<dyn PartOrdering> {
        Box::new(Bookkeeping::new(self.0.make(num_parts, seed), num_parts))
    }
}

impl fmt::Debug for dyn OrderingFactory {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "OrderingFactory({})", self.name())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shuffled_is_one_permutation_for_every_state() {
        let mut o = BuiltinOrder::Shuffled.make(10, 7);
        let mut all: Vec<usize> = (0..10).collect();
        o.order(&PartSet::full(10), &mut all);
        assert_ne!(all, (0..10).collect::<Vec<_>>(), "seed 7 should not give the identity");
        let mut some = vec![1, 3, 5, 7];
        o.order(&PartSet::from_indices(10, [1, 3, 5, 7]), &mut some);
        let expected: Vec<usize> = all.iter().copied().filter(|p| [1, 3, 5, 7].contains(p)).collect();
        assert_eq!(some, expected, "a subset keeps the relative order of the permutation");
    }

    #[test]
    fn random_depends_on_the_state_not_the_history() {
        let state = PartSet::from_indices(12, [0, 2, 3, 5, 8, 9, 11]);
        let order = |seed| {
            let mut o = BuiltinOrder::Random.make(12, seed);
            let mut first: Vec<usize> = state.iter().collect();
            o.order(&PartSet::full(12), &mut (0..12).collect());
            o.order(&state, &mut first);
            first
        };
        assert_eq!(order(3), order(3));
        assert_ne!(order(3), order(4));
        let mut fresh = BuiltinOrder::Random.make(12, 3);
        let mut again: Vec<usize> = state.iter().collect();
        fresh.order(&state, &mut again);
        assert_eq!(again, order(3), "the same state gets the same order whatever came before");
    }

    #[test]
    fn bookkeeping_skips_only_while_every_blocker_is_present() {
        let mut bk = Bookkeeping::new(Box::new(Given), 4);
        let full = PartSet::full(4);
        let blockers = PartSet::from_indices(4, [1, 2]);
        bk.observe(0, &full, MotionKind::Linear, &Outcome::Collision { blockers: blockers.clone() });
        assert_eq!(bk.known_blocked(0, &full), Some(blockers));
        assert_eq!(bk.known_blocked(0, &full.without(2)), None);
        assert_eq!(bk.known_blocked(3, &full), None);
        // a path planner's collision says nothing about straight lines
        bk.observe(3, &full, MotionKind::Path { seed: 1 }, &Outcome::Collision { blockers: PartSet::from_indices(4, [0]) });
        assert_eq!(bk.known_blocked(3, &full), None);
    }
}
