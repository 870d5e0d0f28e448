//! Units declared by the user (`--unit-group NAME,NAME...`): a purchased motor,
//! a pressed-in bearing, parts that are one part for assembly. [`UnitChecker`] wraps any
//! checker so that the planners move each unit as one rigid part, on purpose: its parts never
//! leave alone, the unit leaves whole (a subassembly step whose `unit` is set, never planned
//! apart), and a group that takes one part of a unit takes all of it. A unit holding a fixed part
//! is part of the base.

use asp_geom::{CounterSnapshot, FeasibilityChecker, MotionKind, Outcome, PartSet, Stability};

/// The checker a [`UnitChecker`] wraps: borrowed (the model's) or owned (a subassembly's).
enum Inner<'a> {
    Borrowed(&'a dyn FeasibilityChecker),
    Owned(Box<dyn FeasibilityChecker + 'a>),
}

/// A checker whose declared units move as one part each (see the module documentation).
pub struct UnitChecker<'a> {
    inner: Inner<'a>,
    units: Vec<PartSet>,
}

impl<'a> UnitChecker<'a> {
    /// `inner` with `units` (disjoint sets of at least two parts each) moving as one part each.
    pub fn new(inner: &'a dyn FeasibilityChecker, units: Vec<PartSet>) -> Self {
        UnitChecker { inner: Inner::Borrowed(inner), units }
    }

    fn inner(&self) -> &dyn FeasibilityChecker {
        match &self.inner {
            Inner::Borrowed(c) => *c,
            Inner::Owned(c) => &**c,
        }
    }

    /// The unit that holds `part`, if any.
    fn unit_of(&self, part: usize) -> Option<&PartSet> {
        self.units.iter().find(|u| u.contains(part))
    }

    /// `group` with every unit it touches made whole.
    fn whole(&self, group: &PartSet) -> PartSet {
        let mut g = group.clone();
        for u in self.units.iter().filter(|u| u.intersects(group)) {
            g.union_with(u);
        }
        g
    }
}

impl FeasibilityChecker for UnitChecker<'_> {
    fn num_parts(&self) -> usize {
        self.inner().num_parts()
    }

    /// Fixed, or in a unit with a fixed part (the unit is part of the base).
    fn is_fixed(&self, part: usize) -> bool {
        let inner = self.inner();
        inner.is_fixed(part) || self.unit_of(part).is_some_and(|u| u.iter().any(|q| inner.is_fixed(q)))
    }

    /// A part of a unit never leaves alone: it is blocked by the unit's other parts and by what
    /// blocks the unit as a whole (so a state is never taken for a dead end that the unit's
    /// leaving would open).
    fn test_removal(&self, part: usize, state: &PartSet, kind: MotionKind) -> Outcome {
        let Some(unit) = self.unit_of(part) else { return self.inner().test_removal(part, state, kind) };
        let mut blockers = unit.intersection(state);
        blockers.remove(part);
        if let Outcome::Collision { blockers: b } = self.inner().test_group_removal(&unit.intersection(state), state) {
            blockers.union_with(&b);
        }
        Outcome::Collision { blockers }
    }

    fn stability(&self, state: &PartSet) -> Stability {
        self.inner().stability(state)
    }

    fn counters(&self) -> CounterSnapshot {
        self.inner().counters()
    }

    /// The wrapped checker: whatever a unit does not change is its answer (a robot's refusal
    /// reasons among them).
    fn decorated(&self) -> Option<&dyn FeasibilityChecker> {
        Some(self.inner())
    }

    /// The wrapped checker's groups with their units made whole, then every unit present (none
    /// with a fixed part), smallest first, without duplicates.
    fn group_candidates(&self, state: &PartSet) -> Vec<PartSet> {
        let mut found: Vec<PartSet> = Vec::new();
        let candidates = self.inner().group_candidates(state).into_iter().map(|g| self.whole(&g));
        for g in candidates.chain(self.units.iter().filter(|u| u.is_subset(state)).cloned()) {
            if g.len() >= 2 && g.is_subset(state) && !g.iter().any(|p| self.is_fixed(p)) && !found.iter().any(|f| same(f, &g)) {
                found.push(g);
            }
        }
        found.sort_by_key(|g| (g.len(), g.iter().next()));
        found
    }

    /// The wrapped checker's subassembly, with the units inside the group.
    fn subassembly(&self, group: &PartSet) -> Option<(usize, Box<dyn FeasibilityChecker + '_>)> {
        let (base, sub) = self.inner().subassembly(group)?;
        let units = self.units.iter().filter(|u| u.is_subset(group)).cloned().collect();
        Some((base, Box::new(UnitChecker { inner: Inner::Owned(sub), units })))
    }

    fn is_unit(&self, group: &PartSet) -> bool {
        self.units.iter().any(|u| same(u, group)) || self.inner().is_unit(group)
    }
}

/// Whether two sets hold the same parts (whatever room each has).
fn same(a: &PartSet, b: &PartSet) -> bool {
    a.is_subset(b) && b.is_subset(a)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A checker that refuses every removal with a reason, and moves parts 1 and 2 as a group.
    struct Refusing;

    impl FeasibilityChecker for Refusing {
        fn num_parts(&self) -> usize {
            4
        }
        fn is_fixed(&self, part: usize) -> bool {
            part == 0
        }
        fn test_removal(&self, _part: usize, state: &PartSet, _kind: MotionKind) -> Outcome {
            Outcome::Collision { blockers: state.clone() }
        }
        fn stability(&self, _state: &PartSet) -> Stability {
            Stability::Stable
        }
        fn counters(&self) -> CounterSnapshot {
            CounterSnapshot::default()
        }
        fn in_movable_group(&self, part: usize, _state: &PartSet) -> bool {
            part == 1 || part == 2
        }
        fn refusal_reason(&self, _part: usize, _state: &PartSet) -> Option<&'static str> {
            Some("no path")
        }
    }

    /// What units do not change is the wrapped checker's answer, the methods the unit checker
    /// does not define among them: a robot's refusal reason reaches the caller through units.
    #[test]
    fn a_unit_checker_forwards_what_units_do_not_change() {
        let inner = Refusing;
        let units = UnitChecker::new(&inner, vec![PartSet::from_indices(5, [2, 3])]);
        let all = PartSet::full(4);
        assert_eq!(units.refusal_reason(1, &all), Some("no path"));
        assert!(units.in_movable_group(1, &all) && !units.in_movable_group(3, &all));
        assert!(units.decorated().is_some());
        // what it does define is its own: a unit's part never leaves alone
        assert!(units.is_unit(&PartSet::from_indices(5, [2, 3])) && !inner.is_unit(&PartSet::from_indices(5, [2, 3])));
    }
}
