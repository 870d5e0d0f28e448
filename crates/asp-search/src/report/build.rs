//! A plan report made from a planner's outcome: the removals reversed into assembly steps (each
//! motion into an insertion, subassemblies with their own plans), the status completed by the
//! steps, the locked cores of a partial plan and the explanation of a dead end.

use super::*;

impl PlanReport {
    /// The plan JSON as written to files and stdout: pretty-printed, with a final newline. The
    /// CLI and the Python package both write exactly this.
    pub fn to_json(&self) -> String {
        let mut s = serde_json::to_string_pretty(self).expect("plan reports serialise (no maps with non-string keys)");
        s.push('\n');
        s
    }

    /// The report of `outcome` on `assembly`; `tolerance` in metres.
    pub fn new(assembly: &Assembly, outcome: &PlanOutcome, tolerance: f32, warnings: &[String]) -> Self {
        let u = |m: f32| assembly.units.from_metres(m as f64);
        let name = |i: usize| assembly.parts.get(i).map(|p| p.name.clone()).unwrap_or_else(|| "ground".into());
        let named = |s: &PartSet| s.iter().map(|part| NamedPart { part, name: name(part) }).collect();
        let steps = assembly_steps(&outcome.removals, &name, &u);
        let status = complete(status_name(&outcome.status), &steps);
        let locked_cores = if status == PlanStatus::Partial { locked_cores(&steps, &name) } else { Vec::new() };
        let found = outcome.status == Status::Found;
        let removed = removal_order(&outcome.removals);
        let remaining = (!found).then(|| (0..assembly.parts.len()).filter(|i| !removed.contains(i)).collect());
        let (assembly_sequence, partial_assembly_sequence) = if found { (steps, Vec::new()) } else { (Vec::new(), steps) };
        let explanation = explain(&outcome.status, &name, &named);
        let c = &outcome.stats.counters;
        PlanReport {
            format_version: FORMAT_VERSION.into(),
            model: assembly.source.display().to_string(),
            units: assembly.units.name.clone(),
            up: assembly.up.to_string(),
            tolerance: u(tolerance),
            status,
            parts: assembly.parts.iter().enumerate().map(|(index, p)| PartEntry::of(index, p, &assembly.units)).collect(),
            assembly_sequence,
            disassembly_sequence: removed,
            partial_assembly_sequence,
            remaining,
            stats: StatsEntry {
                checker: Checker::CollisionWorld,
                removal_tests: c.removal_tests,
                failed_collision: c.failed_collision,
                failed_gravity: c.failed_gravity,
                path_planner_calls: c.path_planner_calls,
                seconds: outcome.stats.seconds,
                timings: None,
                stopped_by: outcome.stats.stopped_by,
            },
            explanation,
            locked_cores,
            overlaps: None,
            fits: Vec::new(),
            warnings: warnings.to_vec(),
            pareto_front: None,
            optimisation: None,
            robot: None,
            grid: None,
            file_subassemblies: Vec::new(),
            bearings: Vec::new(),
            components: Vec::new(),
            precedence: None,
        }
    }
}

/// The removals as assembly steps (reversed, each motion reversed into an insertion), with
/// their subassemblies' own plans.
fn assembly_steps(removals: &[Step], name: &dyn Fn(usize) -> String, u: &dyn Fn(f32) -> f64) -> Vec<AssemblyStep> {
    removals
        .iter()
        .rev()
        .map(|s| AssemblyStep {
            part: s.part,
            name: name(s.part),
            motion: insertion(&s.motion, u),
            subassembly: s.group.as_ref().map(|g| {
                let named = |set: &PartSet| set.iter().map(|part| NamedPart { part, name: name(part) }).collect();
                let (status, assembly_sequence, explanation) = match &g.plan {
                    None if g.unit => (SubassemblyStatus::Unit, Vec::new(), Vec::new()),
                    None => (SubassemblyStatus::Unplanned, Vec::new(), Vec::new()),
                    Some(plan) => {
                        let steps = assembly_steps(&plan.removals, name, u);
                        (SubassemblyStatus::from(complete(status_name(&plan.status), &steps)), steps, explain(&plan.status, name, &named))
                    }
                };
                Box::new(SubassemblyEntry { name: None, parts: g.parts.iter().collect(), status, assembly_sequence, explanation })
            }),
            robot: None,
            held: Vec::new(),
            moves: s
                .moves
                .iter()
                .rev()
                .map(|m| MoveEntry {
                    parts: m.parts.iter().collect(),
                    translation: [u(-m.translation.x), u(-m.translation.y), u(-m.translation.z)],
                })
                .collect(),
        })
        .collect()
}

/// `found` only when every part gets its own motion: a found sequence holding a subassembly
/// whose own plan is not `found` (recursively) is `partial`. A unit the user declared counts as
/// one part.
pub(super) fn complete(status: PlanStatus, steps: &[AssemblyStep]) -> PlanStatus {
    let locked = steps
        .iter()
        .any(|s| s.subassembly.as_ref().is_some_and(|g| !matches!(g.status, SubassemblyStatus::Found | SubassemblyStatus::Unit)));
    if status == PlanStatus::Found && locked {
        PlanStatus::Partial
    } else {
        status
    }
}

/// The locked cores of `steps`: of each subassembly not `found`, the parts its own steps do not
/// place; inside subassemblies too.
pub(super) fn locked_cores(steps: &[AssemblyStep], name: &dyn Fn(usize) -> String) -> Vec<LockedCore> {
    let mut cores = Vec::new();
    for step in steps {
        let Some(g) = &step.subassembly else { continue };
        if !matches!(g.status, SubassemblyStatus::Found | SubassemblyStatus::Partial | SubassemblyStatus::Unit) {
            let placed: Vec<usize> = g
                .assembly_sequence
                .iter()
                .flat_map(|s| s.subassembly.as_ref().map_or_else(|| vec![s.part], |inner| inner.parts.clone()))
                .collect();
            let parts: Vec<usize> = g.parts.iter().copied().filter(|p| !placed.contains(p)).collect();
            cores.push(LockedCore {
                base: step.part,
                names: parts.iter().map(|&p| name(p)).collect(),
                parts,
                status: g.status,
                explanation: g.explanation.clone(),
                why: None,
            });
        }
        cores.extend(locked_cores(&g.assembly_sequence, name));
    }
    cores
}

/// The parts in removal order, a subassembly's parts at its step: those its own plan removes
/// first, in that order, then the ones that stay on its base, the base last.
pub fn removal_order(removals: &[Step]) -> Vec<usize> {
    let mut order = Vec::new();
    for s in removals {
        match &s.group {
            None => order.push(s.part),
            Some(g) => {
                let inner = g.plan.as_ref().map(|p| removal_order(&p.removals)).unwrap_or_default();
                let stay = g.parts.iter().filter(|p| !inner.contains(p) && *p != s.part).collect::<Vec<_>>();
                order.extend(inner);
                order.extend(stay);
                order.push(s.part);
            }
        }
    }
    order
}

fn status_name(status: &Status) -> PlanStatus {
    match status {
        Status::Found => PlanStatus::Found,
        Status::NoPlan { .. } => PlanStatus::NoPlan,
        Status::BudgetExhausted => PlanStatus::BudgetExhausted,
    }
}

/// The explanation of a `no_plan` status: what holds each part of the deepest dead end.
fn explain(status: &Status, name: &dyn Fn(usize) -> String, named: &dyn Fn(&PartSet) -> Vec<NamedPart>) -> Vec<Explanation> {
    match status {
        Status::NoPlan { stuck, .. } => stuck
            .iter()
            .map(|s| {
                let (reason, parts, robot) = match &s.reason {
                    StuckReason::Blocked(b) => (ExplanationReason::Blocked, named(b), None),
                    StuckReason::WouldLeaveUnsupported(f) => (ExplanationReason::Unsupported, named(f), None),
                    StuckReason::DeadEnd => (ExplanationReason::DeadEnd, Vec::new(), None),
                    StuckReason::Refused(r) => (ExplanationReason::Blocked, Vec::new(), Some(r.clone())),
                };
                Explanation { part: s.part, name: name(s.part), reason, parts, robot }
            })
            .collect(),
        _ => Vec::new(),
    }
}

/// The insertion that undoes a removal motion, in model units.
pub fn insertion(motion: &Motion, u: &dyn Fn(f32) -> f64) -> MotionEntry {
    let v3 = |v: asp_geom::math::Vec3, f: &dyn Fn(f32) -> f64| [f(v.x), f(v.y), f(v.z)];
    let unit = |x: f32| x as f64;
    match motion {
        Motion::Linear { direction, distance } => MotionEntry::Linear { direction: v3(-*direction, &unit), distance: u(*distance) },
        Motion::Screw { axis_point, direction, distance } => {
            MotionEntry::Screw { direction: v3(-*direction, &unit), distance: u(*distance), axis_point: v3(*axis_point, u) }
        }
        Motion::Path { poses, pivot } => MotionEntry::Path {
            poses: poses
                .iter()
                .rev()
                .map(|p: &Pose| {
                    let t = v3(p.translation, u);
                    let q = p.rotation;
                    [t[0], t[1], t[2], q.x as f64, q.y as f64, q.z as f64, q.w as f64]
                })
                .collect(),
            pivot: v3(*pivot, u),
        },
    }
}
