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
//!    pose to the drop-off pose: RRT-Connect with shortcutting ([`asp_geom::rrt`]), seeded, the
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

mod arm;
mod config;
mod shapes;
mod stats;

use arm::ArmSpace;
pub use config::{RemovalConfig, RobotCell, RobotFailure, RobotRemoval};
use shapes::{box_gap, lowest, shapes_touch, world_shapes, Prepared};
pub use stats::PlanStats;
use stats::{Counters, C};

use std::borrow::Borrow;
use std::collections::HashMap;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::OnceLock;
use std::sync::{Arc, Mutex};
use std::time::Instant;

use asp_geom::math::{Pose, Rot, Vec3};
use asp_geom::rrt::{rrt_connect, RrtConnectConfig, Space};
use asp_geom::{Assembly, Grasp, PartSet, World};
use parry3d::bounding_volume::{Aabb, BoundingVolume};
use parry3d::query;
use parry3d::shape::{Cuboid, HalfSpace, Shape, SharedShape, TriMesh};
use rand::RngExt;
use rand_chacha::ChaCha8Rng;

use crate::grasp::{part_grasps, GraspConfig};
use crate::ik::IkConfig;
use crate::robot::Robot;
use crate::shape::{LinkShape, ShapeKind};

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

/// The arm's configurations for one grasp and lift direction ([`RemovalPlanner::grasp_ik`]).
struct GraspIk {
    /// At the grasp and at the lifted pose (`None`: out of the arm's reach).
    arm: Option<(Vec<f64>, Vec<f64>)>,
    /// At the drop-off, in the order they are tried.
    drop: Vec<Vec<f64>>,
}

/// A part, a grasp and a lift direction (its bits).
type IkKey = (usize, usize, [u32; 3]);

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
    /// Inverse kinematics per part, grasp and lift direction (state-independent).
    ik_cache: Mutex<HashMap<IkKey, Arc<GraspIk>>>,
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
            ik_cache: Mutex::new(HashMap::new()),
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
        self.counters.reset();
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
        self.plan_grasps(p, present, direction, seed, replans, Mode::Bounded, f64::INFINITY)
    }

    /// [`RemovalPlanner::plan`] for a path shorter than `below` (metres; the length of a path
    /// known to work, e.g. one found among more parts): grasps whose lower bound is not below
    /// it are not examined and paths not shorter are dropped unchecked. `Err` when none is
    /// shorter (the failure then says nothing about the known path).
    pub fn plan_below(
        &self,
        p: usize,
        present: &PartSet,
        direction: Vec3,
        seed: u64,
        replans: usize,
        below: f64,
    ) -> Result<RobotRemoval, RobotFailure> {
        self.plan_grasps(p, present, direction, seed, replans, Mode::Bounded, below)
    }

    /// Whether the robot can take the part out, with the first path found: the same grasps in
    /// the same order with the same seeds as [`RemovalPlanner::plan`], stopping at the first
    /// path that passes the re-check. So it succeeds exactly when `plan` does (and fails with
    /// the same failure), at a fraction of the cost; its path is not the shortest. For
    /// feasibility tests (the optimiser's `robot` filter).
    pub fn removable(&self, p: usize, present: &PartSet, direction: Vec3, seed: u64, replans: usize) -> Result<RobotRemoval, RobotFailure> {
        self.plan_grasps(p, present, direction, seed, replans, Mode::FirstPath, f64::INFINITY)
    }

    /// [`RemovalPlanner::plan`] without its shortcuts: every grasp is examined and every
    /// reachable one planned (no bound, no cap). The same grasps in the same order with the
    /// same seeds, so its length is the shortest of all of them: the reference `plan` is
    /// tested against.
    pub fn plan_exhaustive(
        &self,
        p: usize,
        present: &PartSet,
        direction: Vec3,
        seed: u64,
        replans: usize,
    ) -> Result<RobotRemoval, RobotFailure> {
        self.plan_grasps(p, present, direction, seed, replans, Mode::Exhaustive, f64::INFINITY)
    }

    /// The direction the arm lifts part `p` out of `present` along (thesis 5.3: 5 cm up): up
    /// when that lift is collision-free (the world's exact sweep), else `direction` (the
    /// removal direction the geometry found, when there is one). A part taken out sideways
    /// would be pulled along its neighbours' faces, and a part pulled down would drag the
    /// gripper into the structure below it; the generated assemblies are built to be lifted.
    /// Fails with [`RobotFailure::Blocked`] naming the part the last lift tried hits.
    pub fn lift_direction(&self, p: usize, present: &PartSet, direction: Option<Vec3>) -> Result<Vec3, RobotFailure> {
        let world = self.world();
        let bb = world.aabb(p);
        let pivot = (bb.mins + bb.maxs) * 0.5;
        let up = self.cell.up;
        let mut hit = None;
        for d in [Some(up), direction.filter(|d| d.dot(up) < 1.0 - 1e-6)].into_iter().flatten() {
            let lift = Pose::from_translation(d * self.config.lift);
            match world.collision_between(p, &Pose::IDENTITY, &lift, pivot, present) {
                None => return Ok(d),
                Some(by) => hit = Some(by),
            }
        }
        Err(RobotFailure::Blocked { by: hit })
    }

    /// The arm's configurations for grasp `gi` of part `p` lifted along `direction`, computed
    /// once: inverse kinematics of the grasp and lifted poses (seeded by the part and grasp
    /// only, so the same in every state and thread) and of the drop-off poses (the lifted
    /// orientation, then the gripper pointing down, turned twice), each started from the
    /// lifted configuration.
    fn grasp_ik(&self, p: usize, gi: usize, direction: Vec3) -> Arc<GraspIk> {
        let key = (p, gi, direction.to_array().map(f32::to_bits));
        if let Some(k) = self.ik_cache.lock().expect("not poisoned").get(&key) {
            return k.clone();
        }
        let robot = &self.cell.robot;
        let g = &self.grasps(p)[gi];
        let tool = Pose::from_parts(g.position, g.orientation);
        let lifted = Pose::from_translation(direction * self.config.lift) * tool;
        let seed = self.config.ik.seed ^ (p as u64).wrapping_mul(0x2545_f491_4f6c_dd1d) ^ (gi as u64).wrapping_mul(0x9e37_79b9);
        // computed once per grasp, so it can afford more restarts than a per-state test did
        let ik = IkConfig { seed, restarts: self.config.ik.restarts.max(12), ..self.config.ik.clone() };
        let arm = robot.ik(&tool, None, &ik).solution().map(|s| s.joints.clone()).and_then(|qg| {
            let ql = robot.ik(&lifted, Some(&qg), &IkConfig { restarts: 0, ..ik.clone() }).solution().map(|s| s.joints.clone())?;
            Some((qg, ql))
        });
        let mut drop = Vec::new();
        if let Some((_, ql)) = &arm {
            let down = Rot::from_rotation_arc(Vec3::Z, -self.cell.up);
            for (k, rot) in [lifted.rotation, down, down * Rot::from_rotation_z(std::f32::consts::FRAC_PI_2)].into_iter().enumerate() {
                let target = Pose::from_parts(self.cell.drop_off, rot);
                let cfg = IkConfig { seed: ik.seed ^ (k as u64 + 1), ..ik.clone() };
                if let Some(s) = robot.ik(&target, Some(ql), &cfg).solution() {
                    drop.push(s.joints.clone());
                }
            }
        }
        let k = Arc::new(GraspIk { arm, drop });
        self.ik_cache.lock().expect("not poisoned").insert(key, k.clone());
        k
    }

    #[allow(clippy::too_many_arguments)] // the plan's inputs, the search mode and its bound
    fn plan_grasps(
        &self,
        p: usize,
        present: &PartSet,
        direction: Vec3,
        seed: u64,
        replans: usize,
        mode: Mode,
        below: f64,
    ) -> Result<RobotRemoval, RobotFailure> {
        let exhaustive = mode == Mode::Exhaustive;
        let counters = &self.counters;
        counters.add(C::Plans, 1);
        let world = self.world();
        let robot = &self.cell.robot;
        let direction = counters.timed(C::Lift, || self.lift_direction(p, present, Some(direction)))?;
        let lift = Pose::from_translation(direction * self.config.lift);
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
        let mut best: Option<RobotRemoval> = None;
        for (n, &(bound, gi)) in order.iter().enumerate() {
            let found = mode == Mode::FirstPath && best.is_some();
            let shortest = best.as_ref().map_or(below, |b| b.length);
            if found || !exhaustive && (tried >= cap || shortest <= bound) {
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
                })
            {
                counters.add(C::GripperRejected, 1);
                colliding += 1;
                continue;
            }
            // 2. inverse kinematics of both poses (per grasp and lift, once: it does not depend
            // on the state, so an arm out of reach stays out of reach)
            let ik = counters.timed(C::Ik, || self.grasp_ik(p, gi, direction));
            let Some((qg, ql)) = ik.arm.as_ref() else {
                counters.add(C::Unreachable, 1);
                unreachable += 1;
                continue;
            };
            let (qg, ql) = (qg.clone(), ql.clone());
            // 3. the whole arm and the held part at both poses and between them
            let grasp_pose = robot.tool_pose(&qg);
            let space = ArmSpace::new(self, p, &shrunk, grasp_pose, g.width, &obstacles, self.config.edge_resolution);
            if counters.timed(C::Reach, || !space.valid(&qg) || !space.valid(&ql) || !space.edge_valid(&qg, &ql)) {
                colliding += 1;
                continue;
            }
            reached += 1;
            // 4. drop-off: the first of its configurations (lifted orientation, then the
            // gripper pointing down) where the arm and the part in hand are collision-free
            let qd = counters.timed(C::DropOff, || ik.drop.iter().find(|q| space.valid(q)).cloned());
            let Some(qd) = qd else {
                no_drop += 1;
                continue;
            };
            // 5. paths to the drop-off, k times
            tried += 1;
            counters.add(C::Planned, 1);
            let fine = ArmSpace::new(self, p, &shrunk, grasp_pose, g.width, &obstacles, self.config.check_resolution);
            let repair = ArmSpace::new(self, p, &shrunk, grasp_pose, g.width, &obstacles, self.config.repair_resolution);
            for r in 0..replans.max(1) {
                let cfg = RrtConnectConfig {
                    seed: seed ^ ((gi as u64) << 20) ^ (r as u64).wrapping_mul(0x5851_f42d_4c95_7f2d),
                    ..self.config.rrt.clone()
                };
                // the tree on coarse edges; when the fine re-check refuses its path, once more
                // on the repair resolution's edges (same seed)
                let mut kept = None;
                for (attempt, tree) in [&space, &repair].into_iter().enumerate() {
                    let Ok(path) = counters.timed(C::Rrt, || rrt_connect(tree, &ql, &qd, &cfg)) else { break };
                    let mut joints = vec![qg.clone()];
                    joints.extend(path);
                    // the length first (forward kinematics only): a path that cannot be the
                    // best needs no re-check
                    let (length, better, valid) = counters.timed(C::Recheck, || {
                        let length = fine.tool_travel(&joints);
                        let better = length < best.as_ref().map_or(below, |b| b.length);
                        (length, better, better && joints.windows(2).all(|w| fine.edge_valid(&w[0], &w[1])))
                    });
                    if valid {
                        kept = Some((joints, length));
                    } else if better && attempt == 0 {
                        counters.add(C::Refused, 1);
                        continue;
                    }
                    break;
                }
                if let Some((joints, length)) = kept {
                    let gripper_path = repair.tool_samples(&joints);
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
