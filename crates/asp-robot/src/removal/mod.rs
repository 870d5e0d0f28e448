//! Robot removability (thesis 5.3): can the arm take a part out of a state, and how far does
//! its gripper travel doing so?
//!
//! The test is hierarchical, cheapest first:
//! 1. **Lift**: the part moves [`RemovalConfig::lift`] (5 cm) along its removal direction,
//!    collision-checked exactly with the world's sweep ([`asp_geom::world::Removal::collision_between`]).
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
//! Speed: grasps are examined in increasing order of their lower bound and planned
//! at once, so the search stops as soon as no later grasp can beat the best path; each grasp is
//! rejected by the cheapest test that can (the gripper alone at the grasp and lifted poses needs
//! no inverse kinematics); shapes are tested against the state's parts only when they meet the
//! box around them all; one forward kinematics pass gives every shape's pose; a path is re-checked
//! finely only when it is shorter than the best so far; edges are sampled by per-joint lever arms
//! ([`Robot::lever_arms`]). [`RemovalPlanner::stats`] times each phase.

mod arm;
mod bodies;
mod config;
mod fast;
mod grid;
mod plan;
mod shapes;
mod stats;

pub use arm::ArmCheck;
use arm::{ArmSpace, Check};
use bodies::ArmModel;
pub use config::{RemovalConfig, RobotCell, RobotFailure, RobotRemoval};
use grid::{Field, PartGrid};
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
    /// Their distances, filled as the sphere check asks (`ids` as bits).
    field: Field,
    /// Whether the floor counts ([`RemovalPlanner::shapes_collide`]; off only to name the
    /// parts a gripper meets, [`RemovalPlanner::grasp_blockers`]).
    floor: bool,
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

/// The side of the cells of the grid over the parts' boxes, metres.
const GRID_CELL: f32 = 0.03;

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
    /// Per part, its exact boxes ([`asp_geom::world::Shapes::boxes`]) as cuboids: tests against them replace the
    /// mesh tests (primitive against box instead of against triangles).
    cuboids: Vec<Option<Vec<Placed>>>,
    /// The same shrunk by the held part's margin, for the part in hand.
    held_cuboids: Vec<Option<Vec<Placed>>>,
    /// Inverse kinematics per part, grasp and lift direction (state-independent).
    ik_cache: Mutex<HashMap<IkKey, Arc<GraspIk>>>,
    /// The robot as bodies of spheres (the sphere check's arm).
    model: ArmModel,
    /// The parts' boxes in a grid over the cell (the sphere check's parts).
    grid: PartGrid,
    counters: Counters,
}

/// A box of a part as a cuboid: its box in the assembled pose, the cuboid's centre, the cuboid.
struct Placed {
    aabb: Aabb,
    centre: Pose,
    cuboid: Cuboid,
}

fn cuboids_of(world: &World, p: usize, shrink: f32) -> Option<Vec<Placed>> {
    let boxes = world.shapes().boxes(p)?;
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
        let held_shrink = config.margin.max(w.shapes().tolerance());
        let cuboids = (0..w.num_parts()).map(|p| cuboids_of(w, p, 0.0)).collect();
        let held_cuboids = (0..w.num_parts()).map(|p| cuboids_of(w, p, held_shrink)).collect();
        let model = ArmModel::new(robot, &arm);
        // every small sphere of the arm or of a held part (box cells of at most a piece a side)
        let reach = model.largest.max(crate::spheres::SPHERE_PIECE * 0.8661) + 2.0 * crate::spheres::SPHERE_SLACK;
        let grid = PartGrid::new(w, GRID_CELL, reach);
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
            model,
            grid,
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

    /// Runs `f` with the check of the arm holding part `p` with `grasp` (its opening, the tool
    /// centre at the grasp's pose) among the parts of `present` but `p` (the fixed ones and the
    /// ground included): the planner's sphere check and the exact one, configuration by
    /// configuration.
    pub fn with_arm_check<R>(&self, p: usize, present: &PartSet, grasp: &Grasp, f: impl FnOnce(&ArmCheck<'_, W>) -> R) -> R {
        let world = self.world();
        let obstacles = self.obstacles(present, p);
        let shrunk = world.shapes().eroded(p, self.config.margin.max(world.shapes().tolerance()));
        let pose = Pose::from_parts(grasp.position, grasp.orientation);
        let space = |resolution, check| ArmSpace::new(self, p, &shrunk, pose, grasp.width, &obstacles, resolution, check);
        let check = ArmCheck::new(space(self.config.edge_resolution, Check::Spheres), space(self.config.check_resolution, Check::Exact));
        f(&check)
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
        let ground = world.shapes().ground();
        let ids: Vec<usize> = world.contacts().with_fixed(present).iter().filter(|&q| q != held && Some(q) != ground).collect();
        let bounds = ids.iter().map(|&o| *world.shapes().aabb(o)).reduce(|a, b| a.merged(&b));
        let ground = ground.filter(|&g| world.contacts().with_fixed(present).contains(g) && g != held);
        let mut bits = vec![0u64; world.num_parts().div_ceil(64).max(1)];
        for &o in ids.iter().filter(|&&o| o < world.num_parts()) {
            bits[o / 64] |= 1 << (o % 64);
        }
        Obstacles { ids, ground, bounds, field: Field::new(bits), floor: true }
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
                if obstacles.floor && lowest(&bb, up) <= self.cell.floor && prepared.meets(&pose, &self.floor.0, &*self.floor.1) {
                    // the box may reach below the floor: exact test against the half-space
                    return true;
                }
                // the base stands on the ground
                if let Some(g) = obstacles.ground {
                    if bb.intersects(world.shapes().aabb(g)) && prepared.meets(&pose, &Pose::IDENTITY, world.shapes().mesh(g)) {
                        return true;
                    }
                }
            }
            if !obstacles.bounds.is_some_and(|b| bb.intersects(&b)) {
                continue;
            }
            for &o in &obstacles.ids {
                if !bb.intersects(world.shapes().aabb(o)) {
                    continue;
                }
                let hit = match &self.cuboids[o] {
                    Some(boxes) => boxes.iter().any(|c| bb.intersects(&c.aabb) && prepared.meets(&pose, &c.centre, &c.cuboid)),
                    None => prepared.meets(&pose, &Pose::IDENTITY, world.shapes().mesh(o)),
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
                m = m.min(box_gap(bb, world.shapes().aabb(g)));
            }
            if let Some(b) = &obstacles.bounds {
                let d = box_gap(bb, b);
                if d > 0.0 {
                    m = m.min(d);
                } else {
                    for &o in &obstacles.ids {
                        m = m.min(box_gap(bb, world.shapes().aabb(o)));
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

    /// What the gripper alone meets at each grasp of part `p` in `present`, lifted along
    /// `direction` (the robot's first test of a grasp, at the grasp pose and the lifted one),
    /// per grasp of [`RemovalPlanner::grasps`]: `None` when it is free there, else the parts it
    /// collides with in increasing order (empty when only the floor or the ground is in the
    /// way). What a dead end's explanation says about a part's grasps.
    pub fn grasp_blockers(&self, p: usize, present: &PartSet, direction: Vec3) -> Vec<Option<Vec<usize>>> {
        let lift = Pose::from_translation(direction * self.config.lift);
        let all = self.obstacles(present, p);
        let world = self.world();
        let one: Vec<Obstacles> = all
            .ids
            .iter()
            .map(|&o| {
                let mut bits = vec![0u64; world.num_parts().div_ceil(64).max(1)];
                bits[o / 64] |= 1 << (o % 64);
                Obstacles { ids: vec![o], ground: None, bounds: Some(*world.shapes().aabb(o)), field: Field::new(bits), floor: false }
            })
            .collect();
        self.grasps(p)
            .iter()
            .map(|g| {
                let tool = Pose::from_parts(g.position, g.orientation);
                let lifted = lift * tool;
                if !(self.gripper_collides(&tool, g.width, &all) || self.gripper_collides(&lifted, g.width, &all)) {
                    return None;
                }
                Some(
                    all.ids
                        .iter()
                        .zip(&one)
                        .filter(|(_, obs)| self.gripper_collides(&tool, g.width, obs) || self.gripper_collides(&lifted, g.width, obs))
                        .map(|(&o, _)| o)
                        .collect(),
                )
            })
            .collect()
    }

    /// Whether part `p` shrunk (`shrunk`), displaced by `pose` from its assembled pose, crosses
    /// an obstacle (exact triangle tests).
    fn held_collides(&self, p: usize, shrunk: &TriMesh, pose: &Pose, obstacles: &Obstacles) -> bool {
        let world = self.world();
        let bb = world.shapes().aabb(p).transform_by(pose);
        if let Some(g) = obstacles.ground {
            if bb.intersects(world.shapes().aabb(g)) && asp_geom::sweep::meshes_cross_at(shrunk, pose, world.shapes().mesh(g)) {
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
            if !bb.intersects(world.shapes().aabb(o)) {
                return false;
            }
            match (&held, &self.cuboids[o]) {
                (Some(mine), Some(theirs)) => mine.iter().any(|(at, abb, cuboid)| {
                    abb.intersects(world.shapes().aabb(o))
                        && theirs.iter().any(|c| {
                            abb.intersects(&c.aabb)
                                && query::intersection_test(at, *cuboid, &c.centre, &c.cuboid).is_ok_and(|i| i.intersecting)
                        })
                }),
                _ => asp_geom::sweep::meshes_cross_at(shrunk, pose, world.shapes().mesh(o)),
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
        let bb = world.shapes().aabb(p);
        let pivot = (bb.mins + bb.maxs) * 0.5;
        let up = self.cell.up;
        let mut hit = None;
        for d in [Some(up), direction.filter(|d| d.dot(up) < 1.0 - 1e-6)].into_iter().flatten() {
            let lift = Pose::from_translation(d * self.config.lift);
            match world.removal().collision_between(p, &Pose::IDENTITY, &lift, pivot, present) {
                None => return Ok(d),
                Some(by) => hit = Some(by),
            }
        }
        Err(RobotFailure::Blocked { by: hit })
    }
}
