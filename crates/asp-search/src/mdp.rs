//! The optimisation problem as an MDP (thesis 5.4.1, 6.4.1): states are the parts still present
//! plus the objectives' memories, actions are feasible removals (collision-free along a sampled
//! direction and leaving a supported state, 6.3.2), rewards are the objectives' vector.

use crate::error::{Result, SearchError};
use crate::objective::{Memory, Objective};
use asp_geom::distmap::{DistanceMaps, MapState};
use asp_geom::{Motion, PartSet};
use std::sync::Arc;

/// The most objectives a problem may have (rollouts keep them in fixed-size arrays).
pub const MAX_OBJECTIVES: usize = 8;

/// Distance maps plus the objectives to maximise.
#[derive(Clone, Debug)]
pub struct Mdp {
    maps: Arc<DistanceMaps>,
    objectives: Vec<Arc<dyn Objective>>,
}

impl Mdp {
    /// A problem over `maps` with `objectives` (1 to [`MAX_OBJECTIVES`]).
    pub fn new(maps: Arc<DistanceMaps>, objectives: Vec<Arc<dyn Objective>>) -> Result<Self> {
        if objectives.is_empty() || objectives.len() > MAX_OBJECTIVES {
            return Err(SearchError::config(format!(
                "a problem needs 1 to {MAX_OBJECTIVES} objectives, got {}",
                objectives.len()
            )));
        }
        Ok(Mdp { maps, objectives })
    }

    /// The distance maps.
    pub fn maps(&self) -> &DistanceMaps {
        &self.maps
    }

    /// The shared distance maps.
    pub fn maps_arc(&self) -> &Arc<DistanceMaps> {
        &self.maps
    }

    /// The objectives.
    pub fn objectives(&self) -> &[Arc<dyn Objective>] {
        &self.objectives
    }

    /// Number of objectives.
    pub fn num_objectives(&self) -> usize {
        self.objectives.len()
    }

    /// The objectives' names.
    pub fn objective_names(&self) -> Vec<String> {
        self.objectives.iter().map(|o| o.name().to_string()).collect()
    }

    /// Number of parts that a complete sequence removes (the non-fixed ones).
    pub fn removals(&self) -> usize {
        (0..self.maps.num_parts()).filter(|&i| !self.maps.is_fixed(i)).count()
    }

    /// The hypervolume reference point: every objective's worst possible total.
    pub fn reference_point(&self) -> Vec<f64> {
        let r = self.removals();
        self.objectives.iter().map(|o| o.worst_total(&self.maps, r)).collect()
    }

    /// Rewards for removing `part` from `state` (written to `rewards`, one per objective), then
    /// removes it and updates `memories`.
    #[inline]
    pub fn step(
        &self,
        state: &mut MapState<'_>,
        memories: &mut [Memory],
        part: usize,
        rewards: &mut [f64],
    ) {
        for ((o, m), r) in self.objectives.iter().zip(memories.iter_mut()).zip(rewards.iter_mut()) {
            *r = o.reward(part, state, m);
        }
        state.remove(part);
    }

    /// Replays a disassembly sequence from the assembled state, checking every step's
    /// feasibility, and returns its objective vector and each removal's motion. The sequence
    /// must remove every non-fixed part.
    pub fn evaluate(&self, sequence: &[usize]) -> Result<(Vec<f64>, Vec<Motion>)> {
        let maps = &*self.maps;
        let n = maps.num_parts();
        let mut state = MapState::new(maps);
        let mut memories = vec![Memory::default(); self.objectives.len()];
        let mut rewards = vec![0.0; self.objectives.len()];
        let mut totals = vec![0.0; self.objectives.len()];
        let mut motions = Vec::with_capacity(sequence.len());
        let mut actions = Vec::new();
        for (t, &p) in sequence.iter().enumerate() {
            if p >= n || !state.contains(p) {
                return Err(SearchError::Infeasible {
                    reason: format!("step {t}: part {p} is not present"),
                });
            }
            state.feasible_actions(&mut actions);
            if !actions.contains(&p) {
                let why = if maps.is_fixed(p) {
                    "is fixed"
                } else if !state.is_collision_free(p) {
                    "is blocked in every direction"
                } else {
                    "would leave a part without support"
                };
                return Err(SearchError::Infeasible { reason: format!("step {t}: part {p} {why}") });
            }
            let (d, travel) = state.clearance(p).expect("feasible parts have a free direction");
            motions.push(Motion::Linear {
                direction: maps.hemisphere().directions()[d],
                distance: travel,
            });
            self.step(&mut state, &mut memories, p, &mut rewards);
            for (a, r) in totals.iter_mut().zip(&rewards) {
                *a += r;
            }
        }
        if !state.is_complete() {
            let left: Vec<usize> =
                state.present().iter().filter(|&i| !maps.is_fixed(i)).collect();
            return Err(SearchError::Infeasible {
                reason: format!("the sequence leaves parts {left:?} in place"),
            });
        }
        Ok((totals, motions))
    }

    /// The feasible removals of `state` (a stable state), in increasing part order.
    pub fn feasible_actions(&self, state: &PartSet) -> Vec<usize> {
        let mut s = MapState::new(&self.maps);
        s.reset(state);
        let mut out = Vec::new();
        s.feasible_actions(&mut out);
        out
    }
}
