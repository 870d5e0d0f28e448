//! 2½D distance maps (thesis 6.3.1): for every ordered pair of parts `(p_i, p_j)`, how far `p_i`
//! can translate along each direction of a sampled half sphere before it penetrates `p_j`, capped
//! at `d_max`. From the maps follow collision-free removal (6.3.2, eq. 6.5), the gravity check
//! (6.3.2), the accessibility objective (6.6) and the binary maps of the direction-change
//! objective (6.8).
//!
//! # Directions
//! The half sphere points away from gravity (around the assembly's up axis). An `N_M × N_M` grid
//! `(k, l)` of the square `[-1, 1]²` is mapped onto it with the hemi-octahedral map: the square's
//! centre is straight up, its border the horizon, its corners the four horizontal axes. With an
//! odd `N_M` (required) the five axis directions `up, ±e1, ±e2` are all samples, every sample is
//! distinct, and the set is symmetric (`-m` is a sample for every horizontal `m`).
//!
//! # The floor
//! The floor is a part (index [`DistanceMaps::floor`] = number of parts): a half space below the
//! lowest point of the assembly. No half-sphere direction moves a part into it, so `M(p_i, floor)`
//! is `d_max` everywhere; `M(floor, p_i)` — how far the floor can rise along `m` before touching
//! `p_i` — is what the gravity check reads. Because `M(p_j, p_i)(m)` equals how far `p_i` can move
//! along `-m` relative to `p_j`, the pair of maps also answers questions about downward motion:
//! part `i` is *supported* in state `s` when some present `p_j` (or the floor) has
//! `M(p_j, p_i)(up) = 0`, i.e. `p_i` cannot move down at all.
//!
//! # Geometry
//! * **Boxes (exact).** Parts that carry voxels (`extras.asp.cells`, as the Soma generator
//!   writes them) or boxes (`extras.asp.boxes`, as the profile generator writes them), or whose
//!   mesh is a single axis-aligned box, are unions of boxes ([`crate::boxes`]). Distances are
//!   exact box sweeps; voxels on a shared grid are swept in integer grid coordinates, so touching
//!   faces are exactly zero and sliding is exactly free.
//! * **Meshes.** Other parts use exact triangle sweeps ([`crate::sweep`]): the moving part is eroded by the contact
//!   tolerance (so touching faces do not count as collisions, see `research/parry-removal-test.md`)
//!   and cast against the other part's surface; the tolerance is added back to the distance.
//!
//! # Removability and stability
//! `p_i` is collision-free in state `s` when its minimum map `M̄(p_i, s)` (eq. 6.4) reaches
//! `d_max` in at least one direction. The thesis writes `> d_max`; with values capped at `d_max`
//! we write `>= d_max`, which with the default `d_max` (the assembly's diagonal, the longest
//! possible overlap of two parts inside its box) means "never collides". Fixed parts are always
//! supported and never removed.

use crate::assembly::Assembly;
use crate::boxes::{box_distance, first_overlap, fit_boxes, fit_voxels, single_box};
use crate::error::{GeomError, Result};
use crate::feasibility::{
    CounterSnapshot, Counters, FeasibilityChecker, Motion, MotionKind, Outcome, Stability,
};
use crate::math::{Aabb, Axis, Vec3};
use crate::overlap::OverlapPolicy;
use crate::partset::PartSet;
use crate::world::{World, WorldConfig};
use parry3d::shape::TriMesh;
use rayon::prelude::*;

/// Largest supported map resolution `N_M` (`N_M² ≤ 256` directions fit a [`DirMask`]).
pub const MAX_RESOLUTION: usize = 15;
/// Default map resolution `N_M` (the thesis does not state its value): 9 × 9 = 81 directions.
pub const DEFAULT_RESOLUTION: usize = 9;
/// Largest number of parts distance maps are built for.
pub const MAX_PARTS: usize = 255;
/// Default contact tolerance, relative to the assembly's diagonal (as the collision world).
pub const DEFAULT_RELATIVE_TOLERANCE: f32 = 1e-4;
/// Default contact distance of the contact graph, relative to the diagonal (as the world).
pub const DEFAULT_RELATIVE_CONTACT: f32 = 1e-3;

/// Which states stand (the gravity check).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Support {
    /// Thesis 6.3.2: every present part rests on a present part or the floor directly beneath it
    /// — it cannot move along gravity at all (`M(p_j, p_i)(up) = 0`). Fixed parts always stand.
    #[default]
    Below,
    /// The collision world's rule ([`crate::StabilityMode::ContactGraph`]): every present part
    /// is linked through contacts (parts within the contact distance) to a fixed part, or to the
    /// floor when no part is fixed.
    ContactGraph,
}

/// A set of sampled directions (bit `d` = direction index `d`), up to 256.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct DirMask {
    words: [u64; 4],
}

impl DirMask {
    /// No direction.
    pub const EMPTY: DirMask = DirMask { words: [0; 4] };

    /// The set whose direction `64 k + b` is bit `b` of `words[k]` (the inverse of
    /// [`DirMask::words`]; e.g. a mask kept in an objective's memory words).
    pub const fn from_words(words: [u64; 4]) -> DirMask {
        DirMask { words }
    }

    /// The set as four words: direction `64 k + b` is bit `b` of word `k`.
    pub const fn words(&self) -> [u64; 4] {
        self.words
    }

    /// The directions `0..count`.
    pub fn first(count: usize) -> DirMask {
        let mut m = DirMask::EMPTY;
        for (k, w) in m.words.iter_mut().enumerate() {
            let lo = k * 64;
            if count >= lo + 64 {
                *w = u64::MAX;
            } else if count > lo {
                *w = (1u64 << (count - lo)) - 1;
            }
        }
        m
    }

    /// Adds direction `d`.
    #[inline]
    pub fn insert(&mut self, d: usize) {
        self.words[d / 64] |= 1 << (d % 64);
    }

    /// Whether direction `d` is in the set.
    #[inline]
    pub fn contains(&self, d: usize) -> bool {
        self.words[d / 64] & (1 << (d % 64)) != 0
    }

    /// Whether the set is empty.
    #[inline]
    pub fn is_empty(&self) -> bool {
        self.words == [0; 4]
    }

    /// Number of directions in the set.
    #[inline]
    pub fn len(&self) -> usize {
        self.words.iter().map(|w| w.count_ones() as usize).sum()
    }

    /// Directions in both sets.
    #[inline]
    pub fn and(self, other: DirMask) -> DirMask {
        let mut w = self.words;
        for (a, b) in w.iter_mut().zip(other.words) {
            *a &= b;
        }
        DirMask { words: w }
    }

    /// Directions in either set.
    #[inline]
    pub fn or(self, other: DirMask) -> DirMask {
        let mut w = self.words;
        for (a, b) in w.iter_mut().zip(other.words) {
            *a |= b;
        }
        DirMask { words: w }
    }

    /// Directions of `self` not in `other`.
    #[inline]
    pub fn and_not(self, other: DirMask) -> DirMask {
        let mut w = self.words;
        for (a, b) in w.iter_mut().zip(other.words) {
            *a &= !b;
        }
        DirMask { words: w }
    }

    /// The smallest direction in the set.
    #[inline]
    fn lowest(&self) -> Option<usize> {
        self.words.iter().enumerate().find(|(_, w)| **w != 0).map(|(k, w)| k * 64 + w.trailing_zeros() as usize)
    }

    /// The directions in increasing index order.
    pub fn iter(&self) -> impl Iterator<Item = usize> + '_ {
        crate::partset::set_bits(self.words.iter().copied())
    }
}

/// A fixed-width set of part indices (up to 256) for the hot loop of [`MapState`]: the same
/// idea as [`PartSet`], without its heap fallback, so every operation is a few word operations.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
struct Bits([u64; 4]);

impl Bits {
    const EMPTY: Bits = Bits([0; 4]);
    /// Every index: the key of a row not yet computed (a part never blocks itself, so no
    /// part's present blockers are all indices).
    const NO_KEY: Bits = Bits([u64::MAX; 4]);

    /// The parts of `s` below 256.
    fn from_set(s: &PartSet) -> Bits {
        let mut b = Bits::EMPTY;
        for (w, v) in b.0.iter_mut().zip(s.words()) {
            *w = *v;
        }
        b
    }

    fn to_set(self, n: usize) -> PartSet {
        PartSet::from_words(n, &self.0)
    }

    #[inline]
    fn insert(&mut self, i: usize) {
        self.0[i >> 6] |= 1 << (i & 63);
    }

    #[inline]
    fn remove(&mut self, i: usize) {
        self.0[i >> 6] &= !(1 << (i & 63));
    }

    #[inline]
    fn contains(&self, i: usize) -> bool {
        self.0[i >> 6] & (1 << (i & 63)) != 0
    }

    #[inline]
    fn is_empty(&self) -> bool {
        self.0 == [0; 4]
    }

    #[inline]
    fn len(&self) -> usize {
        self.0.iter().map(|w| w.count_ones() as usize).sum()
    }

    #[inline]
    fn or(&self, o: &Bits) -> Bits {
        Bits([self.0[0] | o.0[0], self.0[1] | o.0[1], self.0[2] | o.0[2], self.0[3] | o.0[3]])
    }

    #[inline]
    fn and(&self, o: &Bits) -> Bits {
        Bits([self.0[0] & o.0[0], self.0[1] & o.0[1], self.0[2] & o.0[2], self.0[3] & o.0[3]])
    }

    #[inline]
    fn and_not(&self, o: &Bits) -> Bits {
        Bits([self.0[0] & !o.0[0], self.0[1] & !o.0[1], self.0[2] & !o.0[2], self.0[3] & !o.0[3]])
    }

    #[inline]
    fn iter(self) -> impl Iterator<Item = usize> {
        crate::partset::set_bits(self.0)
    }
}

/// The `N_M × N_M` directions sampled on the half sphere around the up axis.
#[derive(Clone, Debug)]
pub struct Hemisphere {
    resolution: usize,
    up: Vec3,
    directions: Vec<Vec3>,
}

impl Hemisphere {
    /// Samples `resolution × resolution` directions (odd, 3..=15) around `up`.
    pub fn new(resolution: usize, up: Axis) -> Result<Self> {
        if !(3..=MAX_RESOLUTION).contains(&resolution) || resolution.is_multiple_of(2) {
            return Err(GeomError::config(format!(
                "distance map resolution must be odd and within 3..={MAX_RESOLUTION}, got {resolution}"
            )));
        }
        let upv = up.vector();
        let e1 = Axis { index: (up.index + 1) % 3, negative: false }.vector();
        let e2 = Axis { index: (up.index + 2) % 3, negative: up.negative }.vector();
        let step = 2.0 / (resolution - 1) as f64;
        let mut directions = Vec::with_capacity(resolution * resolution);
        for k in 0..resolution {
            for l in 0..resolution {
                let u = -1.0 + step * k as f64;
                let v = -1.0 + step * l as f64;
                let px = (u + v) / 2.0;
                let py = (u - v) / 2.0;
                let pz = (1.0 - px.abs() - py.abs()).max(0.0);
                let norm = (px * px + py * py + pz * pz).sqrt();
                let snap = |c: f64| if c.abs() < 1e-9 { 0.0 } else { c / norm };
                let (x, y, z) = (snap(px) as f32, snap(py) as f32, snap(pz) as f32);
                directions.push(e1 * x + e2 * y + upv * z);
            }
        }
        Ok(Hemisphere { resolution, up: upv, directions })
    }

    /// `N_M`.
    pub fn resolution(&self) -> usize {
        self.resolution
    }

    /// Number of directions, `N_M²`.
    pub fn len(&self) -> usize {
        self.directions.len()
    }

    /// Whether there are no directions (never: the resolution is at least 3).
    pub fn is_empty(&self) -> bool {
        self.directions.is_empty()
    }

    /// The unit directions, indexed `k * N_M + l`.
    pub fn directions(&self) -> &[Vec3] {
        &self.directions
    }

    /// The index of grid cell `(k, l)`.
    pub fn index(&self, k: usize, l: usize) -> usize {
        k * self.resolution + l
    }

    /// The index of the straight-up direction (the grid's centre).
    pub fn up_index(&self) -> usize {
        let c = self.resolution / 2;
        self.index(c, c)
    }

    /// The up vector.
    pub fn up(&self) -> Vec3 {
        self.up
    }

    /// The index of the sample closest to `direction` (which need not be normalised).
    pub fn nearest(&self, direction: Vec3) -> usize {
        let d = direction.normalize_or_zero();
        let mut best = (f32::NEG_INFINITY, 0);
        for (i, m) in self.directions.iter().enumerate() {
            let c = m.dot(d);
            if c > best.0 {
                best = (c, i);
            }
        }
        best.1
    }
}

/// How distance maps are computed. Build with [`MapConfig::builder`].
#[derive(Clone, Debug, PartialEq)]
pub struct MapConfig {
    resolution: usize,
    d_max: Option<f32>,
    tolerance: Option<f32>,
    contact_distance: Option<f32>,
    support: Support,
    use_voxels: bool,
    overlaps: OverlapPolicy,
}

impl Default for MapConfig {
    fn default() -> Self {
        MapConfig {
            resolution: DEFAULT_RESOLUTION,
            d_max: None,
            tolerance: None,
            contact_distance: None,
            support: Support::Below,
            use_voxels: true,
            overlaps: OverlapPolicy::Strict,
        }
    }
}

impl MapConfig {
    /// A builder starting from the defaults.
    pub fn builder() -> MapConfigBuilder {
        MapConfigBuilder { config: MapConfig::default() }
    }

    /// `N_M`: the maps have `N_M × N_M` directions.
    pub fn resolution(&self) -> usize {
        self.resolution
    }

    /// The cap on distances in metres (`None`: the assembly's diagonal).
    pub fn d_max(&self) -> Option<f32> {
        self.d_max
    }

    /// The contact tolerance in metres (`None`: 1e-4 × the assembly's diagonal).
    pub fn tolerance(&self) -> Option<f32> {
        self.tolerance
    }

    /// The contact distance of the contact graph in metres (`None`: 1e-3 × the diagonal).
    pub fn contact_distance(&self) -> Option<f32> {
        self.contact_distance
    }

    /// The gravity check.
    pub fn support(&self) -> Support {
        self.support
    }

    /// How mesh parts that overlap in the input are tested ([`OverlapPolicy`], default strict).
    pub fn overlaps(&self) -> OverlapPolicy {
        self.overlaps
    }
}

/// Builder of [`MapConfig`]; [`MapConfigBuilder::build`] validates.
#[derive(Clone, Debug)]
pub struct MapConfigBuilder {
    config: MapConfig,
}

impl MapConfigBuilder {
    /// `N_M` (odd, 3..=15; default 9).
    pub fn resolution(mut self, n: usize) -> Self {
        self.config.resolution = n;
        self
    }

    /// The cap `d_max` in metres (default: the assembly's bounding-box diagonal).
    pub fn d_max(mut self, d_max: f32) -> Self {
        self.config.d_max = Some(d_max);
        self
    }

    /// The contact tolerance in metres (default: 1e-4 × the diagonal): how deep a motion may push
    /// into another part before it counts as a collision on meshes.
    pub fn tolerance(mut self, tolerance: f32) -> Self {
        self.config.tolerance = Some(tolerance);
        self
    }

    /// Parts closer than this (metres) are in contact for [`Support::ContactGraph`] (default
    /// 1e-3 × the diagonal).
    pub fn contact_distance(mut self, distance: f32) -> Self {
        self.config.contact_distance = Some(distance);
        self
    }

    /// The gravity check (default [`Support::Below`], the thesis' rule).
    pub fn support(mut self, support: Support) -> Self {
        self.config.support = support;
        self
    }

    /// How mesh parts that overlap in the input are tested (default [`OverlapPolicy::Strict`]:
    /// the maps' distance of such a pair is also limited by the strict rule).
    pub fn overlaps(mut self, policy: OverlapPolicy) -> Self {
        self.config.overlaps = policy;
        self
    }

    /// Whether voxels in `extras.asp.voxels` are used for exact box sweeps (default true).
    pub fn use_voxels(mut self, yes: bool) -> Self {
        self.config.use_voxels = yes;
        self
    }

    /// Checks the values.
    pub fn build(self) -> Result<MapConfig> {
        let c = self.config;
        let r = c.resolution;
        if !(3..=MAX_RESOLUTION).contains(&r) || r.is_multiple_of(2) {
            return Err(GeomError::config(format!(
                "distance map resolution must be odd and within 3..={MAX_RESOLUTION}, got {r}"
            )));
        }
        if let Some(d) = c.d_max {
            if !(d.is_finite() && d > 0.0) {
                return Err(GeomError::config(format!("d_max must be positive, got {d}")));
            }
        }
        if let Some(t) = c.tolerance {
            if !(t.is_finite() && t >= 0.0) {
                return Err(GeomError::config(format!("tolerance must be >= 0, got {t}")));
            }
        }
        if let Some(t) = c.contact_distance {
            if !(t.is_finite() && t > 0.0) {
                return Err(GeomError::config(format!("contact distance must be positive, got {t}")));
            }
        }
        Ok(c)
    }
}

/// How the maps of one part were computed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PartGeometry {
    /// Exact sweeps of voxels from `extras.asp.voxels`.
    Voxels,
    /// Exact sweeps of the part's boxes (`extras.asp.boxes`, or its mesh is one axis-aligned box).
    Box,
    /// Shape casting of the eroded mesh (both parts of a pair must be boxes for exact sweeps).
    Mesh,
}

/// The distance maps of an assembly, with the indexes the incremental [`MapState`] needs.
#[derive(Clone, Debug)]
pub struct DistanceMaps {
    n: usize,
    hemisphere: Hemisphere,
    diagonal: f32,
    contact_distance: f32,
    d_max: f32,
    tolerance: f32,
    stride: usize,
    /// Row `i * (n + 1) + j`: `M(p_i, p_j)`, `stride` floats (the padding is 0).
    values: Vec<f32>,
    /// `blocked[i * (n + 1) + j]`: directions where `M(p_i, p_j) < d_max`.
    blocked: Vec<DirMask>,
    fixed: Vec<bool>,
    aabbs: Vec<Aabb>,
    geometry: Vec<PartGeometry>,
    /// For part `i`: the parts `j` (never the floor) with a non-empty `blocked(i, j)`, the
    /// most-blocking first.
    blockers: Vec<Vec<u16>>,
    /// For part `i`: its blockers as a bitset (intersected with the present parts by
    /// [`MapState::min_map`]).
    blocker_set: Vec<Bits>,
    /// A padded row of `d_max` (the padding 0): where a minimum map starts.
    init_row: Vec<f32>,
    /// Words of a part bitset: `ceil(n / 64)`.
    words: usize,
    /// For a blocker `j` of `i`, at `(i * n + j) * words`: the other blockers `k` of `i` with
    /// `M(p_i, p_k) <= M(p_i, p_j)` in every direction (equal maps: the lower index), `words`
    /// words of a bitset. While one of them is present, `M(p_i, p_j)` cannot lower
    /// `M̄(p_i, s)`, so the minimum skips it.
    dominators: Vec<u64>,
    /// For part `i`: `blocked(i, j)` of its blockers, in `blockers[i]` order.
    blocker_masks: Vec<Vec<DirMask>>,
    /// For part `i` and direction `d`, at `(i * N_M² + d) * words`: the parts that block `i`
    /// along `d`, `words` words of a bitset.
    along: Vec<u64>,
    /// For part `k`: the parts `i` that `k` blocks somewhere (`k ∈ blockers[i]`).
    blocks: Vec<Bits>,
    /// For part `i`: the parts directly below it, touching (`M(p_j, p_i)(up) = 0`).
    supporters: Vec<Vec<u16>>,
    /// For part `j`: the parts it supports.
    dependents: Vec<Vec<u16>>,
    /// Whether the floor supports part `i`.
    on_floor: Vec<bool>,
    support: Support,
    /// For part `i` (and the floor at index `n`): the parts and the floor within the contact
    /// distance (filled for [`Support::ContactGraph`] only).
    contacts: Vec<Bits>,
    /// The parts the contact graph hangs from: the fixed parts, and the floor (index `n`) when
    /// no part is fixed.
    bases: Bits,
    warnings: Vec<String>,
}

/// One part's geometry prepared for sweeps: boxes in the sweep frame, or meshes.
enum Shape {
    Boxes { boxes: Vec<Aabb>, integer: bool },
    Mesh,
}

/// A part's voxels with the origin and cell size fitted to its mesh.
type VoxelFit = (Vec<[i32; 3]>, Vec3, Vec3);

/// The frame box sweeps run in: world = origin + grid * cell.
#[derive(Clone, Copy, Debug)]
struct SweepFrame {
    origin: Vec3,
    cell: Vec3,
}

impl SweepFrame {
    fn frame_box(&self, b: &Aabb) -> Aabb {
        Aabb::new((b.mins - self.origin) / self.cell, (b.maxs - self.origin) / self.cell)
    }
}

impl DistanceMaps {
    /// Computes every map of `assembly` (rows in parallel with rayon).
    pub fn build(assembly: &Assembly, config: &MapConfig) -> Result<DistanceMaps> {
        let n = assembly.len();
        if n == 0 {
            return Err(GeomError::Assembly {
                path: assembly.source.clone(),
                reason: "the model has no parts".into(),
            });
        }
        if n > MAX_PARTS {
            return Err(GeomError::Assembly {
                path: assembly.source.clone(),
                reason: format!("distance maps support at most {MAX_PARTS} parts, the model has {n}"),
            });
        }
        let hemisphere = Hemisphere::new(config.resolution, assembly.up)?;
        let diag = assembly.diagonal();
        let d_max = config.d_max.unwrap_or(diag).max(f32::MIN_POSITIVE);
        let tolerance = config.tolerance.unwrap_or(DEFAULT_RELATIVE_TOLERANCE * diag);
        let dcount = hemisphere.len();
        let stride = dcount.div_ceil(8) * 8;
        let mut warnings = Vec::new();
        let aabbs: Vec<Aabb> = assembly
            .parts
            .iter()
            .map(|p| p.mesh.aabb().unwrap_or(Aabb::new(Vec3::ZERO, Vec3::ZERO)))
            .collect();

        // Geometry: voxels, single boxes, or meshes.
        let mut voxel_fits: Vec<Option<VoxelFit>> = Vec::with_capacity(n);
        for p in &assembly.parts {
            let fit = if config.use_voxels {
                p.meta.cells.as_ref().and_then(|cells| match fit_voxels(cells, &p.mesh) {
                    Some((o, c)) => Some((cells.clone(), o, c)),
                    None => {
                        warnings.push(format!(
                            "part '{}': its voxels do not match its mesh; using the mesh",
                            p.name
                        ));
                        None
                    }
                })
            } else {
                None
            };
            voxel_fits.push(fit);
        }
        // A shared grid when every voxel part agrees on origin and cell size.
        let mut frame = SweepFrame { origin: Vec3::ZERO, cell: Vec3::ONE };
        let mut shared_grid = false;
        if let Some((_, o0, c0)) = voxel_fits.iter().flatten().next() {
            let agree = voxel_fits.iter().flatten().all(|(_, o, c)| {
                let eps = 1e-3 * c0.min_element();
                (*c - *c0).abs().max_element() <= eps && {
                    // origins may differ by whole cells
                    let k = (*o - *o0) / *c0;
                    (k - k.round()).abs().max_element() * c0.min_element() <= eps
                }
            });
            if agree {
                frame = SweepFrame { origin: *o0, cell: *c0 };
                shared_grid = true;
            }
        }
        let mut geometry = Vec::with_capacity(n);
        let mut shapes = Vec::with_capacity(n);
        for (i, p) in assembly.parts.iter().enumerate() {
            if let Some((cells, o, c)) = &voxel_fits[i] {
                let boxes = cells
                    .iter()
                    .map(|v| {
                        let lo = Vec3::new(v[0] as f32, v[1] as f32, v[2] as f32);
                        if shared_grid {
                            let shift = ((*o - frame.origin) / frame.cell).round();
                            Aabb::new(lo + shift, lo + shift + Vec3::ONE)
                        } else {
                            Aabb::new(*o + lo * *c, *o + (lo + Vec3::ONE) * *c)
                        }
                    })
                    .collect();
                geometry.push(PartGeometry::Voxels);
                shapes.push(Shape::Boxes { boxes, integer: shared_grid });
            } else if let Some(boxes) = p.meta.boxes.as_ref().and_then(|b| fit_boxes(b, &p.mesh)) {
                geometry.push(PartGeometry::Box);
                shapes.push(Shape::Boxes { boxes: boxes.iter().map(|b| frame.frame_box(b)).collect(), integer: false });
            } else if let Some(b) = single_box(&p.mesh) {
                geometry.push(PartGeometry::Box);
                shapes.push(Shape::Boxes { boxes: vec![frame.frame_box(&b)], integer: false });
            } else {
                geometry.push(PartGeometry::Mesh);
                shapes.push(Shape::Mesh);
            }
        }
        // The collision world (welded, oriented meshes; eroded copies; contacts), only when a
        // pair needs shape casting or the contact graph needs mesh contacts.
        let need_mesh = shapes.iter().any(|s| matches!(s, Shape::Mesh));
        let contact_distance = config.contact_distance.unwrap_or(DEFAULT_RELATIVE_CONTACT * diag);
        let world = if need_mesh {
            let world_config = WorldConfig {
                tolerance: Some(tolerance.max(f32::MIN_POSITIVE)),
                contact_distance: Some(contact_distance.max(f32::MIN_POSITIVE)),
                overlaps: config.overlaps,
                ..WorldConfig::default()
            };
            let world = World::new(assembly.clone(), &world_config)?;
            warnings.extend(world.warnings().iter().cloned());
            Some(world)
        } else {
            None
        };

        let dirs = hemisphere.directions().to_vec();
        let frame_dirs: Vec<Vec3> = dirs.iter().map(|d| *d / frame.cell).collect();
        let frame_tol = tolerance / frame.cell.min_element();
        let upv = hemisphere.up();
        let low: Vec<f32> = aabbs.iter().map(|b| lowest_along(b, upv)).collect();
        let floor_level = low.iter().copied().fold(f32::INFINITY, f32::min);
        let n1 = n + 1;

        // Row i: M(p_i, p_j) for j in 0..=n (j = n is the floor).
        let rows: Vec<(Vec<f32>, Vec<DirMask>)> = (0..n1)
            .into_par_iter()
            .map(|i| {
                let mut vals = vec![0.0f32; n1 * stride];
                let mut masks = vec![DirMask::EMPTY; n1];
                for j in 0..n1 {
                    if i == j {
                        continue;
                    }
                    let row = &mut vals[j * stride..j * stride + dcount];
                    if j == n {
                        // Parts never move into the floor along the half sphere.
                        row.fill(d_max);
                        continue;
                    }
                    if i == n {
                        // The floor rises along m until it touches p_j's lowest point.
                        let gap = low[j] - floor_level;
                        let gap = if gap <= tolerance { 0.0 } else { gap };
                        for (d, m) in dirs.iter().enumerate() {
                            let c = m.dot(upv);
                            row[d] = if c > 1e-6 { (gap / c).min(d_max) } else { d_max };
                        }
                    } else {
                        match (&shapes[i], &shapes[j]) {
                            (
                                Shape::Boxes { boxes: bi, integer: ii },
                                Shape::Boxes { boxes: bj, integer: ij },
                            ) => {
                                let tol = if *ii && *ij { 0.0 } else { frame_tol };
                                let ai = frame.frame_box(&aabbs[i]);
                                let aj = frame.frame_box(&aabbs[j]);
                                for (d, m) in frame_dirs.iter().enumerate() {
                                    let mut best = d_max;
                                    if first_overlap(&ai, *m, &aj, tol).is_some_and(|t| t < d_max) {
                                        for a in bi {
                                            for b in bj {
                                                if let Some(t) = first_overlap(a, *m, b, tol) {
                                                    best = best.min(t);
                                                }
                                            }
                                        }
                                    }
                                    row[d] = best;
                                }
                            }
                            _ => {
                                let world = world.as_ref().expect("built when a part is a mesh");
                                let (_, erosion) = world.pair_erosion(i, j);
                                let (moving, fixed) = world.pair_shapes(i, j);
                                let ignored = world.ignores(i, j);
                                let strict = world.is_strict_pair(i, j);
                                for (d, m) in dirs.iter().enumerate() {
                                    let near = first_overlap(&aabbs[i], *m, &aabbs[j], 0.0).is_some_and(|t| t < d_max);
                                    let mut v = if !ignored && near {
                                        cast_distance(&moving, &fixed, *m, d_max, erosion)
                                    } else {
                                        d_max
                                    };
                                    if strict && near && v > 0.0 {
                                        // an input overlap: no sample may enter new material
                                        if let Some(t) = world.strict_entry(i, j, Vec3::ZERO, *m, v, false) {
                                            v = v.min(if t <= erosion { 0.0 } else { t });
                                        }
                                    }
                                    row[d] = v;
                                }
                            }
                        }
                    }
                    let mut mask = DirMask::EMPTY;
                    for (d, v) in row.iter().enumerate() {
                        if *v < d_max {
                            mask.insert(d);
                        }
                    }
                    masks[j] = mask;
                }
                (vals, masks)
            })
            .collect();
        let mut values = Vec::with_capacity(n1 * n1 * stride);
        let mut blocked = Vec::with_capacity(n1 * n1);
        for (v, m) in rows {
            values.extend(v);
            blocked.extend(m);
        }
        let fixed: Vec<bool> = assembly.parts.iter().map(|p| p.fixed).collect();
        let floor_is_base = !fixed.iter().any(|&f| f);
        let mut bases = PartSet::from_indices(n1, (0..n).filter(|&i| fixed[i]));
        if floor_is_base {
            bases.insert(n);
        }
        let contacts = if config.support == Support::ContactGraph {
            let mut contacts = vec![PartSet::empty(n1); n1];
            let mut touch = |i: usize, j: usize| {
                contacts[i].insert(j);
                contacts[j].insert(i);
            };
            if let Some(w) = &world {
                // the world's contact graph (its ground, when present, is index n)
                for i in 0..w.num_parts() + usize::from(w.ground().is_some()) {
                    for j in w.contacts(i).iter().filter(|&j| j > i) {
                        touch(i, j);
                    }
                }
            } else {
                for i in 0..n {
                    for j in (i + 1)..n {
                        if let (Shape::Boxes { boxes: bi, .. }, Shape::Boxes { boxes: bj, .. }) =
                            (&shapes[i], &shapes[j])
                        {
                            let near = bi.iter().any(|a| {
                                bj.iter().any(|b| box_distance(a, b, frame.cell) <= contact_distance)
                            });
                            if near {
                                touch(i, j);
                            }
                        }
                    }
                    if floor_is_base && low[i] - floor_level <= contact_distance {
                        touch(i, n);
                    }
                }
            }
            contacts
        } else {
            Vec::new()
        };
        let mut maps = DistanceMaps {
            n,
            hemisphere,
            diagonal: diag,
            contact_distance,
            d_max,
            tolerance,
            stride,
            values,
            blocked,
            fixed,
            aabbs,
            geometry,
            blockers: Vec::new(),
            blocker_set: Vec::new(),
            init_row: Vec::new(),
            words: n.div_ceil(64),
            dominators: Vec::new(),
            blocker_masks: Vec::new(),
            along: Vec::new(),
            blocks: Vec::new(),
            supporters: Vec::new(),
            dependents: Vec::new(),
            on_floor: Vec::new(),
            support: config.support,
            contacts: contacts.iter().map(Bits::from_set).collect(),
            bases: Bits::from_set(&bases),
            warnings,
        };
        maps.index();
        Ok(maps)
    }

    /// Builds the blocker, support and dependency indexes from the maps.
    fn index(&mut self) {
        let n = self.n;
        let up = self.hemisphere.up_index();
        let support_tol = 2.0 * self.tolerance;
        // Blockers that block the most directions first (a part's blocked directions fill up
        // after few of them when they are ORed in this order).
        self.blockers = (0..n)
            .map(|i| {
                let mut b: Vec<u16> =
                    (0..n).filter(|&j| j != i && !self.blocked(i, j).is_empty()).map(|j| j as u16).collect();
                b.sort_by_key(|&j| std::cmp::Reverse(self.blocked(i, j as usize).len()));
                b
            })
            .collect();
        self.blocker_set = (0..n)
            .map(|i| {
                let mut b = Bits::EMPTY;
                for &j in &self.blockers[i] {
                    b.insert(j as usize);
                }
                b
            })
            .collect();
        self.init_row = vec![0.0; self.stride];
        self.init_row[..self.hemisphere.len()].fill(self.d_max);
        let this = &*self;
        let dominators: Vec<Vec<Bits>> = (0..n)
            .into_par_iter()
            .map(|i| {
                let mut row = vec![Bits::EMPTY; n];
                for &j in &this.blockers[i] {
                    let j = j as usize;
                    let (mj, bj) = (this.map(i, j), this.blocked(i, j));
                    for &k in &this.blockers[i] {
                        let k = k as usize;
                        // a dominator blocks at least where j does
                        if k == j || !bj.and_not(this.blocked(i, k)).is_empty() {
                            continue;
                        }
                        let mk = this.map(i, k);
                        if mk.iter().zip(mj).all(|(a, b)| a <= b) && (k < j || mk != mj) {
                            row[j].insert(k);
                        }
                    }
                }
                row
            })
            .collect();
        let words = self.words;
        self.dominators = dominators.iter().flatten().flat_map(|b| b.0[..words].to_vec()).collect();
        self.blocker_masks =
            (0..n).map(|i| self.blockers[i].iter().map(|&j| self.blocked(i, j as usize)).collect()).collect();
        let dcount = self.hemisphere.len();
        self.along = vec![0; n * dcount * words];
        for i in 0..n {
            for &j in &self.blockers[i] {
                let j = j as usize;
                for d in self.blocked(i, j).iter() {
                    self.along[(i * dcount + d) * words + j / 64] |= 1 << (j % 64);
                }
            }
        }
        self.blocks = vec![Bits::EMPTY; n];
        for i in 0..n {
            for &j in &self.blockers[i] {
                self.blocks[j as usize].insert(i);
            }
        }
        self.supporters = (0..n)
            .map(|i| {
                (0..n)
                    .filter(|&j| j != i && self.map(j, i)[up] <= support_tol)
                    .map(|j| j as u16)
                    .collect()
            })
            .collect();
        self.dependents = vec![Vec::new(); n];
        for i in 0..n {
            for &j in &self.supporters[i] {
                self.dependents[j as usize].push(i as u16);
            }
        }
        self.on_floor = (0..n).map(|i| self.map(n, i)[up] <= support_tol).collect();
    }

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
    fn linked(&self, alive: Bits) -> Bits {
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
        self.fixed[i]
            || self.on_floor[i]
            || self.supporters[i].iter().any(|&j| state.contains(j as usize))
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

    fn clearance_in(&self, i: usize, state: &PartSet, free: DirMask) -> Option<(usize, f32)> {
        self.clearance_among(i, state.iter(), free)
    }

    fn clearance_among(
        &self,
        i: usize,
        present: impl Iterator<Item = usize>,
        free: DirMask,
    ) -> Option<(usize, f32)> {
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
            if best.is_none_or(|(b, t)| {
                travel < t || (travel == t && dirs[d].dot(up) > dirs[b].dot(up))
            }) {
                best = Some((d, travel));
            }
        }
        best
    }

    /// The removal motion of [`DistanceMaps::clearance`] as a [`Motion::Linear`].
    pub fn removal_motion(&self, i: usize, state: &PartSet) -> Option<Motion> {
        self.clearance(i, state).map(|(d, t)| Motion::Linear {
            direction: self.hemisphere.directions()[d],
            distance: t,
        })
    }

    /// Whether part `i` can be removed from `state` without collision (eq. 6.5).
    pub fn is_collision_free(&self, i: usize, state: &PartSet) -> bool {
        !self.free_mask(i, state).is_empty()
    }
}

/// The smallest `p · up` over the corners of box `b`.
fn lowest_along(b: &Aabb, up: Vec3) -> f32 {
    (0..3).map(|k| (b.mins[k] * up[k]).min(b.maxs[k] * up[k])).sum()
}

/// How far box `moving` travels along unit `dir` until it no longer overlaps box `rest`
/// (0 when they do not overlap now; touching is not overlapping).
fn clear_distance(moving: &Aabb, dir: Vec3, rest: &Aabb) -> f32 {
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

/// Distance the mesh `moving`, eroded by `erosion`, travels along `dir` before touching `fixed`
/// (exact triangle sweeps, [`crate::sweep`]), less the erosion (contacts within it read 0), capped at `d_max`.
fn cast_distance(moving: &TriMesh, fixed: &TriMesh, dir: Vec3, d_max: f32, erosion: f32) -> f32 {
    match crate::sweep::sweep_distance(moving, dir, fixed, d_max) {
        Some(hit) => {
            let t = hit - erosion;
            if t <= erosion {
                0.0
            } else {
                t.min(d_max)
            }
        }
        None => d_max,
    }
}

/// Values per block of [`min_rows`]: 32 floats are eight SSE (or four AVX) registers, so the
/// running minimum of a block stays in registers while the rows stream past.
const MIN_BLOCK: usize = 32;

/// `out = min(init, rows...)` elementwise, where the rows are `values[r * s..(r + 1) * s]`
/// for each row index `r` and the stride `s = out.len()`, and the sum of `out` in f64 (over eight interleaved lanes: element `k` goes
/// to lane `k % 8`, the lanes are added in order at the end). `out.len()` (the stride) is a
/// multiple of 8. Blocks of [`MIN_BLOCK`] values are finished one at a time, in order: the
/// minimum is exact, so the order of the rows does not matter.
fn min_rows(values: &[f32], rows: &[usize], init: &[f32], out: &mut [f32]) -> f64 {
    let stride = out.len();
    let mut lanes = [0.0f64; 8];
    let mut at = 0;
    while at + MIN_BLOCK <= stride {
        min_block::<MIN_BLOCK>(values, rows, init, out, at, &mut lanes);
        at += MIN_BLOCK;
    }
    match stride - at {
        0 => {}
        8 => min_block::<8>(values, rows, init, out, at, &mut lanes),
        16 => min_block::<16>(values, rows, init, out, at, &mut lanes),
        24 => min_block::<24>(values, rows, init, out, at, &mut lanes),
        r => unreachable!("the stride is a multiple of 8, {r} values left"),
    }
    lanes.iter().sum()
}

#[inline(always)]
fn min_block<const W: usize>(
    values: &[f32],
    rows: &[usize],
    init: &[f32],
    out: &mut [f32],
    at: usize,
    lanes: &mut [f64; 8],
) {
    let stride = out.len();
    let mut acc: [f32; W] = init[at..at + W].try_into().expect("W values");
    for &r in rows {
        let o = r * stride + at;
        let row: &[f32; W] = values[o..o + W].try_into().expect("W values");
        for (a, b) in acc.iter_mut().zip(row) {
            // a select, which vectorises to a packed minimum
            *a = if *b < *a { *b } else { *a };
        }
    }
    for chunk in acc.chunks_exact(8) {
        for (l, v) in lanes.iter_mut().zip(chunk) {
            *l += *v as f64;
        }
    }
    out[at..at + W].copy_from_slice(&acc);
}

/// A disassembly state over the distance maps, updated incrementally as parts leave: which
/// parts are present, which are collision-free (monotone: removals only free parts), the
/// minimum maps `M̄(p_i, s)`, and for the [`Support::Below`] rule how many present supports each
/// part has left.
///
/// A minimum map depends only on which of the part's blockers are present, so each computed
/// row is kept with that set as its key and reused — after later removals and across
/// [`MapState::reset`]s — while the part's present blockers are the same.
#[derive(Clone, Debug)]
pub struct MapState<'m> {
    maps: &'m DistanceMaps,
    all: DirMask,
    present: Bits,
    free: Bits,
    unchecked: Bits,
    /// Per part: its minimum map (padded to the maps' stride), computed for the present
    /// blockers in `row_keys` (a key no state has before the first computation).
    rows: Vec<f32>,
    row_keys: Vec<Bits>,
    /// The free directions of each part, computed with its row (valid when the row is).
    row_free: Vec<DirMask>,
    /// The sum of each row (valid with the row).
    row_sums: Vec<f64>,
    /// For each present part not known to be free: present blockers that together block every
    /// direction (a witness that it is stuck); it is re-checked only when one of them leaves.
    covers: Vec<Bits>,
    /// For each part `j`: the parts whose cover holds `j` (re-checked when `j` leaves).
    watchers: Vec<Bits>,
    /// Present supports of each present part ([`UNCOUNTED`] for fixed parts and parts on the
    /// floor, which always stand).
    supports: Vec<u16>,
    /// For each part: how many present parts rest on it alone.
    critical: Vec<u16>,
    /// The parts with `critical > 0` (their removal would drop another part).
    holding: Bits,
    /// The fixed parts.
    fixed: Bits,
    counters: MapCounters,
    /// Scratch (one slot per part): the rows (`i * (n + 1) + j`) of the blockers `j` that shape
    /// part `i`'s minimum map.
    kept: Vec<usize>,
}

const UNCOUNTED: u16 = u16::MAX;

/// The removability tests a [`MapState`] ran. Its answers are incremental: a part found free
/// stays free as parts leave and is not tested again, a stuck part is tested again only when a
/// part of its cover (blockers that together block every direction) leaves.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct MapCounters {
    /// Collision tests: whether a present part has a free direction (eq. 6.5).
    pub collision_tests: u64,
    /// Collision tests that found every direction blocked.
    pub blocked: u64,
    /// Gravity tests: a collision-free, non-fixed part's removal checked by the [`Support`]
    /// rule (once per part each time [`MapState::feasible_actions`] runs).
    pub gravity_tests: u64,
    /// Gravity tests that found the removal would leave a part without support.
    pub unsupported: u64,
}

impl<'m> MapState<'m> {
    /// The assembled state (every part present).
    pub fn new(maps: &'m DistanceMaps) -> Self {
        let n = maps.n;
        let mut s = MapState {
            maps,
            all: DirMask::first(maps.hemisphere.len()),
            present: Bits::EMPTY,
            free: Bits::EMPTY,
            unchecked: Bits::EMPTY,
            rows: vec![0.0; n * maps.stride],
            row_keys: vec![Bits::NO_KEY; n],
            row_free: vec![DirMask::EMPTY; n],
            row_sums: vec![0.0; n],
            covers: vec![Bits::EMPTY; n],
            watchers: vec![Bits::EMPTY; n],
            supports: vec![0; n],
            critical: vec![0; n],
            holding: Bits::EMPTY,
            fixed: Bits::from_set(&PartSet::from_indices(n, (0..n).filter(|&i| maps.fixed[i]))),
            kept: vec![0; n],
            counters: MapCounters::default(),
        };
        s.reset(&PartSet::full(n));
        s
    }

    /// Moves to `present` (which must only name parts of the assembly); no allocation.
    pub fn reset(&mut self, present: &PartSet) {
        self.reset_with_free(present, &PartSet::empty(self.maps.n));
    }

    /// Like [`MapState::reset`], with parts already known to be collision-free in `present` (or
    /// in a state it came from): they are not re-checked.
    pub fn reset_with_free(&mut self, present: &PartSet, free: &PartSet) {
        let p = Bits::from_set(present);
        self.present = p;
        self.free = Bits::from_set(free).and(&p);
        self.unchecked = p;
        // every stuck part is re-checked, and records its cover again
        self.watchers.fill(Bits::EMPTY);
        if self.maps.support == Support::Below {
            let maps = self.maps;
            self.critical.fill(0);
            self.holding = Bits::EMPTY;
            for i in p.iter() {
                self.supports[i] = if maps.fixed[i] || maps.on_floor[i] {
                    UNCOUNTED
                } else {
                    let mut count = 0;
                    let mut last = 0;
                    for &j in &maps.supporters[i] {
                        if p.contains(j as usize) {
                            count += 1;
                            last = j as usize;
                        }
                    }
                    if count == 1 {
                        self.critical[last] += 1;
                        self.holding.insert(last);
                    }
                    count
                };
            }
        }
    }

    /// The maps.
    pub fn maps(&self) -> &'m DistanceMaps {
        self.maps
    }

    /// The present parts.
    pub fn present(&self) -> PartSet {
        self.present.to_set(self.maps.n)
    }

    /// Whether part `i` is present.
    pub fn contains(&self, i: usize) -> bool {
        i < self.maps.n && self.present.contains(i)
    }

    /// Whether no part that can be removed (not fixed) is left.
    pub fn is_complete(&self) -> bool {
        self.present.iter().all(|i| self.maps.fixed[i])
    }

    /// Removes part `k`, marking the parts whose minimum maps it shaped, re-checking the stuck
    /// parts it helped block, and updating the support counts of the parts resting on it.
    pub fn remove(&mut self, k: usize) {
        let maps = self.maps;
        self.present.remove(k);
        self.free.remove(k);
        self.unchecked.remove(k);
        // re-check the stuck parts whose cover `k` was in
        self.unchecked = self.unchecked.or(&self.watchers[k].and(&self.present).and_not(&self.free));
        if maps.support == Support::Below {
            if self.supports[k] == 1 {
                if let Some(j) = self.single_support(k) {
                    self.critical[j] -= 1;
                    if self.critical[j] == 0 {
                        self.holding.remove(j);
                    }
                }
            }
            for &i in &maps.dependents[k] {
                let i = i as usize;
                if !self.present.contains(i) || self.supports[i] == UNCOUNTED {
                    continue;
                }
                self.supports[i] -= 1;
                if self.supports[i] == 1 {
                    if let Some(j) = self.single_support(i) {
                        self.critical[j] += 1;
                        self.holding.insert(j);
                    }
                }
            }
        }
    }

    /// The one present part that `i` rests on, if any.
    fn single_support(&self, i: usize) -> Option<usize> {
        self.maps.supporters[i].iter().map(|&j| j as usize).find(|&j| self.present.contains(j))
    }

    fn refresh_free(&mut self) {
        if self.unchecked.is_empty() {
            return;
        }
        let unchecked = std::mem::replace(&mut self.unchecked, Bits::EMPTY);
        for i in unchecked.and(&self.present).and_not(&self.free).iter() {
            if self.check_free(i) {
                self.free.insert(i);
            }
        }
    }

    /// Whether present part `i` has a free direction. When it has none, records as its cover
    /// present blockers that together block every direction.
    fn check_free(&mut self, i: usize) -> bool {
        // the bitsets in the loop have as many words as the part count needs
        match self.maps.words {
            1 => self.check_free_in::<1>(i),
            2 => self.check_free_in::<2>(i),
            3 => self.check_free_in::<3>(i),
            _ => self.check_free_in::<4>(i),
        }
    }

    fn check_free_in<const W: usize>(&mut self, i: usize) -> bool {
        self.counters.collision_tests += 1;
        let maps = self.maps;
        let first = i * (maps.n + 1);
        let dcount = maps.hemisphere.len();
        let along = &maps.along[i * dcount * W..(i + 1) * dcount * W];
        let present: [u64; W] = self.present.0[..W].try_into().expect("W words");
        // Start from the last cover's present members (they block where they blocked), then
        // take any direction still open: without a present blocker along it the part is free,
        // else the first such blocker joins the cover.
        let mut blocked = DirMask::EMPTY;
        let mut cover = self.covers[i].and(&self.present);
        for j in cover.iter() {
            blocked = blocked.or(maps.blocked[first + j]);
        }
        while let Some(d) = self.all.and_not(blocked).lowest() {
            let mut j = None;
            for (k, (a, p)) in along[d * W..(d + 1) * W].iter().zip(&present).enumerate() {
                let w = a & p;
                if w != 0 {
                    j = Some(k * 64 + w.trailing_zeros() as usize);
                    break;
                }
            }
            let Some(j) = j else { return true };
            blocked = blocked.or(maps.blocked[first + j]);
            cover.insert(j);
        }
        for k in self.covers[i].iter() {
            self.watchers[k].remove(i);
        }
        for k in cover.iter() {
            self.watchers[k].insert(i);
        }
        self.covers[i] = cover;
        self.counters.blocked += 1;
        false
    }

    fn blocked_now(&self, i: usize) -> DirMask {
        let maps = self.maps;
        let mut blocked = DirMask::EMPTY;
        for (&j, &b) in maps.blockers[i].iter().zip(&maps.blocker_masks[i]) {
            if self.present.contains(j as usize) {
                blocked = blocked.or(b);
            }
        }
        blocked
    }

    /// `B^M̄(p_i, s)`: the free directions of present part `i`.
    pub fn free_mask(&self, i: usize) -> DirMask {
        if self.row_is_current(i) {
            self.row_free[i]
        } else {
            self.all.and_not(self.blocked_now(i))
        }
    }

    /// Whether the kept minimum map of part `i` was computed for its present blockers.
    #[inline]
    fn row_is_current(&self, i: usize) -> bool {
        self.maps.blocker_set[i].and(&self.present) == self.row_keys[i]
    }

    /// Whether present part `i` can leave without collision (eq. 6.5).
    pub fn is_collision_free(&mut self, i: usize) -> bool {
        self.refresh_free();
        self.free.contains(i)
    }

    /// The present parts that can leave without collision.
    pub fn collision_free(&mut self) -> PartSet {
        self.refresh_free();
        self.free.to_set(self.maps.n)
    }

    /// `M̄(p_i, s)` (eq. 6.4) of present part `i`, `N_M²` values.
    pub fn min_map(&mut self, i: usize) -> &[f32] {
        if !self.row_is_current(i) {
            self.refresh_row(i);
        }
        let stride = self.maps.stride;
        &self.rows[i * stride..i * stride + self.maps.hemisphere.len()]
    }

    /// Recomputes the minimum map of part `i` and its free directions from its present blockers.
    fn refresh_row(&mut self, i: usize) {
        // the bitsets in the loop have as many words as the part count needs
        match self.maps.words {
            1 => self.refresh_row_in::<1>(i),
            2 => self.refresh_row_in::<2>(i),
            3 => self.refresh_row_in::<3>(i),
            _ => self.refresh_row_in::<4>(i),
        }
    }

    fn refresh_row_in<const W: usize>(&mut self, i: usize) {
        let maps = self.maps;
        let stride = maps.stride;
        let first = i * (maps.n + 1);
        let key = maps.blocker_set[i].and(&self.present);
        let dominators = &maps.dominators[i * maps.n * W..(i + 1) * maps.n * W];
        let present: [u64; W] = self.present.0[..W].try_into().expect("W words");
        let mut count = 0;
        for (k, &word) in key.0[..W].iter().enumerate() {
            let mut w = word;
            while w != 0 {
                let j = k * 64 + w.trailing_zeros() as usize;
                w &= w - 1;
                // Skips (without a branch) blockers with a present dominator: its map is nowhere
                // larger, so the minimum is the same, and it blocks a subset of the directions.
                let d: &[u64; W] = dominators[j * W..(j + 1) * W].try_into().expect("W words");
                let mut shared = 0;
                for (a, b) in d.iter().zip(&present) {
                    shared |= a & b;
                }
                self.kept[count] = first + j;
                count += usize::from(shared == 0);
            }
        }
        let kept = &self.kept[..count];
        let mut blocked = DirMask::EMPTY;
        for &r in kept {
            blocked = blocked.or(maps.blocked[r]);
        }
        let row = &mut self.rows[i * stride..(i + 1) * stride];
        self.row_sums[i] = min_rows(&maps.values, kept, &maps.init_row, row);
        self.row_free[i] = self.all.and_not(blocked);
        self.row_keys[i] = key;
    }

    /// `Σ_{k,l} M̄_{k,l}(p_i, s)` of present part `i` (the accessibility reward, eq. 6.15),
    /// summed in eight interleaved lanes.
    pub fn min_map_sum(&mut self, i: usize) -> f64 {
        self.min_map(i);
        self.row_sums[i]
    }

    /// Whether removing `a` leaves a standing state (the gravity check). With
    /// [`Support::Below`] it assumes the current state stands: no present part may rest on `a`
    /// alone; with [`Support::ContactGraph`] it walks the contact graph.
    pub fn removal_keeps_stable(&self, a: usize) -> bool {
        match self.maps.support {
            Support::Below => self.critical[a] == 0,
            Support::ContactGraph => {
                let mut alive = self.present;
                alive.remove(a);
                alive.and_not(&self.maps.linked(alive)).is_empty()
            }
        }
    }

    /// Whether `i` is a feasible removal: present, not fixed, collision-free, and leaving a
    /// stable state (one part of [`MapState::feasible_actions`]).
    pub fn can_remove(&mut self, i: usize) -> bool {
        if i >= self.maps.n || !self.present.contains(i) || self.fixed.contains(i) || !self.is_collision_free(i) {
            return false;
        }
        self.counters.gravity_tests += 1;
        let stable = self.removal_keeps_stable(i);
        if !stable {
            self.counters.unsupported += 1;
        }
        stable
    }

    /// Whether every present part stands (by the maps' [`Support`] rule).
    pub fn is_stable(&self) -> bool {
        self.maps.stability(&self.present()) == Stability::Stable
    }

    /// The feasible removals: present, not fixed, collision-free, and leaving a stable state.
    /// Writes them to `out` (cleared first) in increasing order.
    pub fn feasible_actions(&mut self, out: &mut Vec<usize>) {
        out.clear();
        self.refresh_free();
        let candidates = self.free.and_not(&self.fixed);
        match self.maps.support {
            Support::Below => {
                for (k, &w) in candidates.and_not(&self.holding).0.iter().enumerate() {
                    let mut w = w;
                    while w != 0 {
                        out.push(k * 64 + w.trailing_zeros() as usize);
                        w &= w - 1;
                    }
                }
            }
            Support::ContactGraph => {
                out.extend(candidates.iter().filter(|&a| self.removal_keeps_stable(a)))
            }
        }
        let tested = candidates.len() as u64;
        self.counters.gravity_tests += tested;
        self.counters.unsupported += tested - out.len() as u64;
    }

    /// What this state has tested so far (over every [`MapState::reset`]).
    pub fn counters(&self) -> MapCounters {
        self.counters
    }

    /// The removal motion of present part `i` (see [`DistanceMaps::clearance`]) as a direction
    /// index and a travel, or `None` when it is blocked.
    pub fn clearance(&self, i: usize) -> Option<(usize, f32)> {
        self.maps.clearance_among(i, self.present.iter(), self.free_mask(i))
    }
}

/// The distance maps as a [`FeasibilityChecker`]: removability (eq. 6.5) and the gravity check
/// of 6.3.2, counted like any removal test. Motions are straight lines along the sampled
/// direction that clears the remaining parts' bounds soonest.
#[derive(Debug)]
pub struct MapChecker {
    maps: std::sync::Arc<DistanceMaps>,
    counters: Counters,
}

impl MapChecker {
    /// A checker over `maps`.
    pub fn new(maps: std::sync::Arc<DistanceMaps>) -> Self {
        MapChecker { maps, counters: Counters::default() }
    }

    /// The maps.
    pub fn maps(&self) -> &DistanceMaps {
        &self.maps
    }
}

impl FeasibilityChecker for MapChecker {
    fn num_parts(&self) -> usize {
        self.maps.n
    }

    fn is_fixed(&self, part: usize) -> bool {
        self.maps.fixed[part]
    }

    fn test_removal(&self, part: usize, state: &PartSet, kind: MotionKind) -> Outcome {
        let maps = &self.maps;
        let outcome = match maps.removal_motion(part, state) {
            None => {
                let mut blockers = PartSet::empty(maps.n);
                for &j in &maps.blockers[part] {
                    if state.contains(j as usize) {
                        blockers.insert(j as usize);
                    }
                }
                Outcome::Collision { blockers }
            }
            Some(motion) => match maps.stability(&state.without(part)) {
                Stability::Stable => Outcome::Removed(motion),
                Stability::Unstable { floating } => Outcome::Unstable { floating, motion },
            },
        };
        self.counters.record(kind, &outcome);
        outcome
    }

    fn stability(&self, state: &PartSet) -> Stability {
        self.maps.stability(state)
    }

    fn counters(&self) -> CounterSnapshot {
        self.counters.snapshot()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::assembly::Part;
    use crate::fixtures;
    use crate::mesh::Mesh;

    fn part(name: &str, mesh: Mesh) -> Part {
        fixtures::part(name, mesh, false)
    }

    fn assembly(parts: Vec<Part>) -> Assembly {
        fixtures::assemble("test", parts, Axis::Z)
    }

    #[test]
    fn hemisphere_has_the_axes_and_no_duplicates() {
        let h = Hemisphere::new(5, Axis::Z).unwrap();
        assert_eq!(h.len(), 25);
        assert_eq!(h.directions()[h.up_index()], Vec3::Z);
        for axis in [Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y] {
            assert!(h.directions().iter().any(|d| (*d - axis).length() < 1e-6), "{axis:?}");
        }
        for (a, d) in h.directions().iter().enumerate() {
            assert!((d.length() - 1.0).abs() < 1e-5 && d.z >= 0.0);
            for e in &h.directions()[a + 1..] {
                assert!((*d - *e).length() > 1e-3);
            }
        }
        let hy = Hemisphere::new(3, Axis::Y).unwrap();
        assert_eq!(hy.directions()[hy.up_index()], Vec3::Y);
        assert!(hy.directions().iter().all(|d| d.y >= 0.0));
        assert!(Hemisphere::new(4, Axis::Z).is_err());
        assert!(MapConfig::builder().resolution(17).build().is_err());
        assert!(MapConfig::builder().d_max(-1.0).build().is_err());
    }

    #[test]
    fn dirmask_operations() {
        let all = DirMask::first(81);
        assert_eq!(all.len(), 81);
        assert!(all.contains(80) && !all.contains(81));
        let mut m = DirMask::EMPTY;
        m.insert(3);
        m.insert(70);
        assert_eq!(all.and(m).iter().collect::<Vec<_>>(), vec![3, 70]);
        assert_eq!(all.and_not(m).len(), 79);
        assert_eq!(DirMask::first(256).len(), 256);
    }

    #[test]
    fn clear_distance_of_boxes() {
        // (box sweeps themselves are tested in `crate::boxes`)
        let a = Aabb::new(Vec3::ZERO, Vec3::ONE);
        let b = Aabb::new(Vec3::new(2.0, 0.0, 0.0), Vec3::new(3.0, 1.0, 1.0));
        // already apart: nothing to travel
        assert_eq!(clear_distance(&a, Vec3::X, &b), 0.0);
        let rest = Aabb::new(Vec3::ZERO, Vec3::new(3.0, 1.0, 2.0));
        assert_eq!(clear_distance(&a, Vec3::X, &rest), 3.0);
        assert_eq!(clear_distance(&a, Vec3::Z, &rest), 2.0);
    }

    #[test]
    fn stacked_boxes_from_meshes_and_boxes_agree() {
        // Two stacked boxes: the top one leaves upward and sideways, the bottom one only
        // sideways (the top one blocks up).
        let mut top = Mesh::cuboid(Vec3::new(0.0, 0.0, 1.0), Vec3::new(1.0, 1.0, 2.0));
        let bottom = Mesh::cuboid(Vec3::ZERO, Vec3::ONE);
        let boxes = DistanceMaps::build(
            &assembly(vec![part("bottom", bottom.clone()), part("top", top.clone())]),
            &MapConfig::builder().resolution(3).build().unwrap(),
        )
        .unwrap();
        assert_eq!(boxes.geometry(0), PartGeometry::Box);
        // Turn the top box into a general mesh (subdivided) to force shape casting.
        let extra = top.vertices.len() as u32;
        top.vertices.push(Vec3::new(0.5, 0.5, 2.0));
        let t = top.triangles.iter().position(|t| t.iter().all(|&v| top.vertices[v as usize].z == 2.0)).unwrap();
        let [a, b, c] = top.triangles.remove(t);
        top.triangles.extend([[a, b, extra], [b, c, extra], [c, a, extra]]);
        assert!(top.topology().is_closed_manifold());
        let meshes = DistanceMaps::build(
            &assembly(vec![part("bottom", bottom), part("top", top)]),
            &MapConfig::builder().resolution(3).build().unwrap(),
        )
        .unwrap();
        assert_eq!(meshes.geometry(1), PartGeometry::Mesh);
        let d_max = boxes.d_max();
        assert!((d_max - 6f32.sqrt()).abs() < 1e-5);
        let h = boxes.hemisphere();
        let up = h.up_index();
        for maps in [&boxes, &meshes] {
            // bottom vs top: moving up hits immediately; horizontal is free
            assert_eq!(maps.map(0, 1)[up], 0.0);
            assert_eq!(maps.map(0, 1)[h.index(2, 2)], d_max); // +x
            // top vs bottom: every half-sphere direction is free
            assert!(maps.map(1, 0).iter().all(|&v| v == d_max));
            // the floor supports the bottom, the bottom supports the top
            assert!(maps.on_floor(0) && !maps.on_floor(1));
            assert_eq!(maps.supporters(1), &[0]);
            let full = PartSet::full(2);
            assert!(maps.is_collision_free(1, &full));
            // the bottom slides out sideways, but that drops the top
            assert!(maps.is_collision_free(0, &full));
            assert!(!maps.free_mask(0, &full).contains(up));
            assert_eq!(maps.stability(&PartSet::from_indices(2, [1])), Stability::Unstable {
                floating: PartSet::from_indices(2, [1])
            });
        }
    }

    #[test]
    fn map_state_tracks_removals() {
        // A column of three boxes: only the top leaves, then the middle, then the bottom.
        let parts = (0..3)
            .map(|k| {
                let z = k as f32;
                part(&format!("b{k}"), Mesh::cuboid(Vec3::new(0.0, 0.0, z), Vec3::new(1.0, 1.0, z + 1.0)))
            })
            .collect();
        let maps = DistanceMaps::build(&assembly(parts), &MapConfig::default()).unwrap();
        let mut s = MapState::new(&maps);
        let mut acts = Vec::new();
        s.feasible_actions(&mut acts);
        assert_eq!(acts, vec![2]);
        let before: f32 = s.min_map(1).iter().sum();
        s.remove(2);
        let after: f32 = s.min_map(1).iter().sum();
        assert!(after > before);
        let direct = maps.min_map(1, &s.present());
        assert_eq!(s.min_map(1), direct.as_slice());
        s.feasible_actions(&mut acts);
        assert_eq!(acts, vec![1]);
        // the middle box is already outside the bottom one's box: no travel, straight up
        let (d, t) = s.clearance(1).unwrap();
        assert_eq!(d, maps.hemisphere().up_index());
        assert_eq!(t, 0.0);
        s.remove(1);
        s.feasible_actions(&mut acts);
        assert_eq!(acts, vec![0]);
        s.remove(0);
        assert!(s.is_complete());
    }
}
