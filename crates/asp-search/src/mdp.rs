//! The optimisation problem as an MDP (thesis 5.4.1, 6.4.1): states are the parts still present
//! plus the objectives' memories, actions are feasible removals (collision-free along a sampled
//! direction and leaving a supported state, 6.3.2, and admitted by every [`ActionFilter`]),
//! rewards are the objectives' vector.
//!
//! # Memory layout
//! The objectives' memories live in one flat slice of `u64` words per state: objective `k` owns
//! [`Mdp::memory_range`]`(k)`. Its first [`Objective::key_words`] words are part of the state's
//! key ([`Mdp::key_eq`], [`Mdp::hash_key`]).
//!
//! # Feasibility filters
//! An [`ActionFilter`] (a robot that must grasp a part and carry it out, or an objective with
//! rules of its own) removes actions from a state's feasible set; every rejection is counted
//! under the filter's reason ([`FilterCounts`], reported as
//! [`crate::mcts::SearchStats::filtered`]).
//!
//! # Extensions
//! An [`crate::extension::MdpExtension`] adds named objectives and filters to the planning
//! pipeline for a model (how a crate above asp-search, such as the robot, plugs into
//! `asp plan --objective`).

use crate::error::{Result, SearchError};
use crate::objective::Objective;
use crate::step::{StepContext, StepKind};
use asp_geom::distmap::{DistanceMaps, MapState};
use asp_geom::{Assembly, Motion, PartSet};
use std::fmt::Debug;
use std::hash::Hasher;
use std::ops::Range;
use std::sync::Arc;

/// The most objectives a problem may have (rollouts keep them in fixed-size arrays).
pub const MAX_OBJECTIVES: usize = 8;

/// An action filter's answer for one removal.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Verdict {
    /// The removal may be taken.
    Feasible,
    /// The removal is not possible; `reason` indexes the filter's [`ActionFilter::reasons`].
    Infeasible {
        /// Index into [`ActionFilter::reasons`].
        reason: usize,
    },
}

/// Removes actions from a state's feasible set (beyond collision-free and supported on the
/// maps): a robot that must reach a grasp and carry the part out, a fixture, a rule.
///
/// A verdict may depend on the state, the part, the memories and the [`StepKind`] only (use
/// [`StepContext::seed`] for randomised checks). A sequence whose rollout steps were admitted as
/// [`StepKind::Simulation`] is replayed as [`StepKind::Replay`] at the end of a search; a filter
/// whose replay rejects what its simulation admitted loses that answer (counted in
/// [`crate::mcts::SearchStats::replay_failures`]), so let replays try at least what
/// simulations try (e.g. the same seed first).
pub trait ActionFilter: Send + Sync + Debug {
    /// A short name for the statistics (e.g. `robot`).
    fn name(&self) -> &str;

    /// The reasons it rejects removals for, indexed by the `reason` of
    /// [`Verdict::Infeasible`] (e.g. `no reachable grasp`, `no path`).
    fn reasons(&self) -> Vec<String>;

    /// Whether `step.part()` may leave `step`'s state; `memory` holds every objective's memory
    /// words ([`Mdp::memory_range`]).
    fn check(&self, step: &mut StepContext<'_, '_>, memory: &[u64]) -> Verdict;
}

/// How many removals each filter rejected, per reason (one counter per reason of every filter
/// of a problem, in the problem's order; [`Mdp::filter_counts`] makes one).
/// Also counts the removals the filters were asked about ([`FilterCounts::checks`]).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct FilterCounts(Vec<u64>, u64);

impl FilterCounts {
    /// Adds `other`'s counts (of the same problem).
    pub fn add(&mut self, other: &FilterCounts) {
        for (a, b) in self.0.iter_mut().zip(&other.0) {
            *a += b;
        }
        self.1 += other.1;
    }

    /// Removals put to the filters (each asked of every filter until one rejects it).
    pub fn checks(&self) -> u64 {
        self.1
    }
}

/// One reason's rejections, for reports.
#[derive(Clone, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct FilterCount {
    /// The filter's name.
    pub filter: String,
    /// The reason.
    pub reason: String,
    /// Removals rejected for it.
    pub count: u64,
}

impl<'s, 'm> StepContext<'s, 'm> {
    /// The removal of present `part` from `state` in `problem` (the context takes the problem's
    /// assembly and seed).
    pub fn new(problem: &'s Mdp, state: &'s mut MapState<'m>, part: usize, kind: StepKind) -> Self {
        StepContext::from_parts(problem.assembly(), problem.seed(), state, part, kind)
    }
}

/// Distance maps plus the objectives to maximise and the filters on the actions.
#[derive(Clone, Debug)]
pub struct Mdp {
    maps: Arc<DistanceMaps>,
    objectives: Vec<Arc<dyn Objective>>,
    filters: Vec<Arc<dyn ActionFilter>>,
    assembly: Option<Arc<Assembly>>,
    seed: u64,
    /// Objective `k`'s memory words: `offsets[k]..offsets[k + 1]`.
    offsets: Vec<usize>,
    /// Objective `k`'s number of memory words.
    widths: Vec<usize>,
    /// The key words' ranges (consecutive ranges merged).
    key: Vec<Range<usize>>,
    /// Per counter of [`FilterCounts`]: (filter, reason).
    reasons: Vec<(usize, String)>,
    /// Filter `f`'s first counter.
    reason_base: Vec<usize>,
}

impl Mdp {
    /// A problem over `maps` with `objectives` (1 to [`MAX_OBJECTIVES`]).
    pub fn new(maps: Arc<DistanceMaps>, objectives: Vec<Arc<dyn Objective>>) -> Result<Self> {
        if objectives.is_empty() || objectives.len() > MAX_OBJECTIVES {
            return Err(SearchError::config(format!("a problem needs 1 to {MAX_OBJECTIVES} objectives, got {}", objectives.len())));
        }
        let mut offsets = vec![0];
        let mut key: Vec<Range<usize>> = Vec::new();
        for o in &objectives {
            let at = *offsets.last().expect("offsets start at 0");
            let (words, key_words) = (o.memory_words(), o.key_words());
            if key_words > words {
                return Err(SearchError::plugin(
                    format!("objective '{}'", o.name()),
                    format!("{key_words} key words of {words} memory words"),
                ));
            }
            if key_words > 0 {
                match key.last_mut() {
                    Some(r) if r.end == at => r.end = at + key_words,
                    _ => key.push(at..at + key_words),
                }
            }
            offsets.push(at + words);
        }
        let widths = offsets.windows(2).map(|w| w[1] - w[0]).collect();
        Ok(Mdp {
            maps,
            objectives,
            filters: Vec::new(),
            assembly: None,
            seed: 0,
            offsets,
            widths,
            key,
            reasons: Vec::new(),
            reason_base: Vec::new(),
        })
    }

    /// Adds a feasibility filter (applied after the maps' collision and gravity checks, in the
    /// order added).
    pub fn with_filter(mut self, filter: Arc<dyn ActionFilter>) -> Self {
        let f = self.filters.len();
        self.reason_base.push(self.reasons.len());
        let reasons = filter.reasons();
        if reasons.is_empty() {
            self.reasons.push((f, "infeasible".into()));
        }
        self.reasons.extend(reasons.into_iter().map(|r| (f, r)));
        self.filters.push(filter);
        self
    }

    /// Gives objectives and filters the assembly the maps were built from
    /// ([`StepContext::assembly`]).
    pub fn with_assembly(mut self, assembly: Arc<Assembly>) -> Self {
        self.assembly = Some(assembly);
        self
    }

    /// The seed [`StepContext::seed`] derives its seeds from (default 0).
    pub fn with_seed(mut self, seed: u64) -> Self {
        self.seed = seed;
        self
    }

    /// The distance maps.
    pub fn maps(&self) -> &DistanceMaps {
        &self.maps
    }

    /// The shared distance maps.
    pub fn maps_arc(&self) -> &Arc<DistanceMaps> {
        &self.maps
    }

    /// The assembly, when given ([`Mdp::with_assembly`]).
    pub fn assembly(&self) -> Option<&Assembly> {
        self.assembly.as_deref()
    }

    /// The seed of [`Mdp::with_seed`].
    pub fn seed(&self) -> u64 {
        self.seed
    }

    /// The objectives.
    pub fn objectives(&self) -> &[Arc<dyn Objective>] {
        &self.objectives
    }

    /// The feasibility filters.
    pub fn filters(&self) -> &[Arc<dyn ActionFilter>] {
        &self.filters
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

    /// Memory words per state, all objectives.
    #[inline]
    pub fn memory_words(&self) -> usize {
        *self.offsets.last().expect("offsets start at 0")
    }

    /// Objective `k`'s words in a state's memory.
    #[inline]
    pub fn memory_range(&self, k: usize) -> Range<usize> {
        self.offsets[k]..self.offsets[k + 1]
    }

    /// The memory at the assembled state.
    pub fn initial_memory(&self) -> Vec<u64> {
        let mut memory = vec![0; self.memory_words()];
        for (k, o) in self.objectives.iter().enumerate() {
            o.init_memory(&self.maps, &mut memory[self.memory_range(k)]);
        }
        memory
    }

    /// Whether two memories have the same key words (with equal present parts: the same state).
    #[inline]
    pub fn key_eq(&self, a: &[u64], b: &[u64]) -> bool {
        self.key.iter().all(|r| a[r.clone()] == b[r.clone()])
    }

    /// Feeds a memory's key words to `hasher`.
    #[inline]
    pub fn hash_key(&self, memory: &[u64], hasher: &mut impl Hasher) {
        for r in &self.key {
            for &w in &memory[r.clone()] {
                hasher.write_u64(w);
            }
        }
    }

    /// The key words of `memory`, in order.
    pub fn key_of(&self, memory: &[u64]) -> Vec<u64> {
        self.key.iter().flat_map(|r| memory[r.clone()].iter().copied()).collect()
    }

    /// Zeroed rejection counters for this problem's filters.
    pub fn filter_counts(&self) -> FilterCounts {
        FilterCounts(vec![0; self.reasons.len()], 0)
    }

    /// The counts by filter and reason (reasons without rejections left out).
    pub fn report_filtered(&self, counts: &FilterCounts) -> Vec<FilterCount> {
        self.reasons
            .iter()
            .zip(&counts.0)
            .filter(|(_, &c)| c > 0)
            .map(|((f, reason), &count)| FilterCount { filter: self.filters[*f].name().to_string(), reason: reason.clone(), count })
            .collect()
    }

    /// Rewards for removing `part` from `state` (written to `rewards`, one per objective), then
    /// removes it and updates `memory` (every objective's words).
    #[inline]
    pub fn step(&self, state: &mut MapState<'_>, memory: &mut [u64], part: usize, kind: StepKind, rewards: &mut [f64]) {
        self.rewards(state, memory, part, kind, rewards);
        state.remove(part);
    }

    /// The rewards of removing `part` from `state` (written to `rewards`) and the memory after
    /// it (in `memory`), without removing the part from `state`.
    #[inline]
    pub fn rewards(&self, state: &mut MapState<'_>, memory: &mut [u64], part: usize, kind: StepKind, rewards: &mut [f64]) {
        let mut ctx = StepContext::new(self, state, part, kind);
        let mut rest = memory;
        for ((o, r), &w) in self.objectives.iter().zip(rewards.iter_mut()).zip(&self.widths) {
            let (mine, tail) = std::mem::take(&mut rest).split_at_mut(w);
            *r = o.reward(&mut ctx, mine);
            rest = tail;
        }
    }

    /// The feasible removals of `state` with `memory` (increasing part order): collision-free
    /// and supported on the maps, then admitted by every filter; rejections are counted in
    /// `counts`.
    #[inline]
    pub fn feasible_actions(
        &self,
        state: &mut MapState<'_>,
        memory: &[u64],
        kind: StepKind,
        out: &mut Vec<usize>,
        counts: &mut FilterCounts,
    ) {
        state.feasible_actions(out);
        if !self.filters.is_empty() {
            self.apply_filters(state, memory, kind, out, counts);
        }
    }

    fn apply_filters(&self, state: &mut MapState<'_>, memory: &[u64], kind: StepKind, out: &mut Vec<usize>, counts: &mut FilterCounts) {
        out.retain(|&part| self.admits(state, memory, part, kind, counts));
    }

    /// Whether every filter admits removing `part` from `state` (a removal the maps already
    /// found collision-free and supported: [`Mdp::candidate_actions`]); a rejection is counted
    /// in `counts`. Rollouts ask this lazily, one candidate at a time in the policy's order,
    /// instead of filtering every candidate of every state ([`Mdp::feasible_actions`]).
    pub fn admits(&self, state: &mut MapState<'_>, memory: &[u64], part: usize, kind: StepKind, counts: &mut FilterCounts) -> bool {
        counts.1 += 1;
        let mut ctx = StepContext::new(self, state, part, kind);
        for (f, filter) in self.filters.iter().enumerate() {
            if let Verdict::Infeasible { reason } = filter.check(&mut ctx, memory) {
                let base = self.reason_base[f];
                let slots = self.reason_base.get(f + 1).copied().unwrap_or(self.reasons.len()) - base;
                counts.0[base + reason.min(slots - 1)] += 1;
                return false;
            }
        }
        true
    }

    /// The removals of `state` that are collision-free and supported on the maps, before the
    /// filters (increasing part order); [`Mdp::admits`] tells which the filters keep.
    #[inline]
    pub fn candidate_actions(&self, state: &mut MapState<'_>, out: &mut Vec<usize>) {
        state.feasible_actions(out);
    }

    /// Why `part` cannot leave `state` (with `memory`), or `None` when it can.
    pub fn why_infeasible(&self, state: &mut MapState<'_>, memory: &[u64], part: usize, kind: StepKind) -> Option<String> {
        let maps = state.maps();
        if part >= maps.num_parts() || !state.contains(part) {
            return Some("is not present".into());
        }
        if !state.can_remove(part) {
            return Some(
                if maps.is_fixed(part) {
                    "is fixed"
                } else if !state.is_collision_free(part) {
                    "is blocked in every direction"
                } else {
                    "would leave a part without support"
                }
                .into(),
            );
        }
        let mut ctx = StepContext::new(self, state, part, kind);
        for filter in &self.filters {
            if let Verdict::Infeasible { reason } = filter.check(&mut ctx, memory) {
                let why = filter.reasons().get(reason).cloned().unwrap_or_else(|| "infeasible".into());
                return Some(format!("is rejected by {}: {why}", filter.name()));
            }
        }
        None
    }

    /// Replays a disassembly sequence from the assembled state ([`StepKind::Replay`]), checking
    /// every step's feasibility, and returns its objective vector and each removal's motion. The
    /// sequence must remove every non-fixed part.
    pub fn evaluate(&self, sequence: &[usize]) -> Result<(Vec<f64>, Vec<Motion>)> {
        let (totals, motions, state) = self.replay_state(sequence)?;
        if !state.is_complete() {
            let maps = &*self.maps;
            let left: Vec<usize> = state.present().iter().filter(|&i| !maps.is_fixed(i)).collect();
            return Err(SearchError::Infeasible { reason: format!("the sequence leaves parts {left:?} in place") });
        }
        Ok((totals, motions))
    }

    /// [`Mdp::evaluate`] for the first removals of a sequence: each step checked and its motion
    /// returned, without asking that every part be removed.
    pub fn replay(&self, sequence: &[usize]) -> Result<(Vec<f64>, Vec<Motion>)> {
        self.replay_state(sequence).map(|(totals, motions, _)| (totals, motions))
    }

    fn replay_state(&self, sequence: &[usize]) -> Result<(Vec<f64>, Vec<Motion>, MapState<'_>)> {
        let maps = &*self.maps;
        let m = self.objectives.len();
        let mut state = MapState::new(maps);
        let mut memory = self.initial_memory();
        let mut rewards = vec![0.0; m];
        let mut totals = vec![0.0; m];
        let mut motions = Vec::with_capacity(sequence.len());
        for (t, &p) in sequence.iter().enumerate() {
            if let Some(why) = self.why_infeasible(&mut state, &memory, p, StepKind::Replay) {
                return Err(SearchError::Infeasible { reason: format!("step {t}: part {p} {why}") });
            }
            let (d, travel) = state.clearance(p).expect("feasible parts have a free direction");
            motions.push(Motion::Linear { direction: maps.hemisphere().directions()[d], distance: travel });
            self.step(&mut state, &mut memory, p, StepKind::Replay, &mut rewards);
            for (a, r) in totals.iter_mut().zip(&rewards) {
                *a += r;
            }
        }
        Ok((totals, motions, state))
    }

    /// The feasible removals of the state `present` with `memory` (for the assembled state:
    /// [`Mdp::initial_memory`]), in increasing part order.
    pub fn feasible_in(&self, present: &PartSet, memory: &[u64]) -> Vec<usize> {
        let mut s = MapState::new(&self.maps);
        s.reset(present);
        let mut out = Vec::new();
        let mut counts = self.filter_counts();
        self.feasible_actions(&mut s, memory, StepKind::Replay, &mut out, &mut counts);
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::objective::{parse_objectives, Accessibility, DirHistory};
    use asp_geom::distmap::MapConfig;

    fn maps() -> Arc<DistanceMaps> {
        let config = MapConfig::builder().resolution(3).build().unwrap();
        Arc::new(DistanceMaps::build(&asp_geom::fixtures::figure_6_2(1.0), &config).unwrap())
    }

    /// Keeps 3 memory words of which the first is key: counts removals in word 0 (key),
    /// remembers the last part in word 1 and a constant in word 2.
    #[derive(Debug)]
    struct Counter;

    impl Objective for Counter {
        fn name(&self) -> &str {
            "counter"
        }
        fn memory_words(&self) -> usize {
            3
        }
        fn key_words(&self) -> usize {
            1
        }
        fn init_memory(&self, _maps: &DistanceMaps, memory: &mut [u64]) {
            memory[2] = 7;
        }
        fn reward(&self, step: &mut StepContext<'_, '_>, memory: &mut [u64]) -> f64 {
            memory[0] += 1;
            memory[1] = step.part() as u64;
            1.0
        }
        fn worst_total(&self, _maps: &DistanceMaps, _removals: usize) -> f64 {
            0.0
        }
    }

    #[test]
    fn memory_layout_and_keys() {
        let mut objectives = parse_objectives("dirchange").unwrap();
        objectives.push(Arc::new(Counter));
        objectives.push(Arc::new(Accessibility));
        let mdp = Mdp::new(maps(), objectives).unwrap();
        assert_eq!(mdp.memory_words(), DirHistory::WORDS + 3);
        assert_eq!(mdp.memory_range(1), 5..8);
        assert_eq!(mdp.memory_range(2), 8..8);
        // the dirchange words and the counter's first word are the key, merged into one range
        assert_eq!(mdp.key, vec![0..6]);
        let init = mdp.initial_memory();
        assert_eq!(init, vec![0, 0, 0, 0, 0, 0, 0, 7]);
        let mut other = init.clone();
        other[6] = 99; // not a key word
        assert!(mdp.key_eq(&init, &other));
        other[5] = 1;
        assert!(!mdp.key_eq(&init, &other));
        assert_eq!(mdp.key_of(&other), vec![0, 0, 0, 0, 0, 1]);
        // a step updates every objective's own words
        let mut state = MapState::new(mdp.maps());
        let mut memory = init;
        let mut rewards = [0.0; 3];
        let first = mdp.feasible_in(&state.present(), &memory)[0];
        mdp.step(&mut state, &mut memory, first, StepKind::Expansion, &mut rewards);
        assert_eq!(&memory[5..8], &[1, first as u64, 7]);
        assert!(DirHistory::load(&memory[..5]).active);
        assert_eq!(rewards[1], 1.0);
    }

    #[test]
    fn more_key_words_than_memory_is_an_error() {
        #[derive(Debug)]
        struct Bad;
        impl Objective for Bad {
            fn name(&self) -> &str {
                "bad"
            }
            fn key_words(&self) -> usize {
                1
            }
            fn reward(&self, _: &mut StepContext<'_, '_>, _: &mut [u64]) -> f64 {
                0.0
            }
            fn worst_total(&self, _: &DistanceMaps, _: usize) -> f64 {
                0.0
            }
        }
        let err = Mdp::new(maps(), vec![Arc::new(Bad)]).unwrap_err();
        assert!(err.to_string().contains("objective 'bad'"), "{err}");
    }

    /// Rejects one part, for a reason of its two.
    #[derive(Debug)]
    struct NotPart(usize);

    impl ActionFilter for NotPart {
        fn name(&self) -> &str {
            "not-part"
        }
        fn reasons(&self) -> Vec<String> {
            vec!["first reason".into(), "second reason".into()]
        }
        fn check(&self, step: &mut StepContext<'_, '_>, _memory: &[u64]) -> Verdict {
            if step.part() == self.0 {
                Verdict::Infeasible { reason: 1 }
            } else {
                Verdict::Feasible
            }
        }
    }

    #[test]
    fn filters_remove_actions_and_count_reasons() {
        let plain = Mdp::new(maps(), parse_objectives("access").unwrap()).unwrap();
        let full = PartSet::full(plain.maps().num_parts());
        let all = plain.feasible_in(&full, &[]);
        assert!(!all.is_empty());
        let banned = all[0];
        let mdp = plain.clone().with_filter(Arc::new(NotPart(banned)));
        let mut state = MapState::new(mdp.maps());
        let mut out = Vec::new();
        let mut counts = mdp.filter_counts();
        mdp.feasible_actions(&mut state, &[], StepKind::Simulation, &mut out, &mut counts);
        assert_eq!(out, all[1..].to_vec());
        let report = mdp.report_filtered(&counts);
        assert_eq!(report, vec![FilterCount { filter: "not-part".into(), reason: "second reason".into(), count: 1 }]);
        // a sequence through the banned part does not replay
        let why = mdp.why_infeasible(&mut state, &[], banned, StepKind::Replay).unwrap();
        assert!(why.contains("not-part: second reason"), "{why}");
    }
}
