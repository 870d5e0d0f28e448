//! RRT-Connect (Kuffner and LaValle 2000) with greedy shortcutting, generic over a
//! configuration space given as `sample / valid / interpolate / distance`. Seeded: the same
//! space, ends and seed give the same path.

use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// A configuration space for [`rrt_connect`].
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
}

/// Settings of [`rrt_connect`].
#[derive(Clone, Debug)]
pub struct RrtConnectConfig {
    /// The longest tree edge, in the units of [`Space::distance`].
    pub step: f64,
    /// Samples drawn before giving up.
    pub max_iterations: usize,
    /// Shortcut attempts on the found path (pairs of waypoints joined directly when the edge is
    /// free).
    pub shortcut_attempts: usize,
    /// Seed of the samples and the shortcuts.
    pub seed: u64,
}

impl Default for RrtConnectConfig {
    fn default() -> Self {
        RrtConnectConfig { step: 0.3, max_iterations: 2000, shortcut_attempts: 60, seed: 0 }
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

struct Tree<S> {
    nodes: Vec<S>,
    parent: Vec<usize>,
}

impl<S: Clone> Tree<S> {
    fn new(root: S) -> Self {
        Tree { nodes: vec![root], parent: vec![usize::MAX] }
    }

    fn nearest<P: Space<State = S>>(&self, space: &P, q: &S) -> usize {
        let mut best = (f64::INFINITY, 0);
        for (i, n) in self.nodes.iter().enumerate() {
            let d = space.distance(n, q);
            if d < best.0 {
                best = (d, i);
            }
        }
        best.1
    }

    fn push(&mut self, s: S, parent: usize) -> usize {
        self.nodes.push(s);
        self.parent.push(parent);
        self.nodes.len() - 1
    }

    /// The states from the root to node `i`.
    fn branch(&self, mut i: usize) -> Vec<S> {
        let mut out = Vec::new();
        while i != usize::MAX {
            out.push(self.nodes[i].clone());
            i = self.parent[i];
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

fn extend<P: Space>(space: &P, tree: &mut Tree<P::State>, q: &P::State, step: f64) -> Extend {
    let near = tree.nearest(space, q);
    let from = &tree.nodes[near];
    let d = space.distance(from, q);
    let (target, reached) = if d <= step { (q.clone(), true) } else { (space.interpolate(from, q, step / d), false) };
    if !space.valid(&target) || !space.edge_valid(from, &target) {
        return Extend::Trapped;
    }
    let i = tree.push(target, near);
    if reached {
        Extend::Reached(i)
    } else {
        Extend::Advanced(i)
    }
}

/// A collision-free path from `start` to `goal` (both included) by RRT-Connect, then shortcut.
/// Every edge of the answer passed [`Space::edge_valid`].
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
    let mut a = Tree::new(start.clone());
    let mut b = Tree::new(goal.clone());
    let mut a_is_start = true;
    for _ in 0..config.max_iterations {
        let q = space.sample(&mut rng);
        let new = match extend(space, &mut a, &q, config.step) {
            Extend::Trapped => None,
            Extend::Advanced(i) | Extend::Reached(i) => Some(i),
        };
        if let Some(i) = new {
            let target = a.nodes[i].clone();
            // connect: extend b toward the new node until reached or trapped
            loop {
                match extend(space, &mut b, &target, config.step) {
                    Extend::Advanced(_) => continue,
                    Extend::Trapped => break,
                    Extend::Reached(j) => {
                        let mut pa = a.branch(i);
                        let mut pb = b.branch(j);
                        pb.pop(); // the meeting state is the end of both branches
                        pb.reverse();
                        pa.extend(pb);
                        if !a_is_start {
                            pa.reverse();
                        }
                        return Ok(shortcut(space, pa, config.shortcut_attempts, &mut rng));
                    }
                }
            }
        }
        std::mem::swap(&mut a, &mut b);
        a_is_start = !a_is_start;
    }
    Err(RrtFailure::Exhausted)
}

/// Greedy shortcutting: first from each waypoint to the farthest later one it sees directly,
/// then `attempts` random pairs.
pub fn shortcut<P: Space>(space: &P, path: Vec<P::State>, attempts: usize, rng: &mut ChaCha8Rng) -> Vec<P::State> {
    let mut path = path;
    // greedy pass
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
    path = out;
    for _ in 0..attempts {
        if path.len() < 3 {
            break;
        }
        let i = rng.random_range(0..path.len() - 2);
        let j = rng.random_range(i + 2..path.len());
        if space.edge_valid(&path[i], &path[j]) {
            path.drain(i + 1..j);
        }
    }
    path
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The unit square with a wall at x = 0.5 from y = 0 to 0.8.
    struct Square;

    impl Space for Square {
        type State = [f64; 2];
        fn sample(&self, rng: &mut ChaCha8Rng) -> [f64; 2] {
            [rng.random_range(0.0..1.0), rng.random_range(0.0..1.0)]
        }
        fn valid(&self, s: &[f64; 2]) -> bool {
            !((s[0] - 0.5).abs() < 0.02 && s[1] < 0.8)
        }
        fn interpolate(&self, a: &[f64; 2], b: &[f64; 2], t: f64) -> [f64; 2] {
            [a[0] + (b[0] - a[0]) * t, a[1] + (b[1] - a[1]) * t]
        }
        fn distance(&self, a: &[f64; 2], b: &[f64; 2]) -> f64 {
            ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2)).sqrt()
        }
        fn edge_resolution(&self) -> f64 {
            0.005
        }
    }

    #[test]
    fn goes_around_the_wall_and_is_deterministic() {
        let cfg = RrtConnectConfig { step: 0.1, seed: 3, ..Default::default() };
        let path = rrt_connect(&Square, &[0.2, 0.1], &[0.8, 0.1], &cfg).unwrap();
        assert_eq!(path.first(), Some(&[0.2, 0.1]));
        assert_eq!(path.last(), Some(&[0.8, 0.1]));
        for w in path.windows(2) {
            assert!(Square.edge_valid(&w[0], &w[1]));
        }
        // it must pass above the wall
        assert!(path.iter().any(|s| s[1] > 0.78), "{path:?}");
        assert_eq!(path, rrt_connect(&Square, &[0.2, 0.1], &[0.8, 0.1], &cfg).unwrap());
        assert_eq!(rrt_connect(&Square, &[0.5, 0.1], &[0.8, 0.1], &cfg), Err(RrtFailure::InvalidStart));
    }

    #[test]
    fn an_enclosed_goal_is_not_reached() {
        struct Boxed;
        impl Space for Boxed {
            type State = [f64; 2];
            fn sample(&self, rng: &mut ChaCha8Rng) -> [f64; 2] {
                Square.sample(rng)
            }
            fn valid(&self, s: &[f64; 2]) -> bool {
                // a ring around (0.8, 0.8)
                let r = ((s[0] - 0.8).powi(2) + (s[1] - 0.8).powi(2)).sqrt();
                !(0.1..0.15).contains(&r)
            }
            fn interpolate(&self, a: &[f64; 2], b: &[f64; 2], t: f64) -> [f64; 2] {
                Square.interpolate(a, b, t)
            }
            fn distance(&self, a: &[f64; 2], b: &[f64; 2]) -> f64 {
                Square.distance(a, b)
            }
            fn edge_resolution(&self) -> f64 {
                0.005
            }
        }
        let cfg = RrtConnectConfig { step: 0.1, max_iterations: 300, seed: 1, ..Default::default() };
        assert_eq!(rrt_connect(&Boxed, &[0.1, 0.1], &[0.8, 0.8], &cfg), Err(RrtFailure::Exhausted));
    }
}
