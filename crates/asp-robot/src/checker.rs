//! The depth-first planner's feasibility with a robot: a [`FeasibilityChecker`] decorator that
//! admits a removal only when the arm can also take the part out ([`RemovalPlanner`]).
//!
//! The inner checker answers first (straight lines, stability); a part it lets leave along a
//! straight line is then planned for the robot, lifted along that line. A robot failure turns
//! the outcome into a collision whose blockers are the other present, non-fixed parts (any of
//! them might be what the arm hits, so the search never concludes that removing others cannot
//! help). Groups (subassemblies) are not offered: the robot carries one part at a time. Path
//! motions (the SE(3) path planner) are refused: the robot needs a straight lift.
//!
//! Every successful plan is kept by state and part, so the plan's steps can be annotated with
//! the robot's grasp, gripper path and joint trajectory ([`RobotChecker::removal`]); every
//! failure is counted by reason, the last one per part is kept ([`RobotChecker::failure`]), and
//! so is the first one per state and part ([`RobotChecker::refusal`]): the robot's reason for a
//! dead end, which the search saw only as a collision with every part.

use std::collections::HashMap;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Mutex;

use asp_geom::{Checker, CounterSnapshot, FeasibilityChecker, Motion, MotionKind, Outcome, PartSet, Stability, World};

use crate::removal::{RemovalPlanner, RobotFailure, RobotRemoval};

/// A deterministic seed for the robot's plan of `part` in `state`.
pub fn step_seed(seed: u64, state: &PartSet, part: usize) -> u64 {
    asp_geom::seed::derive(seed, asp_geom::seed::Stream::Robot, state, part as u64)
}

/// The unit direction of a removal's first move (a straight line's direction, a path's first
/// segment), `None` when it does not start with a translation.
fn first_direction(motion: &Motion) -> Option<asp_geom::math::Vec3> {
    match motion {
        Motion::Linear { direction, .. } | Motion::Screw { direction, .. } => Some(*direction),
        Motion::Path { poses, pivot } => poses
            .windows(2)
            .map(|w| w[1].transform_point(*pivot) - w[0].transform_point(*pivot))
            .find(|d| d.length() > 1e-6)
            .map(|d| d.normalize()),
    }
}

/// Robot removability on top of a collision-world checker. It names no
/// [`FeasibilityChecker::decorated`] checker on purpose: it offers no groups (the robot carries
/// one part at a time), and its refusal reasons are its own.
pub struct RobotChecker<'c> {
    inner: &'c dyn FeasibilityChecker,
    planner: RemovalPlanner<&'c World>,
    seed: u64,
    replans: usize,
    plans: Mutex<HashMap<(Vec<u64>, usize), RobotRemoval>>,
    failures: Mutex<HashMap<usize, RobotFailure>>,
    refusals: Mutex<HashMap<(Vec<u64>, usize), RobotFailure>>,
    counts: [AtomicU64; 3],
}

impl std::fmt::Debug for RobotChecker<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("RobotChecker").field("planner", &self.planner).finish_non_exhaustive()
    }
}

impl<'c> RobotChecker<'c> {
    /// Wraps `inner`; `planner` must plan on the world `inner` tests on. `replans` is `k`.
    pub fn new(inner: &'c dyn FeasibilityChecker, planner: RemovalPlanner<&'c World>, seed: u64, replans: usize) -> Self {
        RobotChecker {
            inner,
            planner,
            seed,
            replans,
            plans: Mutex::new(HashMap::new()),
            failures: Mutex::new(HashMap::new()),
            refusals: Mutex::new(HashMap::new()),
            counts: Default::default(),
        }
    }

    /// The robot planner.
    pub fn planner(&self) -> &RemovalPlanner<&'c World> {
        &self.planner
    }

    /// The robot's plan for removing `part` from `state`, when a test admitted it.
    pub fn removal(&self, part: usize, state: &PartSet) -> Option<RobotRemoval> {
        self.plans.lock().expect("not poisoned").get(&(state.words().to_vec(), part)).cloned()
    }

    /// The last robot failure of `part`, if it ever failed.
    pub fn failure(&self, part: usize) -> Option<RobotFailure> {
        self.failures.lock().expect("not poisoned").get(&part).cloned()
    }

    /// Why the robot refused to take `part` out of `state`, when the inner checker let it out
    /// and the robot did not: the first refusal in that state (a straight lift's reason outlasts
    /// the later refusal of a path motion, [`RobotFailure::Blocked`] without a part).
    pub fn refusal(&self, part: usize, state: &PartSet) -> Option<RobotFailure> {
        self.refusals.lock().expect("not poisoned").get(&(state.words().to_vec(), part)).cloned()
    }

    /// Robot failures so far by reason ([`RobotFailure::REASONS`] order).
    pub fn failure_counts(&self) -> [u64; 3] {
        [0, 1, 2].map(|i| self.counts[i].load(Ordering::Relaxed))
    }

    fn refuse(&self, part: usize, state: &PartSet, failure: RobotFailure) -> Outcome {
        self.counts[failure.index()].fetch_add(1, Ordering::Relaxed);
        self.refusals.lock().expect("not poisoned").entry((state.words().to_vec(), part)).or_insert_with(|| failure.clone());
        self.failures.lock().expect("not poisoned").insert(part, failure);
        let mut blockers = state.without(part);
        for p in state.iter() {
            if self.inner.is_fixed(p) {
                blockers.remove(p);
            }
        }
        Outcome::Collision { blockers }
    }
}

impl FeasibilityChecker for RobotChecker<'_> {
    fn num_parts(&self) -> usize {
        self.inner.num_parts()
    }

    fn is_fixed(&self, part: usize) -> bool {
        self.inner.is_fixed(part)
    }

    fn test_removal(&self, part: usize, state: &PartSet, kind: MotionKind) -> Outcome {
        let outcome = self.inner.test_removal(part, state, kind);
        match &outcome {
            // a screw turns out as its thread requires: not the arm's lift (as before)
            Outcome::Removed(Motion::Screw { .. }) => outcome,
            Outcome::Removed(motion) => {
                let key = (state.words().to_vec(), part);
                if self.plans.lock().expect("not poisoned").contains_key(&key) {
                    return outcome;
                }
                // the arm lifts up when it can (thesis 5.3), else along the motion's first move
                let Some(direction) = first_direction(motion) else {
                    return self.refuse(part, state, RobotFailure::Blocked { by: None });
                };
                match self.planner.plan(part, state, direction, step_seed(self.seed, state, part), self.replans) {
                    Ok(r) => {
                        self.plans.lock().expect("not poisoned").insert(key, r);
                        outcome
                    }
                    Err(f) => self.refuse(part, state, f),
                }
            }
            _ => outcome,
        }
    }

    fn stability(&self, state: &PartSet) -> Stability {
        self.inner.stability(state)
    }

    fn counters(&self) -> CounterSnapshot {
        self.inner.counters()
    }

    fn refusal_reason(&self, part: usize, state: &PartSet) -> Option<&'static str> {
        self.refusal(part, state).map(|f| RobotFailure::REASONS[f.index()])
    }
}

/// A state and the parts removed from it, as bitset words (the held-parts cache key).
type HeldKey = (Vec<u64>, Vec<u64>);

/// Held parts (`--grippers N`): a removal whose remaining state would not stand is admitted
/// when holding at most `N - 1` of the remaining, non-fixed parts in place (a second gripper or
/// a fixture) makes it stand. Candidates to hold: the parts that would fall first, then the
/// other remaining parts in index order; sets of one part, then of two (when `N ≥ 3`, among the
/// first 12 candidates). The same holds for groups leaving as one rigid subassembly: every
/// group operation of the inner checker is passed through, so holding parts never takes away a
/// plan the inner checker finds (more grippers, never fewer plans). The held parts of each
/// admitted removal are kept ([`HoldingChecker::held`]).
pub struct HoldingChecker<'c> {
    inner: &'c Checker,
    grippers: usize,
    /// Held parts by (state, removed parts).
    held: Mutex<HashMap<HeldKey, PartSet>>,
}

impl std::fmt::Debug for HoldingChecker<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("HoldingChecker").field("grippers", &self.grippers).finish_non_exhaustive()
    }
}

impl<'c> HoldingChecker<'c> {
    /// Wraps `inner` with `grippers` grippers in all (the robot's included).
    pub fn new(inner: &'c Checker, grippers: usize) -> Self {
        HoldingChecker { inner, grippers, held: Mutex::new(HashMap::new()) }
    }

    /// The parts held while the rest of `state` stands without `removed` (a part or a rigid
    /// group; empty when none).
    pub fn held(&self, removed: &PartSet, state: &PartSet) -> Vec<usize> {
        let key = (state.words().to_vec(), removed.words().to_vec());
        self.held.lock().expect("not poisoned").get(&key).map_or_else(Vec::new, |h| h.iter().collect())
    }

    /// `outcome` of removing `removed` from `state`, admitted when holding parts makes the rest
    /// stand (and the held parts kept).
    fn admit(&self, removed: &PartSet, state: &PartSet, outcome: Outcome) -> Outcome {
        match outcome {
            Outcome::Unstable { floating, motion } if self.grippers >= 2 => {
                let mut rest = state.clone();
                for p in removed.iter() {
                    rest.remove(p);
                }
                match self.holding(&rest, &floating) {
                    Some(h) => {
                        self.held.lock().expect("not poisoned").insert((state.words().to_vec(), removed.words().to_vec()), h);
                        Outcome::Removed(motion)
                    }
                    None => Outcome::Unstable { floating, motion },
                }
            }
            other => other,
        }
    }

    fn holding(&self, rest: &PartSet, floating: &PartSet) -> Option<PartSet> {
        let n = self.inner.num_parts();
        let mut candidates: Vec<usize> = floating.iter().filter(|&p| p < n && rest.contains(p) && !self.inner.is_fixed(p)).collect();
        for p in rest.iter() {
            if p < n && !self.inner.is_fixed(p) && !candidates.contains(&p) {
                candidates.push(p);
            }
        }
        let stands = |held: &PartSet| self.inner.stability_holding(rest, held) == Stability::Stable;
        for &c in &candidates {
            let h = PartSet::from_indices(n, [c]);
            if stands(&h) {
                return Some(h);
            }
        }
        if self.grippers >= 3 {
            let first = &candidates[..candidates.len().min(12)];
            for (i, &a) in first.iter().enumerate() {
                for &b in &first[i + 1..] {
                    let h = PartSet::from_indices(n, [a, b]);
                    if stands(&h) {
                        return Some(h);
                    }
                }
            }
        }
        None
    }
}

impl FeasibilityChecker for HoldingChecker<'_> {
    fn num_parts(&self) -> usize {
        self.inner.num_parts()
    }

    fn is_fixed(&self, part: usize) -> bool {
        self.inner.is_fixed(part)
    }

    fn test_removal(&self, part: usize, state: &PartSet, kind: MotionKind) -> Outcome {
        let outcome = self.inner.test_removal(part, state, kind);
        self.admit(&PartSet::from_indices(self.inner.num_parts(), [part]), state, outcome)
    }

    fn test_group_removal(&self, group: &PartSet, state: &PartSet) -> Outcome {
        let outcome = self.inner.test_group_removal(group, state);
        self.admit(group, state, outcome)
    }

    fn stability(&self, state: &PartSet) -> Stability {
        self.inner.stability(state)
    }

    fn counters(&self) -> CounterSnapshot {
        self.inner.counters()
    }

    /// The inner checker: its groups, a subassembly planned on its own base (nothing held
    /// inside it), its units and refusal reasons are this checker's.
    fn decorated(&self) -> Option<&dyn FeasibilityChecker> {
        Some(self.inner)
    }
}
