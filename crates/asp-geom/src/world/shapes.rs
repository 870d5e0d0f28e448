//! The parts' collision shapes, the world's first component: every part (and the ground slab,
//! when no part is fixed) as a parry mesh with its bounds, exact boxes, closedness, the cache of
//! its shrunk copies, its surface samples, symmetry axis and recognised surfaces.
//!
//! Everything else in the world reads geometry from here and nowhere else, so a shape is welded,
//! oriented and eroded once, and a world under another overlap policy shares the meshes and the
//! caches instead of building them again.

use super::geom::{contains_point, nests, Geom};
use crate::assembly::Assembly;
use crate::boxes::PartShape;
use crate::error::{GeomError, Result};
use crate::fastener::{self, SymmetryAxis};
use crate::fits::Surfaces;
use crate::math::{aabb_of, Aabb, Vec3};
use crate::mesh::Mesh;
use crate::overlap::{self, OverlapKind};
use crate::sweep;
use parry3d::shape::TriMesh;
use rayon::prelude::*;
use std::collections::BTreeSet;
use std::sync::Arc;

/// About how many surface samples per part the strict overlap rule uses (plus every vertex).
pub(super) const STRICT_SAMPLES: usize = 4000;

/// The collision shapes of the parts, the ground last when there is one.
pub struct Shapes {
    pub(super) geoms: Vec<Geom>,
    parts: usize,
    ground: Option<usize>,
    tolerance: f32,
}

impl Shapes {
    /// Welds, orients and indexes every part's mesh (in parallel) and adds a ground slab under
    /// the lowest point when no part is fixed. Returns the shapes and the warnings about open or
    /// non-manifold meshes and exact boxes, in part order.
    pub(super) fn build(assembly: &Assembly, exact_boxes: bool, tolerance: f32) -> Result<(Shapes, Vec<String>)> {
        let diag = assembly.diagonal().max(f32::MIN_POSITIVE);
        let mut warnings = Vec::new();
        let mut geoms = Vec::with_capacity(assembly.len() + 1);
        // each part's welding, orientation and BVH in parallel (independent), then in part order
        // the first error and the warnings, as a loop over the parts would give them
        let prepared: Vec<_> = assembly
            .parts
            .par_iter()
            .map(|p| {
                // a part whose welded surface keeps no triangle (models built in memory; the
                // loader refuses them in the same words)
                if let Some(reason) = crate::validate::collapsed(p) {
                    return Err(GeomError::Assembly { path: assembly.source.clone(), reason });
                }
                let made = Geom::new(&p.mesh, p.faces.as_deref())
                    .map_err(|e| GeomError::Assembly { path: assembly.source.clone(), reason: format!("part '{}': {e}", p.name) })?;
                Ok((made, PartShape::classify(p, exact_boxes)))
            })
            .collect();
        for (p, made) in assembly.parts.iter().zip(prepared) {
            let ((mut g, t), (shape, warning)) = made?;
            warnings.extend(warning);
            g.boxes = shape.boxes();
            if !t.is_closed_manifold() {
                warnings.push(format!(
                    "part '{}': mesh is not closed and manifold ({} open, {} non-manifold, {} misoriented edges); its removal tests may be conservative",
                    p.name, t.boundary_edges, t.non_manifold_edges, t.misoriented_edges
                ));
            }
            geoms.push(g);
        }
        let n = assembly.len();
        let ground = if assembly.parts.iter().any(|p| p.fixed) {
            None
        } else {
            let bb = assembly.aabb().expect("validated assembly has vertices");
            let (mut g, _) = Geom::new(&ground_box(&bb, assembly.up.vector(), diag), None)?;
            g.boxes = exact_boxes.then(|| vec![g.aabb]);
            geoms.push(g);
            Some(n)
        };
        Ok((Shapes { geoms, parts: n, ground, tolerance }, warnings))
    }

    /// A copy sharing the meshes and the caches made so far.
    pub(super) fn share(&self) -> Shapes {
        Shapes { geoms: self.geoms.iter().map(Geom::share).collect(), ..*self }
    }

    /// How many shapes there are: the parts, and the ground when there is one.
    pub fn count(&self) -> usize {
        self.geoms.len()
    }

    /// How many real parts there are (the ground, when present, has this index).
    pub(super) fn parts(&self) -> usize {
        self.parts
    }

    /// The index of the virtual ground part, when no part of the model is fixed.
    pub fn ground(&self) -> Option<usize> {
        self.ground
    }

    /// The contact tolerance in metres (every part's tests shrink it by this much at least).
    pub fn tolerance(&self) -> f32 {
        self.tolerance
    }

    /// The collision mesh of part `i` in its assembled pose.
    pub fn mesh(&self, i: usize) -> &TriMesh {
        &self.geoms[i].mesh
    }

    /// The bounding box of part `i` (ground included) in its assembled pose.
    pub fn aabb(&self, i: usize) -> &Aabb {
        &self.geoms[i].aabb
    }

    /// The bounds of the `parts` together (`None` when there are none).
    pub fn bounds(&self, parts: impl Iterator<Item = usize>) -> Option<Aabb> {
        aabb_of(parts.flat_map(|q| [self.geoms[q].aabb.mins, self.geoms[q].aabb.maxs]))
    }

    /// The exact boxes of part `i` in its assembled pose when it is a known union of
    /// axis-aligned boxes that describes its mesh (see [`crate::boxes`]; `None` otherwise, and
    /// always with `WorldConfig::exact_boxes` off).
    pub fn boxes(&self, i: usize) -> Option<&[Aabb]> {
        self.geoms[i].boxes.as_deref()
    }

    /// Whether part `i`'s mesh is closed and manifold.
    pub fn is_closed(&self, i: usize) -> bool {
        self.geoms[i].closed
    }

    /// Part `p` shrunk by `amount` (cached).
    pub fn eroded(&self, p: usize, amount: f32) -> Arc<TriMesh> {
        self.geoms[p].eroded(amount)
    }

    /// Part `p`'s axis of near rotational symmetry (a bolt, screw, nut, washer), if any (made
    /// once when first asked).
    pub fn symmetry_axis(&self, p: usize) -> Option<SymmetryAxis> {
        let g = self.geoms.get(p)?;
        *g.axis.get_or_init(|| if g.closed && p < self.parts { fastener::symmetry_axis(&g.mesh) } else { None })
    }

    /// Part `p`'s cylinders and planes ([`crate::fits::recognise`]; made once when first asked).
    pub fn surfaces(&self, p: usize) -> &Surfaces {
        self.geoms[p].surfaces()
    }

    /// Part `p`'s surface samples moved inward by the tolerance (made once), for the strict
    /// overlap rule.
    pub(super) fn strict_samples(&self, p: usize) -> &[Vec3] {
        self.geoms[p].samples.get_or_init(|| overlap::inward_samples(&self.geoms[p].mesh, STRICT_SAMPLES, self.tolerance))
    }

    /// Part `p`'s whole-surface strict samples and, densely, its surface near `q`
    /// ([`overlap::local_inward_samples`] in the pair's common box).
    pub(super) fn dense_samples(&self, p: usize, q: usize) -> Vec<Vec3> {
        let mut all = self.strict_samples(p).to_vec();
        let (a, b) = (self.geoms[p].mesh.local_aabb(), self.geoms[q].mesh.local_aabb());
        all.extend(overlap::local_inward_samples(&self.geoms[p].mesh, &a, &b, self.tolerance));
        all
    }

    /// Shrinks, in parallel, each part of `wanted` (part, erosion amount) not yet in its cache.
    pub(super) fn erode_all(&self, wanted: BTreeSet<(usize, u32)>) {
        let wanted: Vec<(usize, u32)> = wanted.into_iter().filter(|&(k, a)| !self.geoms[k].eroded_cached(f32::from_bits(a))).collect();
        wanted.par_iter().for_each(|&(k, amount)| {
            self.geoms[k].eroded(f32::from_bits(amount));
        });
    }

    /// The least extra erosion of part `p` (beyond the tolerance, to within a sixteenth) after
    /// which it no longer crosses `q`'s surface: 0 when they merely touch, `None` when even
    /// `limit` does not separate them.
    pub(super) fn extra_erosion(&self, p: usize, q: usize, limit: f32) -> Option<f32> {
        let (a, b) = (&self.geoms[p], &self.geoms[q]);
        let tol = self.tolerance;
        // the plain tolerance first, from the cache (most pairs merely touch)
        a.eroded(tol);
        depth_search(tol, limit, |extra| !a.eroded_hits(tol + extra, b))
    }

    /// How overlapping parts `i` and `j` lie in each other: coincident (bounds equal to within
    /// twice the tolerance), nested (one's bounds inside the other's, its surface clear of the
    /// other's when shrunk by the tolerance, and a vertex inside the other's closed surface), or
    /// crossing.
    pub(super) fn overlap_kind(&self, i: usize, j: usize) -> OverlapKind {
        let (a, b) = (&self.geoms[i], &self.geoms[j]);
        let slack = 2.0 * self.tolerance;
        if (a.aabb.mins - b.aabb.mins).abs().max_element() <= slack && (a.aabb.maxs - b.aabb.maxs).abs().max_element() <= slack {
            return OverlapKind::Coincident;
        }
        for (inner, x, y) in [(i, a, b), (j, b, a)] {
            if y.closed
                && nests(&x.aabb, &y.aabb)
                && contains_point(&y.mesh, x.mesh.vertices()[0])
                && !sweep::meshes_cross(&x.eroded(self.tolerance), &y.mesh)
            {
                return OverlapKind::Nested { inner };
            }
        }
        OverlapKind::Crossing
    }
}

/// A slab under the model whose top face lies at the model's lowest point along `up`.
pub(crate) fn ground_box(bb: &Aabb, up: Vec3, diag: f32) -> Mesh {
    let centre = (bb.mins + bb.maxs) * 0.5;
    let half = Vec3::splat(1.5 * diag);
    let (mut mins, mut maxs) = (centre - half, centre + half);
    let axis = up.abs().max_position();
    if up[axis] > 0.0 {
        maxs[axis] = bb.mins[axis];
        mins[axis] = bb.mins[axis] - 0.5 * diag;
    } else {
        mins[axis] = bb.maxs[axis];
        maxs[axis] = bb.maxs[axis] + 0.5 * diag;
    }
    Mesh::cuboid(mins, maxs)
}

/// The least extra erosion (within a factor 2^-4 of the first doubling step) at which `clear`
/// holds: 0 when it holds at once, else doubling from `tol` up to `limit` (`None` past it), then
/// four bisections. `clear` must be monotone in the extra erosion.
pub(super) fn depth_search(tol: f32, limit: f32, clear: impl Fn(f32) -> bool) -> Option<f32> {
    if clear(0.0) {
        return Some(0.0);
    }
    let mut hi = tol;
    while !clear(hi) {
        if hi >= limit {
            return None;
        }
        hi = (hi * 2.0).min(limit);
    }
    let mut lo = hi / 2.0;
    for _ in 0..4 {
        let mid = 0.5 * (lo + hi);
        if clear(mid) {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    Some(hi)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::erode::eroded_mesh;
    use crate::fixtures::{assemble, bolt_and_nut, dowel_in_two_boards, part, pressed_peg};
    use crate::math::{Axis, Rot};
    use crate::world::{World, WorldConfig};

    /// Whether `a` shrunk by `amount` still overlaps `b`, as `Geom::eroded_hits` decided it
    /// before erosion near the region: the whole mesh eroded, as a triangle soup.
    fn hits_by_whole_erosion(a: &Geom, amount: f32, b: &Geom) -> bool {
        let (v, t) = eroded_mesh(a.mesh.vertices(), a.mesh.indices(), amount);
        sweep::soup_crosses(&v, &t, &b.mesh)
            || (b.closed && nests(&a.aabb, &b.aabb) && contains_point(&b.mesh, v[0]))
            || (a.closed && nests(&b.aabb, &a.aabb) && contains_point(&a.erode(amount), b.mesh.vertices()[0]))
    }

    /// `Shapes::extra_erosion`'s search over `hits_by_whole_erosion` (the erosion of the whole part).
    fn depth_by_whole_erosion(s: &Shapes, p: usize, q: usize, limit: f32) -> Option<f32> {
        let (a, b, tol) = (&s.geoms[p], &s.geoms[q], s.tolerance);
        depth_search(tol, limit, |extra| !hits_by_whole_erosion(a, tol + extra, b))
    }

    /// The trial erosions of an overlapping pair shrink only the triangles near
    /// the other part; every pair's measured depth (shallow, deep, gross, nested, threaded) is
    /// the one the whole erosions give, so the warnings and explanations print the same.
    #[test]
    fn overlap_depths_measured_near_the_other_part_are_the_whole_erosions() {
        // a stool's seat and two legs, tessellated (2-unit cells), turned off the axes (no exact
        // boxes), the legs pushed `depth` and a fifth of it into the seat; and a tessellated cube
        // nested in a larger one
        let slab = |n: [i32; 3], origin: [f32; 3]| {
            let cells: Vec<[i32; 3]> = (0..n[0]).flat_map(|x| (0..n[1]).flat_map(move |y| (0..n[2]).map(move |z| [x, y, z]))).collect();
            let mut m = Mesh::from_voxels(&cells, Vec3::splat(2.0), Vec3::from(origin));
            m.vertices.iter_mut().for_each(|v| *v = Rot::from_rotation_z(0.35) * *v);
            part("panel", m, false)
        };
        let stool = |depth: f32| {
            let parts = vec![
                slab([20, 20, 1], [0.0, 0.0, 40.0]),
                slab([1, 20, 20], [0.0, 0.0, depth]),
                slab([1, 20, 20], [38.0, 0.0, 0.2 * depth]),
            ];
            assemble("stool", parts, Axis::Z)
        };
        let nested = assemble("nested", vec![slab([6, 6, 6], [0.0, 0.0, 0.0]), slab([2, 2, 2], [4.0, 4.0, 4.0])], Axis::Z);
        let mut pairs = 0;
        for assembly in [stool(0.3), stool(1.5), nested, pressed_peg(), dowel_in_two_boards(), bolt_and_nut(0.0001)] {
            let w = World::new(assembly, &WorldConfig { exact_boxes: false, ..WorldConfig::default() }).unwrap();
            assert!(!w.overlaps().notes().is_empty(), "{}: the fixture overlaps", w.assembly().source.display());
            let s = w.shapes();
            for i in 0..w.num_parts() {
                for j in w.contacts().of(i).iter().filter(|&j| j < w.num_parts() && j != i) {
                    let limit = 0.4 * (s.geoms[i].aabb.maxs - s.geoms[i].aabb.mins).min_element();
                    let expected = depth_by_whole_erosion(s, i, j, limit);
                    assert_eq!(s.extra_erosion(i, j, limit), expected, "{}: {} in {}", w.assembly().source.display(), w.name(i), w.name(j));
                    pairs += usize::from(expected != Some(0.0));
                }
            }
        }
        assert!(pairs >= 8, "{pairs} overlapping ordered pairs measured");
    }

    /// The ground slab lies under the model, its top face at the lowest point along up, and a
    /// model with a fixed part gets none.
    #[test]
    fn the_ground_slab_lies_under_the_model_only_when_nothing_is_fixed() {
        let bb = Aabb::new(Vec3::new(0.0, 0.0, 1.0), Vec3::new(2.0, 2.0, 3.0));
        let g = ground_box(&bb, Vec3::Z, 4.0).aabb().unwrap();
        assert_eq!(g.maxs.z, 1.0);
        assert_eq!(g.mins.z, -1.0);
        let down = ground_box(&bb, -Vec3::Z, 4.0).aabb().unwrap();
        assert_eq!(down.mins.z, 3.0);
        // the pressed peg's plate is fixed: no ground; loosened, the ground comes last
        let held = World::new(pressed_peg(), &WorldConfig::default()).unwrap();
        assert_eq!((held.shapes().ground(), held.shapes().count()), (None, held.num_parts()));
        let mut loose = pressed_peg();
        loose.parts[0].fixed = false;
        let loose = World::new(loose, &WorldConfig::default()).unwrap();
        assert_eq!(loose.shapes().ground(), Some(loose.num_parts()));
        assert_eq!(loose.shapes().count(), loose.num_parts() + 1);
        assert!(loose.contacts().fixed().contains(loose.num_parts()));
    }

    /// A shrunk copy is made once and shared, also by a world under another policy.
    #[test]
    fn eroded_copies_are_cached_and_shared() {
        let w = World::new(pressed_peg(), &WorldConfig { exact_boxes: false, ..WorldConfig::default() }).unwrap();
        let s = w.shapes();
        let a = s.eroded(0, 2.0 * s.tolerance());
        assert!(Arc::ptr_eq(&a, &s.eroded(0, 2.0 * s.tolerance())));
        assert!(Arc::ptr_eq(&a, &w.lenient().shapes().eroded(0, 2.0 * s.tolerance())));
        assert!(s.bounds(0..w.num_parts()).is_some() && s.bounds(std::iter::empty()).is_none());
    }
}
