//! Local search over the answer's sequences (Pareto local search, after Paquete et al.): every
//! complete sequence that enters a search thread's front of sampled sequences (its seeds) is
//! taken apart by *block moves* —
//! a run of one to [`MAX_BLOCK`] consecutive removals moved earlier or later in the sequence —
//! and every feasible neighbour the archive keeps (it is not dominated) is searched in turn.
//!
//! Random rollouts find the sequences of a front's crowded middle; they rarely find the ones
//! that need many removals in a coordinated order, e.g. all removals along one direction kept
//! together for the direction-change objective. A block move is one step there. On random
//! 4×4×4 Soma cubes (access, direction changes) it lifts a 10-s Pareto-MCTS run from 0.83 to
//! 0.92-0.97 of the exact front's hypervolume, with 5-7 % of the search's work
//! (docs/benchmarks.md, "Local search over the answer").
//!
//! A neighbour is evaluated from where it departs from its sequence: the state after the
//! common prefix is kept, only the moved window is replayed, and past the window the replay
//! stops as soon as the objectives' memories equal the original's at that step — the removed
//! parts are then the same, so the rest of the sequence is feasible and earns the same rewards
//! (the premise of [`crate::exact`] too). Steps are [`StepKind::Replay`] steps: what the local
//! search finds replays.
//!
//! Its work is counted in map steps and filter checks and kept to a share of the search's own
//! ([`crate::mcts::SearchBuilder::polish`]), so the search stays deterministic for a seed.

use crate::hypervolume::ParetoFront;
use crate::mdp::{FilterCounts, Mdp};
use crate::step::StepKind;
use asp_geom::distmap::MapState;

/// The longest block of consecutive removals a move takes.
pub const MAX_BLOCK: usize = 3;

/// One search thread's local search: its scratch and its queue of sequences to search around.
pub(crate) struct Polisher<'p> {
    problem: &'p Mdp,
    m: usize,
    w: usize,
    /// The state after the sequence's first `lo` removals, and a copy a neighbour changes.
    base: MapState<'p>,
    trial: MapState<'p>,
    /// The sequence's memories before each step (`w` words per step, `len + 1` steps) and its
    /// cumulative rewards (`m` per step).
    memories: Vec<u64>,
    totals: Vec<f64>,
    /// Scratch: a neighbour, its memory, one step's rewards, its running totals.
    neighbour: Vec<u16>,
    memory: Vec<u64>,
    rewards: Vec<f64>,
    running: Vec<f64>,
    counts: FilterCounts,
    /// Sequences not searched around yet (the last found first), whether each is a seed
    /// (searched around even when the archive no longer holds it), and the position its search
    /// goes on from.
    pub queue: Vec<(Vec<u16>, bool, usize)>,
    /// The front of the search's own sequences: each that enters it seeds a local search.
    seeds: ParetoFront<()>,
    /// Work so far, in map steps (a removal, or a copy of the state).
    pub steps: u64,
}

/// Why a search around a sequence ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Ended {
    /// Every neighbour was tried.
    Done,
    /// `stop` said to stop; the neighbours from this position on were not tried (pass it as
    /// `from` to go on).
    Stopped(usize),
}

impl<'p> Polisher<'p> {
    pub fn new(problem: &'p Mdp) -> Self {
        let maps = problem.maps();
        let w = problem.initial_memory().len();
        Polisher {
            problem,
            m: problem.num_objectives(),
            w,
            base: MapState::new(maps),
            trial: MapState::new(maps),
            memories: Vec::new(),
            totals: Vec::new(),
            neighbour: Vec::new(),
            memory: Vec::new(),
            rewards: vec![0.0; problem.num_objectives()],
            running: vec![0.0; problem.num_objectives()],
            counts: problem.filter_counts(),
            queue: Vec::new(),
            seeds: ParetoFront::new(problem.num_objectives()),
            steps: 0,
        }
    }

    /// Offers a complete sequence the search found (with its values): it seeds a local search
    /// when no sequence the search found before dominates or equals it. Seeds come from the
    /// search's own front, not the archive the local search improves: improved sequences
    /// would otherwise crowd out the variety the search brings.
    pub fn seed(&mut self, values: &[f64], seq: &[u16]) {
        if self.seeds.insert(values, || ()) {
            self.queue.push((seq.to_vec(), true, 0));
        }
    }

    /// The removals the local search put to the problem's feasibility filters so far.
    pub fn checks(&self) -> u64 {
        self.counts.checks()
    }

    /// Its filters' rejections and checks, by reason.
    pub fn counts(&self) -> &FilterCounts {
        &self.counts
    }

    /// Whether `part` is a feasible removal of `state` with `memory` (a replay step).
    fn admits(problem: &Mdp, state: &mut MapState<'_>, memory: &[u64], part: usize, counts: &mut FilterCounts) -> bool {
        state.can_remove(part) && problem.admits(state, memory, part, StepKind::Replay, counts)
    }

    /// Replays `seq` from the assembled state, keeping its memories and cumulative rewards;
    /// false when it does not replay.
    fn replay(&mut self, seq: &[u16]) -> bool {
        let (m, w) = (self.m, self.w);
        let problem = self.problem;
        self.base.reset(&asp_geom::PartSet::full(problem.maps().num_parts()));
        self.memory.clear();
        self.memory.extend(problem.initial_memory());
        self.memories.clear();
        self.totals.clear();
        self.totals.resize(m, 0.0);
        for (t, &p) in seq.iter().enumerate() {
            self.memories.extend_from_slice(&self.memory);
            self.steps += 1;
            if !Self::admits(problem, &mut self.base, &self.memory, p as usize, &mut self.counts) {
                return false;
            }
            problem.step(&mut self.base, &mut self.memory, p as usize, StepKind::Replay, &mut self.rewards);
            for k in 0..m {
                let v = self.totals[t * m + k] + self.rewards[k];
                self.totals.push(v);
            }
        }
        self.memories.extend_from_slice(&self.memory);
        debug_assert_eq!(self.memories.len(), (seq.len() + 1) * w);
        self.base.is_complete()
    }

    /// Searches the neighbours of `seq` (a complete sequence) whose first change is at position
    /// `from` or later, adding to `archive` every neighbour it keeps and queueing it; `found` is
    /// told each one's values. `stop` is asked between neighbours, with the work so far (map
    /// steps and filter checks).
    pub fn search_around(
        &mut self,
        seq: &[u16],
        from: usize,
        archive: &mut ParetoFront<Vec<u16>>,
        mut found: impl FnMut(&[f64]),
        mut stop: impl FnMut(u64, u64) -> bool,
    ) -> Ended {
        let len = seq.len();
        if len < 2 || !self.replay(seq) {
            return Ended::Done;
        }
        let w = self.w;
        let problem = self.problem;
        self.base.reset(&asp_geom::PartSet::full(problem.maps().num_parts()));
        for (lo, &part) in seq.iter().enumerate().take(from.min(len - 1)) {
            self.memory.clear();
            self.memory.extend_from_slice(&self.memories[lo * w..(lo + 1) * w]);
            problem.step(&mut self.base, &mut self.memory, part as usize, StepKind::Replay, &mut self.rewards);
            self.steps += 1;
        }
        for lo in from..len - 1 {
            // moves whose first changed position is `lo`: a block starting at `lo` moved later,
            // or a block starting after `lo` moved to `lo`
            for block in 1..=MAX_BLOCK.min(len - lo - 1) {
                for to in lo + 1..=len - block {
                    // later: seq[lo..lo+block] goes to position `to` of the rest
                    if stop(self.steps, self.counts.checks()) {
                        return Ended::Stopped(lo);
                    }
                    self.neighbour.clear();
                    self.neighbour.extend_from_slice(&seq[..lo]);
                    self.neighbour.extend_from_slice(&seq[lo + block..to + block]);
                    self.neighbour.extend_from_slice(&seq[lo..lo + block]);
                    self.neighbour.extend_from_slice(&seq[to + block..]);
                    self.try_neighbour(lo, to + block, archive, &mut found);
                    // earlier: seq[to..to+block] goes to position `lo`
                    // (a block of at most MAX_BLOCK moved past this one is a later move above)
                    if to - lo > MAX_BLOCK {
                        self.neighbour.clear();
                        self.neighbour.extend_from_slice(&seq[..lo]);
                        self.neighbour.extend_from_slice(&seq[to..to + block]);
                        self.neighbour.extend_from_slice(&seq[lo..to]);
                        self.neighbour.extend_from_slice(&seq[to + block..]);
                        self.try_neighbour(lo, to + block, archive, &mut found);
                    }
                }
            }
            // the base state moves one removal on
            let p = seq[lo] as usize;
            self.memory.clear();
            self.memory.extend_from_slice(&self.memories[lo * w..(lo + 1) * w]);
            problem.step(&mut self.base, &mut self.memory, p, StepKind::Replay, &mut self.rewards);
            self.steps += 1;
        }
        Ended::Done
    }

    /// Evaluates `self.neighbour`, which departs from the sequence in positions `lo..hi`, from
    /// the base state (the sequence's after `lo` removals); keeps it when the archive does.
    fn try_neighbour(&mut self, lo: usize, hi: usize, archive: &mut ParetoFront<Vec<u16>>, found: &mut impl FnMut(&[f64])) {
        let (m, w) = (self.m, self.w);
        let problem = self.problem;
        let len = self.neighbour.len();
        self.trial.clone_from(&self.base);
        self.steps += 1;
        self.memory.clear();
        self.memory.extend_from_slice(&self.memories[lo * w..(lo + 1) * w]);
        self.running.copy_from_slice(&self.totals[lo * m..(lo + 1) * m]);
        for t in lo..len {
            if t >= hi && self.memory[..] == self.memories[t * w..(t + 1) * w] {
                // same parts left, same memories: the rest is the sequence's own
                for k in 0..m {
                    self.running[k] += self.totals[len * m + k] - self.totals[t * m + k];
                }
                break;
            }
            let p = self.neighbour[t] as usize;
            self.steps += 1;
            if !Self::admits(problem, &mut self.trial, &self.memory, p, &mut self.counts) {
                return;
            }
            problem.step(&mut self.trial, &mut self.memory, p, StepKind::Replay, &mut self.rewards);
            for k in 0..m {
                self.running[k] += self.rewards[k];
            }
            if t + 1 == len && !self.trial.is_complete() {
                return;
            }
        }
        // a neighbour must beat every archived point by more than rounding (the shortcut sums
        // in another order than a replay; ties would otherwise swap places forever)
        let running = &self.running;
        if archive.iter().any(|(p, _)| p.iter().zip(running).all(|(a, b)| *a >= b - 1e-9 * b.abs().max(1.0))) {
            return;
        }
        let neighbour = &self.neighbour;
        if archive.insert(&self.running, || neighbour.clone()) {
            found(&self.running);
            self.queue.push((self.neighbour.clone(), false, 0));
        }
    }
}
