//! Voxel models at voxel speed: the removal tests of an assembly whose parts
//! are unions of axis-aligned boxes on one rectilinear lattice (Soma cubes and their floor,
//! polycubes, burrs) answered from occupancy with bit operations, with no collision world.
//!
//! [`VoxelChecker`] is a [`FeasibilityChecker`] that gives every answer the collision world's
//! [`Checker`](crate::Checker) gives on such a model — the same blockers, motions (directions
//! and travel, to the bit), stability and counters — so the same search over it makes the same
//! plan. What it shares with the world it calls, not copies: the part classification
//! ([`PartShape::classify`]), the candidate directions, the free-direction choice and the travel
//! (`best_free_direction`, `clearance_past`), the ground slab and the box contact rule. Only the
//! pairwise blocking differs in how it is found: the world sweeps every box of `p` against
//! every box of `q` per direction ([`crate::boxes::first_overlap`], lazily per part); here the
//! distinct box coordinates per axis cut space into slabs, every box is a union of lattice
//! cells, and `q` blocks `p` along `+x` exactly when some row of cells along x holds a cell of
//! `q` after a cell of `p` (all rows at once, one pass per axis, part sets as `u64` masks).
//!
//! That equivalence holds when the slabs are thicker than the tolerance and no two parts share
//! a cell; [`VoxelChecker::new`] refuses every model it cannot answer exactly (a mesh part, an
//! overlap, an open mesh, a direction off the axes, more than 63 parts...) and the caller uses
//! the collision world. What it cannot do at all — the path planner, a subassembly's own plan —
//! it refuses at run time: [`VoxelChecker::needs_world`] tells the caller to plan again on the
//! world.

use crate::assembly::Assembly;
use crate::boxes::{self, PartShape};
use crate::feasibility::{CounterSnapshot, Counters, FeasibilityChecker, Motion, MotionKind, Outcome, Stability};
use crate::math::{aabb_of, Aabb, Vec3};
use crate::mesh::Mesh;
use crate::partset::PartSet;
use crate::world::{
    best_free_direction, candidate_directions, clearance_past, ground_box, WorldConfig, DEFAULT_RELATIVE_CONTACT,
    DEFAULT_RELATIVE_TOLERANCE,
};
use std::sync::atomic::{AtomicBool, Ordering};

/// The most lattice cells (all slabs multiplied) a voxel checker builds.
const MAX_LATTICE_CELLS: usize = 1 << 18;

/// Removal tests of a voxel model from occupancy bits (see the module docs).
pub struct VoxelChecker {
    /// Parts of the model (the ground, when added, is index `parts`).
    parts: usize,
    /// Parts plus the ground, when there is one: the room of every part set.
    count: usize,
    up: Vec3,
    directions: Vec<Vec3>,
    /// Bounds of every part (ground included), as the world's.
    aabbs: Vec<Aabb>,
    contact_distance: f32,
    tolerance: f32,
    fixed: u64,
    /// `rows[p][k]`: the parts (ground included) that block part `p` along direction `k`.
    rows: Vec<[u64; 6]>,
    /// Parts in contact with each part (ground included).
    contacts: Vec<u64>,
    warnings: Vec<String>,
    counters: Counters,
    needs_world: AtomicBool,
}

impl VoxelChecker {
    /// The voxel checker of `assembly` under `config` (the world's settings), or `None` when
    /// it cannot answer as the collision world would: a part that is not a union of boxes (or
    /// whose extras do not describe its mesh), a mesh that is not closed and manifold, parts
    /// that overlap or come closer than the tolerance without touching, candidate directions
    /// other than the six axes, more than 63 parts, slabs of the lattice thinner than four
    /// tolerances, or more than 2^18 lattice cells.
    pub fn new(assembly: &Assembly, config: &WorldConfig) -> Option<VoxelChecker> {
        let n = assembly.len();
        if n == 0 || n > 63 || !config.exact_boxes || assembly.validate().is_err() {
            return None;
        }
        // the classification first: a model with a mesh part (most CAD models) is declined at
        // its first one, before any work in proportion to the model's size
        let mut part_boxes: Vec<Vec<Aabb>> = Vec::with_capacity(n + 1);
        for p in &assembly.parts {
            match PartShape::classify(p, true) {
                (shape, None) => part_boxes.push(shape.boxes()?),
                (_, Some(_)) => return None,
            }
        }
        let diag = assembly.diagonal().max(f32::MIN_POSITIVE);
        let tolerance = config.tolerance.unwrap_or(DEFAULT_RELATIVE_TOLERANCE * diag);
        let contact_distance = config.contact_distance.unwrap_or(DEFAULT_RELATIVE_CONTACT * diag);
        if !(tolerance.is_finite() && tolerance > 0.0 && contact_distance.is_finite() && contact_distance > 0.0) {
            return None;
        }
        let mut aabbs = Vec::with_capacity(n + 1);
        for p in &assembly.parts {
            if crate::validate::collapsed(p).is_some() {
                return None;
            }
            aabbs.push(closed_bounds(&p.mesh)?);
        }
        let mut fixed: u64 = assembly.parts.iter().enumerate().filter(|(_, p)| p.fixed).fold(0, |m, (i, _)| m | 1 << i);
        if fixed == 0 {
            let ground = ground_box(&assembly.aabb()?, assembly.up.vector(), diag).aabb()?;
            aabbs.push(ground);
            part_boxes.push(vec![ground]);
            fixed = 1 << n;
        }
        let count = aabbs.len();
        let axes = [Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, Vec3::Z, -Vec3::Z];
        // every face in an axis plane: each normal cluster is (within rounding) an axis, which
        // the six axes already hold, so the candidates are the axes (without clustering them)
        let axial = |m: &Mesh| {
            m.triangles.iter().all(|t| (0..3).any(|k| t.iter().all(|&i| m.vertices[i as usize][k] == m.vertices[t[0] as usize][k])))
        };
        let directions = if config.sphere_directions == 0 && assembly.parts.iter().all(|p| axial(&p.mesh)) {
            axes.to_vec()
        } else {
            candidate_directions(assembly, config)
        };
        if directions != axes {
            return None;
        }
        let contacts = contacts(&aabbs, &part_boxes, tolerance, contact_distance)?;
        let rows = blocking_rows(&part_boxes, tolerance)?;
        Some(VoxelChecker {
            parts: n,
            count,
            up: assembly.up.vector(),
            directions,
            aabbs,
            contact_distance,
            tolerance,
            fixed,
            rows,
            contacts,
            warnings: assembly.warnings.clone(),
            counters: Counters::default(),
            needs_world: AtomicBool::new(false),
        })
    }

    /// Whether a search asked for something only the collision world answers (the path
    /// planner, a subassembly's own plan): its answers here were refusals, so its plan must be
    /// made again on the world.
    pub fn needs_world(&self) -> bool {
        self.needs_world.load(Ordering::Relaxed)
    }

    /// The contact tolerance in metres (the world's).
    pub fn tolerance(&self) -> f32 {
        self.tolerance
    }

    /// The warnings the world would report (the model's own: a voxel checker is only made when
    /// preparing the model finds nothing to warn about).
    pub fn warnings(&self) -> &[String] {
        &self.warnings
    }

    /// For each candidate direction (+x, −x, +y, −y, +z, −z), every part (ground included)
    /// that blocks `p` along it: the world's [`crate::world::Blocking::row`].
    pub fn blocking_row(&self, p: usize) -> Vec<PartSet> {
        self.rows[p].iter().map(|&m| self.set(m)).collect()
    }

    /// Parts in contact with part `i` (ground included): the world's [`crate::world::Contacts::of`].
    pub fn contacts(&self, i: usize) -> PartSet {
        self.set(self.contacts[i])
    }

    fn set(&self, mask: u64) -> PartSet {
        PartSet::from_words(self.count, &[mask])
    }

    fn mask(set: &PartSet) -> u64 {
        set.words().first().copied().unwrap_or(0)
    }

    fn with_fixed(&self, state: u64) -> u64 {
        state | self.fixed
    }

    /// The straight removal of the parts of `group` from `state` among the `present` parts:
    /// the world's `linear_removal_among` / `group_removal_among`.
    fn removal(&self, group: u64, state: u64, present: u64) -> std::result::Result<Motion, PartSet> {
        let members = || bits(group).filter(|&q| q < self.parts);
        let Some(bounds) = aabb_of(bits(group).flat_map(|q| [self.aabbs[q].mins, self.aabbs[q].maxs])) else {
            return Err(PartSet::empty(self.count));
        };
        let others = aabb_of(bits(state & !group).filter(|&q| q < self.parts).flat_map(|q| [self.aabbs[q].mins, self.aabbs[q].maxs]));
        best_free_direction(
            &self.directions,
            self.up,
            self.count,
            |k| self.set(members().fold(0, |b, p| b | self.rows[p][k]) & present & !group),
            |dir| clearance_past(&bounds, others, dir, self.contact_distance),
        )
    }

    fn stability_among(&self, present: u64, base: u64) -> Stability {
        let mut reached = present & base;
        let mut frontier = reached;
        while frontier != 0 {
            let i = frontier.trailing_zeros() as usize;
            frontier &= frontier - 1;
            let new = self.contacts[i] & present & !reached;
            reached |= new;
            frontier |= new;
        }
        let floating = present & !reached;
        if floating == 0 {
            Stability::Stable
        } else {
            Stability::Unstable { floating: self.set(floating) }
        }
    }

    fn finish(&self, kind: MotionKind, motion: std::result::Result<Motion, PartSet>, rest: u64) -> Outcome {
        let outcome = match motion {
            Err(blockers) => Outcome::Collision { blockers },
            Ok(motion) => match self.stability_among(self.with_fixed(rest), self.fixed) {
                Stability::Stable => Outcome::Removed(motion),
                Stability::Unstable { floating } => Outcome::Unstable { floating, motion },
            },
        };
        self.counters.record(kind, &outcome);
        outcome
    }

    /// The closure of `seeds` under "is blocked by" along direction `k` among `present`.
    fn closure(&self, seeds: u64, k: usize, present: u64) -> u64 {
        let mut group = seeds;
        let mut frontier = seeds;
        while frontier != 0 {
            let p = frontier.trailing_zeros() as usize;
            frontier &= frontier - 1;
            if p >= self.parts {
                continue;
            }
            let new = self.rows[p][k] & present & !group;
            group |= new;
            frontier |= new;
        }
        group
    }
}

impl FeasibilityChecker for VoxelChecker {
    fn num_parts(&self) -> usize {
        self.parts
    }

    fn is_fixed(&self, part: usize) -> bool {
        part < 64 && self.fixed >> part & 1 == 1
    }

    fn test_removal(&self, part: usize, state: &PartSet, kind: MotionKind) -> Outcome {
        let s = Self::mask(state);
        let motion = match kind {
            MotionKind::Linear => self.removal(1 << part, s, self.with_fixed(s)),
            MotionKind::Path { .. } => {
                self.needs_world.store(true, Ordering::Relaxed);
                Err(PartSet::empty(self.count))
            }
        };
        self.finish(kind, motion, s & !(1 << part))
    }

    fn stability(&self, state: &PartSet) -> Stability {
        self.stability_among(self.with_fixed(Self::mask(state)), self.fixed)
    }

    fn counters(&self) -> CounterSnapshot {
        self.counters.snapshot()
    }

    fn group_candidates(&self, state: &PartSet) -> Vec<PartSet> {
        let s = Self::mask(state);
        let present = self.with_fixed(s);
        let mut found: Vec<u64> = Vec::new();
        for k in 0..self.directions.len() {
            for p in bits(s & !self.fixed) {
                let closure = self.closure(1 << p, k, present);
                if closure.count_ones() >= 2 && closure & self.fixed == 0 && !found.contains(&closure) {
                    found.push(closure);
                }
            }
        }
        found.sort_by_key(|g| (g.count_ones(), g.trailing_zeros()));
        found.into_iter().map(|g| self.set(g)).collect()
    }

    fn in_movable_group(&self, part: usize, state: &PartSet) -> bool {
        let present = self.with_fixed(Self::mask(state));
        (0..self.directions.len()).any(|k| self.closure(1 << part, k, present) & self.fixed == 0)
    }

    fn test_group_removal(&self, group: &PartSet, state: &PartSet) -> Outcome {
        let (g, s) = (Self::mask(group), Self::mask(state));
        let motion = self.removal(g, s, self.with_fixed(s));
        self.finish(MotionKind::Linear, motion, s & !g)
    }

    fn subassembly(&self, _group: &PartSet) -> Option<(usize, Box<dyn FeasibilityChecker + '_>)> {
        self.needs_world.store(true, Ordering::Relaxed);
        None
    }
}

/// The bounds of `mesh` as the world prepares it (`Geom::new`: weld, orient, topology) when its
/// welded surface is closed and manifold, without hashing: vertices with bit-identical
/// coordinates (±0 alike) are one (the first stands for all), triangles that collapse are
/// dropped, and every edge must be used by exactly two triangles in opposite directions.
fn closed_bounds(mesh: &Mesh) -> Option<Aabb> {
    let mut order: Vec<([u32; 3], u32)> =
        mesh.vertices.iter().enumerate().map(|(i, v)| ([v.x + 0.0, v.y + 0.0, v.z + 0.0].map(f32::to_bits), i as u32)).collect();
    order.sort_unstable();
    // each vertex's welded id: its group's first vertex (ids keep the order of first appearance)
    let mut id = vec![0u32; mesh.vertices.len()];
    let mut firsts = Vec::new();
    for (k, &(key, i)) in order.iter().enumerate() {
        if k > 0 && order[k - 1].0 == key {
            id[i as usize] = id[order[k - 1].1 as usize];
        } else {
            id[i as usize] = i;
            firsts.push(i);
        }
    }
    firsts.sort_unstable();
    let bounds = aabb_of(firsts.iter().map(|&i| mesh.vertices[i as usize]))?;
    let mut edges: Vec<(u32, u32, bool)> = Vec::with_capacity(3 * mesh.triangles.len());
    for t in &mesh.triangles {
        let t = t.map(|i| id[i as usize]);
        if t[0] == t[1] || t[1] == t[2] || t[0] == t[2] {
            continue;
        }
        let [a, b, c] = t.map(|i| mesh.vertices[i as usize]);
        if (b - a).cross(c - a).length_squared() > 0.0 {
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                edges.push((a.min(b), a.max(b), a < b));
            }
        }
    }
    edges.sort_unstable();
    let closed = edges.chunk_by(|x, y| (x.0, x.1) == (y.0, y.1)).all(|e| e.len() == 2 && e[0].2 != e[1].2);
    closed.then_some(bounds)
}

/// The indices of the set bits of `m`, increasing.
fn bits(m: u64) -> impl Iterator<Item = usize> {
    crate::partset::set_bits([m])
}

/// The contact graph as the world measures it on boxes (bounds within the contact distance,
/// then the least box distance), or `None` when two parts overlap deeper than the tolerance.
fn contacts(aabbs: &[Aabb], part_boxes: &[Vec<Aabb>], tolerance: f32, contact_distance: f32) -> Option<Vec<u64>> {
    let count = aabbs.len();
    let mut contacts = vec![0u64; count];
    for i in 0..count {
        for j in (i + 1)..count {
            let (a, b) = (&aabbs[i], &aabbs[j]);
            let m = contact_distance;
            if !(0..3).all(|k| a.mins[k] <= b.maxs[k] + m && b.mins[k] <= a.maxs[k] + m) {
                continue;
            }
            let pairs = || part_boxes[i].iter().flat_map(|a| part_boxes[j].iter().map(move |b| (a, b)));
            let depth = pairs().map(|(a, b)| boxes::overlap_depth(a, b)).fold(f32::NEG_INFINITY, f32::max);
            if depth - tolerance > 0.0 {
                return None;
            }
            let gap = pairs().map(|(a, b)| boxes::box_distance(a, b, Vec3::ONE)).fold(f32::INFINITY, f32::min);
            if gap <= contact_distance {
                contacts[i] |= 1 << j;
                contacts[j] |= 1 << i;
            }
        }
    }
    Some(contacts)
}

/// The slabs of one axis: the distinct box coordinates (those closer than a hundredth of the
/// tolerance are one), or `None` when two distinct ones lie within four tolerances.
fn slabs(coords: &mut [f32], tolerance: f32) -> Option<Vec<f32>> {
    coords.sort_by(f32::total_cmp);
    let mut out: Vec<f32> = Vec::with_capacity(coords.len());
    for &x in coords.iter() {
        match out.last() {
            Some(&last) if x - last < 0.01 * tolerance => {}
            Some(&last) if x - last <= 4.0 * tolerance => return None,
            _ => out.push(x),
        }
    }
    Some(out)
}

/// The index of the lattice coordinate nearest `x`.
fn slab_index(cuts: &[f32], x: f32) -> usize {
    let i = cuts.partition_point(|&c| c < x);
    if i > 0 && (i == cuts.len() || x - cuts[i - 1] < cuts[i] - x) {
        i - 1
    } else {
        i
    }
}

/// Every part's blocking row along the six axis directions, from the lattice of all box
/// coordinates: one pass over each row of cells per axis. `None` when the lattice is too fine,
/// or two parts share a cell.
fn blocking_rows(part_boxes: &[Vec<Aabb>], tolerance: f32) -> Option<Vec<[u64; 6]>> {
    let mut cuts: [Vec<f32>; 3] = Default::default();
    for (k, c) in cuts.iter_mut().enumerate() {
        let mut coords: Vec<f32> = part_boxes.iter().flatten().flat_map(|b| [b.mins[k], b.maxs[k]]).collect();
        *c = slabs(&mut coords, tolerance)?;
    }
    let dims: [usize; 3] = std::array::from_fn(|k| cuts[k].len().saturating_sub(1));
    let total = dims.iter().try_fold(1usize, |a, &d| a.checked_mul(d))?;
    if total == 0 || total > MAX_LATTICE_CELLS {
        return None;
    }
    const EMPTY: u8 = u8::MAX;
    let mut owner = vec![EMPTY; total];
    let at = |c: [usize; 3]| c[0] + dims[0] * (c[1] + dims[1] * c[2]);
    for (p, bs) in part_boxes.iter().enumerate() {
        for b in bs {
            let lo: [usize; 3] = std::array::from_fn(|k| slab_index(&cuts[k], b.mins[k]));
            let hi: [usize; 3] = std::array::from_fn(|k| slab_index(&cuts[k], b.maxs[k]));
            for z in lo[2]..hi[2] {
                for y in lo[1]..hi[1] {
                    for x in lo[0]..hi[0] {
                        let cell = &mut owner[at([x, y, z])];
                        if *cell != EMPTY && *cell as usize != p {
                            return None;
                        }
                        *cell = p as u8;
                    }
                }
            }
        }
    }
    let mut rows = vec![[0u64; 6]; part_boxes.len()];
    for a in 0..3 {
        let (b, c) = ((a + 1) % 3, (a + 2) % 3);
        for j in 0..dims[b] {
            for k in 0..dims[c] {
                // walking along +a: every part met blocks, along +a, each part met before it
                let mut seen = 0u64;
                for i in 0..dims[a] {
                    let mut cell = [0; 3];
                    cell[a] = i;
                    cell[b] = j;
                    cell[c] = k;
                    let q = owner[at(cell)];
                    if q == EMPTY {
                        continue;
                    }
                    let q = q as usize;
                    let behind = seen & !(1 << q);
                    for p in bits(behind) {
                        rows[p][2 * a] |= 1 << q;
                    }
                    rows[q][2 * a + 1] |= behind;
                    seen |= 1 << q;
                }
            }
        }
    }
    Some(rows)
}
