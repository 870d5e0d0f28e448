//! The contact graph, the world's second component: which parts lie within the contact distance
//! of each other (touching or overlapping), the fixed parts (the ground included) every state
//! stands on, and the contact-graph stability test.
//!
//! Stability is a reachability question on this graph; it is asked through
//! [`PartSet::reached_within`], the one breadth-first search over parts, so the world, the
//! generators' checks and the tests agree on what "linked to a fixed part" means.

use crate::feasibility::Stability;
use crate::partset::PartSet;

/// Which parts touch which, and which are fixed.
#[derive(Clone)]
pub struct Contacts {
    sets: Vec<PartSet>,
    distance: f32,
    fixed: PartSet,
}

impl Contacts {
    /// The graph of `sets` (per part, ground included, the parts within `distance` of it) over
    /// the `fixed` parts.
    pub(super) fn new(sets: Vec<PartSet>, distance: f32, fixed: PartSet) -> Contacts {
        Contacts { sets, distance, fixed }
    }

    /// Parts in contact with part `i` (ground included).
    pub fn of(&self, i: usize) -> &PartSet {
        &self.sets[i]
    }

    /// The contact distance of the graph, in metres.
    pub fn distance(&self) -> f32 {
        self.distance
    }

    /// Fixed parts, the ground included.
    pub fn fixed(&self) -> &PartSet {
        &self.fixed
    }

    /// The state plus the fixed parts that are always present (ground included).
    pub fn with_fixed(&self, state: &PartSet) -> PartSet {
        let mut s = state.clone();
        s.union_with(&self.fixed);
        s
    }

    /// Contact-graph stability: every present part is linked through contacts to a fixed part.
    pub fn stability(&self, state: &PartSet) -> Stability {
        self.stability_among(&self.with_fixed(state), &self.fixed)
    }

    /// Contact-graph stability of the `present` parts on the `base` parts among them: every
    /// present part is linked through contacts to a present base part.
    pub fn stability_among(&self, present: &PartSet, base: &PartSet) -> Stability {
        let reached = present.intersection(base).reached_within(present, |i| self.sets[i].iter());
        let floating = PartSet::from_indices(self.sets.len(), present.iter().filter(|&i| !reached.contains(i)));
        if floating.is_empty() {
            Stability::Stable
        } else {
            Stability::Unstable { floating }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A tower 0-1-2 on the ground 4, and 3 touching only 2.
    fn tower() -> Contacts {
        let links = [vec![1, 4], vec![0, 2], vec![1, 3], vec![2], vec![0]];
        let sets = links.iter().map(|l| PartSet::from_indices(5, l.iter().copied())).collect();
        Contacts::new(sets, 0.01, PartSet::from_indices(5, [4]))
    }

    #[test]
    fn a_part_is_stable_while_a_chain_of_contacts_reaches_a_fixed_part() {
        let c = tower();
        assert_eq!(c.stability(&PartSet::from_indices(5, [0, 1, 2, 3])), Stability::Stable);
        // without 1, 2 and 3 float
        let floating = PartSet::from_indices(5, [2, 3]);
        assert_eq!(c.stability(&PartSet::from_indices(5, [0, 2, 3])), Stability::Unstable { floating });
        assert_eq!(c.with_fixed(&PartSet::empty(5)), PartSet::from_indices(5, [4]));
        assert_eq!((c.of(2), c.distance()), (&PartSet::from_indices(5, [1, 3]), 0.01));
    }

    #[test]
    fn a_subassembly_stands_on_its_own_base() {
        let c = tower();
        // 1, 2 and 3 on the base 2 without the ground: all linked
        let present = PartSet::from_indices(5, [1, 2, 3]);
        assert_eq!(c.stability_among(&present, &PartSet::from_indices(5, [2])), Stability::Stable);
        // on the base 3 with 2 missing, 1 floats
        let present = PartSet::from_indices(5, [1, 3]);
        let floating = PartSet::from_indices(5, [1]);
        assert_eq!(c.stability_among(&present, &PartSet::from_indices(5, [3])), Stability::Unstable { floating });
    }
}
