//! Deterministic, area-weighted sampling of a triangle surface: the point clouds `Q_{p_i}` of
//! thesis eq. 3.5 from which descriptors and contact regions are computed.
//!
//! Triangle `t` of area `a_t` (of total `A`) is cut into `k_t²` congruent sub-triangles,
//! `k_t = max(1, round(√(N a_t / A)))` for a target of `N` points, and one point sits at the
//! centroid of each sub-triangle, carrying weight `a_t / k_t²` and the triangle's unit normal.
//! Every triangle with nonzero area gets at least its centroid, so a mesh of more than `N`
//! triangles gets more than `N` points. The pattern is symmetric in the triangle's corners and
//! the counts depend only on area ratios, so the sample is equivariant under rigid motions and
//! uniform scaling: the same triangles give the same points, transformed (weights scale with
//! area, which descriptors normalise away). No point lies on a triangle edge.

use crate::math::Vec3;
use crate::mesh::Mesh;

/// Sample points of a surface with their area weights and unit normals.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SurfaceSample {
    /// Point positions (same frame as the mesh).
    pub points: Vec<Vec3>,
    /// The surface area each point stands for (sums to the mesh's area).
    pub weights: Vec<f32>,
    /// The unit normal of each point's triangle (outward for an outward-wound mesh).
    pub normals: Vec<Vec3>,
}

impl SurfaceSample {
    /// Number of points.
    pub fn len(&self) -> usize {
        self.points.len()
    }

    /// Whether there are no points.
    pub fn is_empty(&self) -> bool {
        self.points.is_empty()
    }

    /// The area-weighted centroid (None when the sample is empty).
    pub fn centroid(&self) -> Option<Vec3> {
        let (mut total, mut sum) = (0.0f64, [0.0f64; 3]);
        for (p, &w) in self.points.iter().zip(&self.weights) {
            let w = w as f64;
            total += w;
            sum = [sum[0] + w * p.x as f64, sum[1] + w * p.y as f64, sum[2] + w * p.z as f64];
        }
        (total > 0.0).then(|| Vec3::new((sum[0] / total) as f32, (sum[1] / total) as f32, (sum[2] / total) as f32))
    }
}

/// The sample of `mesh` with about `target` points (see the module documentation).
pub fn sample_surface(mesh: &Mesh, target: usize) -> SurfaceSample {
    sample_triangles(&mesh.vertices, &mesh.triangles, target)
}

/// The sample of the triangles `triangles` over `vertices` with about `target` points.
/// Triangles with an out-of-range index, a non-finite corner or zero area are skipped.
pub fn sample_triangles(vertices: &[Vec3], triangles: &[[u32; 3]], target: usize) -> SurfaceSample {
    let corner = |i: u32| vertices.get(i as usize).filter(|v| v.is_finite()).map(|v| [v.x as f64, v.y as f64, v.z as f64]);
    // (corners, doubled-area normal, area)
    let tris: Vec<([[f64; 3]; 3], [f64; 3], f64)> = triangles
        .iter()
        .filter_map(|t| {
            let (a, b, c) = (corner(t[0])?, corner(t[1])?, corner(t[2])?);
            let (u, v) = (sub(b, a), sub(c, a));
            let n = [u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]];
            let area = 0.5 * (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
            (area > 0.0 && area.is_finite()).then_some(([a, b, c], n, area))
        })
        .collect();
    let total: f64 = tris.iter().map(|t| t.2).sum();
    let mut out = SurfaceSample::default();
    if !(total > 0.0 && total.is_finite()) {
        return out;
    }
    let target = target.max(1) as f64;
    for ([a, b, c], n, area) in tris {
        let k = ((target * area / total).sqrt().round() as usize).clamp(1, 1 << 12);
        let kf = k as f64;
        let len = 2.0 * area;
        let normal = Vec3::new((n[0] / len) as f32, (n[1] / len) as f32, (n[2] / len) as f32);
        let weight = (area / (kf * kf)) as f32;
        let (u, v) = (sub(b, a), sub(c, a));
        let mut push = |s: f64, t: f64| {
            let p = [0, 1, 2].map(|i| a[i] + s * u[i] + t * v[i]);
            out.points.push(Vec3::new(p[0] as f32, p[1] as f32, p[2] as f32));
            out.weights.push(weight);
            out.normals.push(normal);
        };
        // sub-triangles of the k-subdivision: k(k+1)/2 upright, k(k-1)/2 inverted
        for i in 0..k {
            for j in 0..(k - i) {
                push((i as f64 + 1.0 / 3.0) / kf, (j as f64 + 1.0 / 3.0) / kf);
                if i + j + 2 <= k {
                    push((i as f64 + 2.0 / 3.0) / kf, (j as f64 + 2.0 / 3.0) / kf);
                }
            }
        }
    }
    out
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn box_sample_covers_its_area_with_outward_normals() {
        let m = Mesh::cuboid(Vec3::ZERO, Vec3::new(1.0, 2.0, 3.0));
        let s = sample_surface(&m, 2048);
        let area: f32 = s.weights.iter().sum();
        assert!((area - 22.0).abs() < 1e-3, "{area}");
        assert!(s.len() > 1500 && s.len() < 3000, "{}", s.len());
        let c = s.centroid().unwrap();
        assert!((c - Vec3::new(0.5, 1.0, 1.5)).length() < 1e-5, "{c:?}");
        for (p, n) in s.points.iter().zip(&s.normals) {
            assert!((n.length() - 1.0).abs() < 1e-6);
            // outward: the normal points away from the centre along its axis
            assert!(n.dot(*p - c) > 0.0);
            // on the surface
            let d = (p.x.min(1.0 - p.x)).min(p.y.min(2.0 - p.y)).min(p.z.min(3.0 - p.z));
            assert!(d.abs() < 1e-6, "{p:?}");
        }
    }

    #[test]
    fn every_triangle_gets_a_point_and_the_pattern_is_symmetric() {
        let v = vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::new(5.0, 5.0, 5.0), Vec3::splat(f32::NAN)];
        // a normal triangle, a degenerate one, one with an out-of-range index, one with NaN
        let tris = vec![[0, 1, 2], [0, 0, 1], [0, 1, 9], [0, 1, 4]];
        let s = sample_triangles(&v, &tris, 1);
        assert_eq!(s.points, vec![Vec3::new(1.0 / 3.0, 1.0 / 3.0, 0.0)]);
        assert_eq!(s.weights, vec![0.5]);
        assert_eq!(s.normals, vec![Vec3::Z]);
        // a rotated corner order gives the same set of points, a reversed one flips the normal
        let sort = |mut p: Vec<Vec3>| {
            p.sort_by(|a, b| a.to_array().partial_cmp(&b.to_array()).unwrap());
            p
        };
        let a = sample_triangles(&v, &[[0, 1, 2]], 16);
        let b = sample_triangles(&v, &[[1, 2, 0]], 16);
        let c = sample_triangles(&v, &[[0, 2, 1]], 16);
        assert_eq!(a.len(), 16);
        for (p, q) in sort(a.points.clone()).iter().zip(sort(b.points)) {
            assert!((*p - q).length() < 1e-6);
        }
        for (p, q) in sort(a.points).iter().zip(sort(c.points)) {
            assert!((*p - q).length() < 1e-6);
        }
        assert_eq!(c.normals[0], -Vec3::Z);
        assert!(sample_triangles(&v, &[[0, 0, 1]], 10).is_empty());
        assert_eq!(sample_triangles(&v, &[[0, 0, 1]], 10).centroid(), None);
    }
}
