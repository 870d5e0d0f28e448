//! The arm's joint space while it holds a part: the [`Space`] the path planner searches.
//!
//! A space checks configurations either with spheres ([`SphereSpace`]: the exact verdict, the
//! exact test only near contact; what the planner searches with) or with the exact shapes alone
//! (the primitives against the parts at every shape; the final re-check of a returned path).

use super::fast::{Found, SphereSpace, Walk};
use super::*;

/// How a space checks one configuration.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Check {
    /// Spheres first, the exact test where a sphere comes near something.
    Spheres,
    /// The exact test of every shape (and the boxes' clearance).
    Exact,
}

/// The joint space of the arm holding part `p` with a grasp: valid when neither the robot nor
/// the held part collides.
pub(super) struct ArmSpace<'a, W: Borrow<World>> {
    planner: &'a RemovalPlanner<W>,
    part: usize,
    /// The held part, shrunk by the margin.
    shrunk: &'a TriMesh,
    /// The tool pose at the grasp (the part in its assembled pose).
    grasp_inv: Pose,
    opening: f32,
    obstacles: &'a Obstacles,
    limits: Vec<(f64, f64)>,
    /// Per joint, a bound on the displacement of any point of the robot or the held part per
    /// radian of that joint's motion, metres.
    levers: Vec<f64>,
    resolution: f64,
    /// Link poses of the last check (reused buffer).
    poses: std::cell::RefCell<Vec<Pose>>,
    /// A configuration between two others (reused buffer of the edge walk).
    between: std::cell::RefCell<Vec<f64>>,
    /// The sphere check (`None` in an exact space, and when [`RemovalConfig::sphere_check`] is
    /// off).
    spheres: Option<SphereSpace<'a, W>>,
    /// Verdicts by the exact shapes alone (clearance from the boxes).
    exact: bool,
    checks: std::cell::Cell<(u64, u64)>,
    /// Every 32nd check and edge walk is timed: (checks timed, nanoseconds).
    timed: std::cell::Cell<(u64, u64)>,
    /// Edge walks so far.
    edges: std::cell::Cell<u64>,
    /// Per body, the most its points move between two samples of the current edge.
    reach: std::cell::RefCell<Vec<f64>>,
    /// Edge samples skipped by their clearance.
    skipped: std::cell::Cell<u64>,
}

impl<W: Borrow<World>> Drop for ArmSpace<'_, W> {
    fn drop(&mut self) {
        let (robot, held) = self.checks.get();
        let counters = &self.planner.counters;
        counters.add(C::RobotChecks, robot);
        counters.add(C::HeldChecks, held);
        counters.add(C::Skipped, self.skipped.get());
        let (timed, ns) = self.timed.get();
        if !self.exact {
            counters.add(C::SphereTimed, timed);
            counters.add(C::SphereNs, ns);
        } else {
            counters.add(C::ExactChecks, robot);
            counters.add(C::ExactTimed, timed);
            counters.add(C::ExactNs, ns);
        }
    }
}

impl<'a, W: Borrow<World>> ArmSpace<'a, W> {
    #[allow(clippy::too_many_arguments)] // the held part, its grasp, the state, and how to check
    pub(super) fn new(
        planner: &'a RemovalPlanner<W>,
        part: usize,
        shrunk: &'a TriMesh,
        grasp: Pose,
        opening: f32,
        obstacles: &'a Obstacles,
        resolution: f32,
        check: Check,
    ) -> Self {
        let robot = &planner.cell.robot;
        // every point of the held part lies this close to the tool centre
        let bb = planner.world().shapes().aabb(part);
        let mut held_reach: f64 = 0.0;
        for i in 0..8 {
            let corner = Vec3::new(
                if i & 1 == 0 { bb.mins.x } else { bb.maxs.x },
                if i & 2 == 0 { bb.mins.y } else { bb.maxs.y },
                if i & 4 == 0 { bb.mins.z } else { bb.maxs.z },
            );
            held_reach = held_reach.max((corner - grasp.translation).length() as f64);
        }
        let mut levers = robot.lever_arms(held_reach.max(planner.gripper_reach) + 1e-3);
        let levers_len = levers.len();
        if !planner.config.per_joint_levers {
            let max = levers.iter().copied().fold(0.0, f64::max);
            levers.iter_mut().for_each(|l| *l = max);
        }
        ArmSpace {
            planner,
            part,
            shrunk,
            grasp_inv: grasp.inverse(),
            opening,
            obstacles,
            limits: robot.limits(),
            levers,
            resolution: resolution as f64,
            poses: std::cell::RefCell::new(Vec::with_capacity(planner.arm.len())),
            between: std::cell::RefCell::new(Vec::with_capacity(levers_len)),
            spheres: (planner.config.sphere_check && check == Check::Spheres)
                .then(|| SphereSpace::new(planner, part, shrunk, grasp, opening, obstacles)),
            exact: check == Check::Exact || !planner.config.sphere_check,
            checks: std::cell::Cell::new((0, 0)),
            timed: std::cell::Cell::new((0, 0)),
            edges: std::cell::Cell::new(0),
            reach: std::cell::RefCell::new(Vec::new()),
            skipped: std::cell::Cell::new(0),
        }
    }

    /// Whether `q` is collision-free; if so, with `clearance: Some(need)`, a lower bound on how
    /// far every point of the robot and the held part may move before anything collides
    /// (metres; 0 when below `need` or without `clearance`).
    pub(super) fn check(&self, q: &[f64], clearance: Option<f32>) -> Option<f32> {
        if !self.checks.get().0.is_multiple_of(32) {
            return self.check_untimed(q, clearance);
        }
        let started = Instant::now();
        let out = self.check_untimed(q, clearance);
        let (timed, ns) = self.timed.get();
        self.timed.set((timed + 1, ns + started.elapsed().as_nanos() as u64));
        out
    }

    fn check_untimed(&self, q: &[f64], clearance: Option<f32>) -> Option<f32> {
        // an exact space has no sphere check: the exact verdict and the boxes' clearance
        let Some(spheres) = &self.spheres else { return self.check_exact(q, clearance) };
        let (robot, held) = self.checks.get();
        match spheres.check(q, clearance) {
            Found::Robot => {
                self.checks.set((robot + 1, held));
                None
            }
            Found::Held => {
                self.checks.set((robot + 1, held + 1));
                None
            }
            Found::Free(c) => {
                self.checks.set((robot + 1, held + 1));
                Some(c)
            }
        }
    }

    /// [`ArmSpace::check`] with the exact shapes (f64 forward kinematics, every shape against
    /// the parts near it, the boxes' clearance).
    fn check_exact(&self, q: &[f64], clearance: Option<f32>) -> Option<f32> {
        let planner = self.planner;
        let mut poses = self.poses.borrow_mut();
        let tool = planner.cell.robot.collision_link_poses(q, self.opening, &mut poses);
        let placed = world_shapes(&planner.arm, &poses);
        let (robot, held) = self.checks.get();
        if planner.shapes_collide(&placed, 0, self.obstacles) || planner.self_collides(&placed) {
            self.checks.set((robot + 1, held));
            return None;
        }
        self.checks.set((robot + 1, held + 1));
        let displacement = tool * self.grasp_inv;
        if planner.held_collides(self.part, self.shrunk, &displacement, self.obstacles) {
            return None;
        }
        let Some(need) = clearance else { return Some(0.0) };
        let held_box = planner.world().shapes().aabb(self.part).transform_by(&displacement);
        Some(planner.clearance(&placed, &held_box, self.obstacles, need))
    }

    /// The sum of the tool centre's translations along the trajectory sampled at this space's
    /// resolution (eq. 5.2-5.3), or `None` when it is not below `below`: decided, where it can
    /// be, on the polylines through the waypoints and through every fifth sample, which are no
    /// longer (their corners are samples of the fine one).
    pub(super) fn tool_travel_below(&self, joints: &[Vec<f64>], below: f64) -> Option<f64> {
        let model = &self.planner.model;
        let mut frames = Vec::new();
        let mut q = Vec::new();
        let mut length = |every: usize| {
            let mut last = model.tool_position(&joints[0], &mut frames);
            let mut sum = 0.0;
            for w in joints.windows(2) {
                let n = self.samples(&w[0], &w[1]);
                for i in (every..=n).step_by(every) {
                    lerp_into(&w[0], &w[1], i as f64 / n as f64, &mut q);
                    let p = model.tool_position(&q, &mut frames);
                    sum += (p - last).length() as f64;
                    last = p;
                }
            }
            sum
        };
        let chords: f64 = joints
            .windows(2)
            .map(|w| (model.tool_position(&w[1], &mut Vec::new()) - model.tool_position(&w[0], &mut Vec::new())).length() as f64)
            .sum();
        if chords >= below || length(5) >= below {
            return None;
        }
        Some(length(1)).filter(|&l| l < below)
    }

    /// Samples along the edge from `a` to `b` at this space's resolution, a multiple of five.
    fn samples(&self, a: &[f64], b: &[f64]) -> usize {
        5 * (self.metric(a, b) / (5.0 * self.resolution)).ceil().max(1.0) as usize
    }

    /// [`Space::distance`]: each joint's motion times its lever arm, summed.
    fn metric(&self, a: &[f64], b: &[f64]) -> f64 {
        a.iter().zip(b).zip(&self.levers).map(|((x, y), l)| (x - y).abs() * l).sum::<f64>()
    }

    /// The tool centre's positions along the trajectory at this space's resolution (`f32`
    /// forward kinematics).
    pub(super) fn tool_samples(&self, joints: &[Vec<f64>]) -> Vec<Vec3> {
        let model = &self.planner.model;
        let mut frames = Vec::new();
        let mut q = joints[0].clone();
        let mut out = vec![model.tool_position(&q, &mut frames)];
        for w in joints.windows(2) {
            let n = (self.distance(&w[0], &w[1]) / self.resolution).ceil().max(1.0) as usize;
            for i in 1..=n {
                lerp_into(&w[0], &w[1], i as f64 / n as f64, &mut q);
                out.push(model.tool_position(&q, &mut frames));
            }
        }
        out
    }

    /// [`Space::valid`] of the configuration a fraction `t` from `a` to `b` (no allocation).
    fn check_between(&self, a: &[f64], b: &[f64], t: f64, clearance: Option<f32>) -> Option<f32> {
        let mut q = self.between.borrow_mut();
        lerp_into(a, b, t, &mut q);
        self.check(&q, clearance)
    }
}

impl<W: Borrow<World>> Space for ArmSpace<'_, W> {
    type State = Vec<f64>;

    fn sample(&self, rng: &mut ChaCha8Rng) -> Vec<f64> {
        self.limits.iter().map(|&(lo, hi)| if hi > lo { rng.random_range(lo..=hi) } else { lo }).collect()
    }

    fn valid(&self, q: &Vec<f64>) -> bool {
        self.check(q, None).is_some()
    }

    /// The evenly spaced samples of [`Space::edge_valid`], but a sample whose clearance bound
    /// shows that the next `s` samples cannot collide skips them: the same answer as testing
    /// every sample.
    fn edge_valid(&self, a: &Vec<f64>, b: &Vec<f64>) -> bool {
        let n = (self.distance(a, b) / self.resolution).ceil().max(1.0) as usize;
        if let (Some(spheres), true) = (&self.spheres, self.planner.config.clearance_skipping) {
            // shape by shape: each evaluated only where its clearance has run out
            let timed = self.edges.get().is_multiple_of(32);
            self.edges.set(self.edges.get() + 1);
            let started = timed.then(Instant::now);
            let mut walk = Walk::default();
            // per body, how far its points may move between two samples: the joints before it
            let mut reach = self.reach.borrow_mut();
            reach.clear();
            reach.push(0.0);
            for ((x, y), l) in a.iter().zip(b).zip(&self.levers) {
                let last = reach[reach.len() - 1];
                reach.push(last + (x - y).abs() * l / n as f64);
            }
            let free = spheres.edge_free(a, b, n, &reach, &mut walk);
            let (robot, held) = self.checks.get();
            self.checks.set((robot + walk.examined, held + walk.examined));
            self.skipped.set(self.skipped.get() + walk.skipped);
            if let Some(started) = started {
                let (t, ns) = self.timed.get();
                self.timed.set((t + walk.examined, ns + started.elapsed().as_nanos() as u64));
            }
            return free;
        }
        if !self.planner.config.clearance_skipping {
            return (1..n).all(|i| self.check_between(a, b, i as f64 / n as f64, None).is_some());
        }
        let step = self.distance(a, b) / n as f64;
        let mut i = 0;
        while i < n {
            let Some(c) = self.check_between(a, b, i as f64 / n as f64, Some(step as f32)) else {
                return false;
            };
            // samples i + 1 ..= i + s lie within c of sample i
            let s = if step > 0.0 { ((c as f64 - 1e-6) / step).floor().max(0.0) as usize } else { n };
            self.skipped.set(self.skipped.get() + s.min(n - 1 - i) as u64);
            i += s + 1;
        }
        true
    }

    fn interpolate(&self, a: &Vec<f64>, b: &Vec<f64>, t: f64) -> Vec<f64> {
        a.iter().zip(b).map(|(x, y)| x + (y - x) * t).collect()
    }

    /// An upper bound on how far any point of the robot or the held part moves from `a` to `b`
    /// (metres): each joint's motion times its lever arm bound ([`Robot::lever_arms`]), summed.
    fn distance(&self, a: &Vec<f64>, b: &Vec<f64>) -> f64 {
        self.metric(a, b)
    }

    fn edge_resolution(&self) -> f64 {
        self.resolution
    }
}

/// The arm holding a part with a grasp among one state's parts, checked one configuration at a
/// time: with spheres (what the planner searches with) or with the exact shapes alone (what it
/// re-checks a returned path with). Made by [`RemovalPlanner::with_arm_check`]; for tests and
/// benchmarks of the check itself.
pub struct ArmCheck<'a, W: Borrow<World>> {
    spheres: ArmSpace<'a, W>,
    exact: ArmSpace<'a, W>,
}

impl<'a, W: Borrow<World>> ArmCheck<'a, W> {
    pub(super) fn new(spheres: ArmSpace<'a, W>, exact: ArmSpace<'a, W>) -> Self {
        ArmCheck { spheres, exact }
    }

    /// Whether the configuration `q` is collision-free, by the sphere check.
    pub fn free(&self, q: &[f64]) -> bool {
        self.spheres.check(q, None).is_some()
    }

    /// Whether the configuration `q` is collision-free, by the exact shapes alone.
    pub fn free_exact(&self, q: &[f64]) -> bool {
        self.exact.check(q, None).is_some()
    }

    /// Whether the straight joint-space edge from `a` to `b` (both free) is collision-free at the
    /// planner's tree resolution ([`RemovalConfig::edge_resolution`]), by the sphere check.
    pub fn edge_free(&self, a: &[f64], b: &[f64]) -> bool {
        self.spheres.edge_valid(&a.to_vec(), &b.to_vec())
    }

    /// The same edge at the re-check's resolution ([`RemovalConfig::check_resolution`]), by the
    /// exact shapes alone.
    pub fn edge_free_exact(&self, a: &[f64], b: &[f64]) -> bool {
        self.exact.edge_valid(&a.to_vec(), &b.to_vec())
    }

    /// The interior samples [`ArmCheck::edge_free`] stands for: `a + (b − a) i/n` for
    /// `i = 1..n` (the walk skips those its clearances prove free).
    pub fn edge_samples(&self, a: &[f64], b: &[f64]) -> Vec<Vec<f64>> {
        let n = (self.spheres.metric(a, b) / self.spheres.resolution).ceil().max(1.0) as usize;
        (1..n)
            .map(|i| {
                let mut q = Vec::new();
                lerp_into(a, b, i as f64 / n as f64, &mut q);
                q
            })
            .collect()
    }
}

/// `out` = `a + (b − a) t`.
fn lerp_into(a: &[f64], b: &[f64], t: f64, out: &mut Vec<f64>) {
    out.clear();
    out.extend(a.iter().zip(b).map(|(x, y)| x + (y - x) * t));
}
