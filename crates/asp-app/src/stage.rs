//! The feasibility pipeline's one mechanism: a declared list of stages
//! ([`crate::stages::STAGES`]) run in order over a checker source. Each [`Stage`] says when it
//! applies (or why not), runs, and whether its answer ends the run; a [`Run`] carries what the
//! earlier stages found (the last search's outcome, a grid search to reuse) and builds the
//! collision world once, for the first stage that asks for it. No stage calls another: the
//! order is the list's, and what a stage needs of an earlier one it reads from the run.

use crate::error::{AppError, Result};
use crate::setup::{checker, PlanResult, PlanSettings};
use crate::why::GridRan;
use asp_geom::grid::VoxelModel;
use asp_geom::{Assembly, Checker, PartSet, World};
use asp_search::grid::GridRun;
use asp_search::report::ExtensionReport;
use asp_search::{Budget, PlanOutcome, Progress};
use std::borrow::Cow;
use std::time::Instant;

/// Where a stage's removal tests are answered.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Source {
    /// The lattice of a model whose parts are all unions of boxes
    /// ([`asp_geom::voxel::VoxelChecker`]): no collision world is built.
    Voxels,
    /// The collision world of the parts' meshes ([`asp_geom::Checker`]), built once, by the
    /// first stage that asks ([`Model::world`]).
    World,
}

/// Whether a stage runs in a run, and if not, why.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Applies {
    /// It runs.
    Yes,
    /// It does not run, for this reason.
    No(&'static str),
}

/// What a stage that ran hands on.
#[derive(Debug)]
pub(crate) enum Next {
    /// The run goes on to the next stage; why this stage's answer did not end it.
    Pass(&'static str),
    /// This stage's answer is the plan: the run ends.
    End(Box<PlanResult>),
}

/// One stage of the feasibility pipeline.
pub(crate) struct Stage {
    /// Its name, as the run's trace records it.
    pub name: &'static str,
    /// Where its removal tests are answered.
    pub source: Source,
    /// Whether it runs, given the settings and what the earlier stages found.
    pub applies: fn(&Run<'_>) -> Applies,
    /// Runs it: its answer ends the run, or it passes the run on (leaving what it found in the
    /// run for the later stages and the report).
    pub run: fn(&mut Run<'_>) -> Result<Next>,
}

/// What became of one stage in a run.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Decision {
    /// It did not apply, for this reason.
    Skipped(&'static str),
    /// It ran and passed the run on, for this reason.
    Passed(&'static str),
    /// It ran and its answer ended the run.
    Ended,
}

/// The model a run plans: the assembly, and its collision world once a stage asked for it.
pub(crate) struct Model<'a> {
    assembly: Option<Cow<'a, Assembly>>,
    checker: Option<Checker>,
    world_seconds: f64,
}

impl Model<'_> {
    /// The assembly.
    pub fn assembly(&self) -> Result<&Assembly> {
        match (&self.checker, &self.assembly) {
            (Some(c), _) => Ok(c.world().assembly()),
            (None, Some(a)) => Ok(a),
            (None, None) => Err(AppError::config("the pipeline lost its model (a world that failed to build)")),
        }
    }

    /// The collision world's checker and the seconds its build took, built the first time it
    /// is asked for; `units` then gain the world's rolling bearings and components drawn as several
    /// solids ([`with_found_units`]).
    pub fn world(&mut self, settings: &PlanSettings, units: &mut Vec<PartSet>) -> Result<(&Checker, f64)> {
        if self.checker.is_none() {
            let assembly = self.assembly.take().ok_or_else(|| AppError::config("the pipeline lost its model"))?;
            let started = Instant::now();
            let built = checker(assembly.into_owned(), settings)?;
            self.world_seconds = started.elapsed().as_secs_f64();
            *units = with_found_units(std::mem::take(units), built.world());
            self.checker = Some(built);
        }
        let seconds = self.world_seconds;
        self.checker.as_ref().map(|c| (c, seconds)).ok_or_else(|| AppError::config("the pipeline lost its world"))
    }
}

/// One run of the feasibility pipeline: its inputs, and what its stages found so far.
pub(crate) struct Run<'a> {
    /// The run's settings.
    pub settings: &'a PlanSettings,
    /// The run's budget (each search counts it from its own start).
    pub budget: &'a Budget,
    /// The depth-first searches' progress callback.
    pub progress: Option<&'a (dyn Fn(&Progress) + Sync)>,
    /// The model, and its world once built.
    pub model: Model<'a>,
    /// The parts kept together: the declared units, and the world's bearings and components drawn
    /// as several solids once it is built.
    pub units: Vec<PartSet>,
    /// The grid planner's voxel view of the model, or why the grid planner does not run on it.
    pub grid: std::result::Result<VoxelModel, &'static str>,
    /// When the run reached the source of the current stage (the grid's and the locked cores'
    /// time is counted from it).
    pub started: Instant,
    /// A whole grid search that ran and did not end the run (the fallback reuses it).
    pub grid_run: Option<GridRun>,
    /// How the grid planner's fallback ran (for the locked cores' why).
    pub grid_ran: GridRan,
    /// The last depth-first search's outcome, with its extension's report (a robot's): the plan
    /// when no stage ends the run.
    pub outcome: Option<(PlanOutcome, Option<ExtensionReport>)>,
    /// Each stage the run reached, in order, with what became of it.
    pub trace: Vec<(&'static str, Decision)>,
}

impl<'a> Run<'a> {
    /// A run of `assembly` with `settings`: its declared units checked and its grid view made.
    pub fn new(
        assembly: Cow<'a, Assembly>,
        settings: &'a PlanSettings,
        budget: &'a Budget,
        progress: Option<&'a (dyn Fn(&Progress) + Sync)>,
    ) -> Result<Run<'a>> {
        let units = unit_sets(&assembly, &settings.unit_groups)?;
        let grid = grid_view(&assembly, settings);
        Ok(Run {
            settings,
            budget,
            progress,
            model: Model { assembly: Some(assembly), checker: None, world_seconds: 0.0 },
            units,
            grid,
            started: Instant::now(),
            grid_run: None,
            grid_ran: GridRan::No,
            outcome: None,
            trace: Vec::new(),
        })
    }

    /// Runs `stages` in order: each that applies runs, until one ends the run (its answer) or
    /// the list ends (`None`: the caller reports [`Run::outcome`]). Every stage reached is
    /// recorded in [`Run::trace`].
    pub fn run<'s>(&mut self, stages: impl IntoIterator<Item = &'s Stage>) -> Result<Option<PlanResult>> {
        let mut source = None;
        for stage in stages {
            if source != Some(stage.source) {
                source = Some(stage.source);
                self.started = Instant::now();
            }
            if let Applies::No(why) = (stage.applies)(self) {
                self.trace.push((stage.name, Decision::Skipped(why)));
                continue;
            }
            match (stage.run)(self)? {
                Next::Pass(why) => self.trace.push((stage.name, Decision::Passed(why))),
                Next::End(result) => {
                    self.trace.push((stage.name, Decision::Ended));
                    return Ok(Some(*result));
                }
            }
        }
        Ok(None)
    }
}

/// The voxel view the grid planner takes apart, or why it does not run: it does not keep
/// declared units together, and a robot checks what the grid cannot.
fn grid_view(assembly: &Assembly, settings: &PlanSettings) -> std::result::Result<VoxelModel, &'static str> {
    if !settings.grid {
        Err("the grid planner is off")
    } else if settings.checker_extension.is_some() {
        Err("a robot checks what the grid planner cannot")
    } else if !settings.unit_groups.is_empty() {
        Err("the grid planner does not keep declared units together")
    } else {
        VoxelModel::of(assembly).ok_or("the parts are not on one grid")
    }
}

/// `units` with every rolling bearing `world` found ([`asp_geom::Bearing`]) and every component
/// drawn as several interpenetrating solids ([`asp_geom::world::Overlaps::fused_components`]) as one more unit: a
/// bought unit whose balls never leave their grooves, or one piece drawn as several, goes in
/// whole. A declared unit that shares a part with one is merged with it (units are disjoint).
fn with_found_units(mut units: Vec<PartSet>, world: &World) -> Vec<PartSet> {
    let n = world.num_parts();
    let found = world.overlaps().fits().bearings().iter().map(|b| b.parts()).chain(world.overlaps().fused_components().iter().cloned());
    for parts in found {
        let mut merged = PartSet::from_indices(n + 1, parts);
        units.retain(|u| {
            let meets = u.intersects(&merged);
            if meets {
                merged.union_with(u);
            }
            !meets
        });
        units.push(merged);
    }
    units
}

/// The declared units ([`PlanSettings::unit_groups`]) as sets of part indices.
fn unit_sets(assembly: &Assembly, groups: &[Vec<String>]) -> Result<Vec<PartSet>> {
    let n = assembly.len();
    groups
        .iter()
        .map(|g| {
            let parts = g
                .iter()
                .map(|name| assembly.part_index(name).ok_or_else(|| AppError::setting("unit_group", format!("no part is named '{name}'"))))
                .collect::<Result<Vec<usize>>>()?;
            Ok(PartSet::from_indices(n + 1, parts))
        })
        .collect()
}
