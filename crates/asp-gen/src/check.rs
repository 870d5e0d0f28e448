//! The generators' own straight-line disassembly check: which parts can leave along a ±axis,
//! in which order, and whether that order keeps every intermediate state linked to the fixed
//! parts through contacts.
//!
//! Whether a part can leave along an axis only gets easier as other parts leave, so removing any
//! removable part never hurts: the greedy loop below decides straight-line disassemblability
//! exactly. Stability is not monotone; the greedy order that prefers stable states is a witness
//! when it succeeds, not a proof of impossibility when it fails.

use crate::cuboid::Cuboid;
use asp_geom::math::Axis;
use asp_geom::PartSet;
use serde::{Deserialize, Serialize};

/// The six removal directions, upward first (the natural way to lift a part off).
pub const DIRECTIONS: [Axis; 6] = [
    Axis { index: 2, negative: false },
    Axis { index: 0, negative: false },
    Axis { index: 0, negative: true },
    Axis { index: 1, negative: false },
    Axis { index: 1, negative: true },
    Axis { index: 2, negative: true },
];

/// What the straight-line disassembly check found for one assembly.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct DisassemblyCheck {
    /// The assembled state is contact-linked to the fixed parts (nothing floats).
    pub linked: bool,
    /// Every non-fixed part can be removed along a ±axis, one after the other (exact).
    pub straight_line: bool,
    /// Non-fixed parts left when no remaining part could leave (empty when `straight_line`).
    pub stuck: Vec<usize>,
    /// The greedy order found keeps each state contact-linked to the fixed parts.
    pub stable_order: bool,
    /// The removal order found: part index and the axis it leaves along.
    pub order: Vec<(usize, Axis)>,
}

/// The geometry the check needs from a generator.
pub trait RemovalModel {
    /// Number of parts.
    fn num_parts(&self) -> usize;
    /// Whether part `i` stays in place.
    fn is_fixed(&self, i: usize) -> bool;
    /// Whether part `i` can leave `state` along `axis` without pushing into any present part.
    fn can_leave(&self, i: usize, axis: Axis, state: &PartSet) -> bool;
    /// The parts that touch part `i` (shared face area), in any order.
    fn contacts(&self, i: usize) -> &[usize];
    /// The height of part `i`'s lowest point; parts lying higher are tried first (top-down).
    fn bottom(&self, i: usize) -> f64;
}

/// Whether every part of `state` is linked to a present fixed part through contacts.
pub fn is_contact_linked(model: &impl RemovalModel, state: &PartSet) -> bool {
    let mut reached = PartSet::empty(model.num_parts());
    let mut stack: Vec<usize> = state.iter().filter(|&i| model.is_fixed(i)).collect();
    for &i in &stack {
        reached.insert(i);
    }
    while let Some(i) = stack.pop() {
        for &j in model.contacts(i) {
            if state.contains(j) && !reached.contains(j) {
                reached.insert(j);
                stack.push(j);
            }
        }
    }
    reached.len() == state.len()
}

/// Removes parts greedily along ±axes, top-down, preferring stable remaining states.
pub fn check_disassembly(model: &impl RemovalModel) -> DisassemblyCheck {
    let n = model.num_parts();
    let mut order_by_height: Vec<usize> = (0..n).filter(|&i| !model.is_fixed(i)).collect();
    order_by_height.sort_by(|&a, &b| model.bottom(b).total_cmp(&model.bottom(a)).then(a.cmp(&b)));
    let mut state = PartSet::full(n);
    let mut order = Vec::new();
    let mut stable_order = true;
    loop {
        let mut fallback = None;
        let mut pick = None;
        for &i in order_by_height.iter().filter(|&&i| state.contains(i)) {
            let Some(&axis) = DIRECTIONS.iter().find(|&&a| model.can_leave(i, a, &state)) else {
                continue;
            };
            if is_contact_linked(model, &state.without(i)) {
                pick = Some((i, axis));
                break;
            }
            fallback.get_or_insert((i, axis));
        }
        let Some((i, axis)) = pick.or(fallback) else { break };
        stable_order &= pick.is_some();
        state.remove(i);
        order.push((i, axis));
    }
    let stuck: Vec<usize> = state.iter().filter(|&i| !model.is_fixed(i)).collect();
    DisassemblyCheck {
        linked: is_contact_linked(model, &PartSet::full(n)),
        straight_line: stuck.is_empty(), stable_order: stable_order && stuck.is_empty(), stuck, order }
}

/// Parts made of axis-aligned boxes: a part leaves along an axis when sweeping its boxes to
/// infinity pushes none of them deeper than `tol` into a box of another present part.
pub struct BoxModel {
    parts: Vec<Vec<Cuboid>>,
    fixed: Vec<bool>,
    contacts: Vec<Vec<usize>>,
    tol: f64,
}

impl BoxModel {
    /// The model of `parts` (boxes per part) with their fixed flags; boxes of two parts that
    /// share a face patch (within `tol`) are in contact.
    pub fn new(parts: Vec<Vec<Cuboid>>, fixed: Vec<bool>, tol: f64) -> Self {
        let mut contacts = vec![Vec::new(); parts.len()];
        for i in 0..parts.len() {
            for j in i + 1..parts.len() {
                if parts[i].iter().any(|a| parts[j].iter().any(|b| a.touches(b, tol))) {
                    contacts[i].push(j);
                    contacts[j].push(i);
                }
            }
        }
        BoxModel { parts, fixed, contacts, tol }
    }
}

impl RemovalModel for BoxModel {
    fn num_parts(&self) -> usize {
        self.parts.len()
    }

    fn is_fixed(&self, i: usize) -> bool {
        self.fixed[i]
    }

    fn can_leave(&self, i: usize, axis: Axis, state: &PartSet) -> bool {
        !state.iter().filter(|&j| j != i).any(|j| {
            self.parts[i].iter().any(|a| {
                self.parts[j].iter().any(|b| a.sweep_hits(b, axis.index as usize, axis.negative, self.tol))
            })
        })
    }

    fn contacts(&self, i: usize) -> &[usize] {
        &self.contacts[i]
    }

    fn bottom(&self, i: usize) -> f64 {
        self.parts[i].iter().map(|b| b.mins[2]).fold(f64::INFINITY, f64::min)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn unit(x: f64, y: f64, z: f64) -> Cuboid {
        Cuboid::new([x, y, z], [x + 1.0, y + 1.0, z + 1.0])
    }

    #[test]
    fn a_stack_comes_apart_top_down() {
        // floor (fixed), a block on it, a block on that
        let parts = vec![vec![Cuboid::new([-1.0, -1.0, -1.0], [2.0, 2.0, 0.0])], vec![unit(0.0, 0.0, 0.0)], vec![unit(0.0, 0.0, 1.0)]];
        let check = check_disassembly(&BoxModel::new(parts, vec![true, false, false], 1e-9));
        assert!(check.linked && check.straight_line && check.stable_order);
        assert_eq!(check.order, vec![(2, Axis::Z), (1, Axis::Z)]);
    }

    #[test]
    fn a_floating_part_is_not_linked() {
        let parts = vec![vec![unit(0.0, 0.0, 0.0)], vec![unit(0.0, 0.0, 3.0)]];
        let check = check_disassembly(&BoxModel::new(parts, vec![true, false], 1e-9));
        assert!(!check.linked && check.straight_line);
    }

    #[test]
    fn a_caged_part_is_stuck() {
        // part 1 sits in a closed box of six fixed walls
        let wall = |mins: [f64; 3], maxs: [f64; 3]| vec![Cuboid::new(mins, maxs)];
        let parts = vec![
            wall([-1.0, -1.0, -1.0], [2.0, 2.0, 0.0]),
            vec![unit(0.0, 0.0, 0.0)],
            wall([-1.0, -1.0, 1.0], [2.0, 2.0, 2.0]),
            wall([-1.0, -1.0, 0.0], [0.0, 2.0, 1.0]),
            wall([1.0, -1.0, 0.0], [2.0, 2.0, 1.0]),
            wall([0.0, -1.0, 0.0], [1.0, 0.0, 1.0]),
            wall([0.0, 1.0, 0.0], [1.0, 2.0, 1.0]),
        ];
        let fixed = vec![true, false, true, true, true, true, true];
        let check = check_disassembly(&BoxModel::new(parts, fixed, 1e-9));
        assert!(!check.straight_line && !check.stable_order);
        assert_eq!(check.stuck, vec![1]);
    }
}
