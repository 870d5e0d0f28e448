//! The measurement that builds the contact graph and the overlaps together: every pair of
//! parts whose bounds come within the contact distance is measured once (exactly on exact
//! boxes, else by shrinking each part until it clears the other, or where they overlap when no
//! shrinking does), and what it finds is both a contact and, beyond the tolerance, an overlap
//! note with its warning and its handling under the policy.
//!
//! One pass for both because the expensive part, the pair's erosion search, answers both
//! questions.

use super::classify::Regions;
use super::overlaps::Overlaps;
use super::shapes::Shapes;
use crate::assembly::Assembly;
use crate::boxes;
use crate::error::{GeomError, Result};
use crate::math::{Pose, Vec3};
use crate::overlap::{self, OverlapClass, OverlapHandling, OverlapKind, OverlapNote, OverlapPolicy};
use crate::partset::PartSet;
use parry3d::query::{self, ClosestPoints};
use rayon::prelude::*;
use std::collections::BTreeSet;
use std::sync::OnceLock;

/// What [`measure`] found.
pub(super) struct Measured {
    /// Per part (ground included), the parts within the contact distance.
    pub(super) sets: Vec<PartSet>,
    /// The overlapping pairs, their notes and handling (no fits yet).
    pub(super) overlaps: Overlaps,
    /// One warning per overlapping pair, in pair order.
    pub(super) warnings: Vec<String>,
    /// The overlap regions measured (gross mesh pairs), for the classification.
    pub(super) regions: Regions,
}

/// Finds contacts (parts within `contact_distance`) and input overlaps between parts, and
/// decides by `policy` what each overlap's tests do.
pub(super) fn measure(
    assembly: &Assembly,
    shapes: &Shapes,
    contact_distance: f32,
    max_overlap_fraction: f32,
    policy: OverlapPolicy,
) -> Result<Measured> {
    let count = shapes.count();
    let name = |i: usize| -> &str { assembly.parts.get(i).map(|p| p.name.as_str()).unwrap_or("ground") };
    let tolerance = shapes.tolerance();
    let geoms = &shapes.geoms;
    let mut overlaps = Overlaps::new(policy, tolerance, assembly.len());
    let mut warnings = Vec::new();
    let pairs: Vec<(usize, usize)> = (0..count)
        .flat_map(|i| ((i + 1)..count).map(move |j| (i, j)))
        .filter(|&(i, j)| {
            let m = contact_distance;
            let a = &geoms[i].aabb;
            let b = &geoms[j].aabb;
            (0..3).all(|k| a.mins[k] <= b.maxs[k] + m && b.mins[k] <= a.maxs[k] + m)
        })
        .collect();
    // every part a mesh pair measures is shrunk by the tolerance first (each pair's test
    // starts there, and the removal tests use it): once per part, in parallel, instead of
    // inside the pairs, where pairs sharing a part would wait on its cache
    let meshed: BTreeSet<usize> = pairs
        .iter()
        .filter(|&&(i, j)| geoms[i].boxes.is_none() || geoms[j].boxes.is_none())
        .flat_map(|&(i, j)| [i, j])
        .filter(|&k| !geoms[k].eroded_cached(tolerance))
        .collect();
    meshed.into_iter().collect::<Vec<_>>().par_iter().for_each(|&k| {
        geoms[k].eroded(tolerance);
    });
    let limit_of = |k: usize| max_overlap_fraction * (geoms[k].aabb.maxs - geoms[k].aabb.mins).min_element();
    // (pair, touching, extra erosions, a gross pair's depth: exact on boxes, else measured
    // in its overlap region)
    type Found = (usize, usize, bool, Option<f32>, Option<f32>, Option<f32>, Option<overlap::OverlapRegion>);
    let found: Vec<Found> = pairs
        .par_iter()
        .map(|&(i, j)| {
            if let (Some(bi), Some(bj)) = (&geoms[i].boxes, &geoms[j].boxes) {
                // exact: how deep the boxes overlap, and how close they come
                let pairs = || bi.iter().flat_map(|a| bj.iter().map(move |b| (a, b)));
                let depth = pairs().map(|(a, b)| boxes::overlap_depth(a, b)).fold(f32::NEG_INFINITY, f32::max);
                let gap = pairs().map(|(a, b)| boxes::box_distance(a, b, Vec3::ONE)).fold(f32::INFINITY, f32::min);
                let extra = (depth - tolerance).max(0.0);
                let within = |k: usize| (extra <= limit_of(k)).then_some(extra);
                return (i, j, gap <= contact_distance, within(i), within(j), Some(depth), None);
            }
            let (a, b) = (&*geoms[i].mesh, &*geoms[j].mesh);
            let id = Pose::IDENTITY;
            // parry's mesh-mesh closest points can miss an overlap: measure every candidate
            let (e_ij, e_ji) = (shapes.extra_erosion(i, j, limit_of(i)), shapes.extra_erosion(j, i, limit_of(j)));
            let overlapping = e_ij != Some(0.0) || e_ji != Some(0.0);
            let touching = overlapping || !matches!(query::closest_points(&id, a, &id, b, contact_distance), Ok(ClosestPoints::Disjoint));
            // no shrinking separates them: how deep they overlap is measured where they do
            let region = (e_ij.is_none() && e_ji.is_none()).then(|| overlap::overlap_region(a, b, overlap::REGION_SAMPLES));
            let measured = region.as_ref().and_then(|r| r.depth());
            (i, j, touching, e_ij, e_ji, measured, region)
        })
        .collect();
    let mut sets = vec![PartSet::empty(count); count];
    let units = assembly.units.clone();
    let len = |m: f32| format!("{} {}", significant(units.from_metres(m as f64), 3), units.name);
    let mut regions = Regions::new();
    for (i, j, touching, e_ij, e_ji, measured, region) in found {
        if touching {
            sets[i].insert(j);
            sets[j].insert(i);
        }
        let (a, b) = (name(i).to_string(), name(j).to_string());
        // the pair's tests shrink whichever part separates with the least shrinking: a screw
        // through a thin plate's tapped hole is shrunk, not the plate
        let eroder = match (e_ij, e_ji) {
            (Some(x), Some(y)) if x <= y => Some((i, x)),
            (_, Some(y)) => Some((j, y)),
            (Some(x), None) => Some((i, x)),
            (None, None) => None,
        };
        let limit = limit_of(i).max(limit_of(j));
        let (depth, gross, bound) = match eroder {
            _ if e_ij == Some(0.0) && e_ji == Some(0.0) => continue,
            Some((k, 0.0)) => {
                // only the other part, shrunk by the tolerance, still crosses: shrink this one
                overlaps.pairs.insert((i, j), (k, 0.0));
                continue;
            }
            Some((k, extra)) => {
                overlaps.pairs.insert((i, j), (k, extra));
                (tolerance + extra, false, false)
            }
            // the erosion bound overstates thin-walled and detailed parts (a panel 2 mm into
            // another is no shallower for being large): the overlap region says how deep
            None => match measured.filter(|d| d.is_finite() && *d > 0.0) {
                Some(d) => (d.max(tolerance), true, false),
                None => (tolerance + limit, true, true),
            },
        };
        let kind = shapes.overlap_kind(i, j);
        // coincident parts are as deep as they are thick, which no sample measures
        let (depth, bound) = if gross && kind == OverlapKind::Coincident { (tolerance + limit, true) } else { (depth, bound) };
        if let Some(r) = region {
            regions.insert((i, j), r);
        }
        let what = match kind {
            OverlapKind::Crossing => "overlap".to_string(),
            OverlapKind::Nested { inner } => format!("overlap ('{}' lies inside the other)", name(inner)),
            OverlapKind::Coincident => "overlap (they occupy the same space)".to_string(),
        };
        let measured = if bound {
            format!(
                "by more than {} (shrinking either by {:.0}% of its thickness does not separate them)",
                len(depth),
                max_overlap_fraction * 100.0
            )
        } else if gross {
            format!(
                "by about {} (measured where they overlap; shrinking either by {:.0}% of its thickness does not separate them)",
                len(depth),
                max_overlap_fraction * 100.0
            )
        } else {
            format!("by about {}", len(depth))
        };
        let handling = match (policy, gross) {
            (OverlapPolicy::Error, true) => {
                return Err(GeomError::GrossOverlap {
                    path: assembly.source.clone(),
                    reason: format!(
                        "parts '{a}' and '{b}' {what} far beyond the tolerance ({}): {measured}; fix the model, raise the tolerance, or plan with the overlaps policy strict or lenient",
                        len(tolerance)
                    ),
                });
            }
            (OverlapPolicy::Strict, _) => {
                overlaps.strict.insert((i, j));
                overlaps.strict.insert((j, i));
                if gross {
                    // no shrunk sweep guards this pair: its samples alone must see a part
                    // cut sideways through the other
                    overlaps.strict_samples.insert((i, j), OnceLock::new());
                    overlaps.strict_samples.insert((j, i), OnceLock::new());
                    overlaps.ignored.insert((i, j));
                    overlaps.ignored.insert((j, i));
                }
                OverlapHandling::Strict
            }
            (_, false) => OverlapHandling::Shrunk,
            (OverlapPolicy::Lenient, true) => {
                overlaps.ignored.insert((i, j));
                overlaps.ignored.insert((j, i));
                OverlapHandling::Ignored
            }
        };
        let consequence = match handling {
            OverlapHandling::Strict => "they may separate only along motions that enter no new material of each other".to_string(),
            OverlapHandling::Ignored => "their collisions with each other are ignored".to_string(),
            OverlapHandling::Shrunk => format!("their mutual tests shrink '{}' by that much", name(overlaps.erosion(i, j).0)),
        };
        warnings.push(format!("parts '{a}' and '{b}' {what} in the input {measured} (tolerance {}); {consequence}", len(tolerance)));
        // classified with the fits ([`super::classify::classify_overlaps`])
        let class = OverlapClass::Interpenetration;
        overlaps.notes.push(OverlapNote { parts: (i, j), kind, depth, gross, bound, handling, class, normal: None });
    }
    Ok(Measured { sets, overlaps, warnings, regions })
}

/// `x` rounded to `digits` significant digits, without an exponent (0.000123, 12.3, 1230).
fn significant(x: f64, digits: i32) -> String {
    if x == 0.0 || !x.is_finite() {
        return format!("{x}");
    }
    let decimals = (digits - 1 - x.abs().log10().floor() as i32).max(0) as usize;
    format!("{x:.decimals$}")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lengths_in_messages_keep_three_significant_digits() {
        assert_eq!(significant(0.000123456, 3), "0.000123");
        assert_eq!(significant(0.0021, 3), "0.00210");
        assert_eq!(significant(12.345, 3), "12.3");
        assert_eq!(significant(1234.5, 3), "1234");
        assert_eq!(significant(0.0, 3), "0");
    }
}
