//! Grid plans of interlocking voxel puzzles as plan outcomes.
//!
//! [`super::solver`] takes a voxel model apart by moves of parts and groups on its grid; here
//! its answer becomes the steps every report and picture reads: each separation a removal
//! (a single part, or a subassembly with its own plan on its base) carrying the moves made
//! before it ([`Step::moves`]). The pipeline (`asp_app::pipeline::plan_assembly`) uses it for
//! voxel models when several parts must move in turn before anything can leave (straight away:
//! the depth-first search could only spend its budget on path planning there), and as the
//! fallback when the depth-first search ends without a plan.

use super::solver::{self as grid, GridConfig, GridPlan, GridSolution, GridStatus};
use crate::problem::{Budget, GroupMove, PlanOutcome, Stats, Status, Step, Stuck, StuckReason, Subassembly};
use asp_geom::grid::VoxelModel;
use asp_geom::{Assembly, Motion, PartSet};
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
}

impl GridRun {
    /// Searches the voxel `model` on its grid with `config`, within `budget` (its time and
    /// cancel token, counted from `started`).
    pub fn new(model: VoxelModel, config: &GridConfig, budget: &Budget, started: Instant) -> GridRun {
        let stop = || budget.stop_reason(0, started).is_some();
        let solution = grid::solve(&model, config, &stop);
        GridRun { model, solution }
    }

    /// Only the model's first separation, within a small budget (200,000 states, 2 s): whether
    /// the grid plan should run first ([`GridRun::needs_moves`]).
    pub fn probe(model: VoxelModel, budget: &Budget, started: Instant) -> GridRun {
        let stop = || budget.stop_reason(0, started).is_some() || started.elapsed().as_secs_f64() > PROBE_SECONDS;
        let config = GridConfig { max_states: 200_000, first_only: true, ..GridConfig::default() };
        let solution = grid::solve(&model, &config, &stop);
        GridRun { model, solution }
    }

    /// Whether the whole model comes apart (down to its fixed parts, or its last part).
    pub fn found(&self) -> bool {
        self.solution.plan.status == GridStatus::Found
    }

    /// Whether parts must move in turn before the first separation in a way no straight-line
    /// removal, group removal or single-part path finds: some move before it moves another
    /// group than the single part that then leaves.
    pub fn needs_moves(&self) -> bool {
        let Some(first) = self.solution.plan.steps.first() else { return false };
        !(first.moves.is_empty() || first.parts.len() == 1 && first.moves.iter().all(|m| m.parts == first.parts))
    }

    /// The plan outcome: the separations as removals with their moves; with no fixed part the
    /// last part (the base that never moved) is lifted off along `up` at the end.
    pub fn outcome(&self, assembly: &Assembly) -> PlanOutcome {
        let n = assembly.len();
        let margin = 1e-3 * assembly.diagonal();
        let plan = &self.solution.plan;
        let mut removals = steps(&self.model, plan, n, margin);
        let status = status(plan, n);
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
            stats: Stats { seconds: self.solution.seconds, states_expanded: self.solution.states, ..Stats::default() },
        }
    }
}

fn status(plan: &GridPlan, n: usize) -> Status {
    match plan.status {
        GridStatus::Found => Status::Found,
        GridStatus::Budget => Status::BudgetExhausted,
        GridStatus::Stuck => {
            let state = PartSet::from_indices(n, plan.remaining.iter().copied());
            let stuck = plan.remaining.iter().map(|&p| Stuck { part: p, reason: StuckReason::Blocked(state.without(p)) }).collect();
            Status::NoPlan { stuck, state }
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
                        status: status(p, n),
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
