//! The search graph: nodes (a state each, shared by transpositions), edges with their rewards,
//! the transposition index, and what the variants ([`super::uct`], [`super::pareto`]) plug in:
//! a node value with its backup and the tree policy ([`Variant`]).

use crate::mdp::{Mdp, MAX_OBJECTIVES};
use asp_geom::PartSet;
use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hash, Hasher};

pub(crate) const NONE: u32 = u32::MAX;
/// The prior span of a node added while the policy gives priors, before they are asked for
/// (when the search first expands from it).
pub(crate) const PENDING: (u32, u32) = (NONE, NONE - 1);

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
    pub next_same: u32,
    /// Removals not expanded yet (the size of [`NodeSets::untried`]).
    pub untried_left: u16,
    pub status: Status,
}

/// The part sets of a node, read when the search expands it.
#[derive(Clone, Debug)]
pub(crate) struct NodeSets {
    pub present: PartSet,
    /// Parts known to be collision-free here (they stay so in every descendant).
    pub free: PartSet,
    pub untried: PartSet,
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
    pub sets: Vec<NodeSets>,
    pub values: Vec<V>,
    pub edges: Vec<Edge>,
    pub rewards: Vec<f64>,
    /// `w` memory words per node.
    pub memory: Vec<u64>,
    pub w: usize,
    pub index: HashMap<u64, u32, BuildHasherDefault<KeyHasher>>,
    pub m: usize,
    /// With a policy that gives priors: per node, its feasible actions' priors (a range of
    /// `node_priors`; [`PENDING`] until the search first expands from it, `(NONE, NONE)` for a
    /// node added while the policy gave none), and per edge its action's prior.
    pub prior_spans: Vec<(u32, u32)>,
    pub node_priors: Vec<(u16, f32)>,
    pub edge_priors: Vec<f32>,
}

impl<V> Tree<V> {
    pub fn memory(&self, n: u32) -> &[u64] {
        &self.memory[n as usize * self.w..(n as usize + 1) * self.w]
    }

    /// Whether node `n` has priors (it was added while the policy gave priors).
    pub fn has_priors(&self, n: u32) -> bool {
        self.prior_spans.get(n as usize).is_some_and(|s| s.0 != NONE)
    }

    /// Whether node `n`'s priors are still to be asked for.
    pub fn priors_pending(&self, n: u32) -> bool {
        self.prior_spans.get(n as usize) == Some(&PENDING)
    }

    /// The prior node `n` gave `action` (0 when it gave none).
    pub fn prior_of(&self, n: u32, action: usize) -> f32 {
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
    pub fn is(&self, n: u32, present: &PartSet, memory: &[u64], problem: &Mdp) -> bool {
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
pub(super) fn state_hash(present: &PartSet, memory: &[u64], problem: &Mdp) -> u64 {
    let mut h = KeyHasher::default();
    present.hash(&mut h);
    problem.hash_key(memory, &mut h);
    h.finish()
}

/// The transposition index's hasher: a multiply-xor mix of the state's words (they are
/// hashed once by [`state_hash`]), which the index then uses as they are. Only speed depends
/// on it: the index's chains are compared state by state ([`Tree::is`]).
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct KeyHasher(u64);

impl KeyHasher {
    #[inline]
    fn mix(&mut self, x: u64) {
        self.0 = (self.0.rotate_left(5) ^ x).wrapping_mul(0x51_7c_c1_b7_27_22_0a_95);
    }
}

impl Hasher for KeyHasher {
    #[inline]
    fn finish(&self) -> u64 {
        // a final avalanche, so that the index's table (which reads the high and the low bits)
        // sees every word
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    #[inline]
    fn write(&mut self, bytes: &[u8]) {
        for chunk in bytes.chunks(8) {
            let mut word = [0u8; 8];
            word[..chunk.len()].copy_from_slice(chunk);
            self.mix(u64::from_le_bytes(word));
        }
    }

    #[inline]
    fn write_u64(&mut self, x: u64) {
        self.mix(x);
    }

    #[inline]
    fn write_usize(&mut self, x: usize) {
        self.mix(x as u64);
    }
}

/// Global bounds of the returns seen so far (per objective).
#[derive(Clone, Debug)]
pub(crate) struct Bounds {
    pub lo: [f64; MAX_OBJECTIVES],
    pub hi: [f64; MAX_OBJECTIVES],
}

impl Bounds {
    pub fn new() -> Self {
        Bounds { lo: [f64::INFINITY; MAX_OBJECTIVES], hi: [f64::NEG_INFINITY; MAX_OBJECTIVES] }
    }

    pub fn update(&mut self, ret: &[f64]) {
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
