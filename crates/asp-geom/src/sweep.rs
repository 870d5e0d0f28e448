//! Exact straight-line sweeps of triangle meshes: when does a mesh translated along a direction
//! first overlap another?
//!
//! Two triangles are convex, and a translation does not turn them, so the separating-axis test
//! decides their contact over time exactly: on each candidate axis the projections overlap
//! during one interval of time, and the triangles overlap exactly while every axis' interval
//! does. The axes are both normals, the nine edge-edge cross products and the six in-plane edge
//! normals (these cover coplanar triangles); extra axes never make the test wrong. Arithmetic is
//! in `f64` and overlap is strict, so faces that touch, and a face sliding along another at any
//! gap, are never a collision — the property the shrink-then-sweep removal test rests on, which
//! parry's mesh-mesh shape cast does not keep at tolerance-sized gaps (it reported a connector
//! sliding along its profile 0.08 mm away as a hit).
//!
//! Candidate pairs come from the meshes' BVHs: the moving triangles whose box meets the other
//! mesh's box swept backwards, then, for each, the fixed triangles whose box meets its swept box.

use crate::math::{Aabb, Pose, Vec3};
use parry3d::glamx::DVec3;
use parry3d::shape::TriMesh;

/// The first time `t` in `[0, t_max]` at which triangle `a` moved by `t * dir` overlaps
/// triangle `b` (interiors, strictly), or `None`. Parallel triangles that the motion carries
/// through each other's plane overlap at the one instant they are coplanar, when their
/// interiors overlap in that plane.
pub fn triangle_sweep(a: &[DVec3; 3], dir: DVec3, b: &[DVec3; 3], t_max: f64) -> Option<f64> {
    crossing_sweep(a, dir, b, t_max).or_else(|| coplanar_passage(a, dir, b, t_max))
}

/// When triangle `a`, moved by `t * dir`, passes through the plane of the parallel triangle `b`
/// at a time `t` in `(0, t_max]` with their interiors overlapping in that plane: that time.
///
/// Interiors that meet in one plane at one instant are no strict overlap at any time, so the
/// separating-axis sweep ([`crossing_sweep`]) never reports them. A solid moving into another
/// also crosses its side faces, but a part of no thickness (a sheet drawn as a closed surface
/// of no volume) has none: without this it went through a floor, or a box through it, along
/// the sheet's normal.
fn coplanar_passage(a: &[DVec3; 3], dir: DVec3, b: &[DVec3; 3], t_max: f64) -> Option<f64> {
    let na = (a[1] - a[0]).cross(a[2] - a[1]);
    let nb = (b[1] - b[0]).cross(b[2] - b[1]);
    let (la, lb) = (na.length(), nb.length());
    if !(la > 0.0 && lb > 0.0) || na.cross(nb).length() > 1e-9 * la * lb {
        return None;
    }
    let n = na / la;
    let v = dir.dot(n);
    if v.abs() <= 1e-9 * dir.length() {
        return None;
    }
    // when `a` reaches `b`'s plane (from the mean of each triangle's offsets along the normal)
    let offset = |t: &[DVec3; 3]| (t[0].dot(n) + t[1].dot(n) + t[2].dot(n)) / 3.0;
    let t = (offset(b) - offset(a)) / v;
    if !(t > 0.0 && t <= t_max) {
        return None;
    }
    // the in-plane separating axes at that instant: strict overlap on every one, by more than
    // rounding (triangles that only share an edge or a corner in the plane do not overlap)
    let moved = a.map(|p| p + dir * t);
    let edges = [a[1] - a[0], a[2] - a[1], a[0] - a[2], b[1] - b[0], b[2] - b[1], b[0] - b[2]];
    let size = edges.iter().map(|e| e.length()).fold(0.0, f64::max);
    edges
        .iter()
        .all(|e| {
            let l = n.cross(*e);
            let slack = 1e-9 * l.length() * size;
            let (a0, a1) = project(&moved, l);
            let (b0, b1) = project(b, l);
            a1 > b0 + slack && b1 > a0 + slack
        })
        .then_some(t)
}

/// [`triangle_sweep`] by the separating axes alone: the first time the interiors overlap
/// strictly, with a nonzero volume of contact times.
fn crossing_sweep(a: &[DVec3; 3], dir: DVec3, b: &[DVec3; 3], t_max: f64) -> Option<f64> {
    let ea = [a[1] - a[0], a[2] - a[1], a[0] - a[2]];
    let eb = [b[1] - b[0], b[2] - b[1], b[0] - b[2]];
    let na = ea[0].cross(ea[1]);
    let nb = eb[0].cross(eb[1]);
    let scale = ea.iter().chain(&eb).map(|e| e.length_squared()).fold(0.0, f64::max);
    let (mut lo, mut hi) = (0.0f64, t_max);
    let mut overlaps_on = |l: DVec3| -> bool {
        // a (nearly) zero axis separates nothing
        if l.length_squared() <= 1e-24 * scale * scale {
            return true;
        }
        let (a0, a1) = project(a, l);
        let (b0, b1) = project(b, l);
        let v = dir.dot(l);
        // strict overlap at time t: a1 + t v > b0 and b1 > a0 + t v
        if v == 0.0 {
            return a1 > b0 && b1 > a0;
        }
        let (enter, exit) = if v > 0.0 { ((b0 - a1) / v, (b1 - a0) / v) } else { ((b1 - a0) / v, (b0 - a1) / v) };
        lo = lo.max(enter);
        hi = hi.min(exit);
        lo < hi
    };
    let axes_ok = overlaps_on(na)
        && overlaps_on(nb)
        && ea.iter().all(|e| eb.iter().all(|f| overlaps_on(e.cross(*f))))
        && ea.iter().all(|e| overlaps_on(na.cross(*e)))
        && eb.iter().all(|e| overlaps_on(nb.cross(*e)));
    (axes_ok && lo < hi).then_some(lo)
}

fn project(t: &[DVec3; 3], l: DVec3) -> (f64, f64) {
    let p = [t[0].dot(l), t[1].dot(l), t[2].dot(l)];
    (p[0].min(p[1]).min(p[2]), p[0].max(p[1]).max(p[2]))
}

/// Triangle `i` of `mesh` placed by `pose`, in `f64`.
fn triangle(mesh: &TriMesh, pose: &Pose, i: u32) -> [DVec3; 3] {
    let t = mesh.triangle(i);
    [t.a, t.b, t.c].map(|p| pose.transform_point(p).as_dvec3())
}

fn box_of(t: &[DVec3; 3]) -> Aabb {
    let lo = t[0].min(t[1]).min(t[2]).as_vec3();
    let hi = t[0].max(t[1]).max(t[2]).as_vec3();
    // f64 → f32 rounds to nearest: widen by a few ulps so the box still holds the triangle
    let pad = Vec3::splat(f32::EPSILON * 4.0) * lo.abs().max(hi.abs()).max(Vec3::splat(1e-30));
    Aabb::new(lo - pad, hi + pad)
}

/// Whether box `a`, moved by `t * dir` for some `t` in `[0, t_max]`, meets box `b` (closed
/// boxes, a little widened against rounding: a cull that never drops a real contact). Unlike
/// the box around the whole path, this follows a slanted path tightly.
fn box_path_meets(a: &Aabb, dir: Vec3, b: &Aabb, t_max: f32) -> bool {
    let (mut t0, mut t1) = (0.0f32, t_max);
    for k in 0..3 {
        let slack = 1e-6 * (a.maxs[k].abs().max(a.mins[k].abs()) + b.maxs[k].abs().max(b.mins[k].abs()));
        // a.max + t d >= b.min and a.min + t d <= b.max
        let (lo, hi) = (b.mins[k] - a.maxs[k] - slack, b.maxs[k] - a.mins[k] + slack);
        let d = dir[k];
        if d == 0.0 {
            if lo > 0.0 || hi < 0.0 {
                return false;
            }
        } else {
            let (enter, exit) = if d > 0.0 { (lo / d, hi / d) } else { (hi / d, lo / d) };
            t0 = t0.max(enter);
            t1 = t1.min(exit);
            if t0 > t1 {
                return false;
            }
        }
    }
    true
}

/// When `moving`, placed by `pose` and then translated along unit `dir`, first overlaps `fixed`
/// (in its own frame) within `t_max`. With `earliest == false` the search stops at any overlap
/// and returns its time (not necessarily the earliest).
///
/// Candidate pairs come from a simultaneous descent of the two BVHs (parry's
/// [`Bvh::leaf_pairs`](parry3d::partitioning::Bvh::leaf_pairs)): a pair of nodes is opened only
/// when the moving node's box, swept along `dir`, meets the fixed node's box, so whole subtrees
/// of both meshes are dropped at once, and each triangle is converted to `f64` once per call.
fn mesh_sweep(moving: &TriMesh, pose: &Pose, dir: Vec3, fixed: &TriMesh, t_max: f32, earliest: bool) -> Option<f32> {
    let placed = *pose != Pose::IDENTITY;
    let place = |aabb: Aabb| if placed { aabb.transform_by(pose) } else { aabb };
    if !box_path_meets(&place(moving.local_aabb()), dir, &fixed.local_aabb(), t_max) {
        return None;
    }
    let d = dir.as_dvec3();
    let best = std::cell::Cell::new(None::<f64>);
    let limit = || best.get().map_or(t_max, |b| b as f32);
    let mut moving_cache = TriangleCache::new(moving.num_triangles());
    let mut fixed_cache = TriangleCache::new(fixed.num_triangles());
    let pairs = moving.bvh().leaf_pairs(fixed.bvh(), |a, b| box_path_meets(&place(a.aabb()), dir, &b.aabb(), limit()));
    for (i, j) in pairs {
        let ta = moving_cache.get(i, || triangle(moving, pose, i));
        let tb = fixed_cache.get(j, || triangle(fixed, &Pose::IDENTITY, j));
        // leaves of the root level come without the check: test their boxes here
        if !box_path_meets(&box_of(&ta), dir, &box_of(&tb), limit()) {
            continue;
        }
        if let Some(t) = triangle_sweep(&ta, d, &tb, best.get().unwrap_or(t_max as f64)) {
            if !earliest {
                return Some(t as f32);
            }
            best.set(Some(best.get().map_or(t, |b| b.min(t))));
        }
    }
    best.get().map(|t| t as f32)
}

/// Triangles of one mesh in `f64`, each converted (and placed) the first time a pair needs it.
struct TriangleCache {
    /// Per triangle of the mesh: 0 when not yet converted, else its position in `triangles` + 1
    /// (a zeroed allocation: the operating system's zero pages make it free for big meshes).
    slot: Vec<u32>,
    triangles: Vec<[DVec3; 3]>,
}

impl TriangleCache {
    fn new(count: usize) -> Self {
        TriangleCache { slot: vec![0; count], triangles: Vec::new() }
    }

    fn get(&mut self, i: u32, make: impl FnOnce() -> [DVec3; 3]) -> [DVec3; 3] {
        let k = self.slot[i as usize];
        if k > 0 {
            return self.triangles[k as usize - 1];
        }
        let t = make();
        self.triangles.push(t);
        self.slot[i as usize] = self.triangles.len() as u32;
        t
    }
}

/// The candidate search before [`mesh_sweep`]'s simultaneous descent, kept as the reference
/// its tests compare against: the moving triangles whose path meets the fixed mesh's box, then
/// for each one query of the fixed BVH with its swept box.
fn mesh_sweep_per_triangle(moving: &TriMesh, pose: &Pose, dir: Vec3, fixed: &TriMesh, t_max: f32, earliest: bool) -> Option<f32> {
    // the moving triangles whose path meets the fixed mesh's box, found in the moving mesh's
    // own frame (the box placed there is a little larger, still a safe cull)
    let inverse = pose.inverse();
    let fixed_box = fixed.local_aabb().transform_by(&inverse);
    let local_dir = inverse.rotation * dir;
    let candidates = moving.bvh().leaves(|n| box_path_meets(&n.aabb(), local_dir, &fixed_box, t_max));
    sweep_triangles(candidates.map(|i| triangle(moving, pose, i)), dir, fixed, t_max, earliest)
}

/// [`sweep_distance`] by the per-triangle candidate search (the reference of the simultaneous
/// BVH descent; slower on large meshes in contact).
pub fn sweep_distance_reference(moving: &TriMesh, dir: Vec3, fixed: &TriMesh, t_max: f32) -> Option<f32> {
    mesh_sweep_per_triangle(moving, &Pose::IDENTITY, dir, fixed, t_max, true)
}

/// [`sweep_hits_at`] by the per-triangle candidate search (the reference of the simultaneous
/// BVH descent).
pub fn sweep_hits_at_reference(moving: &TriMesh, pose: &Pose, dir: Vec3, fixed: &TriMesh, t_max: f32) -> bool {
    mesh_sweep_per_triangle(moving, pose, dir, fixed, t_max, false).is_some()
}

/// [`mesh_sweep`] for moving triangles given one by one: each is swept against the fixed
/// triangles its path's box culling leaves.
fn sweep_triangles(moving: impl Iterator<Item = [DVec3; 3]>, dir: Vec3, fixed: &TriMesh, t_max: f32, earliest: bool) -> Option<f32> {
    let d = dir.as_dvec3();
    let mut best: Option<f64> = None;
    for ta in moving {
        let limit = best.unwrap_or(t_max as f64);
        let own = box_of(&ta);
        for j in fixed.bvh().leaves(|n| box_path_meets(&own, dir, &n.aabb(), limit as f32)) {
            if let Some(t) = triangle_sweep(&ta, d, &triangle(fixed, &Pose::IDENTITY, j), best.unwrap_or(t_max as f64)) {
                if !earliest {
                    return Some(t as f32);
                }
                best = Some(best.map_or(t, |b| b.min(t)));
            }
        }
    }
    best.map(|t| t as f32)
}

/// Whether two triangle meshes (same frame) cross: some pair of their triangles overlaps
/// strictly (touching is not crossing). One wholly inside the other is not found here.
pub fn meshes_cross(a: &TriMesh, b: &TriMesh) -> bool {
    meshes_cross_at(a, &Pose::IDENTITY, b)
}

/// [`meshes_cross`] with `a` placed by `pose` (`b` in its own frame).
pub fn meshes_cross_at(a: &TriMesh, pose: &Pose, b: &TriMesh) -> bool {
    // without motion every axis' interval is all of time or nothing
    mesh_sweep(a, pose, Vec3::ZERO, b, 1.0, false).is_some()
}

/// [`meshes_cross`] for a triangle soup `a` (no BVH of its own to build: each of its triangles
/// queries `b`'s).
pub fn soup_crosses(vertices: &[Vec3], triangles: &[[u32; 3]], b: &TriMesh) -> bool {
    let soup = triangles.iter().map(|t| t.map(|i| vertices[i as usize].as_dvec3()));
    // without motion every axis' interval is all of time or nothing
    sweep_triangles(soup, Vec3::ZERO, b, 1.0, false).is_some()
}

/// Whether `moving`, translated along unit `dir` by up to `t_max`, overlaps `fixed`.
pub fn sweep_hits(moving: &TriMesh, dir: Vec3, fixed: &TriMesh, t_max: f32) -> bool {
    mesh_sweep(moving, &Pose::IDENTITY, dir, fixed, t_max, false).is_some()
}

/// [`sweep_hits`] with `moving` first placed by `pose`.
pub fn sweep_hits_at(moving: &TriMesh, pose: &Pose, dir: Vec3, fixed: &TriMesh, t_max: f32) -> bool {
    mesh_sweep(moving, pose, dir, fixed, t_max, false).is_some()
}

/// How far `moving` travels along unit `dir` (up to `t_max`) before it first overlaps `fixed`.
pub fn sweep_distance(moving: &TriMesh, dir: Vec3, fixed: &TriMesh, t_max: f32) -> Option<f32> {
    mesh_sweep(moving, &Pose::IDENTITY, dir, fixed, t_max, true)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::Mesh;
    use parry3d::shape::TriMeshFlags;

    fn trimesh(m: Mesh) -> TriMesh {
        TriMesh::with_flags(m.vertices, m.triangles, TriMeshFlags::ORIENTED).unwrap()
    }

    fn cube(lo: Vec3, hi: Vec3) -> TriMesh {
        trimesh(Mesh::cuboid(lo, hi))
    }

    /// Parallel triangles carried through each other's plane meet at the
    /// instant they are coplanar when their interiors overlap there (a sheet of no thickness
    /// has no side faces whose crossing would say so); sliding in the plane, passing beside the
    /// other or only sharing an edge with it in the plane is no hit.
    #[test]
    fn parallel_triangles_passing_through_each_others_plane_meet() {
        let d = |x: f64, y: f64, z: f64| DVec3::new(x, y, z);
        let sheet = [d(0.0, 0.0, 1.0), d(1.0, 0.0, 1.0), d(0.0, 1.0, 1.0)];
        let floor = [d(-5.0, -5.0, 0.0), d(5.0, -5.0, 0.0), d(0.0, 5.0, 0.0)];
        let t = triangle_sweep(&sheet, d(0.0, 0.0, -1.0), &floor, 10.0).expect("the sheet goes through the floor");
        assert!((t - 1.0).abs() < 1e-12, "{t}");
        // slanted: at the instant the sheet reaches the plane
        let slant = d(0.6, 0.0, -0.8);
        assert!((triangle_sweep(&sheet, slant, &floor, 10.0).unwrap() - 1.25).abs() < 1e-12);
        // not far enough, away from it, in the plane, beside it, or sharing only an edge
        assert_eq!(triangle_sweep(&sheet, d(0.0, 0.0, -1.0), &floor, 0.9), None);
        assert_eq!(triangle_sweep(&sheet, d(0.0, 0.0, 1.0), &floor, 10.0), None);
        let beside = [d(20.0, 0.0, 1.0), d(21.0, 0.0, 1.0), d(20.0, 1.0, 1.0)];
        assert_eq!(triangle_sweep(&beside, d(0.0, 0.0, -1.0), &floor, 10.0), None);
        let on_floor = sheet.map(|p| p - d(0.0, 0.0, 1.0));
        assert_eq!(triangle_sweep(&on_floor, d(1.0, 0.0, 0.0), &floor, 10.0), None);
        let neighbour = [d(1.0, 0.0, 0.0), d(0.0, 1.0, 0.0), d(1.0, 1.0, 0.0)];
        assert_eq!(triangle_sweep(&sheet, d(0.0, 0.0, -1.0), &neighbour, 10.0), None);
    }

    #[test]
    fn head_on_contact_time_is_exact() {
        let a = cube(Vec3::ZERO, Vec3::ONE);
        let b = cube(Vec3::new(2.5, 0.2, 0.2), Vec3::new(3.0, 0.8, 0.8));
        let t = sweep_distance(&a, Vec3::X, &b, 10.0).unwrap();
        assert!((t - 1.5).abs() < 1e-6, "{t}");
        assert!(sweep_distance(&a, Vec3::X, &b, 1.4).is_none(), "beyond t_max");
        assert!(!sweep_hits(&a, -Vec3::X, &b, 10.0));
        // diagonally, into a box that is long along y: met when the face x = 1 reaches 2.5
        let long = cube(Vec3::new(2.5, 0.2, 0.2), Vec3::new(3.0, 5.0, 0.8));
        let d = Vec3::new(1.0, 1.0, 0.0).normalize();
        let t = sweep_distance(&a, d, &long, 10.0).unwrap();
        assert!((t - 1.5 * 2f32.sqrt()).abs() < 1e-5, "{t}");
    }

    #[test]
    fn sliding_along_a_face_at_a_tiny_gap_is_free_and_touching_faces_do_not_count() {
        // a thin plate 0.08 mm above a long profile, sliding along it: parry's cast called this
        // kind of motion a hit
        let profile = cube(Vec3::new(0.023, 0.0, 0.003), Vec3::new(0.377, 0.02, 0.023));
        let gap = 8.3e-5;
        let plate = cube(Vec3::new(0.026, 0.0, 0.023 + gap), Vec3::new(0.04, 0.02, 0.026));
        for dir in [Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, Vec3::Z] {
            assert!(!sweep_hits(&plate, dir, &profile, 1.0), "{dir:?}");
        }
        assert!(sweep_hits(&plate, -Vec3::Z, &profile, 1.0));
        // exactly touching: free to slide, blocked going in
        let touching = cube(Vec3::new(0.026, 0.0, 0.023), Vec3::new(0.04, 0.02, 0.026));
        assert!(!sweep_hits(&touching, Vec3::X, &profile, 1.0));
        assert_eq!(sweep_distance(&touching, -Vec3::Z, &profile, 1.0), Some(0.0));
    }

    #[test]
    fn crossing_meshes_and_touching_ones() {
        let a = cube(Vec3::ZERO, Vec3::ONE);
        assert!(meshes_cross(&a, &cube(Vec3::splat(0.5), Vec3::splat(2.0))));
        assert!(!meshes_cross(&a, &cube(Vec3::new(1.0, 0.0, 0.0), Vec3::new(2.0, 1.0, 1.0))), "touching");
        assert!(!meshes_cross(&a, &cube(Vec3::new(1.0 + 1e-6, 0.2, 0.2), Vec3::new(2.0, 0.8, 0.8))));
        // a thin slab crossing one face by a micrometre, at millimetre scale
        let small = cube(Vec3::ZERO, Vec3::splat(0.005));
        let slab = Mesh::cuboid(Vec3::new(0.005 - 1e-6, 0.001, 0.001), Vec3::new(0.01, 0.004, 0.004));
        assert!(soup_crosses(&slab.vertices, &slab.triangles, &small));
        assert!(meshes_cross(&small, &trimesh(slab)));
        // placed by a pose: turned a quarter about z and moved next to the unit cube
        let turn = Pose::from_parts(Vec3::new(2.0, 0.0, 0.0), crate::math::Rot::from_rotation_z(std::f32::consts::FRAC_PI_2));
        let bar = cube(Vec3::new(0.0, 0.0, 0.2), Vec3::new(0.5, 0.9, 0.8)); // x in [1.1, 2] once turned
        assert!(!meshes_cross_at(&bar, &turn, &a));
        let closer = Pose::from_parts(Vec3::new(1.5, 0.0, 0.0), turn.rotation); // x in [0.6, 1.5]
        assert!(meshes_cross_at(&bar, &closer, &a));
        assert!(sweep_hits_at(&bar, &turn, -Vec3::X, &a, 1.0) && !sweep_hits_at(&bar, &turn, -Vec3::X, &a, 0.05));
    }

    #[test]
    fn coplanar_and_parallel_triangles() {
        let t = |p: [[f64; 3]; 3]| p.map(DVec3::from_array);
        let a = t([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]);
        // coplanar, ahead along +x: surfaces in one plane only touch (the solids' other faces
        // cross when they really meet)
        let b = t([[2.0, 0.0, 0.0], [3.0, 0.0, 0.0], [2.0, 1.0, 0.0]]);
        assert_eq!(triangle_sweep(&a, DVec3::X, &b, 10.0), None);
        // the same triangle turned upright across the path: met after 1
        let upright = t([[2.0, 0.0, -1.0], [2.0, 0.0, 1.0], [2.0, 1.0, 0.0]]);
        let hit = triangle_sweep(&a, DVec3::X, &upright, 10.0).unwrap();
        assert!((hit - 1.0).abs() < 1e-12, "{hit}");
        // the same triangle one unit above: sliding parallel never meets it
        let above = t([[2.0, 0.0, 1.0], [3.0, 0.0, 1.0], [2.0, 1.0, 1.0]]);
        assert_eq!(triangle_sweep(&a, DVec3::X, &above, 10.0), None);
        // crossing triangles overlap at once
        let cross = t([[0.2, 0.2, -1.0], [0.2, 0.2, 1.0], [0.3, -1.0, 0.0]]);
        assert_eq!(triangle_sweep(&a, DVec3::X, &cross, 10.0), Some(0.0));
    }

    #[test]
    fn a_peg_leaves_its_zero_clearance_hole_only_along_the_axis() {
        let a = crate::fixtures::peg_in_hole();
        let m = |i: usize| {
            let mut mesh = a.parts[i].mesh.clone();
            mesh.weld();
            mesh.orient_outward();
            mesh
        };
        let (plate, peg) = (m(0), m(1));
        let (v, t) = crate::erode::eroded_mesh(&peg.vertices, &peg.triangles, 1e-4);
        let shrunk = TriMesh::with_flags(v, t, TriMeshFlags::ORIENTED).unwrap();
        let plate = trimesh(plate);
        assert!(!sweep_hits(&shrunk, Vec3::Z, &plate, 10.0));
        for dir in [Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, -Vec3::Z] {
            assert!(sweep_hits(&shrunk, dir, &plate, 10.0), "{dir:?}");
        }
    }
}
