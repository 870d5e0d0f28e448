//! Grasps of a parallel two-finger gripper (thesis 5.2): read from a part's metadata, or computed
//! for any part mesh as antipodal pairs of parallel faces within the gripper's opening.
//!
//! A grasp is the tool centre's pose (the fingers' midpoint) and the opening: the gripper's z axis
//! is the approach direction (pointing from the hand into the part), its y axis the closing
//! direction of the fingers, as in [`asp_geom::Grasp`].

use asp_geom::math::{Rot, Vec3};
use asp_geom::{Grasp, Mesh, Part, PartMeta};
use parry3d::math::Mat3;
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// Settings of [`antipodal_grasps`].
#[derive(Clone, Debug)]
pub struct GraspConfig {
    /// The gripper's widest opening, metres (the shipped panda: 0.08).
    pub max_opening: f32,
    /// Narrowest accepted width, metres.
    pub min_width: f32,
    /// Largest angle between one face's outward normal and the reversed normal of the face
    /// opposite, radians.
    pub parallel_tolerance: f32,
    /// How deep the fingertips reach past the surface along the approach, metres: a grasp is kept
    /// only when the part's surface lies within this distance of the grasp centre against the
    /// approach direction (so the hand stays outside the part).
    pub finger_depth: f32,
    /// Surface points sampled (area-weighted).
    pub samples: usize,
    /// Approach directions tried around the closing axis of each antipodal pair.
    pub approaches: usize,
    /// Grasps closer than this (metres, with an orientation within 0.3 rad) count as one.
    pub min_spacing: f32,
    /// At most this many grasps are returned.
    pub max_grasps: usize,
    /// Seed of the surface sampling.
    pub seed: u64,
}

impl Default for GraspConfig {
    fn default() -> Self {
        GraspConfig {
            max_opening: 0.08,
            min_width: 0.002,
            parallel_tolerance: 5f32.to_radians(),
            finger_depth: 0.04,
            samples: 400,
            approaches: 4,
            min_spacing: 0.01,
            max_grasps: 64,
            seed: 0,
        }
    }
}

/// The grasps stored in a part's metadata that fit an opening of `max_opening`.
pub fn grasps_from_meta(meta: &PartMeta, max_opening: f32) -> Vec<Grasp> {
    meta.grasps.iter().filter(|g| g.width <= max_opening + 1e-6).cloned().collect()
}

/// The grasps of `part`: those in its metadata when it has any, else [`antipodal_grasps`] of its mesh.
pub fn part_grasps(part: &Part, cfg: &GraspConfig) -> Vec<Grasp> {
    if part.meta.grasps.is_empty() {
        antipodal_grasps(&part.mesh, cfg)
    } else {
        grasps_from_meta(&part.meta, cfg.max_opening)
    }
}

/// Distance along the ray `o + t d` (t > `t_min`) to the first triangle of `tris` it crosses, with that
/// triangle's index (Möller-Trumbore, both sides).
fn first_hit(tris: &[[Vec3; 3]], o: Vec3, d: Vec3, t_min: f32) -> Option<(f32, usize)> {
    let mut best: Option<(f32, usize)> = None;
    for (i, [a, b, c]) in tris.iter().enumerate() {
        let e1 = *b - *a;
        let e2 = *c - *a;
        let p = d.cross(e2);
        let det = e1.dot(p);
        if det.abs() < 1e-12 {
            continue;
        }
        let inv = 1.0 / det;
        let s = o - *a;
        let u = s.dot(p) * inv;
        if !(-1e-6..=1.0 + 1e-6).contains(&u) {
            continue;
        }
        let q = s.cross(e1);
        let v = d.dot(q) * inv;
        if v < -1e-6 || u + v > 1.0 + 1e-6 {
            continue;
        }
        let t = e2.dot(q) * inv;
        if t > t_min && best.is_none_or(|(bt, _)| t < bt) {
            best = Some((t, i));
        }
    }
    best
}

/// A unit vector perpendicular to `y`, from the world axis least aligned with it.
fn perpendicular(y: Vec3) -> Vec3 {
    let a = y.abs();
    let r = if a.x <= a.y && a.x <= a.z {
        Vec3::X
    } else if a.y <= a.z {
        Vec3::Y
    } else {
        Vec3::Z
    };
    (r - y * r.dot(y)).normalize()
}

/// Antipodal grasps of a closed mesh (world frame, metres): surface points sampled with `cfg.seed`,
/// each paired with the face straight through the part; pairs whose faces are parallel within
/// `cfg.parallel_tolerance` and lie at most `cfg.max_opening` apart give grasps, one per approach
/// direction around the closing axis that keeps the hand outside the part. Deterministic per seed.
pub fn antipodal_grasps(mesh: &Mesh, cfg: &GraspConfig) -> Vec<Grasp> {
    let tris: Vec<[Vec3; 3]> = mesh.triangles.iter().map(|t| t.map(|i| mesh.vertices[i as usize])).collect();
    if tris.is_empty() || !mesh.is_finite() || cfg.samples == 0 {
        return Vec::new();
    }
    let flip = if mesh.signed_volume() < 0.0 { -1.0 } else { 1.0 };
    let normals: Vec<Vec3> = tris.iter().map(|[a, b, c]| (*b - *a).cross(*c - *a).normalize_or_zero() * flip).collect();
    let mut cumulative = Vec::with_capacity(tris.len());
    let mut total = 0.0f64;
    for [a, b, c] in &tris {
        total += 0.5 * (*b - *a).cross(*c - *a).length() as f64;
        cumulative.push(total);
    }
    if total <= 0.0 {
        return Vec::new();
    }
    let scale = mesh.aabb().map_or(1.0, |b| (b.maxs - b.mins).length()).max(1e-6);
    let eps = 1e-5 * scale;
    let cos_tol = cfg.parallel_tolerance.cos();
    let mut rng = ChaCha8Rng::seed_from_u64(cfg.seed);
    let mut out: Vec<Grasp> = Vec::new();
    for _ in 0..cfg.samples {
        let pick = rng.random_range(0.0..total);
        let ti = cumulative.partition_point(|&c| c <= pick).min(tris.len() - 1);
        let (mut u, mut v) = (rng.random_range(0.0f32..1.0), rng.random_range(0.0f32..1.0));
        if u + v > 1.0 {
            (u, v) = (1.0 - u, 1.0 - v);
        }
        let [a, b, c] = tris[ti];
        let n = normals[ti];
        if n == Vec3::ZERO {
            continue;
        }
        let p = a + (b - a) * u + (c - a) * v;
        let Some((width, tj)) = first_hit(&tris, p, -n, eps) else { continue };
        if width < cfg.min_width || width > cfg.max_opening || normals[tj].dot(-n) < cos_tol {
            continue;
        }
        let centre = p - n * (0.5 * width);
        let y = n;
        let u0 = perpendicular(y);
        let v0 = y.cross(u0);
        for k in 0..cfg.approaches.max(1) {
            let th = std::f32::consts::TAU * k as f32 / cfg.approaches.max(1) as f32;
            let z = u0 * th.cos() + v0 * th.sin();
            // the hand comes from -z: the part's surface must be within finger reach behind the centre
            match first_hit(&tris, centre, -z, 0.0) {
                Some((d, _)) if d <= cfg.finger_depth => {}
                _ => continue,
            }
            let x = y.cross(z);
            let orientation = Rot::from_mat3(&Mat3::from_cols(x, y, z)).normalize();
            let duplicate =
                out.iter().any(|g| (g.position - centre).length() < cfg.min_spacing && g.orientation.angle_between(orientation) < 0.3);
            if !duplicate {
                out.push(Grasp { position: centre, orientation, width });
                if out.len() >= cfg.max_grasps {
                    return out;
                }
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ray_hits_the_far_side_of_a_cube() {
        let m = Mesh::cuboid(Vec3::ZERO, Vec3::ONE);
        let tris: Vec<[Vec3; 3]> = m.triangles.iter().map(|t| t.map(|i| m.vertices[i as usize])).collect();
        let (t, _) = first_hit(&tris, Vec3::new(0.5, 0.5, 0.0), Vec3::Z, 1e-4).unwrap();
        assert!((t - 1.0).abs() < 1e-5);
    }

    #[test]
    fn same_seed_same_grasps() {
        let m = Mesh::cuboid(Vec3::ZERO, Vec3::new(0.2, 0.04, 0.03));
        let cfg = GraspConfig { seed: 7, ..Default::default() };
        assert_eq!(antipodal_grasps(&m, &cfg), antipodal_grasps(&m, &cfg));
        assert!(!antipodal_grasps(&m, &cfg).is_empty());
    }
}
