//! What every planner gets (a [`Problem`] and a [`Budget`]) and gives back (a [`PlanOutcome`]).

use crate::annotation::RobotRefusal;
use asp_geom::{CounterSnapshot, FeasibilityChecker, Motion, PartSet};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
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

/// A planner: takes a problem apart within a budget, and says how it ended in the one vocabulary
/// every planner shares ([`PlanOutcome`], [`Status`], [`StopReason`]); OMPL's `Planner::solve`
/// with its termination condition. A planner that searches a model of its own (the tree
/// searches on the distance maps, [`crate::mcts::MapPlanner`]; the grid planner on the voxel
/// view, [`crate::grid::GridPlanner`]) is made on that model, as an OMPL planner is made on its
/// space; the depth-first search ([`crate::Dfs`]) searches the problem's checker itself. Every
/// planner runs the same conformance tests through this trait (`tests/conformance`).
///
/// The contract, for every implementation:
/// - a `Found` outcome's removals take [`Problem::start`] down to its fixed parts, each a
///   removal the problem's checker allows (the conformance tests re-check them on the
///   geometry);
/// - a budget already spent when the search starts, or spent before an answer, ends it
///   [`Status::BudgetExhausted`] with [`Stats::stopped_by`] saying which limit
///   ([`StopReason::Interrupted`] for a cancelled token);
/// - the same planner on the same problem gives the same outcome (its seed is a setting),
///   unless wall time or a cancel ends it.
///
/// Errors are for what is not an outcome: settings the planner cannot run with, a problem its
/// model does not describe, a plug-in that failed.
pub trait Planner {
    /// A short name for reports.
    fn name(&self) -> &'static str;
    /// Searches for a disassembly sequence of `problem` within `budget`.
    fn solve(&self, problem: &Problem, budget: &Budget) -> crate::Result<PlanOutcome>;
}

/// Stops running searches from another thread (Ctrl-C from Python, a caller's deadline): each
/// search thread finishes its current iteration and the search returns what it has found, as
/// with a time limit ([`crate::SearchStats::stopped`]). Clones share the token.
#[derive(Clone, Debug, Default)]
pub struct StopToken(Arc<AtomicBool>);

impl StopToken {
    /// A token that has not been stopped.
    pub fn new() -> Self {
        StopToken::default()
    }

    /// Asks every search holding the token to stop.
    pub fn stop(&self) {
        self.0.store(true, Ordering::Relaxed);
    }

    /// Whether [`StopToken::stop`] was called.
    #[inline]
    pub fn is_stopped(&self) -> bool {
        self.0.load(Ordering::Relaxed)
    }
}

/// How far a search may go: the termination condition every planner shares (OMPL's
/// `PlannerTerminationCondition`). Each count is kept by the planners that have the thing it
/// counts (— : not counted, as if nothing of it were spent):
///
/// | limit | [`crate::Dfs`] | [`crate::Mcts`], [`crate::ParetoMcts`] | the grid planner |
/// |---|---|---|---|
/// | `max_tests` | removal tests | — (its map lookups are no checker's tests) | — (it runs no tests) |
/// | `timeout` | yes | yes | yes |
/// | `max_episodes` | — | episodes | — |
/// | `max_states` | states expanded | — (its node cap is no stop) | states visited |
/// | `cancel` | yes | yes | yes |
///
/// So a zero limit of any count, a cancelled token or no time is spent before the start for
/// every planner. Reaching a limit before an answer ends the search with
/// [`Status::BudgetExhausted`] and [`Stats::stopped_by`] saying which.
#[derive(Clone, Debug, Default)]
pub struct Budget {
    /// The most removal tests to run.
    pub max_tests: Option<u64>,
    /// The longest wall time.
    pub timeout: Option<Duration>,
    /// The most episodes of a tree search (over all its threads).
    pub max_episodes: Option<u64>,
    /// The most search states to expand or visit.
    pub max_states: Option<u64>,
    /// Stopped from outside (a Ctrl-C handler, a Python signal, a caller's deadline) to end the
    /// search now; it then ends like an exhausted budget, with the best result so far.
    pub cancel: Option<StopToken>,
}

/// What a search has spent of its [`Budget`] so far (wall time aside: the budget measures it
/// from the search's start).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Spent {
    /// Removal tests run.
    pub tests: u64,
    /// Episodes finished.
    pub episodes: u64,
    /// States expanded or visited.
    pub states: u64,
}

impl Spent {
    /// Only `tests` removal tests.
    pub fn tests(tests: u64) -> Spent {
        Spent { tests, ..Spent::default() }
    }
}

/// Why a search stopped before it could finish (in the plan JSON by [`StopReason::as_str`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum StopReason {
    /// The wall-time budget ran out.
    Timeout,
    /// The removal-test budget ran out.
    MaxTests,
    /// It was cancelled ([`Budget::cancel`], e.g. Ctrl-C).
    Interrupted,
    /// The episode budget of a tree search ran out ([`Budget::max_episodes`]; `asp plan` sets
    /// none, so no plan file says it).
    MaxEpisodes,
    /// The state budget ran out ([`Budget::max_states`]; `asp plan` sets none, so no plan
    /// file says it).
    MaxStates,
}

impl StopReason {
    /// The name in the plan JSON (`timeout`, `max_tests`, `interrupted`, `max_episodes`,
    /// `max_states`).
    pub fn as_str(self) -> &'static str {
        match self {
            StopReason::Timeout => "timeout",
            StopReason::MaxTests => "max_tests",
            StopReason::Interrupted => "interrupted",
            StopReason::MaxEpisodes => "max_episodes",
            StopReason::MaxStates => "max_states",
        }
    }
}

impl Budget {
    /// Whether the budget is used up, given what was spent and the start time.
    pub fn exhausted(&self, spent: Spent, started: Instant) -> bool {
        self.stop_reason(spent, started).is_some()
    }

    /// Why the budget is used up, if it is (a cancel first, then the counted limits, then the
    /// time).
    pub fn stop_reason(&self, spent: Spent, started: Instant) -> Option<StopReason> {
        if self.cancel.as_ref().is_some_and(StopToken::is_stopped) {
            Some(StopReason::Interrupted)
        } else if self.max_tests.is_some_and(|m| spent.tests >= m) {
            Some(StopReason::MaxTests)
        } else if self.max_episodes.is_some_and(|m| spent.episodes >= m) {
            Some(StopReason::MaxEpisodes)
        } else if self.max_states.is_some_and(|m| spent.states >= m) {
            Some(StopReason::MaxStates)
        } else if self.timeout.is_some_and(|t| started.elapsed() >= t) {
            Some(StopReason::Timeout)
        } else {
            None
        }
    }

    /// The budget left after `spent` and the time since `started` (for a search that
    /// continues another's work, e.g. a subassembly's own plan).
    pub fn remaining(&self, spent: Spent, started: Instant) -> Budget {
        Budget {
            max_tests: self.max_tests.map(|m| m.saturating_sub(spent.tests)),
            timeout: self.timeout.map(|t| t.saturating_sub(started.elapsed())),
            max_episodes: self.max_episodes.map(|m| m.saturating_sub(spent.episodes)),
            max_states: self.max_states.map(|m| m.saturating_sub(spent.states)),
            cancel: self.cancel.clone(),
        }
    }

    /// Whether a cancel token is set and stopped.
    pub fn cancelled(&self) -> bool {
        self.cancel.as_ref().is_some_and(StopToken::is_stopped)
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

/// One removal: which part (or rigid subassembly), along which motion.
#[derive(Clone, Debug, PartialEq)]
pub struct Step {
    /// The part index (for a subassembly, its base: the part the others are put onto).
    pub part: usize,
    /// Its removal motion (from the assembled pose outward).
    pub motion: Motion,
    /// When several parts leave together as one rigid subassembly: which, and how the
    /// subassembly itself comes apart.
    pub group: Option<Box<Subassembly>>,
    /// Moves of parts made before this removal, in order (grid plans of interlocking puzzles:
    /// pieces slide a few cells before anything can leave). Moved parts stay where they end;
    /// the removal starts from the moved pose, and a moved part removed later starts from
    /// where its moves left it. Empty for plain removals.
    pub moves: Vec<GroupMove>,
}

/// A rigid translation of some present parts, made between removals.
#[derive(Clone, Debug, PartialEq)]
pub struct GroupMove {
    /// The parts that move together.
    pub parts: PartSet,
    /// The translation, world frame, metres.
    pub translation: asp_geom::math::Vec3,
}

impl Step {
    /// A single part's removal.
    pub fn single(part: usize, motion: Motion) -> Step {
        Step { part, motion, group: None, moves: Vec::new() }
    }

    /// The parts that leave in this step (the part, or every part of the subassembly).
    pub fn parts(&self) -> Vec<usize> {
        match &self.group {
            Some(g) => g.parts.iter().collect(),
            None => vec![self.part],
        }
    }
}

/// A group of parts that leaves as one rigid body (built beforehand as a subassembly).
#[derive(Clone, Debug, PartialEq)]
pub struct Subassembly {
    /// Every part of the subassembly (the step's part, its base, among them).
    pub parts: PartSet,
    /// The subassembly's own disassembly on its base (the step's part as the only fixed part):
    /// `Found` when it can be built part by part; otherwise it cannot be taken apart (a locked
    /// core: its explanation says what holds what), or was not planned (`None`: the checker
    /// cannot plan subassemblies, or the budget ran out first).
    pub plan: Option<PlanOutcome>,
    /// A unit the user declared ([`crate::units`]): planned as one part on purpose, never taken
    /// apart (`plan` is `None`).
    pub unit: bool,
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
    /// The geometry lets it leave, but a robot cannot take it out, and why. The search itself
    /// saw a collision with every other present part (any of them may be what the arm hits); a
    /// [`crate::CheckerExtension`] puts the robot's reason in its place in the outcome.
    Refused(RobotRefusal),
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
    /// Wall time spent in path planner calls (part of `seconds`).
    pub path_planner_seconds: f64,
    /// Why the search stopped early (with [`Status::BudgetExhausted`]).
    pub stopped_by: Option<StopReason>,
}

impl Stats {
    /// Adds the effort of `earlier`, a search that ran on the problem before this one (the
    /// depth-first search before the grid planner's fallback): its counters, time, path planner
    /// time and states. Not why it stopped: how this search ended is the outcome's.
    pub fn add_effort(&mut self, earlier: &Stats) {
        let (c, e) = (&mut self.counters, &earlier.counters);
        c.removal_tests += e.removal_tests;
        c.failed_collision += e.failed_collision;
        c.failed_gravity += e.failed_gravity;
        c.path_planner_calls += e.path_planner_calls;
        self.seconds += earlier.seconds;
        self.states_expanded += earlier.states_expanded;
        self.path_planner_seconds += earlier.path_planner_seconds;
    }
}

/// The result of [`Planner::solve`].
#[derive(Clone, Debug, PartialEq)]
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

impl PlanOutcome {
    /// The outcome of a search whose budget ran out (by `reason`) before it removed anything.
    pub fn stopped_before_start(reason: StopReason) -> PlanOutcome {
        PlanOutcome { status: Status::BudgetExhausted, removals: Vec::new(), stats: Stats { stopped_by: Some(reason), ..Stats::default() } }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_budget_names_the_limit_that_is_spent_a_cancel_first() {
        let started = Instant::now();
        let token = StopToken::new();
        let budget = Budget {
            max_tests: Some(10),
            timeout: Some(Duration::from_secs(3600)),
            max_episodes: Some(5),
            max_states: Some(7),
            cancel: Some(token.clone()),
        };
        let spent = |tests, episodes, states| Spent { tests, episodes, states };
        assert_eq!(budget.stop_reason(spent(9, 4, 6), started), None);
        assert_eq!(budget.stop_reason(spent(10, 4, 6), started), Some(StopReason::MaxTests));
        assert_eq!(budget.stop_reason(spent(9, 5, 6), started), Some(StopReason::MaxEpisodes));
        assert_eq!(budget.stop_reason(spent(9, 4, 7), started), Some(StopReason::MaxStates));
        assert_eq!(budget.stop_reason(spent(10, 5, 7), started), Some(StopReason::MaxTests));
        token.stop();
        assert_eq!(budget.stop_reason(spent(10, 5, 7), started), Some(StopReason::Interrupted));
        assert!(budget.cancelled());
        let no_time = Budget { timeout: Some(Duration::ZERO), ..Budget::default() };
        assert_eq!(no_time.stop_reason(Spent::default(), started), Some(StopReason::Timeout));
        assert_eq!(Budget::default().stop_reason(spent(u64::MAX, u64::MAX, u64::MAX), started), None);
    }

    #[test]
    fn the_remaining_budget_subtracts_what_was_spent_and_keeps_the_token() {
        let token = StopToken::new();
        let budget =
            Budget { max_tests: Some(10), max_episodes: Some(5), max_states: Some(7), cancel: Some(token.clone()), ..Budget::default() };
        let left = budget.remaining(Spent { tests: 4, episodes: 6, states: 2 }, Instant::now());
        assert_eq!((left.max_tests, left.max_episodes, left.max_states, left.timeout), (Some(6), Some(0), Some(5), None));
        token.stop();
        assert!(left.cancelled(), "the remaining budget shares the token");
    }

    #[test]
    fn effort_adds_up_but_not_the_reason_to_stop() {
        let counters = |t| CounterSnapshot { removal_tests: t, failed_collision: t, failed_gravity: 1, path_planner_calls: 2 };
        let mut later = Stats { counters: counters(3), seconds: 1.0, states_expanded: 4, path_planner_seconds: 0.5, stopped_by: None };
        let earlier = Stats {
            counters: counters(5),
            seconds: 2.0,
            states_expanded: 6,
            path_planner_seconds: 1.0,
            stopped_by: Some(StopReason::Timeout),
        };
        later.add_effort(&earlier);
        assert_eq!(
            later,
            Stats {
                counters: CounterSnapshot { removal_tests: 8, failed_collision: 8, failed_gravity: 2, path_planner_calls: 4 },
                seconds: 3.0,
                states_expanded: 10,
                path_planner_seconds: 1.5,
                stopped_by: None,
            }
        );
    }
}
