//! Plans that follow the file's product tree (`subassemblies` from-file, `asp plan
//! --subassemblies from-file`): each subassembly of the file (a STEP assembly instance, a named
//! glTF node with children) is planned on its own, on its largest part as its base, then the
//! level above with each subassembly as one unit ([`PlanSettings::unit_groups`]), up to the
//! model. The result is one hierarchical plan in the plan JSON's subassembly step format: each
//! unit's step carries its subassembly's own plan and its name in the tree.
//!
//! Every level is planned by the pipeline's `plan_assembly` (handed in as [`PlanLevel`]) on the level's
//! parts; the contact tolerance and distance are the whole model's, so that a bolt and its nut
//! are tested alike in their subassembly and in the model.

use crate::error::{AppError, Result};
use crate::setup::{PlanResult, PlanSettings};

/// How one level of the tree is planned (the pipeline's `plan_assembly`): the level's parts, its
/// settings (its subassemblies as units), the progress callback.
pub type PlanLevel<'a> = &'a dyn Fn(Assembly, &PlanSettings, Option<&(dyn Fn(&Progress) + Sync)>) -> Result<PlanResult>;
use asp_geom::world::{DEFAULT_RELATIVE_CONTACT, DEFAULT_RELATIVE_TOLERANCE};
use asp_geom::Assembly;
use asp_search::report::{AssemblyStep, LockedCore, PlanReport, SubassemblyEntry, SubassemblyStatus};
use asp_search::Progress;
use serde_json::Value;

/// A subassembly of the product tree (or the model, its root).
#[derive(Clone, Debug, PartialEq)]
pub struct Node {
    /// Its path in the tree, `/`-joined (`as1/l-bracket-assembly_1`); the model's own name for
    /// the root.
    pub name: String,
    /// Every part beneath it, by index, ascending.
    pub parts: Vec<usize>,
    /// Its subassemblies of two parts or more (a subassembly of one part is that part).
    pub children: Vec<Node>,
}

/// The product tree of `assembly`, from its parts' paths ([`asp_geom::Part::path`]). The
/// assemblies that hold every part (a STEP file's top product) are the root.
pub fn tree(assembly: &Assembly) -> Node {
    let paths: Vec<&[String]> = assembly.parts.iter().map(|p| p.path.as_slice()).collect();
    let first = paths.first().copied().unwrap_or_default();
    let common = (0..first.len()).take_while(|&k| paths.iter().all(|p| p.get(k) == first.get(k))).count();
    let name = match common {
        0 => assembly.source.file_stem().map_or_else(|| "model".into(), |s| s.to_string_lossy().into_owned()),
        c => first[..c].join("/"),
    };
    node(assembly, name, common, (0..assembly.len()).collect())
}

fn node(assembly: &Assembly, name: String, depth: usize, parts: Vec<usize>) -> Node {
    let mut groups: Vec<(String, Vec<usize>)> = Vec::new();
    for &i in &parts {
        if let Some(child) = assembly.parts[i].path.get(depth) {
            match groups.iter_mut().find(|(n, _)| n == child) {
                Some((_, members)) => members.push(i),
                None => groups.push((child.clone(), vec![i])),
            }
        }
    }
    let children = groups
        .into_iter()
        .filter(|(_, members)| members.len() >= 2)
        .map(|(_, members)| {
            let path = assembly.parts[members[0]].path[..=depth].join("/");
            node(assembly, path, depth + 1, members)
        })
        .collect();
    Node { name, parts, children }
}

/// Plans `assembly` level by level along its product tree (see the module documentation).
/// `settings` are the run's, with [`PlanSettings::from_file`] set; `plan_level` plans each level.
pub fn plan(
    assembly: Assembly,
    settings: &PlanSettings,
    progress: Option<&(dyn Fn(&Progress) + Sync)>,
    plan_level: PlanLevel<'_>,
) -> Result<PlanResult> {
    let root = tree(&assembly);
    let metres = assembly.units.metres;
    let diagonal = assembly.diagonal() as f64 / metres;
    // the whole model's tolerances at every level
    let level = PlanSettings {
        from_file: false,
        tolerance: settings.tolerance.or(Some(DEFAULT_RELATIVE_TOLERANCE as f64 * diagonal)),
        contact_distance: settings.contact_distance.or(Some(DEFAULT_RELATIVE_CONTACT as f64 * diagonal)),
        ..settings.clone()
    };
    let mut entries = Vec::new();
    let mut result = plan_node(&assembly, &root, &level, progress, plan_level, true, &mut entries)?;
    result.report.file_subassemblies = entries;
    if root.children.is_empty() {
        result
            .report
            .warnings
            .push(format!("the model has no subassemblies in its file ({} parts on one level); planned as one level", assembly.len()));
    }
    Ok(result)
}

/// The plan of `node` (indices of the whole model): its subassemblies' plans first, then its
/// own level with each of them as one unit, their plans put into its unit steps.
fn plan_node(
    assembly: &Assembly,
    node: &Node,
    settings: &PlanSettings,
    progress: Option<&(dyn Fn(&Progress) + Sync)>,
    plan_level: PlanLevel<'_>,
    root: bool,
    entries: &mut Vec<SubassemblyEntry>,
) -> Result<PlanResult> {
    let mut inner = Vec::new();
    let children = node
        .children
        .iter()
        .map(|child| plan_node(assembly, child, settings, progress, plan_level, false, &mut inner))
        .collect::<Result<Vec<PlanResult>>>()?;
    let mut level = assembly.subset(&node.parts);
    if !root && !level.parts.iter().any(|p| p.fixed) {
        // a subassembly is built on its largest part, as the search builds the groups it finds
        if let Some(base) = largest(&level) {
            level.parts[base].fixed = true;
        }
    }
    let units = node.children.iter().map(|c| c.parts.iter().map(|&i| assembly.parts[i].name.clone()).collect()).collect();
    let level_settings = PlanSettings { unit_groups: units, ..settings.clone() };
    let mut result = plan_level(level, &level_settings, progress)?;
    if !root {
        result.report = remapped(&result.report, &node.parts)?;
    }
    let mut known: Vec<LockedCore> = Vec::new();
    for (child, plan) in node.children.iter().zip(&children) {
        known.extend(plan.report.locked_cores.iter().cloned());
        let report = &mut result.report;
        for steps in [&mut report.assembly_sequence, &mut report.partial_assembly_sequence] {
            embed(steps, child, &plan.report);
        }
        add_effort(report, &plan.report);
        for w in &plan.report.warnings {
            if !report.warnings.contains(w) {
                report.warnings.push(w.clone());
            }
        }
    }
    result.report.settle(&known);
    if !root {
        let r = &result.report;
        entries.push(SubassemblyEntry {
            name: Some(node.name.clone()),
            parts: node.parts.clone(),
            status: r.status.into(),
            assembly_sequence: if r.status.has_sequence() { r.assembly_sequence.clone() } else { r.partial_assembly_sequence.clone() },
            explanation: r.explanation.clone(),
        });
    }
    entries.extend(inner);
    Ok(result)
}

/// The part of `level` with the largest box (the first of equals).
fn largest(level: &Assembly) -> Option<usize> {
    let volume = |p: &asp_geom::Part| {
        asp_geom::math::aabb_of(p.mesh.vertices.iter().copied()).map_or(0.0, |b| (b.maxs - b.mins).as_dvec3().element_product())
    };
    let mut best: Option<(usize, f64)> = None;
    for (i, p) in level.parts.iter().enumerate() {
        let v = volume(p);
        if best.is_none_or(|(_, b)| v > b) {
            best = Some((i, v));
        }
    }
    best.map(|(i, _)| i)
}

/// Puts `plan`, the plan of the subassembly `child`, into the unit step of `steps` (at any
/// depth) that moves exactly its parts.
fn embed(steps: &mut [AssemblyStep], child: &Node, plan: &PlanReport) {
    for step in steps {
        let Some(entry) = step.subassembly.as_mut() else { continue };
        let mut parts = entry.parts.clone();
        parts.sort_unstable();
        if entry.status == SubassemblyStatus::Unit && parts == child.parts {
            entry.name = Some(child.name.clone());
            entry.status = plan.status.into();
            entry.assembly_sequence =
                if plan.status.has_sequence() { plan.assembly_sequence.clone() } else { plan.partial_assembly_sequence.clone() };
            entry.explanation = plan.explanation.clone();
            if let Some(base) = plan.parts.iter().find(|p| p.fixed && child.parts.contains(&p.index)) {
                step.part = base.index;
                step.name = base.name.clone();
            }
        } else {
            embed(&mut entry.assembly_sequence, child, plan);
        }
    }
}

/// Adds a subassembly's search effort to its parent's.
pub(crate) fn add_effort(report: &mut PlanReport, child: &PlanReport) {
    let (s, c) = (&mut report.stats, &child.stats);
    s.removal_tests += c.removal_tests;
    s.failed_collision += c.failed_collision;
    s.failed_gravity += c.failed_gravity;
    s.path_planner_calls += c.path_planner_calls;
    s.seconds += c.seconds;
    if let (Some(t), Some(ct)) = (s.timings.as_mut(), c.timings.as_ref()) {
        t.load += ct.load;
        t.world += ct.world;
        t.search += ct.search;
        t.path_planner += ct.path_planner;
    }
    if s.stopped_by.is_none() {
        s.stopped_by = c.stopped_by;
    }
}

/// `report` of a level whose part `k` is part `map[k]` of the model, in the model's indices:
/// every part index of the plan format (`part`, `parts`, `base`, `inner`, `index`, `held`,
/// `remaining`, `disassembly_sequence`, at any depth) mapped.
pub(crate) fn remapped(report: &PlanReport, map: &[usize]) -> Result<PlanReport> {
    let fail = |e: serde_json::Error| AppError::config(format!("cannot map a subassembly's plan to the model: {e}"));
    let mut value = serde_json::to_value(report).map_err(fail)?;
    remap(&mut value, map);
    serde_json::from_value(value).map_err(fail)
}

fn remap(value: &mut Value, map: &[usize]) {
    let index = |v: &mut Value| {
        if let Some(k) = v.as_u64().and_then(|k| map.get(k as usize)) {
            *v = Value::from(*k);
        }
    };
    match value {
        Value::Object(fields) => {
            for (key, v) in fields.iter_mut() {
                match key.as_str() {
                    "part" | "base" | "inner" | "index" if v.is_u64() => index(v),
                    "parts" | "held" | "remaining" | "disassembly_sequence" => match v {
                        Value::Array(items) => items.iter_mut().for_each(|item| if item.is_u64() { index(item) } else { remap(item, map) }),
                        other => remap(other, map),
                    },
                    _ => remap(v, map),
                }
            }
        }
        Value::Array(items) => items.iter_mut().for_each(|item| remap(item, map)),
        _ => {}
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use asp_geom::fixtures::box_part;

    #[test]
    fn the_tree_groups_parts_by_their_paths_below_the_common_root() {
        let mut parts = Vec::new();
        for (name, path) in [
            ("plate", vec!["top"]),
            ("bolt", vec!["top", "a"]),
            ("nut", vec!["top", "a"]),
            ("bolt", vec!["top", "b"]),
            ("washer", vec!["top", "c"]),
        ] {
            let mut p = box_part(name, [0.0; 3], [1.0; 3]);
            p.path = path.into_iter().map(String::from).collect();
            parts.push(p);
        }
        let assembly = asp_geom::fixtures::assemble("tree", parts, asp_geom::math::Axis::Z);
        let root = tree(&assembly);
        assert_eq!(root.name, "top");
        assert_eq!(root.parts, vec![0, 1, 2, 3, 4]);
        // `b` and `c` hold one part each: those are parts of the root level
        assert_eq!(root.children, vec![Node { name: "top/a".into(), parts: vec![1, 2], children: vec![] }]);
    }

    #[test]
    fn remapping_moves_every_part_index() {
        let mut v: Value = serde_json::json!({"part": 0, "parts": [0, 1], "explanation": [{"part": 1, "parts": [{"part": 0, "name": "x"}]}],
            "robot": {"base": [0.5, 1.5]}, "stats": {"removal_tests": 1}});
        remap(&mut v, &[4, 7]);
        assert_eq!(v["part"], 4);
        assert_eq!(v["parts"], serde_json::json!([4, 7]));
        assert_eq!(v["explanation"][0]["part"], 7);
        assert_eq!(v["explanation"][0]["parts"][0]["part"], 4);
        assert_eq!(v["robot"]["base"], serde_json::json!([0.5, 1.5]));
        assert_eq!(v["stats"]["removal_tests"], 1);
    }
}
