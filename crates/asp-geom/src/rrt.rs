//! RRT-Connect in SE(3): removal paths for parts that cannot leave along a straight line.
//!
//! A configuration is the displacement of the part about the centre of its bounds: a
//! translation and a rotation. The start tree grows from the assembled pose; the goal tree from
//! collision-free poses just outside the bounds of what remains, one per candidate direction.
//! Edges are checked exactly (continuous collision detection by parry's nonlinear shape cast of
//! the part shrunk by the tolerance), so a path never grazes deeper than the tolerance.

use crate::feasibility::Motion;
use crate::math::{Pose, Rot, Vec3};
use crate::partset::PartSet;
use crate::world::World;
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::time::{Duration, Instant};

/// Budget and resolution of the path planner.
#[derive(Clone, Debug)]
pub struct RrtConfig {
    /// Iterations (sample + extend + connect) before giving up. Default 2000.
    pub max_iterations: usize,
    /// Wall-time safety cap per call (the iteration budget is the one that keeps results
    /// reproducible). Default 5 s.
    pub max_time: Duration,
    /// Longest tree edge as a fraction of the model's diagonal. Default 0.05.
    pub step_fraction: f32,
    /// Whether the part may rotate. Default true.
    pub rotate: bool,
}

impl Default for RrtConfig {
    fn default() -> Self {
        RrtConfig { max_iterations: 2000, max_time: Duration::from_secs(5), step_fraction: 0.05, rotate: true }
    }
}

#[derive(Clone, Copy, Debug)]
struct Config {
    t: Vec3,
    r: Rot,
}

struct Tree {
    nodes: Vec<Config>,
    parent: Vec<Option<usize>>,
}

impl Tree {
    fn nearest(&self, q: &Config, radius: f32) -> usize {
        let mut best = (f32::INFINITY, 0);
        for (i, n) in self.nodes.iter().enumerate() {
            let d = distance(n, q, radius);
            if d < best.0 {
                best = (d, i);
            }
        }
        best.1
    }
    fn push(&mut self, q: Config, parent: Option<usize>) -> usize {
        self.nodes.push(q);
        self.parent.push(parent);
        self.nodes.len() - 1
    }
    fn path_to_root(&self, mut i: usize) -> Vec<Config> {
        let mut path = vec![self.nodes[i]];
        while let Some(p) = self.parent[i] {
            path.push(self.nodes[p]);
            i = p;
        }
        path
    }
}

fn distance(a: &Config, b: &Config, radius: f32) -> f32 {
    (a.t - b.t).length() + radius * a.r.angle_between(b.r)
}

fn interpolate(a: &Config, b: &Config, s: f32) -> Config {
    Config { t: a.t.lerp(b.t, s), r: a.r.slerp(b.r, s) }
}

/// The planner for one (part, state) query.
struct Query<'a> {
    world: &'a World,
    part: usize,
    state: &'a PartSet,
    centre: Vec3,
    radius: f32,
    step: f32,
    blockers: PartSet,
}

impl Query<'_> {
    fn pose(&self, q: &Config) -> Pose {
        // x' = c + R (x - c) + t
        Pose::from_parts(self.centre + q.t - q.r * self.centre, q.r)
    }

    fn free(&mut self, q: &Config) -> bool {
        let pose = self.pose(q);
        match self.world.collision_at(self.part, &pose, self.state) {
            Some(q) => {
                self.blockers.insert(q);
                false
            }
            None => true,
        }
    }

    fn edge_free(&mut self, a: &Config, b: &Config) -> bool {
        let (pa, pb) = (self.pose(a), self.pose(b));
        match self.world.collision_between(self.part, &pa, &pb, self.centre, self.state) {
            Some(q) => {
                self.blockers.insert(q);
                false
            }
            None => true,
        }
    }

    /// Extends `tree` from its node nearest `target` by at most one step; returns the new node
    /// and whether it reached `target`.
    fn extend(&mut self, tree: &mut Tree, target: &Config) -> Option<(usize, bool)> {
        let near = tree.nearest(target, self.radius);
        let from = tree.nodes[near];
        let d = distance(&from, target, self.radius);
        let (to, reached) = if d <= self.step { (*target, true) } else { (interpolate(&from, target, self.step / d), false) };
        self.edge_free(&from, &to).then(|| (tree.push(to, Some(near)), reached))
    }

    fn connect(&mut self, tree: &mut Tree, target: &Config) -> Option<usize> {
        loop {
            match self.extend(tree, target) {
                Some((i, true)) => return Some(i),
                Some((_, false)) => continue,
                None => return None,
            }
        }
    }

    /// Greedy shortcutting: from each waypoint jump to the farthest one reachable directly.
    fn shortcut(&mut self, path: Vec<Config>) -> Vec<Config> {
        let mut out = vec![path[0]];
        let mut i = 0;
        while i + 1 < path.len() {
            let mut j = path.len() - 1;
            while j > i + 1 && !self.edge_free(&path[i], &path[j]) {
                j -= 1;
            }
            out.push(path[j]);
            i = j;
        }
        out
    }
}

/// Plans a removal path for `part` out of `state` with RRT-Connect. Translation-only paths are
/// tried first with half the budget (most real removal paths need no rotation, and the 3-D
/// search is far easier), then full SE(3) when `config.rotate`. Returns the path (poses of the
/// part, the first the identity) or the parts that were hit while searching.
pub fn plan_removal_path(
    world: &World,
    part: usize,
    state: &PartSet,
    config: &RrtConfig,
    seed: u64,
) -> std::result::Result<Motion, PartSet> {
    if !config.rotate {
        return rrt_connect(world, part, state, config, seed);
    }
    let half =
        RrtConfig { max_iterations: config.max_iterations.div_ceil(2), max_time: config.max_time / 2, rotate: false, ..config.clone() };
    rrt_connect(world, part, state, &half, seed).or_else(|mut blockers| {
        let full = RrtConfig {
            max_iterations: config.max_iterations - half.max_iterations,
            max_time: config.max_time - half.max_time,
            ..config.clone()
        };
        rrt_connect(world, part, state, &full, seed.wrapping_add(1)).map_err(|b| {
            blockers.union_with(&b);
            blockers
        })
    })
}

/// One RRT-Connect search within `config`'s budget.
fn rrt_connect(world: &World, part: usize, state: &PartSet, config: &RrtConfig, seed: u64) -> std::result::Result<Motion, PartSet> {
    let start_time = Instant::now();
    let mut rng = ChaCha8Rng::seed_from_u64(seed ^ (part as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15));
    let bb = *world.aabb(part);
    let extent = bb.maxs - bb.mins;
    let diag = world.assembly().diagonal();
    let mut query = Query {
        world,
        part,
        state,
        centre: (bb.mins + bb.maxs) * 0.5,
        radius: extent.length() * 0.5,
        step: config.step_fraction * diag,
        blockers: PartSet::empty(world.num_parts() + 1),
    };
    let identity = Config { t: Vec3::ZERO, r: Rot::IDENTITY };
    let start = Tree { nodes: vec![identity], parent: vec![None] };
    let mut goal = Tree { nodes: Vec::new(), parent: Vec::new() };
    for dir in world.directions() {
        let q = Config { t: *dir * world.clearance(part, state, *dir), r: Rot::IDENTITY };
        if query.free(&q) {
            goal.push(q, None);
        }
    }
    if goal.nodes.is_empty() {
        return Err(query.blockers);
    }
    // the sampling box: the bounds of the present parts, grown by the part's size
    let mut lo = bb.mins;
    let mut hi = bb.maxs;
    for q in state.iter().filter(|&q| q < world.num_parts()) {
        lo = lo.min(world.aabb(q).mins);
        hi = hi.max(world.aabb(q).maxs);
    }
    lo -= extent;
    hi += extent;
    let mut trees = (start, goal);
    let mut start_is_first = true;
    for _ in 0..config.max_iterations {
        if start_time.elapsed() > config.max_time {
            break;
        }
        let centre = Vec3::new(rng.random_range(lo.x..=hi.x), rng.random_range(lo.y..=hi.y), rng.random_range(lo.z..=hi.z));
        let r = if config.rotate {
            let u: f32 = rng.random();
            let random = Rot::from_xyzw(
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
            )
            .normalize();
            Rot::IDENTITY.slerp(random, u * u)
        } else {
            Rot::IDENTITY
        };
        let target = Config { t: centre - query.centre, r };
        if let Some((new, _)) = query.extend(&mut trees.0, &target) {
            let q = trees.0.nodes[new];
            if let Some(met) = query.connect(&mut trees.1, &q) {
                let (a, b) = if start_is_first { (&trees.0, &trees.1) } else { (&trees.1, &trees.0) };
                let (ia, ib) = if start_is_first { (new, met) } else { (met, new) };
                let mut path = a.path_to_root(ia);
                path.reverse();
                path.extend(b.path_to_root(ib).into_iter().skip(1));
                let path = query.shortcut(path);
                let poses = path.iter().map(|q| query.pose(q)).collect();
                return Ok(Motion::Path { poses, pivot: query.centre });
            }
        }
        std::mem::swap(&mut trees.0, &mut trees.1);
        start_is_first = !start_is_first;
    }
    Err(query.blockers)
}
