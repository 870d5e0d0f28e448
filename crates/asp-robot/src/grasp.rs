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
    /// [`face_pair_grasps`]: the spacing of the grasp centres on each pair of parallel faces,
    /// metres (4 cm: a face shorter than that gets one centre; at 2 cm `asp plan --robot` on
    /// held-out single-layer assemblies took up to 2.4× the CPU time, all found either way).
    pub face_spacing: f32,
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
            face_spacing: 0.04,
        }
    }
}

/// The grasps stored in a part's metadata that fit an opening of `max_opening`.
pub fn grasps_from_meta(meta: &PartMeta, max_opening: f32) -> Vec<Grasp> {
    meta.grasps.iter().filter(|g| g.width <= max_opening + 1e-6).cloned().collect()
}

/// The grasps of `part`: those in its metadata followed by [`face_pair_grasps`] on every pair
/// of parallel faces the metadata's grasps do not close on (a generated profile's metadata
/// holds grasps across its four long sides only; its end faces, when the profile is short
/// enough, and the faces of the connectors attached to it are held by none), so a part a
/// person could take by any two parallel faces the gripper spans is grasped there too.
/// Without metadata, [`antipodal_grasps`] of its mesh (sampled over the whole surface, so
/// over every face pair, in proportion to area).
pub fn part_grasps(part: &Part, cfg: &GraspConfig) -> Vec<Grasp> {
    if part.meta.grasps.is_empty() {
        return antipodal_grasps(&part.mesh, cfg);
    }
    let mut grasps = grasps_from_meta(&part.meta, cfg.max_opening);
    let faces = face_pair_grasps(&part.mesh, cfg, &grasps);
    grasps.extend(faces);
    grasps
}

/// The hand orientations of a grasp closing along `y` at `centre` (`cfg.approaches` of them
/// evenly around `y`, z the approach) for which the hand, coming from -z, finds the part's
/// surface within finger reach behind the centre.
fn approaches<'a>(tris: &'a [[Vec3; 3]], centre: Vec3, y: Vec3, cfg: &'a GraspConfig) -> impl Iterator<Item = Rot> + 'a {
    let u0 = perpendicular(y);
    let v0 = y.cross(u0);
    let count = cfg.approaches.max(1);
    (0..count).filter_map(move |k| {
        let th = std::f32::consts::TAU * k as f32 / count as f32;
        let z = u0 * th.cos() + v0 * th.sin();
        match first_hit(tris, centre, -z, 0.0) {
            Some((d, _)) if d <= cfg.finger_depth => Some(Rot::from_mat3(&Mat3::from_cols(y.cross(z), y, z)).normalize()),
            _ => None,
        }
    })
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
        for orientation in approaches(&tris, centre, n, cfg) {
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

/// A plane of a mesh's surface: the triangles on it with the same outward normal.
#[derive(Debug)]
struct Face {
    tris: Vec<usize>,
    normal: Vec3,
    /// `normal · x` for every point `x` of the face.
    offset: f32,
}

/// The mesh's triangles grouped into [`Face`]s: same outward normal within `cos_same`, same
/// plane within `eps`. Coplanar pieces that do not touch count as one face.
fn planar_faces(tris: &[[Vec3; 3]], normals: &[Vec3], cos_same: f32, eps: f32) -> Vec<Face> {
    let mut faces: Vec<Face> = Vec::new();
    for (i, (t, &n)) in tris.iter().zip(normals).enumerate() {
        if n == Vec3::ZERO {
            continue;
        }
        let offset = n.dot((t[0] + t[1] + t[2]) / 3.0);
        match faces.iter_mut().find(|f| f.normal.dot(n) >= cos_same && (f.offset - offset).abs() <= eps) {
            Some(f) => f.tris.push(i),
            None => faces.push(Face { tris: vec![i], normal: n, offset }),
        }
    }
    faces
}

/// Points of `face` on a square lattice of about `spacing` in its plane: the centres of the
/// cells of an even grid over the face's extent that lie on one of its triangles.
fn face_lattice(face: &Face, tris: &[[Vec3; 3]], spacing: f32) -> Vec<Vec3> {
    let n = face.normal;
    let u = perpendicular(n);
    let v = n.cross(u);
    let flat = |x: Vec3| (x.dot(u), x.dot(v));
    let (mut lo, mut hi) = ((f32::INFINITY, f32::INFINITY), (f32::NEG_INFINITY, f32::NEG_INFINITY));
    for &t in &face.tris {
        for x in tris[t] {
            let (a, b) = flat(x);
            lo = (lo.0.min(a), lo.1.min(b));
            hi = (hi.0.max(a), hi.1.max(b));
        }
    }
    let cells = |extent: f32| (extent / spacing).ceil().clamp(1.0, 1000.0) as usize;
    let (nu, nv) = (cells(hi.0 - lo.0), cells(hi.1 - lo.1));
    let on_face = |(pa, pb): (f32, f32)| {
        face.tris.iter().any(|&t| {
            let [a, b, c] = tris[t].map(flat);
            let cross = |p: (f32, f32), q: (f32, f32), r: (f32, f32)| (q.0 - p.0) * (r.1 - p.1) - (q.1 - p.1) * (r.0 - p.0);
            let x = (pa, pb);
            let (d1, d2, d3) = (cross(a, b, x), cross(b, c, x), cross(c, a, x));
            let tol = 1e-9;
            (d1 >= -tol && d2 >= -tol && d3 >= -tol) || (d1 <= tol && d2 <= tol && d3 <= tol)
        })
    };
    let mut out = Vec::new();
    for i in 0..nu {
        for j in 0..nv {
            let p = (lo.0 + (hi.0 - lo.0) * (i as f32 + 0.5) / nu as f32, lo.1 + (hi.1 - lo.1) * (j as f32 + 0.5) / nv as f32);
            if on_face(p) {
                out.push(u * p.0 + v * p.1 + n * face.offset);
            }
        }
    }
    out
}

/// Grasps on every pair of parallel faces of a closed mesh (world frame, metres) within the
/// opening, enumerated, not sampled: the surface is grouped into planar faces; every two faces
/// whose outward normals are opposite within `cfg.parallel_tolerance` and whose planes lie
/// `cfg.min_width` to `cfg.max_opening` apart with the part between them are a pair; on the
/// first face of a pair, points on a lattice of `cfg.face_spacing` whose ray straight through
/// the part comes out on the second face are finger contacts, the grasp centre halfway, and
/// `cfg.approaches` approach directions around the closing axis keep the hand outside the part
/// (as in [`antipodal_grasps`]). Pairs that a grasp of `known` already closes on (its closing
/// axis along their normal, its fingers on their planes) are left out; grasps within
/// `cfg.min_spacing` (and 0.3 rad) of a kept one are dropped; at most `cfg.max_grasps` per
/// pair, spread over the pair's lattice. Deterministic: no sampling.
pub fn face_pair_grasps(mesh: &Mesh, cfg: &GraspConfig, known: &[Grasp]) -> Vec<Grasp> {
    let tris: Vec<[Vec3; 3]> = mesh.triangles.iter().map(|t| t.map(|i| mesh.vertices[i as usize])).collect();
    if tris.is_empty() || !mesh.is_finite() || cfg.face_spacing <= 0.0 {
        return Vec::new();
    }
    let flip = if mesh.signed_volume() < 0.0 { -1.0 } else { 1.0 };
    let normals: Vec<Vec3> = tris.iter().map(|[a, b, c]| (*b - *a).cross(*c - *a).normalize_or_zero() * flip).collect();
    let scale = mesh.aabb().map_or(1.0, |b| (b.maxs - b.mins).length()).max(1e-6);
    let eps = 1e-5 * scale;
    let plane_eps = (1e-4 * scale).max(1e-5);
    let cos_tol = cfg.parallel_tolerance.cos();
    let faces = planar_faces(&tris, &normals, 1e-3f32.cos(), plane_eps);
    let mut face_of = vec![usize::MAX; tris.len()];
    for (k, f) in faces.iter().enumerate() {
        for &t in &f.tris {
            face_of[t] = k;
        }
    }
    // a grasp closes on a pair when its closing axis is along the pair's normal and each
    // finger contact lies on one of the two planes
    let closes_on = |g: &Grasp, a: &Face, b: &Face| {
        let y = g.orientation * Vec3::Y;
        if y.dot(a.normal).abs() < cos_tol {
            return false;
        }
        let contacts = [g.position + y * (0.5 * g.width), g.position - y * (0.5 * g.width)];
        let on = |f: &Face, x: Vec3| (f.normal.dot(x) - f.offset).abs() <= 2.0 * plane_eps + 1e-4;
        contacts.iter().any(|&x| on(a, x)) && contacts.iter().any(|&x| on(b, x))
    };
    let mut out: Vec<Grasp> = Vec::new();
    for (i, a) in faces.iter().enumerate() {
        for (j, b) in faces.iter().enumerate().skip(i + 1) {
            let width = a.offset + b.offset;
            if a.normal.dot(-b.normal) < cos_tol || width < cfg.min_width || width > cfg.max_opening + 1e-6 {
                continue;
            }
            if known.iter().any(|g| closes_on(g, a, b)) {
                continue;
            }
            let mut pair: Vec<Grasp> = Vec::new();
            for p in face_lattice(a, &tris, cfg.face_spacing) {
                let Some((w, hit)) = first_hit(&tris, p, -a.normal, eps) else { continue };
                if face_of[hit] != j || (w - width).abs() > 2.0 * plane_eps + 1e-4 {
                    continue;
                }
                let centre = p - a.normal * (0.5 * w);
                for orientation in approaches(&tris, centre, a.normal, cfg) {
                    let near =
                        |g: &Grasp| (g.position - centre).length() < cfg.min_spacing && g.orientation.angle_between(orientation) < 0.3;
                    if !(pair.iter().any(near) || out.iter().any(near) || known.iter().any(near)) {
                        pair.push(Grasp { position: centre, orientation, width: w });
                    }
                }
            }
            // at most max_grasps of the pair, evenly spread over its lattice
            let keep = cfg.max_grasps.max(1);
            if pair.len() > keep {
                let n = pair.len();
                pair = (0..keep).map(|k| pair[k * n / keep].clone()).collect();
            }
            out.extend(pair);
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

    /// The finger contacts of `g` and the closing axis.
    fn contacts(g: &Grasp) -> (Vec3, Vec3, Vec3) {
        let y = g.orientation * Vec3::Y;
        (g.position + y * (0.5 * g.width), g.position - y * (0.5 * g.width), y)
    }

    /// Every pair of parallel faces within the opening gets grasps, and only those: a
    /// 7 × 4 × 3 cm box is held across each of its three pairs (the 7 cm one is the pair the
    /// random sampler rarely hits, the pair of end faces, and metadata of a profile lacks), a 20 × 4 × 3 cm box across the two
    /// narrow pairs only; every grasp's fingers lie on the two faces, its approach across the
    /// closing axis; the lattice covers a pair evenly (grasp centres every 4 cm).
    #[test]
    fn face_pairs_are_enumerated_within_the_opening() {
        let cfg = GraspConfig::default();
        for (hi, expected) in [(Vec3::new(0.07, 0.04, 0.03), vec![30, 40, 70]), (Vec3::new(0.2, 0.04, 0.03), vec![30, 40])] {
            let grasps = face_pair_grasps(&Mesh::cuboid(Vec3::ZERO, hi), &cfg, &[]);
            let mut widths = std::collections::BTreeMap::new();
            for g in &grasps {
                let (a, b, y) = contacts(g);
                let axis = (0..3).max_by(|&i, &j| y[i].abs().total_cmp(&y[j].abs())).unwrap();
                assert!(y[axis].abs() > 0.999, "closing axis {y:?} not along a face normal");
                for c in [a, b] {
                    assert!(c[axis].abs() < 1e-5 || (c[axis] - hi[axis]).abs() < 1e-5, "contact {c:?} off the faces");
                }
                assert!((g.orientation * Vec3::Z).dot(y).abs() < 1e-4);
                *widths.entry((g.width * 1000.0).round() as i32).or_insert(0) += 1;
            }
            assert_eq!(widths.keys().copied().collect::<Vec<_>>(), expected, "{hi:?}");
            // across the 3 cm sides of the long box: centres every 4 cm along its 20 cm and
            // one across its 4 cm (5 × 1)
            if hi.x > 0.1 {
                let mut centres: Vec<[i32; 3]> = grasps
                    .iter()
                    .filter(|g| (g.width - 0.03).abs() < 1e-5)
                    .map(|g| g.position.to_array().map(|x| (x * 1000.0).round() as i32))
                    .collect();
                centres.sort();
                centres.dedup();
                assert_eq!(centres.len(), 5, "{centres:?}");
                assert!(centres.iter().all(|c| c[0] % 40 == 20 && c[1] == 20 && c[2] == 15), "{centres:?}");
            }
        }
    }

    /// A pair a known grasp already closes on is left out, the others kept; the same call,
    /// the same grasps.
    #[test]
    fn face_pairs_held_by_known_grasps_are_left_out() {
        let m = Mesh::cuboid(Vec3::ZERO, Vec3::new(0.07, 0.04, 0.03));
        let cfg = GraspConfig::default();
        let all = face_pair_grasps(&m, &cfg, &[]);
        let across_z = all.iter().find(|g| (g.width - 0.03).abs() < 1e-5).unwrap().clone();
        let rest = face_pair_grasps(&m, &cfg, &[across_z]);
        let widths: std::collections::BTreeSet<i32> = rest.iter().map(|g| (g.width * 1000.0).round() as i32).collect();
        assert_eq!(widths.into_iter().collect::<Vec<_>>(), vec![40, 70]);
        assert_eq!(
            rest,
            face_pair_grasps(&m, &cfg, &[all[0].clone()]).into_iter().filter(|g| (g.width - 0.03).abs() > 1e-5).collect::<Vec<_>>()
        );
    }
}
