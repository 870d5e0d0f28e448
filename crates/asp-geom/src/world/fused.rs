//! Components drawn as several solids: CAD keeps a part's pieces as solids of one product (a
//! screw's body and the helical solid of its thread, a weldment's plates) and lets them
//! interpenetrate, since they are one piece. Two parts under one product of the file's tree (the
//! same non-empty [`crate::assembly::Part::path`]) whose input overlap is real interpenetration
//! ([`OverlapClass::Interpenetration`]: no fit, slab or tessellation artefact) cannot be
//! separated by any motion that enters no new material; they are one component as drawn. Each
//! group of such parts, linked by interpenetrating pairs, is planned as one unit and named in a
//! warning. Parts of different products, or of a file without a tree, are never grouped: their
//! interpenetration stays a lock the plan explains. A rolling bearing's parts (balls drawn a
//! little into their races) are the bearing's, a unit of its own, never a component.

use super::bearings::Bearing;
use crate::assembly::Assembly;
use crate::overlap::{OverlapClass, OverlapNote};

/// The groups of parts drawn as one component of several interpenetrating solids (see the
/// module documentation), each ascending, in the order of their first part: from the
/// overlap `notes` of the `assembly`'s parts and its `bearings`.
pub(super) fn fused_components(assembly: &Assembly, notes: &[OverlapNote], bearings: &[Bearing]) -> Vec<Vec<usize>> {
    let n = assembly.len();
    let mut root: Vec<usize> = (0..n).collect();
    fn find(root: &mut [usize], mut i: usize) -> usize {
        while root[i] != i {
            root[i] = root[root[i]];
            i = root[i];
        }
        i
    }
    let parts = &assembly.parts;
    // a bearing's balls drawn into its races are the bearing's, a unit already
    let in_bearing: std::collections::BTreeSet<usize> = bearings.iter().flat_map(|b| b.parts()).collect();
    for note in notes {
        let (a, b) = note.parts;
        let same_product = a < n && b < n && !parts[a].path.is_empty() && parts[a].path == parts[b].path;
        if same_product && note.class == OverlapClass::Interpenetration && !in_bearing.contains(&a) && !in_bearing.contains(&b) {
            let (ra, rb) = (find(&mut root, a), find(&mut root, b));
            root[ra.max(rb)] = ra.min(rb);
        }
    }
    let mut groups: std::collections::BTreeMap<usize, Vec<usize>> = std::collections::BTreeMap::new();
    for p in 0..n {
        let r = find(&mut root, p);
        groups.entry(r).or_default().push(p);
    }
    groups.into_values().filter(|g| g.len() > 1).collect()
}

/// One warning per group of [`fused_components`].
pub(super) fn fused_warnings(assembly: &Assembly, groups: &[Vec<usize>]) -> Vec<String> {
    groups
        .iter()
        .map(|g| {
            let names: Vec<String> = g.iter().map(|&p| format!("'{}'", assembly.parts[p].name)).collect();
            let product = assembly.parts[g[0]].path.last().map_or(String::new(), |s| format!(" of '{s}'"));
            format!("parts {}{product} interpenetrate: one component drawn as several solids, planned as one unit", names.join(", "))
        })
        .collect()
}
