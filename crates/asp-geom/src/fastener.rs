//! Fasteners (issue 9 item 5): a part's axis of near rotational symmetry, and *threaded*
//! contacts, along whose axis a bolt or nut leaves by screwing.
//!
//! A bolt, screw or nut is nearly invariant under rotations about its axis: a thread turned by
//! 60° is the same thread shifted by a sixth of its pitch, a hexagon is exactly invariant. So a
//! part has a symmetry axis when, for one of its principal axes (whose two transverse moments
//! agree), its surface sample turned by 60°, 120° and 180° about it stays within a few percent of
//! its radius of its own surface. A pair (`p`, `q`) is threaded when `p` has such an axis, the
//! two touch or overlap, and the part of `q`'s surface near `p`'s axis (the hole or the nut's
//! bore) is invariant under the same rotations. Along that axis the pair's thread zone — the
//! cylinder around the axis out to `p`'s largest radius in contact with `q` on its side faces
//! (not its head's bearing face) — is invariant under the screw motion, so the removal test of
//! the pair along the axis exempts surface samples inside that cylinder and tests the rest by
//! the strict sample rule ([`crate::overlap`]): a bolt's head still cannot pass through the plate
//! it bears on, but its thread turns out of the nut.

use crate::erode::symmetric_eigen;
use crate::graph::sample::sample_triangles;
use crate::math::Vec3;
use parry3d::math::Mat3;
use parry3d::query::PointQuery;
use parry3d::shape::TriMesh;

/// Rotations a fastener must be nearly invariant under (degrees).
const ANGLES_DEG: [f32; 3] = [60.0, 120.0, 180.0];
/// The share of turned samples that must land near the surface.
const AGREEMENT: f32 = 0.9;
/// How near (a fraction of the part's radius about the axis).
const SLACK: f32 = 0.06;
/// Samples per part for the symmetry test.
const SAMPLES: usize = 1500;

/// A line about which a part is nearly rotationally symmetric.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SymmetryAxis {
    /// A point on the axis (the surface's area centroid).
    pub point: Vec3,
    /// Unit direction.
    pub direction: Vec3,
    /// The largest distance of the surface from the axis.
    pub radius: f32,
}

impl SymmetryAxis {
    /// The distance of `x` from the axis line.
    pub fn radial(&self, x: Vec3) -> f32 {
        let r = x - self.point;
        (r - self.direction * r.dot(self.direction)).length()
    }

    /// `x` turned by `angle` (radians) about the axis.
    pub fn turn(&self, x: Vec3, angle: f32) -> Vec3 {
        let rot = crate::math::Rot::from_axis_angle(self.direction, angle);
        self.point + rot * (x - self.point)
    }
}

/// Whether at least [`AGREEMENT`] of `points`, turned by each of [`ANGLES_DEG`] about `axis`,
/// lie within `slack` of `mesh`'s surface.
fn invariant(points: &[Vec3], axis: &SymmetryAxis, mesh: &TriMesh, slack: f32) -> bool {
    if points.is_empty() {
        return false;
    }
    ANGLES_DEG.iter().all(|deg| {
        let near = points
            .iter()
            .filter(|&&x| {
                let y = axis.turn(x, deg.to_radians());
                (mesh.project_local_point(y, false).point - y).length() <= slack
            })
            .count();
        near as f32 >= AGREEMENT * points.len() as f32
    })
}

/// The axis of near rotational symmetry of a closed part's surface, if it has one.
pub fn symmetry_axis(mesh: &TriMesh) -> Option<SymmetryAxis> {
    let sample = sample_triangles(mesh.vertices(), mesh.indices(), SAMPLES);
    if sample.len() < 24 {
        return None;
    }
    let c = sample.centroid()?;
    let mut cov = [[0.0f64; 3]; 3];
    let total: f64 = sample.weights.iter().map(|&w| w as f64).sum();
    for (p, &w) in sample.points.iter().zip(&sample.weights) {
        let d = *p - c;
        for i in 0..3 {
            for j in 0..3 {
                cov[i][j] += w as f64 * d[i] as f64 * d[j] as f64;
            }
        }
    }
    let col = |j: usize| Vec3::new((cov[0][j] / total) as f32, (cov[1][j] / total) as f32, (cov[2][j] / total) as f32);
    let (values, vectors) = symmetric_eigen(Mat3::from_cols(col(0), col(1), col(2)));
    for k in 0..3 {
        let (a, b) = (values[(k + 1) % 3], values[(k + 2) % 3]);
        if (a - b).abs() > 0.15 * a.abs().max(b.abs()) {
            continue; // a rotationally symmetric surface has equal transverse moments
        }
        let Some(direction) = vectors[k].try_normalize() else { continue };
        let mut axis = SymmetryAxis { point: c, direction, radius: 0.0 };
        axis.radius = sample.points.iter().map(|&x| axis.radial(x)).fold(0.0, f32::max);
        if axis.radius > 0.0 && invariant(&sample.points, &axis, mesh, SLACK * axis.radius) {
            return Some(axis);
        }
    }
    None
}

/// A threaded contact of part `p` (with axis `axis`) with part `q`: the radius of the thread zone
/// about the axis.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Thread {
    /// The moving part's symmetry axis.
    pub axis: SymmetryAxis,
    /// Samples closer to the axis than this are in the thread zone.
    pub radius: f32,
}

/// Whether `p` (surface `pm`, symmetry axis `axis`) and `q` (surface `qm`) are in threaded
/// contact: `p`'s side faces touch or cut `q` (within `contact`), and `q`'s surface near the axis
/// is invariant under the same rotations. `None` otherwise.
pub fn threaded_contact(axis: &SymmetryAxis, pm: &TriMesh, qm: &TriMesh, contact: f32) -> Option<Thread> {
    let ps = sample_triangles(pm.vertices(), pm.indices(), 4 * SAMPLES);
    // p's side faces (not its head's bearing face) in contact with q: the thread zone's radius
    let mut radius = 0.0f32;
    for (x, n) in ps.points.iter().zip(&ps.normals) {
        if n.dot(axis.direction).abs() >= 0.9 {
            continue;
        }
        let proj = qm.project_local_point(*x, true);
        if (proj.point - *x).length() <= contact {
            radius = radius.max(axis.radial(*x));
        }
    }
    if radius <= 0.0 {
        return None;
    }
    let radius = radius + contact;
    // q's surface within the zone (and p's axial extent) must be symmetric about the same axis
    let along = |x: Vec3| (x - axis.point).dot(axis.direction);
    let (lo, hi) = ps.points.iter().fold((f32::INFINITY, f32::NEG_INFINITY), |(l, h), &x| (l.min(along(x)), h.max(along(x))));
    let qs = sample_triangles(qm.vertices(), qm.indices(), 4 * SAMPLES);
    // a bore: q's faces around p's side (not a plane p is pushed into, which is symmetric too)
    let local: Vec<Vec3> = qs
        .points
        .iter()
        .zip(&qs.normals)
        .filter(|(x, n)| axis.radial(**x) <= radius && (lo..=hi).contains(&along(**x)) && n.dot(axis.direction).abs() < 0.9)
        .map(|(x, _)| *x)
        .collect();
    if local.len() < 24 {
        return None;
    }
    invariant(&local, axis, qm, SLACK * axis.radius).then_some(Thread { axis: *axis, radius })
}
