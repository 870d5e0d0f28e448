//! The planner's work and time counters by phase ([`PlanStats`]).

use super::*;

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
    /// Paths of the coarse tree the fine re-check refused (each planned again on the repair
    /// resolution's edges).
    pub rechecks_refused: u64,
    /// Of `robot_checks`, those made with the exact shapes alone (the final re-check of a
    /// path; every check when [`RemovalConfig::sphere_check`] is off).
    pub exact_checks: u64,
    /// Every 32nd check of the sphere check timed: how many, and their nanoseconds (wall
    /// clock of the calling thread) — the mean cost of one check without timing every one.
    pub sphere_checks_timed: u64,
    /// The nanoseconds of `sphere_checks_timed`.
    pub sphere_check_ns: u64,
    /// The same for the exact checks: how many were timed.
    pub exact_checks_timed: u64,
    /// The nanoseconds of `exact_checks_timed`.
    pub exact_check_ns: u64,
    /// The exact check of returned paths (once per path returned, after the sphere check
    /// accepted it).
    pub exact_ns: u64,
    /// Paths the sphere check accepted and the exact check refused (then the next shortest is
    /// taken; none is expected: the sphere check gives the exact verdict).
    pub exact_refused: u64,
}

impl PlanStats {
    /// The mean time of one sphere check in nanoseconds (`None` before any was timed).
    pub fn sphere_check_mean_ns(&self) -> Option<f64> {
        (self.sphere_checks_timed > 0).then(|| self.sphere_check_ns as f64 / self.sphere_checks_timed as f64)
    }

    /// The mean time of one exact check in nanoseconds (`None` before any was timed).
    pub fn exact_check_mean_ns(&self) -> Option<f64> {
        (self.exact_checks_timed > 0).then(|| self.exact_check_ns as f64 / self.exact_checks_timed as f64)
    }
}

pub(super) const N_COUNTERS: usize = 24;

#[derive(Default)]
pub(super) struct Counters([AtomicU64; N_COUNTERS]);

#[derive(Clone, Copy)]
pub(super) enum C {
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
    Refused,
    ExactChecks,
    SphereTimed,
    SphereNs,
    ExactTimed,
    ExactNs,
    Exact,
    ExactRefused,
}

impl Counters {
    pub(super) fn add(&self, c: C, v: u64) {
        self.0[c as usize].fetch_add(v, Ordering::Relaxed);
    }

    pub(super) fn timed<T>(&self, c: C, f: impl FnOnce() -> T) -> T {
        let t = Instant::now();
        let out = f();
        self.add(c, t.elapsed().as_nanos() as u64);
        out
    }

    /// Sets every counter back to zero.
    pub(super) fn reset(&self) {
        for c in &self.0 {
            c.store(0, Ordering::Relaxed);
        }
    }

    pub(super) fn snapshot(&self) -> PlanStats {
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
            rechecks_refused: v(C::Refused),
            exact_checks: v(C::ExactChecks),
            sphere_checks_timed: v(C::SphereTimed),
            sphere_check_ns: v(C::SphereNs),
            exact_checks_timed: v(C::ExactTimed),
            exact_check_ns: v(C::ExactNs),
            exact_ns: v(C::Exact),
            exact_refused: v(C::ExactRefused),
        }
    }
}
