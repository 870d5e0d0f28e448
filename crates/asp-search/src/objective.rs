//! Objectives: the reward of removing a part from a disassembly state given the history
//! (thesis 5.4.1 and 6.4.1). Every objective is maximised; costs are negative rewards.
//!
//! * [`Accessibility`] (eq. 6.6 / 6.15): the sum of the entries of the minimum distance map
//!   `M̄(p_a, s)` of the removed part — clearance around it while it is assembled.
//! * [`DirectionChanges`] (eq. 6.9–6.13 / 6.16): `Ĥ`, the number of removal directions the part
//!   shares with the parts removed since the last direction change, 0 on a change. It depends on
//!   the history through `H`, kept in the objective's [`Memory`].
//! * [`PathLength`]: minus the straight-line distance the part travels along its best free
//!   direction until its bounds clear the remaining parts' bounds — a robot-free stand-in for
//!   the removal path length of 5.2 (eq. 5.8).
//!
//! New objectives implement [`Objective`] and are added to [`objective_by_name`].

use crate::error::{Result, SearchError};
use asp_geom::distmap::{DirMask, DistanceMaps, MapState};
use asp_geom::PartSet;
use std::fmt::Debug;
use std::sync::Arc;

/// What an objective remembers along a sequence; copied with every state of the search.
/// [`DirectionChanges`] keeps `H` in `mask` and whether it has started in `active`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct Memory {
    /// A set of directions (e.g. the common removal directions `H`).
    pub mask: DirMask,
    /// Whether the memory holds anything yet (false before the first removal).
    pub active: bool,
}

/// One objective of the MDP: the reward of removing `part` from `state`.
pub trait Objective: Send + Sync + Debug {
    /// The objective's name as the CLI spells it (e.g. `access`).
    fn name(&self) -> &str;

    /// The reward of removing present `part` from `state` (before the removal), updating the
    /// objective's `memory`. `state` is mutable only so minimum maps can be computed lazily.
    fn reward(&self, part: usize, state: &mut MapState<'_>, memory: &mut Memory) -> f64;

    /// A value no sequence of `removals` removals can fall below: the hypervolume reference
    /// coordinate of this objective.
    fn worst_total(&self, maps: &DistanceMaps, removals: usize) -> f64;
}

/// Accessibility (eq. 6.15): `Σ_{k,l} M̄_{k,l}(p_a, s)`, in metres.
#[derive(Clone, Copy, Debug, Default)]
pub struct Accessibility;

impl Objective for Accessibility {
    fn name(&self) -> &str {
        "access"
    }

    fn reward(&self, part: usize, state: &mut MapState<'_>, _memory: &mut Memory) -> f64 {
        state.min_map_sum(part)
    }

    fn worst_total(&self, _maps: &DistanceMaps, _removals: usize) -> f64 {
        0.0
    }
}

/// Direction changes (eq. 6.16): `Ĥ(a_n, s_n, u_{f,n})`, a count of directions.
#[derive(Clone, Copy, Debug, Default)]
pub struct DirectionChanges;

impl DirectionChanges {
    /// The update of eq. 6.9–6.12: the new `H` and the reward `Ĥ` given the part's free
    /// directions `free` and the previous memory.
    pub fn update(free: DirMask, memory: &mut Memory) -> f64 {
        if !memory.active {
            memory.active = true;
            memory.mask = free;
            return free.len() as f64;
        }
        let common = free.and(memory.mask);
        if common.is_empty() {
            // A change of direction: restart H with the part's own directions (eq. 6.10, 6.12).
            memory.mask = free;
            0.0
        } else {
            memory.mask = common;
            common.len() as f64
        }
    }
}

impl Objective for DirectionChanges {
    fn name(&self) -> &str {
        "dirchange"
    }

    fn reward(&self, part: usize, state: &mut MapState<'_>, memory: &mut Memory) -> f64 {
        DirectionChanges::update(state.free_mask(part), memory)
    }

    fn worst_total(&self, _maps: &DistanceMaps, _removals: usize) -> f64 {
        0.0
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

    fn reward(&self, part: usize, state: &mut MapState<'_>, _memory: &mut Memory) -> f64 {
        state.clearance(part).map_or(0.0, |(_, t)| -(t as f64))
    }

    fn worst_total(&self, maps: &DistanceMaps, removals: usize) -> f64 {
        // A box inside the assembly's box clears it within √3 × its diagonal along any sample.
        -(removals as f64) * 3f64.sqrt() * maps.diagonal() as f64
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

/// Parses a comma-separated list of objective names (e.g. `access,dirchange`); repeats are an
/// error.
pub fn parse_objectives(list: &str) -> Result<Vec<Arc<dyn Objective>>> {
    let mut out: Vec<Arc<dyn Objective>> = Vec::new();
    for name in list.split(',').filter(|s| !s.trim().is_empty()) {
        let o = objective_by_name(name)?;
        if out.iter().any(|p| p.name() == o.name()) {
            return Err(SearchError::config(format!("objective '{}' is given twice", o.name())));
        }
        out.push(o);
    }
    if out.is_empty() {
        return Err(SearchError::config("no objective given"));
    }
    Ok(out)
}

/// The number of direction changes along a disassembly sequence (the restarts of `H` in
/// eq. 6.10), for reporting. Parts that cannot leave count as a change.
pub fn direction_changes(maps: &DistanceMaps, sequence: &[usize]) -> usize {
    let mut state = PartSet::full(maps.num_parts());
    let mut memory = Memory::default();
    let mut changes = 0;
    for &p in sequence {
        let free = maps.free_mask(p, &state);
        let was_active = memory.active;
        if DirectionChanges::update(free, &mut memory) == 0.0 && was_active {
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
        let mut mem = Memory::default();
        assert_eq!(DirectionChanges::update(mask(&[0, 1, 2]), &mut mem), 3.0);
        assert_eq!(DirectionChanges::update(mask(&[1, 2, 5]), &mut mem), 2.0);
        assert_eq!(mem.mask, mask(&[1, 2]));
        // no overlap: a direction change, H restarts from the part's own directions
        assert_eq!(DirectionChanges::update(mask(&[7, 8]), &mut mem), 0.0);
        assert_eq!(mem.mask, mask(&[7, 8]));
        assert_eq!(DirectionChanges::update(mask(&[8]), &mut mem), 1.0);
    }

    #[test]
    fn names() {
        assert_eq!(parse_objectives("access, dirchange").unwrap().len(), 2);
        assert!(matches!(parse_objectives("speed"), Err(SearchError::UnknownObjective { .. })));
        assert!(parse_objectives("access,access").is_err());
        assert!(parse_objectives("").is_err());
    }
}
