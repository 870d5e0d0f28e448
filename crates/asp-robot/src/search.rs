//! The robot in the planners, through their seams:
//! * the depth-first search: [`CellSetup`] is a [`CheckerExtension`] that wraps the checker in
//!   a [`HoldingChecker`] (`--grippers`) and a [`RobotChecker`] (a removal must also be one the
//!   robot can carry out);
//! * the optimiser: [`RobotSetup`] is an [`MdpExtension`] with the filter `robot` (reasons
//!   `blocked`, `no reachable grasp`, `no path`) and the objective `robot-path` (reward: minus
//!   the robot's path length in metres, eq. 5.8). The filter asks only whether a path exists
//!   ([`RobotModel::feasible`]: the first path found, the same verdict as the full plan); the
//!   objective plans the shortest for the step taken. Expansion and replay plan `k` times
//!   ([`RemovalConfig::replans`]) and keep the shortest; simulation plans once (5.4.2) and takes
//!   the first path found, the one the filter found when it admitted the step (rollouts ask the
//!   filter lazily, [`asp_search::mcts`]). Verdicts are remembered per state and part and
//!   carry over between numbers of replans ([`RobotModel`]). The lift direction is the
//!   distance maps' straight-line removal direction of the step.
//!
//! Both describe their plan's steps for the plan JSON ([`ExtensionReport`]).

use std::collections::HashMap;
use std::sync::{Arc, Mutex};

use asp_geom::distmap::{DistanceMaps, MapState};
use asp_geom::math::{Pose, Vec3};
use asp_geom::{Assembly, Checker, FeasibilityChecker, Motion, PartSet, World, WorldConfig};
use asp_search::extension::{MdpExtension, ModelContext};
use asp_search::mdp::{ActionFilter, Verdict};
use asp_search::objective::Objective;
use asp_search::report::{ExtensionReport, RobotEntry, RobotReason, RobotRefusal, RobotStepEntry};
use asp_search::step::{StepContext, StepKind};
use asp_search::CheckerExtension;
use asp_search::{Mdp, PathLength, PlanOutcome, SearchError, Status, StuckReason};

use crate::checker::{HoldingChecker, RobotChecker};
use crate::removal::{RemovalConfig, RemovalPlanner, RobotCell, RobotFailure, RobotRemoval};
use crate::reuse::PathStore;
use crate::robot::Robot;

/// The objective name of the robot's path length.
pub const ROBOT_PATH: &str = "robot-path";

/// A robot, where it stands, and how it plans: what `--robot` sets up.
#[derive(Clone, Debug)]
pub struct RobotSetup {
    /// The robot (its base pose is set per model from `base`).
    pub robot: Robot,
    /// The base position in the model's units, model frame (default: [`RobotCell::for_assembly`]).
    pub base: Option<Vec3>,
    /// The drop-off point in the model's units, model frame (default: [`RobotCell::for_assembly`]).
    pub drop_off: Option<Vec3>,
    /// The removal test's settings (`k` is `replans`).
    pub config: RemovalConfig,
}

impl RobotSetup {
    /// The default panda with default settings.
    pub fn panda() -> Self {
        RobotSetup { robot: Robot::panda(), base: None, drop_off: None, config: RemovalConfig::default() }
    }

    /// The robot cell on `assembly` (the positions converted to metres).
    pub fn cell(&self, assembly: &Assembly) -> RobotCell {
        let m = assembly.units.metres as f32;
        RobotCell::for_assembly(assembly, self.robot.clone(), self.base.map(|b| b * m), self.drop_off.map(|d| d * m))
    }
}

/// The report entries of a robot: the cell and one entry per step (`None` where not planned).
pub fn robot_report(assembly: &Assembly, cell: &RobotCell, steps: Vec<Option<RobotRemoval>>) -> ExtensionReport {
    let u = |m: f64| assembly.units.from_metres(m);
    let v3 = |v: Vec3| [u(v.x as f64), u(v.y as f64), u(v.z as f64)];
    let pose7 = |p: &Pose| {
        let t = v3(p.translation);
        let q = p.rotation;
        [t[0], t[1], t[2], q.x as f64, q.y as f64, q.z as f64, q.w as f64]
    };
    let mut total = 0.0;
    let steps = steps
        .into_iter()
        .map(|s| {
            s.map(|r| {
                total += r.length;
                RobotStepEntry {
                    grasp: pose7(&Pose::from_parts(r.grasp.position, r.grasp.orientation)),
                    grasp_width: u(r.grasp.width as f64),
                    gripper_path: r.gripper_path.iter().map(|p| v3(*p)).collect(),
                    joint_trajectory: r.joints.clone(),
                    path_length: u(r.length),
                }
            })
        })
        .collect();
    ExtensionReport {
        entry: Some(RobotEntry {
            name: cell.robot.name.clone(),
            source: cell.robot.source.display().to_string(),
            base: pose7(&cell.robot.base_pose()),
            drop_off: v3(cell.drop_off),
            joints: cell.robot.movable_joints().map(|j| j.name.clone()).collect(),
            total_path_length: u(total),
        }),
        steps,
        held: Vec::new(),
    }
}

/// What the depth-first search gets from `--robot` and `--grippers`: a robot, held parts, or
/// both (held parts are tested first, the robot on what they admit).
#[derive(Clone, Debug)]
pub struct CellSetup {
    /// The robot, if any.
    pub robot: Option<RobotSetup>,
    /// Grippers in all (`--grippers`, default 1: nothing is held).
    pub grippers: usize,
}

impl CheckerExtension for CellSetup {
    fn checks_arm(&self) -> bool {
        self.robot.is_some()
    }

    fn solve(
        &self,
        checker: &Checker,
        seed: u64,
        search: &mut dyn FnMut(&dyn FeasibilityChecker) -> asp_search::Result<PlanOutcome>,
    ) -> asp_search::Result<(PlanOutcome, Option<ExtensionReport>)> {
        let world = checker.world();
        let holding = (self.grippers >= 2).then(|| HoldingChecker::new(checker, self.grippers));
        let base: &dyn FeasibilityChecker = match &holding {
            Some(h) => h,
            None => checker,
        };
        let robot = self.robot.as_ref().map(|r| {
            let cell = r.cell(world.assembly());
            let planner = RemovalPlanner::new(world, cell.clone(), r.config.clone());
            (cell, RobotChecker::new(base, planner, seed, r.config.replans))
        });
        let mut outcome = match &robot {
            Some((_, rc)) => search(rc)?,
            None => search(base)?,
        };
        if let Some((_, rc)) = &robot {
            explain_refusals(&mut outcome, rc, world.assembly());
        }
        let mut state = PartSet::full(checker.num_parts());
        let (mut steps, mut held) = (Vec::new(), Vec::new());
        for s in &outcome.removals {
            steps.push(robot.as_ref().and_then(|(_, rc)| rc.removal(s.part, &state)));
            held.push(holding.as_ref().map_or_else(Vec::new, |h| h.held(&PartSet::from_indices(checker.num_parts(), s.parts()), &state)));
            for p in s.parts() {
                state.remove(p);
            }
        }
        let mut report = match &robot {
            Some((cell, _)) => robot_report(world.assembly(), cell, steps),
            None => ExtensionReport::default(),
        };
        report.held = held;
        Ok((outcome, Some(report)))
    }
}

/// Puts the robot's reasons into a `no_plan` outcome: each part of the dead end that the search
/// saw blocked by every other part because the robot refused it (the geometry lets it out)
/// gets the robot's reason instead ([`StuckReason::Refused`]); a part the geometry blocks keeps
/// its blockers. Every such part was tested in the dead-end state itself: bookkeeping skips a
/// test only in a state holding all the recorded blockers, and a refusal's blockers are every
/// other part of its state, so the skipping state would hold the refusing one, which is then
/// no smaller and no deeper dead end.
fn explain_refusals(outcome: &mut PlanOutcome, robot: &RobotChecker<'_>, assembly: &Assembly) {
    let Status::NoPlan { stuck, state } = &mut outcome.status else { return };
    for s in stuck.iter_mut() {
        if !matches!(s.reason, StuckReason::Blocked(_)) {
            continue;
        }
        if let Some(f) = robot.refusal(s.part, state) {
            let mut refusal = f.refusal(assembly);
            if matches!(f, RobotFailure::NoReachableGrasp { grasps: 1.., .. }) {
                if let Some(more) = grasp_detail(robot, s.part, state, assembly) {
                    refusal.detail.push_str(&more);
                }
            }
            s.reason = StuckReason::Refused(refusal);
        }
    }
}

/// More words for a part refused for want of a reachable grasp, lifted up (`None` when the
/// lift up is blocked: the refusal lifted along another direction): which present parts the
/// gripper alone collides with at how many of its grasps (the most first, three by name),
/// how many grasps one part alone blocks (taken out first, it frees them), how many the gripper
/// alone fits at (the arm then does not reach them or collides on the way), and that a second
/// gripper does not change it (`--grippers 2` holds parts in place; it moves none, and the
/// arm's grasps stay where they are).
fn grasp_detail(robot: &RobotChecker<'_>, part: usize, state: &PartSet, assembly: &Assembly) -> Option<String> {
    let planner = robot.planner();
    let up = planner.lift_direction(part, state, None).ok()?;
    let blockers = planner.grasp_blockers(part, state, up);
    let name = |p: usize| assembly.parts.get(p).map_or_else(|| format!("part {p}"), |p| format!("'{}'", p.name));
    let mut by: Vec<(usize, usize, usize)> = Vec::new(); // part, grasps it meets, grasps it alone blocks
    for b in blockers.iter().flatten() {
        for &o in b {
            match by.iter_mut().find(|e| e.0 == o) {
                Some(e) => e.1 += 1,
                None => by.push((o, 1, 0)),
            }
        }
        if let [only] = b[..] {
            if let Some(e) = by.iter_mut().find(|e| e.0 == only) {
                e.2 += 1;
            }
        }
    }
    by.sort_by(|a, b| b.1.cmp(&a.1).then(a.0.cmp(&b.0)));
    let colliding = blockers.iter().filter(|b| b.is_some()).count();
    let fits = blockers.len() - colliding;
    let mut out = String::new();
    if colliding > 0 {
        let named: Vec<String> = by.iter().take(3).map(|&(o, n, _)| format!("{} at {n}", name(o))).collect();
        out.push_str(&format!("; lifted up, the gripper alone collides at {colliding} of {} grasps", blockers.len()));
        if !named.is_empty() {
            out.push_str(&format!(": with {}", named.join(", ")));
            if by.len() > 3 {
                out.push_str(&format!(" and {} more parts", by.len() - 3));
            }
        }
        let alone: Vec<String> = by.iter().filter(|e| e.2 > 0).take(3).map(|&(o, _, k)| format!("{} alone blocks {k}", name(o))).collect();
        if !alone.is_empty() {
            out.push_str(&format!(" ({}: taken out first, it frees them)", alone.join(", ")));
        }
    }
    if fits > 0 {
        out.push_str(&format!("; at {fits} the gripper alone fits and the arm does not reach it or collides on the way"));
    }
    out.push_str("; a second gripper (--grippers 2) does not change this: it holds parts in place and moves none");
    Some(out)
}

impl RobotFailure {
    /// The plan JSON's words for this failure (`explanation[].robot`), parts of `assembly` by
    /// name.
    pub fn refusal(&self, assembly: &Assembly) -> RobotRefusal {
        let name = |p: usize| assembly.parts.get(p).map_or_else(|| "the ground".to_string(), |p| format!("'{}'", p.name));
        let (reason, detail) = match *self {
        RobotFailure::Blocked { by: Some(by) } => (RobotReason::BlockedLift, format!("the lift along its removal direction hits {}", name(by))),
        RobotFailure::Blocked { by: None } => {
            (RobotReason::NoStraightLift, "it leaves only along a path of several moves; the arm lifts along a straight line".to_string())
        }
        RobotFailure::NoReachableGrasp { grasps: 0, .. } => (RobotReason::NoReachableGrasp, "no grasp fits the gripper".to_string()),
        RobotFailure::NoReachableGrasp { grasps, unreachable, colliding } => {
            (RobotReason::NoReachableGrasp, format!("of {grasps} grasps {unreachable} are out of reach, {colliding} collide"))
        }
        RobotFailure::NoPath { drop_off_blocked, grasps_tried: 0, .. } => (
            RobotReason::NoDropOff,
            format!("with none of its {drop_off_blocked} reachable grasps can the part be put down at the drop-off"),
        ),
        RobotFailure::NoPath { reachable, drop_off_blocked, grasps_tried } => (
            RobotReason::NoPath,
            format!(
                "{reachable} reachable grasps, {drop_off_blocked} cannot put the part down at the drop-off, no collision-free path from the other {grasps_tried}"
            ),
        ),
    };
        RobotRefusal { reason, detail }
    }
}

/// A state (bitset words), a part, the replans and whether only the first path counts.
type PlanKey = (Vec<u64>, usize, usize, bool);

/// The robot on one model for the optimiser: its planner on a collision world of the model and
/// what it has learnt so far, by state and part: the plans made (by number of replans) and the
/// verdicts of first paths.
///
/// Verdicts carry over between numbers of replans `k`: the `k` plans of a grasp use the seeds
/// of the first `k` of any larger number, so a path found with `k` replans is found with more,
/// and a part with no path after `k` replans has none after fewer; `blocked` and `no reachable
/// grasp` do not depend on `k` at all. A simulation (one plan) therefore reuses what an
/// expansion (`k` plans) learnt and the other way round, and a full plan's verdict is the first
/// path's ([`RemovalPlanner::removable`]).
///
/// Across states: each search thread keeps a [`PathStore`] of the paths and monotone
/// failures it found, each with its state. A rollout step takes a kept path whose state holds
/// every present part (collision-free there; its length an upper bound) or a kept failure from
/// a subset of the state before it plans; an expansion plans only for a path shorter than a
/// kept one ([`RemovalPlanner::plan_below`]) and keeps the kept one when none is. Replays plan
/// each state on its own, the same in every search. The stores are per thread (and emptied
/// when a search is built, [`RobotModel::new_search`]), so a search's answer depends on its
/// seed and thread count only.
#[derive(Debug)]
pub struct RobotModel {
    planner: RemovalPlanner<Arc<World>>,
    replans: usize,
    assembly: Arc<Assembly>,
    /// Plans by state, part, replans and whether it is the first path found (simulation).
    cache: Mutex<HashMap<PlanKey, Result<RobotRemoval, RobotFailure>>>,
    /// Per (state, part): what is known of its feasibility.
    verdicts: Mutex<HashMap<(Vec<u64>, usize), Known>>,
    /// Per search thread: what it learnt, reused in its later states ([`PathStore`]).
    threads: Mutex<HashMap<std::thread::ThreadId, Arc<Mutex<ThreadStore>>>>,
}

/// What is known of one step's feasibility.
#[derive(Clone, Debug, Default)]
struct Known {
    /// The fewest replans with which a path was found.
    path_with: Option<usize>,
    /// The most replans with which none was found, and why.
    failed_with: Option<(usize, RobotFailure)>,
}

impl Known {
    /// The verdict for `replans` plans per grasp, when it follows from what is known.
    fn verdict(&self, replans: usize) -> Option<Result<(), RobotFailure>> {
        if self.path_with.is_some_and(|k| k <= replans) {
            return Some(Ok(()));
        }
        match &self.failed_with {
            Some((_, f)) if !matches!(f, RobotFailure::NoPath { .. }) => Some(Err(f.clone())),
            Some((k, f)) if *k >= replans => Some(Err(f.clone())),
            _ => None,
        }
    }

    fn learn(&mut self, replans: usize, r: Result<(), &RobotFailure>) {
        match r {
            Ok(()) => self.path_with = Some(self.path_with.map_or(replans, |k| k.min(replans))),
            Err(f) => {
                if self.failed_with.as_ref().is_none_or(|(k, _)| *k < replans) {
                    self.failed_with = Some((replans, f.clone()));
                }
            }
        }
    }
}

/// A state (bitset words) and a part.
type StepKey = (Vec<u64>, usize);

/// One search thread's store, and the step its filter checked last in a rollout (the
/// rollout's reward plans the same step next).
#[derive(Debug, Default)]
struct ThreadStore {
    store: PathStore,
    last: Option<(StepKey, Result<RobotRemoval, RobotFailure>)>,
}

impl RobotModel {
    fn replans(&self, step: &StepContext<'_, '_>) -> usize {
        if step.kind() == StepKind::Simulation {
            1
        } else {
            self.replans.max(1)
        }
    }

    /// The verdict known for `part` in the state `present` with `replans` plans per grasp.
    fn known(&self, present: &[u64], part: usize, replans: usize) -> Option<Result<(), RobotFailure>> {
        self.verdicts.lock().expect("not poisoned").get(&(present.to_vec(), part)).and_then(|k| k.verdict(replans))
    }

    /// Remembers the verdict of planning `part` in the state `present` with `replans` plans.
    fn learn(&self, present: &[u64], part: usize, replans: usize, r: Result<(), &RobotFailure>) {
        self.verdicts.lock().expect("not poisoned").entry((present.to_vec(), part)).or_default().learn(replans, r);
    }

    /// Forgets what the search threads learnt ([`PathStore`]): a new search starts from
    /// nothing, so its answer depends on its seed alone. The plans and verdicts of single
    /// states (the same in every search) are kept.
    pub fn new_search(&self) {
        self.threads.lock().expect("not poisoned").clear();
    }

    /// This thread's store.
    fn thread_store(&self) -> Arc<Mutex<ThreadStore>> {
        self.threads.lock().expect("not poisoned").entry(std::thread::current().id()).or_default().clone()
    }

    /// Paths reused and failures reused so far (all threads of the current search).
    pub fn reuse_hits(&self) -> (u64, u64) {
        self.threads.lock().expect("not poisoned").values().fold((0, 0), |(a, b), t| {
            let (x, y) = t.lock().expect("not poisoned").store.hits();
            (a + x, b + y)
        })
    }

    /// The plan of `step` as a function of its state alone, for `replans` plans per grasp
    /// (`first`: the first path found, [`RemovalPlanner::removable`]; else the shortest,
    /// [`RemovalPlanner::plan`]), shared by all threads.
    fn state_plan(&self, step: &mut StepContext<'_, '_>, replans: usize, first: bool) -> Result<RobotRemoval, RobotFailure> {
        let present = step.present();
        let key = (present.words().to_vec(), step.part(), replans, first);
        if let Some(r) = self.cache.lock().expect("not poisoned").get(&key) {
            return r.clone();
        }
        let known = self.known(&key.0, key.1, replans);
        let r = match (known, step.motion()) {
            (Some(Err(f)), _) => Err(f),
            (_, Some(Motion::Linear { direction, .. })) if first => {
                self.planner.removable(step.part(), &present, direction, step.seed(), replans)
            }
            (_, Some(Motion::Linear { direction, .. })) => self.planner.plan(step.part(), &present, direction, step.seed(), replans),
            _ => Err(RobotFailure::Blocked { by: None }),
        };
        self.learn(&key.0, key.1, replans, r.as_ref().map(|_| ()));
        self.cache.lock().expect("not poisoned").insert(key, r.clone());
        r
    }

    /// The lift of `step` (up when free, else the removal direction; see
    /// [`RemovalPlanner::lift_direction`]).
    fn lift(&self, step: &mut StepContext<'_, '_>) -> Result<Vec3, RobotFailure> {
        match step.motion() {
            Some(Motion::Linear { direction, .. }) => self.planner.lift_direction(step.part(), &step.present(), Some(direction)),
            _ => Err(RobotFailure::Blocked { by: None }),
        }
    }

    /// A rollout step with this thread's store: a kept path valid in the state, else a kept
    /// failure that holds in it, else the state's own first path (kept in the store).
    fn simulation(&self, step: &mut StepContext<'_, '_>) -> Result<RobotRemoval, RobotFailure> {
        let present = step.present();
        let key = (present.words().to_vec(), step.part());
        let store = self.thread_store();
        let mut t = store.lock().expect("not poisoned");
        if let Some((k, r)) = &t.last {
            if *k == key {
                return r.clone();
            }
        }
        if let Some(r) = t.store.path(step.part(), &present) {
            let r = Ok(r.clone());
            t.last = Some((key, r.clone()));
            return r;
        }
        let r = match self.lift(step) {
            Err(f) => Err(f),
            Ok(lift) => match t.store.failure(step.part(), &present, lift, 1) {
                Some(f) => Err(f),
                None => {
                    let r = self.state_plan(step, 1, true);
                    t.store.learn(step.part(), &present, lift, 1, &r);
                    r
                }
            },
        };
        t.last = Some((key, r.clone()));
        r
    }

    /// An expansion with this thread's store: with a kept path valid in the state, only a
    /// shorter one is planned (`k` plans per grasp, [`RemovalPlanner::plan_below`]) and the
    /// kept one serves when none is; without one, the state's own shortest plan.
    fn expansion(&self, step: &mut StepContext<'_, '_>) -> Result<RobotRemoval, RobotFailure> {
        let replans = self.replans(step);
        let present = step.present();
        let store = self.thread_store();
        let mut t = store.lock().expect("not poisoned");
        let kept = t.store.path(step.part(), &present).cloned();
        let lift = self.lift(step);
        let r = match (kept, &lift) {
            (Some(kept), Ok(lift)) => self.planner.plan_below(step.part(), &present, *lift, step.seed(), replans, kept.length).or(Ok(kept)),
            (Some(kept), Err(_)) => Ok(kept),
            (None, Err(f)) => Err(f.clone()),
            (None, Ok(lift)) => match t.store.failure(step.part(), &present, *lift, replans) {
                Some(f) => Err(f),
                None => self.state_plan(step, replans, false),
            },
        };
        if let Ok(lift) = lift {
            t.store.learn(step.part(), &present, lift, replans, &r);
        }
        r
    }

    /// The robot's plan for `step`: for a rollout step (simulation) the first path found with
    /// one plan per grasp, or a path kept from a state with more parts (this thread's
    /// [`PathStore`]); for an expansion the shortest of `k` plans per grasp, or a kept path
    /// when none is shorter; for a replay the state's own shortest plan, the same in every
    /// search.
    pub fn plan(&self, step: &mut StepContext<'_, '_>) -> Result<RobotRemoval, RobotFailure> {
        match step.kind() {
            StepKind::Simulation => self.simulation(step),
            StepKind::Expansion => self.expansion(step),
            StepKind::Replay => {
                let replans = self.replans(step);
                self.state_plan(step, replans, false)
            }
        }
    }

    /// Whether the robot can do `step`: in a rollout the verdict of the plan it will take
    /// ([`RobotModel::plan`]); at an expansion, yes when this thread keeps a path valid in the
    /// state, else the verdict of the first path found with `k` plans per grasp (a kept failure
    /// that holds in the state, or [`RemovalPlanner::removable`], the same grasps and seeds as
    /// the full plan, so the same verdict); in a replay the latter, without the store.
    pub fn feasible(&self, step: &mut StepContext<'_, '_>) -> Result<(), RobotFailure> {
        let replans = self.replans(step);
        match step.kind() {
            StepKind::Simulation => return self.simulation(step).map(|_| ()),
            StepKind::Replay => {}
            StepKind::Expansion => {
                let present = step.present();
                let store = self.thread_store();
                let mut t = store.lock().expect("not poisoned");
                if t.store.path(step.part(), &present).is_some() {
                    return Ok(());
                }
                let lift = self.lift(step)?;
                if let Some(f) = t.store.failure(step.part(), &present, lift, replans) {
                    return Err(f);
                }
                let r = self.state_verdict(step, replans);
                if let Err(f) = &r {
                    t.store.learn(step.part(), &present, lift, replans, &Err(f.clone()));
                }
                return r;
            }
        }
        self.state_verdict(step, replans)
    }

    /// The verdict of the first path found in `step`'s state with `replans` plans per grasp
    /// (shared by all threads).
    fn state_verdict(&self, step: &mut StepContext<'_, '_>, replans: usize) -> Result<(), RobotFailure> {
        let present = step.present();
        let key = (present.words().to_vec(), step.part());
        if let Some(v) = self.known(&key.0, key.1, replans) {
            return v;
        }
        let r = match step.motion() {
            Some(Motion::Linear { direction, .. }) => self.planner.removable(step.part(), &present, direction, step.seed(), replans),
            _ => Err(RobotFailure::Blocked { by: None }),
        };
        self.learn(&key.0, key.1, replans, r.as_ref().map(|_| ()));
        r.map(|_| ())
    }

    /// The planner.
    pub fn planner(&self) -> &RemovalPlanner<Arc<World>> {
        &self.planner
    }
}

/// The optimiser's filter: the robot must be able to take the part out.
#[derive(Debug)]
pub struct RobotFilter(pub Arc<RobotModel>);

impl ActionFilter for RobotFilter {
    fn name(&self) -> &str {
        "robot"
    }

    fn reasons(&self) -> Vec<String> {
        RobotFailure::REASONS.iter().map(|r| r.to_string()).collect()
    }

    fn check(&self, step: &mut StepContext<'_, '_>, _memory: &[u64]) -> Verdict {
        match self.0.feasible(step) {
            Ok(_) => Verdict::Feasible,
            Err(f) => Verdict::Infeasible { reason: f.index() },
        }
    }
}

/// The objective `robot-path`: minus the robot's path length of the removal, metres (eq. 5.8).
#[derive(Debug)]
pub struct RobotPath(pub Arc<RobotModel>);

/// A bound on one removal's path length, metres (the robot cannot drive much farther than this
/// between any two poses of a path).
const LENGTH_BOUND: f64 = 20.0;

impl Objective for RobotPath {
    fn name(&self) -> &str {
        ROBOT_PATH
    }

    fn reward(&self, step: &mut StepContext<'_, '_>, _memory: &mut [u64]) -> f64 {
        // the filter admitted the step; without the filter a failing step costs the bound
        self.0.plan(step).map_or(-LENGTH_BOUND, |r| -r.length)
    }

    fn worst_total(&self, _maps: &DistanceMaps, removals: usize) -> f64 {
        -LENGTH_BOUND * removals as f64
    }

    fn reward_range(&self, _maps: &DistanceMaps) -> Option<(f64, f64)> {
        // a step's reward is minus a path length, never below the bound a failing step costs
        Some((-LENGTH_BOUND, 0.0))
    }
}

/// The optimiser's extension: one [`RobotModel`] per model, shared by the filter and the
/// objective.
#[derive(Debug)]
pub struct RobotExtension {
    setup: RobotSetup,
    model: Mutex<Option<(usize, Arc<RobotModel>)>>,
}

impl RobotExtension {
    /// The extension of `setup`.
    pub fn new(setup: RobotSetup) -> Self {
        RobotExtension { setup, model: Mutex::new(None) }
    }

    /// The robot of the last model [`RobotExtension::model`] built, if any (its planner's
    /// [`RemovalPlanner::stats`] say what the searches on it cost).
    pub fn current_model(&self) -> Option<Arc<RobotModel>> {
        self.model.lock().expect("not poisoned").as_ref().map(|(_, m)| m.clone())
    }

    /// The robot on `model` (built once per assembly).
    pub fn model(&self, model: &ModelContext<'_>) -> asp_search::Result<Arc<RobotModel>> {
        let id = Arc::as_ptr(model.assembly) as usize;
        let mut slot = self.model.lock().expect("not poisoned");
        if let Some((k, m)) = slot.as_ref() {
            if *k == id {
                return Ok(m.clone());
            }
        }
        let config = WorldConfig {
            tolerance: Some(model.maps.tolerance()),
            contact_distance: Some(model.maps.contact_distance()),
            ..WorldConfig::default()
        };
        // the maps' world when it has the robot's settings (one World per run), else a new one
        let world = match model.maps.world() {
            Some(w) if *w.config() == config => w.clone(),
            _ => Arc::new(World::new(model.assembly.as_ref().clone(), &config).map_err(SearchError::from)?),
        };
        let cell = self.setup.cell(model.assembly);
        let m = Arc::new(RobotModel {
            planner: RemovalPlanner::new(world, cell, self.setup.config.clone()),
            replans: self.setup.config.replans,
            assembly: model.assembly.clone(),
            cache: Mutex::new(HashMap::new()),
            verdicts: Mutex::new(HashMap::new()),
            threads: Mutex::new(HashMap::new()),
        });
        *slot = Some((id, m.clone()));
        Ok(m)
    }
}

impl MdpExtension for RobotExtension {
    fn objective_names(&self) -> Vec<String> {
        vec![ROBOT_PATH.into()]
    }

    fn objective(&self, name: &str, model: &ModelContext<'_>) -> asp_search::Result<Option<Arc<dyn Objective>>> {
        if name.trim() != ROBOT_PATH {
            return Ok(None);
        }
        let m = self.model(model)?;
        m.new_search();
        Ok(Some(Arc::new(RobotPath(m))))
    }

    fn filters(&self, model: &ModelContext<'_>) -> asp_search::Result<Vec<Arc<dyn ActionFilter>>> {
        let m = self.model(model)?;
        m.new_search();
        Ok(vec![Arc::new(RobotFilter(m))])
    }

    fn describe(&self, model: &ModelContext<'_>, sequence: &[usize]) -> asp_search::Result<Option<ExtensionReport>> {
        let robot = self.model(model)?;
        // the steps' seeds as the search saw them: a problem with the run's seed
        let mdp = Mdp::new(model.maps.clone(), vec![Arc::new(PathLength) as Arc<dyn Objective>])?
            .with_assembly(model.assembly.clone())
            .with_seed(model.seed);
        let mut state = MapState::new(model.maps);
        let mut steps = Vec::new();
        for &p in sequence {
            let mut ctx = StepContext::new(&mdp, &mut state, p, StepKind::Replay);
            steps.push(robot.plan(&mut ctx).ok());
            state.remove(p);
        }
        Ok(Some(robot_report(&robot.assembly, robot.planner.cell(), steps)))
    }
}
