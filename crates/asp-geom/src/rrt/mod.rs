//! RRT-Connect (Kuffner and LaValle 2000) with greedy shortcutting, generic over a configuration
//! space given as `sample / valid / interpolate / distance`. One algorithm, two spaces: the
//! removal paths of parts in SE(3) ([`se3`], [`plan_removal_path`]) and the robot's joint space
//! (`asp-robot`'s arm, through [`rrt_connect`]). Seeded: the same space, ends and seed give the
//! same path.
//!
//! [`connect_trees`] grows a start tree and a goal tree (each from one or more roots) towards
//! random samples and each other, swapping them after every sample; [`shortcut`] shortens the
//! path it returns; [`rrt_connect`] is the single start, single goal planner built from both.

pub mod se3;

pub use se3::{plan_removal_path, RrtConfig};

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use std::time::Instant;

/// A configuration space for [`connect_trees`] and [`rrt_connect`].
pub trait Space {
    /// A configuration.
    type State: Clone;

    /// A random configuration (uniform over the space, normally).
    fn sample(&self, rng: &mut ChaCha8Rng) -> Self::State;

    /// Whether the configuration is collision-free.
    fn valid(&self, s: &Self::State) -> bool;

    /// The configuration a fraction `t ∈ [0, 1]` of the way from `a` to `b`.
    fn interpolate(&self, a: &Self::State, b: &Self::State, t: f64) -> Self::State;

    /// A metric on configurations (the tree's nearest neighbours and its step size).
    fn distance(&self, a: &Self::State, b: &Self::State) -> f64;

    /// Whether the straight edge from `a` to `b` (both valid) is collision-free: by default,
    /// [`Space::valid`] at `ceil(distance / resolution)` evenly spaced interior points.
    fn edge_valid(&self, a: &Self::State, b: &Self::State) -> bool {
        let n = (self.distance(a, b) / self.edge_resolution()).ceil().max(1.0) as usize;
        (1..n).all(|i| self.valid(&self.interpolate(a, b, i as f64 / n as f64)))
    }

    /// The spacing of [`Space::edge_valid`]'s checks, in the units of [`Space::distance`].
    fn edge_resolution(&self) -> f64;

    /// Whether a tree may grow from `from` (a node, valid) to the new node `to`: by default
    /// [`Space::valid`] of `to`, then [`Space::edge_valid`]. A space whose edge check covers its
    /// end (an exact, continuous one) checks the edge alone.
    fn step_valid(&self, from: &Self::State, to: &Self::State) -> bool {
        self.valid(to) && self.edge_valid(from, to)
    }
}

/// How far [`connect_trees`] grows its trees.
#[derive(Clone, Copy, Debug)]
pub struct Growth {
    /// The longest tree edge, in the units of [`Space::distance`].
    pub step: f64,
    /// Samples drawn before giving up.
    pub max_iterations: usize,
    /// No sample is drawn after this instant (a wall-time safety cap; the iteration budget is
    /// the one that keeps results reproducible).
    pub deadline: Option<Instant>,
}

/// A forest: nodes with their parents, roots without. A lazy tree also knows which edges to
/// their parents were checked, and which nodes were cut off (an edge above them failed).
struct Tree<S> {
    nodes: Vec<S>,
    parent: Vec<Option<usize>>,
    checked: Vec<bool>,
    dead: Vec<bool>,
}

impl<S: Clone> Tree<S> {
    fn new(roots: &[S]) -> Self {
        Tree { nodes: roots.to_vec(), parent: vec![None; roots.len()], checked: vec![true; roots.len()], dead: vec![false; roots.len()] }
    }

    /// The first live node nearest `q`.
    fn nearest<P: Space<State = S>>(&self, space: &P, q: &S) -> usize {
        let mut best = (f64::INFINITY, 0);
        for (i, n) in self.nodes.iter().enumerate() {
            if self.dead[i] {
                continue;
            }
            let d = space.distance(n, q);
            if d < best.0 {
                best = (d, i);
            }
        }
        best.1
    }

    fn push(&mut self, s: S, parent: usize, checked: bool) -> usize {
        self.nodes.push(s);
        self.parent.push(Some(parent));
        self.checked.push(checked);
        self.dead.push(false);
        self.nodes.len() - 1
    }

    /// Cuts node `i` and everything below it off the tree (children come after their parents).
    fn cut(&mut self, i: usize) {
        self.dead[i] = true;
        for k in i + 1..self.nodes.len() {
            if let Some(p) = self.parent[k] {
                if self.dead[p] {
                    self.dead[k] = true;
                }
            }
        }
    }

    /// Checks the unchecked edges from a root to node `i`, root first; cuts the tree below the
    /// first that fails and returns false.
    fn validate<P: Space<State = S>>(&mut self, space: &P, i: usize) -> bool {
        let mut chain = vec![i];
        while let Some(p) = self.parent[chain[chain.len() - 1]] {
            chain.push(p);
        }
        for &k in chain.iter().rev() {
            if self.checked[k] {
                continue;
            }
            let p = self.parent[k].expect("only roots have no parent, and roots are checked");
            if !space.edge_valid(&self.nodes[p], &self.nodes[k]) {
                self.cut(k);
                return false;
            }
            self.checked[k] = true;
        }
        true
    }

    /// The states from the root to node `i`.
    fn branch(&self, mut i: usize) -> Vec<S> {
        let mut out = vec![self.nodes[i].clone()];
        while let Some(p) = self.parent[i] {
            out.push(self.nodes[p].clone());
            i = p;
        }
        out.reverse();
        out
    }
}

enum Extend {
    Trapped,
    Advanced(usize),
    Reached(usize),
}

/// Grows `tree` from its node nearest `q` by at most one step towards `q` (`lazy`: only the new
/// node is checked, its edge when a path uses it).
fn extend<P: Space>(space: &P, tree: &mut Tree<P::State>, q: &P::State, step: f64, lazy: bool) -> Extend {
    let near = tree.nearest(space, q);
    let from = &tree.nodes[near];
    let d = space.distance(from, q);
    let (target, reached) = if d <= step { (q.clone(), true) } else { (space.interpolate(from, q, step / d), false) };
    let ok = if lazy { space.valid(&target) } else { space.step_valid(from, &target) };
    if !ok {
        return Extend::Trapped;
    }
    let i = tree.push(target, near, !lazy);
    if reached {
        Extend::Reached(i)
    } else {
        Extend::Advanced(i)
    }
}

/// RRT-Connect between two trees grown from `starts` and `goals` (neither empty, every root
/// valid): each iteration extends one tree by a step towards a sample, then the other towards
/// the new node until it reaches it or is trapped, then swaps the trees. Returns the path from a
/// start root to a goal root (both included; every edge passed [`Space::step_valid`]), or `None`
/// when the trees did not meet within `growth`. Draws from `rng` only in [`Space::sample`].
pub fn connect_trees<P: Space>(
    space: &P,
    starts: &[P::State],
    goals: &[P::State],
    growth: &Growth,
    rng: &mut ChaCha8Rng,
) -> Option<Vec<P::State>> {
    grow(space, starts, goals, growth, rng, false)
}

/// [`connect_trees`] with lazy edges (lazy RRT-Connect): a new node is checked with
/// [`Space::valid`] alone; when the trees meet, the edges of the path between the two roots are
/// checked ([`Space::edge_valid`], from each root outwards), and an edge that fails cuts its
/// node and everything below it off its tree, which then grows on. Every edge of the path it
/// returns passed [`Space::edge_valid`], as with [`connect_trees`]; the edges the trees grew
/// but no path used are never checked.
pub fn connect_trees_lazy<P: Space>(
    space: &P,
    starts: &[P::State],
    goals: &[P::State],
    growth: &Growth,
    rng: &mut ChaCha8Rng,
) -> Option<Vec<P::State>> {
    grow(space, starts, goals, growth, rng, true)
}

fn grow<P: Space>(
    space: &P,
    starts: &[P::State],
    goals: &[P::State],
    growth: &Growth,
    rng: &mut ChaCha8Rng,
    lazy: bool,
) -> Option<Vec<P::State>> {
    let mut a = Tree::new(starts);
    let mut b = Tree::new(goals);
    let mut a_is_start = true;
    for _ in 0..growth.max_iterations {
        if growth.deadline.is_some_and(|d| Instant::now() > d) {
            break;
        }
        let q = space.sample(rng);
        let new = match extend(space, &mut a, &q, growth.step, lazy) {
            Extend::Trapped => None,
            Extend::Advanced(i) | Extend::Reached(i) => Some(i),
        };
        if let Some(i) = new {
            let target = a.nodes[i].clone();
            // connect: extend b toward the new node until reached or trapped
            loop {
                match extend(space, &mut b, &target, growth.step, lazy) {
                    Extend::Advanced(_) => continue,
                    Extend::Trapped => break,
                    Extend::Reached(j) => {
                        // lazy: the path's edges now, both trees (a failure cuts and grows on)
                        if lazy && !(a.validate(space, i) && b.validate(space, j)) {
                            break;
                        }
                        let mut pa = a.branch(i);
                        let mut pb = b.branch(j);
                        pb.pop(); // the meeting state is the end of both branches
                        pb.reverse();
                        pa.extend(pb);
                        if !a_is_start {
                            pa.reverse();
                        }
                        return Some(pa);
                    }
                }
            }
        }
        std::mem::swap(&mut a, &mut b);
        a_is_start = !a_is_start;
    }
    None
}

/// Settings of [`rrt_connect`].
#[derive(Clone, Debug)]
pub struct RrtConnectConfig {
    /// The longest tree edge, in the units of [`Space::distance`].
    pub step: f64,
    /// Samples drawn before giving up.
    pub max_iterations: usize,
    /// Seed of the samples.
    pub seed: u64,
    /// Check tree edges only when a path between the roots uses them
    /// ([`connect_trees_lazy`]); false: every edge as it is grown ([`connect_trees`]).
    pub lazy: bool,
}

impl Default for RrtConnectConfig {
    fn default() -> Self {
        RrtConnectConfig { step: 0.3, max_iterations: 2000, seed: 0, lazy: false }
    }
}

/// Why [`rrt_connect`] found no path.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RrtFailure {
    /// The start configuration is in collision.
    InvalidStart,
    /// The goal configuration is in collision.
    InvalidGoal,
    /// The trees did not meet within the iteration budget.
    Exhausted,
}

/// A collision-free path from `start` to `goal` (both included): the direct edge when it is
/// free, else [`connect_trees`] from the two, then [`shortcut`]. Every edge of the answer
/// passed [`Space::edge_valid`].
pub fn rrt_connect<P: Space>(space: &P, start: &P::State, goal: &P::State, config: &RrtConnectConfig) -> Result<Vec<P::State>, RrtFailure> {
    if !space.valid(start) {
        return Err(RrtFailure::InvalidStart);
    }
    if !space.valid(goal) {
        return Err(RrtFailure::InvalidGoal);
    }
    let mut rng = ChaCha8Rng::seed_from_u64(config.seed);
    if space.edge_valid(start, goal) {
        return Ok(vec![start.clone(), goal.clone()]);
    }
    let growth = Growth { step: config.step, max_iterations: config.max_iterations, deadline: None };
    let path = grow(space, std::slice::from_ref(start), std::slice::from_ref(goal), &growth, &mut rng, config.lazy)
        .ok_or(RrtFailure::Exhausted)?;
    Ok(shortcut(space, path))
}

/// Greedy shortcutting: from each waypoint, straight to the farthest later one it sees directly
/// ([`Space::edge_valid`]).
///
/// Afterwards no two waypoints but neighbours see each other (each such pair was tested and
/// refused), so random waypoint pairs tried after it could never shorten the path: there are
/// none (they once cost the robot's path planner a third of its collision checks).
pub fn shortcut<P: Space>(space: &P, path: Vec<P::State>) -> Vec<P::State> {
    let mut out = vec![path[0].clone()];
    let mut i = 0;
    while i + 1 < path.len() {
        let mut j = path.len() - 1;
        while j > i + 1 && !space.edge_valid(&path[i], &path[j]) {
            j -= 1;
        }
        out.push(path[j].clone());
        i = j;
    }
    out
}

#[cfg(test)]
mod tests;
