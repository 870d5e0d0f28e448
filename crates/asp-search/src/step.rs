//! One removal step as objectives and feasibility filters see it: which part of the search takes
//! it ([`StepKind`]) and what it removes from which state ([`StepContext`]).
//!
//! The context holds what the step needs of its problem (the assembly, the seed), not the
//! problem itself, so that objectives ([`crate::objective`]) and filters ([`crate::mdp`]) depend
//! on this module and not on each other; [`StepContext::new`] (in [`crate::mdp`]) takes both
//! from an [`crate::Mdp`].

use asp_geom::distmap::{DistanceMaps, MapState};
use asp_geom::{Assembly, Motion, PartMeta, PartSet};
use std::fmt::Debug;

/// Which part of the search takes a removal step. Objectives and filters that plan (a robot
/// arm) may spend more effort where the result is kept: the thesis plans a robot's path `k`
/// times at expansion and once in simulation (5.4.2).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum StepKind {
    /// The removal becomes an edge of the search graph; its reward is kept there.
    Expansion,
    /// A rollout (simulation) step: the reward counts for one sampled sequence.
    Simulation,
    /// Replaying a finished sequence: an answer's values and motions, exact references, data
    /// collection.
    Replay,
}

/// What an objective (or a feasibility filter) sees of one removal: the part, the state it
/// leaves (before the removal), the problem's assembly and seed, and the step's kind.
pub struct StepContext<'s, 'm> {
    assembly: Option<&'s Assembly>,
    seed: u64,
    state: &'s mut MapState<'m>,
    part: usize,
    kind: StepKind,
    clearance: Option<Option<(usize, f32)>>,
}

impl Debug for StepContext<'_, '_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("StepContext").field("part", &self.part).field("kind", &self.kind).finish_non_exhaustive()
    }
}

impl<'s, 'm> StepContext<'s, 'm> {
    /// The removal of present `part` from `state`, in a problem over `assembly` (when it carries
    /// one) with seed `seed` ([`StepContext::new`] takes both from the problem).
    pub(crate) fn from_parts(assembly: Option<&'s Assembly>, seed: u64, state: &'s mut MapState<'m>, part: usize, kind: StepKind) -> Self {
        StepContext { assembly, seed, state, part, kind, clearance: None }
    }

    /// The part being removed.
    #[inline]
    pub fn part(&self) -> usize {
        self.part
    }

    /// Which part of the search takes the step.
    #[inline]
    pub fn kind(&self) -> StepKind {
        self.kind
    }

    /// The state before the removal (mutable only so that minimum maps are computed lazily:
    /// never remove parts from it).
    #[inline]
    pub fn state(&mut self) -> &mut MapState<'m> {
        self.state
    }

    /// The parts present before the removal.
    pub fn present(&self) -> PartSet {
        self.state.present()
    }

    /// The distance maps.
    #[inline]
    pub fn maps(&self) -> &'m DistanceMaps {
        self.state.maps()
    }

    /// The assembly the maps were built from, when the problem carries it
    /// ([`crate::Mdp::with_assembly`]; the planning pipeline always sets it). Metres, world frame.
    pub fn assembly(&self) -> Option<&'s Assembly> {
        self.assembly
    }

    /// What the file says about the moving part (grasps, kind, boxes), when the problem
    /// carries the assembly.
    pub fn meta(&self) -> Option<&'s PartMeta> {
        self.assembly().map(|a| &a.parts[self.part].meta)
    }

    /// The straight-line removal on the maps: the free direction's index in
    /// [`asp_geom::distmap::Hemisphere::directions`] along which the part's bounds clear the
    /// remaining parts' bounds soonest, and that travel (metres); `None` when the part is
    /// blocked. Computed once per step and shared by every objective.
    pub fn clearance(&mut self) -> Option<(usize, f32)> {
        if self.clearance.is_none() {
            self.clearance = Some(self.state.clearance(self.part));
        }
        self.clearance.expect("just set")
    }

    /// [`StepContext::clearance`] as a motion (without the contact margin the plan adds).
    pub fn motion(&mut self) -> Option<Motion> {
        let maps = self.maps();
        self.clearance().map(|(d, t)| Motion::Linear { direction: maps.hemisphere().directions()[d], distance: t })
    }

    /// A seed for randomised work (a planner's samples) that depends only on the problem's seed
    /// ([`crate::Mdp::with_seed`]), the present parts and the moving part: the same step gives the same
    /// seed in every thread, episode and replay.
    pub fn seed(&self) -> u64 {
        asp_geom::seed::derive(self.seed, asp_geom::seed::Stream::Step, &self.state.present(), self.part as u64)
    }
}
