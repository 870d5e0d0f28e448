//! A part's cylinders and planes, read from its B-rep faces where the file has them and
//! recognised from its triangles where it does not.
//!
//! **From triangles.** A tessellated cylinder is a ring of triangles whose normals are all
//! normal to its axis, each crease between neighbours a fraction of a turn (360°/n for an
//! n-gon; its two rims may be tessellated independently, so creases need not run along the
//! axis). So smooth regions are grown from each triangle: a neighbour joins across a crease of
//! at most [`CREASE_DEG`] when its normal is normal (within twice [`AXIS_DEG`]) to the region's
//! axis, the line the first two differing normals span; neighbours within [`FLAT_DEG`] of each
//! other share a flat facet. A region of one facet is a plane; a region of at least
//! [`MIN_FACETS`] facets is a cylinder when its vertices, projected on the plane normal to the
//! axis (refined over all its normals), lie on a circle (the least-squares fit, within
//! [`RESIDUAL`] of its radius). Its
//! tolerance is the chord's *sagitta*, `r (1 − cos(Δ/2))` for the widest facet's angle `Δ`: two
//! coaxial cylinders of one radius, faceted differently, overlap by up to the sum of theirs.
//!
//! **From the file.** A B-rep face's triangles are one group; an analytic cylinder or plane is
//! taken as it is (its tolerance the triangles' largest deviation from it), and a free-form face
//! (many exporters write round faces as B-splines) is fitted like a candidate above.

use super::{Cylinder, Plane, Surfaces};
use crate::erode::symmetric_eigen;
use crate::math::Vec3;
use crate::surface::{PartFaces, Surface, SurfaceSource};
use parry3d::math::Mat3;
use std::collections::HashMap;

/// Adjacent triangles whose normals differ by less than this (degrees) lie in one flat facet.
pub const FLAT_DEG: f32 = 0.5;
/// Two facets of one cylinder meet at a crease of at most this (degrees): an octagon's 45°.
pub const CREASE_DEG: f32 = 50.0;
/// A crease joins a cylinder when it runs along the cylinder's axis within this (degrees).
pub const AXIS_DEG: f32 = 2.0;
/// While a region's axis rests on a narrow angle, a normal may stray from normal to it by at
/// most this (the sine of 15°).
pub const MAX_STRAY: f32 = 0.26;
/// A cylinder has at least this many facets.
pub const MIN_FACETS: usize = 3;
/// Its vertices lie within this fraction of its radius of the fitted circle.
pub const RESIDUAL: f32 = 0.02;

/// The cylinders and planes of a closed, outward-oriented mesh (`vertices`, `triangles`), with
/// the file's B-rep `faces` (one face index per triangle of this mesh) when it has them.
pub fn surfaces(vertices: &[Vec3], triangles: &[[u32; 3]], faces: Option<&PartFaces>) -> Surfaces {
    let faces = faces.filter(|f| f.fits(triangles.len()));
    let normal = |t: &[u32; 3]| {
        let [a, b, c] = t.map(|i| vertices[i as usize]);
        (b - a).cross(c - a)
    };
    let normals: Vec<Vec3> = triangles.iter().map(|t| normal(t).normalize_or_zero()).collect();
    let areas: Vec<f32> = triangles.iter().map(|t| 0.5 * normal(t).length()).collect();
    // undirected edge -> the triangles using it
    let mut edges: HashMap<(u32, u32), Vec<u32>> = HashMap::new();
    for (k, t) in triangles.iter().enumerate() {
        for e in 0..3 {
            let (a, b) = (t[e], t[(e + 1) % 3]);
            edges.entry((a.min(b), a.max(b))).or_default().push(k as u32);
        }
    }
    let same_face = |a: u32, b: u32| faces.is_none_or(|f| f.triangle_face[a as usize] == f.triangle_face[b as usize]);
    // triangle adjacency across manifold edges
    let mut neighbours: Vec<Vec<u32>> = vec![Vec::new(); triangles.len()];
    let mut pairs: Vec<(u32, u32)> = edges.values().filter(|ts| ts.len() == 2).map(|ts| (ts[0], ts[1])).collect();
    pairs.sort_unstable(); // HashMap order is not deterministic
    for (a, b) in pairs {
        neighbours[a as usize].push(b);
        neighbours[b as usize].push(a);
    }
    // smooth regions grown from each unassigned triangle in order: a neighbour joins across a
    // crease of at most CREASE_DEG (within one B-rep face) when its normal is normal to the
    // region's axis, the line two of the region's differing normals span (a cylinder's
    // triangles, however its rims are tessellated); a region of one normal is a plane
    let flat = FLAT_DEG.to_radians().cos();
    let crease = CREASE_DEG.to_radians().cos();
    let across = (2.0 * AXIS_DEG).to_radians().sin();
    let mut region_of = vec![usize::MAX; triangles.len()];
    let mut axis: HashMap<usize, Vec3> = HashMap::new();
    let mut facet_of = vec![0usize; triangles.len()];
    for seed in 0..triangles.len() {
        if region_of[seed] != usize::MAX || normals[seed] == Vec3::ZERO {
            continue;
        }
        region_of[seed] = seed;
        facet_of[seed] = seed;
        // the axis: the seed's normal crossed with the region's normal most unlike it (the
        // wider the angle, the less the triangles' own noise tilts it), and how far a normal
        // may stray from normal to it while the angle is still narrow
        let n0 = normals[seed];
        let mut widest = Vec3::ZERO;
        let mut region_axis: Option<Vec3> = None;
        let mut queue = std::collections::VecDeque::from([seed as u32]);
        while let Some(t) = queue.pop_front() {
            for &u in &neighbours[t as usize] {
                if region_of[u as usize] != usize::MAX || !same_face(t, u) || normals[u as usize] == Vec3::ZERO {
                    continue;
                }
                let (nt, nu) = (normals[t as usize], normals[u as usize]);
                let c = nt.dot(nu);
                if c < crease {
                    continue;
                }
                if c >= flat {
                    // the same flat facet as `t` (and so normal to the region's axis, if any)
                    facet_of[u as usize] = facet_of[t as usize];
                } else {
                    if let Some(a) = region_axis {
                        let spread = widest.length();
                        if nu.dot(a).abs() > (across + 0.01 / spread.max(1e-3)).min(MAX_STRAY) {
                            continue;
                        }
                    }
                    let w = n0.cross(nu);
                    if w.length() > widest.length() {
                        widest = w;
                        region_axis = Some(w.normalize_or_zero());
                    }
                    facet_of[u as usize] = u as usize;
                }
                region_of[u as usize] = seed;
                queue.push_back(u);
            }
        }
        if let Some(a) = region_axis {
            axis.insert(seed, a);
        }
    }
    let mut members: HashMap<usize, Vec<u32>> = HashMap::new();
    for (t, &r) in region_of.iter().enumerate() {
        members.entry(if r == usize::MAX { t } else { r }).or_default().push(t as u32);
    }
    let mut keys: Vec<usize> = members.keys().copied().collect();
    keys.sort_unstable();
    let mut out = Surfaces::default();
    let mut used = vec![false; triangles.len()];
    // the file's analytic faces first
    if let Some(f) = faces {
        let mut by_face: HashMap<u32, Vec<u32>> = HashMap::new();
        for (t, &face) in f.triangle_face.iter().enumerate() {
            by_face.entry(face).or_default().push(t as u32);
        }
        let mut ids: Vec<u32> = by_face.keys().copied().collect();
        ids.sort_unstable();
        for id in ids {
            let tris = &by_face[&id];
            let face = &f.faces[id as usize];
            let area: f32 = tris.iter().map(|&t| areas[t as usize]).sum();
            match face.surface {
                Some(Surface::Cylinder { point, axis, radius }) => {
                    let tol = tris
                        .iter()
                        .flat_map(|&t| edge_midpoints(vertices, &triangles[t as usize]))
                        .map(|x| (crate::surface::radial(x, point, axis) - radius).abs())
                        .fold(0.0, f32::max);
                    let convex = convexity(vertices, triangles, &normals, &areas, tris, point, axis) > 0.0;
                    let extent = extent_along(vertices, triangles, tris, point, axis);
                    out.cylinders.push(Cylinder {
                        point,
                        axis,
                        radius,
                        convex,
                        tolerance: tol,
                        extent,
                        area,
                        triangles: tris.clone(),
                        source: face.source,
                    });
                    tris.iter().for_each(|&t| used[t as usize] = true);
                }
                Some(Surface::Plane { point, normal }) => {
                    // the triangles decide the side (outward)
                    let side: f32 = tris.iter().map(|&t| normals[t as usize].dot(normal) * areas[t as usize]).sum();
                    let normal = if side < 0.0 { -normal } else { normal };
                    out.planes.push(Plane { point, normal, area, triangles: tris.clone(), source: face.source });
                    tris.iter().for_each(|&t| used[t as usize] = true);
                }
                _ => {}
            }
        }
    }
    for g in keys {
        let tris = &members[&g];
        if tris.iter().any(|&t| used[t as usize]) {
            continue;
        }
        let area: f32 = tris.iter().map(|&t| areas[t as usize]).sum();
        if area.is_nan() || area <= 0.0 {
            continue;
        }
        let distinct_facets = {
            let mut f: Vec<usize> = tris.iter().map(|&t| facet_of[t as usize]).collect();
            f.sort_unstable();
            f.dedup();
            f.len()
        };
        if distinct_facets == 1 {
            let n = normals[tris[0] as usize];
            let point = vertices[triangles[tris[0] as usize][0] as usize];
            out.planes.push(Plane { point, normal: n, area, triangles: tris.clone(), source: SurfaceSource::Fitted });
            continue;
        }
        let Some(&a) = axis.get(&g) else { continue };
        if a == Vec3::ZERO || distinct_facets < MIN_FACETS {
            continue;
        }
        if let Some(c) = fit_cylinder(vertices, triangles, &normals, &areas, tris, a) {
            out.cylinders.push(c);
        }
    }
    out
}

/// The midpoints of a triangle's edges (where a chord strays furthest from its arc).
fn edge_midpoints(vertices: &[Vec3], t: &[u32; 3]) -> [Vec3; 3] {
    let [a, b, c] = t.map(|i| vertices[i as usize]);
    [(a + b) * 0.5, (b + c) * 0.5, (c + a) * 0.5]
}

/// Area-weighted mean of whether the triangles face away from the axis (a shaft: positive) or
/// towards it (a hole: negative).
fn convexity(vertices: &[Vec3], triangles: &[[u32; 3]], normals: &[Vec3], areas: &[f32], tris: &[u32], point: Vec3, axis: Vec3) -> f32 {
    tris.iter()
        .map(|&t| {
            let [a, b, c] = triangles[t as usize].map(|i| vertices[i as usize]);
            let r = (a + b + c) / 3.0 - point;
            let out = (r - axis * r.dot(axis)).normalize_or_zero();
            normals[t as usize].dot(out) * areas[t as usize]
        })
        .sum()
}

/// The range of the triangles' vertices along the axis, measured from `point`.
fn extent_along(vertices: &[Vec3], triangles: &[[u32; 3]], tris: &[u32], point: Vec3, axis: Vec3) -> (f32, f32) {
    tris.iter()
        .flat_map(|&t| triangles[t as usize])
        .map(|i| (vertices[i as usize] - point).dot(axis))
        .fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), h| (lo.min(h), hi.max(h)))
}

/// The cylinder through a group of facets whose creases run along `axis_hint`: the axis refined
/// as the direction the facets' normals are most nearly normal to, the circle fitted to the
/// vertices projected on the plane normal to it; `None` when they do not lie on one.
pub(super) fn fit_cylinder(
    vertices: &[Vec3],
    triangles: &[[u32; 3]],
    normals: &[Vec3],
    areas: &[f32],
    tris: &[u32],
    axis_hint: Vec3,
) -> Option<Cylinder> {
    // the axis: the eigenvector of the least eigenvalue of sum(area n n^T)
    let mut m = Mat3::ZERO;
    for &t in tris {
        let n = normals[t as usize];
        m += Mat3::from_cols(n * n.x, n * n.y, n * n.z) * areas[t as usize];
    }
    let (values, vectors) = symmetric_eigen(m);
    let k = (0..3).min_by(|&a, &b| values[a].total_cmp(&values[b])).unwrap_or(0);
    let mut axis = vectors[k].normalize_or_zero();
    if axis == Vec3::ZERO {
        axis = axis_hint.normalize_or_zero();
    }
    if axis.dot(axis_hint) < 0.0 {
        axis = -axis;
    }
    // every facet normal nearly normal to the axis
    if tris.iter().any(|&t| normals[t as usize].dot(axis).abs() > AXIS_DEG.to_radians().sin() * 2.0) {
        return None;
    }
    let (u, v) = axis.any_orthonormal_pair();
    let mut ids: Vec<u32> = tris.iter().flat_map(|&t| triangles[t as usize]).collect();
    ids.sort_unstable();
    ids.dedup();
    if ids.len() < 4 {
        return None;
    }
    let origin = vertices[ids[0] as usize];
    let pts: Vec<[f64; 2]> = ids
        .iter()
        .map(|&i| {
            let r = vertices[i as usize] - origin;
            [r.dot(u) as f64, r.dot(v) as f64]
        })
        .collect();
    let (cx, cy, r) = fit_circle(&pts)?;
    let radius = r as f32;
    let centre = origin + u * cx as f32 + v * cy as f32;
    let residual = pts.iter().map(|p| ((p[0] - cx).hypot(p[1] - cy) - r).abs()).fold(0.0f64, f64::max) as f32;
    if radius.is_nan() || radius <= 0.0 || residual > RESIDUAL * radius {
        return None;
    }
    // the angular span must not be a sliver of the circle (two nearly flat facets)
    let tolerance = tris
        .iter()
        .flat_map(|&t| edge_midpoints(vertices, &triangles[t as usize]))
        .map(|x| (crate::surface::radial(x, centre, axis) - radius).abs())
        .fold(residual, f32::max);
    if tolerance > 0.25 * radius {
        return None;
    }
    let convex = convexity(vertices, triangles, normals, areas, tris, centre, axis) > 0.0;
    let extent = extent_along(vertices, triangles, tris, centre, axis);
    let area: f32 = tris.iter().map(|&t| areas[t as usize]).sum();
    Some(Cylinder { point: centre, axis, radius, convex, tolerance, extent, area, triangles: tris.to_vec(), source: SurfaceSource::Fitted })
}

/// The least-squares circle through 2-D points (Kåsa's algebraic fit, centred for
/// conditioning): `(cx, cy, r)`, `None` when the points are collinear.
fn fit_circle(pts: &[[f64; 2]]) -> Option<(f64, f64, f64)> {
    let n = pts.len() as f64;
    let (mx, my) = pts.iter().fold((0.0, 0.0), |(a, b), p| (a + p[0] / n, b + p[1] / n));
    // solve [suu suv; suv svv] [a b] = 0.5 [suuu + suvv; svvv + svuu] on centred coordinates
    let (mut suu, mut suv, mut svv, mut ru, mut rv) = (0.0, 0.0, 0.0, 0.0, 0.0);
    for p in pts {
        let (x, y) = (p[0] - mx, p[1] - my);
        let s = x * x + y * y;
        suu += x * x;
        suv += x * y;
        svv += y * y;
        ru += 0.5 * x * s;
        rv += 0.5 * y * s;
    }
    let det = suu * svv - suv * suv;
    if det.abs() <= 1e-18 * (suu * svv).max(f64::MIN_POSITIVE) {
        return None;
    }
    let a = (ru * svv - rv * suv) / det;
    let b = (suu * rv - suv * ru) / det;
    let r2 = a * a + b * b + (suu + svv) / n;
    (r2 > 0.0).then(|| (a + mx, b + my, r2.sqrt()))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fixtures::prism;
    use crate::mesh::Mesh;

    #[test]
    fn a_circle_is_fitted_through_its_points() {
        let pts: Vec<[f64; 2]> = (0..7)
            .map(|k| {
                let a = k as f64 * 0.4;
                [3.0 + 2.0 * a.cos(), -1.0 + 2.0 * a.sin()]
            })
            .collect();
        let (cx, cy, r) = fit_circle(&pts).unwrap();
        assert!((cx - 3.0).abs() < 1e-9 && (cy + 1.0).abs() < 1e-9 && (r - 2.0).abs() < 1e-9);
        assert!(fit_circle(&[[0.0, 0.0], [1.0, 1.0], [2.0, 2.0]]).is_none());
    }

    #[test]
    fn a_faceted_rod_is_one_convex_cylinder_and_two_caps() {
        for n in [8usize, 26, 64] {
            let m = prism(1.0, 2.0, 0.5, 3.0, 7.0, n as u32);
            let s = surfaces(&m.vertices, &m.triangles, None);
            assert_eq!(s.cylinders.len(), 1, "{n}-gon");
            let c = &s.cylinders[0];
            assert!(c.convex);
            assert!((c.radius - 0.5).abs() < 1e-4, "{}", c.radius);
            assert!(c.axis.dot(Vec3::Z).abs() > 0.9999);
            let sag = 0.5 * (1.0 - (std::f32::consts::PI / n as f32).cos());
            assert!((c.tolerance - sag).abs() < 0.1 * sag + 1e-6, "{n}: {} vs {sag}", c.tolerance);
            assert!((c.extent.1 - c.extent.0 - 4.0).abs() < 1e-4);
            assert_eq!(s.planes.len(), 2);
        }
    }

    #[test]
    fn a_box_has_no_cylinder_and_a_hexagonal_prism_neither() {
        let m = Mesh::cuboid(Vec3::ZERO, Vec3::ONE);
        let s = surfaces(&m.vertices, &m.triangles, None);
        assert!(s.cylinders.is_empty());
        assert_eq!(s.planes.len(), 6);
        // six facets at 60 degrees: more than a cylinder's crease
        let hex = prism(0.0, 0.0, 1.0, 0.0, 1.0, 6);
        assert!(surfaces(&hex.vertices, &hex.triangles, None).cylinders.is_empty());
    }
}
