//! A worker's recording of the removal steps it simulates
//! ([`super::SearchBuilder::record_transitions`]).

use super::outcome::Transition;
use crate::mdp::FilterCounts;
use crate::step::StepKind;
use asp_geom::PartSet;

/// A worker's recording: the transitions so far, the step being recorded (until the feasible
/// actions of its `s'` are known) and scratch.
pub(super) struct Recorder {
    pub transitions: Vec<Transition>,
    pub limit: usize,
    pub capped: bool,
    /// The current episode's number.
    pub episode: u64,
    pub pending: Option<Transition>,
    pub actions: Vec<usize>,
    pub counts: FilterCounts,
}

impl Recorder {
    /// Whether there is room for another transition (sets `capped` when there is not).
    pub fn active(&mut self) -> bool {
        if self.transitions.len() >= self.limit {
            self.capped = true;
        }
        !self.capped
    }

    /// Starts recording a step from `s` (before it is taken). A step whose action is not among
    /// `s`'s admitted ones is not recorded: the search tried a removal the filters refuse (a lazy
    /// filter's candidate, a robot that cannot take the part), its reward is the objective's
    /// penalty, not an outcome, and a learner reads `action ∈ actions` as the data's contract.
    pub fn begin(&mut self, kind: StepKind, present: PartSet, memory: &[u64], actions: &[usize], action: usize) {
        if !actions.contains(&action) {
            self.pending = None;
            return;
        }
        self.pending = Some(Transition {
            episode: self.episode,
            kind,
            present,
            memory: memory.to_vec(),
            actions: actions.to_vec(),
            action,
            rewards: Vec::new(),
            next_memory: Vec::new(),
            next_actions: Vec::new(),
            complete: false,
        });
    }

    /// The step's outcome, once taken.
    pub fn taken(&mut self, rewards: &[f64], next_memory: &[u64], complete: bool) {
        if let Some(t) = &mut self.pending {
            t.rewards = rewards.to_vec();
            t.next_memory = next_memory.to_vec();
            t.complete = complete;
        }
    }

    /// Completes the pending step with the feasible actions of its `s'`.
    pub fn finish(&mut self, next_actions: &[usize]) {
        if let Some(mut t) = self.pending.take() {
            t.next_actions = next_actions.to_vec();
            self.transitions.push(t);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn recorder() -> Recorder {
        Recorder {
            transitions: Vec::new(),
            limit: 10,
            capped: false,
            episode: 0,
            pending: None,
            actions: Vec::new(),
            counts: FilterCounts::default(),
        }
    }

    #[test]
    fn a_step_the_filters_refuse_is_not_recorded() {
        let mut r = recorder();
        let present = PartSet::full(4);
        r.begin(StepKind::Expansion, present.clone(), &[], &[0, 1], 3);
        r.taken(&[-20.0], &[], false);
        r.finish(&[0, 1]);
        assert!(r.transitions.is_empty());
        r.begin(StepKind::Expansion, present, &[], &[0, 1], 1);
        r.taken(&[-1.0], &[], false);
        r.finish(&[0]);
        assert_eq!(r.transitions.len(), 1);
        assert_eq!((r.transitions[0].action, r.transitions[0].rewards[0]), (1, -1.0));
    }
}
