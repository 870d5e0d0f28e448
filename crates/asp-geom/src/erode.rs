//! Shrinking a closed mesh by a distance (erosion), the core of the tolerant removal test.
//!
//! A part shrunk by the contact tolerance no longer touches its neighbours, so a shape cast of
//! the shrunk part hits a neighbour only when the motion pushes into it deeper than the
//! tolerance: sliding along a face or a zero-clearance shaft leaving its hole is free (see
//! `research/parry-removal-test.md`: this was the only strategy right on every fixture).

use crate::math::{Aabb, Vec3};
use parry3d::math::Mat3;
use std::collections::HashMap;

/// Two unit normals closer than this (cosine) are one plane.
const SAME_PLANE: f32 = 0.9995;

/// Shrinks a closed, outward-wound mesh by `amount`: every vertex moves inward by the
/// least-squares miter offset over the distinct normals of the faces around it (exact at box
/// corners and edges), clamped to `3 × amount`.
///
/// A *saddle* vertex — where the offset planes of the faces around it have no common point, e.g.
/// faces facing `+z` and `-z` meet there, as on many voxel shapes — is split: each triangle
/// corner there takes the offset of its own plane and of the other planes in order of how near
/// their faces lie to the corner, skipping any plane that would leave no common point. The
/// shrunk surface then has cracks of about `amount` at such vertices, but no face of it stays
/// closer than `amount` to the original surface (a single shared point would have to stay on
/// some of the original faces). Returns the new vertices and triangles.
pub fn eroded_mesh(vertices: &[Vec3], triangles: &[[u32; 3]], amount: f32) -> (Vec<Vec3>, Vec<[u32; 3]>) {
    let face_normals: Vec<Option<Vec3>> = triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| vertices[i as usize]);
            let n = (b - a).cross(c - a);
            let len = n.length();
            (len > 0.0 && len.is_finite()).then(|| n / len)
        })
        .collect();
    let mut normals: Vec<Vec<Vec3>> = vec![Vec::new(); vertices.len()];
    for (t, n) in triangles.iter().zip(&face_normals) {
        let Some(n) = *n else { continue };
        for &i in t {
            push_distinct(&mut normals[i as usize], n);
        }
    }
    let mut out: Vec<Vec3> = Vec::with_capacity(vertices.len());
    let mut saddle = vec![false; vertices.len()];
    for (i, (v, ns)) in vertices.iter().zip(&normals).enumerate() {
        let (o, consistent) = miter_offset(ns, amount);
        saddle[i] = !consistent;
        out.push(*v + o);
    }
    if !saddle.iter().any(|&s| s) {
        return (out, triangles.to_vec());
    }
    // each triangle corner at a saddle vertex gets its own vertex, shared by the corners whose
    // offsets agree
    let mut corners: HashMap<u32, Vec<(usize, Vec3, Vec3)>> = HashMap::new(); // (triangle, bisector, normal)
    for (k, t) in triangles.iter().enumerate() {
        let Some(n) = face_normals[k] else { continue };
        for c in 0..3 {
            if saddle[t[c] as usize] {
                let v = vertices[t[c] as usize];
                let a = (vertices[t[(c + 1) % 3] as usize] - v).normalize_or_zero();
                let b = (vertices[t[(c + 2) % 3] as usize] - v).normalize_or_zero();
                corners.entry(t[c]).or_default().push((k, (a + b).normalize_or_zero(), n));
            }
        }
    }
    let mut split: HashMap<(u32, [u32; 3]), u32> = HashMap::new();
    let mut tris = triangles.to_vec();
    let mut saddles: Vec<u32> = corners.keys().copied().collect();
    saddles.sort_unstable();
    for v in saddles {
        let list = &corners[&v];
        for &(k, bisector, own) in list {
            // the planes of the faces nearest this corner (by the angle between the corners'
            // bisectors), each kept only while all kept planes still meet in one point
            let mut order: Vec<(f32, Vec3)> = normals[v as usize]
                .iter()
                .map(|&n| {
                    let near = list.iter().filter(|c| c.2.dot(n) > SAME_PLANE).map(|c| c.1.dot(bisector)).fold(f32::NEG_INFINITY, f32::max);
                    (if n.dot(own) > SAME_PLANE { f32::INFINITY } else { near }, n)
                })
                .collect();
            order.sort_by(|a, b| b.0.total_cmp(&a.0));
            let mut kept: Vec<Vec3> = Vec::with_capacity(order.len());
            for (_, n) in order {
                kept.push(n);
                if !miter_offset(&kept, amount).1 {
                    kept.pop();
                }
            }
            let p = vertices[v as usize] + miter_offset(&kept, amount).0;
            let index = *split.entry((v, [p.x, p.y, p.z].map(f32::to_bits))).or_insert_with(|| {
                out.push(p);
                (out.len() - 1) as u32
            });
            let c = triangles[k].iter().position(|&x| x == v).expect("corner of its triangle");
            tris[k][c] = index;
        }
    }
    (out, tris)
}

/// The triangles of [`eroded_mesh`]`(vertices, triangles, amount)` that may reach `region`,
/// eroded exactly as there, at the cost of the triangles near the region (so an
/// overlapping pair's trial erosions shrink only the part of a mesh near the other part).
///
/// A vertex moves by at most `3 × amount`, so a triangle whose box, grown by twice that, misses
/// `region` cannot reach it and is left out. A vertex's offset depends only on the faces around
/// it, taken in triangle order: the triangles kept are eroded together with every triangle
/// sharing a vertex with them (in their original order), which gives them the same vertices,
/// bit for bit, as the erosion of the whole mesh. Returns the vertices (indexed as
/// [`eroded_mesh`] indexes them for the sub-mesh) and the kept triangles only.
pub fn eroded_near(vertices: &[Vec3], triangles: &[[u32; 3]], amount: f32, region: &Aabb) -> (Vec<Vec3>, Vec<[u32; 3]>) {
    let margin = Vec3::splat(6.0 * amount.abs());
    let (lo, hi) = (region.mins - margin, region.maxs + margin);
    let near = |t: &[u32; 3]| {
        let [a, b, c] = t.map(|i| vertices[i as usize]);
        let (tmin, tmax) = (a.min(b).min(c), a.max(b).max(c));
        // a NaN vertex keeps its triangle (as the whole mesh's erosion would)
        !(tmin.cmpgt(hi).any() || tmax.cmplt(lo).any())
    };
    let keep: Vec<bool> = triangles.iter().map(near).collect();
    let mut marked = vec![false; vertices.len()];
    for (t, _) in triangles.iter().zip(&keep).filter(|(_, &k)| k) {
        for &i in t {
            marked[i as usize] = true;
        }
    }
    // the kept triangles and their neighbours, in order; which of them are kept
    let (ring, kept): (Vec<[u32; 3]>, Vec<bool>) =
        triangles.iter().zip(&keep).filter(|(t, _)| t.iter().any(|&i| marked[i as usize])).map(|(t, &k)| (*t, k)).unzip();
    let (out, tris) = eroded_mesh(vertices, &ring, amount);
    let tris = tris.into_iter().zip(kept).filter(|&(_, k)| k).map(|(t, _)| t).collect();
    (out, tris)
}

fn push_distinct(list: &mut Vec<Vec3>, n: Vec3) {
    if !list.iter().any(|m| m.dot(n) > SAME_PLANE) {
        list.push(n);
    }
}

/// The offset `o` minimising `Σ (n·o + amount)²` with the least norm (the planes' common point
/// when they have one), clamped to `3 × amount`, and whether it satisfies every plane (all
/// faces' offset planes meet there).
fn miter_offset(normals: &[Vec3], amount: f32) -> (Vec3, bool) {
    // the common cases in closed form (the same point as the pseudo-inverse): a face's inside,
    // an edge, a corner of three independent planes
    let (o, consistent) = match normals {
        [] => (Vec3::ZERO, true),
        [n] => (*n * -amount, true),
        [n1, n2] if n1.dot(*n2) > -0.999 => ((*n1 + *n2) * (-amount / (1.0 + n1.dot(*n2))), true),
        [n1, n2, n3] if Mat3::from_cols(*n1, *n2, *n3).determinant().abs() > 1e-3 => {
            (Mat3::from_cols(*n1, *n2, *n3).transpose().inverse() * Vec3::splat(-amount), true)
        }
        _ => least_squares_offset(normals, amount),
    };
    let limit = 3.0 * amount;
    (if o.length() > limit { o.normalize() * limit } else { o }, consistent)
}

/// The offset `o` minimising `Σ (n·o + amount)²` with the least norm (pseudo-inverse), and
/// whether it satisfies every plane (all faces' offset planes meet there); not clamped.
fn least_squares_offset(normals: &[Vec3], amount: f32) -> (Vec3, bool) {
    let mut a = Mat3::ZERO;
    let mut b = Vec3::ZERO;
    for n in normals {
        a += Mat3::from_cols(*n * n.x, *n * n.y, *n * n.z);
        b -= *n * amount;
    }
    let (values, vectors) = symmetric_eigen(a);
    let max = values.iter().copied().fold(0.0f32, f32::max);
    let mut o = Vec3::ZERO;
    for (l, v) in values.into_iter().zip(vectors) {
        if l > max * 1e-3 {
            o += v * (v.dot(b) / l);
        }
    }
    let consistent = normals.iter().all(|n| (n.dot(o) + amount).abs() <= 0.1 * amount);
    (o, consistent)
}

/// Eigenvalues and unit eigenvectors of a symmetric 3×3 matrix by cyclic Jacobi rotations
/// (parry's `SymmetricEigen3` returned wrong eigenvectors for `diag(1, 0, 0)`).
pub(crate) fn symmetric_eigen(m: Mat3) -> ([f32; 3], [Vec3; 3]) {
    let mut a = [[0.0f64; 3]; 3];
    for (i, row) in a.iter_mut().enumerate() {
        for (j, x) in row.iter_mut().enumerate() {
            *x = m.col(j)[i] as f64;
        }
    }
    let mut v = [[1.0f64, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    for _ in 0..32 {
        let off = a[0][1].abs() + a[0][2].abs() + a[1][2].abs();
        if off <= 1e-15 * (a[0][0].abs() + a[1][1].abs() + a[2][2].abs()).max(f64::MIN_POSITIVE) {
            break;
        }
        for (p, q) in [(0, 1), (0, 2), (1, 2)] {
            if a[p][q] == 0.0 {
                continue;
            }
            let theta = (a[q][q] - a[p][p]) / (2.0 * a[p][q]);
            let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
            let t = if theta == 0.0 { 1.0 } else { t };
            let (c, s) = (1.0 / (t * t + 1.0).sqrt(), t / (t * t + 1.0).sqrt());
            // A ← Jᵀ A J: columns p, q, then rows p, q
            for row in a.iter_mut() {
                let (akp, akq) = (row[p], row[q]);
                row[p] = c * akp - s * akq;
                row[q] = s * akp + c * akq;
            }
            let (rp, rq) = (a[p], a[q]);
            for k in 0..3 {
                a[p][k] = c * rp[k] - s * rq[k];
                a[q][k] = s * rp[k] + c * rq[k];
            }
            for row in v.iter_mut() {
                let (vp, vq) = (row[p], row[q]);
                row[p] = c * vp - s * vq;
                row[q] = s * vp + c * vq;
            }
        }
    }
    let values = [a[0][0] as f32, a[1][1] as f32, a[2][2] as f32];
    let vectors = [0, 1, 2].map(|k| Vec3::new(v[0][k] as f32, v[1][k] as f32, v[2][k] as f32));
    (values, vectors)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::Mesh;
    use parry3d::query::PointQuery;
    use parry3d::shape::{TriMesh, TriMeshFlags};

    #[test]
    fn a_box_shrinks_exactly() {
        let m = Mesh::cuboid(Vec3::ZERO, Vec3::new(1.0, 2.0, 3.0));
        let (e, t) = eroded_mesh(&m.vertices, &m.triangles, 0.1);
        assert_eq!(t, m.triangles, "no saddle, no split");
        let bb = crate::math::aabb_of(e).unwrap();
        assert!((bb.mins - Vec3::splat(0.1)).abs().max_element() < 1e-5, "{bb:?}");
        assert!((bb.maxs - Vec3::new(0.9, 1.9, 2.9)).abs().max_element() < 1e-5, "{bb:?}");
    }

    #[test]
    fn an_l_shape_keeps_its_concave_corner_offset() {
        let m = Mesh::from_voxels(&[[0, 0, 0], [1, 0, 0], [0, 1, 0]], Vec3::ONE, Vec3::ZERO);
        let (e, _) = eroded_mesh(&m.vertices, &m.triangles, 0.1);
        // the concave corner at (1,1,0) moves into the solid by the tolerance along every face normal
        let i = m.vertices.iter().position(|v| *v == Vec3::new(1.0, 1.0, 0.0)).unwrap();
        assert!((e[i] - Vec3::new(0.9, 0.9, 0.1)).length() < 1e-5, "{:?}", e[i]);
    }

    /// Every vertex of the shrunk mesh lies inside the original solid, at least `amount` from
    /// its surface.
    fn assert_shrunk_by(m: &Mesh, amount: f32) {
        let mut m = m.clone();
        m.weld();
        m.orient_outward();
        let solid = TriMesh::with_flags(m.vertices.clone(), m.triangles.clone(), TriMeshFlags::ORIENTED).unwrap();
        let (e, t) = eroded_mesh(&m.vertices, &m.triangles, amount);
        for tri in &t {
            for &i in tri {
                let p = solid.project_local_point(e[i as usize], false);
                let depth = (p.point - e[i as usize]).length();
                assert!(p.is_inside && depth >= 0.999 * amount, "vertex {:?}: inside {}, depth {depth}", e[i as usize], p.is_inside);
            }
        }
    }

    #[test]
    fn eigen_decomposition_of_rank_one_and_full_matrices() {
        for n in [Vec3::X, -Vec3::X, Vec3::Y, Vec3::Z, Vec3::new(1.0, 2.0, -2.0) / 3.0] {
            let (o, consistent) = miter_offset(&[n], 0.01);
            assert!(consistent && (o + n * 0.01).length() < 1e-6, "{n:?}: {o:?}");
        }
        let m = Mat3::from_cols(Vec3::new(2.0, 1.0, 0.0), Vec3::new(1.0, 3.0, 1.0), Vec3::new(0.0, 1.0, 4.0));
        let (values, vectors) = symmetric_eigen(m);
        for (l, v) in values.into_iter().zip(vectors) {
            assert!((m * v - v * l).length() < 1e-5 && (v.length() - 1.0).abs() < 1e-5, "{l} {v:?}");
        }
    }

    #[test]
    fn closed_forms_meet_every_plane() {
        let mut seed = 7u32;
        let mut unit = || {
            let mut r = || {
                seed = seed.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
                (seed >> 8) as f32 / (1u32 << 24) as f32 * 2.0 - 1.0
            };
            Vec3::new(r(), r(), r()).normalize()
        };
        for count in 1..=3 {
            for _ in 0..200 {
                let ns: Vec<Vec3> = (0..count).map(|_| unit()).collect();
                let (fast, ok) = miter_offset(&ns, 0.01);
                let (slow, exact) = least_squares_offset(&ns, 0.01);
                // one face or an edge: the same point as the pseudo-inverse; three planes: their
                // exact common point (the pseudo-inverse, dropping small eigenvalues, is only
                // within a tenth of the erosion of every plane there)
                if count < 3 {
                    let slow = if slow.length() > 0.03 { slow.normalize() * 0.03 } else { slow };
                    assert!(ok && exact && (fast - slow).length() < 1e-5, "{ns:?}: {fast:?} vs {slow:?}");
                }
                if ok {
                    let unclamped = fast.length() < 0.0299;
                    assert!(!unclamped || ns.iter().all(|n| (n.dot(fast) + 0.01).abs() < 1e-5), "{ns:?}: {fast:?}");
                }
            }
        }
    }

    /// The trial erosions of an overlapping pair shrink only the triangles
    /// near the other part; those triangles are the whole erosion's, bit for bit (saddle splits
    /// included), and every triangle of the whole erosion that reaches the region is among them.
    #[test]
    fn erosion_near_a_region_is_the_whole_erosion_there() {
        let cells: Vec<[i32; 3]> = (0..4).flat_map(|x| (0..3).map(move |y| [x, y, (x * y) % 2])).collect();
        let voxels = Mesh::from_voxels(&cells, Vec3::ONE, Vec3::ZERO);
        let mut prism = crate::fixtures::prism(0.5, 0.5, 0.6, -0.3, 1.4, 24);
        prism.weld();
        prism.orient_outward();
        for (m, amounts) in [(&voxels, [0.01f32, 0.2]), (&prism, [0.001, 0.1])] {
            for amount in amounts {
                let (whole_v, whole_t) = eroded_mesh(&m.vertices, &m.triangles, amount);
                let regions = [
                    ([0.8, 0.8, -1.0], [1.6, 1.2, 3.0]),
                    ([-1.0, -1.0, -1.0], [0.2, 5.0, 0.1]),
                    // thin slabs just inside the bottom faces, which the shrunk faces move into
                    ([-1.0, -1.0, 0.009], [5.0, 5.0, 0.011]),
                    ([-1.0, -1.0, -0.2995], [5.0, 5.0, -0.2985]),
                    ([9.0, 9.0, 9.0], [10.0, 10.0, 10.0]),
                ];
                for (lo, hi) in regions {
                    let region = Aabb::new(Vec3::from(lo), Vec3::from(hi));
                    let (near_v, near_t) = eroded_near(&m.vertices, &m.triangles, amount, &region);
                    let corners = |v: &[Vec3], t: &[u32; 3]| t.map(|i| v[i as usize].to_array().map(f32::to_bits));
                    let whole: Vec<_> = whole_t.iter().map(|t| corners(&whole_v, t)).collect();
                    let near: Vec<_> = near_t.iter().map(|t| corners(&near_v, t)).collect();
                    // the kept triangles are the whole erosion's, in order
                    let mut rest = whole.iter();
                    for t in &near {
                        assert!(
                            rest.any(|w| w == t),
                            "amount {amount}, region {region:?}: a kept triangle differs from the whole erosion's"
                        );
                    }
                    // none that reaches the region is left out
                    for (t, w) in whole_t.iter().zip(&whole) {
                        let b = crate::math::aabb_of(t.map(|i| whole_v[i as usize])).unwrap();
                        let meets = (0..3).all(|k| b.mins[k] <= region.maxs[k] && b.maxs[k] >= region.mins[k]);
                        assert!(
                            !meets || near.contains(w),
                            "amount {amount}, region {region:?}: a triangle reaching the region was left out"
                        );
                    }
                    if hi[0] > 5.0 {
                        assert!(near.is_empty(), "a region away from the mesh keeps no triangle");
                    }
                }
            }
        }
    }

    #[test]
    fn saddle_vertices_are_split_so_every_face_moves_inward() {
        // classic Soma piece B: at (1, 2, 1) faces facing +x and -x meet; the least-squares
        // offset over all faces left that vertex on the top face of cell (1, 2, 0)
        let b = Mesh::from_voxels(&[[0, 2, 0], [1, 2, 0], [1, 1, 1], [1, 2, 1]], Vec3::ONE, Vec3::ZERO);
        assert_shrunk_by(&b, 0.01);
        let (e, _) = eroded_mesh(&b.vertices, &b.triangles, 0.01);
        assert!(e.len() > b.vertices.len(), "the saddle vertex was not split");
        for cells in [&[[0, 0, 0], [1, 0, 0], [1, 1, 0], [1, 1, 1]][..], &[[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]]] {
            assert_shrunk_by(&Mesh::from_voxels(cells, Vec3::splat(0.05), Vec3::ZERO), 1e-4);
        }
    }
}
