//! Depth-first Assembly-by-Disassembly (thesis 3.3) with backtracking, part orderings and the
//! bookkeeping heuristic (thesis 3.1.1).
//!
//! In each state the parts are tested in the configured order with the fast straight-line test;
//! the first removal whose remainder is stable is followed. When every single-part removal of a
//! state fails (or leads to dead ends), groups of parts that can leave together along a straight
//! line are tried (subassemblies, smallest first; on by default). When no part of a state can
//! leave along a straight line, the slow test (a path planner) is tried for each blocked part,
//! except where it failed before with the same blockers. Dead-end states are remembered so that
//! no state is expanded twice, and so are locked cores: sets of parts that hold each other in
//! every state that contains them, so the search stops as soon as every branch contains one.
//! Subassemblies of the result are then planned on their own base, recursively.

use crate::ordering::{state_seed, BuiltinOrder, OrderingFactory, PartOrdering, WithBookkeeping};
use crate::problem::{
    Budget, PlanOutcome, Planner, Problem, Progress, Spent, Stats, Status, Step, StopReason, Stuck, StuckReason, Subassembly,
};
use asp_geom::{MotionKind, Outcome, PartSet};
use std::collections::{HashMap, HashSet};
use std::sync::Arc;
use std::time::Instant;

/// Settings of [`Dfs`]; build with [`Dfs::builder`].
#[derive(Clone, Debug)]
pub struct Dfs {
    ordering: Arc<dyn OrderingFactory>,
    path_planner: bool,
    subassemblies: bool,
    seed: u64,
}

/// Builder of [`Dfs`].
#[derive(Clone, Debug)]
pub struct DfsBuilder {
    ordering: Arc<dyn OrderingFactory>,
    bookkeeping: bool,
    no_path_planner: bool,
    no_subassemblies: bool,
    seed: u64,
}

impl Default for DfsBuilder {
    fn default() -> Self {
        DfsBuilder { ordering: Arc::new(BuiltinOrder::Given), bookkeeping: false, no_path_planner: false, no_subassemblies: false, seed: 0 }
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
    /// Bookkeeping (thesis 3.1.1) on top of the ordering: a part blocked by collision is retested
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
    /// Whether groups of parts may leave together as rigid subassemblies (when no single part
    /// can). Default on.
    pub fn subassemblies(mut self, on: bool) -> Self {
        self.no_subassemblies = !on;
        self
    }
    /// Seed of every random choice (shuffled and random orderings, path planner). Default 0.
    pub fn seed(mut self, seed: u64) -> Self {
        self.seed = seed;
        self
    }
    /// The planner (every combination of settings is valid).
    pub fn build(self) -> Dfs {
        let ordering: Arc<dyn OrderingFactory> = if self.bookkeeping { Arc::new(WithBookkeeping(self.ordering)) } else { self.ordering };
        Dfs { ordering, path_planner: !self.no_path_planner, subassemblies: !self.no_subassemblies, seed: self.seed }
    }
}

impl Dfs {
    /// A builder with the defaults: given order, no bookkeeping, path planner and subassemblies
    /// on, seed 0.
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
    /// Per part, the straight-line blockers of the states where the path planner failed for it:
    /// it is not called again while those blockers are all present (more obstacles never help).
    path_failed: HashMap<usize, Vec<PartSet>>,
    /// Time spent in the path planner.
    path_seconds: f64,
    /// Why the budget ran out.
    stopped_by: Option<StopReason>,
}

impl Search<'_, '_, '_> {
    fn tests(&self) -> u64 {
        self.counters.removal_tests
    }

    fn out_of_budget(&mut self) -> bool {
        if !self.exhausted {
            let spent = Spent { tests: self.tests(), states: self.expanded, ..Spent::default() };
            if let Some(reason) = self.budget.stop_reason(spent, self.started) {
                self.exhausted = true;
                self.stopped_by = Some(reason);
            }
        }
        self.exhausted
    }

    fn report_progress(&self) {
        if let Some(report) = self.problem.progress {
            let removed = self.path.iter().map(|s| s.group.as_ref().map_or(1, |g| g.parts.len())).sum();
            report(&Progress { removed, total: self.total, tests: self.tests() });
        }
    }

    /// Whether a known locked core lies within `state` (then `state` is a dead end).
    fn holds_core(&self, state: &PartSet) -> bool {
        self.cores.iter().any(|c| c.is_subset(state))
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
        if self.dead.contains(state) || self.holds_core(state) || self.out_of_budget() {
            return false;
        }
        self.expanded += 1;
        if let Some(visit) = self.visit.as_mut() {
            visit(state);
        }
        self.report_progress();
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
            if self.holds_core(state) {
                // a branch below found a locked core that this state holds too
                return self.dead_end(state, reasons);
            }
        }
        if self.config.subassemblies {
            for group in self.problem.checker.group_candidates(state) {
                if self.out_of_budget() {
                    return false;
                }
                let outcome = self.problem.checker.test_group_removal(&group, state);
                self.counters.record(MotionKind::Linear, &outcome);
                if let Outcome::Removed(motion) = outcome {
                    any_removed = true;
                    let mut rest = state.clone();
                    for p in group.iter() {
                        rest.remove(p);
                    }
                    let part = group.iter().next().expect("a group has parts");
                    let unit = self.problem.checker.is_unit(&group);
                    let group = Some(Box::new(Subassembly { parts: group, plan: None, unit }));
                    if self.descend(Step { part, motion, group, moves: Vec::new() }, &rest) {
                        return true;
                    }
                    if self.holds_core(state) {
                        return self.dead_end(state, reasons);
                    }
                }
            }
        }
        if self.config.path_planner && !any_removed {
            for part in collided {
                if self.out_of_budget() {
                    return false;
                }
                let blockers = match reasons.iter().find(|s| s.part == part).map(|s| &s.reason) {
                    Some(StuckReason::Blocked(b)) => b.clone(),
                    _ => PartSet::empty(0),
                };
                if self.path_failed.get(&part).is_some_and(|f| f.iter().any(|b| b.is_subset(&blockers))) {
                    continue; // it failed before among these blockers or fewer: the same answer
                }
                // a path planner call is slow: report progress before each (a caller's hook may
                // stop the search there, e.g. on Ctrl-C)
                self.report_progress();
                // seeded by the state and the part, not by the search's history: the same
                // state gets the same path-planner runs whatever the ordering skipped before
                let seed = state_seed(self.config.seed, state, part as u64);
                let started = Instant::now();
                let outcome = self.test(part, state, MotionKind::Path { seed });
                self.path_seconds += started.elapsed().as_secs_f64();
                if let Outcome::Collision { .. } = &outcome {
                    self.path_failed.entry(part).or_default().push(blockers);
                }
                reasons.retain(|s| s.part != part);
                if self.follow(part, state, outcome, &mut reasons) {
                    return true;
                }
            }
        }
        self.dead_end(state, reasons)
    }

    /// Records `state` as a dead end (unless the budget ran out, which proves nothing): its
    /// locked core, if any, and the deepest dead end with its reasons. Returns false.
    fn dead_end(&mut self, state: &PartSet, mut reasons: Vec<Stuck>) -> bool {
        if !self.exhausted {
            let checker = self.problem.checker;
            let groups = self.config.subassemblies;
            let core = locked_core(&reasons, |p| checker.is_fixed(p))
                // with subassemblies a core is locked only when none of its parts can leave in a
                // group either (a group closure only grows when parts are added)
                .filter(|core| !groups || !core.iter().any(|p| checker.in_movable_group(p, state)));
            if let Some(core) = core {
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

    /// Follows a removal into the state it leaves; true when that led to a full sequence.
    fn descend(&mut self, step: Step, rest: &PartSet) -> bool {
        self.path.push(step);
        if self.path.len() > self.longest.len() {
            self.longest.clone_from(&self.path);
        }
        if self.search(rest) {
            return true;
        }
        self.path.pop();
        false
    }

    /// Acts on one test's outcome: recurse into the child state, or record why it failed.
    fn follow(&mut self, part: usize, state: &PartSet, outcome: Outcome, reasons: &mut Vec<Stuck>) -> bool {
        match outcome {
            Outcome::Removed(motion) => {
                if self.descend(Step::single(part, motion), &state.without(part)) {
                    return true;
                }
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
/// containing `C` is a dead end too. (With the path planner in play, physics stability or a
/// robot's refusals, which block a part by every other present part, this is a heuristic: a
/// path or an arm's plan that failed among these parts is taken to fail among more.)
///
/// A part that could leave but would leave others without support is never in a core: in a
/// state with more parts, the extra parts may hold the others up (a frame's crossbar that
/// leaves two uprights standing alone in a 3-part state leaves freely while their neighbours
/// stand), so such a set is not locked, and taking it for one made the search answer `no_plan`
/// on assemblies that plan.
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

    /// [`Dfs::solve`] (the depth-first search has no error to report).
    fn solve(&self, problem: &Problem, budget: &Budget) -> crate::Result<PlanOutcome> {
        Ok(Dfs::solve(self, problem, budget))
    }
}

impl Dfs {
    /// [`Planner::solve`] without its `Result`: the depth-first search cannot fail (its settings
    /// are all valid, its checker answers every test), so its callers need not unwrap. It
    /// counts removal tests ([`Budget::max_tests`]), expanded states ([`Budget::max_states`]),
    /// wall time and the cancel token.
    pub fn solve(&self, problem: &Problem, budget: &Budget) -> PlanOutcome {
        self.solve_visiting(problem, budget, None)
    }

    /// [`Dfs::solve`], calling `visit` with every state the search expands (in order; each
    /// state once). Data collection records these states.
    pub fn solve_visiting(&self, problem: &Problem, budget: &Budget, visit: Option<&mut dyn FnMut(&PartSet)>) -> PlanOutcome {
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
            path_failed: HashMap::new(),
            path_seconds: 0.0,
            stopped_by: None,
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
        let mut outcome = PlanOutcome {
            status,
            removals,
            stats: Stats {
                counters: search.counters,
                seconds: 0.0,
                states_expanded: search.expanded,
                path_planner_seconds: search.path_seconds,
                stopped_by: search.stopped_by,
            },
        };
        self.plan_subassemblies(problem, budget, started, &mut outcome);
        outcome.stats.seconds = started.elapsed().as_secs_f64();
        outcome
    }

    /// Plans every subassembly of `outcome`'s removals on its own base (recursively: a
    /// subassembly's plan may hold subassemblies), within what is left of the budget; adds their
    /// effort to `outcome`'s. The step's part becomes the subassembly's base.
    fn plan_subassemblies(&self, problem: &Problem, budget: &Budget, started: Instant, outcome: &mut PlanOutcome) {
        let inner = Dfs { path_planner: false, ..self.clone() };
        for step in &mut outcome.removals {
            let Some(group) = step.group.as_mut() else { continue };
            let Some((base, checker)) = problem.checker.subassembly(&group.parts) else { continue };
            step.part = base;
            if group.unit {
                continue; // declared one unit: not taken apart
            }
            let stats = &outcome.stats;
            let left =
                budget.remaining(Spent { tests: stats.counters.removal_tests, states: stats.states_expanded, ..Spent::default() }, started);
            if left.exhausted(Spent::default(), Instant::now()) {
                continue;
            }
            let sub = Problem { checker: &*checker, start: group.parts.clone(), progress: problem.progress };
            let plan = inner.solve(&sub, &left);
            let (c, s) = (&mut outcome.stats.counters, &plan.stats);
            c.removal_tests += s.counters.removal_tests;
            c.failed_collision += s.counters.failed_collision;
            c.failed_gravity += s.counters.failed_gravity;
            outcome.stats.states_expanded += s.states_expanded;
            if plan.status == Status::BudgetExhausted {
                outcome.stats.stopped_by = outcome.stats.stopped_by.or(s.stopped_by);
            }
            group.plan = Some(plan);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use asp_geom::math::Vec3;
    use asp_geom::{CounterSnapshot, FeasibilityChecker, Motion, Stability};

    /// A frame of four parts: 0 the fixed base, 1 a free support, 2 a crossbar, 3 an upright.
    /// The crossbar blocks the upright; the upright stands while the crossbar or the support is
    /// present. Taking the support first leaves {base, crossbar, upright}: a dead end (the
    /// crossbar would leave the upright unsupported, the upright is blocked by the crossbar).
    /// From the assembled state the crossbar leaves freely (the support holds the upright up).
    struct Frame;

    impl FeasibilityChecker for Frame {
        fn num_parts(&self) -> usize {
            4
        }
        fn is_fixed(&self, part: usize) -> bool {
            part == 0
        }
        fn test_removal(&self, part: usize, state: &PartSet, _kind: MotionKind) -> Outcome {
            let motion = Motion::Linear { direction: Vec3::Z, distance: 1.0 };
            if part == 3 && state.contains(2) {
                return Outcome::Collision { blockers: PartSet::from_indices(4, [2]) };
            }
            let rest = state.without(part);
            match self.stability(&rest) {
                Stability::Stable => Outcome::Removed(motion),
                Stability::Unstable { floating } => Outcome::Unstable { floating, motion },
            }
        }
        fn stability(&self, state: &PartSet) -> Stability {
            if state.contains(3) && !state.contains(1) && !state.contains(2) {
                Stability::Unstable { floating: PartSet::from_indices(4, [3]) }
            } else {
                Stability::Stable
            }
        }
        fn counters(&self) -> CounterSnapshot {
            CounterSnapshot::default()
        }
    }

    #[test]
    fn a_part_that_would_leave_others_unsupported_does_not_lock_a_core() {
        // the given order takes the support first and reaches the dead end; a core of
        // {crossbar, upright} would hold in the assembled state too and end the search there
        let dfs = Dfs::builder().ordering(BuiltinOrder::Given).path_planner(false).subassemblies(false).build();
        let outcome = dfs.solve(&Problem::full(&Frame), &Budget::default());
        assert_eq!(outcome.status, Status::Found, "{:?}", outcome.status);
        let order: Vec<usize> = outcome.removals.iter().map(|s| s.part).collect();
        assert_eq!(order, [2, 3, 1]);
    }
}
