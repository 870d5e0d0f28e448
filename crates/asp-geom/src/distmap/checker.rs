//! [`MapChecker`]: the maps as a [`FeasibilityChecker`].

use super::DistanceMaps;
use crate::feasibility::{CounterSnapshot, Counters, FeasibilityChecker, MotionKind, Outcome, Stability};
use crate::partset::PartSet;

/// The distance maps as a [`FeasibilityChecker`]: removability (eq. 6.5) and the gravity check
/// of 6.3.2, counted like any removal test. Motions are straight lines along the sampled
/// direction that clears the remaining parts' bounds soonest.
#[derive(Debug)]
pub struct MapChecker {
    maps: std::sync::Arc<DistanceMaps>,
    counters: Counters,
}

impl MapChecker {
    /// A checker over `maps`.
    pub fn new(maps: std::sync::Arc<DistanceMaps>) -> Self {
        MapChecker { maps, counters: Counters::default() }
    }

    /// The maps.
    pub fn maps(&self) -> &DistanceMaps {
        &self.maps
    }
}

impl FeasibilityChecker for MapChecker {
    fn num_parts(&self) -> usize {
        self.maps.n
    }

    fn is_fixed(&self, part: usize) -> bool {
        self.maps.fixed[part]
    }

    fn test_removal(&self, part: usize, state: &PartSet, kind: MotionKind) -> Outcome {
        let maps = &self.maps;
        let outcome = match maps.removal_motion(part, state) {
            None => {
                let mut blockers = PartSet::empty(maps.n);
                for &j in &maps.blockers[part] {
                    if state.contains(j as usize) {
                        blockers.insert(j as usize);
                    }
                }
                Outcome::Collision { blockers }
            }
            Some(motion) => match maps.stability(&state.without(part)) {
                Stability::Stable => Outcome::Removed(motion),
                Stability::Unstable { floating } => Outcome::Unstable { floating, motion },
            },
        };
        self.counters.record(kind, &outcome);
        outcome
    }

    fn stability(&self, state: &PartSet) -> Stability {
        self.maps.stability(state)
    }

    fn counters(&self) -> CounterSnapshot {
        self.counters.snapshot()
    }
}
