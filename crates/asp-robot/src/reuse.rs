//! Robot verdicts reused across states: what one search thread has learnt of the arm,
//! kept with the parts that were present when it was learnt.
//!
//! A path is checked against the parts present (its obstacles): it stays collision-free among
//! any subset of them, so it serves every later state whose present parts are a subset of its
//! own, with its length an upper bound on that state's shortest. MCTS states only shrink along
//! an episode, so most rollout steps find such a path and plan nothing.
//!
//! Failures go the other way round, and only those that are monotone are kept: with the same
//! lift, "no reachable grasp" (every grasp out of the arm's reach, which never changes, or
//! colliding with a present part, which more parts do not free) and "no path" (no
//! collision-free path among fewer parts, so none among more) hold in every superset of the
//! state they were found in. A blocked lift is not kept: it is cheap to test again, and which
//! lift a state uses depends on the state.
//!
//! A store is deterministic: its answers depend only on what was put in it, in order. The
//! optimiser keeps one per search thread ([`crate::search::RobotModel`]), so a search's answer
//! depends on its seed and thread count, not on timing.

use std::collections::HashMap;

use asp_geom::math::Vec3;
use asp_geom::PartSet;

use crate::removal::{RobotFailure, RobotRemoval};

/// At most this many paths are kept per part (the oldest go first).
const MAX_PATHS: usize = 64;
/// At most this many failures are kept per part (the oldest go first).
const MAX_FAILURES: usize = 64;

/// A failure with the state it was found in, the lift it used and the plans per grasp.
#[derive(Clone, Debug)]
struct Failed {
    present: PartSet,
    lift: [u32; 3],
    replans: usize,
    failure: RobotFailure,
}

/// Paths and failures of the robot by part, each with the parts present when it was found.
#[derive(Clone, Debug, Default)]
pub struct PathStore {
    paths: HashMap<usize, Vec<(PartSet, RobotRemoval)>>,
    failures: HashMap<usize, Vec<Failed>>,
    hits: u64,
    failure_hits: u64,
}

/// Whether every part of `a` is in `b`.
fn subset(a: &PartSet, b: &PartSet) -> bool {
    a.words().iter().zip(b.words()).all(|(x, y)| x & !y == 0) && a.words().len() <= b.words().len()
}

impl PathStore {
    /// An empty store.
    pub fn new() -> Self {
        PathStore::default()
    }

    /// The shortest kept path of `part` found in a state holding every part of `present`: it is
    /// collision-free in `present`.
    pub fn path(&mut self, part: usize, present: &PartSet) -> Option<&RobotRemoval> {
        let best = self
            .paths
            .get(&part)?
            .iter()
            .filter(|(p, _)| subset(present, p))
            .min_by(|a, b| a.1.length.total_cmp(&b.1.length))
            .map(|(_, r)| r);
        if best.is_some() {
            self.hits += 1;
        }
        best
    }

    /// A kept failure of `part` found in a state whose parts are all in `present`, with the
    /// lift `lift` and at least `replans` plans per grasp ("no path" depends on them, "no
    /// reachable grasp" does not): it holds in `present` too.
    pub fn failure(&mut self, part: usize, present: &PartSet, lift: Vec3, replans: usize) -> Option<RobotFailure> {
        let lift = lift.to_array().map(f32::to_bits);
        let f = self.failures.get(&part)?.iter().find(|f| {
            f.lift == lift
                && subset(&f.present, present)
                && match f.failure {
                    RobotFailure::NoPath { .. } => f.replans >= replans,
                    _ => true,
                }
        })?;
        self.failure_hits += 1;
        Some(f.failure.clone())
    }

    /// Keeps what planning `part` in `present` with lift `lift` and `replans` plans per grasp
    /// gave: a path (unless a kept one, found in a superset, is no longer), or a monotone
    /// failure (a blocked lift is not kept).
    pub fn learn(&mut self, part: usize, present: &PartSet, lift: Vec3, replans: usize, result: &Result<RobotRemoval, RobotFailure>) {
        match result {
            Ok(r) => {
                let list = self.paths.entry(part).or_default();
                if list.iter().any(|(p, k)| subset(present, p) && k.length <= r.length) {
                    return;
                }
                list.retain(|(p, k)| !(subset(p, present) && r.length <= k.length));
                if list.len() >= MAX_PATHS {
                    list.remove(0);
                }
                list.push((present.clone(), r.clone()));
            }
            Err(RobotFailure::Blocked { .. }) => {}
            Err(f) => {
                let list = self.failures.entry(part).or_default();
                if list.len() >= MAX_FAILURES {
                    list.remove(0);
                }
                list.push(Failed { present: present.clone(), lift: lift.to_array().map(f32::to_bits), replans, failure: f.clone() });
            }
        }
    }

    /// How many queries a kept path answered, and how many a kept failure.
    pub fn hits(&self) -> (u64, u64) {
        (self.hits, self.failure_hits)
    }

    /// Paths kept (all parts).
    pub fn paths_kept(&self) -> usize {
        self.paths.values().map(Vec::len).sum()
    }
}
