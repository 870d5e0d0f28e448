//! Shrinking a closed mesh by a distance (erosion), the core of the tolerant removal test.
//!
//! A part shrunk by the contact tolerance no longer touches its neighbours, so a shape cast of
//! the shrunk part hits a neighbour only when the motion pushes into it deeper than the
//! tolerance: sliding along a face or a zero-clearance shaft leaving its hole is free (see
//! `research/parry-removal-test.md`: this was the only strategy right on every fixture).

use crate::math::Vec3;
use parry3d::math::{Mat3, SymmetricEigen3};

/// Moves every vertex inward by `amount`: the least-squares miter offset over the distinct
/// normals of the faces around it (exact at box corners and edges), clamped to `3 × amount`.
/// The mesh must be closed and wound outward.
pub fn eroded_vertices(vertices: &[Vec3], triangles: &[[u32; 3]], amount: f32) -> Vec<Vec3> {
    let mut normals: Vec<Vec<Vec3>> = vec![Vec::new(); vertices.len()];
    for t in triangles {
        let [a, b, c] = t.map(|i| vertices[i as usize]);
        let n = (b - a).cross(c - a);
        let len = n.length();
        if len <= 0.0 || !len.is_finite() {
            continue;
        }
        let n = n / len;
        for &i in t {
            let list = &mut normals[i as usize];
            if !list.iter().any(|m| m.dot(n) > 0.9995) {
                list.push(n);
            }
        }
    }
    vertices
        .iter()
        .zip(&normals)
        .map(|(v, ns)| *v + miter_offset(ns, amount))
        .collect()
}

/// The offset `o` minimising `Σ (n·o + amount)²` with the least norm (pseudo-inverse).
fn miter_offset(normals: &[Vec3], amount: f32) -> Vec3 {
    if normals.is_empty() {
        return Vec3::ZERO;
    }
    let mut a = Mat3::ZERO;
    let mut b = Vec3::ZERO;
    for n in normals {
        a += Mat3::from_cols(*n * n.x, *n * n.y, *n * n.z);
        b -= *n * amount;
    }
    let eig = SymmetricEigen3::new(a);
    let max = eig.eigenvalues.max_element();
    let mut o = Vec3::ZERO;
    for k in 0..3 {
        let l = eig.eigenvalues[k];
        if l > max * 1e-3 {
            let v = eig.eigenvectors.col(k);
            o += v * (v.dot(b) / l);
        }
    }
    let limit = 3.0 * amount;
    if o.length() > limit {
        o = o.normalize() * limit;
    }
    o
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::Mesh;

    #[test]
    fn a_box_shrinks_exactly() {
        let m = Mesh::cuboid(Vec3::ZERO, Vec3::new(1.0, 2.0, 3.0));
        let e = eroded_vertices(&m.vertices, &m.triangles, 0.1);
        let bb = crate::math::aabb_of(e).unwrap();
        assert!((bb.mins - Vec3::splat(0.1)).abs().max_element() < 1e-5, "{bb:?}");
        assert!((bb.maxs - Vec3::new(0.9, 1.9, 2.9)).abs().max_element() < 1e-5, "{bb:?}");
    }

    #[test]
    fn an_l_shape_keeps_its_concave_corner_offset() {
        let m = Mesh::from_voxels(&[[0, 0, 0], [1, 0, 0], [0, 1, 0]], Vec3::ONE, Vec3::ZERO);
        let e = eroded_vertices(&m.vertices, &m.triangles, 0.1);
        // the concave corner at (1,1,0) moves into the solid by the tolerance along every face normal
        let i = m.vertices.iter().position(|v| *v == Vec3::new(1.0, 1.0, 0.0)).unwrap();
        assert!((e[i] - Vec3::new(0.9, 0.9, 0.1)).length() < 1e-5, "{:?}", e[i]);
    }
}
