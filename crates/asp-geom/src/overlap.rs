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
//! An entry counts only when the path gets deeper than the tolerance into the other part
//! ([`entry_along`]): a sample that grazes a face (a sliver's centroid beside a hole's wall as a
//! panel lifts off the panel it is sunk into) enters nothing, as in the shrunk sweep.
//!
//! How deep a pair overlaps is measured from the overlap region itself ([`overlap_region`]: the
//! samples of each surface that lie inside the other, and their distance to its surface), not
//! bounded by shrinking: a thin-walled part 1 mm into another is 1 mm deep, whatever its size.
//!
//! The test is a sampling of the surfaces, so it is used *together with* the exact (shrunk)
//! sweep of the pair, never instead of it: a strict pair is blocked when either blocks.

use crate::math::{Aabb, Vec3};
use crate::sample::sample_triangles;
use parry3d::query::{PointQuery, Ray, RayCullingMode};
use parry3d::shape::TriMesh;
use rayon::prelude::*;

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

/// What an overlapping pair is, by the shape of its overlap (in the plan JSON by its name).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum OverlapClass {
    /// A coaxial fit that is not a clearance fit (a press fit, a thread drawn without its helix,
    /// one nominal radius): the plan's `fits` list it ([`crate::fits`]).
    Fit,
    /// No deeper than the sagittas (and twice the tolerance) of two coaxial faceted round faces
    /// of one radius, one of each part, that the overlap lies on: two tessellations of one
    /// surface, not material of one part in the other.
    Tessellation,
    /// A thin slab between parallel planar faces of the two parts, one facing the other: a panel
    /// sunk a millimetre or two into another. It comes apart along the slab's normal.
    PlanarSlab,
    /// Anything else: material of one part really inside the other.
    Interpenetration,
}

impl OverlapClass {
    /// `fit`, `tessellation`, `planar_slab` or `interpenetration`.
    pub fn name(self) -> &'static str {
        match self {
            OverlapClass::Fit => "fit",
            OverlapClass::Tessellation => "tessellation",
            OverlapClass::PlanarSlab => "planar_slab",
            OverlapClass::Interpenetration => "interpenetration",
        }
    }

    /// Words a mechanical engineer uses for it.
    pub fn describe(self) -> &'static str {
        match self {
            OverlapClass::Fit => "a fit (see fits)",
            OverlapClass::Tessellation => "a tessellation artefact",
            OverlapClass::PlanarSlab => "a planar slab",
            OverlapClass::Interpenetration => "interpenetration",
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
    /// The measured depth in metres. For pairs some shrinking separates: the least shrinking of
    /// one part (tolerance included) after which they no longer cross. For `gross` pairs: how
    /// deep the surface of each part lies inside the other, measured in the overlap region
    /// ([`overlap_region`]; exact on two unions of boxes; the largest shrinking tried, and
    /// `bound` true, when no sample of either surface lies inside the other).
    pub depth: f32,
    /// No shrinking up to the limit separates them.
    pub gross: bool,
    /// `depth` is a lower bound, the largest shrinking tried: a `gross` pair whose overlap
    /// region no surface sample of either part found.
    pub bound: bool,
    /// How their mutual tests treat them.
    pub handling: OverlapHandling,
    /// What the pair is, by the shape of its overlap.
    pub class: OverlapClass,
    /// For a [`OverlapClass::PlanarSlab`]: the slab's unit normal, the outward normal of the
    /// first part's face in it (the second part lifts off the first along it).
    pub normal: Option<Vec3>,
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
    let (clipped, tris, area) = clipped_surface(mesh, &region);
    let target = ((area / f64::from(spacing * spacing)).ceil() as usize).min(LOCAL_SAMPLES_CAP);
    if target == 0 {
        return Vec::new();
    }
    let sample = sample_triangles(&clipped, &tris, target);
    sample.points.iter().zip(&sample.normals).map(|(p, n)| *p - *n * depth).collect()
}

/// `mesh`'s surface clipped to box `region`: the clipped polygons' corners, their fan
/// triangles and their area.
fn clipped_surface(mesh: &TriMesh, region: &Aabb) -> (Vec<Vec3>, Vec<[u32; 3]>, f64) {
    let (vertices, triangles) = (mesh.vertices(), mesh.indices());
    let mut clipped: Vec<Vec3> = Vec::new();
    let mut tris: Vec<[u32; 3]> = Vec::new();
    let mut area = 0.0f64;
    for t in triangles {
        let corners = t.map(|i| vertices[i as usize]);
        let (tmin, tmax) = (corners[0].min(corners[1]).min(corners[2]), corners[0].max(corners[1]).max(corners[2]));
        if (0..3).any(|k| tmax[k] < region.mins[k] || tmin[k] > region.maxs[k]) {
            continue;
        }
        let poly = clip_to_box(corners, region);
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
    (clipped, tris, area)
}

/// About how many surface samples per part [`overlap_region`] takes in the pair's common box.
pub const REGION_SAMPLES: usize = 3000;

/// Where two parts overlap, seen from their surfaces: the samples of each part's surface that
/// lie inside the other, and how deep (their distance to the other's surface).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct OverlapRegion {
    /// The first part's surface samples inside the second, then the second's inside the first.
    pub inside: [Vec<Vec3>; 2],
    /// Each sample's distance to the other part's surface (the same order).
    pub depths: [Vec<f32>; 2],
}

impl OverlapRegion {
    /// Every sample inside the other part, of either part.
    pub fn points(&self) -> impl Iterator<Item = Vec3> + '_ {
        self.inside.iter().flatten().copied()
    }

    /// How deep the two parts overlap: a robust maximum of the samples' depths (the 99th
    /// percentile, so a stray sample of an open or self-touching mesh does not decide it);
    /// `None` when no sample lies inside the other part.
    pub fn depth(&self) -> Option<f32> {
        let mut all: Vec<f32> = self.depths.iter().flatten().copied().filter(|d| d.is_finite()).collect();
        if all.is_empty() {
            return None;
        }
        all.sort_by(f32::total_cmp);
        Some(all[((all.len() - 1) as f32 * 0.99).round() as usize])
    }
}

/// The overlap region of meshes `a` and `b` ([`OverlapRegion`]): each one's surface in the two
/// boxes' intersection, about `target` samples (sub-triangle centroids, [`sample_triangles`]),
/// kept where it lies inside the other (parry's point projection, pseudo-normals), with its
/// distance to the other's surface. The samples are tested in parallel.
pub fn overlap_region(a: &TriMesh, b: &TriMesh, target: usize) -> OverlapRegion {
    let (ba, bb) = (a.local_aabb(), b.local_aabb());
    let (lo, hi) = (ba.mins.max(bb.mins), ba.maxs.min(bb.maxs));
    if (hi - lo).min_element() < 0.0 {
        return OverlapRegion::default();
    }
    // a hair larger, so faces lying in the boxes' planes are not clipped away by rounding
    let pad = 1e-6 * (ba.maxs - ba.mins).max(bb.maxs - bb.mins).length();
    let region = Aabb::new(lo - Vec3::splat(pad), hi + Vec3::splat(pad));
    let side = |own: &TriMesh, other: &TriMesh| -> (Vec<Vec3>, Vec<f32>) {
        let (clipped, tris, _) = clipped_surface(own, &region);
        let sample = sample_triangles(&clipped, &tris, target);
        sample
            .points
            .par_iter()
            .filter_map(|&x| {
                let p = other.project_local_point(x, false);
                p.is_inside.then(|| (x, (p.point - x).length()))
            })
            .unzip()
    };
    let ((ia, da), (ib, db)) = rayon::join(|| side(a, b), || side(b, a));
    OverlapRegion { inside: [ia, ib], depths: [da, db] }
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
/// moved along unit `dir`, enters `other` (crosses one of its faces from outside and gets
/// deeper than `slack` into it before it leaves, [`entry_along`]), or `None`. With
/// `first_only`, any entry is returned as soon as it is found (not the earliest).
pub fn first_entry(samples: &[Vec3], from: Vec3, dir: Vec3, t_max: f32, other: &TriMesh, first_only: bool, slack: f32) -> Option<f32> {
    let bounds = other.local_aabb();
    let pad = 1e-5 * (bounds.maxs - bounds.mins).length();
    let mut best: Option<f32> = None;
    for &s in samples {
        let s = s + from;
        let limit = best.unwrap_or(t_max);
        if !path_meets(s, dir, limit, &bounds, pad) {
            continue;
        }
        if let Some(t) = entry_along(other, s, dir, limit, slack) {
            if first_only {
                return Some(t);
            }
            best = Some(best.map_or(t, |b: f32| b.min(t)));
        }
    }
    best
}

/// The most stretches inside `other` one sample's path is followed through ([`entry_along`]).
const MAX_STRETCHES: usize = 8;

/// The travel (within `limit`) at which point `s`, moving along unit `dir`, enters `other`
/// deeper than `slack`, or `None`. Each stretch of the path inside `other` runs from a front
/// face the ray crosses (parry's ray cast, back faces culled) to the next back face (front
/// faces culled) or the end of the motion; it counts when a point at a quarter, half or three
/// quarters of it lies inside `other` (parry's point projection) farther than `slack` from its
/// surface. A path that only grazes the surface (a sample at a sliver's centroid beside a hole's
/// wall, a vertex in the plane of the other's side face, a lift a hair off the wall's direction:
/// parry then reports a front face crossed where the path stays outside or within a hair of it)
/// enters nothing, as in the shrunk sweep; a dowel dragged sideways through its bore, a panel
/// slid through another, cross material deeply.
/// With `slack` 0 the first front face crossed is the entry.
pub fn entry_along(other: &TriMesh, s: Vec3, dir: Vec3, limit: f32, slack: f32) -> Option<f32> {
    let mut t0 = 0.0f32;
    let mut last = None;
    for _ in 0..MAX_STRETCHES {
        let hit = other.cast_local_ray_with_culling(&Ray::new(s + dir * t0, dir), limit - t0, RayCullingMode::IgnoreBackfaces)?;
        let t_in = t0 + hit.time_of_impact;
        if slack <= 0.0 {
            return Some(t_in);
        }
        last = Some(t_in);
        let t_out = other
            .cast_local_ray_with_culling(&Ray::new(s + dir * t_in, dir), limit - t_in, RayCullingMode::IgnoreFrontfaces)
            .map_or(limit, |h| t_in + h.time_of_impact);
        let deep = [0.25f32, 0.5, 0.75].iter().any(|f| {
            let x = s + dir * (t_in + f * (t_out - t_in));
            let p = other.project_local_point(x, false);
            p.is_inside && (p.point - x).length() > slack
        });
        if deep {
            return Some(t_in);
        }
        // past the stretch, a hair on (its exit face would stop the next cast at once)
        t0 = t_out + 1e-3 * slack;
        if t0 >= limit {
            return None;
        }
    }
    // a path crossing the surface this often: count it (conservative)
    last
}

/// The strict test of one pair: how far the moving part (samples `moving`, mesh `moving_mesh`),
/// displaced by `from`, travels along unit `dir` (up to `t_max`) before a sample of either part
/// enters the other's material deeper than `slack`; `None` when no sample does. With
/// `first_only` any entry ends the search (a yes/no answer).
#[allow(clippy::too_many_arguments)] // the pair's two sides (samples and mesh each), the motion, the slack
pub fn strict_entry(
    moving: &[Vec3],
    moving_mesh: &TriMesh,
    still: &[Vec3],
    still_mesh: &TriMesh,
    from: Vec3,
    dir: Vec3,
    t_max: f32,
    first_only: bool,
    slack: f32,
) -> Option<f32> {
    let a = first_entry(moving, from, dir, t_max, still_mesh, first_only, slack);
    if first_only && a.is_some() {
        return a;
    }
    // the still part's samples seen from the moving part: displaced by -from, moving along -dir
    let b = first_entry(still, -from, -dir, a.unwrap_or(t_max), moving_mesh, first_only, slack);
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

    /// A path entering a box counts only when it gets deeper than the slack inside: straight
    /// through the middle, yes; down the box's side 0.5 mm inside its face, only for a slack
    /// under 0.5 mm; in the plane of a face or beside it, never.
    #[test]
    fn an_entry_counts_when_the_path_gets_deeper_than_the_slack() {
        let m = crate::mesh::Mesh::cuboid(Vec3::ZERO, Vec3::ONE);
        let mesh = TriMesh::with_flags(m.vertices, m.triangles, parry3d::shape::TriMeshFlags::ORIENTED).unwrap();
        let down = -Vec3::Z;
        assert_eq!(entry_along(&mesh, Vec3::new(0.5, 0.5, 2.0), down, 5.0, 1e-3), Some(1.0));
        assert_eq!(entry_along(&mesh, Vec3::new(0.5, 0.0005, 2.0), down, 5.0, 1e-3), None);
        assert_eq!(entry_along(&mesh, Vec3::new(0.5, 0.0005, 2.0), down, 5.0, 1e-4), Some(1.0));
        for y in [0.0, -0.0005] {
            assert_eq!(entry_along(&mesh, Vec3::new(0.5, y, 2.0), down, 5.0, 1e-4), None, "{y}");
        }
        // the strict rule: the moving sample through the box is refused, beside it not
        let still: Vec<Vec3> = Vec::new();
        let through = [Vec3::new(0.5, 0.5, 2.0)];
        assert!(strict_entry(&through, &mesh, &still, &mesh, Vec3::ZERO, down, 5.0, true, 1e-3).is_some());
        assert!(strict_entry(&[Vec3::new(0.5, -0.0005, 2.0)], &mesh, &still, &mesh, Vec3::ZERO, down, 5.0, true, 1e-3).is_none());
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
