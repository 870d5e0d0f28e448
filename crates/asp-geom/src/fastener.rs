//! Fasteners: a part's axis of near rotational symmetry, and *threaded*
//! contacts, along whose axis a bolt or nut leaves by screwing.
//!
//! **The axis.** A surface of revolution (or a helical surface, a thread) is swept into itself by
//! a rotation (or a screw motion) about its axis: the motion's velocity `v(x) = ā + a × x` is
//! tangent to the surface everywhere, `n(x) · v(x) = 0`. So the axis is found, as in Pottmann and
//! Randrup's kinematic surface fitting (1998), as the motion `(ā, a)`, `|a| = 1`, that minimises
//! `Σ area · (n · ā + (x × n) · a)²` over the part's triangles: a 3×3 eigenproblem once `ā` is
//! eliminated. Features that are symmetric under the axis's discrete rotations (a hexagonal head,
//! flats) pull the fit equally from every side and leave the axis in place. The principal axes of
//! the surface (the earlier estimate) are kept as fallbacks; they are a few tenths of a millimetre
//! off on real bolts (`pump-threaded`: the surface centroid of an M5 bolt with its head 0.1 mm off
//! the axis, its direction 0.5° off), and a 30 mm bolt turned by 180° about such a line no longer
//! lands on itself.
//!
//! **The check.** A part has a symmetry axis when its surface sample turned by 60°, 120° and 180°
//! about the line stays within a few percent of its radius of its own surface (a hexagon is
//! exactly invariant; a helical thread turned by θ is the same thread shifted by `pitch·θ/2π`,
//! which stays within that slack for metric pitches; threads modelled as rings, as in
//! `pump-threaded`, are exactly invariant).
//!
//! **Threads.** A pair (`p`, `q`) is threaded when `p` has such an axis, `p`'s side faces touch
//! or cut `q`, a good share of them are thread *flanks* (faces oblique to the axis: a smooth pin
//! in a bore has none, and is not a fastener), and the part of `q`'s surface near `p`'s axis (the
//! hole or the nut's bore) is invariant under the same rotations. Along that axis the pair's
//! thread zone — the cylinder around the axis out to `p`'s thread crests where it engages `q`
//! (not a head seated in a counterbore) — is invariant under the screw motion, so the
//! removal test of the pair along the axis exempts surface samples inside that cylinder and tests
//! the rest by the strict sample rule ([`crate::overlap`]): a bolt's head still cannot pass
//! through the plate it bears on, but its thread turns out of the nut.

use crate::erode::symmetric_eigen;
use crate::math::Vec3;
use crate::sample::sample_triangles;
use parry3d::math::Mat3;
use parry3d::query::PointQuery;
use parry3d::shape::TriMesh;

/// Rotations a fastener must be nearly invariant under (degrees).
const ANGLES_DEG: [f32; 3] = [60.0, 120.0, 180.0];
/// The share of turned samples that must land near the surface.
const AGREEMENT: f32 = 0.9;
/// How near (a fraction of the part's radius about the axis).
const SLACK: f32 = 0.06;
/// Axial shifts (in steps of the slack, each way) a turned sample may take to land on the surface.
const SHIFTS: u32 = 4;
/// Samples per part for the symmetry test.
const SAMPLES: usize = 1500;
/// A side face is a thread flank when its normal's component along the axis lies in this range
/// (a 60° metric flank: about 0.87; a crest or a smooth shank: 0; a bearing face: 1).
const FLANK: std::ops::Range<f32> = 0.3..0.95;
/// The least share of a threaded part's side area where it engages its partner that must be
/// flanks.
const FLANK_SHARE: f32 = 0.2;
/// The least number of alternating runs of flanks there (three pitches).
const MIN_TURNS: usize = 6;
/// A thread's crests lie within this factor of its flanks' largest radius.
const CREST: f32 = 1.15;

/// A line about which a part is nearly rotationally symmetric.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SymmetryAxis {
    /// A point on the axis (the surface's area centroid projected on it).
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

/// Whether `y` lies within `distance` of `mesh`'s surface, as `project_local_point` would say
/// (the distance to the closest point on a triangle), asking only whether some triangle is that
/// near: the closest-point search visits the BVH down to the closest triangle
/// even for points far off the surface (most turned samples of a part that is not a fastener),
/// and among many near triangles (a modelled thread) keeps looking for the closest.
fn within(mesh: &TriMesh, y: Vec3, distance: f32) -> bool {
    mesh.bvh()
        .leaves(|n| n.aabb().distance_to_local_point(y, true) <= distance)
        .any(|j| (mesh.triangle(j).project_local_point(y, false).point - y).length() <= distance)
}

/// Whether `x`, turned by `angle` about `axis` (and shifted along it by up to [`SHIFTS`] times
/// `slack` either way, in steps of `slack`: a helical thread turned by θ is itself shifted by
/// `pitch·θ/2π`), lies within `slack` of `mesh`'s surface.
fn lands(x: Vec3, angle: f32, axis: &SymmetryAxis, mesh: &TriMesh, slack: f32) -> bool {
    let near_surface = |y: Vec3| within(mesh, y, slack);
    let y = axis.turn(x, angle);
    near_surface(y)
        || (1..=SHIFTS).any(|k| {
            let s = axis.direction * (k as f32 * slack);
            near_surface(y + s) || near_surface(y - s)
        })
}

/// The shares of `points` that land on `mesh`'s surface turned by each of the check angles
/// (60°, 120° and 180°) about `axis`.
pub fn agreement(points: &[Vec3], axis: &SymmetryAxis, mesh: &TriMesh, slack: f32) -> [f32; 3] {
    ANGLES_DEG.map(|deg| {
        let near = points.iter().filter(|&&x| lands(x, deg.to_radians(), axis, mesh, slack)).count();
        near as f32 / points.len().max(1) as f32
    })
}

/// Whether at least [`AGREEMENT`] of `points`, turned by each of [`ANGLES_DEG`] about `axis`,
/// land on `mesh`'s surface (stops at the first angle with too many misses).
fn invariant(points: &[Vec3], axis: &SymmetryAxis, mesh: &TriMesh, slack: f32) -> bool {
    let allowed = ((1.0 - AGREEMENT) * points.len() as f32).floor() as usize;
    !points.is_empty()
        && ANGLES_DEG.iter().all(|deg| {
            let mut misses = 0;
            points.iter().all(|&x| {
                if !lands(x, deg.to_radians(), axis, mesh, slack) {
                    misses += 1;
                }
                misses <= allowed
            })
        })
}

type M3 = [[f64; 3]; 3];

fn inverse(m: &M3) -> Option<M3> {
    let c = |i: usize, j: usize| {
        let (i1, i2, j1, j2) = ((i + 1) % 3, (i + 2) % 3, (j + 1) % 3, (j + 2) % 3);
        m[i1][j1] * m[i2][j2] - m[i1][j2] * m[i2][j1]
    };
    let det = m[0][0] * c(0, 0) + m[0][1] * c(0, 1) + m[0][2] * c(0, 2);
    if !det.is_finite() || det.abs() < 1e-300 {
        return None;
    }
    let mut out = [[0.0; 3]; 3];
    for (i, row) in out.iter_mut().enumerate() {
        for (j, x) in row.iter_mut().enumerate() {
            *x = c(j, i) / det; // the adjugate is the transposed cofactor matrix
        }
    }
    Some(out)
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

fn mul(m: &M3, v: [f64; 3]) -> [f64; 3] {
    [0, 1, 2].map(|i| m[i][0] * v[0] + m[i][1] * v[1] + m[i][2] * v[2])
}

/// The rotation or screw motion whose velocity is most nearly tangent to the closed surface
/// (`vertices`, `triangles`): its axis (through the area centroid's foot on it) and its pitch as
/// travel per radian (near 0 for a surface of revolution; meaningless for a plain cylinder, which
/// every pitch fits). `None` for a degenerate surface.
pub fn kinematic_axis(vertices: &[Vec3], triangles: &[[u32; 3]]) -> Option<(SymmetryAxis, f32)> {
    // per triangle: centroid, unit normal, area (f64, about the area centroid, scaled to ~1)
    let mut tris = Vec::with_capacity(triangles.len());
    let (mut total, mut centre) = (0.0f64, [0.0f64; 3]);
    for t in triangles {
        let [a, b, c] = t.map(|i| vertices.get(i as usize).copied().unwrap_or(Vec3::NAN));
        let n = (b - a).cross(c - a);
        let area = 0.5 * n.length() as f64;
        if !(area > 0.0 && area.is_finite()) {
            continue;
        }
        let x = (a + b + c) / 3.0;
        let u = n.normalize();
        tris.push(([x.x as f64, x.y as f64, x.z as f64], [u.x as f64, u.y as f64, u.z as f64], area));
        total += area;
        for k in 0..3 {
            centre[k] += area * [x.x, x.y, x.z][k] as f64;
        }
    }
    if tris.len() < 8 || total <= 0.0 {
        return None;
    }
    centre = centre.map(|c| c / total);
    let scale = tris
        .iter()
        .map(|(x, _, _)| ((x[0] - centre[0]).powi(2) + (x[1] - centre[1]).powi(2) + (x[2] - centre[2]).powi(2)).sqrt())
        .fold(0.0f64, f64::max);
    if scale.is_nan() || scale <= 0.0 {
        return None;
    }
    let (mut a, mut b, mut c) = ([[0.0f64; 3]; 3], [[0.0f64; 3]; 3], [[0.0f64; 3]; 3]);
    for (x, n, w) in &tris {
        let x = [0, 1, 2].map(|k| (x[k] - centre[k]) / scale);
        let m = cross(x, *n);
        for i in 0..3 {
            for j in 0..3 {
                a[i][j] += w * n[i] * n[j];
                b[i][j] += w * n[i] * m[j];
                c[i][j] += w * m[i] * m[j];
            }
        }
    }
    // eliminate ā = -A⁻¹ B a (A is regularised: a long cylinder's caps may be tiny)
    let trace = a[0][0] + a[1][1] + a[2][2];
    for (i, row) in a.iter_mut().enumerate() {
        row[i] += 1e-9 * trace;
    }
    let ainv = inverse(&a)?;
    // S = C - Bᵀ A⁻¹ B
    let mut s = [[0.0f64; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            let mut btab = 0.0;
            for k in 0..3 {
                for l in 0..3 {
                    btab += b[k][i] * ainv[k][l] * b[l][j];
                }
            }
            s[i][j] = (c[i][j] - btab) / total;
        }
    }
    let col = |j: usize| Vec3::new(s[0][j] as f32, s[1][j] as f32, s[2][j] as f32);
    let (values, vectors) = symmetric_eigen(Mat3::from_cols(col(0), col(1), col(2)));
    let k = (0..3).min_by(|&i, &j| values[i].total_cmp(&values[j]))?;
    let dir = vectors[k].try_normalize()?;
    let d = [dir.x as f64, dir.y as f64, dir.z as f64];
    // ā = -A⁻¹ B a; the axis' point nearest the centroid is a × ā, the pitch a · ā
    let bd = mul(&b, d);
    let abar = mul(&ainv, bd).map(|v| -v);
    let foot = cross(d, abar);
    let pitch = (d[0] * abar[0] + d[1] * abar[1] + d[2] * abar[2]) * scale;
    let point = Vec3::new((centre[0] + foot[0] * scale) as f32, (centre[1] + foot[1] * scale) as f32, (centre[2] + foot[2] * scale) as f32);
    point.is_finite().then_some((SymmetryAxis { point, direction: dir, radius: 0.0 }, pitch as f32))
}

/// The candidate axes of a closed part's surface, best first: the kinematic fit, then the
/// principal axes of the surface sample whose two transverse moments agree.
fn candidate_axes(mesh: &TriMesh, points: &[Vec3], weights: &[f32], centroid: Vec3) -> Vec<SymmetryAxis> {
    let mut out = Vec::new();
    if let Some((mut axis, _)) = kinematic_axis(mesh.vertices(), mesh.indices()) {
        // the centroid's foot on the axis
        axis.point += axis.direction * (centroid - axis.point).dot(axis.direction);
        out.push(axis);
    }
    let mut cov = [[0.0f64; 3]; 3];
    let total: f64 = weights.iter().map(|&w| w as f64).sum();
    for (p, &w) in points.iter().zip(weights) {
        let d = *p - centroid;
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
        if let Some(direction) = vectors[k].try_normalize() {
            out.push(SymmetryAxis { point: centroid, direction, radius: 0.0 });
        }
    }
    out
}

/// The axis of near rotational symmetry of a closed part's surface, if it has one.
pub fn symmetry_axis(mesh: &TriMesh) -> Option<SymmetryAxis> {
    let sample = sample_triangles(mesh.vertices(), mesh.indices(), SAMPLES);
    if sample.len() < 24 {
        return None;
    }
    let c = sample.centroid()?;
    candidate_axes(mesh, &sample.points, &sample.weights, c).into_iter().find_map(|mut axis| {
        axis.radius = sample.points.iter().map(|&x| axis.radial(x)).fold(0.0, f32::max);
        (axis.radius > 0.0 && invariant(&sample.points, &axis, mesh, SLACK * axis.radius)).then_some(axis)
    })
}

/// What [`symmetry_axis`] measured on a part, for diagnosis: each candidate axis with its
/// agreement shares.
pub fn symmetry_report(mesh: &TriMesh) -> Vec<(SymmetryAxis, [f32; 3])> {
    let sample = sample_triangles(mesh.vertices(), mesh.indices(), SAMPLES);
    let Some(c) = sample.centroid() else { return Vec::new() };
    candidate_axes(mesh, &sample.points, &sample.weights, c)
        .into_iter()
        .map(|mut axis| {
            axis.radius = sample.points.iter().map(|&x| axis.radial(x)).fold(0.0, f32::max);
            (axis, agreement(&sample.points, &axis, mesh, SLACK * axis.radius))
        })
        .collect()
}

/// A threaded contact of part `p` (with axis `axis`) with part `q`: the radius of the thread zone
/// about the axis, out to `p`'s thread crests where it engages `q` (plus the contact distance).
/// The zone is the whole cylinder: what lies in it on either part (the thread, the bore, the
/// shank beyond the nut) turns with the screw motion; what lies outside (a head, the faces a nut
/// or a head bears on) is tested. So a headless stud may leave through the bottom of a blind hole
/// in line with it (a known limitation).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Thread {
    /// The moving part's symmetry axis.
    pub axis: SymmetryAxis,
    /// Samples closer to the axis than this are in the thread zone.
    pub radius: f32,
}

/// What [`threaded_contact`] measures of a pair, for its decision and for diagnosis.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ThreadMeasure {
    /// The largest distance from the axis of `p`'s thread flanks where it engages `q` (of its
    /// side faces touching `q` when it has no flanks there).
    pub radius: f32,
    /// The area of `p`'s side faces in contact with `q`.
    pub side_area: f32,
    /// The share of `p`'s side surface where it engages `q` that is thread flanks.
    pub flank_share: f32,
    /// How many runs of flanks facing one way along the axis alternate there.
    pub flank_turns: usize,
    /// How many samples of `q`'s side faces lie in the zone.
    pub zone_samples: usize,
    /// The shares of those that land on `q` turned by 60°, 120°, 180°.
    pub agreement: [f32; 3],
}

/// Measures the pair (`p` with surface `pm` and symmetry axis `axis`, `q` with surface `qm`) as
/// [`threaded_contact`] does, within `contact`.
pub fn measure_thread(axis: &SymmetryAxis, pm: &TriMesh, qm: &TriMesh, contact: f32) -> ThreadMeasure {
    let mut m = ThreadMeasure::default();
    let (local, radius) = contact_zone(axis, pm, qm, contact, &mut m);
    if radius > 0.0 && !local.is_empty() {
        m.agreement = agreement(&local, axis, qm, SLACK * axis.radius);
    }
    m
}

/// `q`'s side-face samples in `p`'s thread zone, and the zone's radius (0 when `p`'s side faces
/// do not touch `q`); fills in `m`.
fn contact_zone(axis: &SymmetryAxis, pm: &TriMesh, qm: &TriMesh, contact: f32, m: &mut ThreadMeasure) -> (Vec<Vec3>, f32) {
    let qb = qm.local_aabb();
    let (lo_q, hi_q) = (qb.mins - Vec3::splat(contact), qb.maxs + Vec3::splat(contact));
    let ps = sample_triangles(pm.vertices(), pm.indices(), 4 * SAMPLES);
    let along = |x: Vec3| (x - axis.point).dot(axis.direction);
    // p's side faces (not its head's bearing face) touching or inside q: the thread zone's
    // radius and the axial range where p engages q (parry's solid projection on a triangle mesh
    // does not report inside points, so containment is asked for)
    let (mut radius, mut lo_e, mut hi_e) = (0.0f32, f32::INFINITY, f32::NEG_INFINITY);
    for (x, n) in ps.points.iter().zip(&ps.normals) {
        if n.dot(axis.direction).abs() >= FLANK.end || x.cmplt(lo_q).any() || x.cmpgt(hi_q).any() {
            continue;
        }
        let touching = within(qm, *x, contact) || qm.contains_local_point(*x);
        if touching {
            radius = radius.max(axis.radial(*x));
            lo_e = lo_e.min(along(*x));
            hi_e = hi_e.max(along(*x));
        }
    }
    // p's side surface where it engages q (out to that radius): how much of it is thread
    // flanks, and how often the flanks turn (a thread's flanks alternate along the axis, once
    // per half pitch; a chamfer or a cone does not)
    let (mut side, mut flank) = (0.0f32, 0.0f32);
    let mut flanks: Vec<(f32, bool, f32)> = Vec::new();
    let mut sides: Vec<(f32, f32)> = Vec::new();
    for ((x, n), w) in ps.points.iter().zip(&ps.normals).zip(&ps.weights) {
        let a = n.dot(axis.direction);
        let t = along(*x);
        // out to a little beyond the contact: a nut's thread roots lie beyond the bolt's crests
        if a.abs() >= FLANK.end || t < lo_e || t > hi_e || axis.radial(*x) > CREST * radius + contact {
            continue;
        }
        side += w;
        sides.push((t, axis.radial(*x)));
        if FLANK.contains(&a.abs()) {
            flank += w;
            flanks.push((t, a > 0.0, axis.radial(*x)));
        }
    }
    flanks.sort_by(|a, b| a.0.total_cmp(&b.0));
    m.flank_turns = turns(&flanks);
    // the zone reaches the thread's crests, not a head seated in a counterbore whose sides touch
    // too, nor its chamfer: the flanks counted are those in pitch-long stretches of the axis
    // holding flanks facing both ways (a thread), and the crests lie a little beyond them
    let mut flank_radius = 0.0f32;
    if m.flank_turns >= 2 {
        let pitch = 2.0 * (hi_e - lo_e) / m.flank_turns as f32;
        let mut bins: std::collections::BTreeMap<i64, (bool, bool, f32)> = std::collections::BTreeMap::new();
        for &(t, up, r) in &flanks {
            let b = bins.entry(((t - lo_e) / pitch).floor() as i64).or_insert((false, false, 0.0));
            if up {
                b.0 = true;
            } else {
                b.1 = true;
            }
            b.2 = b.2.max(r);
        }
        flank_radius = bins.values().filter(|b| b.0 && b.1).map(|b| b.2).fold(0.0, f32::max);
    }
    // (the samples are sub-triangle centroids: a sharp crest is reached by the vertices only)
    let crests = pm.vertices().iter().filter(|&&v| (lo_e..=hi_e).contains(&along(v))).map(|&v| axis.radial(v));
    let radius = sides.iter().map(|s| s.1).chain(crests).filter(|&r| r <= CREST * flank_radius).fold(flank_radius, f32::max);
    m.radius = radius;
    m.side_area = side;
    m.flank_share = if side > 0.0 { flank / side } else { 0.0 };
    if radius <= 0.0 {
        return (Vec::new(), 0.0);
    }
    let radius = radius + contact;
    // q's surface within the zone (and p's axial extent) must be symmetric about the same axis
    let (lo, hi) = ps.points.iter().fold((f32::INFINITY, f32::NEG_INFINITY), |(l, h), &x| (l.min(along(x)), h.max(along(x))));
    // sampled densely where it matters: q's triangles with a corner in the zone (a tapped hole
    // is a small part of a pump body's surface)
    let in_zone = |x: Vec3| axis.radial(x) <= radius && (lo..=hi).contains(&along(x));
    let near: Vec<[u32; 3]> = qm.indices().iter().filter(|t| t.iter().any(|&i| in_zone(qm.vertices()[i as usize]))).copied().collect();
    let qs = sample_triangles(qm.vertices(), &near, 4 * SAMPLES);
    // a bore: q's faces around p's side (not a plane p is pushed into, which is symmetric too)
    let local: Vec<Vec3> = qs
        .points
        .iter()
        .zip(&qs.normals)
        .filter(|(x, n)| in_zone(**x) && n.dot(axis.direction).abs() < FLANK.end)
        .map(|(x, _)| *x)
        .collect();
    m.zone_samples = local.len();
    (local, radius)
}

/// The number of runs of flank samples (axial position, facing +axis) sorted along the axis,
/// runs of fewer than 3 samples merged into their neighbours.
fn turns(flanks: &[(f32, bool, f32)]) -> usize {
    let mut runs: Vec<(bool, usize)> = Vec::new();
    for &(_, up, _) in flanks {
        match runs.last_mut() {
            Some((s, n)) if *s == up => *n += 1,
            _ => runs.push((up, 1)),
        }
    }
    let mut merged: Vec<bool> = Vec::new();
    for (s, n) in runs {
        if n >= 3 && merged.last() != Some(&s) {
            merged.push(s);
        }
    }
    merged.len()
}

/// Whether `p` (surface `pm`, symmetry axis `axis`) and `q` (surface `qm`) are in threaded
/// contact: `p`'s side faces touch or cut `q` (within `contact`), where `p` engages `q` at least
/// a fifth of its side surface is thread flanks alternating at least 6 times along the
/// axis (a thread drawn into a plain hole at its major diameter, as CAD draws tapped holes,
/// counts: the crests touch, the flanks lie below them), and `q`'s surface near the axis is invariant under the same
/// rotations. `None` otherwise.
pub fn threaded_contact(axis: &SymmetryAxis, pm: &TriMesh, qm: &TriMesh, contact: f32) -> Option<Thread> {
    let mut m = ThreadMeasure::default();
    let (local, radius) = contact_zone(axis, pm, qm, contact, &mut m);
    if radius <= 0.0 || m.flank_share < FLANK_SHARE || m.flank_turns < MIN_TURNS || local.len() < 24 {
        return None;
    }
    invariant(&local, axis, qm, SLACK * axis.radius).then_some(Thread { axis: *axis, radius })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fixtures::bolt_and_nut;
    use parry3d::shape::TriMeshFlags;

    /// Whether a point lies within a distance of a surface, asked of the
    /// triangles that near (the symmetry and thread checks' query), says what the closest
    /// point's distance says, for points on, near and far from a threaded bolt's surface.
    #[test]
    fn a_near_triangle_answers_as_the_closest_point_does() {
        let bolt = &bolt_and_nut(0.0).parts[1].mesh;
        let mesh = TriMesh::with_flags(bolt.vertices.clone(), bolt.triangles.clone(), TriMeshFlags::ORIENTED).unwrap();
        let bb = mesh.local_aabb();
        let mut seed = 11u32;
        let mut r = || {
            seed = seed.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            (seed >> 8) as f32 / (1u32 << 24) as f32
        };
        let (mut near, mut far) = (0, 0);
        for k in 0..3000 {
            let y = if k % 3 == 0 {
                // on the surface, then pushed off it a little
                let v = mesh.vertices()[(r() * mesh.vertices().len() as f32) as usize % mesh.vertices().len()];
                v + (Vec3::new(r(), r(), r()) - 0.5) * 0.0006
            } else {
                bb.mins + (bb.maxs - bb.mins) * (Vec3::new(r(), r(), r()) * 1.4 - 0.2)
            };
            let closest = (mesh.project_local_point(y, false).point - y).length();
            for d in [0.00005, 0.0003, 0.001] {
                assert_eq!(within(&mesh, y, d), closest <= d, "point {y:?}, distance {d}: closest point {closest}");
                if closest <= d {
                    near += 1;
                } else {
                    far += 1;
                }
            }
            // exactly at the closest point's distance: within
            assert!(within(&mesh, y, closest), "point {y:?} at its own distance {closest}");
        }
        assert!(near > 1000 && far > 1000, "the points test both answers ({near} near, {far} far)");
    }
}
