//! Robot removability (thesis 5.3): can the arm take a part out of a state, and how far does
//! its gripper travel doing so?
//!
//! The test is hierarchical, cheapest first:
//! 1. **Lift**: the part moves [`RemovalConfig::lift`] (5 cm) along its removal direction,
//!    collision-checked exactly with the world's sweep ([`World::collision_between`]).
//! 2. **Reachable grasps**: for each grasp of the part ([`crate::part_grasps`]), inverse
//!    kinematics of the grasp pose and of the lifted pose succeed, and neither the arm's links
//!    nor the gripper (opened to the grasp's width) collide with the parts still present or
//!    go below the floor.
//! 3. **Path**: a collision-free joint-space path of arm, gripper and held part from the lifted
//!    pose to the drop-off pose: RRT-Connect with shortcutting ([`crate::rrt`]), seeded, the
//!    whole trajectory re-validated at [`RemovalConfig::check_resolution`].
//!
//! The path length is the sum of the tool centre's translations between consecutive poses of
//! the trajectory sampled every [`RemovalConfig::check_resolution`] (eq. 5.2-5.3), lift
//! included; the part's length is the shortest over its reachable grasps (eq. 5.4), each
//! planned `k` times with different seeds (5.5.3). Reachable grasps are planned in increasing
//! order of a lower bound (the lift plus the straight distance from the lifted tool centre to the
//! drop-off point), stopping when the best length found is below the next bound or after
//! [`RemovalConfig::path_grasps`] grasps.
//!
//! Collisions: the robot's primitive shapes are shrunk by [`RemovalConfig::margin`] so that
//! touching is not colliding (fingers on the grasped part's neighbours); the held part is tested
//! with the world's exact, eroded static test ([`World::collision_at`]). Self-collision of the
//! arm and collisions between the arm and the part it holds are not checked.

use std::borrow::Borrow;
use std::sync::OnceLock;

use asp_geom::math::{Pose, Rot, Vec3};
use asp_geom::{Assembly, Grasp, PartSet, World};
use parry3d::bounding_volume::{Aabb, BoundingVolume};
use parry3d::query;
use parry3d::shape::{HalfSpace, SharedShape};
use rand::RngExt;
use rand_chacha::ChaCha8Rng;

use crate::grasp::{part_grasps, GraspConfig};
use crate::ik::IkConfig;
use crate::robot::Robot;
use crate::rrt::{rrt_connect, RrtConnectConfig, Space};
use crate::shape::{LinkShape, ShapeKind};

/// Settings of the robot removal test.
#[derive(Clone, Debug)]
pub struct RemovalConfig {
    /// The lift along the removal direction, metres (thesis: 5 cm).
    pub lift: f32,
    /// `k`: path plans per grasp, each with its own seed; the shortest is kept (5.5.3).
    pub replans: usize,
    /// At most this many reachable grasps get a path plan (lowest lower bound first).
    pub path_grasps: usize,
    /// Inverse kinematics of grasp, lift and drop-off poses.
    pub ik: IkConfig,
    /// Grasps computed for parts without grasps in their metadata.
    pub grasp: GraspConfig,
    /// The joint-space path planner (its seed is replaced per plan).
    pub rrt: RrtConnectConfig,
    /// The largest displacement of any point of the arm, gripper or held part between two
    /// configurations checked along a tree edge, metres.
    pub edge_resolution: f32,
    /// The same for the final trajectory's re-check and its length, metres.
    pub check_resolution: f32,
    /// The robot's shapes are shrunk by this much (touching is not colliding), metres.
    pub margin: f32,
}

impl Default for RemovalConfig {
    fn default() -> Self {
        RemovalConfig {
            lift: 0.05,
            replans: 4,
            path_grasps: 6,
            ik: IkConfig { max_iterations: 60, restarts: 3, position_tolerance: 1e-4, rotation_tolerance: 1e-3, ..IkConfig::default() },
            grasp: GraspConfig::default(),
            rrt: RrtConnectConfig { step: 0.4, max_iterations: 1500, shortcut_attempts: 40, seed: 0 },
            edge_resolution: 0.01,
            check_resolution: 0.002,
            margin: 0.001,
        }
    }
}

/// Where the robot stands and where it puts parts down.
#[derive(Clone, Debug)]
pub struct RobotCell {
    /// The robot, its base placed ([`Robot::base_pose`]).
    pub robot: Robot,
    /// Where the tool centre puts a removed part down, world frame, metres.
    pub drop_off: Vec3,
    /// The up direction (gravity points the other way).
    pub up: Vec3,
    /// The floor's height along `up`: no link but the base may go below it.
    pub floor: f32,
}

impl RobotCell {
    /// The default cell for `assembly`: the base on the floor (the model's lowest point along
    /// up), 0.3 m in front of the model's bounds on the −x side (−y when up is x), centred on
    /// it; the drop-off point 0.5 m to the robot's side and 0.4 m above the floor. Overrides:
    /// `base` (a position; the base's z axis points up) and `drop_off`, world frame, metres.
    pub fn for_assembly(assembly: &Assembly, robot: Robot, base: Option<Vec3>, drop_off: Option<Vec3>) -> RobotCell {
        let up = assembly.up.vector();
        let (mut lo, mut hi) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
        for p in &assembly.parts {
            for v in &p.mesh.vertices {
                lo = lo.min(*v);
                hi = hi.max(*v);
            }
        }
        if !lo.is_finite() {
            (lo, hi) = (Vec3::ZERO, Vec3::ZERO);
        }
        let centre = (lo + hi) * 0.5;
        let floor = lo.dot(up).min(hi.dot(up));
        let front = if up.x.abs() > 0.5 { Vec3::NEG_Y } else { Vec3::NEG_X };
        let half = ((hi - lo) * 0.5).dot(front.abs());
        let on_floor = |p: Vec3| p - up * (p.dot(up) - floor);
        let base_at = base.unwrap_or_else(|| on_floor(centre + front * (half + 0.3)));
        let side = up.cross(front).normalize_or_zero();
        let drop = drop_off.unwrap_or_else(|| on_floor(base_at) + side * 0.5 + up * 0.4);
        let rotation = Rot::from_rotation_arc(Vec3::Z, up);
        let robot = robot.with_base_pose(Pose::from_parts(base_at, rotation));
        RobotCell { robot, drop_off: drop, up, floor }
    }
}

/// Why the robot cannot take a part out.
#[derive(Clone, Debug, PartialEq)]
pub enum RobotFailure {
    /// The lift along the removal direction collides with a part (`None`: the part's removal
    /// is not a straight line the robot could lift along).
    Blocked {
        /// The part hit.
        by: Option<usize>,
    },
    /// No grasp is reachable without collision.
    NoReachableGrasp {
        /// Grasps of the part.
        grasps: usize,
        /// Grasps whose pose (or lifted pose) inverse kinematics did not reach.
        unreachable: usize,
        /// Grasps reached only with the arm or gripper colliding (at the grasp or the lift).
        colliding: usize,
    },
    /// Grasps are reachable but no collision-free path to the drop-off was found: the drop-off
    /// pose is unreachable or in collision with the part in hand, or the path planner found no
    /// path within its budget.
    NoPath {
        /// Reachable grasps.
        reachable: usize,
        /// Of those, grasps whose drop-off pose is unreachable or in collision.
        drop_off_blocked: usize,
        /// Reachable grasps given to the path planner.
        grasps_tried: usize,
    },
}

impl RobotFailure {
    /// The short reason (`blocked`, `no reachable grasp`, `no path`), as filters count them.
    pub fn reason(&self) -> &'static str {
        match self {
            RobotFailure::Blocked { .. } => "blocked",
            RobotFailure::NoReachableGrasp { .. } => "no reachable grasp",
            RobotFailure::NoPath { .. } => "no path",
        }
    }

    /// Index of [`RobotFailure::reason`] in [`RobotFailure::REASONS`].
    pub fn index(&self) -> usize {
        match self {
            RobotFailure::Blocked { .. } => 0,
            RobotFailure::NoReachableGrasp { .. } => 1,
            RobotFailure::NoPath { .. } => 2,
        }
    }

    /// Every reason, in [`RobotFailure::index`] order.
    pub const REASONS: [&'static str; 3] = ["blocked", "no reachable grasp", "no path"];
}

impl std::fmt::Display for RobotFailure {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            RobotFailure::Blocked { by: Some(by) } => write!(f, "blocked: the lift collides with part {by}"),
            RobotFailure::Blocked { by: None } => write!(f, "blocked: the removal is not a straight lift"),
            RobotFailure::NoReachableGrasp { grasps, unreachable, colliding } => {
                write!(f, "no reachable grasp: of {grasps} grasps {unreachable} are out of reach, {colliding} collide")
            }
            RobotFailure::NoPath { reachable, drop_off_blocked, grasps_tried } => write!(
                f,
                "no path: {reachable} reachable grasps, {drop_off_blocked} cannot put the part down at the drop-off, no collision-free path from {grasps_tried}"
            ),
        }
    }
}

/// How the robot takes a part out.
#[derive(Clone, Debug, PartialEq)]
pub struct RobotRemoval {
    /// The grasp used.
    pub grasp: Grasp,
    /// Its index among the part's grasps.
    pub grasp_index: usize,
    /// The lift direction (unit).
    pub direction: Vec3,
    /// Joint waypoints: the grasp, the lifted pose, then the path to the drop-off. Between two
    /// waypoints the joints move linearly.
    pub joints: Vec<Vec<f64>>,
    /// The tool centre's positions along the trajectory, sampled every
    /// [`RemovalConfig::edge_resolution`] or closer (world frame, metres).
    pub gripper_path: Vec<Vec3>,
    /// The path length (eq. 5.3): the tool centre's travel, metres.
    pub length: f64,
    /// Grasps that were reachable (grasp and lift collision-free).
    pub reachable_grasps: usize,
}

/// A robot shape ready for collision tests: parry shape shrunk by the margin, the pose of it in
/// the link frame, and whether it belongs to the (fixed) base link.
struct Prepared {
    local: Pose,
    shape: SharedShape,
}

fn shrunk(s: &LinkShape, margin: f32) -> (Pose, SharedShape) {
    let m = margin;
    let k = match s.kind {
        ShapeKind::Box { half_extents } => ShapeKind::Box { half_extents: (half_extents - Vec3::splat(m)).max(Vec3::splat(1e-4)) },
        ShapeKind::Cylinder { radius, half_length } => {
            ShapeKind::Cylinder { radius: (radius - m).max(1e-4), half_length: (half_length - m).max(1e-4) }
        }
        ShapeKind::Capsule { radius, half_length } => ShapeKind::Capsule { radius: (radius - m).max(1e-4), half_length },
        ShapeKind::Sphere { radius } => ShapeKind::Sphere { radius: (radius - m).max(1e-4) },
    };
    let ls = LinkShape { local_pose: s.local_pose, kind: k };
    let (fix, shape) = ls.to_parry();
    (s.local_pose * fix, shape)
}

/// Plans robot removals of the parts of one collision world (`W`: a `&World`, an
/// `Arc<World>`, or anything else that borrows one).
pub struct RemovalPlanner<W: Borrow<World>> {
    world: W,
    cell: RobotCell,
    config: RemovalConfig,
    grasps: Vec<OnceLock<Vec<Grasp>>>,
    /// Per link shape index in [`Robot::collision_shapes`] order: the prepared shape.
    arm: Vec<Prepared>,
    /// How many of the leading arm shapes belong to the base link (never moves; not checked
    /// against the floor).
    base_shapes: usize,
    floor: (Pose, SharedShape),
}

impl<W: Borrow<World>> std::fmt::Debug for RemovalPlanner<W> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("RemovalPlanner").field("robot", &self.cell.robot.name).field("config", &self.config).finish_non_exhaustive()
    }
}

impl<W: Borrow<World>> RemovalPlanner<W> {
    /// A planner for the parts of `world` with the robot `cell`.
    pub fn new(world: W, cell: RobotCell, config: RemovalConfig) -> Self {
        let robot = &cell.robot;
        let q = robot.mid_configuration();
        let base_shapes = robot.links()[0].shapes.len();
        // the shapes in the order collision_shapes emits them: the arm's links base first, then
        // the links rigid with the tool from the tool centre back, then the fingers
        let arm_count = robot.arm_shapes(&q).len();
        let links = robot.links();
        let (mut start, mut acc) = (0, 0);
        while start < links.len() && acc < arm_count {
            acc += links[start].shapes.len();
            start += 1;
        }
        let mut arm = Vec::new();
        for l in links[..start].iter().chain(links[start..].iter().rev()) {
            for s in &l.shapes {
                let (local, shape) = shrunk(s, config.margin);
                arm.push(Prepared { local, shape });
            }
        }
        for f in robot.fingers() {
            for s in &f.link.shapes {
                let (local, shape) = shrunk(s, config.margin);
                arm.push(Prepared { local, shape });
            }
        }
        debug_assert_eq!(arm.len(), robot.collision_shapes(&q, 0.0).len());
        let floor_pose = Pose::from_parts(cell.up * cell.floor, Rot::IDENTITY);
        let floor = (floor_pose, SharedShape::new(HalfSpace::new(cell.up)));
        let grasps = (0..world.borrow().num_parts()).map(|_| OnceLock::new()).collect();
        RemovalPlanner { world, cell, config, grasps, arm, base_shapes, floor }
    }

    /// The robot cell.
    pub fn cell(&self) -> &RobotCell {
        &self.cell
    }

    /// The settings.
    pub fn config(&self) -> &RemovalConfig {
        &self.config
    }

    /// The collision world.
    pub fn world(&self) -> &World {
        self.world.borrow()
    }

    /// The grasps of part `p` (computed once).
    pub fn grasps(&self, p: usize) -> &[Grasp] {
        self.grasps[p].get_or_init(|| {
            let cfg = GraspConfig { max_opening: self.cell.robot.max_opening(), ..self.config.grasp.clone() };
            part_grasps(&self.world().assembly().parts[p], &cfg)
        })
    }

    /// The obstacles of a state: the present parts (fixed ones and the ground included) but `held`.
    fn obstacles(&self, present: &PartSet, held: usize) -> Vec<usize> {
        self.world().with_fixed(present).iter().filter(|&q| q != held).collect()
    }

    /// Whether the robot at `q` with the gripper opened to `opening` collides with an obstacle
    /// or goes below the floor.
    fn robot_collides(&self, q: &[f64], opening: f32, obstacles: &[usize]) -> bool {
        let shapes = self.cell.robot.collision_shapes(q, opening);
        for (k, ((link_pose, _), prepared)) in shapes.iter().zip(&self.arm).enumerate() {
            let pose = *link_pose * prepared.local;
            let bb: Aabb = prepared.shape.compute_aabb(&pose);
            if k >= self.base_shapes && bb.mins.dot(self.cell.up).min(bb.maxs.dot(self.cell.up)) < self.cell.floor + 0.5 {
                // the box may reach below the floor: exact test against the half-space
                if query::intersection_test(&pose, &*prepared.shape, &self.floor.0, &*self.floor.1).is_ok_and(|i| i.intersecting) {
                    return true;
                }
            }
            for &o in obstacles {
                let world = self.world();
                if !bb.intersects(world.aabb(o)) {
                    continue;
                }
                if k < self.base_shapes && world.ground() == Some(o) {
                    continue; // the base stands on the ground
                }
                if query::intersection_test(&pose, &*prepared.shape, &Pose::IDENTITY, world.mesh(o))
                    .is_ok_and(|i| i.intersecting)
                {
                    return true;
                }
            }
        }
        false
    }

    /// Whether part `p`, displaced by `pose` from its assembled pose and shrunk by the margin
    /// (at least the world's tolerance), crosses an obstacle (exact triangle tests).
    fn held_collides(&self, p: usize, pose: &Pose, obstacles: &[usize]) -> bool {
        let world = self.world();
        let shrunk = world.eroded(p, self.config.margin.max(world.tolerance()));
        let bb = world.aabb(p).transform_by(pose);
        obstacles.iter().any(|&o| bb.intersects(world.aabb(o)) && asp_geom::sweep::meshes_cross_at(&shrunk, pose, world.mesh(o)))
    }

    /// Plans the removal of part `p` from `present` (which holds it) lifted along `direction`
    /// (unit), with `replans` path plans per grasp from seeds derived from `seed`.
    pub fn plan(&self, p: usize, present: &PartSet, direction: Vec3, seed: u64, replans: usize) -> Result<RobotRemoval, RobotFailure> {
        let world = self.world();
        let robot = &self.cell.robot;
        let bb = world.aabb(p);
        let pivot = (bb.mins + bb.maxs) * 0.5;
        let lift = Pose::from_translation(direction * self.config.lift);
        if let Some(by) = world.collision_between(p, &Pose::IDENTITY, &lift, pivot, present) {
            return Err(RobotFailure::Blocked { by: Some(by) });
        }
        let obstacles = self.obstacles(present, p);
        let grasps = self.grasps(p);
        let part_radius = (bb.maxs - bb.mins).length() * 0.5;
        // reachable grasps: (grasp index, q at grasp, q lifted, q at drop-off, lower bound)
        let mut reachable = Vec::new();
        let (mut unreachable, mut colliding, mut no_drop) = (0, 0, 0);
        let mut reached = 0;
        let mut last_solution: Option<Vec<f64>> = None;
        for (gi, g) in grasps.iter().enumerate() {
            let tool = Pose::from_parts(g.position, g.orientation);
            let ik = IkConfig { seed: seed ^ (gi as u64).wrapping_mul(0x9e37_79b9), ..self.config.ik.clone() };
            let Some(qg) = robot.ik(&tool, last_solution.as_deref(), &ik).solution().map(|s| s.joints.clone()) else {
                unreachable += 1;
                continue;
            };
            let lifted = lift * tool;
            let Some(ql) = robot.ik(&lifted, Some(&qg), &IkConfig { restarts: 0, ..ik.clone() }).solution().map(|s| s.joints.clone())
            else {
                unreachable += 1;
                continue;
            };
            last_solution = Some(qg.clone());
            let space = ArmSpace::new(self, p, robot.tool_pose(&qg), g.width, &obstacles, part_radius, self.config.edge_resolution);
            if !space.valid(&qg) || !space.valid(&ql) || !space.edge_valid(&qg, &ql) {
                colliding += 1;
                continue;
            }
            reached += 1;
            // drop-off: the lifted orientation first, then the gripper pointing down
            let mut qd = None;
            let down = Rot::from_rotation_arc(Vec3::Z, -self.cell.up);
            for (k, rot) in [lifted.rotation, down, down * Rot::from_rotation_z(std::f32::consts::FRAC_PI_2)].into_iter().enumerate() {
                let target = Pose::from_parts(self.cell.drop_off, rot);
                let cfg = IkConfig { seed: ik.seed ^ (k as u64 + 1), ..ik.clone() };
                if let Some(s) = robot.ik(&target, Some(&ql), &cfg).solution() {
                    if space.valid(&s.joints) {
                        qd = Some(s.joints.clone());
                        break;
                    }
                }
            }
            let Some(qd) = qd else {
                no_drop += 1;
                continue;
            };
            let bound = self.config.lift as f64 + (lifted.translation - self.cell.drop_off).length() as f64;
            reachable.push((gi, qg, ql, qd, bound));
        }
        if reached == 0 {
            return Err(RobotFailure::NoReachableGrasp { grasps: grasps.len(), unreachable, colliding });
        }
        reachable.sort_by(|a, b| a.4.total_cmp(&b.4).then(a.0.cmp(&b.0)));
        let mut best: Option<RobotRemoval> = None;
        let mut tried = 0;
        for (gi, qg, ql, qd, bound) in reachable.into_iter().take(self.config.path_grasps.max(1)) {
            if best.as_ref().is_some_and(|b| b.length <= bound) {
                break;
            }
            tried += 1;
            let g = &grasps[gi];
            let tool = robot.tool_pose(&qg);
            let space = ArmSpace::new(self, p, tool, g.width, &obstacles, part_radius, self.config.edge_resolution);
            let fine = ArmSpace::new(self, p, tool, g.width, &obstacles, part_radius, self.config.check_resolution);
            for r in 0..replans.max(1) {
                let cfg = RrtConnectConfig { seed: seed ^ ((gi as u64) << 20) ^ (r as u64).wrapping_mul(0x5851_f42d_4c95_7f2d), ..self.config.rrt.clone() };
                let Ok(path) = rrt_connect(&space, &ql, &qd, &cfg) else { continue };
                let mut joints = vec![qg.clone()];
                joints.extend(path);
                if !joints.windows(2).all(|w| fine.edge_valid(&w[0], &w[1])) {
                    continue;
                }
                let length = fine.tool_travel(&joints);
                if best.as_ref().is_none_or(|b| length < b.length) {
                    let gripper_path = space.tool_samples(&joints);
                    best = Some(RobotRemoval {
                        grasp: g.clone(),
                        grasp_index: gi,
                        direction,
                        joints,
                        gripper_path,
                        length,
                        reachable_grasps: reached,
                    });
                }
            }
        }
        best.ok_or(RobotFailure::NoPath { reachable: reached, drop_off_blocked: no_drop, grasps_tried: tried })
    }
}

/// The joint space of the arm holding part `p` with a grasp: valid when neither the robot nor
/// the held part collides.
struct ArmSpace<'a, W: Borrow<World>> {
    planner: &'a RemovalPlanner<W>,
    part: usize,
    /// The tool pose at the grasp (the part in its assembled pose).
    grasp_inv: Pose,
    opening: f32,
    obstacles: &'a [usize],
    limits: Vec<(f64, f64)>,
    /// Bound on the displacement of any point per radian of joint motion (L1), metres.
    lever: f64,
    resolution: f64,
}

impl<'a, W: Borrow<World>> ArmSpace<'a, W> {
    fn new(
        planner: &'a RemovalPlanner<W>,
        part: usize,
        grasp: Pose,
        opening: f32,
        obstacles: &'a [usize],
        part_radius: f32,
        resolution: f32,
    ) -> Self {
        let robot = &planner.cell.robot;
        // a point of the held part lies within the part's diameter of the tool centre
        let lever = robot.reach_bound() + 0.15 + 2.0 * part_radius as f64;
        ArmSpace {
            planner,
            part,
            grasp_inv: grasp.inverse(),
            opening,
            obstacles,
            limits: robot.limits(),
            lever,
            resolution: resolution as f64,
        }
    }

    /// The sum of the tool centre's translations along the trajectory sampled at this space's
    /// resolution (eq. 5.2-5.3).
    fn tool_travel(&self, joints: &[Vec<f64>]) -> f64 {
        let pts = self.tool_samples(joints);
        pts.windows(2).map(|w| (w[1] - w[0]).length() as f64).sum()
    }

    /// The tool centre's positions along the trajectory at this space's resolution.
    fn tool_samples(&self, joints: &[Vec<f64>]) -> Vec<Vec3> {
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
        if self.planner.robot_collides(q, self.opening, self.obstacles) {
            return false;
        }
        let tool = self.planner.cell.robot.tool_pose(q);
        let displacement = tool * self.grasp_inv;
        !self.planner.held_collides(self.part, &displacement, self.obstacles)
    }

    fn interpolate(&self, a: &Vec<f64>, b: &Vec<f64>, t: f64) -> Vec<f64> {
        a.iter().zip(b).map(|(x, y)| x + (y - x) * t).collect()
    }

    /// An upper bound on how far any point of the robot or the held part moves from `a` to `b`
    /// (metres): the L1 joint distance times a lever arm bound.
    fn distance(&self, a: &Vec<f64>, b: &Vec<f64>) -> f64 {
        a.iter().zip(b).map(|(x, y)| (x - y).abs()).sum::<f64>() * self.lever
    }

    fn edge_resolution(&self) -> f64 {
        self.resolution
    }
}
