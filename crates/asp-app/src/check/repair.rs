//! The repair: a depth-first search that tries the given steps in the given order at every
//! state, and the distances of its sequence to the given one (steps moved, Kendall tau).

use super::*;

/// What the repair search found: the units in assembly order with their removal motions.
pub(super) struct Found {
    pub(super) sequence: Option<Vec<(usize, Motion)>>,
    pub(super) tests: u64,
    pub(super) exhausted: bool,
}

/// The depth-first search of the repair: from the assembled state, at every state the present
/// units in the given sequence's disassembly order (the latest placed first), dead states
/// remembered; within the settings' budget.
pub(super) fn repair_search(tester: &Tester<'_>, units: &[Unit], full: &PartSet, budget: &Budget) -> Found {
    struct Search<'s, 'a> {
        tester: &'s Tester<'a>,
        units: &'s [Unit],
        budget: &'s Budget,
        started: Instant,
        tests: u64,
        dead: HashSet<PartSet>,
        exhausted: bool,
    }
    impl Search<'_, '_> {
        fn go(&mut self, state: &PartSet, left: &mut Vec<usize>, removals: &mut Vec<(usize, Motion)>) -> bool {
            if left.is_empty() {
                return true;
            }
            if self.dead.contains(state) {
                return false;
            }
            // straight lines for every step first (in the given order), then the path planner
            // for the single parts no straight line freed, as the planner's own search does
            let mut straight_free = vec![false; self.units.len()];
            for path in [false, true] {
                for i in (0..left.len()).rev() {
                    if self.budget.exhausted(asp_search::Spent::tests(self.tests), self.started) {
                        self.exhausted = true;
                        return false;
                    }
                    let k = left[i];
                    let parts = &self.units[k].parts;
                    let outcome = if !path {
                        self.tests += 1;
                        self.tester.straight(parts, state)
                    } else if parts.len() == 1 && !straight_free[k] {
                        self.tests += 1;
                        match self.tester.path(parts[0], state) {
                            Some(o) => o,
                            None => continue,
                        }
                    } else {
                        continue;
                    };
                    if !path && !matches!(outcome, Outcome::Collision { .. }) {
                        straight_free[k] = true; // a path would not make it stand
                    }
                    let Outcome::Removed(motion) = outcome else { continue };
                    let next = Tester::rest(state, parts);
                    left.remove(i);
                    removals.push((k, motion));
                    if self.go(&next, left, removals) {
                        return true;
                    }
                    removals.pop();
                    left.insert(i, k);
                    if self.exhausted {
                        return false;
                    }
                }
            }
            self.dead.insert(state.clone());
            false
        }
    }
    let mut search = Search { tester, units, budget, started: Instant::now(), tests: 0, dead: HashSet::new(), exhausted: false };
    let mut left: Vec<usize> = (0..units.len()).collect();
    let mut removals = Vec::new();
    let found = search.go(full, &mut left, &mut removals);
    removals.reverse();
    Found { sequence: found.then_some(removals), tests: search.tests, exhausted: search.exhausted }
}

/// For an order of the given steps (`order[j]` = the given index of the `j`-th step), the number
/// of moved steps (`n` − the longest increasing subsequence, i.e. the longest common subsequence
/// with the given order) and, per position, whether it is in that subsequence (kept in place).
pub fn moved_steps(order: &[usize]) -> (usize, Vec<bool>) {
    let n = order.len();
    // O(n²) longest increasing subsequence with predecessors
    let mut len = vec![1usize; n];
    let mut prev = vec![usize::MAX; n];
    for j in 0..n {
        for i in 0..j {
            if order[i] < order[j] && len[i] + 1 > len[j] {
                len[j] = len[i] + 1;
                prev[j] = i;
            }
        }
    }
    let mut kept = vec![false; n];
    if let Some(mut j) = (0..n).max_by_key(|&j| (len[j], std::cmp::Reverse(j))) {
        let best = len[j];
        loop {
            kept[j] = true;
            if prev[j] == usize::MAX {
                break;
            }
            j = prev[j];
        }
        (n - best, kept)
    } else {
        (0, kept)
    }
}

/// The Kendall tau distance of an order of the given steps to the given order: pairs in the
/// other order.
pub fn kendall_tau(order: &[usize]) -> usize {
    let mut count = 0;
    for j in 0..order.len() {
        for i in 0..j {
            count += usize::from(order[i] > order[j]);
        }
    }
    count
}
