//! RRT-Connect in SE(3): removal paths for parts that cannot leave along a straight line. The
//! removal space of the generic [`super::connect_trees`] and [`super::shortcut`].
//!
//! A configuration is the displacement of the part about the centre of its bounds: a
//! translation and a rotation. The start tree grows from the assembled pose; the goal tree from
//! collision-free poses just outside the bounds of what remains, one root per candidate
//! direction. Edges are checked exactly (continuous collision detection by parry's nonlinear
//! shape cast of the part shrunk by the tolerance), so a path never grazes deeper than the
//! tolerance; the path is shortcut greedily (no random attempts). Every failed check records the
//! part it hit: when no path is found, those are the blockers.

use super::{connect_trees, shortcut, Growth, Space};
use crate::feasibility::Motion;
use crate::math::{Pose, Rot, Vec3};
use crate::partset::PartSet;
use crate::world::World;
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::cell::RefCell;
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

/// A displacement of the part about the centre of its bounds.
#[derive(Clone, Copy, Debug)]
struct Config {
    t: Vec3,
    r: Rot,
}

/// The removal space of one (part, state) query: displacements of the part, valid when the part
/// displaced does not collide with the present parts. Every failed check records the part hit.
struct RemovalSpace<'a> {
    world: &'a World,
    part: usize,
    state: &'a PartSet,
    centre: Vec3,
    /// Weight of the rotation angle in [`Space::distance`]: half the part's box diagonal.
    radius: f32,
    /// The sampling box of the part's centre.
    lo: Vec3,
    hi: Vec3,
    rotate: bool,
    /// The parts hit by failed checks (the trait's checks take `&self`).
    blockers: RefCell<PartSet>,
}

impl RemovalSpace<'_> {
    fn pose(&self, q: &Config) -> Pose {
        // x' = c + R (x - c) + t
        Pose::from_parts(self.centre + q.t - q.r * self.centre, q.r)
    }

    fn blocked(&self, hit: Option<usize>) -> bool {
        match hit {
            Some(q) => {
                self.blockers.borrow_mut().insert(q);
                true
            }
            None => false,
        }
    }
}

impl Space for RemovalSpace<'_> {
    type State = Config;

    /// A centre uniform in the sampling box, then (with `rotate`) a rotation slerped from the
    /// identity towards a random one by the square of a uniform fraction.
    fn sample(&self, rng: &mut ChaCha8Rng) -> Config {
        let (lo, hi) = (self.lo, self.hi);
        let centre = Vec3::new(rng.random_range(lo.x..=hi.x), rng.random_range(lo.y..=hi.y), rng.random_range(lo.z..=hi.z));
        let r = if self.rotate {
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
        Config { t: centre - self.centre, r }
    }

    fn valid(&self, q: &Config) -> bool {
        !self.blocked(self.world.removal().collision_at(self.part, &self.pose(q), self.state))
    }

    /// Pivot straight, slerp about it (f32, as the plan's `path` motions).
    fn interpolate(&self, a: &Config, b: &Config, s: f64) -> Config {
        let s = s as f32;
        Config { t: a.t.lerp(b.t, s), r: a.r.slerp(b.r, s) }
    }

    /// Translation plus `radius` times the rotation angle (computed in f32; exact in f64).
    fn distance(&self, a: &Config, b: &Config) -> f64 {
        ((a.t - b.t).length() + self.radius * a.r.angle_between(b.r)) as f64
    }

    /// Exact: continuous collision detection over the whole edge, ends included.
    fn edge_valid(&self, a: &Config, b: &Config) -> bool {
        let (pa, pb) = (self.pose(a), self.pose(b));
        !self.blocked(self.world.removal().collision_between(self.part, &pa, &pb, self.centre, self.state))
    }

    /// None: [`Space::edge_valid`] is exact.
    fn edge_resolution(&self) -> f64 {
        f64::INFINITY
    }

    /// The exact edge check covers the new node.
    fn step_valid(&self, from: &Config, to: &Config) -> bool {
        self.edge_valid(from, to)
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
        return search(world, part, state, config, seed);
    }
    let half =
        RrtConfig { max_iterations: config.max_iterations.div_ceil(2), max_time: config.max_time / 2, rotate: false, ..config.clone() };
    search(world, part, state, &half, seed).or_else(|mut blockers| {
        let full = RrtConfig {
            max_iterations: config.max_iterations - half.max_iterations,
            max_time: config.max_time - half.max_time,
            ..config.clone()
        };
        search(world, part, state, &full, seed.wrapping_add(1)).map_err(|b| {
            blockers.union_with(&b);
            blockers
        })
    })
}

/// One RRT-Connect search within `config`'s budget: [`connect_trees`] from the assembled pose to
/// the free poses outside along each direction, then the greedy [`shortcut`].
fn search(world: &World, part: usize, state: &PartSet, config: &RrtConfig, seed: u64) -> std::result::Result<Motion, PartSet> {
    let start_time = Instant::now();
    let mut rng = ChaCha8Rng::seed_from_u64(seed ^ (part as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15));
    let bb = *world.shapes().aabb(part);
    let extent = bb.maxs - bb.mins;
    let diag = world.assembly().diagonal();
    // the sampling box: the bounds of the present parts, grown by the part's size
    let mut lo = bb.mins;
    let mut hi = bb.maxs;
    for q in state.iter().filter(|&q| q < world.num_parts()) {
        lo = lo.min(world.shapes().aabb(q).mins);
        hi = hi.max(world.shapes().aabb(q).maxs);
    }
    lo -= extent;
    hi += extent;
    let space = RemovalSpace {
        world,
        part,
        state,
        centre: (bb.mins + bb.maxs) * 0.5,
        radius: extent.length() * 0.5,
        lo,
        hi,
        rotate: config.rotate,
        blockers: RefCell::new(PartSet::empty(world.num_parts() + 1)),
    };
    let identity = Config { t: Vec3::ZERO, r: Rot::IDENTITY };
    let goals: Vec<Config> = world
        .blocking()
        .directions()
        .iter()
        .map(|dir| Config { t: *dir * world.removal().clearance(part, state, *dir), r: Rot::IDENTITY })
        .filter(|q| space.valid(q))
        .collect();
    if goals.is_empty() {
        return Err(space.blockers.into_inner());
    }
    let growth = Growth {
        step: (config.step_fraction * diag) as f64,
        max_iterations: config.max_iterations,
        deadline: start_time.checked_add(config.max_time),
    };
    match connect_trees(&space, &[identity], &goals, &growth, &mut rng) {
        Some(path) => {
            let path = shortcut(&space, path);
            let poses = path.iter().map(|q| space.pose(q)).collect();
            Ok(Motion::Path { poses, pivot: space.centre })
        }
        None => Err(space.blockers.into_inner()),
    }
}
