//! Computing the maps: part shapes (voxels, boxes, meshes), the rows of sweeps in parallel, and
//! the contact graph.

use super::maps::MapWorld;
use super::*;
use crate::assembly::Assembly;
use crate::boxes::{box_distance, first_overlap, PartShape};
use crate::error::{GeomError, Result};
use crate::math::{Aabb, Vec3};
use crate::partset::PartSet;
use crate::world::World;
use parry3d::shape::TriMesh;
use rayon::prelude::*;
use std::sync::Arc;

/// One part's geometry prepared for sweeps: boxes in the sweep frame, or meshes.
enum Shape {
    Boxes { boxes: Vec<Aabb>, integer: bool },
    Mesh,
}

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
    /// Computes every map of `assembly` (rows in parallel with rayon). When a part is a mesh,
    /// the maps build their own collision world (settings of [`MapConfig::world_config`]) and keep
    /// it ([`DistanceMaps::world`]).
    pub fn build(assembly: &Assembly, config: &MapConfig) -> Result<DistanceMaps> {
        Self::build_with(assembly, config, None)
    }

    /// [`DistanceMaps::build`] on the collision world of a run, so the maps, the depth-first
    /// planner and the robot share one `World`: the maps of `world.assembly()`, equal to the maps
    /// built alone. The world must have the maps' settings ([`MapConfig::world_config`]; its
    /// candidate directions may differ, the maps do not read them), else an error names the
    /// setting. The maps keep the world ([`DistanceMaps::world`]).
    pub fn build_on(world: Arc<World>, config: &MapConfig) -> Result<DistanceMaps> {
        let assembly = world.assembly();
        let want = config.world_config(assembly);
        let have = world.config();
        let differs = [
            ("tolerance", have.tolerance != want.tolerance),
            ("contact distance", have.contact_distance != want.contact_distance),
            ("overlap policy", have.overlaps != want.overlaps),
            ("max overlap fraction", have.max_overlap_fraction != want.max_overlap_fraction),
            ("exact boxes", have.exact_boxes != want.exact_boxes),
            ("fasteners", have.fasteners != want.fasteners),
        ];
        if let Some((name, _)) = differs.iter().find(|(_, d)| *d) {
            return Err(GeomError::config(format!("distance maps: the collision world's {name} differs from the maps' settings")));
        }
        Self::build_with(&world.assembly().clone(), config, Some(world))
    }

    /// The build in its steps: each part's shape in the sweep frame, the collision world when a
    /// pair needs triangle sweeps, the rows of sweeps (in parallel), the contact graph, the
    /// indexes.
    fn build_with(assembly: &Assembly, config: &MapConfig, given: Option<Arc<World>>) -> Result<DistanceMaps> {
        let n = assembly.len();
        if n == 0 {
            return Err(GeomError::Assembly { path: assembly.source.clone(), reason: "the model has no parts".into() });
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
        let contact_distance = config.contact_distance.unwrap_or(DEFAULT_RELATIVE_CONTACT * diag);
        let stride = hemisphere.len().div_ceil(8) * 8;
        let mut warnings = Vec::new();
        let aabbs: Vec<Aabb> = assembly.parts.iter().map(|p| p.mesh.aabb().unwrap_or(Aabb::new(Vec3::ZERO, Vec3::ZERO))).collect();

        // 1. Shapes: the one classification of the collision world (voxels, boxes or a mesh).
        let shapes = SweepShapes::classify(assembly, config.exact_boxes, &mut warnings);

        // 2. The collision world (welded, oriented meshes; eroded copies; contacts), only when a
        // pair needs triangle sweeps or the contact graph needs mesh contacts; a given world is
        // kept for the robot even when no pair reads it.
        let need_mesh = shapes.shapes.iter().any(|s| matches!(s, Shape::Mesh));
        let (world, kept) = match given {
            _ if !need_mesh => (None, given),
            Some(world) => (Some(world), None),
            None => (Some(Arc::new(World::new(assembly.clone(), &config.world_config(assembly))?)), None),
        };
        if let Some(world) = &world {
            // the world classified the parts the same way: its warnings repeat the maps'
            let fresh: Vec<String> = world.warnings().iter().filter(|w| !warnings.contains(w)).cloned().collect();
            warnings.extend(fresh);
        }

        // 3. The rows: M(p_i, p_j) for every ordered pair and the floor, in parallel.
        let upv = hemisphere.up();
        let low: Vec<f32> = aabbs.iter().map(|b| lowest_along(b, upv)).collect();
        let floor_level = low.iter().copied().fold(f32::INFINITY, f32::min);
        let sweeps = RowSweeps {
            n,
            stride,
            d_max,
            tolerance,
            dirs: hemisphere.directions().to_vec(),
            frame_dirs: hemisphere.directions().iter().map(|d| *d / shapes.frame.cell).collect(),
            frame_tol: tolerance / shapes.frame.cell.min_element(),
            up: upv,
            low: &low,
            floor_level,
            aabbs: &aabbs,
            shapes: &shapes,
            world: world.as_deref(),
        };
        let (values, blocked) = sweeps.all();

        // 4. The bases and, for the contact-graph support rule, the contact graph.
        let fixed: Vec<bool> = assembly.parts.iter().map(|p| p.fixed).collect();
        let floor_is_base = !fixed.iter().any(|&f| f);
        let mut bases = PartSet::from_indices(n + 1, (0..n).filter(|&i| fixed[i]));
        if floor_is_base {
            bases.insert(n);
        }
        let contacts = if config.support == Support::ContactGraph {
            contact_graph(n, world.as_deref(), &shapes, contact_distance, floor_is_base.then_some((&low[..], floor_level)))
        } else {
            Vec::new()
        };

        // 5. The indexes the incremental state reads.
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
            geometry: shapes.geometry,
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
            world: MapWorld(world.or(kept)),
        };
        maps.index();
        Ok(maps)
    }
}

/// Every part's shape for sweeps, in the frame they run in.
struct SweepShapes {
    /// The sweep frame: a shared voxel grid when every voxel part agrees on it, else the world.
    frame: SweepFrame,
    shapes: Vec<Shape>,
    geometry: Vec<PartGeometry>,
}

impl SweepShapes {
    /// Classifies every part ([`PartShape::classify`]) and puts its boxes in the sweep frame:
    /// voxels on a shared grid are swept in integer grid coordinates.
    fn classify(assembly: &Assembly, exact: bool, warnings: &mut Vec<String>) -> SweepShapes {
        let classified: Vec<PartShape> = assembly
            .parts
            .iter()
            .map(|p| {
                let (shape, warning) = PartShape::classify(p, exact);
                warnings.extend(warning);
                shape
            })
            .collect();
        // A shared grid when every voxel part agrees on origin and cell size.
        let mut frame = SweepFrame { origin: Vec3::ZERO, cell: Vec3::ONE };
        let mut shared_grid = false;
        let voxel_grids = || {
            classified.iter().filter_map(|s| match s {
                PartShape::Voxels { origin, cell, .. } => Some((*origin, *cell)),
                _ => None,
            })
        };
        if let Some((o0, c0)) = voxel_grids().next() {
            let agree = voxel_grids().all(|(o, c)| {
                let eps = 1e-3 * c0.min_element();
                (c - c0).abs().max_element() <= eps && {
                    // origins may differ by whole cells
                    let k = (o - o0) / c0;
                    (k - k.round()).abs().max_element() * c0.min_element() <= eps
                }
            });
            if agree {
                frame = SweepFrame { origin: o0, cell: c0 };
                shared_grid = true;
            }
        }
        let mut geometry = Vec::with_capacity(classified.len());
        let mut shapes = Vec::with_capacity(classified.len());
        for shape in &classified {
            match shape {
                PartShape::Voxels { cells, origin: o, cell: c } => {
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
                }
                PartShape::Boxes(boxes) => {
                    geometry.push(PartGeometry::Box);
                    shapes.push(Shape::Boxes { boxes: boxes.iter().map(|b| frame.frame_box(b)).collect(), integer: false });
                }
                PartShape::Mesh => {
                    geometry.push(PartGeometry::Mesh);
                    shapes.push(Shape::Mesh);
                }
            }
        }
        SweepShapes { frame, shapes, geometry }
    }
}

/// The sweeps of every row of the maps, with what they read.
struct RowSweeps<'a> {
    n: usize,
    stride: usize,
    d_max: f32,
    tolerance: f32,
    /// The candidate directions, in the world and in the sweep frame.
    dirs: Vec<Vec3>,
    frame_dirs: Vec<Vec3>,
    /// The tolerance in the sweep frame.
    frame_tol: f32,
    up: Vec3,
    /// Each part's lowest point along `up`, and the lowest of all (the floor).
    low: &'a [f32],
    floor_level: f32,
    aabbs: &'a [Aabb],
    shapes: &'a SweepShapes,
    world: Option<&'a World>,
}

impl RowSweeps<'_> {
    /// Every row, in parallel: the values (`stride` floats per pair) and the blocked directions.
    fn all(&self) -> (Vec<f32>, Vec<DirMask>) {
        let n1 = self.n + 1;
        let rows: Vec<(Vec<f32>, Vec<DirMask>)> = (0..n1).into_par_iter().map(|i| self.row(i)).collect();
        let mut values = Vec::with_capacity(n1 * n1 * self.stride);
        let mut blocked = Vec::with_capacity(n1 * n1);
        for (v, m) in rows {
            values.extend(v);
            blocked.extend(m);
        }
        (values, blocked)
    }

    /// Row i: M(p_i, p_j) for j in 0..=n (j = n is the floor).
    fn row(&self, i: usize) -> (Vec<f32>, Vec<DirMask>) {
        let (n, d_max) = (self.n, self.d_max);
        let n1 = n + 1;
        let dcount = self.dirs.len();
        let mut vals = vec![0.0f32; n1 * self.stride];
        let mut masks = vec![DirMask::EMPTY; n1];
        for j in 0..n1 {
            if i == j {
                continue;
            }
            let row = &mut vals[j * self.stride..j * self.stride + dcount];
            if j == n {
                // Parts never move into the floor along the half sphere.
                row.fill(d_max);
                continue;
            }
            if i == n {
                // The floor rises along m until it touches p_j's lowest point.
                let gap = self.low[j] - self.floor_level;
                let gap = if gap <= self.tolerance { 0.0 } else { gap };
                for (d, m) in self.dirs.iter().enumerate() {
                    let c = m.dot(self.up);
                    row[d] = if c > 1e-6 { (gap / c).min(d_max) } else { d_max };
                }
            } else {
                self.pair(i, j, row);
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
    }

    /// M(p_i, p_j) along every direction into `row`: box sweeps when both are boxes, else
    /// triangle sweeps of the world's eroded meshes.
    fn pair(&self, i: usize, j: usize, row: &mut [f32]) {
        let d_max = self.d_max;
        let frame = &self.shapes.frame;
        match (&self.shapes.shapes[i], &self.shapes.shapes[j]) {
            (Shape::Boxes { boxes: bi, integer: ii }, Shape::Boxes { boxes: bj, integer: ij }) => {
                let tol = if *ii && *ij { 0.0 } else { self.frame_tol };
                let ai = frame.frame_box(&self.aabbs[i]);
                let aj = frame.frame_box(&self.aabbs[j]);
                for (d, m) in self.frame_dirs.iter().enumerate() {
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
                let world = self.world.expect("built when a part is a mesh");
                let (_, erosion) = world.overlaps().erosion(i, j);
                let (moving, fixed) = world.blocking().pairs().shapes(i, j);
                let ignored = world.overlaps().ignores(i, j);
                let strict = world.overlaps().is_strict(i, j);
                for (d, m) in self.dirs.iter().enumerate() {
                    let near = first_overlap(&self.aabbs[i], *m, &self.aabbs[j], 0.0).is_some_and(|t| t < d_max);
                    let mut v = if !ignored && near { cast_distance(&moving, &fixed, *m, d_max, erosion) } else { d_max };
                    if strict && near && v > 0.0 {
                        // an input overlap: no sample may enter new material
                        if let Some(t) = world.blocking().pairs().strict_entry(i, j, Vec3::ZERO, *m, v, false) {
                            v = v.min(if t <= erosion { 0.0 } else { t });
                        }
                    }
                    row[d] = v;
                }
            }
        }
    }
}

/// The contact graph over the parts and the floor (index `n`): the world's contacts when there
/// is a world, else box pairs within `contact_distance`, and with `floor` (each part's lowest
/// point and the floor's level, when the floor is the base) parts within it of the floor.
fn contact_graph(
    n: usize,
    world: Option<&World>,
    shapes: &SweepShapes,
    contact_distance: f32,
    floor: Option<(&[f32], f32)>,
) -> Vec<PartSet> {
    let n1 = n + 1;
    let mut contacts = vec![PartSet::empty(n1); n1];
    let mut touch = |i: usize, j: usize| {
        contacts[i].insert(j);
        contacts[j].insert(i);
    };
    if let Some(w) = world {
        // the world's contact graph (its ground, when present, is index n)
        for i in 0..w.num_parts() + usize::from(w.shapes().ground().is_some()) {
            for j in w.contacts().of(i).iter().filter(|&j| j > i) {
                touch(i, j);
            }
        }
    } else {
        for i in 0..n {
            for j in (i + 1)..n {
                if let (Shape::Boxes { boxes: bi, .. }, Shape::Boxes { boxes: bj, .. }) = (&shapes.shapes[i], &shapes.shapes[j]) {
                    let near = bi.iter().any(|a| bj.iter().any(|b| box_distance(a, b, shapes.frame.cell) <= contact_distance));
                    if near {
                        touch(i, j);
                    }
                }
            }
            if let Some((low, floor_level)) = floor {
                if low[i] - floor_level <= contact_distance {
                    touch(i, n);
                }
            }
        }
    }
    contacts
}

/// The smallest `p · up` over the corners of box `b`.
fn lowest_along(b: &Aabb, up: Vec3) -> f32 {
    (0..3).map(|k| (b.mins[k] * up[k]).min(b.maxs[k] * up[k])).sum()
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
