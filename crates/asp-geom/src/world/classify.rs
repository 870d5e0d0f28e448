//! Every overlapping pair classified by the shape of its overlap ([`OverlapClass`]): a coaxial
//! fit, a tessellation artefact (no deeper than the facets' sagittas), a planar slab (a panel
//! sunk into another between parallel planar faces; its normal joins the candidate directions,
//! the one lift that separates the pair), or interpenetration.

use super::fits::{Fits, AXIS_ALIGNED};
use super::overlaps::Overlaps;
use super::shapes::Shapes;
use crate::fits::{Cylinder, FitClass, Plane};
use crate::math::{Aabb, Vec3};
use crate::overlap::{self, OverlapClass, OverlapNote, OverlapRegion};
use rayon::prelude::*;
use std::collections::BTreeMap;

/// The overlap regions measured with the contacts, per pair (low, high).
pub(super) type Regions = BTreeMap<(usize, usize), OverlapRegion>;

/// Two planar faces of a slab face each other: their outward normals' cosine is below minus this
/// (about 1.8°).
const FACING: f32 = 0.9995;
/// A slab is thin: its thickness is at most this fraction of its narrowest width across the
/// normal (a panel sunk 2 mm into another over 20 mm or more; a dowel 10 mm into a board is no
/// slab).
const SLAB_THIN: f32 = 0.25;
/// At least this share of the overlap region's samples lies between the slab's two faces.
const SLAB_SHARE: f32 = 0.98;
/// The slab's thickness (the two faces' distance) and the measured depth agree within this
/// fraction of the depth, plus two tolerances.
const SLAB_DEPTH: f32 = 0.25;
/// The most planar faces per part that may bound a slab (the largest near the other part).
const SLAB_FACES: usize = 64;

/// Classifies every overlap note (after the fits are found: a pair with a fit that is not a
/// clearance fit is one), in parallel, measuring the overlap region of the pairs whose
/// depth the contacts measured by shrinking; each slab's normal, both ways, joins the
/// candidate directions unless one lies within 0.1°.
pub(super) fn classify_overlaps(overlaps: &mut Overlaps, shapes: &Shapes, distance: f32, directions: &mut Vec<Vec3>, regions: Regions) {
    let (notes, fits) = (&overlaps.notes, &overlaps.fits);
    let classes: Vec<(OverlapClass, Option<Vec3>)> =
        notes.par_iter().map(|n| classify(shapes, fits, distance, n, regions.get(&n.parts))).collect();
    for (n, (class, normal)) in overlaps.notes.iter_mut().zip(classes) {
        n.class = class;
        n.normal = normal;
    }
    let normals: Vec<Vec3> = overlaps.notes.iter().filter_map(|n| n.normal).collect();
    for n in normals {
        for d in [n, -n] {
            if !directions.iter().any(|e| e.dot(d) > AXIS_ALIGNED) {
                directions.push(d);
            }
        }
    }
}

/// The class of one overlap note, and a slab's normal (the first part's outward normal).
fn classify(
    shapes: &Shapes,
    fits: &Fits,
    distance: f32,
    note: &OverlapNote,
    region: Option<&OverlapRegion>,
) -> (OverlapClass, Option<Vec3>) {
    let (i, j) = note.parts;
    if fits.between(i, j).iter().any(|f| f.class != FitClass::Clearance) {
        return (OverlapClass::Fit, None);
    }
    let common = common_box(shapes, distance, i, j);
    let measured;
    let region = match region {
        Some(r) => r,
        None => {
            measured = overlap::overlap_region(shapes.mesh(i), shapes.mesh(j), overlap::REGION_SAMPLES);
            &measured
        }
    };
    // two faceted round faces of one surface, one of each part, that the overlap lies on:
    // coaxial, of one radius within their sagittas; their sagittas together
    let points: Vec<Vec3> = region.points().collect();
    let tol = shapes.tolerance();
    let on = |c: &Cylinder| {
        cylinder_meets(c, &common)
            && points.iter().any(|&x| (crate::surface::radial(x, c.point, c.axis) - c.radius).abs() <= c.tolerance + 2.0 * tol)
    };
    let faces = |k: usize| -> Vec<&Cylinder> { shapes.surfaces(k).cylinders.iter().filter(|c| on(c)).collect() };
    let (ci, cj) = (faces(i), faces(j));
    let parallel = 1.5f32.to_radians().cos();
    let sagitta = ci
        .iter()
        .flat_map(|a| cj.iter().map(move |b| (a, b)))
        .filter(|(a, b)| {
            a.axis.dot(b.axis).abs() >= parallel
                && crate::surface::radial(b.point, a.point, a.axis) <= 0.1 * a.radius.min(b.radius)
                && (a.radius - b.radius).abs() <= a.tolerance + b.tolerance + 2.0 * tol
        })
        .map(|(a, b)| a.tolerance + b.tolerance)
        .fold(0.0, f32::max);
    if !note.bound && note.depth <= sagitta + 2.0 * tol {
        return (OverlapClass::Tessellation, None);
    }
    let depth = region.depth().unwrap_or(note.depth);
    match slab_normal(shapes, i, j, region, depth, &common) {
        Some(n) => (OverlapClass::PlanarSlab, Some(n)),
        None => (OverlapClass::Interpenetration, None),
    }
}

/// The two parts' common box, grown by the contact distance.
fn common_box(shapes: &Shapes, distance: f32, i: usize, j: usize) -> Aabb {
    let (a, b) = (shapes.aabb(i), shapes.aabb(j));
    let m = Vec3::splat(distance);
    Aabb::new(a.mins.max(b.mins) - m, a.maxs.min(b.maxs) + m)
}

/// The normal of the slab the overlap `region` of `i` and `j` (`depth` deep) is, if it is
/// one: a planar face of `i` and one of `j` facing each other, `i`'s lying inside `j` by
/// the depth (within [`SLAB_DEPTH`]), nearly every sample of the region ([`SLAB_SHARE`])
/// between the two, and the region thin across the normal ([`SLAB_THIN`]). The unit normal
/// is `i`'s outward one (`j` lifts off `i` along it); of several, the pair of largest faces.
fn slab_normal(shapes: &Shapes, i: usize, j: usize, region: &OverlapRegion, depth: f32, common: &Aabb) -> Option<Vec3> {
    let points: Vec<Vec3> = region.points().collect();
    if points.is_empty() {
        return None;
    }
    let (fi, fj) = (slab_faces(shapes, i, common), slab_faces(shapes, j, common));
    let tol = shapes.tolerance();
    let mut best: Option<(f32, Vec3)> = None;
    for (a, na) in &fi {
        for (b, nb) in &fj {
            if na.dot(*nb) > -FACING {
                continue;
            }
            let n = (*na - *nb).normalize_or_zero();
            // `i`'s face lies `gap` beyond `j`'s, into `j`
            let (ha, hb) = (a.point.dot(n), b.point.dot(n));
            let gap = ha - hb;
            if gap <= 0.0 || (gap - depth).abs() > SLAB_DEPTH * depth + 2.0 * tol {
                continue;
            }
            let slack = 2.0 * tol + 0.05 * gap;
            let within = points.iter().filter(|x| (hb - slack..=ha + slack).contains(&x.dot(n))).count();
            if (within as f32) < SLAB_SHARE * points.len() as f32 || gap > SLAB_THIN * width_across(&points, n) {
                continue;
            }
            let w = a.area.min(b.area);
            if best.is_none_or(|(bw, _)| w > bw) {
                best = Some((w, n));
            }
        }
    }
    best.map(|(_, n)| n)
}

/// Part `k`'s planar faces that reach the box `common`, the largest [`SLAB_FACES`], each with
/// its area-weighted mean normal (a sliver's own normal is too noisy to stand for a face).
fn slab_faces<'a>(shapes: &'a Shapes, k: usize, common: &Aabb) -> Vec<(&'a Plane, Vec3)> {
    let mesh = shapes.mesh(k);
    let (v, t) = (mesh.vertices(), mesh.indices());
    let mut faces: Vec<(&Plane, Vec3)> = shapes
        .surfaces(k)
        .planes
        .iter()
        .filter(|p| {
            p.triangles.iter().any(|&x| {
                let [a, b, c] = t[x as usize].map(|i| v[i as usize]);
                let (lo, hi) = (a.min(b).min(c), a.max(b).max(c));
                (0..3).all(|d| lo[d] <= common.maxs[d] && hi[d] >= common.mins[d])
            })
        })
        .map(|p| {
            let n: Vec3 = p
                .triangles
                .iter()
                .map(|&x| {
                    let [a, b, c] = t[x as usize].map(|i| v[i as usize]);
                    (b - a).cross(c - a)
                })
                .sum();
            (p, n.normalize_or_zero())
        })
        .filter(|(_, n)| *n != Vec3::ZERO)
        .collect();
    faces.sort_by(|a, b| b.0.area.total_cmp(&a.0.area));
    faces.truncate(SLAB_FACES);
    faces
}

/// Whether cylinder `c` (its axis segment grown by its radius) reaches box `b`.
fn cylinder_meets(c: &Cylinder, b: &Aabb) -> bool {
    let (p0, p1) = (c.point + c.axis * c.extent.0, c.point + c.axis * c.extent.1);
    let (lo, hi) = (p0.min(p1) - Vec3::splat(c.radius), p0.max(p1) + Vec3::splat(c.radius));
    (0..3).all(|d| lo[d] <= b.maxs[d] && hi[d] >= b.mins[d])
}

/// The narrowest extent of `points` across unit `n` (over eight directions normal to it).
fn width_across(points: &[Vec3], n: Vec3) -> f32 {
    let u = n.any_orthonormal_vector();
    let v = n.cross(u);
    (0..8)
        .map(|k| {
            let a = std::f32::consts::PI * k as f32 / 8.0;
            let d = u * a.cos() + v * a.sin();
            let (lo, hi) = points.iter().fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), x| (lo.min(x.dot(d)), hi.max(x.dot(d))));
            hi - lo
        })
        .fold(f32::INFINITY, f32::min)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fixtures::{stabbed_board, sunk_boards};
    use crate::math::Rot;
    use crate::world::{World, WorldConfig};

    /// A turn off every axis (the slab's normal is then no axis and no cluster of the model's).
    fn tilt() -> Rot {
        Rot::from_axis_angle(Vec3::new(1.0, 2.0, 0.5).normalize(), 0.3)
    }

    /// Two holed boards sunk 1.5 mm into each other are a planar slab 1.5 mm deep, its normal
    /// the lower board's top face's, at coarse and fine holes, on and off the axes: measured
    /// where they overlap when the boards are 3 mm sheets no shrinking up to 1.2 mm separates
    /// (the erosion bound said "more than 1.2 mm"; on thin-walled parts with a large box, tens
    /// of millimetres), by the least shrinking when they are 10 mm boards.
    #[test]
    fn boards_sunk_into_each_other_are_a_planar_slab_as_deep_as_they_are_sunk() {
        for (thickness, gross) in [(0.003, true), (0.010, false)] {
            for facets in [16, 96] {
                for turn in [Rot::IDENTITY, tilt()] {
                    let w = World::new(sunk_boards(facets, thickness, turn), &WorldConfig::default()).unwrap();
                    let notes = w.overlaps().notes();
                    assert_eq!(notes.len(), 1, "{facets}: {notes:?}");
                    let n = &notes[0];
                    assert_eq!((n.gross, n.bound), (gross, false), "{thickness} m, {facets} facets: {n:?}");
                    assert!((n.depth - 0.0015).abs() <= 0.1 * 0.0015, "{thickness} m, {facets}: depth {} m, sunk 1.5 mm", n.depth);
                    assert_eq!(n.class, OverlapClass::PlanarSlab, "{thickness} m, {facets}: {n:?}");
                    let normal = n.normal.expect("a slab has a normal");
                    assert!(normal.dot(turn * Vec3::Z) > 0.99999, "{facets}: {normal:?}");
                    assert!(w.blocking().directions().iter().any(|d| d.dot(normal) > AXIS_ALIGNED), "{facets}: the lift is a candidate");
                    if gross {
                        let said = w.warnings().iter().any(|s| s.contains("by about 0.001") && s.contains("measured where they overlap"));
                        assert!(said, "{:?}", w.warnings());
                    }
                }
            }
        }
    }

    /// A board stabbed 8 mm edge-first into another is no slab (its facing faces lie 8 mm apart
    /// across 10 mm) but interpenetration, however it is tessellated.
    #[test]
    fn a_board_stabbed_into_another_is_interpenetration() {
        for facets in [16, 96] {
            let w = World::new(stabbed_board(facets, tilt()), &WorldConfig::default()).unwrap();
            let n = &w.overlaps().notes()[0];
            assert_eq!((n.class, n.normal), (OverlapClass::Interpenetration, None), "{facets}: {n:?}");
            assert!(n.depth > 0.003 && n.depth < 0.0081, "{facets}: {n:?}");
        }
    }

    /// The shallow overlaps of a faceted bolt in its nut and holes are fits, not slabs; a
    /// peg pressed into a solid plate is interpenetration (its overlap is as deep as it is wide).
    #[test]
    fn fits_and_pressed_pegs_are_no_slabs() {
        let w = World::new(crate::fixtures::bolted_joint([24, 32, 24]), &WorldConfig::default()).unwrap();
        assert!(!w.overlaps().notes().is_empty());
        for n in w.overlaps().notes() {
            assert!(matches!(n.class, OverlapClass::Fit | OverlapClass::Tessellation), "{n:?}");
        }
        let w = World::new(crate::fixtures::pressed_peg(), &WorldConfig::default()).unwrap();
        let n = &w.overlaps().notes()[0];
        assert_eq!(n.class, OverlapClass::Interpenetration, "{n:?}");
        assert!((n.depth - 0.5).abs() < 0.05, "the peg is 0.5 into the plate: {n:?}");
    }

    #[test]
    fn a_square_is_as_wide_as_its_side_across_its_normal() {
        let square: Vec<Vec3> = (0..=10).flat_map(|x| (0..=10).map(move |y| Vec3::new(x as f32, y as f32, 0.0))).collect();
        assert!((width_across(&square, Vec3::Z) - 10.0).abs() < 1e-4);
        // across x: 10 along y, nothing along z
        assert!(width_across(&square, Vec3::X) < 1e-4);
    }
}
