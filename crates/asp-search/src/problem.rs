//! What every planner gets (a [`Problem`] and a [`Budget`]) and gives back (a [`PlanOutcome`]).

use asp_geom::{CounterSnapshot, FeasibilityChecker, Motion, PartSet};
use std::time::{Duration, Instant};

/// A planning problem: the feasibility checker of an assembly and the state to take apart.
pub struct Problem<'a> {
    /// Removal tests and stability.
    pub checker: &'a dyn FeasibilityChecker,
    /// The start state (all parts, normally).
    pub start: PartSet,
    /// Called now and then with the search's progress (for progress bars).
    pub progress: Option<&'a (dyn Fn(&Progress) + Sync)>,
}

impl<'a> Problem<'a> {
    /// Take the whole assembly apart.
    pub fn full(checker: &'a dyn FeasibilityChecker) -> Self {
        Problem { checker, start: PartSet::full(checker.num_parts()), progress: None }
    }

    /// The parts of `state` that may be removed (present and not fixed).
    pub fn removable(&self, state: &PartSet) -> Vec<usize> {
        state.iter().filter(|&p| !self.checker.is_fixed(p)).collect()
    }

    /// Whether only fixed parts remain.
    pub fn is_goal(&self, state: &PartSet) -> bool {
        state.iter().all(|p| self.checker.is_fixed(p))
    }
}

/// How far the search may go. Exceeding it ends the search with
/// [`Status::BudgetExhausted`].
#[derive(Clone, Debug, Default)]
pub struct Budget {
    /// The most removal tests to run.
    pub max_tests: Option<u64>,
    /// The longest wall time.
    pub timeout: Option<Duration>,
}

impl Budget {
    /// Whether the budget is used up, given the tests run so far and the start time.
    pub fn exhausted(&self, tests: u64, started: Instant) -> bool {
        self.max_tests.is_some_and(|m| tests >= m) || self.timeout.is_some_and(|t| started.elapsed() >= t)
    }
}

/// A snapshot of a running search.
#[derive(Clone, Debug)]
pub struct Progress {
    /// Parts removed on the current branch.
    pub removed: usize,
    /// Parts to remove in all.
    pub total: usize,
    /// Removal tests so far.
    pub tests: u64,
}

/// One removal: which part, along which motion.
#[derive(Clone, Debug, PartialEq)]
pub struct Step {
    /// The part index.
    pub part: usize,
    /// Its removal motion (from the assembled pose outward).
    pub motion: Motion,
}

/// Why a part could not leave the state where the search got stuck.
#[derive(Clone, Debug, PartialEq)]
pub enum StuckReason {
    /// Every motion tried collides with these parts.
    Blocked(PartSet),
    /// It could leave, but these parts would lose their support.
    WouldLeaveUnsupported(PartSet),
    /// It could leave, but every state after that is a dead end.
    DeadEnd,
}

/// A part of the deepest dead-end state, with why it could not leave.
#[derive(Clone, Debug, PartialEq)]
pub struct Stuck {
    /// The part index.
    pub part: usize,
    /// Why it is stuck.
    pub reason: StuckReason,
}

/// How a search ended — a value, not an error.
#[derive(Clone, Debug, PartialEq)]
pub enum Status {
    /// A complete disassembly sequence was found.
    Found,
    /// The search space is exhausted: no sequence exists (under the tests used). `stuck` explains
    /// the deepest state reached.
    NoPlan {
        /// The parts of the deepest dead-end state and why each could not leave.
        stuck: Vec<Stuck>,
        /// That state.
        state: PartSet,
    },
    /// The budget ran out first.
    BudgetExhausted,
}

/// Measures of the search effort.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Stats {
    /// The checker's counters (tests, failures, path planner calls).
    pub counters: CounterSnapshot,
    /// Wall time of the search.
    pub seconds: f64,
    /// Disassembly states expanded.
    pub states_expanded: u64,
}

/// The result of [`crate::Planner::solve`].
#[derive(Clone, Debug)]
pub struct PlanOutcome {
    /// How the search ended.
    pub status: Status,
    /// The removals in disassembly order: the whole sequence when `status` is `Found`; otherwise
    /// the partial disassembly that got furthest (to the deepest dead end for `NoPlan`, the
    /// longest branch for `BudgetExhausted`).
    pub removals: Vec<Step>,
    /// The effort spent.
    pub stats: Stats,
}
