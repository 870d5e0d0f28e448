//! The settings, the robot cell and the results of the robot removal test.

use super::*;

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
    /// configurations checked along a tree edge, metres. Coarse (4 cm) on purpose: the path
    /// kept is re-checked at [`RemovalConfig::check_resolution`], so a coarse tree only costs
    /// the few paths the re-check refuses (7 % against 2 % at 1 cm, on generated profile
    /// assemblies; those are planned again at [`RemovalConfig::repair_resolution`]), and it halves the robot's planning time twice over (`docs/benchmarks.md`,
    /// "Coarse tree edges").
    pub edge_resolution: f32,
    /// The same for a second tree when the re-check refused the first tree's path (same
    /// seed), and for the gripper path reported in the plan, metres.
    pub repair_resolution: f32,
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
    /// for every joint, as before the per-joint bound; for comparisons).
    pub per_joint_levers: bool,
    /// Skip edge samples that the clearance bound at an earlier sample proves free (box
    /// distances to the parts and the floor, exact distances between the arm's own shapes):
    /// the same answers with fewer tests (false: test every sample; for comparisons).
    pub clearance_skipping: bool,
    /// Check configurations while planning with the arm as spheres against the parts' boxes,
    /// the exact test only where a sphere comes near something: the exact verdict at a
    /// fraction of the cost (false: the exact shapes at every configuration, as before; for
    /// comparisons). The final re-check of a path is exact either way.
    pub sphere_check: bool,
}

impl Default for RemovalConfig {
    fn default() -> Self {
        RemovalConfig {
            lift: 0.05,
            replans: 4,
            path_grasps: 6,
            ik: IkConfig { max_iterations: 60, restarts: 3, position_tolerance: 1e-4, rotation_tolerance: 1e-3, ..IkConfig::default() },
            grasp: GraspConfig::default(),
            rrt: RrtConnectConfig { step: 0.4, max_iterations: 1500, seed: 0, lazy: false },
            edge_resolution: 0.04,
            repair_resolution: 0.01,
            check_resolution: 0.002,
            margin: 0.001,
            self_collision: true,
            gripper_precheck: true,
            per_joint_levers: true,
            clearance_skipping: true,
            sphere_check: true,
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
