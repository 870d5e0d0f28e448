//! Depth-first Assembly-by-Disassembly (seed 3.3) with backtracking, part orderings and the
//! bookkeeping heuristic (seed 3.1.1).
//!
//! In each state the parts are tested in the configured order with the fast straight-line test;
//! the first removal whose remainder is stable is followed. When no part of a state can leave
//! along a straight line, the slow test (a path planner) is tried for each blocked part. Dead-end
//! states are remembered so that no state is expanded twice.

use crate::ordering::{state_seed, BuiltinOrder, OrderingFactory, PartOrdering, WithBookkeeping};
use crate::problem::{Budget, PlanOutcome, Problem, Progress, Stats, Status, Step, Stuck, StuckReason};
use crate::Planner;
use asp_geom::{MotionKind, Outcome, PartSet};
use std::collections::HashSet;
use std::sync::Arc;
use std::time::Instant;

/// Settings of [`Dfs`]; build with [`Dfs::builder`].
#[derive(Clone, Debug)]
pub struct Dfs {
    ordering: Arc<dyn OrderingFactory>,
    path_planner: bool,
    seed: u64,
}

/// Builder of [`Dfs`].
#[derive(Clone, Debug)]
pub struct DfsBuilder {
    ordering: Arc<dyn OrderingFactory>,
    bookkeeping: bool,
    no_path_planner: bool,
    seed: u64,
}

impl Default for DfsBuilder {
    fn default() -> Self {
        DfsBuilder { ordering: Arc::new(BuiltinOrder::Given), bookkeeping: false, no_path_planner: false, seed: 0 }
    }
}

impl DfsBuilder {
    /// One of the built-in part orderings (default [`BuiltinOrder::Given`]).
    pub fn ordering(self, ordering: BuiltinOrder) -> Self {
        self.ordering_factory(Arc::new(ordering))
    }
    /// Any part ordering, e.g. a learned one (`asp-learn`).
    pub fn ordering_factory(mut self, factory: Arc<dyn OrderingFactory>) -> Self {
        self.ordering = factory;
        self
    }
    /// Bookkeeping (seed 3.1.1) on top of the ordering: a part blocked by collision is retested
    /// only after one of its recorded blockers is gone. Default off.
    pub fn bookkeeping(mut self, on: bool) -> Self {
        self.bookkeeping = on;
        self
    }
    /// Whether to fall back to the path planner when no straight line works. Default on.
    pub fn path_planner(mut self, on: bool) -> Self {
        self.no_path_planner = !on;
        self
    }
    /// Seed of every random choice (shuffled and random orderings, path planner). Default 0.
    pub fn seed(mut self, seed: u64) -> Self {
        self.seed = seed;
        self
    }
    /// The planner (every combination of settings is valid).
    pub fn build(self) -> Dfs {
        let ordering: Arc<dyn OrderingFactory> =
            if self.bookkeeping { Arc::new(WithBookkeeping(self.ordering)) } else { self.ordering };
        Dfs { ordering, path_planner: !self.no_path_planner, seed: self.seed }
    }
}

impl Dfs {
    /// A builder with the defaults: given order, no bookkeeping, path planner on, seed 0.
    pub fn builder() -> DfsBuilder {
        DfsBuilder::default()
    }

    /// The name of the part ordering (with `+bookkeeping` when decorated).
    pub fn ordering_name(&self) -> String {
        self.ordering.name()
    }
}

/// The mutable state of one search.
struct Search<'p, 'a, 'v> {
    problem: &'p Problem<'a>,
    config: &'p Dfs,
    budget: &'p Budget,
    started: Instant,
    ordering: Box<dyn PartOrdering>,
    /// The tests this search ran.
    counters: asp_geom::CounterSnapshot,
    /// Called with every visited state (data collection).
    visit: Option<&'v mut dyn FnMut(&PartSet)>,
    dead: HashSet<PartSet>,
    /// Locked cores: sets of parts each blocked only by parts of the set (and fixed parts), so
    /// no state containing one can ever be taken apart (see [`locked_core`]).
    cores: Vec<PartSet>,
    path: Vec<Step>,
    expanded: u64,
    exhausted: bool,
    total: usize,
    /// The dead-end state with the fewest parts, with its parts' reasons and the removals that
    /// reached it (a `no_plan` result's partial disassembly).
    deepest: Option<(PartSet, Vec<Stuck>, Vec<Step>)>,
    /// The longest branch so far (a `budget_exhausted` result's partial disassembly).
    longest: Vec<Step>,
}

impl Search<'_, '_, '_> {
    fn tests(&self) -> u64 {
        self.counters.removal_tests
    }

    fn out_of_budget(&mut self) -> bool {
        if !self.exhausted && self.budget.exhausted(self.tests(), self.started) {
            self.exhausted = true;
        }
        self.exhausted
    }

    fn order(&mut self, state: &PartSet) -> Vec<usize> {
        let mut parts = self.problem.removable(state);
        self.ordering.order(state, &mut parts);
        parts
    }

    fn test(&mut self, part: usize, state: &PartSet, kind: MotionKind) -> Outcome {
        let outcome = self.problem.checker.test_removal(part, state, kind);
        // counted here, not read off the checker: searches may share one checker in parallel
        self.counters.record(kind, &outcome);
        self.ordering.observe(part, state, kind, &outcome);
        outcome
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
        if let Some(visit) = self.visit.as_mut() {
            visit(state);
        }
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
            if let Some(blockers) = self.ordering.known_blocked(part, state) {
                // the skipped test would collide again; the part still gets its path-planner
                // chance below, so the search is the same as without bookkeeping
                collided.push(part);
                reasons.push(Stuck { part, reason: StuckReason::Blocked(blockers) });
                continue;
            }
            let outcome = self.test(part, state, MotionKind::Linear);
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
                // seeded by the state and the part, not by the search's history: the same
                // state gets the same path-planner runs whatever the ordering skipped before
                let seed = state_seed(self.config.seed, state, part as u64);
                let outcome = self.test(part, state, MotionKind::Path { seed });
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
            if self.deepest.as_ref().is_none_or(|(s, _, _)| state.len() < s.len()) {
                reasons.sort_by_key(|s| s.part);
                self.deepest = Some((state.clone(), reasons, self.path.clone()));
            }
        }
        false
    }

    /// Acts on one test's outcome: recurse into the child state, or record why it failed.
    fn follow(&mut self, part: usize, state: &PartSet, outcome: Outcome, reasons: &mut Vec<Stuck>) -> bool {
        match outcome {
            Outcome::Removed(motion) => {
                self.path.push(Step { part, motion });
                if self.path.len() > self.longest.len() {
                    self.longest.clone_from(&self.path);
                }
                if self.search(&state.without(part)) {
                    return true;
                }
                self.path.pop();
                reasons.push(Stuck { part, reason: StuckReason::DeadEnd });
            }
            Outcome::Collision { blockers } => {
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
        self.solve_visiting(problem, budget, None)
    }
}

impl Dfs {
    /// [`Planner::solve`], calling `visit` with every state the search expands (in order; each
    /// state once). Data collection records these states.
    pub fn solve_visiting(
        &self,
        problem: &Problem,
        budget: &Budget,
        visit: Option<&mut dyn FnMut(&PartSet)>,
    ) -> PlanOutcome {
        let started = Instant::now();
        let mut search = Search {
            problem,
            config: self,
            budget,
            started,
            ordering: self.ordering.make(problem.checker.num_parts(), self.seed),
            visit,
            counters: asp_geom::CounterSnapshot::default(),
            dead: HashSet::new(),
            cores: Vec::new(),
            path: Vec::new(),
            expanded: 0,
            exhausted: false,
            total: problem.removable(&problem.start).len(),
            deepest: None,
            longest: Vec::new(),
        };
        let found = search.search(&problem.start);
        // not found: the removals of the partial disassembly that got furthest (to the deepest
        // dead end, whose parts the explanation lists, or the longest branch when the budget ran
        // out), so a failed search still says which parts came off and how
        let (status, removals) = if found {
            (Status::Found, std::mem::take(&mut search.path))
        } else if search.exhausted {
            (Status::BudgetExhausted, std::mem::take(&mut search.longest))
        } else {
            let (state, stuck, path) = search.deepest.take().unwrap_or_else(|| (problem.start.clone(), Vec::new(), Vec::new()));
            (Status::NoPlan { stuck, state }, path)
        };
        let counters = search.counters;
        PlanOutcome {
            status,
            removals,
            stats: Stats { counters, seconds: started.elapsed().as_secs_f64(), states_expanded: search.expanded },
        }
    }
}
