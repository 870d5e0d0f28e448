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
//! A reward may depend on the state, the part, the objective's memory and the [`StepKind`](crate::StepKind)
//! only — anything else it needs from the history belongs in its memory. [`StepContext`] hands it
//! the state, the removal's straight-line motion, the assembly and its part metadata, and a seed
//! that depends only on the problem's seed, the state and the part.
//!
//! New objectives implement [`Objective`]; the built-in ones are named by [`objective_by_name`],
//! others come from an [`crate::extension::MdpExtension`].

use crate::error::{Result, SearchError};
use crate::step::StepContext;
use asp_geom::distmap::{DirMask, DistanceMaps};
use asp_geom::PartSet;
use std::fmt::Debug;
use std::sync::Arc;

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
        _ => Err(SearchError::UnknownObjective { name: name.to_string(), known: OBJECTIVE_NAMES.join(", ") }),
    }
}

/// Parses a comma-separated list of built-in objective names (e.g. `access,dirchange`);
/// repeats are an error.
pub fn parse_objectives(list: &str) -> Result<Vec<Arc<dyn Objective>>> {
    let names: Vec<&str> = list.split(',').collect();
    collect_objectives(&names, |name| objective_by_name(name).map(Some), &[])
}

/// The names of `names`, trimmed, blanks left out; none is an error.
pub(crate) fn collect_names<S: AsRef<str>>(names: &[S]) -> Result<Vec<&str>> {
    let names: Vec<&str> = names.iter().map(|s| s.as_ref().trim()).filter(|s| !s.is_empty()).collect();
    if names.is_empty() {
        return Err(SearchError::config("no objective given"));
    }
    Ok(names)
}

pub(crate) fn unknown(name: &str, provided: &[String]) -> SearchError {
    let mut known: Vec<String> = OBJECTIVE_NAMES.iter().map(|s| s.to_string()).collect();
    known.extend(provided.iter().cloned());
    SearchError::UnknownObjective { name: name.to_string(), known: known.join(", ") }
}

pub(crate) fn collect_objectives<S: AsRef<str>>(
    names: &[S],
    mut by_name: impl FnMut(&str) -> Result<Option<Arc<dyn Objective>>>,
    provided: &[String],
) -> Result<Vec<Arc<dyn Objective>>> {
    let mut out: Vec<Arc<dyn Objective>> = Vec::new();
    for name in collect_names(names)? {
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
