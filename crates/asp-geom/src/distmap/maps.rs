//! [`DistanceMaps`]: the maps and their indexes, and the questions a single state asks of them
//! (free directions, clearance, stability).

use super::{Bits, DirMask, Hemisphere, Support};
use crate::feasibility::{Motion, Stability};
use crate::math::{Aabb, Vec3};
use crate::partset::PartSet;
use crate::world::World;
use std::sync::Arc;

/// How the maps of one part were computed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PartGeometry {
    /// Exact sweeps of voxels from `extras.asp.voxels`.
    Voxels,
    /// Exact sweeps of the part's boxes (`extras.asp.boxes`, or its mesh is one axis-aligned box).
    Box,
    /// Exact triangle sweeps of the eroded mesh (both parts of a pair must be boxes for box sweeps).
    Mesh,
}

/// The distance maps of an assembly, with the indexes the incremental [`MapState`](super::MapState) needs.
#[derive(Clone, Debug)]
pub struct DistanceMaps {
    pub(super) n: usize,
    pub(super) hemisphere: Hemisphere,
    pub(super) diagonal: f32,
    pub(super) contact_distance: f32,
    pub(super) d_max: f32,
    pub(super) tolerance: f32,
    pub(super) stride: usize,
    /// Row `i * (n + 1) + j`: `M(p_i, p_j)`, `stride` floats (the padding is 0).
    pub(super) values: Vec<f32>,
    /// `blocked[i * (n + 1) + j]`: directions where `M(p_i, p_j) < d_max`.
    pub(super) blocked: Vec<DirMask>,
    pub(super) fixed: Vec<bool>,
    pub(super) aabbs: Vec<Aabb>,
    pub(super) geometry: Vec<PartGeometry>,
    /// For part `i`: the parts `j` (never the floor) with a non-empty `blocked(i, j)`, the
    /// most-blocking first.
    pub(super) blockers: Vec<Vec<u16>>,
    /// For part `i`: its blockers as a bitset (intersected with the present parts by
    /// [`MapState::min_map`]).
    pub(super) blocker_set: Vec<Bits>,
    /// A padded row of `d_max` (the padding 0): where a minimum map starts.
    pub(super) init_row: Vec<f32>,
    /// Words of a part bitset: `ceil(n / 64)`.
    pub(super) words: usize,
    /// For a blocker `j` of `i`, at `(i * n + j) * words`: the other blockers `k` of `i` with
    /// `M(p_i, p_k) <= M(p_i, p_j)` in every direction (equal maps: the lower index), `words`
    /// words of a bitset. While one of them is present, `M(p_i, p_j)` cannot lower
    /// `M̄(p_i, s)`, so the minimum skips it.
    pub(super) dominators: Vec<u64>,
    /// For part `i`: `blocked(i, j)` of its blockers, in `blockers[i]` order.
    pub(super) blocker_masks: Vec<Vec<DirMask>>,
    /// For part `i` and direction `d`, at `(i * N_M² + d) * words`: the parts that block `i`
    /// along `d`, `words` words of a bitset.
    pub(super) along: Vec<u64>,
    /// For part `k`: the parts `i` that `k` blocks somewhere (`k ∈ blockers[i]`).
    pub(super) blocks: Vec<Bits>,
    /// For part `i`: the parts directly below it, touching (`M(p_j, p_i)(up) = 0`).
    pub(super) supporters: Vec<Vec<u16>>,
    /// For part `j`: the parts it supports.
    pub(super) dependents: Vec<Vec<u16>>,
    /// Whether the floor supports part `i`.
    pub(super) on_floor: Vec<bool>,
    pub(super) support: Support,
    /// For part `i` (and the floor at index `n`): the parts and the floor within the contact
    /// distance (filled for [`Support::ContactGraph`] only).
    pub(super) contacts: Vec<Bits>,
    /// The parts the contact graph hangs from: the fixed parts, and the floor (index `n`) when
    /// no part is fixed.
    pub(super) bases: Bits,
    pub(super) warnings: Vec<String>,
    /// The collision world the maps were built on or built (when a part is a mesh).
    pub(super) world: MapWorld,
}

/// The maps' collision world (`World` has no `Debug`: it prints whether there is one).
#[derive(Clone)]
pub(super) struct MapWorld(pub(super) Option<Arc<World>>);

impl std::fmt::Debug for MapWorld {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(if self.0.is_some() { "Some(World)" } else { "None" })
    }
}

impl DistanceMaps {
    /// Number of parts (the floor not counted).
    pub fn num_parts(&self) -> usize {
        self.n
    }

    /// The index of the floor in [`DistanceMaps::map`] (= number of parts).
    pub fn floor(&self) -> usize {
        self.n
    }

    /// The sampled directions.
    pub fn hemisphere(&self) -> &Hemisphere {
        &self.hemisphere
    }

    /// Number of directions per map, `N_M²`.
    pub fn num_directions(&self) -> usize {
        self.hemisphere.len()
    }

    /// The diagonal of the assembly's bounding box (metres): its size.
    pub fn diagonal(&self) -> f32 {
        self.diagonal
    }

    /// The contact distance (metres): parts closer than this touch in the contact graph, and
    /// the margin the collision world adds to removal travels.
    pub fn contact_distance(&self) -> f32 {
        self.contact_distance
    }

    /// The cap on distances, metres.
    pub fn d_max(&self) -> f32 {
        self.d_max
    }

    /// The contact tolerance, metres.
    pub fn tolerance(&self) -> f32 {
        self.tolerance
    }

    /// Whether part `i` is fixed (never removed, always supported).
    pub fn is_fixed(&self, i: usize) -> bool {
        self.fixed[i]
    }

    /// The bounding box of part `i`.
    pub fn part_aabb(&self, i: usize) -> &Aabb {
        &self.aabbs[i]
    }

    /// How the maps of part `i` were computed.
    pub fn geometry(&self, i: usize) -> PartGeometry {
        self.geometry[i]
    }

    /// The collision world the maps were built on ([`DistanceMaps::build_on`]) or built
    /// themselves (a part is a mesh); `None` for maps of boxes and voxels built alone. The robot
    /// reuses it instead of building a second one.
    pub fn world(&self) -> Option<&Arc<World>> {
        self.world.0.as_ref()
    }

    /// Problems met while building (voxels that do not match meshes, open meshes).
    pub fn warnings(&self) -> &[String] {
        &self.warnings
    }

    /// `M(p_i, p_j)`: how far `i` moves along each direction before penetrating `j`, capped at
    /// `d_max` (`i` or `j` may be [`DistanceMaps::floor`]). Indexed like the hemisphere.
    pub fn map(&self, i: usize, j: usize) -> &[f32] {
        let off = (i * (self.n + 1) + j) * self.stride;
        &self.values[off..off + self.hemisphere.len()]
    }

    /// The directions in which `j` blocks `i` (`M(p_i, p_j) < d_max`).
    pub fn blocked(&self, i: usize, j: usize) -> DirMask {
        self.blocked[i * (self.n + 1) + j]
    }

    /// The parts that block `i` in some direction.
    pub fn blockers(&self, i: usize) -> &[u16] {
        &self.blockers[i]
    }

    /// The parts directly below `i` and touching it (its supports besides the floor).
    pub fn supporters(&self, i: usize) -> &[u16] {
        &self.supporters[i]
    }

    /// Whether the floor supports part `i`.
    pub fn on_floor(&self, i: usize) -> bool {
        self.on_floor[i]
    }

    /// `M̄(p_i, s)` (eq. 6.4): the minimum over the maps of the present parts (and the floor).
    pub fn min_map(&self, i: usize, state: &PartSet) -> Vec<f32> {
        let mut out = vec![self.d_max; self.hemisphere.len()];
        for j in (0..self.n).filter(|&j| j != i && state.contains(j)) {
            for (o, v) in out.iter_mut().zip(self.map(i, j)) {
                *o = o.min(*v);
            }
        }
        out
    }

    /// `B^M̄(p_i, s)` (eq. 6.8): the directions along which `i` leaves `state` without collision.
    pub fn free_mask(&self, i: usize, state: &PartSet) -> DirMask {
        let mut blocked = DirMask::EMPTY;
        for &j in &self.blockers[i] {
            if state.contains(j as usize) {
                blocked = blocked.or(self.blocked(i, j as usize));
            }
        }
        DirMask::first(self.hemisphere.len()).and_not(blocked)
    }

    /// The gravity rule of the maps.
    pub fn support(&self) -> Support {
        self.support
    }

    /// The parts of `alive` linked through contacts among `alive` to a base (a fixed part, or
    /// the floor when no part is fixed); fixed parts are always alive.
    pub(super) fn linked(&self, alive: Bits) -> Bits {
        let alive = alive.or(&self.bases);
        let mut reached = self.bases;
        let mut frontier = self.bases;
        // breadth-first, a whole layer per step
        while !frontier.is_empty() {
            let mut next = Bits::EMPTY;
            for i in frontier.iter() {
                next = next.or(&self.contacts[i]);
            }
            frontier = next.and(&alive).and_not(&reached);
            reached = reached.or(&frontier);
        }
        reached.remove(self.n);
        reached
    }

    /// Whether `i` rests on the floor or a part of `state` directly beneath it (or is fixed):
    /// the [`Support::Below`] rule for one part.
    pub fn is_supported(&self, i: usize, state: &PartSet) -> bool {
        self.fixed[i] || self.on_floor[i] || self.supporters[i].iter().any(|&j| state.contains(j as usize))
    }

    /// The gravity check on every part of `state`, by the configured [`Support`] rule.
    pub fn stability(&self, state: &PartSet) -> Stability {
        let mut floating = PartSet::empty(self.n);
        match self.support {
            Support::Below => {
                for i in state.iter().filter(|&i| i < self.n) {
                    if !self.is_supported(i, state) {
                        floating.insert(i);
                    }
                }
            }
            Support::ContactGraph => {
                let alive = PartSet::from_indices(self.n, state.iter().filter(|&i| i < self.n));
                let reached = self.linked(Bits::from_set(&alive));
                for i in alive.iter() {
                    if !reached.contains(i) {
                        floating.insert(i);
                    }
                }
            }
        }
        if floating.is_empty() {
            Stability::Stable
        } else {
            Stability::Unstable { floating }
        }
    }

    /// The straight-line removal of `i` from `state` (which contains it): among the free
    /// directions, the one with the shortest travel until `i`'s bounds clear the bounds of the
    /// other present parts (the most upward one among equals), and that travel. `None` when no
    /// direction is free.
    pub fn clearance(&self, i: usize, state: &PartSet) -> Option<(usize, f32)> {
        let free = self.free_mask(i, state);
        self.clearance_in(i, state, free)
    }

    pub(super) fn clearance_in(&self, i: usize, state: &PartSet, free: DirMask) -> Option<(usize, f32)> {
        self.clearance_among(i, state.iter(), free)
    }

    pub(super) fn clearance_among(&self, i: usize, present: impl Iterator<Item = usize>, free: DirMask) -> Option<(usize, f32)> {
        if free.is_empty() {
            return None;
        }
        let mut rest: Option<Aabb> = None;
        for j in present.filter(|&j| j != i && j < self.n) {
            let b = &self.aabbs[j];
            rest = Some(match rest {
                None => *b,
                Some(r) => Aabb::new(r.mins.min(b.mins), r.maxs.max(b.maxs)),
            });
        }
        let dirs = self.hemisphere.directions();
        let up = self.hemisphere.up();
        let mut best: Option<(usize, f32)> = None;
        for d in free.iter() {
            let travel = match &rest {
                None => 0.0,
                Some(r) => clear_distance(&self.aabbs[i], dirs[d], r),
            };
            // shortest travel; among equal travels the most upward direction
            if best.is_none_or(|(b, t)| travel < t || (travel == t && dirs[d].dot(up) > dirs[b].dot(up))) {
                best = Some((d, travel));
            }
        }
        best
    }

    /// The removal motion of [`DistanceMaps::clearance`] as a [`Motion::Linear`].
    pub fn removal_motion(&self, i: usize, state: &PartSet) -> Option<Motion> {
        self.clearance(i, state).map(|(d, t)| Motion::Linear { direction: self.hemisphere.directions()[d], distance: t })
    }

    /// Whether part `i` can be removed from `state` without collision (eq. 6.5).
    pub fn is_collision_free(&self, i: usize, state: &PartSet) -> bool {
        !self.free_mask(i, state).is_empty()
    }
}

/// (0 when they do not overlap now; touching is not overlapping).
pub(super) fn clear_distance(moving: &Aabb, dir: Vec3, rest: &Aabb) -> f32 {
    let mut t = f32::INFINITY;
    for k in 0..3 {
        let lo = rest.mins[k] - moving.maxs[k];
        let hi = rest.maxs[k] - moving.mins[k];
        if !(lo < 0.0 && hi > 0.0) {
            return 0.0;
        }
        let d = dir[k];
        if d > 1e-6 {
            t = t.min(hi / d);
        } else if d < -1e-6 {
            t = t.min(lo / d);
        }
    }
    if t.is_finite() {
        t
    } else {
        0.0
    }
}
