//! The generators' own straight-line disassembly check: which parts can leave along a ±axis,
//! in which order, and whether an order exists that keeps every intermediate state linked to
//! the fixed parts through contacts.
//!
//! Whether a part can leave along an axis only gets easier as other parts leave, so removing any
//! removable part never hurts: a greedy loop decides straight-line disassemblability exactly.
//! Stability is not monotone, so a stable order is searched depth-first (dead states
//! remembered) within a budget of expanded states, trying a few part orderings in turn.

use crate::cuboid::Cuboid;
use asp_geom::math::Axis;
use asp_geom::PartSet;
use serde::{Deserialize, Serialize};
use std::collections::HashSet;

/// The six removal directions, upward first (the natural way to lift a part off).
pub const DIRECTIONS: [Axis; 6] = [
    Axis { index: 2, negative: false },
    Axis { index: 0, negative: false },
    Axis { index: 0, negative: true },
    Axis { index: 1, negative: false },
    Axis { index: 1, negative: true },
    Axis { index: 2, negative: true },
];

/// States the stable-order search may expand per part ordering before it gives up.
pub const SEARCH_BUDGET: usize = 20_000;

/// What the straight-line disassembly check found for one assembly.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct DisassemblyCheck {
    /// The assembled state is contact-linked to the fixed parts (nothing floats).
    pub linked: bool,
    /// Every non-fixed part can be removed along a ±axis, one after the other (exact).
    pub straight_line: bool,
    /// Non-fixed parts left when no remaining part could leave (empty when `straight_line`).
    pub stuck: Vec<usize>,
    /// A removal order was found in which every state stays contact-linked to the fixed parts
    /// (false: none exists, or none was found within [`SEARCH_BUDGET`] states).
    pub stable_order: bool,
    /// The removal order found: part index and the axis it leaves along (the stable order when
    /// one was found, else the greedy straight-line order).
    pub order: Vec<(usize, Axis)>,
}

/// The geometry the check needs from a generator.
pub trait RemovalModel {
    /// Number of parts.
    fn num_parts(&self) -> usize;
    /// Whether part `i` stays in place.
    fn is_fixed(&self, i: usize) -> bool;
    /// Every part that part `i` would push into if it moved along `axis` to infinity.
    fn blockers(&self, i: usize, axis: Axis) -> Vec<usize>;
    /// The parts that touch part `i` (shared face area), in any order.
    fn contacts(&self, i: usize) -> &[usize];
    /// The height of part `i`'s lowest point; parts lying higher are tried first (top-down),
    /// and among parts at one height the later ones (generators add a part after the parts it
    /// rests on: reverse build order).
    fn bottom(&self, i: usize) -> f64;
}

/// Whether every part of `state` is linked to a present fixed part through contacts.
pub fn is_contact_linked(model: &impl RemovalModel, state: &PartSet) -> bool {
    let fixed = PartSet::from_indices(model.num_parts(), state.iter().filter(|&i| model.is_fixed(i)));
    fixed.reached_within(state, |i| model.contacts(i).iter().copied()).len() == state.len()
}

/// Runs the check: exact straight-line disassemblability, then a search for a stable order.
pub fn check_disassembly(model: &impl RemovalModel) -> DisassemblyCheck {
    let n = model.num_parts();
    let movable: Vec<usize> = (0..n).filter(|&i| !model.is_fixed(i)).collect();
    let top_down = |later_first: bool| {
        let mut r = movable.clone();
        r.sort_by(|&a, &b| {
            let by_index = if later_first { b.cmp(&a) } else { a.cmp(&b) };
            model.bottom(b).total_cmp(&model.bottom(a)).then(by_index)
        });
        r
    };
    // the part orders the stable search tries in turn: top-down in reverse build order (a part
    // is added after what it rests on), plain reverse build order, top-down in build order; on
    // 300 double-layer assemblies each alone missed 1 to 14 stable orders, together none
    let rankings = [top_down(true), movable.iter().rev().copied().collect(), top_down(false)];
    let blockers: Vec<Vec<PartSet>> =
        (0..n).map(|i| DIRECTIONS.iter().map(|&a| PartSet::from_indices(n, model.blockers(i, a))).collect()).collect();
    let free_axis = |i: usize, state: &PartSet| DIRECTIONS.iter().zip(&blockers[i]).find(|(_, b)| !b.intersects(state)).map(|(&a, _)| a);
    // straight lines only: take out whatever can leave, until nothing can
    let mut state = PartSet::full(n);
    let mut order = Vec::new();
    while let Some((i, axis)) = rankings[0].iter().filter(|&&i| state.contains(i)).find_map(|&i| Some((i, free_axis(i, &state)?))) {
        state.remove(i);
        order.push((i, axis));
    }
    let stuck: Vec<usize> = state.iter().filter(|&i| !model.is_fixed(i)).collect();
    let stable = stuck.is_empty().then(|| {
        rankings.iter().find_map(|ranked| {
            let dead = HashSet::new();
            let mut search = StableSearch { model, ranked, free_axis: &free_axis, dead, budget: SEARCH_BUDGET, order: Vec::new() };
            (search.run(&PartSet::full(n)) == Some(true)).then_some(search.order)
        })
    });
    let stable_order = matches!(stable, Some(Some(_)));
    if let Some(Some(stable)) = stable {
        order = stable;
    }
    DisassemblyCheck { linked: is_contact_linked(model, &PartSet::full(n)), straight_line: stuck.is_empty(), stuck, stable_order, order }
}

/// Depth-first search for a removal order whose states all stay contact-linked.
struct StableSearch<'a, M, F> {
    model: &'a M,
    ranked: &'a [usize],
    free_axis: &'a F,
    /// States from which no stable order exists.
    dead: HashSet<PartSet>,
    budget: usize,
    order: Vec<(usize, Axis)>,
}

impl<M: RemovalModel, F: Fn(usize, &PartSet) -> Option<Axis>> StableSearch<'_, M, F> {
    /// Some(true) when `state` can be emptied, Some(false) when it cannot, None out of budget.
    fn run(&mut self, state: &PartSet) -> Option<bool> {
        if self.ranked.iter().all(|&i| !state.contains(i)) {
            return Some(true);
        }
        if self.dead.contains(state) {
            return Some(false);
        }
        self.budget = self.budget.checked_sub(1)?;
        for &i in self.ranked.iter().filter(|&&i| state.contains(i)) {
            let Some(axis) = (self.free_axis)(i, state) else { continue };
            let next = state.without(i);
            if !is_contact_linked(self.model, &next) {
                continue;
            }
            self.order.push((i, axis));
            if self.run(&next)? {
                return Some(true);
            }
            self.order.pop();
        }
        self.dead.insert(state.clone());
        Some(false)
    }
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
        Self::with_contacts(parts, fixed, tol, false)
    }

    /// As [`BoxModel::new`], and when `overlaps` also boxes of two parts that overlap deeper
    /// than `tol` are in contact (parts fitted or drawn into each other: a press fit, a thread,
    /// a dowel drawn into a solid panel).
    pub fn with_contacts(parts: Vec<Vec<Cuboid>>, fixed: Vec<bool>, tol: f64, overlaps: bool) -> Self {
        let mut contacts = vec![Vec::new(); parts.len()];
        for i in 0..parts.len() {
            for j in i + 1..parts.len() {
                if parts[i].iter().any(|a| parts[j].iter().any(|b| a.touches(b, tol) || (overlaps && a.overlaps(b, tol)))) {
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

    fn blockers(&self, i: usize, axis: Axis) -> Vec<usize> {
        let (a, negative) = (axis.index as usize, axis.negative);
        (0..self.parts.len())
            .filter(|&j| j != i)
            .filter(|&j| self.parts[i].iter().any(|x| self.parts[j].iter().any(|y| x.sweep_hits(y, a, negative, self.tol))))
            .collect()
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

    /// Explicit blockers and contacts: 0 fixed; 1 free; 2 free; 3 blocked by 2 everywhere.
    /// 3 rests on 1 and 2, so 1 must stay until 2 and 3 are gone.
    struct DeadEnd {
        contacts: Vec<Vec<usize>>,
    }

    impl RemovalModel for DeadEnd {
        fn num_parts(&self) -> usize {
            4
        }
        fn is_fixed(&self, i: usize) -> bool {
            i == 0
        }
        fn blockers(&self, i: usize, _: Axis) -> Vec<usize> {
            if i == 3 {
                vec![2]
            } else {
                vec![]
            }
        }
        fn contacts(&self, i: usize) -> &[usize] {
            &self.contacts[i]
        }
        fn bottom(&self, i: usize) -> f64 {
            [0.0, 3.0, 2.0, 1.0][i]
        }
    }

    #[test]
    fn the_stable_search_backtracks_out_of_a_dead_end() {
        // top-down, part 1 goes first and strands 3 on 2; the search must back out of that
        let model = DeadEnd { contacts: vec![vec![1, 2], vec![0, 3], vec![0, 3], vec![1, 2]] };
        let check = check_disassembly(&model);
        assert!(check.linked && check.straight_line && check.stable_order);
        let parts: Vec<usize> = check.order.iter().map(|&(i, _)| i).collect();
        assert_eq!(parts, vec![2, 3, 1]);
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
