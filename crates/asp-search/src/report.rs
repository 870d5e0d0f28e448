//! The plan JSON: a versioned contract other tools read (documented in `docs/plan-format.md`).
//!
//! Lengths and positions are in the model's units; directions are unit vectors in the model
//! frame; `assembly_sequence` runs in assembly order (the removal order reversed, each motion
//! reversed into an insertion).

pub use crate::annotation::{ExtensionReport, RobotEntry, RobotReason, RobotRefusal, RobotStepEntry};
use crate::problem::{PlanOutcome, Status, Step, StopReason, StuckReason};
use crate::vocabulary::vocabulary;
use asp_geom::math::Pose;
use asp_geom::{Assembly, Motion, PartSet};
use serde::{Deserialize, Serialize};

mod build;
mod found;
mod parts;
mod precedence;
pub mod text;

use build::{complete, locked_cores};
pub use build::{insertion, removal_order};
pub use found::{BearingEntry, ComponentEntry, FitEntry, OverlapKindName, OverlapPair, OverlapsEntry};
pub use parts::{FaceEntry, PartEntry, SurfaceEntry, TessellationEntry};
pub use precedence::{PrecedenceEdge, PrecedenceEntry, PrecedenceReason, PrecedenceStability, PrecedenceStep};

/// The version of the plan format this build writes. Minor bumps add keys; major bumps change
/// or remove them.
pub const FORMAT_VERSION: &str = "1.15";

/// A whole plan file.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct PlanReport {
    /// [`FORMAT_VERSION`].
    pub format_version: String,
    /// The model file or folder, as given.
    pub model: String,
    /// The model's unit (`m`, `mm`, ...); every length below is in it.
    pub units: String,
    /// The up axis (`+z`, `+y`, ...); gravity points the other way.
    pub up: String,
    /// The contact tolerance used, in model units.
    pub tolerance: f64,
    /// How the search ended.
    pub status: PlanStatus,
    /// Every part of the model.
    pub parts: Vec<PartEntry>,
    /// One entry per non-fixed part, in assembly order (empty unless `found`).
    pub assembly_sequence: Vec<AssemblyStep>,
    /// Part indices in removal order (when not `found`: the partial disassembly that got
    /// furthest, to the deepest dead end or, when the budget ran out, the longest branch).
    pub disassembly_sequence: Vec<usize>,
    /// When not `found`: the parts that did come off, in assembly order onto the `remaining`
    /// parts, with their motions (as `assembly_sequence`). Since format 1.3.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub partial_assembly_sequence: Vec<AssemblyStep>,
    /// When not `found`: the parts still present where the partial disassembly stops (fixed
    /// parts included). Since format 1.3.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub remaining: Option<Vec<usize>>,
    /// The effort spent.
    pub stats: StatsEntry,
    /// For `no_plan`: the parts of the deepest dead-end state and what holds each.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub explanation: Vec<Explanation>,
    /// For `partial`: the parts that go in together because no plan took them apart, one
    /// entry per core (cores inside subassemblies included). Since format 1.8.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub locked_cores: Vec<LockedCore>,
    /// Pairs of parts that overlap in the input beyond the tolerance, and how their tests
    /// treated them (feasibility planning; absent when no pair overlaps). Since format 1.5.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub overlaps: Option<OverlapsEntry>,
    /// Every coaxial fit between two parts (a shaft of one in a hole of the other), classified,
    /// and the fasteners among the parts (feasibility planning; absent when there is none).
    /// Since format 1.10.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub fits: Vec<FitEntry>,
    /// The rolling bearings found in the model (balls captive between two rings), each planned
    /// as one unit (feasibility planning; absent when there is none). Since format 1.12.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub bearings: Vec<BearingEntry>,
    /// The components drawn as several interpenetrating solids of one product (format 1.14),
    /// each planned as one unit; empty when there is none.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub components: Vec<ComponentEntry>,
    /// Non-fatal problems found in the model, one line each.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub warnings: Vec<String>,
    /// Pareto runs: every non-dominated sequence with its objective vector.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pareto_front: Option<Vec<ParetoEntry>>,
    /// Optimising runs (`--objective`): the objectives, the result and the search's settings.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub optimisation: Option<OptimisationEntry>,
    /// Plans with a robot (`--robot`): the robot, its base and drop-off, the total path length.
    /// Since format 1.5.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub robot: Option<RobotEntry>,
    /// Plans made by the grid search of a voxel model (interlocking puzzles): its grid and
    /// effort. Since format 1.6.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub grid: Option<GridEntry>,
    /// Plans that follow the file's product tree (`--subassemblies from-file`): every
    /// subassembly of the file, outermost first, with its own plan on its base (whether or not
    /// the plan above could put it in as one unit). Since format 1.10.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub file_subassemblies: Vec<SubassemblyEntry>,
    /// With `precedence` (`asp plan --precedence`), found feasibility plans: the partial order
    /// of the assembly steps, its levels and critical path. Since format 1.12.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub precedence: Option<PrecedenceEntry>,
}

/// Parts that go in together as one unit because asp could not take them apart (format 1.8):
/// what stays of a subassembly whose own plan is not `found`.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct LockedCore {
    /// The subassembly's base (its step's part).
    pub base: usize,
    /// The parts of the core, by index (the base among them): the subassembly's parts its own
    /// plan does not take off.
    pub parts: Vec<usize>,
    /// Their names.
    pub names: Vec<String>,
    /// Why: the subassembly's own status (`no_plan`: nothing comes off, `explanation` says what
    /// holds what; `budget_exhausted`; `unplanned`: not tried).
    pub status: SubassemblyStatus,
    /// The subassembly's own explanation: the parts of its dead end and what holds each.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub explanation: Vec<Explanation>,
    /// Why it is locked: overlaps, blocking pairs, the grid planner, what `--overlaps lenient`
    /// would free (feasibility plans; format 1.9).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub why: Option<CoreWhy>,
}

/// The grid search behind a plan (format 1.6).
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct GridEntry {
    /// The size of a grid cell along x, y, z, model units.
    pub cell: [f64; 3],
    /// Why the grid search made the plan: `needs_moves` (parts must move in turn before
    /// anything can leave, so it ran first) or `fallback` (the depth-first search found no
    /// plan).
    pub reason: GridReason,
    /// States the breadth-first searches visited (every subassembly's included).
    pub states: u64,
    /// Moves before the model's first separation (the fewest possible).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub first_separation_moves: Option<usize>,
    /// Seconds of grid search.
    pub seconds: f64,
}

/// A move of some parts between removals (format 1.6).
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct MoveEntry {
    /// The parts that move together.
    pub parts: Vec<usize>,
    /// The translation, model units, model frame.
    pub translation: [f64; 3],
}

impl PlanReport {
    /// Recomputes `status` and `locked_cores` from the steps, after subassemblies' own plans
    /// were put into them (plans that follow the file's product tree): a `found` plan holding a
    /// subassembly not taken apart becomes `partial`. A core keeps the `why` of the core of
    /// `known` (or of this report) with the same base and parts.
    pub fn settle(&mut self, known: &[LockedCore]) {
        let steps = if self.assembly_sequence.is_empty() { &self.partial_assembly_sequence } else { &self.assembly_sequence };
        self.status = complete(self.status, steps);
        let parts = &self.parts;
        let name = |i: usize| parts.get(i).map_or_else(|| "ground".to_string(), |p| p.name.clone());
        let mut cores = if self.status == PlanStatus::Partial { locked_cores(steps, &name) } else { Vec::new() };
        for core in &mut cores {
            let same = |k: &&LockedCore| k.base == core.base && k.parts == core.parts;
            core.why = known.iter().chain(&self.locked_cores).find(same).and_then(|k| k.why.clone());
        }
        self.locked_cores = cores;
    }

    /// Attaches a robot's entries: each removal's entry to its assembly step (assembly order is
    /// the removal order reversed; the partial sequence when no plan was found).
    pub fn attach_robot(&mut self, robot: ExtensionReport) {
        let steps = if self.assembly_sequence.is_empty() { &mut self.partial_assembly_sequence } else { &mut self.assembly_sequence };
        let n = steps.len();
        for (k, entry) in robot.steps.into_iter().enumerate() {
            if k < n {
                steps[n - 1 - k].robot = entry;
            }
        }
        for (k, held) in robot.held.into_iter().enumerate() {
            if k < n {
                steps[n - 1 - k].held = held;
            }
        }
        self.robot = robot.entry;
    }
}

/// One assembly step.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct AssemblyStep {
    /// Part index (for a subassembly, its base).
    pub part: usize,
    /// Part name.
    pub name: String,
    /// How it goes in.
    pub motion: MotionEntry,
    /// When several parts go in together as one rigid subassembly (built beforehand): its parts
    /// and its own plan. Since format 1.4.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub subassembly: Option<Box<SubassemblyEntry>>,
    /// Plans with a robot: how the robot takes this part out. Since format 1.5.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub robot: Option<RobotStepEntry>,
    /// With `--grippers N`: the parts (at most N-1, already in place) held by another gripper
    /// or a fixture while this part goes in, because the state before it stands only so. Since
    /// format 1.5.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub held: Vec<usize>,
    /// Moves made after this step goes in, in order (assembly direction): parts already in
    /// place, this step's among them, slide into their next poses (grid plans of interlocking
    /// puzzles). The step's motion ends where these moves start from. Since format 1.6.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub moves: Vec<MoveEntry>,
}

/// A subassembly: parts that go in together, rigidly, as one step.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct SubassemblyEntry {
    /// The subassembly's name in the file's product tree, when the plan follows it
    /// (`--subassemblies from-file`). Since format 1.10.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    /// Every part of it, by index (the step's part, its base, among them).
    pub parts: Vec<usize>,
    /// How it is built on its base: `found` (its `assembly_sequence` builds it part by part),
    /// `partial` (its sequence is complete but holds a subassembly not taken apart; format 1.8),
    /// `no_plan` (it cannot be taken apart: a locked core, `explanation` says what holds
    /// what), `budget_exhausted`, or `unplanned` (not tried).
    pub status: SubassemblyStatus,
    /// Its own steps onto the base, in assembly order (for `no_plan` and `budget_exhausted`
    /// the parts that do come off, onto the parts that stay); steps may be subassemblies again.
    pub assembly_sequence: Vec<AssemblyStep>,
    /// For `no_plan`: the parts that cannot be separated and what holds each.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub explanation: Vec<Explanation>,
}

/// An insertion motion, ending in the part's assembled pose.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(tag = "kind", rename_all = "lowercase")]
pub enum MotionEntry {
    /// Move along `direction` (unit) by `distance` into place.
    Linear {
        /// Unit insertion direction.
        direction: [f64; 3],
        /// Travel in model units.
        distance: f64,
    },
    /// Follow `poses` (each `[x, y, z, qx, qy, qz, qw]`: the rigid transform applied to the
    /// part's assembled geometry; the last is the identity). Between waypoints `pivot` moves on
    /// a straight line and the rotation turns by slerp about it.
    Path {
        /// Waypoints.
        poses: Vec<[f64; 7]>,
        /// The point that moves straight between waypoints, model frame.
        pivot: [f64; 3],
    },
    /// Screw in along `direction` (unit, the part's symmetry axis through `axis_point`) by
    /// `distance`, turning about the axis as the thread requires (format 1.5).
    Screw {
        /// Unit insertion direction.
        direction: [f64; 3],
        /// Travel in model units.
        distance: f64,
        /// A point on the axis, model frame.
        axis_point: [f64; 3],
    },
}

/// Effort counters.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq, Default)]
pub struct StatsEntry {
    /// What the removal tests ran on: [`CHECKER_COLLISION_WORLD`] (exact sweeps on the
    /// collision world, the feasibility planner) or [`CHECKER_DISTANCE_MAPS`] (the optimiser; format 1.2).
    #[serde(default)]
    pub checker: Checker,
    /// Removal tests run.
    pub removal_tests: u64,
    /// Tests failed by collision.
    pub failed_collision: u64,
    /// Tests failed by stability.
    pub failed_gravity: u64,
    /// Path planner calls.
    pub path_planner_calls: u64,
    /// Wall time in seconds (the only field that differs between identical runs).
    pub seconds: f64,
    /// Where the wall time went: `load`, `world`, `search` (= `seconds`) and `path_planner`
    /// (part of `search`), seconds. Since format 1.4.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub timings: Option<Timings>,
    /// For `budget_exhausted`: `timeout`, `max_tests` or `interrupted` (Ctrl-C). Since 1.4.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stopped_by: Option<StopReason>,
}

/// Where a run's wall time went, in seconds.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq, Default)]
pub struct Timings {
    /// Reading the model file(s).
    pub load: f64,
    /// Building the collision world (meshes, directions, contacts, overlaps).
    pub world: f64,
    /// The search, from its start to its answer (removal tests included).
    pub search: f64,
    /// Path planner calls (part of `search`).
    pub path_planner: f64,
}

/// `stats.checker` of plans tested on the collision world.
pub const CHECKER_COLLISION_WORLD: Checker = Checker::CollisionWorld;
/// `stats.checker` of optimised plans, tested on distance maps.
pub const CHECKER_DISTANCE_MAPS: Checker = Checker::DistanceMaps;

/// Why one part could not leave the deepest dead-end state.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct Explanation {
    /// Part index.
    pub part: usize,
    /// Part name.
    pub name: String,
    /// `blocked` (every motion collides), `unsupported` (its removal leaves parts without
    /// support) or `dead_end` (it can leave, but nothing after that works).
    pub reason: ExplanationReason,
    /// The parts involved: blockers, or parts left unsupported (empty when `robot` says why).
    pub parts: Vec<NamedPart>,
    /// With a robot: the geometry lets the part out, but the robot cannot take it out, and why
    /// (`reason` is then `blocked` and `parts` empty). Since format 1.9.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub robot: Option<RobotRefusal>,
}

/// A part reference with its name (`ground` for the virtual ground plane).
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct NamedPart {
    /// Part index (the ground has index = number of parts).
    pub part: usize,
    /// Name.
    pub name: String,
}

/// A point of a Pareto front.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct ParetoEntry {
    /// Objective values, in the order of the run's objectives.
    pub objectives: Vec<f64>,
    /// The disassembly sequence (part indices in removal order).
    pub disassembly_sequence: Vec<usize>,
}

/// What an optimising run (`--objective`) searched for and found.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct OptimisationEntry {
    /// `mcts` (one objective) or `pareto_mcts`.
    pub method: OptimisationMethod,
    /// The objectives' names, in the order of every objective vector.
    pub objectives: Vec<String>,
    /// The objective vector of `assembly_sequence` (the best sequence, or the front's first).
    pub values: Vec<f64>,
    /// Pareto runs: the hypervolume of the front relative to `reference`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub hypervolume: Option<f64>,
    /// The hypervolume reference point (each objective's worst possible total).
    pub reference: Vec<f64>,
    /// Whether the whole search space was explored (the answer is then exact).
    pub exhaustive: bool,
    /// Episodes run.
    pub episodes: u64,
    /// MCTS iterations run.
    pub iterations: u64,
    /// Tree nodes built (all threads).
    pub tree_nodes: u64,
    /// The local search's share of the search's work (0: none; format 1.7).
    #[serde(default)]
    pub polish: f64,
    /// Sequences the local search added to the threads' answers (format 1.7).
    #[serde(default)]
    pub polished: u64,
    /// Iterations per search step.
    pub budget: usize,
    /// Threads.
    pub threads: usize,
    /// Seed.
    pub seed: u64,
    /// Distance map resolution `N_M`.
    pub resolution: usize,
    /// The distance maps' cap `d_max` in metres (objective values are in metres too:
    /// `access` and `pathlen` are sums of lengths, `dirchange` a count).
    pub d_max: f64,
    /// Seconds to build the distance maps.
    pub map_seconds: f64,
    /// Seconds of search.
    pub search_seconds: f64,
    /// The learned guidance the search ran with (absent: none, random rollouts and
    /// expansions). Since format 1.11.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub guidance: Option<GuidanceEntry>,
}

/// Which learned guidance an optimising run used (format 1.11).
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct GuidanceEntry {
    /// `q`: learned Q-functions, one per objective, their values multiplied.
    pub kind: String,
    /// The Q model files, one per objective in the objectives' order, as given.
    pub models: Vec<String>,
    /// Where the Q-values guided the search: `rollouts` (ε-greedy rollouts), `expansions`
    /// (they order expansions), `both`, `priors` (PUCT priors at expansions and a greedy
    /// seed of the local search; rollouts random) or `seed` (greedy seeds only, then vanilla).
    pub q_use: String,
    /// The probability of a random removal in guided rollouts (`rollouts` and `both` only).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub epsilon: Option<f64>,
}

vocabulary! {
    /// How a plan's search ended (`status`).
    PlanStatus {
        /// Every part gets its own motion: `assembly_sequence` builds the product part by part.
        Found => "found",
        /// `assembly_sequence` is complete, but some of its subassemblies could not be taken
        /// apart: their parts go in as one unit (`locked_cores`; format 1.8).
        Partial => "partial",
        /// No sequence exists under the model's tests: `explanation` says what holds what.
        NoPlan => "no_plan",
        /// The budget ran out first (`stats.stopped_by` says which).
        BudgetExhausted => "budget_exhausted",
    }
}

vocabulary! {
    /// How a subassembly is built on its base (`subassembly.status`).
    SubassemblyStatus {
        /// Its `assembly_sequence` builds it part by part.
        Found => "found",
        /// Its `assembly_sequence` is complete but holds a subassembly not taken apart.
        Partial => "partial",
        /// It cannot be taken apart (a locked core); `explanation` says what holds what.
        NoPlan => "no_plan",
        /// Its own search ran out of budget.
        BudgetExhausted => "budget_exhausted",
        /// Its own plan was not tried.
        Unplanned => "unplanned",
        /// Declared one unit (`--unit-group`): planned as one part on purpose, not taken apart
        /// (format 1.9).
        Unit => "unit",
    }
}

impl PlanStatus {
    /// Whether `assembly_sequence` holds a complete sequence (`found` or `partial`).
    pub fn has_sequence(self) -> bool {
        matches!(self, PlanStatus::Found | PlanStatus::Partial)
    }
}

impl From<PlanStatus> for SubassemblyStatus {
    fn from(s: PlanStatus) -> Self {
        match s {
            PlanStatus::Found => SubassemblyStatus::Found,
            PlanStatus::Partial => SubassemblyStatus::Partial,
            PlanStatus::NoPlan => SubassemblyStatus::NoPlan,
            PlanStatus::BudgetExhausted => SubassemblyStatus::BudgetExhausted,
        }
    }
}

vocabulary! {
    /// Why the grid search made a plan (`grid.reason`).
    GridReason {
        /// Parts must move in turn before anything can leave, so it ran first.
        NeedsMoves => "needs_moves",
        /// The depth-first search found no plan.
        Fallback => "fallback",
    }
}

vocabulary! {
    /// What the removal tests ran on (`stats.checker`).
    #[derive(Default)]
    Checker {
        /// Shape casts on the meshes (the feasibility planner).
        #[default]
        CollisionWorld => "collision_world",
        /// Distance maps (the optimiser; format 1.2).
        DistanceMaps => "distance_maps",
    }
}

vocabulary! {
    /// Why a part cannot leave the deepest dead end (`explanation[].reason`).
    ExplanationReason {
        /// Every motion collides (`parts` are the blockers).
        Blocked => "blocked",
        /// Its removal leaves `parts` without support.
        Unsupported => "unsupported",
        /// It can leave, but nothing after that works.
        DeadEnd => "dead_end",
    }
}

vocabulary! {
    /// The optimiser that made a plan (`optimisation.method`).
    OptimisationMethod {
        /// One objective.
        Mcts => "mcts",
        /// Several objectives: a Pareto front.
        ParetoMcts => "pareto_mcts",
    }
}

vocabulary! {
    /// Whether and why the grid planner ran on a locked core (`locked_cores[].why.grid.reason`,
    /// format 1.9).
    CoreGridReason {
        /// It ran on the model and every grid state it reached still holds the core together
        /// (the core cannot come apart by moves on the grid either).
        Stuck => "stuck",
        /// It ran, but its state budget or the time ran out first.
        Budget => "budget",
        /// Not tried: it was turned off (`--no-grid`).
        Off => "off",
        /// Not tried: the plan was made with a robot (the grid planner plans no arm).
        Robot => "robot",
        /// Not tried: the model has more parts than the grid planner takes (64).
        TooManyParts => "too_many_parts",
        /// Not tried: the model's parts are not all unions of cells of one common grid.
        NotOnGrid => "not_on_grid",
        /// Not tried: units were declared (`--unit-group`), which the grid planner does not keep
        /// together.
        UnitGroups => "unit_groups",
    }
}

vocabulary! {
    /// What the core's own plan on its base gives under `--overlaps lenient`
    /// (`locked_cores[].why.lenient.status`, format 1.9).
    LenientStatus {
        /// Not rerun: no two parts of the core overlap beyond the tolerance (or the plan's policy
        /// already tests them as `lenient` does), so its tests would be the same.
        Unchanged => "unchanged",
        /// Every part of the core comes off its base.
        Found => "found",
        /// A complete sequence, but a smaller core in it still goes in as one unit.
        Partial => "partial",
        /// Some parts (`frees`) or none come off before it is stuck again.
        NoPlan => "no_plan",
        /// The rerun's budget ran out (`frees` is what came off by then: a lower bound).
        BudgetExhausted => "budget_exhausted",
        /// The rerun could not be made (its checker could not be set up as the plan's).
        Unknown => "unknown",
    }
}

pub mod why;
pub use why::{CoreBlocker, CoreBlocks, CoreGrid, CoreLenient, CoreOverlap, CoreWhy};
