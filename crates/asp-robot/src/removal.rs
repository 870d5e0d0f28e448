//! Robot removability (thesis 5.3): can the arm take a part out of a state, and how far does
//! its gripper travel doing so?
//!
//! The test is hierarchical, cheapest first:
//! 1. **Lift**: the part moves [`RemovalConfig::lift`] (5 cm) along its removal direction,
//!    collision-checked exactly with the world's sweep ([`World::collision_between`]).
//! 2. **Reachable grasps**: for a grasp of the part ([`crate::part_grasps`]), the gripper
//!    alone (opened to the grasp's width, placed at the grasp and at the lifted pose; no
//!    inverse kinematics needed) is collision-free, inverse kinematics of the grasp pose and of
//!    the lifted pose succeed, and neither the arm's links nor the gripper collide with the
//!    parts still present, go below the floor or collide with each other.
//! 3. **Path**: a collision-free joint-space path of arm, gripper and held part from the lifted
//!    pose to the drop-off pose: RRT-Connect with shortcutting ([`crate::rrt`]), seeded, the
//!    whole trajectory re-validated at [`RemovalConfig::check_resolution`].
//!
//! The path length is the sum of the tool centre's translations between consecutive poses of
//! the trajectory sampled every [`RemovalConfig::check_resolution`] (eq. 5.2-5.3), lift
//! included; the part's length is the shortest over its reachable grasps (eq. 5.4), each
//! planned `k` times with different seeds (5.5.3). Grasps are examined in increasing order of
//! a lower bound of their length (the lift plus the straight distance from the lifted tool
//! centre to the drop-off point, less the inverse kinematics' tolerances) and each reachable
//! one is planned at once; the search stops when the best length found is no longer than the
//! next grasp's bound (exact: no later grasp can be shorter) or after
//! [`RemovalConfig::path_grasps`] planned grasps (a cap; `usize::MAX` makes the search exact).
//!
//! Collisions: the robot's primitive shapes are shrunk by [`RemovalConfig::margin`] so that
//! touching is not colliding (fingers on the grasped part's neighbours); the held part is tested
//! with the world's exact, eroded static test ([`asp_geom::sweep::meshes_cross_at`] on the part
//! shrunk by the margin). Self-collision: shapes on links at least two joints apart (the
//! gripper counts as one link with the last one) may not overlap, except pairs that already
//! overlap in the middle of the joint limits ([`RemovalConfig::self_collision`]). Collisions
//! between the arm and the part it holds are not checked.
//!
//! Speed (issue 10): grasps are examined in increasing order of their lower bound and planned
//! at once, so the search stops as soon as no later grasp can beat the best path; each grasp is
//! rejected by the cheapest test that can (the gripper alone at the grasp and lifted poses needs
//! no inverse kinematics); shapes are tested against the state's parts only when they meet the
//! box around them all; one forward kinematics pass gives every shape's pose; a path is re-checked
//! finely only when it is shorter than the best so far; edges are sampled by per-joint lever arms
//! ([`Robot::lever_arms`]). [`RemovalPlanner::stats`] times each phase.

use std::borrow::Borrow;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::OnceLock;
use std::time::Instant;

use asp_geom::math::{Pose, Rot, Vec3};
use asp_geom::{Assembly, Grasp, PartSet, World};
use parry3d::bounding_volume::{Aabb, BoundingVolume};
use parry3d::query;
use parry3d::shape::{Cuboid, HalfSpace, Shape, SharedShape, TriMesh};
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
    /// Check the arm against itself (links at least two joints apart).
    pub self_collision: bool,
    /// Test the gripper alone at the grasp and lifted poses before any inverse kinematics
    /// (false: only the whole arm after inverse kinematics; for comparisons).
    pub gripper_precheck: bool,
    /// Bound a point's displacement by each joint's own lever arm (false: the largest lever arm
    /// for every joint, as before issue 10's speed-up; for comparisons).
    pub per_joint_levers: bool,
    /// Skip edge samples that the clearance bound at an earlier sample proves free (box
    /// distances to the parts and the floor, exact distances between the arm's own shapes):
    /// the same answers with fewer tests (false: test every sample; for comparisons).
    pub clearance_skipping: bool,
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
            self_collision: true,
            gripper_precheck: true,
            per_joint_levers: true,
            clearance_skipping: true,
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
        /// Grasps whose pose (or lifted pose) inverse kinematics did not reach (of those whose
        /// gripper alone is collision-free there).
        unreachable: usize,
        /// Grasps where the gripper alone collides at the grasp or lifted pose (tested first,
        /// without inverse kinematics), or the arm reached them only colliding.
        colliding: usize,
    },
    /// Grasps are reachable but no collision-free path to the drop-off was found: the drop-off
    /// pose is unreachable or in collision with the part in hand, or the path planner found no
    /// path within its budget.
    NoPath {
        /// Reachable grasps (among those examined).
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
    /// Grasps found reachable (grasp and lift collision-free) among those examined: the search
    /// stops when no later grasp can be shorter, so this is not a count over all grasps.
    pub reachable_grasps: usize,
}

/// A robot shape ready for collision tests: parry shape shrunk by the margin and its pose in
/// the link frame.
struct Prepared {
    local: Pose,
    shape: SharedShape,
    /// The shape's kind after shrinking, for its box in closed form.
    kind: ShapeKind,
}

impl Prepared {
    fn new(s: &LinkShape, margin: f32) -> Prepared {
        let (local, shape, kind) = shrunk(s, margin);
        Prepared { local, shape, kind }
    }

    /// The shape's bounding box at `pose` (closed form for capsules, boxes and spheres).
    fn aabb(&self, pose: &Pose) -> Aabb {
        let c = pose.translation;
        let e = match self.kind {
            ShapeKind::Capsule { radius, half_length } => (pose.rotation * Vec3::new(0.0, 0.0, half_length)).abs() + Vec3::splat(radius),
            ShapeKind::Box { half_extents: h } => {
                (pose.rotation * Vec3::X).abs() * h.x + (pose.rotation * Vec3::Y).abs() * h.y + (pose.rotation * Vec3::Z).abs() * h.z
            }
            ShapeKind::Sphere { radius } => Vec3::splat(radius),
            ShapeKind::Cylinder { .. } => return self.shape.compute_aabb(pose),
        };
        Aabb::new(c - e, c + e)
    }
}

fn shrunk(s: &LinkShape, margin: f32) -> (Pose, SharedShape, ShapeKind) {
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
    (s.local_pose * fix, shape, k)
}

/// The world pose and box of every prepared shape, their links at `link_poses`.
fn world_shapes(arm: &[Prepared], link_poses: &[Pose]) -> Vec<(Pose, Aabb)> {
    link_poses
        .iter()
        .zip(arm)
        .map(|(l, p)| {
            let pose = *l * p.local;
            (pose, p.aabb(&pose))
        })
        .collect()
}

/// The lowest point of a box along `up` (its height above the origin's plane).
fn lowest(bb: &Aabb, up: Vec3) -> f32 {
    (0..3).map(|k| (bb.mins[k] * up[k]).min(bb.maxs[k] * up[k])).sum()
}

/// The distance between two boxes (0 when they meet).
fn box_gap(a: &Aabb, b: &Aabb) -> f32 {
    let gap = (a.mins - b.maxs).max(b.mins - a.maxs).max(Vec3::ZERO);
    gap.length()
}

/// Whether prepared shapes `i` and `j`, placed as in `placed`, overlap.
fn shapes_touch(arm: &[Prepared], placed: &[(Pose, Aabb)], i: usize, j: usize) -> bool {
    placed[i].1.intersects(&placed[j].1)
        && query::intersection_test(&placed[i].0, &*arm[i].shape, &placed[j].0, &*arm[j].shape).is_ok_and(|x| x.intersecting)
}

/// Work and time of [`RemovalPlanner::plan`] by phase, summed over every call (all threads)
/// since the planner was made or [`RemovalPlanner::reset_stats`]. Times are wall-clock
/// nanoseconds of the calling threads.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct PlanStats {
    /// Calls of `plan`.
    pub plans: u64,
    /// The lift's exact sweep.
    pub lift_ns: u64,
    /// The gripper alone at the grasp and lifted poses (before any inverse kinematics).
    pub gripper_ns: u64,
    /// Inverse kinematics of the grasp and lifted poses.
    pub ik_ns: u64,
    /// Collision checks of the arm at the grasp, the lifted pose and the motion between them.
    pub reach_check_ns: u64,
    /// Inverse kinematics and checks of the drop-off pose.
    pub drop_off_ns: u64,
    /// The path planner (RRT-Connect and its shortcuts).
    pub rrt_ns: u64,
    /// The path's length and the fine re-check of the trajectory.
    pub recheck_ns: u64,
    /// Grasps looked at.
    pub grasps_examined: u64,
    /// Grasps never looked at: the bound proved they cannot beat the best path, or the cap
    /// ([`RemovalConfig::path_grasps`]) was reached.
    pub grasps_pruned: u64,
    /// Grasps rejected because the gripper alone collides at the grasp or lifted pose.
    pub gripper_rejected: u64,
    /// Grasps whose grasp or lifted pose inverse kinematics did not reach.
    pub unreachable: u64,
    /// Grasps given to the path planner.
    pub grasps_planned: u64,
    /// Collision checks of the whole robot at one configuration.
    pub robot_checks: u64,
    /// Collision checks of the held part at one pose.
    pub held_checks: u64,
    /// Edge samples not tested because the clearance at an earlier sample proved them free.
    pub skipped_samples: u64,
}

const N_COUNTERS: usize = 16;

#[derive(Default)]
struct Counters([AtomicU64; N_COUNTERS]);

#[derive(Clone, Copy)]
enum C {
    Plans,
    Lift,
    Gripper,
    Ik,
    Reach,
    DropOff,
    Rrt,
    Recheck,
    Examined,
    Pruned,
    GripperRejected,
    Unreachable,
    Planned,
    RobotChecks,
    HeldChecks,
    Skipped,
}

impl Counters {
    fn add(&self, c: C, v: u64) {
        self.0[c as usize].fetch_add(v, Ordering::Relaxed);
    }

    fn timed<T>(&self, c: C, f: impl FnOnce() -> T) -> T {
        let t = Instant::now();
        let out = f();
        self.add(c, t.elapsed().as_nanos() as u64);
        out
    }

    fn snapshot(&self) -> PlanStats {
        let v = |c: C| self.0[c as usize].load(Ordering::Relaxed);
        PlanStats {
            plans: v(C::Plans),
            lift_ns: v(C::Lift),
            gripper_ns: v(C::Gripper),
            ik_ns: v(C::Ik),
            reach_check_ns: v(C::Reach),
            drop_off_ns: v(C::DropOff),
            rrt_ns: v(C::Rrt),
            recheck_ns: v(C::Recheck),
            grasps_examined: v(C::Examined),
            grasps_pruned: v(C::Pruned),
            gripper_rejected: v(C::GripperRejected),
            unreachable: v(C::Unreachable),
            grasps_planned: v(C::Planned),
            robot_checks: v(C::RobotChecks),
            held_checks: v(C::HeldChecks),
            skipped_samples: v(C::Skipped),
        }
    }
}

/// How far [`RemovalPlanner::plan_grasps`] searches.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Mode {
    /// Until no later grasp can be shorter, or the cap.
    Bounded,
    /// Every grasp.
    Exhaustive,
    /// Until the first path (the same grasps as `Bounded` up to it).
    FirstPath,
}

/// The obstacles of one state: the present parts but the held one, the ground apart.
struct Obstacles {
    ids: Vec<usize>,
    ground: Option<usize>,
    /// The union of the boxes of `ids` (broad phase).
    bounds: Option<Aabb>,
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
    /// Index of the first gripper shape (links rigid with the tool centre, then fingers).
    gripper_first: usize,
    /// The farthest point of the gripper from the tool centre.
    gripper_reach: f64,
    floor: (Pose, SharedShape),
    /// Pairs of robot shapes (indices as in `arm`) tested against each other: shapes on links
    /// at least two joints apart (the gripper and the fingers count as one link with the last
    /// link), except pairs that already touch in the middle of the joint limits.
    self_pairs: Vec<(usize, usize)>,
    /// Per part, its exact boxes ([`World::boxes`]) as cuboids: tests against them replace the
    /// mesh tests (primitive against box instead of against triangles).
    cuboids: Vec<Option<Vec<Placed>>>,
    /// The same shrunk by the held part's margin, for the part in hand.
    held_cuboids: Vec<Option<Vec<Placed>>>,
    counters: Counters,
}

/// A box of a part as a cuboid: its box in the assembled pose, the cuboid's centre, the cuboid.
struct Placed {
    aabb: Aabb,
    centre: Pose,
    cuboid: Cuboid,
}

fn cuboids_of(world: &World, p: usize, shrink: f32) -> Option<Vec<Placed>> {
    let boxes = world.boxes(p)?;
    Some(
        boxes
            .iter()
            .map(|b| {
                let half = (b.half_extents() - Vec3::splat(shrink)).max(Vec3::splat(1e-5));
                let centre = b.center();
                Placed { aabb: Aabb::new(centre - half, centre + half), centre: Pose::from_translation(centre), cuboid: Cuboid::new(half) }
            })
            .collect(),
    )
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
                arm.push(Prepared::new(s, config.margin));
            }
        }
        for f in robot.fingers() {
            for s in &f.link.shapes {
                arm.push(Prepared::new(s, config.margin));
            }
        }
        debug_assert_eq!(arm.len(), robot.collision_shapes(&q, 0.0).len());
        let floor_pose = Pose::from_parts(cell.up * cell.floor, Rot::IDENTITY);
        let floor = (floor_pose, SharedShape::new(HalfSpace::new(cell.up)));
        let grasps = (0..world.borrow().num_parts()).map(|_| OnceLock::new()).collect();
        let gripper_reach = robot.gripper_reach();
        // the link (body) of every shape: arm shapes by link, the gripper as one body after them
        let mut body = Vec::with_capacity(arm.len());
        for (i, l) in links[..start].iter().enumerate() {
            body.extend(l.shapes.iter().map(|_| i));
        }
        body.resize(arm.len(), start);
        let mid: Vec<(Pose, Aabb)> = {
            let mut poses = Vec::new();
            robot.collision_link_poses(&q, robot.max_opening() * 0.5, &mut poses);
            world_shapes(&arm, &poses)
        };
        let mut self_pairs = Vec::new();
        for i in 0..arm.len() {
            for j in i + 1..arm.len() {
                if body[j] >= body[i] + 2 && !shapes_touch(&arm, &mid, i, j) {
                    self_pairs.push((i, j));
                }
            }
        }
        let w: &World = world.borrow();
        let held_shrink = config.margin.max(w.tolerance());
        let cuboids = (0..w.num_parts()).map(|p| cuboids_of(w, p, 0.0)).collect();
        let held_cuboids = (0..w.num_parts()).map(|p| cuboids_of(w, p, held_shrink)).collect();
        RemovalPlanner {
            world,
            cell,
            config,
            grasps,
            arm,
            base_shapes,
            gripper_first: arm_count,
            gripper_reach,
            floor,
            self_pairs,
            cuboids,
            held_cuboids,
            counters: Counters::default(),
        }
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

    /// Whether the arm at `q` (gripper opened to `opening`) collides with itself: two shapes on
    /// links at least two joints apart overlap (see the module documentation).
    pub fn self_collision(&self, q: &[f64], opening: f32) -> bool {
        let mut poses = Vec::new();
        self.cell.robot.collision_link_poses(q, opening, &mut poses);
        let placed = world_shapes(&self.arm, &poses);
        self.self_pairs.iter().any(|&(i, j)| shapes_touch(&self.arm, &placed, i, j))
    }

    /// The pairs of shapes (indices in [`Robot::collision_shapes`] order) tested for
    /// self-collision.
    pub fn self_collision_pairs(&self) -> &[(usize, usize)] {
        &self.self_pairs
    }

    /// Work and time by phase of every plan so far.
    pub fn stats(&self) -> PlanStats {
        self.counters.snapshot()
    }

    /// Sets [`RemovalPlanner::stats`] back to zero.
    pub fn reset_stats(&self) {
        for c in &self.counters.0 {
            c.store(0, Ordering::Relaxed);
        }
    }

    /// The grasps of part `p` (computed once).
    pub fn grasps(&self, p: usize) -> &[Grasp] {
        self.grasps[p].get_or_init(|| {
            let cfg = GraspConfig { max_opening: self.cell.robot.max_opening(), ..self.config.grasp.clone() };
            part_grasps(&self.world().assembly().parts[p], &cfg)
        })
    }

    /// The obstacles of a state: the present parts (fixed ones and the ground included) but `held`.
    fn obstacles(&self, present: &PartSet, held: usize) -> Obstacles {
        let world = self.world();
        let ground = world.ground();
        let ids: Vec<usize> = world.with_fixed(present).iter().filter(|&q| q != held && Some(q) != ground).collect();
        let bounds = ids.iter().map(|&o| *world.aabb(o)).reduce(|a, b| a.merged(&b));
        let ground = ground.filter(|&g| world.with_fixed(present).contains(g) && g != held);
        Obstacles { ids, ground, bounds }
    }

    /// Whether robot shapes `first..first + placed.len()` (in [`Robot::collision_shapes`]
    /// order), placed as in `placed` ([`world_shapes`]), collide with an obstacle or go below
    /// the floor.
    fn shapes_collide(&self, placed: &[(Pose, Aabb)], first: usize, obstacles: &Obstacles) -> bool {
        let world = self.world();
        let up = self.cell.up;
        for (i, (pose, bb)) in placed.iter().enumerate() {
            let (pose, bb) = (*pose, *bb);
            let k = first + i;
            let prepared = &self.arm[k];
            let on_base = k < self.base_shapes;
            if !on_base {
                if lowest(&bb, up) <= self.cell.floor
                    && query::intersection_test(&pose, &*prepared.shape, &self.floor.0, &*self.floor.1).is_ok_and(|i| i.intersecting)
                {
                    // the box may reach below the floor: exact test against the half-space
                    return true;
                }
                // the base stands on the ground
                if let Some(g) = obstacles.ground {
                    if bb.intersects(world.aabb(g))
                        && query::intersection_test(&pose, &*prepared.shape, &Pose::IDENTITY, world.mesh(g)).is_ok_and(|i| i.intersecting)
                    {
                        return true;
                    }
                }
            }
            if !obstacles.bounds.is_some_and(|b| bb.intersects(&b)) {
                continue;
            }
            for &o in &obstacles.ids {
                if !bb.intersects(world.aabb(o)) {
                    continue;
                }
                let hit = match &self.cuboids[o] {
                    Some(boxes) => boxes.iter().any(|c| {
                        bb.intersects(&c.aabb)
                            && query::intersection_test(&pose, &*prepared.shape, &c.centre, &c.cuboid).is_ok_and(|i| i.intersecting)
                    }),
                    None => query::intersection_test(&pose, &*prepared.shape, &Pose::IDENTITY, world.mesh(o)).is_ok_and(|i| i.intersecting),
                };
                if hit {
                    return true;
                }
            }
        }
        false
    }

    /// Whether two robot shapes on links at least two joints apart overlap (self-collision);
    /// `link_poses` in [`Robot::collision_shapes`] order.
    fn self_collides(&self, placed: &[(Pose, Aabb)]) -> bool {
        if !self.config.self_collision {
            return false;
        }
        self.self_pairs.iter().any(|&(i, j)| shapes_touch(&self.arm, placed, i, j))
    }

    /// A lower bound on how far any point of the robot (links at `link_poses`, base excluded:
    /// it never moves) or of the held part (inside `held_box`) may move before one of them meets
    /// an obstacle, the floor or (the robot) itself: box distances to the parts and the floor,
    /// exact distances between the robot's own shapes whose boxes meet. Call it only at a
    /// collision-free configuration.
    ///
    /// A clearance below `need` is of no use to the caller: it returns 0 as soon as the bound
    /// falls below it.
    fn clearance(&self, placed: &[(Pose, Aabb)], held_box: &Aabb, obstacles: &Obstacles, need: f32) -> f32 {
        let world = self.world();
        let up = self.cell.up;
        let to_obstacles = |bb: &Aabb| {
            let mut m = f32::INFINITY;
            if let Some(g) = obstacles.ground {
                m = m.min(box_gap(bb, world.aabb(g)));
            }
            if let Some(b) = &obstacles.bounds {
                let d = box_gap(bb, b);
                if d > 0.0 {
                    m = m.min(d);
                } else {
                    for &o in &obstacles.ids {
                        m = m.min(box_gap(bb, world.aabb(o)));
                    }
                }
            }
            m
        };
        let mut c = to_obstacles(held_box);
        if c < need {
            return 0.0;
        }
        for (_, bb) in placed.iter().skip(self.base_shapes) {
            c = c.min(lowest(bb, up) - self.cell.floor).min(to_obstacles(bb));
            if c < need {
                return 0.0;
            }
        }
        if self.config.self_collision {
            for &(i, j) in &self.self_pairs {
                let d = box_gap(&placed[i].1, &placed[j].1);
                let d = if d > 0.0 {
                    d
                } else {
                    query::distance(&placed[i].0, &*self.arm[i].shape, &placed[j].0, &*self.arm[j].shape).map_or(0.0, |d| d.distance)
                };
                c = c.min(d);
                if c < need {
                    return 0.0;
                }
            }
        }
        c.max(0.0)
    }

    /// Whether the gripper alone, its tool centre at `tool` and opened to `opening`, collides
    /// with an obstacle or goes below the floor (no inverse kinematics needed).
    fn gripper_collides(&self, tool: &Pose, opening: f32, obstacles: &Obstacles) -> bool {
        let poses: Vec<Pose> = self.cell.robot.gripper_shapes(tool, opening).into_iter().map(|(p, _)| p).collect();
        let placed = world_shapes(&self.arm[self.gripper_first..], &poses);
        self.shapes_collide(&placed, self.gripper_first, obstacles)
    }

    /// Whether part `p` shrunk (`shrunk`), displaced by `pose` from its assembled pose, crosses
    /// an obstacle (exact triangle tests).
    fn held_collides(&self, p: usize, shrunk: &TriMesh, pose: &Pose, obstacles: &Obstacles) -> bool {
        let world = self.world();
        let bb = world.aabb(p).transform_by(pose);
        if let Some(g) = obstacles.ground {
            if bb.intersects(world.aabb(g)) && asp_geom::sweep::meshes_cross_at(shrunk, pose, world.mesh(g)) {
                return true;
            }
        }
        if !obstacles.bounds.is_some_and(|b| bb.intersects(&b)) {
            return false;
        }
        let held: Option<Vec<(Pose, Aabb, &Cuboid)>> = self.held_cuboids[p].as_ref().map(|boxes| {
            boxes
                .iter()
                .map(|c| {
                    let at = *pose * c.centre;
                    (at, c.cuboid.compute_aabb(&at), &c.cuboid)
                })
                .collect()
        });
        obstacles.ids.iter().any(|&o| {
            if !bb.intersects(world.aabb(o)) {
                return false;
            }
            match (&held, &self.cuboids[o]) {
                (Some(mine), Some(theirs)) => mine.iter().any(|(at, abb, cuboid)| {
                    abb.intersects(world.aabb(o))
                        && theirs.iter().any(|c| {
                            abb.intersects(&c.aabb)
                                && query::intersection_test(at, *cuboid, &c.centre, &c.cuboid).is_ok_and(|i| i.intersecting)
                        })
                }),
                _ => asp_geom::sweep::meshes_cross_at(shrunk, pose, world.mesh(o)),
            }
        })
    }

    /// Plans the removal of part `p` from `present` (which holds it) lifted along `direction`
    /// (unit), with `replans` path plans per grasp from seeds derived from `seed`.
    ///
    /// Grasps are taken in increasing order of a lower bound of their path length (the lift
    /// plus the straight distance from the lifted tool centre to the drop-off, less the inverse
    /// kinematics' tolerances); each is tested cheapest first (the gripper alone, then inverse
    /// kinematics, then the whole arm, then the drop-off) and planned at once. The search stops
    /// when the best path is no longer than the next grasp's bound — no later grasp can be
    /// shorter, so the answer is the shortest over all grasps' plans
    /// ([`RemovalPlanner::plan_exhaustive`]) — or after [`RemovalConfig::path_grasps`] planned
    /// grasps (a cap: then a later grasp might have been shorter).
    pub fn plan(&self, p: usize, present: &PartSet, direction: Vec3, seed: u64, replans: usize) -> Result<RobotRemoval, RobotFailure> {
        self.plan_grasps(p, present, direction, seed, replans, Mode::Bounded)
    }

    /// Whether the robot can take the part out, with the first path found: the same grasps in
    /// the same order with the same seeds as [`RemovalPlanner::plan`], stopping at the first
    /// path that passes the re-check. So it succeeds exactly when `plan` does (and fails with
    /// the same failure), at a fraction of the cost; its path is not the shortest. For
    /// feasibility tests (the optimiser's `robot` filter).
    pub fn removable(&self, p: usize, present: &PartSet, direction: Vec3, seed: u64, replans: usize) -> Result<RobotRemoval, RobotFailure> {
        self.plan_grasps(p, present, direction, seed, replans, Mode::FirstPath)
    }

    /// [`RemovalPlanner::plan`] without its shortcuts: every grasp is examined and every
    /// reachable one planned (no bound, no cap). The same grasps in the same order with the
    /// same seeds, so its length is the shortest of all of them: the reference `plan` is
    /// tested against.
    pub fn plan_exhaustive(&self, p: usize, present: &PartSet, direction: Vec3, seed: u64, replans: usize) -> Result<RobotRemoval, RobotFailure> {
        self.plan_grasps(p, present, direction, seed, replans, Mode::Exhaustive)
    }

    fn plan_grasps(
        &self,
        p: usize,
        present: &PartSet,
        direction: Vec3,
        seed: u64,
        replans: usize,
        mode: Mode,
    ) -> Result<RobotRemoval, RobotFailure> {
        let exhaustive = mode == Mode::Exhaustive;
        let counters = &self.counters;
        counters.add(C::Plans, 1);
        let world = self.world();
        let robot = &self.cell.robot;
        let bb = world.aabb(p);
        let pivot = (bb.mins + bb.maxs) * 0.5;
        let lift = Pose::from_translation(direction * self.config.lift);
        if let Some(by) = counters.timed(C::Lift, || world.collision_between(p, &Pose::IDENTITY, &lift, pivot, present)) {
            return Err(RobotFailure::Blocked { by: Some(by) });
        }
        let obstacles = self.obstacles(present, p);
        let grasps = self.grasps(p);
        let shrunk = world.eroded(p, self.config.margin.max(world.tolerance()));
        // The tool centre travels from the grasp (within the position tolerance) through the
        // lifted pose to the drop-off: the sampled polyline is at least as long as the lift plus
        // the straight distance, less twice the tolerance at each of the three ends.
        let slack = 6.0 * self.config.ik.position_tolerance + 1e-5;
        let mut order: Vec<(f64, usize)> = grasps
            .iter()
            .enumerate()
            .map(|(gi, g)| {
                let lifted = lift * Pose::from_parts(g.position, g.orientation);
                (self.config.lift as f64 + (lifted.translation - self.cell.drop_off).length() as f64 - slack, gi)
            })
            .collect();
        order.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        let cap = if exhaustive { usize::MAX } else { self.config.path_grasps.max(1) };
        let (mut unreachable, mut colliding, mut no_drop, mut reached, mut tried) = (0, 0, 0, 0, 0);
        // grasps solved so far with their arm configurations: the nearest one seeds the next
        // grasp's inverse kinematics
        let mut solved: Vec<(Pose, Vec<f64>)> = Vec::new();
        let mut best: Option<RobotRemoval> = None;
        for (n, &(bound, gi)) in order.iter().enumerate() {
            let found = mode == Mode::FirstPath && best.is_some();
            if found || !exhaustive && (tried >= cap || best.as_ref().is_some_and(|b| b.length <= bound)) {
                counters.add(C::Pruned, (order.len() - n) as u64);
                break;
            }
            counters.add(C::Examined, 1);
            let g = &grasps[gi];
            let tool = Pose::from_parts(g.position, g.orientation);
            let lifted = lift * tool;
            // 1. the gripper alone at the grasp and lifted poses: no inverse kinematics needed
            if self.config.gripper_precheck
                && counters.timed(C::Gripper, || {
                self.gripper_collides(&tool, g.width, &obstacles) || self.gripper_collides(&lifted, g.width, &obstacles)
            }) {
                counters.add(C::GripperRejected, 1);
                colliding += 1;
                continue;
            }
            // 2. inverse kinematics of both poses
            let ik = IkConfig { seed: seed ^ (gi as u64).wrapping_mul(0x9e37_79b9), ..self.config.ik.clone() };
            let start = solved
                .iter()
                .map(|(pose, q)| ((pose.translation - tool.translation).length() + 0.3 * pose.rotation.angle_between(tool.rotation), q))
                .min_by(|a, b| a.0.total_cmp(&b.0))
                .map(|(_, q)| q.as_slice());
            let reached_ik = counters.timed(C::Ik, || {
                let qg = robot.ik(&tool, start, &ik).solution().map(|s| s.joints.clone())?;
                let ql = robot.ik(&lifted, Some(&qg), &IkConfig { restarts: 0, ..ik.clone() }).solution().map(|s| s.joints.clone())?;
                Some((qg, ql))
            });
            let Some((qg, ql)) = reached_ik else {
                counters.add(C::Unreachable, 1);
                unreachable += 1;
                continue;
            };
            solved.push((tool, qg.clone()));
            // 3. the whole arm and the held part at both poses and between them
            let grasp_pose = robot.tool_pose(&qg);
            let space = ArmSpace::new(self, p, &shrunk, grasp_pose, g.width, &obstacles, self.config.edge_resolution);
            if counters.timed(C::Reach, || !space.valid(&qg) || !space.valid(&ql) || !space.edge_valid(&qg, &ql)) {
                colliding += 1;
                continue;
            }
            reached += 1;
            // 4. drop-off: the lifted orientation first, then the gripper pointing down
            let qd = counters.timed(C::DropOff, || {
                let down = Rot::from_rotation_arc(Vec3::Z, -self.cell.up);
                for (k, rot) in [lifted.rotation, down, down * Rot::from_rotation_z(std::f32::consts::FRAC_PI_2)].into_iter().enumerate() {
                    let target = Pose::from_parts(self.cell.drop_off, rot);
                    let cfg = IkConfig { seed: ik.seed ^ (k as u64 + 1), ..ik.clone() };
                    if let Some(s) = robot.ik(&target, Some(&ql), &cfg).solution() {
                        if space.valid(&s.joints) {
                            return Some(s.joints.clone());
                        }
                    }
                }
                None
            });
            let Some(qd) = qd else {
                no_drop += 1;
                continue;
            };
            // 5. paths to the drop-off, k times
            tried += 1;
            counters.add(C::Planned, 1);
            let fine = ArmSpace::new(self, p, &shrunk, grasp_pose, g.width, &obstacles, self.config.check_resolution);
            for r in 0..replans.max(1) {
                let cfg = RrtConnectConfig { seed: seed ^ ((gi as u64) << 20) ^ (r as u64).wrapping_mul(0x5851_f42d_4c95_7f2d), ..self.config.rrt.clone() };
                let Ok(path) = counters.timed(C::Rrt, || rrt_connect(&space, &ql, &qd, &cfg)) else { continue };
                let mut joints = vec![qg.clone()];
                joints.extend(path);
                // the length first (forward kinematics only): a path that cannot be the best
                // needs no re-check
                let kept = counters.timed(C::Recheck, || {
                    let length = fine.tool_travel(&joints);
                    let better = best.as_ref().is_none_or(|b| length < b.length);
                    (better && joints.windows(2).all(|w| fine.edge_valid(&w[0], &w[1]))).then_some(length)
                });
                if let Some(length) = kept {
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
                    if mode == Mode::FirstPath {
                        break;
                    }
                }
            }
        }
        if let Some(mut b) = best {
            b.reachable_grasps = reached;
            return Ok(b);
        }
        if reached == 0 {
            return Err(RobotFailure::NoReachableGrasp { grasps: grasps.len(), unreachable, colliding });
        }
        Err(RobotFailure::NoPath { reachable: reached, drop_off_blocked: no_drop, grasps_tried: tried })
    }
}

/// The joint space of the arm holding part `p` with a grasp: valid when neither the robot nor
/// the held part collides.
struct ArmSpace<'a, W: Borrow<World>> {
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
    fn new(
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
    fn check(&self, q: &[f64], clearance: Option<f32>) -> Option<f32> {
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
