//! Locked cores planned as models of their own. A subassembly's own plan inside the depth-first
//! search tries straight lines in the whole model's candidate directions, with no path planner
//! and no grid moves; a core it cannot open may still come apart when planned alone: its own
//! candidate directions (the contacts and fits of its parts only), the path planner (a part
//! that must move in an L), the grid planner (a voxel puzzle). A subassembly moves as one body
//! before its own plan runs, so the plan of the core alone, on the subassembly's base, is a
//! valid plan of the subassembly: the core built first, then the parts the subassembly's own
//! plan did place.

use crate::setup::{PlanResult, PlanSettings};
use crate::tree::{add_effort, remapped};
use crate::Result;
use asp_geom::Assembly;
use asp_search::report::{AssemblyStep, LockedCore, PlanReport, SubassemblyStatus};
use asp_search::Budget;
use std::time::Instant;

/// Plans every locked core of `report` (planned on `assembly` with `settings`) alone, and puts
/// each plan that takes a core further apart into its subassembly's step; then settles the
/// report's status and cores ([`PlanReport::settle`]). Cores holding a fixed part of the model
/// stay as they are, and so do cores of subassemblies stopped by the budget and the cores of
/// robot plans. `started` and
/// `budget` are the run's: the cores share what is left of its time. `plan_core` plans one core
/// as a model of its own (the pipeline's).
pub(crate) fn plan_cores_alone(
    report: &mut PlanReport,
    assembly: &Assembly,
    settings: &PlanSettings,
    budget: &Budget,
    started: Instant,
    plan_core: &dyn Fn(Assembly, &PlanSettings, Budget) -> Result<PlanResult>,
) -> Result<()> {
    // a robot plans in its cell, with the whole model: a core alone is no cell
    if report.locked_cores.is_empty() || settings.checker_extension.is_some() {
        return Ok(());
    }
    let mut known: Vec<LockedCore> = Vec::new();
    let mut changed = false;
    for core in report.locked_cores.clone() {
        if core.status != SubassemblyStatus::NoPlan || core.parts.iter().any(|&p| assembly.parts.get(p).is_none_or(|x| x.fixed)) {
            continue;
        }
        let left = budget.timeout.map(|t| t.saturating_sub(started.elapsed()));
        if left.is_some_and(|t| t.is_zero()) || budget.cancel.as_ref().is_some_and(|c| c.is_stopped()) {
            break;
        }
        let Some(local_base) = core.parts.iter().position(|&p| p == core.base) else { continue };
        let mut alone = assembly.subset(&core.parts);
        alone.parts[local_base].fixed = true;
        let mut plan = plan_core(alone, settings, Budget { timeout: left, ..budget.clone() })?;
        plan.report = remapped(&plan.report, &core.parts)?;
        add_effort(report, &plan.report);
        let r = &plan.report;
        let placed = if r.status.has_sequence() { r.assembly_sequence.len() } else { 0 };
        if placed == 0 {
            continue;
        }
        for steps in [&mut report.assembly_sequence, &mut report.partial_assembly_sequence] {
            changed |= put_into(steps, &core, r);
        }
        known.extend(r.locked_cores.iter().cloned());
    }
    if changed {
        // the core's why is of the core that stayed locked; a core opened by its own plan
        // has none
        known.append(&mut report.locked_cores);
        report.status = asp_search::report::PlanStatus::Found;
        report.settle(&known);
    }
    Ok(())
}

/// Puts `plan`, the plan of `core` alone, into the subassembly step of `steps` (at any depth)
/// whose core it is: the core built by `plan` first, then what the subassembly's own plan
/// placed onto it. Whether a step took it.
fn put_into(steps: &mut [AssemblyStep], core: &LockedCore, plan: &PlanReport) -> bool {
    for step in steps {
        let Some(entry) = step.subassembly.as_mut() else { continue };
        if step.part == core.base && entry.status == SubassemblyStatus::NoPlan {
            let placed: Vec<usize> = entry
                .assembly_sequence
                .iter()
                .flat_map(|s| s.subassembly.as_ref().map_or_else(|| vec![s.part], |g| g.parts.clone()))
                .collect();
            let rest: Vec<usize> = entry.parts.iter().copied().filter(|p| !placed.contains(p)).collect();
            if rest == core.parts {
                let mut sequence = plan.assembly_sequence.clone();
                sequence.append(&mut entry.assembly_sequence);
                entry.assembly_sequence = sequence;
                entry.status = plan.status.into();
                entry.explanation = Vec::new();
                return true;
            }
        }
        if put_into(&mut entry.assembly_sequence, core, plan) {
            return true;
        }
    }
    false
}
