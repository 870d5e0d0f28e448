//! The candidate removal directions: ± axes, clusters of surface normals, sphere directions.

use super::WorldConfig;
use crate::assembly::Assembly;
use crate::math::Vec3;
use std::collections::BTreeMap;

/// ± axes, then the largest clusters of area-weighted surface normals with their opposites,
/// then optional Fibonacci-sphere directions; near-duplicates (within 1°) are dropped.
pub fn candidate_directions(assembly: &Assembly, config: &WorldConfig) -> Vec<Vec3> {
    let mut dirs: Vec<Vec3> = Vec::new();
    let push = |d: Vec3, dirs: &mut Vec<Vec3>| {
        let d = d.normalize_or_zero();
        if d != Vec3::ZERO && !dirs.iter().any(|e| e.dot(d) > 0.99985) {
            dirs.push(d);
        }
    };
    for axis in [Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, Vec3::Z, -Vec3::Z] {
        push(axis, &mut dirs);
    }
    for c in cluster_normals(assembly, config.cluster_angle_deg, config.normal_clusters) {
        push(c, &mut dirs);
        push(-c, &mut dirs);
    }
    let m = config.sphere_directions;
    let golden = std::f32::consts::PI * (3.0 - 5f32.sqrt());
    for i in 0..m {
        let z = 1.0 - 2.0 * (i as f32 + 0.5) / m as f32;
        let r = (1.0 - z * z).sqrt();
        let phi = golden * i as f32;
        push(Vec3::new(r * phi.cos(), r * phi.sin(), z), &mut dirs);
    }
    dirs
}

/// The mean directions of the `count` largest (by area) clusters of face normals.
fn cluster_normals(assembly: &Assembly, angle_deg: f32, count: usize) -> Vec<Vec3> {
    if count == 0 {
        return Vec::new();
    }
    let cos = angle_deg.to_radians().cos();
    // quantise normals first so that big meshes cluster in time linear in their size
    let mut buckets: BTreeMap<[i32; 3], (Vec3, f64)> = BTreeMap::new();
    for p in &assembly.parts {
        for t in &p.mesh.triangles {
            let n = p.mesh.triangle_normal(t);
            let area = n.length() as f64 * 0.5;
            if area <= 0.0 || !area.is_finite() {
                continue;
            }
            let u = n.normalize();
            let key = [u.x, u.y, u.z].map(|c| (c * 64.0).round() as i32);
            let e = buckets.entry(key).or_insert((Vec3::ZERO, 0.0));
            e.0 += u * area as f32;
            e.1 += area;
        }
    }
    let mut items: Vec<(Vec3, f64)> = buckets.into_values().map(|(v, a)| (v.normalize_or_zero(), a)).collect();
    items.sort_by(|a, b| b.1.total_cmp(&a.1));
    let mut clusters: Vec<(Vec3, Vec3, f64)> = Vec::new(); // (first direction, weighted sum, area)
    for (u, area) in items {
        match clusters.iter_mut().find(|c| c.0.dot(u) >= cos) {
            Some(c) => {
                c.1 += u * area as f32;
                c.2 += area;
            }
            None => clusters.push((u, u * area as f32, area)),
        }
    }
    clusters.sort_by(|a, b| b.2.total_cmp(&a.2));
    clusters.into_iter().take(count).map(|c| c.1.normalize_or_zero()).collect()
}
