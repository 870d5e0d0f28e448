//! Parts that overlap in the input: the policy, and the *strict* per-pair motion test.
//!
//! Real CAD overlaps on purpose (press fits, dowels pushed into boards without modelled holes,
//! screws in tapped holes drawn at their major diameter) and by accident (modelling slop). Such a
//! pair may separate only along motions that cut into no material it did not already overlap: a
//! dowel leaves along its axis, never sideways.
//!
//! The strict test samples both surfaces ([`crate::sample`]: sub-triangle centroids plus
//! the vertices), moves every sample inward by the tolerance (so touching and sliding never
//! count, as in the shrink-then-sweep test), and follows each sample along the relative motion
//! as a ray: the moving part's samples along `d` against the other's mesh, the other's samples
//! along `-d` against the moving part's mesh. A sample *enters* material when its ray crosses a
//! face of the other part from outside, i.e. a face whose outward normal points against the
//! ray (parry's ray cast with back faces culled); leaving through a back face is always allowed.
//! So a sample that starts inside the other part may leave it, and one that starts outside may
//! never get in — continuously along the segment, with no time steps. A sample that leaves and
//! later enters again is refused too (stricter than "inside at the start may stay inside").
//!
//! The test is a sampling of the surfaces, so it is used *together with* the exact (shrunk)
//! sweep of the pair, never instead of it: a strict pair is blocked when either blocks.

use crate::math::{Aabb, Vec3};
use crate::sample::sample_triangles;
use parry3d::query::{Ray, RayCullingMode};
use parry3d::shape::TriMesh;

/// What asp does with parts that overlap in the input beyond the tolerance (in the plan JSON
/// by its name: `strict`, `lenient`, `error`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum OverlapPolicy {
    /// The default: an overlapping pair may separate only along motions that enter no new
    /// material of the other part (the strict test above, on top of the shrunk sweep); pairs
    /// that no shrinking separates are tested by the strict rule alone. Never an error.
    #[default]
    Strict,
    /// Shrink one part of the pair in their mutual tests; pairs that no shrinking separates
    /// ignore each other's collisions (a pressed-in dowel may slide sideways: physically wrong).
    Lenient,
    /// Shrink small overlaps; a pair that no shrinking separates stops planning with an error.
    Error,
}

impl OverlapPolicy {
    /// Every policy's name, as the CLI and Python spell them.
    pub const NAMES: [&'static str; 3] = ["strict", "lenient", "error"];

    /// The policy named `s` (`strict`, `lenient`, `error`).
    pub fn parse(s: &str) -> Option<OverlapPolicy> {
        match s {
            "strict" => Some(OverlapPolicy::Strict),
            "lenient" => Some(OverlapPolicy::Lenient),
            "error" => Some(OverlapPolicy::Error),
            _ => None,
        }
    }

    /// The policy's name.
    pub fn name(self) -> &'static str {
        match self {
            OverlapPolicy::Strict => "strict",
            OverlapPolicy::Lenient => "lenient",
            OverlapPolicy::Error => "error",
        }
    }
}

/// How two overlapping parts lie in each other.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum OverlapKind {
    /// Their surfaces cross.
    Crossing,
    /// The first part lies wholly inside the second (its index).
    Nested {
        /// The part inside.
        inner: usize,
    },
    /// The two parts occupy the same space (their bounds agree to within the tolerance and
    /// each holds the other's surface).
    Coincident,
}

impl OverlapKind {
    /// `crossing`, `nested` or `coincident`.
    pub fn name(self) -> &'static str {
        match self {
            OverlapKind::Crossing => "crossing",
            OverlapKind::Nested { .. } => "nested",
            OverlapKind::Coincident => "coincident",
        }
    }
}

/// One pair of parts that overlap in the input beyond the tolerance, as measured and handled.
#[derive(Clone, Debug, PartialEq)]
pub struct OverlapNote {
    /// The pair (low index, high index).
    pub parts: (usize, usize),
    /// How they lie in each other.
    pub kind: OverlapKind,
    /// The measured depth in metres: the least shrinking of one part (tolerance included) after
    /// which they no longer cross; for pairs no shrinking separates, the largest shrinking tried
    /// (a lower bound, `gross` is true).
    pub depth: f32,
    /// No shrinking up to the limit separates them.
    pub gross: bool,
    /// How their mutual tests treat them.
    pub handling: OverlapHandling,
}

/// How the mutual tests of an overlapping pair treat it (in the plan JSON by its name).
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum OverlapHandling {
    /// They separate only along motions that enter no new material (the strict policy).
    Strict,
    /// One part is shrunk in their tests (lenient or error policy, small overlap).
    Shrunk,
    /// Their collisions with each other are ignored (lenient policy, gross overlap).
    Ignored,
}

impl OverlapHandling {
    /// `strict`, `shrunk` or `ignored`.
    pub fn name(self) -> &'static str {
        match self {
            OverlapHandling::Strict => "strict",
            OverlapHandling::Shrunk => "shrunk",
            OverlapHandling::Ignored => "ignored",
        }
    }
}

/// A part's surface samples moved inward by `depth` along their outward normals: the
/// sub-triangle centroids of about `target` area-weighted points, and every vertex (moved along
/// the area-weighted mean of its faces' normals).
pub fn inward_samples(mesh: &TriMesh, target: usize, depth: f32) -> Vec<Vec3> {
    let (vertices, triangles) = (mesh.vertices(), mesh.indices());
    let sample = sample_triangles(vertices, triangles, target);
    let mut out: Vec<Vec3> = sample.points.iter().zip(&sample.normals).map(|(p, n)| *p - *n * depth).collect();
    let mut normals = vec![Vec3::ZERO; vertices.len()];
    for t in triangles {
        let [a, b, c] = t.map(|i| vertices[i as usize]);
        let n = (b - a).cross(c - a); // twice the area, outward for an oriented mesh
        for i in t {
            normals[*i as usize] += n;
        }
    }
    out.extend(vertices.iter().zip(&normals).filter_map(|(v, n)| {
        let n = n.normalize_or_zero();
        (n != Vec3::ZERO).then(|| *v - n * depth)
    }));
    out
}

/// Most local samples per part and pair ([`local_inward_samples`]).
const LOCAL_SAMPLES_CAP: usize = 20_000;

/// Samples of `mesh` (a part whose box is `own`) near another part (box `other`), moved inward
/// by `depth`: the mesh's surface clipped to the two boxes' intersection grown by a quarter of
/// its largest extent (at least four `depth`s), sampled about a tenth of the intersection's
/// smallest extent apart (at least two `depth`s; at most 20,000 points). Where a
/// small part is drawn into a large one (a dowel in a solid panel), the whole-surface samples
/// are too sparse to see the small part cut sideways through the large one's surface next to
/// it; these see it at the scale of the overlap. Empty when the boxes do not meet.
pub fn local_inward_samples(mesh: &TriMesh, own: &Aabb, other: &Aabb, depth: f32) -> Vec<Vec3> {
    let (lo, hi) = (own.mins.max(other.mins), own.maxs.min(other.maxs));
    let extent = hi - lo;
    if extent.min_element() < 0.0 {
        return Vec::new();
    }
    let grow = (0.25 * extent.max_element()).max(4.0 * depth);
    let region = Aabb::new(lo - Vec3::splat(grow), hi + Vec3::splat(grow));
    let spacing = (0.1 * extent.min_element()).max(2.0 * depth);
    if !(spacing > 0.0 && spacing.is_finite()) {
        return Vec::new();
    }
    let (vertices, triangles) = (mesh.vertices(), mesh.indices());
    let mut clipped: Vec<Vec3> = Vec::new();
    let mut tris: Vec<[u32; 3]> = Vec::new();
    let mut area = 0.0f64;
    for t in triangles {
        let poly = clip_to_box(t.map(|i| vertices[i as usize]), &region);
        if poly.len() < 3 {
            continue;
        }
        let base = clipped.len() as u32;
        clipped.extend_from_slice(&poly);
        for k in 1..poly.len() as u32 - 1 {
            area += 0.5 * f64::from((poly[k as usize] - poly[0]).cross(poly[k as usize + 1] - poly[0]).length());
            tris.push([base, base + k, base + k + 1]);
        }
    }
    let target = ((area / f64::from(spacing * spacing)).ceil() as usize).min(LOCAL_SAMPLES_CAP);
    if target == 0 {
        return Vec::new();
    }
    let sample = sample_triangles(&clipped, &tris, target);
    sample.points.iter().zip(&sample.normals).map(|(p, n)| *p - *n * depth).collect()
}

/// Triangle `t` clipped to box `b` (Sutherland–Hodgman against its six planes): the corners
/// of the convex polygon left, in the triangle's winding; empty when nothing is left.
fn clip_to_box(t: [Vec3; 3], b: &Aabb) -> Vec<Vec3> {
    let mut poly: Vec<Vec3> = t.to_vec();
    for axis in 0..3 {
        for (bound, keep_below) in [(b.maxs[axis], true), (b.mins[axis], false)] {
            if poly.is_empty() {
                return poly;
            }
            let inside = |v: Vec3| if keep_below { v[axis] <= bound } else { v[axis] >= bound };
            let mut out = Vec::with_capacity(poly.len() + 2);
            for i in 0..poly.len() {
                let (a, c) = (poly[i], poly[(i + 1) % poly.len()]);
                if inside(a) {
                    out.push(a);
                }
                if inside(a) != inside(c) {
                    let f = (bound - a[axis]) / (c[axis] - a[axis]);
                    out.push(a + (c - a) * f);
                }
            }
            poly = out;
        }
    }
    poly
}

/// Whether point `s`, moved along unit `dir` for `t` in `[0, t_max]`, can meet box `b` widened
/// by `pad` (a cull: true when unsure).
fn path_meets(s: Vec3, dir: Vec3, t_max: f32, b: &Aabb, pad: f32) -> bool {
    let (mut t0, mut t1) = (0.0f32, t_max);
    for k in 0..3 {
        let (lo, hi) = (b.mins[k] - pad, b.maxs[k] + pad);
        if dir[k].abs() < 1e-12 {
            if s[k] < lo || s[k] > hi {
                return false;
            }
            continue;
        }
        let (a, c) = ((lo - s[k]) / dir[k], (hi - s[k]) / dir[k]);
        t0 = t0.max(a.min(c));
        t1 = t1.min(a.max(c));
        if t0 > t1 {
            return false;
        }
    }
    true
}

/// The earliest travel `t` in `[0, t_max]` at which one of `samples`, displaced by `from` and
/// moved along unit `dir`, enters `other` (crosses one of its faces from outside), or `None`.
/// With `first_only`, any entry is returned as soon as it is found (not the earliest).
pub fn first_entry(samples: &[Vec3], from: Vec3, dir: Vec3, t_max: f32, other: &TriMesh, first_only: bool) -> Option<f32> {
    let bounds = other.local_aabb();
    let pad = 1e-5 * (bounds.maxs - bounds.mins).length();
    let mut best: Option<f32> = None;
    for &s in samples {
        let s = s + from;
        let limit = best.unwrap_or(t_max);
        if !path_meets(s, dir, limit, &bounds, pad) {
            continue;
        }
        let ray = Ray::new(s, dir);
        if let Some(hit) = other.cast_local_ray_with_culling(&ray, limit, RayCullingMode::IgnoreBackfaces) {
            if first_only {
                return Some(hit.time_of_impact);
            }
            best = Some(best.map_or(hit.time_of_impact, |b: f32| b.min(hit.time_of_impact)));
        }
    }
    best
}

/// The strict test of one pair: how far the moving part (samples `moving`, mesh `moving_mesh`),
/// displaced by `from`, travels along unit `dir` (up to `t_max`) before a sample of either part
/// enters the other's material; `None` when no sample does. With `first_only` any entry ends
/// the search (a yes/no answer).
#[allow(clippy::too_many_arguments)] // the pair's two sides (samples and mesh each) and the motion
pub fn strict_entry(
    moving: &[Vec3],
    moving_mesh: &TriMesh,
    still: &[Vec3],
    still_mesh: &TriMesh,
    from: Vec3,
    dir: Vec3,
    t_max: f32,
    first_only: bool,
) -> Option<f32> {
    let a = first_entry(moving, from, dir, t_max, still_mesh, first_only);
    if first_only && a.is_some() {
        return a;
    }
    // the still part's samples seen from the moving part: displaced by -from, moving along -dir
    let b = first_entry(still, -from, -dir, a.unwrap_or(t_max), moving_mesh, first_only);
    match (a, b) {
        (Some(x), Some(y)) => Some(x.min(y)),
        (x, y) => x.or(y),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn policies_round_trip_their_names() {
        for name in OverlapPolicy::NAMES {
            assert_eq!(OverlapPolicy::parse(name).unwrap().name(), name);
        }
        assert_eq!(OverlapPolicy::parse("ignore"), None);
        assert_eq!(OverlapPolicy::default(), OverlapPolicy::Strict);
    }

    #[test]
    fn a_point_path_misses_a_box_beside_it() {
        let b = Aabb::new(Vec3::ZERO, Vec3::ONE);
        assert!(path_meets(Vec3::new(-1.0, 0.5, 0.5), Vec3::X, 2.0, &b, 0.0));
        assert!(!path_meets(Vec3::new(-1.0, 0.5, 0.5), Vec3::X, 0.5, &b, 0.0));
        assert!(!path_meets(Vec3::new(-1.0, 2.0, 0.5), Vec3::X, 5.0, &b, 0.0));
        assert!(!path_meets(Vec3::new(-1.0, 0.5, 0.5), -Vec3::X, 5.0, &b, 0.0));
    }
}
