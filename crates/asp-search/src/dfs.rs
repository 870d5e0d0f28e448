//! Depth-first Assembly-by-Disassembly (seed 3.3) with backtracking, part orderings and the
//! bookkeeping heuristic (seed 3.1.1).
//!
//! In each state the parts are tested in the configured order with the fast straight-line test;
//! the first removal whose remainder is stable is followed. When no part of a state can leave
//! along a straight line, the slow test (a path planner) is tried for each blocked part. Dead-end
//! states are remembered so that no state is expanded twice.

use crate::problem::{Budget, PlanOutcome, Problem, Progress, Stats, Status, Step, Stuck, StuckReason};
use crate::Planner;
use asp_geom::{MotionKind, Outcome, PartSet};
use rand::seq::SliceRandom;
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::collections::HashSet;
use std::time::Instant;

/// The order in which the parts of a state are tested.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Ordering {
    /// Index order (the model's part order): the thesis' "vanilla" AbD.
    #[default]
    Given,
    /// A fresh random permutation in every state, from the planner's seed.
    Random,
}

/// Settings of [`Dfs`]; build with [`Dfs::builder`].
#[derive(Clone, Debug)]
pub struct Dfs {
    ordering: Ordering,
    bookkeeping: bool,
    path_planner: bool,
    seed: u64,
}

/// Builder of [`Dfs`].
#[derive(Clone, Debug, Default)]
pub struct DfsBuilder {
    ordering: Ordering,
    bookkeeping: bool,
    no_path_planner: bool,
    seed: u64,
}

impl DfsBuilder {
    /// The part ordering (default [`Ordering::Given`]).
    pub fn ordering(mut self, ordering: Ordering) -> Self {
        self.ordering = ordering;
        self
    }
    /// Bookkeeping (seed 3.1.1): a part blocked by collision is retested only after one of its
    /// recorded blockers is gone. Default off.
    pub fn bookkeeping(mut self, on: bool) -> Self {
        self.bookkeeping = on;
        self
    }
    /// Whether to fall back to the path planner when no straight line works. Default on.
    pub fn path_planner(mut self, on: bool) -> Self {
        self.no_path_planner = !on;
        self
    }
    /// Seed of every random choice (random ordering, path planner). Default 0.
    pub fn seed(mut self, seed: u64) -> Self {
        self.seed = seed;
        self
    }
    /// The planner (every combination of settings is valid).
    pub fn build(self) -> Dfs {
        Dfs {
            ordering: self.ordering,
            bookkeeping: self.bookkeeping,
            path_planner: !self.no_path_planner,
            seed: self.seed,
        }
    }
}

impl Dfs {
    /// A builder with the defaults: given order, no bookkeeping, path planner on, seed 0.
    pub fn builder() -> DfsBuilder {
        DfsBuilder::default()
    }
}

/// The mutable state of one search.
struct Search<'p, 'a> {
    problem: &'p Problem<'a>,
    config: &'p Dfs,
    budget: &'p Budget,
    started: Instant,
    rng: ChaCha8Rng,
    /// Bookkeeping: the blockers of each part's last collision failure.
    blocked_by: Vec<Option<PartSet>>,
    dead: HashSet<PartSet>,
    /// Locked cores: sets of parts each blocked only by parts of the set (and fixed parts), so
    /// no state containing one can ever be taken apart (see [`locked_core`]).
    cores: Vec<PartSet>,
    path: Vec<Step>,
    expanded: u64,
    exhausted: bool,
    total: usize,
    /// The dead-end state with the fewest parts, with its parts' reasons.
    deepest: Option<(PartSet, Vec<Stuck>)>,
}

impl Search<'_, '_> {
    fn tests(&self) -> u64 {
        self.problem.checker.counters().removal_tests
    }

    fn out_of_budget(&mut self) -> bool {
        if !self.exhausted && self.budget.exhausted(self.tests(), self.started) {
            self.exhausted = true;
        }
        self.exhausted
    }

    fn order(&mut self, state: &PartSet) -> Vec<usize> {
        let mut parts = self.problem.removable(state);
        if self.config.ordering == Ordering::Random {
            parts.shuffle(&mut self.rng);
        }
        parts
    }

    /// Depth-first search from `state`; true when a full sequence was found (in `self.path`).
    fn search(&mut self, state: &PartSet) -> bool {
        if self.problem.is_goal(state) {
            return true;
        }
        if self.dead.contains(state) || self.cores.iter().any(|c| c.is_subset(state)) || self.out_of_budget() {
            return false;
        }
        self.expanded += 1;
        if let Some(report) = self.problem.progress {
            report(&Progress { removed: self.path.len(), total: self.total, tests: self.tests() });
        }
        let mut reasons: Vec<Stuck> = Vec::new();
        let mut collided: Vec<usize> = Vec::new();
        let mut any_removed = false;
        for part in self.order(state) {
            if self.out_of_budget() {
                return false;
            }
            if self.config.bookkeeping {
                if let Some(b) = &self.blocked_by[part] {
                    if b.is_subset(state) {
                        reasons.push(Stuck { part, reason: StuckReason::Blocked(b.clone()) });
                        continue;
                    }
                }
            }
            let outcome = self.problem.checker.test_removal(part, state, MotionKind::Linear);
            if let Outcome::Collision { .. } = &outcome {
                collided.push(part);
            }
            any_removed |= matches!(outcome, Outcome::Removed(_));
            if self.follow(part, state, outcome, &mut reasons) {
                return true;
            }
        }
        if self.config.path_planner && !any_removed {
            for part in collided {
                if self.out_of_budget() {
                    return false;
                }
                let seed = self.rng.random::<u64>();
                let outcome = self.problem.checker.test_removal(part, state, MotionKind::Path { seed });
                reasons.retain(|s| s.part != part);
                if self.follow(part, state, outcome, &mut reasons) {
                    return true;
                }
            }
        }
        if !self.exhausted {
            if let Some(core) = locked_core(&reasons, |p| self.problem.checker.is_fixed(p)) {
                self.cores.push(core);
            }
            self.dead.insert(state.clone());
            if self.deepest.as_ref().is_none_or(|(s, _)| state.len() < s.len()) {
                reasons.sort_by_key(|s| s.part);
                self.deepest = Some((state.clone(), reasons));
            }
        }
        false
    }

    /// Acts on one test's outcome: recurse into the child state, or record why it failed.
    fn follow(&mut self, part: usize, state: &PartSet, outcome: Outcome, reasons: &mut Vec<Stuck>) -> bool {
        match outcome {
            Outcome::Removed(motion) => {
                self.path.push(Step { part, motion });
                if self.search(&state.without(part)) {
                    return true;
                }
                self.path.pop();
                reasons.push(Stuck { part, reason: StuckReason::DeadEnd });
            }
            Outcome::Collision { blockers } => {
                if self.config.bookkeeping {
                    self.blocked_by[part] = Some(blockers.clone());
                }
                reasons.push(Stuck { part, reason: StuckReason::Blocked(blockers) });
            }
            Outcome::Unstable { floating, .. } => {
                reasons.push(Stuck { part, reason: StuckReason::WouldLeaveUnsupported(floating) });
            }
        }
        false
    }
}

/// The largest set `C` of parts of a dead state such that each part of `C` was blocked (in
/// every direction tried) only by parts of `C` and fixed parts. Straight-line blocking is a
/// property of part pairs, so removing parts outside `C` never frees a part of `C`: every state
/// containing `C` is a dead end too. (With the path planner in play this is a heuristic: a path
/// that failed among these parts is taken to fail among more.)
fn locked_core(reasons: &[Stuck], is_fixed: impl Fn(usize) -> bool) -> Option<PartSet> {
    let mut core: Vec<(usize, &PartSet)> = reasons
        .iter()
        .filter_map(|s| match &s.reason {
            StuckReason::Blocked(b) => Some((s.part, b)),
            _ => None,
        })
        .collect();
    loop {
        let members: Vec<usize> = core.iter().map(|(p, _)| *p).collect();
        let before = core.len();
        core.retain(|(_, b)| b.iter().all(|q| is_fixed(q) || members.contains(&q)));
        if core.len() == before {
            break;
        }
    }
    let n = reasons.iter().map(|s| s.part + 1).max().unwrap_or(0);
    (!core.is_empty()).then(|| PartSet::from_indices(n, core.iter().map(|(p, _)| *p)))
}

impl Planner for Dfs {
    fn name(&self) -> &'static str {
        "dfs"
    }

    fn solve(&self, problem: &Problem, budget: &Budget) -> PlanOutcome {
        let started = Instant::now();
        let before = problem.checker.counters();
        let mut search = Search {
            problem,
            config: self,
            budget,
            started,
            rng: ChaCha8Rng::seed_from_u64(self.seed),
            blocked_by: vec![None; problem.checker.num_parts()],
            dead: HashSet::new(),
            cores: Vec::new(),
            path: Vec::new(),
            expanded: 0,
            exhausted: false,
            total: problem.removable(&problem.start).len(),
            deepest: None,
        };
        let found = search.search(&problem.start);
        let status = if found {
            Status::Found
        } else if search.exhausted {
            Status::BudgetExhausted
        } else {
            let (state, stuck) = search.deepest.take().unwrap_or_default();
            Status::NoPlan { stuck, state }
        };
        let after = problem.checker.counters();
        let counters = asp_geom::CounterSnapshot {
            removal_tests: after.removal_tests - before.removal_tests,
            failed_collision: after.failed_collision - before.failed_collision,
            failed_gravity: after.failed_gravity - before.failed_gravity,
            path_planner_calls: after.path_planner_calls - before.path_planner_calls,
        };
        PlanOutcome {
            status,
            removals: search.path,
            stats: Stats { counters, seconds: started.elapsed().as_secs_f64(), states_expanded: search.expanded },
        }
    }
}
