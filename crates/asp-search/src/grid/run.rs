//! Grid plans of interlocking voxel puzzles as plan outcomes, and the grid planner behind
//! [`Planner`] ([`GridPlanner`]).
//!
//! [`super::solver`] takes a voxel model apart by moves of parts and groups on its grid; here
//! its answer becomes the steps every report and picture reads: each separation a removal
//! (a single part, or a subassembly with its own plan on its base) carrying the moves made
//! before it ([`Step::moves`]). The pipeline (`asp_app::pipeline::plan_assembly`) uses it for
//! voxel models when several parts must move in turn before anything can leave (straight away:
//! the depth-first search could only spend its budget on path planning there), and as the
//! fallback when the depth-first search ends without a plan.

use super::solver::{self as grid, GridConfig, GridPlan, GridSolution};
use crate::error::{Result, SearchError};
use crate::problem::{Budget, GroupMove, PlanOutcome, Planner, Problem, Spent, Stats, Status, Step, StopReason, Subassembly};
use asp_geom::grid::VoxelModel;
use asp_geom::{Assembly, Motion, PartSet};
use std::cell::Cell;
use std::time::Instant;

/// The longest the probe before the depth-first search may take, seconds.
const PROBE_SECONDS: f64 = 2.0;

/// A grid search of one model.
#[derive(Clone, Debug)]
pub struct GridRun {
    /// The model's voxel view.
    pub model: VoxelModel,
    /// The search's answer.
    pub solution: GridSolution,
    /// Which limit of the budget ended the search, when one did (`None` also when the model is
    /// too large for the search's tables: it then ends at once).
    pub stopped_by: Option<StopReason>,
}

impl GridRun {
    /// Searches the voxel `model` on its grid with `config`, within `budget` (its time, states
    /// and cancel token, counted from `started`; the fewer states of the two).
    pub fn new(model: VoxelModel, config: &GridConfig, budget: &Budget, started: Instant) -> GridRun {
        let config = GridConfig { max_states: budget.max_states.map_or(config.max_states, |m| m.min(config.max_states)), ..*config };
        let reason = Cell::new(None);
        let stop = || {
            reason.set(budget.stop_reason(Spent::default(), started));
            reason.get().is_some()
        };
        let solution = grid::solve(&model, &config, &stop);
        let stopped_by = match solution.plan.status {
            Status::BudgetExhausted => reason.get().or((solution.states >= config.max_states).then_some(StopReason::MaxStates)),
            _ => None,
        };
        GridRun { model, solution, stopped_by }
    }

    /// Only the model's first separation, within a small budget (200,000 states, 2 s): whether
    /// the grid plan should run first ([`GridRun::needs_moves`]).
    pub fn probe(model: VoxelModel, budget: &Budget, started: Instant) -> GridRun {
        let stop = || budget.stop_reason(Spent::default(), started).is_some() || started.elapsed().as_secs_f64() > PROBE_SECONDS;
        let config = GridConfig { max_states: 200_000, first_only: true, ..GridConfig::default() };
        let solution = grid::solve(&model, &config, &stop);
        GridRun { model, solution, stopped_by: None }
    }

    /// Whether the whole model comes apart (down to its fixed parts, or its last part).
    pub fn found(&self) -> bool {
        self.solution.plan.status == Status::Found
    }

    /// Whether parts must move in turn before the first separation in a way no straight-line
    /// removal, group removal or single-part path finds: some move before it moves another
    /// group than the single part that then leaves.
    pub fn needs_moves(&self) -> bool {
        let Some(first) = self.solution.plan.steps.first() else { return false };
        !(first.moves.is_empty() || first.parts.len() == 1 && first.moves.iter().all(|m| m.parts == first.parts))
    }

    /// The plan outcome: the separations as removals with their moves; with no fixed part the
    /// last part (the base that never moved) is lifted off along `up` at the end. Its stats hold
    /// the states visited, the time and, for `BudgetExhausted`, which limit stopped it.
    pub fn outcome(&self, assembly: &Assembly) -> PlanOutcome {
        let n = assembly.len();
        let margin = 1e-3 * assembly.diagonal();
        let plan = &self.solution.plan;
        let mut removals = steps(&self.model, plan, n, margin);
        let status = plan.status.clone();
        if status == Status::Found && !self.model.fixed.iter().any(|f| *f) {
            if let [last] = plan.remaining[..] {
                let up = assembly.up.vector();
                let extent = self.model.cells[last]
                    .iter()
                    .map(|c| self.model.metres(*c).dot(up))
                    .fold((f32::MAX, f32::MIN), |(l, h), x| (l.min(x), h.max(x)));
                let height = extent.1 - extent.0 + self.model.cell.dot(up.abs());
                removals.push(Step::single(last, Motion::Linear { direction: up, distance: height + margin }));
            }
        }
        PlanOutcome {
            status,
            removals,
            stats: Stats {
                seconds: self.solution.seconds,
                states_expanded: self.solution.states,
                stopped_by: self.stopped_by,
                ..Stats::default()
            },
        }
    }
}

fn steps(model: &VoxelModel, plan: &GridPlan, n: usize, margin: f32) -> Vec<Step> {
    plan.steps
        .iter()
        .map(|g| {
            let direction = model.metres(g.direction).normalize();
            let distance = model.metres(g.direction.map(|x| x * g.clearance)).length() + margin;
            let moves = g
                .moves
                .iter()
                .map(|m| GroupMove { parts: PartSet::from_indices(n, m.parts.iter().copied()), translation: model.metres(m.delta) })
                .collect();
            let group = (g.parts.len() > 1).then(|| {
                Box::new(Subassembly {
                    parts: PartSet::from_indices(n, g.parts.iter().copied()),
                    plan: g.plan.as_ref().map(|p| PlanOutcome {
                        status: p.status.clone(),
                        removals: steps(model, p, n, margin),
                        stats: Stats::default(),
                    }),
                    unit: false,
                })
            });
            let part = if group.is_some() { g.base } else { g.parts[0] };
            Step { part, motion: Motion::Linear { direction, distance }, group, moves }
        })
        .collect()
}

/// The grid planner behind [`Planner`]: an assembly's voxel view taken apart by moves of parts
/// and groups on its grid. It is made on that view (as an OMPL planner on its space), plans the
/// whole assembly and counts the budget's time, states and cancel token.
#[derive(Clone, Debug)]
pub struct GridPlanner<'a> {
    assembly: &'a Assembly,
    model: VoxelModel,
    config: GridConfig,
}

impl<'a> GridPlanner<'a> {
    /// The grid planner of `assembly` with `config`, or `None` when the assembly is no voxel
    /// model ([`VoxelModel::of`]).
    pub fn of(assembly: &'a Assembly, config: GridConfig) -> Option<GridPlanner<'a>> {
        VoxelModel::of(assembly).map(|model| GridPlanner { assembly, model, config })
    }

    /// The grid planner of `assembly` on its voxel view `model` (as [`VoxelModel::of`] made it).
    pub fn new(assembly: &'a Assembly, model: VoxelModel, config: GridConfig) -> GridPlanner<'a> {
        GridPlanner { assembly, model, config }
    }

    /// The search itself, with everything it found ([`GridRun::solution`]: the grid plan, the
    /// moves before the first separation), for a caller that reports more than the outcome.
    pub fn run(&self, budget: &Budget, started: Instant) -> GridRun {
        GridRun::new(self.model.clone(), &self.config, budget, started)
    }
}

impl Planner for GridPlanner<'_> {
    fn name(&self) -> &'static str {
        "grid"
    }

    /// [`GridPlanner::run`]'s outcome. The problem must be the whole assembly of the planner's
    /// model (its checker's parts, all present): the grid planner takes nothing else apart.
    fn solve(&self, problem: &Problem, budget: &Budget) -> Result<PlanOutcome> {
        let n = self.model.len();
        if problem.checker.num_parts() != n || !problem.start.iter().eq(0..n) {
            return Err(SearchError::config(format!(
                "the grid planner takes the whole assembly of its voxel model apart ({n} parts), not this problem"
            )));
        }
        let started = Instant::now();
        if let Some(reason) = budget.stop_reason(Spent::default(), started) {
            return Ok(PlanOutcome::stopped_before_start(reason));
        }
        Ok(self.run(budget, started).outcome(self.assembly))
    }
}
