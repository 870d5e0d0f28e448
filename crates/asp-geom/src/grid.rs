//! Voxel models: an assembly whose parts are sets of cells on ONE common grid ([`VoxelModel::of`]:
//! from `extras.asp.cells`, or voxelised from a polycube mesh), the geometry the grid planner of
//! asp-search (`asp_search::grid`) takes apart by moves of parts and groups.

use crate::assembly::Assembly;
use crate::boxes;
use crate::math::{Aabb, Vec3};
use crate::mesh::Mesh;
use std::collections::HashMap;

/// A cell of the grid.
pub type Cell = [i32; 3];

/// An assembly seen on one voxel grid.
#[derive(Clone, Debug, PartialEq)]
pub struct VoxelModel {
    /// The size of a cell along x, y, z (metres).
    pub cell: Vec3,
    /// The world position of the min corner of cell `[0, 0, 0]` (metres).
    pub origin: Vec3,
    /// The cells of every part (sorted, distinct), by part index.
    pub cells: Vec<Vec<Cell>>,
    /// Which parts are fixed.
    pub fixed: Vec<bool>,
}

/// The most cells times triangles a mesh is voxelised with (beyond: not a voxel model).
const MAX_VOXELISE_WORK: usize = 50_000_000;
/// The most cells of a voxel model (all parts): puzzles, not furniture boards on a fine grid.
const MAX_CELLS: usize = 20_000;

impl VoxelModel {
    /// A voxel model of unit cells at the origin (tests, fixtures).
    pub fn from_cells(cells: Vec<Vec<Cell>>, fixed: Vec<bool>) -> VoxelModel {
        let cells = cells
            .into_iter()
            .map(|mut c| {
                c.sort_unstable();
                c.dedup();
                c
            })
            .collect();
        VoxelModel { cell: Vec3::ONE, origin: Vec3::ZERO, cells, fixed }
    }

    /// The voxel view of `assembly`, or `None` when it is not a voxel model: every part must be
    /// a union of cells of one common grid — its `extras.asp.cells` fitted to its mesh, or its
    /// mesh voxelised (the grid's spacing and origin found from the vertex coordinates of every
    /// part, cell centres classified inside/outside the closed mesh, accepted only when the
    /// cells' volume and boundary area equal the mesh's and every vertex lies on a cell) — and
    /// no two parts may share a cell. Fixed parts are immovable cells.
    pub fn of(assembly: &Assembly) -> Option<VoxelModel> {
        if assembly.parts.is_empty() || assembly.parts.len() > 64 {
            return None;
        }
        let mut cell = Vec3::ZERO;
        let mut origin = Vec3::ZERO;
        for k in 0..3 {
            let coords: Vec<f64> = assembly.parts.iter().flat_map(|p| p.mesh.vertices.iter().map(move |v| v[k] as f64)).collect();
            let (s, o) = lattice(&coords)?;
            cell[k] = s as f32;
            origin[k] = o as f32;
        }
        let mut cells = Vec::with_capacity(assembly.parts.len());
        let mut total = 0;
        for part in &assembly.parts {
            let c = match &part.meta.cells {
                Some(local) => from_meta(local, &part.mesh, cell, origin)?,
                None => voxelise(&part.mesh, cell, origin, MAX_CELLS - total)?,
            };
            total += c.len();
            if total > MAX_CELLS {
                return None;
            }
            cells.push(c);
        }
        let mut owner: HashMap<Cell, usize> = HashMap::new();
        for (p, cs) in cells.iter().enumerate() {
            for c in cs {
                if owner.insert(*c, p).is_some() {
                    return None;
                }
            }
        }
        Some(VoxelModel { cell, origin, cells, fixed: assembly.parts.iter().map(|p| p.fixed).collect() })
    }

    /// Number of parts.
    pub fn len(&self) -> usize {
        self.cells.len()
    }

    /// Whether there are no parts.
    pub fn is_empty(&self) -> bool {
        self.cells.is_empty()
    }

    /// A translation by `delta` cells, in metres.
    pub fn metres(&self, delta: Cell) -> Vec3 {
        Vec3::new(delta[0] as f32, delta[1] as f32, delta[2] as f32) * self.cell
    }
}

/// The spacing and origin of a 1-D lattice holding every coordinate (tolerance 1e-4 of a cell).
fn lattice(coords: &[f64]) -> Option<(f64, f64)> {
    let mut v: Vec<f64> = coords.to_vec();
    v.sort_by(f64::total_cmp);
    let (lo, hi) = (*v.first()?, *v.last()?);
    let extent = hi - lo;
    if !(extent > 0.0 && extent.is_finite()) {
        return None;
    }
    let eps = 1e-6 * extent;
    let mut distinct = vec![v[0]];
    for &x in &v[1..] {
        if x - distinct.last().unwrap() > eps {
            distinct.push(x);
        }
    }
    let gap = distinct.windows(2).map(|w| w[1] - w[0]).fold(f64::INFINITY, f64::min);
    if !gap.is_finite() {
        return None;
    }
    'divisor: for j in 1..=12 {
        let s = gap / j as f64;
        if extent / s > 4096.0 {
            return None;
        }
        for &x in &distinct {
            let r = (x - lo) / s;
            if (r - r.round()).abs() > 1e-4 {
                continue 'divisor;
            }
        }
        // snap the spacing to the whole extent for accuracy
        let n = (extent / s).round();
        return Some((extent / n, lo));
    }
    None
}

/// A part's metadata cells on the common grid, when they describe its mesh.
fn from_meta(local: &[Cell], mesh: &Mesh, cell: Vec3, origin: Vec3) -> Option<Vec<Cell>> {
    let (offset, scale) = boxes::fit_voxels(local, mesh)?;
    let mut shift = [0i32; 3];
    for k in 0..3 {
        if ((scale[k] - cell[k]) / cell[k]).abs() > 1e-3 {
            return None;
        }
        let r = (offset[k] - origin[k]) / cell[k];
        if (r - r.round()).abs() > 1e-3 {
            return None;
        }
        shift[k] = r.round() as i32;
    }
    let mut out: Vec<Cell> = local.iter().map(|c| [c[0] + shift[0], c[1] + shift[1], c[2] + shift[2]]).collect();
    out.sort_unstable();
    out.dedup();
    Some(out)
}

/// The cells of the grid whose centres lie inside the closed mesh, when they describe it.
fn voxelise(mesh: &Mesh, cell: Vec3, origin: Vec3, max_cells: usize) -> Option<Vec<Cell>> {
    let b = mesh.aabb()?;
    let idx = |x: f32, k: usize| ((x - origin[k]) / cell[k]).round() as i32;
    let lo = [idx(b.mins.x, 0), idx(b.mins.y, 1), idx(b.mins.z, 2)];
    let hi = [idx(b.maxs.x, 0), idx(b.maxs.y, 1), idx(b.maxs.z, 2)];
    let count = (0..3).map(|k| (hi[k] - lo[k]).max(0) as usize).product::<usize>();
    if count == 0 || count > 8 * max_cells || count.saturating_mul(mesh.triangles.len()) > MAX_VOXELISE_WORK {
        return None;
    }
    let tris: Vec<[[f64; 3]; 3]> =
        mesh.triangles.iter().map(|t| t.map(|i| mesh.vertices[i as usize].to_array().map(|x| x as f64))).collect();
    // a ray direction off every lattice plane and diagonal
    let dir = [0.8113_f64, 0.4521, 0.3702];
    let mut cells = Vec::new();
    for i in lo[0]..hi[0] {
        for j in lo[1]..hi[1] {
            for k in lo[2]..hi[2] {
                let c = [i, j, k];
                let p: [f64; 3] = std::array::from_fn(|a| origin[a] as f64 + (c[a] as f64 + 0.5) * cell[a] as f64);
                let crossings = tris.iter().filter(|t| ray_hits(p, dir, t)).count();
                if crossings % 2 == 1 {
                    cells.push(c);
                }
            }
        }
    }
    if cells.is_empty() {
        return None;
    }
    // the cells must describe the mesh: volume, every vertex on a cell, boundary area
    let world: Vec<Aabb> = cells
        .iter()
        .map(|c| {
            let lo = origin + Vec3::new(c[0] as f32, c[1] as f32, c[2] as f32) * cell;
            Aabb::new(lo, lo + cell)
        })
        .collect();
    boxes::fit_boxes(&world, mesh)?;
    let set: std::collections::HashSet<Cell> = cells.iter().copied().collect();
    let mut area = 0.0f64;
    for c in &cells {
        for a in 0..3 {
            for s in [-1, 1] {
                let mut n = *c;
                n[a] += s;
                if !set.contains(&n) {
                    area += (cell[(a + 1) % 3] * cell[(a + 2) % 3]) as f64;
                }
            }
        }
    }
    ((mesh.area() - area).abs() <= 1e-3 * area).then_some(cells)
}

/// Möller–Trumbore: whether the ray from `p` along `d` crosses the triangle.
fn ray_hits(p: [f64; 3], d: [f64; 3], t: &[[f64; 3]; 3]) -> bool {
    let sub = |a: [f64; 3], b: [f64; 3]| [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    let cross = |a: [f64; 3], b: [f64; 3]| [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
    let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let (e1, e2) = (sub(t[1], t[0]), sub(t[2], t[0]));
    let h = cross(d, e2);
    let det = dot(e1, h);
    if det.abs() < 1e-300 {
        return false;
    }
    let f = 1.0 / det;
    let s = sub(p, t[0]);
    let u = f * dot(s, h);
    if !(0.0..=1.0).contains(&u) {
        return false;
    }
    let q = cross(s, e1);
    let v = f * dot(d, q);
    if v < 0.0 || u + v > 1.0 {
        return false;
    }
    f * dot(e2, q) > 0.0
}
