//! The collision world: every part as a parry triangle mesh, the tolerance policy, candidate
//! removal directions, the contact graph, and the cached pairwise blocking relation.
//!
//! The straight-line removal test rests on one fact: a translation along `d` collides with a
//! union of obstacles iff it collides with one of them, and a part that hits `q` does so before
//! its bounds clear the bounds of what remains (which contain `q`). So "does `q` block `p` along
//! `d`" is a property of the pair, independent of the state. asp computes it once per
//! (part, direction, neighbour) — lazily, the first time a part is tested, in parallel — and every
//! later removal test of that part is a few bitset operations.

use crate::assembly::Assembly;
use crate::erode::eroded_vertices;
use crate::error::{GeomError, Result};
use crate::feasibility::{Motion, Stability};
use crate::math::{aabb_of, sweep_overlap, Aabb, Pose, Vec3};
use crate::mesh::Mesh;
use crate::partset::PartSet;
use parry3d::query::{self, ClosestPoints, NonlinearRigidMotion, PointQuery, ShapeCastOptions};
use parry3d::shape::{TriMesh, TriMeshFlags};
use rayon::prelude::*;
use std::collections::BTreeMap;
use std::sync::{Arc, Mutex, OnceLock};

/// Settings of the collision world. Lengths in metres; `None` means "relative to the model".
#[derive(Clone, Debug)]
pub struct WorldConfig {
    /// Contact tolerance: a motion is blocked only when it pushes a part deeper than this into
    /// another. Default `1e-4 ×` the model's diagonal.
    pub tolerance: Option<f32>,
    /// Parts closer than this are in contact (the stability graph). Default `1e-3 ×` diagonal.
    pub contact_distance: Option<f32>,
    /// How many clustered surface-normal directions join the six axis directions (each with its
    /// opposite). Default 10.
    pub normal_clusters: usize,
    /// Normals within this angle (degrees) fall into one cluster. Default 10.
    pub cluster_angle_deg: f32,
    /// Extra directions sampled evenly on the sphere (Fibonacci lattice). Default 0.
    pub sphere_directions: usize,
    /// Two parts overlapping in the input by more than this fraction of the smaller part's
    /// thinnest extent cannot be planned (error); smaller overlaps are warned about and absorbed
    /// by shrinking that pair's test by the overlap depth. Default 0.25.
    pub max_overlap_fraction: f32,
}

impl Default for WorldConfig {
    fn default() -> Self {
        WorldConfig {
            tolerance: None,
            contact_distance: None,
            normal_clusters: 10,
            cluster_angle_deg: 10.0,
            sphere_directions: 0,
            max_overlap_fraction: 0.25,
        }
    }
}

/// One part's collision geometry.
struct Geom {
    mesh: TriMesh,
    aabb: Aabb,
    /// Eroded copies keyed by the erosion amount's bits.
    eroded: Mutex<BTreeMap<u32, Arc<TriMesh>>>,
    closed: bool,
}

impl Geom {
    fn new(mesh: &Mesh, weld_eps: f32) -> Result<(Geom, bool)> {
        let mut m = mesh.clone();
        m.weld(weld_eps);
        m.orient_outward();
        let closed = m.topology().is_closed_manifold();
        let aabb = m.aabb().ok_or_else(|| GeomError::config("empty mesh"))?;
        let mesh = TriMesh::with_flags(m.vertices, m.triangles, TriMeshFlags::ORIENTED)
            .map_err(|e| GeomError::config(format!("cannot build a collision mesh: {e}")))?;
        Ok((Geom { mesh, aabb, eroded: Mutex::new(BTreeMap::new()), closed }, closed))
    }

    fn eroded(&self, amount: f32) -> Arc<TriMesh> {
        let mut cache = self.eroded.lock().unwrap_or_else(|e| e.into_inner());
        cache
            .entry(amount.to_bits())
            .or_insert_with(|| {
                let v = eroded_vertices(self.mesh.vertices(), self.mesh.indices(), amount);
                Arc::new(
                    TriMesh::with_flags(v, self.mesh.indices().to_vec(), TriMeshFlags::ORIENTED)
                        .unwrap_or_else(|_| self.mesh.clone()),
                )
            })
            .clone()
    }
}

/// The parts of an assembly as collision objects, plus an optional ground plane.
pub struct World {
    assembly: Assembly,
    geoms: Vec<Geom>,
    ground: Option<usize>,
    tolerance: f32,
    contact_distance: f32,
    directions: Vec<Vec3>,
    contacts: Vec<PartSet>,
    overlaps: BTreeMap<(usize, usize), f32>,
    fixed: PartSet,
    rows: Vec<OnceLock<Vec<PartSet>>>,
    warnings: Vec<String>,
}

impl World {
    /// Prepares `assembly` for planning: welds and orients meshes, warns about open or
    /// non-manifold meshes and overlapping parts, adds a ground plane under the lowest point when
    /// no part is fixed, computes candidate directions and the contact graph.
    pub fn new(assembly: Assembly, config: &WorldConfig) -> Result<World> {
        assembly.validate()?;
        let diag = assembly.diagonal().max(f32::MIN_POSITIVE);
        let tolerance = config.tolerance.unwrap_or(1e-4 * diag);
        let contact_distance = config.contact_distance.unwrap_or(1e-3 * diag);
        if !(tolerance > 0.0 && tolerance.is_finite()) || !(contact_distance > 0.0) {
            return Err(GeomError::config("tolerance and contact distance must be positive"));
        }
        let mut warnings = assembly.warnings.clone();
        let weld_eps = 1e-7 * diag;
        let mut geoms = Vec::with_capacity(assembly.len() + 1);
        for p in &assembly.parts {
            let (g, closed) = Geom::new(&p.mesh, weld_eps).map_err(|e| GeomError::Assembly {
                path: assembly.source.clone(),
                reason: format!("part '{}': {e}", p.name),
            })?;
            if !closed {
                let t = p.mesh.topology();
                warnings.push(format!(
                    "part '{}': mesh is not closed and manifold ({} open, {} non-manifold, {} misoriented edges); its removal tests may be conservative",
                    p.name, t.boundary_edges, t.non_manifold_edges, t.misoriented_edges
                ));
            }
            geoms.push(g);
        }
        let n = assembly.len();
        let mut fixed = PartSet::from_indices(n + 1, assembly.parts.iter().enumerate().filter(|(_, p)| p.fixed).map(|(i, _)| i));
        let ground = if fixed.is_empty() {
            let bb = assembly.aabb().expect("validated assembly has vertices");
            let (g, _) = Geom::new(&ground_box(&bb, assembly.up.vector(), diag), weld_eps)?;
            geoms.push(g);
            fixed.insert(n);
            Some(n)
        } else {
            None
        };
        let directions = candidate_directions(&assembly, config);
        let rows = (0..n).map(|_| OnceLock::new()).collect();
        let mut world = World {
            assembly,
            geoms,
            ground,
            tolerance,
            contact_distance,
            directions,
            contacts: Vec::new(),
            overlaps: BTreeMap::new(),
            fixed,
            rows,
            warnings,
        };
        world.measure_contacts(config.max_overlap_fraction)?;
        Ok(world)
    }

    /// Finds contacts (parts within the contact distance) and input overlaps between parts.
    fn measure_contacts(&mut self, max_overlap_fraction: f32) -> Result<()> {
        let count = self.geoms.len();
        let pairs: Vec<(usize, usize)> = (0..count)
            .flat_map(|i| ((i + 1)..count).map(move |j| (i, j)))
            .filter(|&(i, j)| {
                let m = self.contact_distance;
                let a = &self.geoms[i].aabb;
                let b = &self.geoms[j].aabb;
                (0..3).all(|k| a.mins[k] <= b.maxs[k] + m && b.mins[k] <= a.maxs[k] + m)
            })
            .collect();
        let found: Vec<(usize, usize, bool, f32)> = pairs
            .par_iter()
            .map(|&(i, j)| {
                let (a, b) = (&self.geoms[i].mesh, &self.geoms[j].mesh);
                let id = Pose::IDENTITY;
                let touching = !matches!(
                    query::closest_points(&id, a, &id, b, self.contact_distance),
                    Ok(ClosestPoints::Disjoint)
                );
                let depth = if touching {
                    penetration_depth(&self.geoms[i], &self.geoms[j])
                        .max(penetration_depth(&self.geoms[j], &self.geoms[i]))
                } else {
                    0.0
                };
                (i, j, touching, depth)
            })
            .collect();
        self.contacts = vec![PartSet::empty(count); count];
        for (i, j, touching, depth) in found {
            if touching {
                self.contacts[i].insert(j);
                self.contacts[j].insert(i);
            }
            if depth > self.tolerance {
                let thinnest = |k: usize| {
                    let e = self.geoms[k].aabb.maxs - self.geoms[k].aabb.mins;
                    e.min_element()
                };
                let limit = max_overlap_fraction * thinnest(i).min(thinnest(j));
                let units = &self.assembly.units;
                let msg = format!(
                    "parts '{}' and '{}' overlap by {:.4} {} in the input (tolerance {:.4} {})",
                    self.name(i),
                    self.name(j),
                    units.from_metres(depth as f64),
                    units.name,
                    units.from_metres(self.tolerance as f64),
                    units.name
                );
                if depth > limit {
                    return Err(GeomError::Assembly {
                        path: self.assembly.source.clone(),
                        reason: format!("{msg}, more than {:.0}% of the thinner part: fix the model or raise --tolerance", max_overlap_fraction * 100.0),
                    });
                }
                self.warnings.push(format!("{msg}; their mutual tests allow that overlap"));
                self.overlaps.insert((i, j), depth);
            }
        }
        Ok(())
    }

    /// The assembly this world was built from.
    pub fn assembly(&self) -> &Assembly {
        &self.assembly
    }

    /// Number of real parts (the ground, when present, has index `num_parts()`).
    pub fn num_parts(&self) -> usize {
        self.assembly.len()
    }

    /// The index of the virtual ground part, when no part of the model is fixed.
    pub fn ground(&self) -> Option<usize> {
        self.ground
    }

    /// The name of part `i` (`ground` for the virtual ground).
    pub fn name(&self, i: usize) -> &str {
        self.assembly.parts.get(i).map(|p| p.name.as_str()).unwrap_or("ground")
    }

    /// Fixed parts, the ground included.
    pub fn fixed(&self) -> &PartSet {
        &self.fixed
    }

    /// The contact tolerance in metres.
    pub fn tolerance(&self) -> f32 {
        self.tolerance
    }

    /// The contact distance of the stability graph, in metres.
    pub fn contact_distance(&self) -> f32 {
        self.contact_distance
    }

    /// Candidate straight-line removal directions (unit vectors).
    pub fn directions(&self) -> &[Vec3] {
        &self.directions
    }

    /// Parts in contact with part `i` (ground included).
    pub fn contacts(&self, i: usize) -> &PartSet {
        &self.contacts[i]
    }

    /// Pairs that overlap in the input beyond the tolerance, with their depth in metres.
    pub fn overlaps(&self) -> &BTreeMap<(usize, usize), f32> {
        &self.overlaps
    }

    /// Warnings found while preparing (open meshes, overlaps), one line each.
    pub fn warnings(&self) -> &[String] {
        &self.warnings
    }

    /// Whether part `i`'s mesh is closed and manifold.
    pub fn is_closed(&self, i: usize) -> bool {
        self.geoms[i].closed
    }

    /// The bounding box of part `i` (ground included) in its assembled pose.
    pub fn aabb(&self, i: usize) -> &Aabb {
        &self.geoms[i].aabb
    }

    /// The collision mesh of part `i` in its assembled pose.
    pub fn mesh(&self, i: usize) -> &TriMesh {
        &self.geoms[i].mesh
    }

    /// How much part `p`'s test against `q` shrinks `p`: the tolerance plus their input overlap.
    pub fn erosion(&self, p: usize, q: usize) -> f32 {
        self.tolerance + self.overlaps.get(&(p.min(q), p.max(q))).copied().unwrap_or(0.0)
    }

    /// Part `p` shrunk by `amount` (cached).
    pub fn eroded(&self, p: usize, amount: f32) -> Arc<TriMesh> {
        self.geoms[p].eroded(amount)
    }

    /// The state plus the fixed parts that are always present (ground included).
    pub fn with_fixed(&self, state: &PartSet) -> PartSet {
        let mut s = state.clone();
        s.union_with(&self.fixed);
        s
    }

    /// Whether `q` blocks `p` moving along `dir` (unit) from the assembled pose, to infinity.
    pub fn pair_blocks(&self, p: usize, q: usize, dir: Vec3) -> bool {
        let Some((_, t1)) = sweep_overlap(&self.geoms[p].aabb, dir, &self.geoms[q].aabb) else {
            return false;
        };
        let moving = self.eroded(p, self.erosion(p, q));
        let options = ShapeCastOptions {
            max_time_of_impact: t1,
            target_distance: 0.0,
            stop_at_penetration: true,
            compute_impact_geometry_on_penetration: false,
        };
        let id = Pose::IDENTITY;
        // an unsupported pair would be a parry gap: block, the conservative answer
        query::cast_shapes(&id, dir, &*moving, &id, Vec3::ZERO, &self.geoms[q].mesh, options)
            .map(|hit| hit.is_some())
            .unwrap_or(true)
    }

    /// For each candidate direction, every part (ground included) that blocks `p` along it.
    /// Computed once per part, in parallel, then cached.
    pub fn blocking_row(&self, p: usize) -> &[PartSet] {
        self.rows[p].get_or_init(|| {
            let count = self.geoms.len();
            let jobs: Vec<(usize, usize)> = (0..self.directions.len())
                .flat_map(|k| (0..count).filter(move |&q| q != p).map(move |q| (k, q)))
                .collect();
            let blocked: Vec<bool> =
                jobs.par_iter().map(|&(k, q)| self.pair_blocks(p, q, self.directions[k])).collect();
            let mut row = vec![PartSet::empty(count); self.directions.len()];
            for (&(k, q), b) in jobs.iter().zip(blocked) {
                if b {
                    row[k].insert(q);
                }
            }
            row
        })
    }

    /// Whether part `p`'s blocking row is already computed.
    pub fn row_cached(&self, p: usize) -> bool {
        self.rows[p].get().is_some()
    }

    /// How far `p` must travel along `dir` for its bounds to clear the bounds of the other
    /// present real parts (plus the contact distance); at least that margin.
    pub fn clearance(&self, p: usize, state: &PartSet, dir: Vec3) -> f32 {
        let others = aabb_of(
            state
                .iter()
                .filter(|&q| q != p && q < self.num_parts())
                .flat_map(|q| [self.geoms[q].aabb.mins, self.geoms[q].aabb.maxs]),
        );
        let a = &self.geoms[p].aabb;
        let t = match others {
            None => 0.0,
            Some(u) => (0..3)
                .filter(|&i| dir[i].abs() > 1e-6)
                .map(|i| {
                    if dir[i] > 0.0 {
                        (u.maxs[i] - a.mins[i]) / dir[i]
                    } else {
                        (a.maxs[i] - u.mins[i]) / -dir[i]
                    }
                })
                .fold(f32::INFINITY, f32::min)
                .max(0.0),
        };
        t + self.contact_distance
    }

    /// The straight-line removal test of `p` in `state`: the free direction with the shortest
    /// travel, or the union of all blockers when every direction is blocked.
    pub fn linear_removal(&self, p: usize, state: &PartSet) -> std::result::Result<Motion, PartSet> {
        let present = self.with_fixed(state);
        let row = self.blocking_row(p);
        let mut best: Option<(f32, Vec3)> = None;
        let mut blockers = PartSet::empty(self.geoms.len());
        for (k, dir) in self.directions.iter().enumerate() {
            let b = row[k].intersection(&present);
            if b.is_empty() {
                let d = self.clearance(p, state, *dir);
                if best.is_none_or(|(bd, _)| d < bd) {
                    best = Some((d, *dir));
                }
            } else {
                blockers.union_with(&b);
            }
        }
        match best {
            Some((distance, direction)) => Ok(Motion::Linear { direction, distance }),
            None => Err(blockers),
        }
    }

    /// Contact-graph stability: every present part is linked through contacts to a fixed part.
    pub fn contact_stability(&self, state: &PartSet) -> Stability {
        let present = self.with_fixed(state);
        let mut reached = present.intersection(&self.fixed);
        let mut frontier: Vec<usize> = reached.iter().collect();
        while let Some(i) = frontier.pop() {
            for j in self.contacts[i].intersection(&present).iter() {
                if !reached.contains(j) {
                    reached.insert(j);
                    frontier.push(j);
                }
            }
        }
        let floating = PartSet::from_indices(
            self.geoms.len(),
            present.iter().filter(|&i| !reached.contains(i)),
        );
        if floating.is_empty() {
            Stability::Stable
        } else {
            Stability::Unstable { floating }
        }
    }

    /// The first present part that part `p` penetrates deeper than the tolerance while moving
    /// from pose `a` to pose `b` (pivot moving straight, rotation by slerp about it; see
    /// [`crate::feasibility::interpolate_about`]) — exact continuous collision detection with
    /// parry's nonlinear shape cast.
    pub fn collision_between(&self, p: usize, a: &Pose, b: &Pose, pivot: Vec3, state: &PartSet) -> Option<usize> {
        let present = self.with_fixed(state);
        let (ca, cb) = (a.transform_point(pivot), b.transform_point(pivot));
        let radius = {
            let bb = &self.geoms[p].aabb;
            (bb.maxs - pivot).abs().max((bb.mins - pivot).abs()).length()
        };
        let sweep = Aabb::new(ca.min(cb) - Vec3::splat(radius), ca.max(cb) + Vec3::splat(radius));
        let rel = b.rotation * a.rotation.inverse();
        let motion = NonlinearRigidMotion::new(*a, pivot, cb - ca, rel.to_scaled_axis());
        let still = NonlinearRigidMotion::constant_position(Pose::IDENTITY);
        let hit = present.iter().filter(|&q| q != p).find(|&q| {
            let qb = &self.geoms[q].aabb;
            if !(0..3).all(|k| sweep.mins[k] < qb.maxs[k] && qb.mins[k] < sweep.maxs[k]) {
                return false;
            }
            let moving = self.eroded(p, self.erosion(p, q));
            let fixed = &self.geoms[q].mesh;
            let hit = if rel.angle_between(crate::math::Rot::IDENTITY) < 1e-6 {
                // pure translation: the (faster) linear cast is exact
                let options = ShapeCastOptions {
                    max_time_of_impact: 1.0,
                    target_distance: 0.0,
                    stop_at_penetration: true,
                    compute_impact_geometry_on_penetration: false,
                };
                query::cast_shapes(a, cb - ca, &*moving, &Pose::IDENTITY, Vec3::ZERO, fixed, options)
            } else {
                query::cast_shapes_nonlinear(&motion, &*moving, &still, fixed, 0.0, 1.0, true)
            };
            hit.map_or(true, |h| h.is_some())
        });
        hit
    }

    /// The first present part that part `p`, displaced by `pose` (applied to its assembled world
    /// position), penetrates deeper than the tolerance — the static test of the path planner.
    pub fn collision_at(&self, p: usize, pose: &Pose, state: &PartSet) -> Option<usize> {
        let present = self.with_fixed(state);
        let bb = self.geoms[p].aabb.transform_by(pose);
        let id = Pose::IDENTITY;
        let hit = present.iter().filter(|&q| q != p).find(|&q| {
            let qb = &self.geoms[q].aabb;
            if !(0..3).all(|k| bb.mins[k] < qb.maxs[k] && qb.mins[k] < bb.maxs[k]) {
                return false;
            }
            let moving = self.eroded(p, self.erosion(p, q));
            let fixed = &self.geoms[q].mesh;
            query::intersection_test(pose, &*moving, &id, fixed).map_or(true, |r| r.intersecting)
                || contains_point(fixed, pose.transform_point(moving.vertices()[0]))
                || contains_point(&moving, pose.inverse_transform_point(fixed.vertices()[0]))
        });
        hit
    }
}

/// Whether `point` is inside the closed mesh.
fn contains_point(mesh: &TriMesh, point: Vec3) -> bool {
    mesh.local_aabb().contains_local_point(point) && mesh.project_local_point(point, false).is_inside
}

/// How deep the vertices of `a` reach inside `b` (0 when none is inside).
fn penetration_depth(a: &Geom, b: &Geom) -> f32 {
    if !b.closed {
        return 0.0;
    }
    a.mesh
        .vertices()
        .iter()
        .filter(|v| b.aabb.contains_local_point(**v))
        .map(|v| {
            let proj = b.mesh.project_local_point(*v, false);
            if proj.is_inside {
                (proj.point - *v).length()
            } else {
                0.0
            }
        })
        .fold(0.0, f32::max)
}

/// A slab under the model whose top face lies at the model's lowest point along `up`.
fn ground_box(bb: &Aabb, up: Vec3, diag: f32) -> Mesh {
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
