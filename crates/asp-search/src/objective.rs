//! Objectives: the reward of removing a part from a disassembly state given the history
//! (thesis 5.4.1 and 6.4.1). Every objective is maximised; costs are negative rewards.
//!
//! * [`Accessibility`] (eq. 6.6 / 6.15): the sum of the entries of the minimum distance map
//!   `M̄(p_a, s)` of the removed part — clearance around it while it is assembled.
//! * [`DirectionChanges`] (eq. 6.9–6.13 / 6.16): `Ĥ`, the number of removal directions the part
//!   shares with the parts removed since the last direction change, 0 on a change. It depends on
//!   the history through `H`, which it keeps in its memory ([`DirHistory`]).
//! * [`PathLength`]: minus the straight-line distance the part travels along its best free
//!   direction until its bounds clear the remaining parts' bounds — a robot-free stand-in for
//!   the removal path length of 5.2 (eq. 5.8).
//!
//! # Memory
//! An objective whose reward depends on the history keeps what it needs in its own **memory**:
//! [`Objective::memory_words`] `u64` words per search state, set by
//! [`Objective::init_memory`] at the assembled state and updated by [`Objective::reward`] at
//! every removal. The search copies the words with its states; the first
//! [`Objective::key_words`] of them (all, by default) are part of the state's identity, so two
//! removal orders that reach the same parts with the same key words share one node of the search
//! graph (and one entry of the exact dynamic programme). Words after the key are carried along
//! but do not tell states apart: a state reached again keeps the memory of the path that reached
//! it first (a cache, or a continuous configuration that a quantised key word stands for).
//!
//! A reward may depend on the state, the part, the objective's memory and the [`StepKind`]
//! only — anything else it needs from the history belongs in its memory. [`StepContext`] hands it
//! the state, the removal's straight-line motion, the assembly and its part metadata, and a seed
//! that depends only on the problem's seed, the state and the part.
//!
//! New objectives implement [`Objective`]; the built-in ones are named by [`objective_by_name`],
//! others come from an [`crate::mdp::MdpExtension`].

use crate::error::{Result, SearchError};
use crate::mdp::{Mdp, MdpExtension, ModelContext};
use asp_geom::distmap::{DirMask, DistanceMaps, MapState};
use asp_geom::{Assembly, Motion, PartMeta, PartSet};
use std::fmt::Debug;
use std::sync::Arc;

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
/// leaves (before the removal), the problem, and the step's kind.
pub struct StepContext<'s, 'm> {
    problem: &'s Mdp,
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
    /// The removal of present `part` from `state` in `problem`.
    pub fn new(problem: &'s Mdp, state: &'s mut MapState<'m>, part: usize, kind: StepKind) -> Self {
        StepContext { problem, state, part, kind, clearance: None }
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

    /// The problem (objectives, filters, the assembly when the caller gave it).
    #[inline]
    pub fn problem(&self) -> &'s Mdp {
        self.problem
    }

    /// The assembly the maps were built from, when the problem carries it
    /// ([`Mdp::with_assembly`]; the planning pipeline always sets it). Metres, world frame.
    pub fn assembly(&self) -> Option<&'s Assembly> {
        self.problem.assembly()
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
    /// ([`Mdp::with_seed`]), the present parts and the moving part: the same step gives the same
    /// seed in every thread, episode and replay.
    pub fn seed(&self) -> u64 {
        let mut h = splitmix(self.problem.seed() ^ 0x6a09_e667_f3bc_c909);
        for w in self.state.present().words() {
            h = splitmix(h ^ w);
        }
        splitmix(h ^ self.part as u64)
    }
}

/// SplitMix64's finaliser: a cheap, well-mixed hash of one word.
fn splitmix(x: u64) -> u64 {
    let mut z = x.wrapping_add(0x9e37_79b9_7f4a_7c15);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// One objective of the MDP: the reward of a removal, with the objective's own memory.
pub trait Objective: Send + Sync + Debug {
    /// The objective's name as the CLI spells it (e.g. `access`).
    fn name(&self) -> &str;

    /// Words of memory this objective keeps per search state (default 0: the reward depends on
    /// the state alone).
    fn memory_words(&self) -> usize {
        0
    }

    /// How many of the first memory words are part of a state's identity for transpositions
    /// and the exact programme (default: all of them; at most [`Objective::memory_words`]).
    fn key_words(&self) -> usize {
        self.memory_words()
    }

    /// The memory at the assembled state (`memory` is zeroed before the call; the default
    /// leaves it so).
    fn init_memory(&self, _maps: &DistanceMaps, _memory: &mut [u64]) {}

    /// The reward of removing `step.part()` from `step`'s state (before the removal), updating
    /// this objective's `memory` for the state after it.
    fn reward(&self, step: &mut StepContext<'_, '_>, memory: &mut [u64]) -> f64;

    /// A value no sequence of `removals` removals can fall below: the hypervolume reference
    /// coordinate of this objective.
    fn worst_total(&self, maps: &DistanceMaps, removals: usize) -> f64;

    /// Bounds `(lo, hi)` of one removal's reward on these maps, when known (default `None`).
    /// Learned Q-functions train on rewards mapped to `[0, 1]` by them, so that values are
    /// comparable across assemblies and positive for products.
    fn reward_range(&self, _maps: &DistanceMaps) -> Option<(f64, f64)> {
        None
    }
}

/// Accessibility (eq. 6.15): `Σ_{k,l} M̄_{k,l}(p_a, s)`, in metres.
#[derive(Clone, Copy, Debug, Default)]
pub struct Accessibility;

impl Objective for Accessibility {
    fn name(&self) -> &str {
        "access"
    }

    #[inline]
    fn reward(&self, step: &mut StepContext<'_, '_>, _memory: &mut [u64]) -> f64 {
        let part = step.part();
        step.state().min_map_sum(part)
    }

    fn worst_total(&self, _maps: &DistanceMaps, _removals: usize) -> f64 {
        0.0
    }

    fn reward_range(&self, maps: &DistanceMaps) -> Option<(f64, f64)> {
        // every direction's entry is at most d_max
        Some((0.0, maps.num_directions() as f64 * maps.d_max() as f64))
    }
}

/// The direction-change objective's memory: `H`, the removal directions shared by the parts
/// removed since the last direction change (eq. 6.9), and whether the first removal has
/// happened. Kept in [`DirHistory::WORDS`] memory words, all of them part of the state's key.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct DirHistory {
    /// `H`.
    pub mask: DirMask,
    /// Whether `H` holds anything yet (false before the first removal).
    pub active: bool,
}

impl DirHistory {
    /// Memory words: the mask's four, then the flag.
    pub const WORDS: usize = 5;

    /// Reads the history from its memory words.
    #[inline]
    pub fn load(words: &[u64]) -> Self {
        DirHistory { mask: DirMask::from_words([words[0], words[1], words[2], words[3]]), active: words[4] != 0 }
    }

    /// Writes the history to its memory words.
    #[inline]
    pub fn store(&self, words: &mut [u64]) {
        words[..4].copy_from_slice(&self.mask.words());
        words[4] = u64::from(self.active);
    }
}

/// Direction changes (eq. 6.16): `Ĥ(a_n, s_n, u_{f,n})`, a count of directions.
#[derive(Clone, Copy, Debug, Default)]
pub struct DirectionChanges;

impl DirectionChanges {
    /// The update of eq. 6.9–6.12: the new `H` and the reward `Ĥ` given the part's free
    /// directions `free` and the previous history.
    pub fn update(free: DirMask, history: &mut DirHistory) -> f64 {
        if !history.active {
            history.active = true;
            history.mask = free;
            return free.len() as f64;
        }
        let common = free.and(history.mask);
        if common.is_empty() {
            // A change of direction: restart H with the part's own directions (eq. 6.10, 6.12).
            history.mask = free;
            0.0
        } else {
            history.mask = common;
            common.len() as f64
        }
    }
}

impl Objective for DirectionChanges {
    fn name(&self) -> &str {
        "dirchange"
    }

    fn memory_words(&self) -> usize {
        DirHistory::WORDS
    }

    #[inline]
    fn reward(&self, step: &mut StepContext<'_, '_>, memory: &mut [u64]) -> f64 {
        let part = step.part();
        let free = step.state().free_mask(part);
        let words: &mut [u64; DirHistory::WORDS] = memory.first_chunk_mut().expect("the history's memory words");
        let mut history = DirHistory { mask: DirMask::from_words([words[0], words[1], words[2], words[3]]), active: words[4] != 0 };
        let r = DirectionChanges::update(free, &mut history);
        let [a, b, c, d] = history.mask.words();
        *words = [a, b, c, d, u64::from(history.active)];
        r
    }

    fn worst_total(&self, _maps: &DistanceMaps, _removals: usize) -> f64 {
        0.0
    }

    fn reward_range(&self, maps: &DistanceMaps) -> Option<(f64, f64)> {
        Some((0.0, maps.num_directions() as f64))
    }
}

/// Removal path length with straight lines: minus the travel until the part's bounds clear the
/// bounds of the remaining parts, along the free direction where that is shortest (metres).
#[derive(Clone, Copy, Debug, Default)]
pub struct PathLength;

impl Objective for PathLength {
    fn name(&self) -> &str {
        "pathlen"
    }

    #[inline]
    fn reward(&self, step: &mut StepContext<'_, '_>, _memory: &mut [u64]) -> f64 {
        step.clearance().map_or(0.0, |(_, t)| -(t as f64))
    }

    fn worst_total(&self, maps: &DistanceMaps, removals: usize) -> f64 {
        // A box inside the assembly's box clears it within √3 × its diagonal along any sample.
        -(removals as f64) * 3f64.sqrt() * maps.diagonal() as f64
    }

    fn reward_range(&self, maps: &DistanceMaps) -> Option<(f64, f64)> {
        Some((-(3f64.sqrt()) * maps.diagonal() as f64, 0.0))
    }
}

/// The names [`objective_by_name`] knows.
pub const OBJECTIVE_NAMES: [&str; 3] = ["access", "dirchange", "pathlen"];

/// The objective called `name` (`access`, `dirchange`, `pathlen`; a few aliases are accepted).
pub fn objective_by_name(name: &str) -> Result<Arc<dyn Objective>> {
    match name.trim().to_ascii_lowercase().as_str() {
        "access" | "accessibility" => Ok(Arc::new(Accessibility)),
        "dirchange" | "direction" | "directions" | "dirchanges" => Ok(Arc::new(DirectionChanges)),
        "pathlen" | "path" | "pathlength" | "length" => Ok(Arc::new(PathLength)),
        _ => Err(SearchError::UnknownObjective {
            name: name.to_string(),
            known: OBJECTIVE_NAMES.join(", "),
        }),
    }
}

/// Parses a comma-separated list of built-in objective names (e.g. `access,dirchange`);
/// repeats are an error.
pub fn parse_objectives(list: &str) -> Result<Vec<Arc<dyn Objective>>> {
    collect_objectives(list, |name| objective_by_name(name).map(Some), &[])
}

/// Checks a comma-separated list of objective names against the built-in ones and those the
/// `extensions` provide (before a model is loaded: for early, clear errors).
pub fn check_objective_names(list: &str, extensions: &[Arc<dyn MdpExtension>]) -> Result<()> {
    let provided: Vec<String> = extensions.iter().flat_map(|e| e.objective_names()).collect();
    let names = collect_names(list)?;
    for name in &names {
        if objective_by_name(name).is_err() && !provided.iter().any(|p| p == name.trim()) {
            return Err(unknown(name, &provided));
        }
    }
    Ok(())
}

/// The objectives of a comma-separated list on one model: the built-in ones by name, the
/// others from the first extension that provides them.
pub fn resolve_objectives(
    list: &str,
    extensions: &[Arc<dyn MdpExtension>],
    model: &ModelContext<'_>,
) -> Result<Vec<Arc<dyn Objective>>> {
    let provided: Vec<String> = extensions.iter().flat_map(|e| e.objective_names()).collect();
    collect_objectives(
        list,
        |name| {
            if let Ok(o) = objective_by_name(name) {
                return Ok(Some(o));
            }
            for e in extensions {
                if let Some(o) = e.objective(name.trim(), model)? {
                    return Ok(Some(o));
                }
            }
            Ok(None)
        },
        &provided,
    )
}

fn collect_names(list: &str) -> Result<Vec<&str>> {
    let names: Vec<&str> = list.split(',').filter(|s| !s.trim().is_empty()).collect();
    if names.is_empty() {
        return Err(SearchError::config("no objective given"));
    }
    Ok(names)
}

fn unknown(name: &str, provided: &[String]) -> SearchError {
    let mut known: Vec<String> = OBJECTIVE_NAMES.iter().map(|s| s.to_string()).collect();
    known.extend(provided.iter().cloned());
    SearchError::UnknownObjective { name: name.to_string(), known: known.join(", ") }
}

fn collect_objectives(
    list: &str,
    mut by_name: impl FnMut(&str) -> Result<Option<Arc<dyn Objective>>>,
    provided: &[String],
) -> Result<Vec<Arc<dyn Objective>>> {
    let mut out: Vec<Arc<dyn Objective>> = Vec::new();
    for name in collect_names(list)? {
        let o = match by_name(name) {
            Ok(Some(o)) => o,
            Ok(None) | Err(SearchError::UnknownObjective { .. }) => return Err(unknown(name, provided)),
            Err(e) => return Err(e),
        };
        if out.iter().any(|p| p.name() == o.name()) {
            return Err(SearchError::config(format!("objective '{}' is given twice", o.name())));
        }
        out.push(o);
    }
    Ok(out)
}

/// The number of direction changes along a disassembly sequence (the restarts of `H` in
/// eq. 6.10), for reporting. Parts that cannot leave count as a change.
pub fn direction_changes(maps: &DistanceMaps, sequence: &[usize]) -> usize {
    let mut state = PartSet::full(maps.num_parts());
    let mut history = DirHistory::default();
    let mut changes = 0;
    for &p in sequence {
        let free = maps.free_mask(p, &state);
        let was_active = history.active;
        if DirectionChanges::update(free, &mut history) == 0.0 && was_active {
            changes += 1;
        }
        state.remove(p);
    }
    changes
}

#[cfg(test)]
mod tests {
    use super::*;

    fn mask(bits: &[usize]) -> DirMask {
        let mut m = DirMask::EMPTY;
        for &b in bits {
            m.insert(b);
        }
        m
    }

    #[test]
    fn h_intersects_and_resets() {
        let mut mem = DirHistory::default();
        assert_eq!(DirectionChanges::update(mask(&[0, 1, 2]), &mut mem), 3.0);
        assert_eq!(DirectionChanges::update(mask(&[1, 2, 5]), &mut mem), 2.0);
        assert_eq!(mem.mask, mask(&[1, 2]));
        // no overlap: a direction change, H restarts from the part's own directions
        assert_eq!(DirectionChanges::update(mask(&[7, 8]), &mut mem), 0.0);
        assert_eq!(mem.mask, mask(&[7, 8]));
        assert_eq!(DirectionChanges::update(mask(&[8]), &mut mem), 1.0);
        // the memory words round trip
        let mut words = [0u64; DirHistory::WORDS];
        mem.store(&mut words);
        assert_eq!(DirHistory::load(&words), mem);
        assert_eq!(DirHistory::load(&[0; DirHistory::WORDS]), DirHistory::default());
    }

    #[test]
    fn names() {
        assert_eq!(parse_objectives("access, dirchange").unwrap().len(), 2);
        assert!(matches!(parse_objectives("speed"), Err(SearchError::UnknownObjective { .. })));
        assert!(parse_objectives("access,access").is_err());
        assert!(parse_objectives("").is_err());
    }
}
