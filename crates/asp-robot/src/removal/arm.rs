//! The arm's joint space while it holds a part: the [`Space`] the path planner searches.

use super::*;

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
    checks: std::cell::Cell<(u64, u64)>,
    /// Edge samples skipped by their clearance.
    skipped: std::cell::Cell<u64>,
}

impl<W: Borrow<World>> Drop for ArmSpace<'_, W> {
    fn drop(&mut self) {
        let (robot, held) = self.checks.get();
        self.planner.counters.add(C::RobotChecks, robot);
        self.planner.counters.add(C::HeldChecks, held);
        self.planner.counters.add(C::Skipped, self.skipped.get());
    }
}

impl<'a, W: Borrow<World>> ArmSpace<'a, W> {
    pub(super) fn new(
        planner: &'a RemovalPlanner<W>,
        part: usize,
        shrunk: &'a TriMesh,
        grasp: Pose,
        opening: f32,
        obstacles: &'a Obstacles,
        resolution: f32,
    ) -> Self {
        let robot = &planner.cell.robot;
        // every point of the held part lies this close to the tool centre
        let bb = planner.world().aabb(part);
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
            checks: std::cell::Cell::new((0, 0)),
            skipped: std::cell::Cell::new(0),
        }
    }

    /// Whether `q` is collision-free; if so, with `clearance: Some(need)`, a lower bound on how
    /// far every point of the robot and the held part may move before anything collides
    /// (metres; 0 when below `need` or without `clearance`).
    pub(super) fn check(&self, q: &[f64], clearance: Option<f32>) -> Option<f32> {
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
        let held_box = planner.world().aabb(self.part).transform_by(&displacement);
        Some(planner.clearance(&placed, &held_box, self.obstacles, need))
    }

    /// The sum of the tool centre's translations along the trajectory sampled at this space's
    /// resolution (eq. 5.2-5.3).
    pub(super) fn tool_travel(&self, joints: &[Vec<f64>]) -> f64 {
        let pts = self.tool_samples(joints);
        pts.windows(2).map(|w| (w[1] - w[0]).length() as f64).sum()
    }

    /// The tool centre's positions along the trajectory at this space's resolution.
    pub(super) fn tool_samples(&self, joints: &[Vec<f64>]) -> Vec<Vec3> {
        let robot = &self.planner.cell.robot;
        let mut out = vec![robot.tool_pose(&joints[0]).translation];
        for w in joints.windows(2) {
            let n = (self.distance(&w[0], &w[1]) / self.resolution).ceil().max(1.0) as usize;
            for i in 1..=n {
                out.push(robot.tool_pose(&self.interpolate(&w[0], &w[1], i as f64 / n as f64)).translation);
            }
        }
        out
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
        if !self.planner.config.clearance_skipping {
            return (1..n).all(|i| self.valid(&self.interpolate(a, b, i as f64 / n as f64)));
        }
        let step = self.distance(a, b) / n as f64;
        let mut i = 0;
        while i < n {
            let Some(c) = self.check(&self.interpolate(a, b, i as f64 / n as f64), Some(step as f32)) else {
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
        a.iter().zip(b).zip(&self.levers).map(|((x, y), l)| (x - y).abs() * l).sum::<f64>()
    }

    fn edge_resolution(&self) -> f64 {
        self.resolution
    }
}
