//! The feasibility vocabulary every planner speaks: motions, removal outcomes, stability, and
//! the [`FeasibilityChecker`] trait that counts every test it runs.

use crate::math::{Pose, Vec3};
use crate::partset::PartSet;
use std::sync::atomic::{AtomicU64, Ordering};

/// How a part leaves its assembled pose (removal) — world frame, metres, displacements of the
/// part relative to its assembled pose.
#[derive(Clone, Debug, PartialEq)]
pub enum Motion {
    /// A straight line: unit `direction`, travelled `distance` until the part's bounds clear the
    /// bounds of what remains.
    Linear {
        /// Unit removal direction.
        direction: Vec3,
        /// Travel in metres.
        distance: f32,
    },
    /// A path of poses (translation + rotation), the first the identity. Each pose is the rigid
    /// transform applied to the part's assembled geometry. Between two waypoints the `pivot`
    /// (the centre of the part's bounds, world frame) moves on a straight line while the rotation
    /// turns by slerp about it (see [`interpolate_about`]).
    Path {
        /// Waypoints.
        poses: Vec<Pose>,
        /// The point of the part that moves straight between waypoints.
        pivot: Vec3,
    },
    /// A fastener screwed out: the part turns about its symmetry axis (through `axis_point`,
    /// along unit `direction`) as its thread requires while it travels `distance` along
    /// `direction`, until its bounds clear the bounds of what remains. Its threaded partners
    /// were tested outside their thread zone, every other part as for a straight line.
    Screw {
        /// A point on the axis (world frame, metres).
        axis_point: Vec3,
        /// Unit removal direction, along the axis.
        direction: Vec3,
        /// Travel in metres.
        distance: f32,
    },
}

/// The pose a fraction `s` of the way from `a` to `b`: the `pivot`'s image moves linearly, the
/// rotation turns by slerp about it.
pub fn interpolate_about(pivot: Vec3, a: &Pose, b: &Pose, s: f32) -> Pose {
    let centre = a.transform_point(pivot).lerp(b.transform_point(pivot), s);
    let r = a.rotation.slerp(b.rotation, s);
    Pose::from_parts(centre - r * pivot, r)
}

impl Motion {
    /// The distance the part's pivot (or any point, for a straight line) travels, in metres.
    pub fn length(&self) -> f32 {
        match self {
            Motion::Linear { distance, .. } | Motion::Screw { distance, .. } => *distance,
            Motion::Path { poses, pivot } => {
                poses.windows(2).map(|w| (w[1].transform_point(*pivot) - w[0].transform_point(*pivot)).length()).sum()
            }
        }
    }
}

/// Which kind of motion a removal test may use.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MotionKind {
    /// Straight lines along the candidate directions (the fast test).
    Linear,
    /// A sampling-based path planner (RRT-Connect in SE(3)), seeded.
    Path {
        /// Seed of the planner's random choices.
        seed: u64,
    },
}

/// The answer to "can this part leave this state?".
#[derive(Clone, Debug, PartialEq)]
pub enum Outcome {
    /// The part leaves along `motion`, and what remains is stable.
    Removed(Motion),
    /// Every motion tried collides; `blockers` are the present parts that stopped it.
    Collision {
        /// The parts that block at least one tried motion.
        blockers: PartSet,
    },
    /// The part could leave, but what remains is unstable: `floating` parts lose their support.
    Unstable {
        /// The parts left without support (empty when a physics check cannot say which).
        floating: PartSet,
        /// The motion the part would have used.
        motion: Motion,
    },
}

/// Whether a state stands.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Stability {
    /// Every present part is supported.
    Stable,
    /// These parts are not supported.
    Unstable {
        /// The parts that would fall (or moved in simulation).
        floating: PartSet,
    },
}

/// Test counters (the thesis' measures of planning effort).
#[derive(Debug, Default)]
pub struct Counters {
    /// Removal tests run.
    pub removal_tests: AtomicU64,
    /// Tests that failed because every motion collided.
    pub failed_collision: AtomicU64,
    /// Tests that failed because the remaining state was unstable.
    pub failed_gravity: AtomicU64,
    /// Calls of the path planner.
    pub path_planner_calls: AtomicU64,
}

/// A copy of the counters at one moment.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct CounterSnapshot {
    /// Removal tests run.
    pub removal_tests: u64,
    /// Tests that failed because every motion collided.
    pub failed_collision: u64,
    /// Tests that failed because the remaining state was unstable.
    pub failed_gravity: u64,
    /// Calls of the path planner.
    pub path_planner_calls: u64,
}

impl CounterSnapshot {
    /// Records one test and its outcome (for a search that counts its own tests).
    pub fn record(&mut self, kind: MotionKind, outcome: &Outcome) {
        self.removal_tests += 1;
        self.path_planner_calls += u64::from(matches!(kind, MotionKind::Path { .. }));
        self.failed_collision += u64::from(matches!(outcome, Outcome::Collision { .. }));
        self.failed_gravity += u64::from(matches!(outcome, Outcome::Unstable { .. }));
    }
}

impl Counters {
    /// Records one test and its outcome.
    pub fn record(&self, kind: MotionKind, outcome: &Outcome) {
        self.removal_tests.fetch_add(1, Ordering::Relaxed);
        if matches!(kind, MotionKind::Path { .. }) {
            self.path_planner_calls.fetch_add(1, Ordering::Relaxed);
        }
        match outcome {
            Outcome::Removed(_) => {}
            Outcome::Collision { .. } => {
                self.failed_collision.fetch_add(1, Ordering::Relaxed);
            }
            Outcome::Unstable { .. } => {
                self.failed_gravity.fetch_add(1, Ordering::Relaxed);
            }
        }
    }

    /// The current values.
    pub fn snapshot(&self) -> CounterSnapshot {
        CounterSnapshot {
            removal_tests: self.removal_tests.load(Ordering::Relaxed),
            failed_collision: self.failed_collision.load(Ordering::Relaxed),
            failed_gravity: self.failed_gravity.load(Ordering::Relaxed),
            path_planner_calls: self.path_planner_calls.load(Ordering::Relaxed),
        }
    }
}

/// Removal test + stability, as a planner sees them. Implementations count every test they run.
///
/// A checker that decorates another (held parts, declared units) names it in
/// [`FeasibilityChecker::decorated`]: every optional method it does not define then forwards to
/// the decorated checker, so a decorator changes what it means to change and forgets nothing.
/// The defaults below are a checker's that decorates nothing.
pub trait FeasibilityChecker: Send + Sync {
    /// Number of parts (indices `0..num_parts()`).
    fn num_parts(&self) -> usize;
    /// Whether part `i` is a base part that is never removed.
    fn is_fixed(&self, part: usize) -> bool;
    /// Tests whether `part` can leave `state` (which contains it) with a motion of `kind`, and
    /// whether `state` without it is stable. Counts the test.
    fn test_removal(&self, part: usize, state: &PartSet, kind: MotionKind) -> Outcome;
    /// Whether `state` is stable (not counted as a removal test).
    fn stability(&self, state: &PartSet) -> Stability;
    /// The counters so far.
    fn counters(&self) -> CounterSnapshot;

    /// The checker this one decorates, to which every optional method it does not define
    /// forwards. Default: `None` (it decorates nothing).
    fn decorated(&self) -> Option<&dyn FeasibilityChecker> {
        None
    }

    /// Candidate subassemblies of `state`: sets of at least two present, non-fixed parts that can
    /// translate together along one straight line without colliding with the rest (for each
    /// candidate direction, the closure of a part under "is blocked by"), smallest first, without
    /// duplicates. Default: none (a checker that cannot move groups).
    fn group_candidates(&self, state: &PartSet) -> Vec<PartSet> {
        self.decorated().map_or_else(Vec::new, |c| c.group_candidates(state))
    }

    /// Whether some rigid group of parts of `state` that contains `part` and no fixed part could
    /// translate along a candidate direction (a closure under blocking that reaches no fixed
    /// part). Removing other parts never makes such a closure smaller, so `false` holds in every
    /// state that contains this one. Default: `false` (a checker that cannot move groups).
    fn in_movable_group(&self, part: usize, state: &PartSet) -> bool {
        self.decorated().is_some_and(|c| c.in_movable_group(part, state))
    }

    /// Tests whether the parts of `group` (present, non-fixed) can leave `state` together as one
    /// rigid body along a straight line, and whether what remains is stable. Counts the test.
    /// Default: blocked by nothing nameable (a checker that cannot move groups).
    fn test_group_removal(&self, group: &PartSet, state: &PartSet) -> Outcome {
        match self.decorated() {
            Some(c) => c.test_group_removal(group, state),
            None => Outcome::Collision { blockers: PartSet::empty(group.len()) },
        }
    }

    /// The checker of a subassembly planned on its own: its base part (one of `group`) and a
    /// checker in which that base is the only fixed part (no virtual ground), so the group's own
    /// disassembly can be planned. Default: `None` (subassemblies stay unplanned).
    fn subassembly(&self, group: &PartSet) -> Option<(usize, Box<dyn FeasibilityChecker + '_>)> {
        self.decorated()?.subassembly(group)
    }

    /// Whether `group` is a unit declared by the user (a purchased component: planned as one
    /// part on purpose, never taken apart). Default: `false`.
    fn is_unit(&self, group: &PartSet) -> bool {
        self.decorated().is_some_and(|c| c.is_unit(group))
    }

    /// Why a checker that decorates another (a robot arm that must also carry the part out)
    /// refused the removal of `part` from `state` that its inner checker admitted, as a short
    /// reason (`blocked`, `no reachable grasp`, `no path`): its first such refusal of that part
    /// in that state (the test then returned [`Outcome::Collision`]), `None` when it never
    /// refused it there. Removability labels record it. Default: `None` (nothing decorates).
    fn refusal_reason(&self, part: usize, state: &PartSet) -> Option<&'static str> {
        self.decorated()?.refusal_reason(part, state)
    }
}
