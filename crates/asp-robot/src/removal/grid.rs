//! The parts as the sphere tests ask for them: "how far is this point from the parts present?"
//!
//! [`PartGrid`] holds every part's exact boxes ([`asp_geom::world::Shapes::boxes`]; a part without them by its
//! bounding box, a lower bound of its distance, whose exact test is on its mesh) and a uniform
//! grid over them (the broad phase over the cell). Each grid cell lists the parts whose box
//! lies within `reach` of it and keeps a lower bound on its distance to every part it does not
//! list, so a point's distance to the present parts is bounded from below by one cell: the
//! exact distances of the listed present parts' boxes (a part's boxes only when its bounding
//! box is nearer than the best so far), and the cell's bound for the rest.
//! Parts only leave, so the bound of the whole model holds in every state. The virtual ground
//! is not in the grid (it is tested apart, like the floor).

use asp_geom::World;

/// A box of a part: its corners and the part.
#[derive(Clone, Copy, Debug)]
pub(super) struct GridBox {
    pub(super) mins: [f32; 3],
    pub(super) maxs: [f32; 3],
    pub(super) part: u32,
    /// Index among the part's exact boxes (`u32::MAX`: the part's bounding box; test its mesh).
    pub(super) index: u32,
}

impl GridBox {
    /// The squared distance from `p` to the box (0 inside).
    #[inline]
    pub(super) fn distance_squared(&self, p: [f32; 3]) -> f32 {
        let e = |k: usize| (self.mins[k] - p[k]).max(p[k] - self.maxs[k]).max(0.0);
        let (x, y, z) = (e(0), e(1), e(2));
        x * x + y * y + z * z
    }
}

#[derive(Clone, Copy, Debug)]
struct Cell {
    start: u32,
    len: u32,
    /// A lower bound on the squared distance from any point of the cell to any part not listed.
    far_squared: f32,
}

/// A part in the grid: its bounding box (a lower bound of its boxes' distances) and its boxes.
#[derive(Clone, Copy, Debug)]
struct GridPart {
    aabb: GridBox,
    boxes: (u32, u32),
}

/// The parts' boxes in a uniform grid (see the module documentation).
#[derive(Debug)]
pub(super) struct PartGrid {
    origin: [f32; 3],
    inv_size: f32,
    dims: [usize; 3],
    cells: Vec<Cell>,
    /// Parts listed by the cells (indices into `parts`).
    items: Vec<u32>,
    parts: Vec<GridPart>,
    /// Every part's boxes, part by part.
    pub(super) boxes: Vec<GridBox>,
    /// The box around every box (None: no parts).
    all: Option<GridBox>,
}

/// The squared distance between two boxes.
fn box_gap_squared(a_min: [f32; 3], a_max: [f32; 3], b: &GridBox) -> f32 {
    let mut d = 0.0;
    for k in 0..3 {
        let e = (a_min[k] - b.maxs[k]).max(b.mins[k] - a_max[k]).max(0.0);
        d += e * e;
    }
    d
}

impl PartGrid {
    /// The grid of `world`'s parts (the ground left out) with cells of `size` metres listing the
    /// parts within `reach` metres.
    pub(super) fn new(world: &World, size: f32, reach: f32) -> PartGrid {
        let mut boxes = Vec::new();
        let mut parts = Vec::new();
        for p in 0..world.num_parts() {
            let first = boxes.len() as u32;
            match world.shapes().boxes(p) {
                Some(bs) => boxes.extend(bs.iter().enumerate().map(|(i, b)| GridBox {
                    mins: b.mins.to_array(),
                    maxs: b.maxs.to_array(),
                    part: p as u32,
                    index: i as u32,
                })),
                None => {
                    let b = world.shapes().aabb(p);
                    boxes.push(GridBox { mins: b.mins.to_array(), maxs: b.maxs.to_array(), part: p as u32, index: u32::MAX });
                }
            }
            let mine = &boxes[first as usize..];
            let mut aabb = GridBox { mins: [f32::INFINITY; 3], maxs: [f32::NEG_INFINITY; 3], part: p as u32, index: u32::MAX };
            for b in mine {
                for k in 0..3 {
                    aabb.mins[k] = aabb.mins[k].min(b.mins[k]);
                    aabb.maxs[k] = aabb.maxs[k].max(b.maxs[k]);
                }
            }
            if !mine.is_empty() {
                parts.push(GridPart { aabb, boxes: (first, boxes.len() as u32) });
            }
        }
        let size = size.max(1e-3);
        let all = parts.iter().map(|p| p.aabb).reduce(|a, b| GridBox {
            mins: std::array::from_fn(|k| a.mins[k].min(b.mins[k])),
            maxs: std::array::from_fn(|k| a.maxs[k].max(b.maxs[k])),
            part: 0,
            index: 0,
        });
        let Some(all) = all else {
            return PartGrid {
                origin: [0.0; 3],
                inv_size: 1.0 / size,
                dims: [0; 3],
                cells: Vec::new(),
                items: Vec::new(),
                parts,
                boxes,
                all: None,
            };
        };
        let pad = reach + size;
        let origin = all.mins.map(|m| m - pad);
        let extent: [f32; 3] = std::array::from_fn(|k| all.maxs[k] - all.mins[k] + 2.0 * pad);
        let dims = extent.map(|e| ((e / size).ceil() as usize).clamp(1, 512));
        // the grid stays within about 2^27 cells: coarser cells for huge models
        let size = (0..3).map(|k| extent[k] / dims[k] as f32).fold(size, f32::max);
        let n = dims[0] * dims[1] * dims[2];
        let mut lists: Vec<Vec<u32>> = vec![Vec::new(); n];
        let index = |x: f32, k: usize| (((x - origin[k]) / size).floor().max(0.0) as usize).min(dims[k] - 1);
        for (pi, part) in parts.iter().enumerate() {
            let b = &part.aabb;
            let lo: [usize; 3] = std::array::from_fn(|k| index(b.mins[k] - reach, k));
            let hi: [usize; 3] = std::array::from_fn(|k| index(b.maxs[k] + reach, k));
            for i in lo[0]..=hi[0] {
                for j in lo[1]..=hi[1] {
                    for k in lo[2]..=hi[2] {
                        lists[(i * dims[1] + j) * dims[2] + k].push(pi as u32);
                    }
                }
            }
        }
        let mut cells = Vec::with_capacity(n);
        let mut items = Vec::new();
        for i in 0..dims[0] {
            for j in 0..dims[1] {
                for k in 0..dims[2] {
                    let list = &lists[(i * dims[1] + j) * dims[2] + k];
                    let c_min = [origin[0] + size * i as f32, origin[1] + size * j as f32, origin[2] + size * k as f32];
                    let c_max = [c_min[0] + size, c_min[1] + size, c_min[2] + size];
                    let mut far = f32::INFINITY;
                    let mut listed = list.iter().peekable();
                    for (pi, part) in parts.iter().enumerate() {
                        if listed.peek() == Some(&&(pi as u32)) {
                            listed.next();
                            continue;
                        }
                        far = far.min(box_gap_squared(c_min, c_max, &part.aabb));
                    }
                    cells.push(Cell { start: items.len() as u32, len: list.len() as u32, far_squared: far });
                    items.extend_from_slice(list);
                }
            }
        }
        PartGrid { origin, inv_size: 1.0 / size, dims, cells, items, parts, boxes, all: Some(all) }
    }

    /// The index of the cell holding `p` and the cell's centre, `None` outside the grid (no box
    /// within `reach` there).
    #[inline]
    fn cell_index(&self, p: [f32; 3]) -> Option<(usize, [f32; 3])> {
        let mut idx = [0usize; 3];
        let mut centre = [0.0; 3];
        for k in 0..3 {
            let f = (p[k] - self.origin[k]) * self.inv_size;
            // NaN fails both comparisons: outside
            if !(0.0..(self.dims[k] as f32)).contains(&f) {
                return None;
            }
            idx[k] = f as usize;
            centre[k] = self.origin[k] + (idx[k] as f32 + 0.5) / self.inv_size;
        }
        Some(((idx[0] * self.dims[1] + idx[1]) * self.dims[2] + idx[2], centre))
    }

    /// The cell holding `p`, `None` outside the grid (no box within `reach` there).
    #[inline]
    fn cell(&self, p: [f32; 3]) -> Option<&Cell> {
        self.cell_index(p).map(|(i, _)| &self.cells[i])
    }

    /// Cells in the grid (the size of a [`Field`]).
    pub(super) fn num_cells(&self) -> usize {
        self.cells.len()
    }

    /// The parts listed in cell `c` that are in `present` (bits by part index).
    #[inline]
    fn present_parts<'g>(&'g self, c: &Cell, present: &'g [u64]) -> impl Iterator<Item = &'g GridPart> + 'g {
        self.items[c.start as usize..(c.start + c.len) as usize].iter().map(|&pi| &self.parts[pi as usize]).filter(move |part| {
            let q = part.aabb.part;
            present.get((q >> 6) as usize).is_some_and(|w| w >> (q & 63) & 1 == 1)
        })
    }

    /// A lower bound on the squared distance from `p` to the boxes of the parts in `present`
    /// (bits by part index): exact when below `reach`².
    #[inline]
    pub(super) fn distance_squared(&self, p: [f32; 3], present: &[u64]) -> f32 {
        match self.cell(p) {
            Some(c) => {
                let mut d = c.far_squared;
                for part in self.present_parts(c, present) {
                    if part.aabb.distance_squared(p) < d {
                        for b in &self.boxes[part.boxes.0 as usize..part.boxes.1 as usize] {
                            d = d.min(b.distance_squared(p));
                        }
                    }
                }
                d
            }
            None => self.all.as_ref().map_or(f32::INFINITY, |all| all.distance_squared(p)),
        }
    }

    /// Calls `hit` with every box (index and box) of a present part closer to `p` than `radius`
    /// (at most `reach`), until it returns true; whether one did.
    #[inline]
    pub(super) fn any_near(&self, p: [f32; 3], radius: f32, present: &[u64], mut hit: impl FnMut(u32, &GridBox) -> bool) -> bool {
        let Some(c) = self.cell(p) else { return false };
        let r2 = radius * radius;
        self.present_parts(c, present).any(|part| {
            part.aabb.distance_squared(p) < r2
                && (part.boxes.0..part.boxes.1).any(|bi| {
                    let b = &self.boxes[bi as usize];
                    b.distance_squared(p) < r2 && hit(bi, b)
                })
        })
    }
}

/// The distances of one state's parts at the grid's cell centres, filled as they are asked
/// for: a lower bound on the distance from any point `p` of a cell is the centre's distance
/// less `|p − centre|` (distance is 1-Lipschitz), one memory read per point after the first.
#[derive(Debug)]
pub(super) struct Field {
    /// The parts, bits by part index.
    pub(super) present: Vec<u64>,
    /// Per cell, the centre's distance (NaN: not yet asked for); made when first asked.
    values: std::cell::OnceCell<Vec<std::cell::Cell<f32>>>,
}

impl Field {
    /// The field of the parts in `present` (bits by part index).
    pub(super) fn new(present: Vec<u64>) -> Field {
        Field { present, values: std::cell::OnceCell::new() }
    }

    /// A lower bound on the distance from `p` to the boxes of this field's parts.
    #[inline]
    pub(super) fn distance(&self, grid: &PartGrid, p: [f32; 3]) -> f32 {
        let Some((i, c)) = grid.cell_index(p) else {
            return grid.all.as_ref().map_or(f32::INFINITY, |all| all.distance_squared(p).sqrt());
        };
        let values = self.values.get_or_init(|| vec![std::cell::Cell::new(f32::NAN); grid.num_cells()]);
        let mut v = values[i].get();
        if v.is_nan() {
            v = grid.distance_squared(c, &self.present).sqrt();
            values[i].set(v);
        }
        let (x, y, z) = (p[0] - c[0], p[1] - c[1], p[2] - c[2]);
        v - (x * x + y * y + z * z).sqrt()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use asp_geom::fixtures::{assemble, box_part};
    use asp_geom::math::Vec3;
    use asp_geom::{PartSet, WorldConfig};
    use rand::{RngExt, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    #[test]
    fn the_grid_bounds_the_distance_to_the_present_boxes_and_is_exact_nearby() {
        let parts = vec![
            box_part("a", [0.0; 3], [0.4, 0.04, 0.04]),
            box_part("b", [0.0, 0.1, 0.0], [0.04, 0.5, 0.04]),
            box_part("c", [0.2, 0.2, 0.2], [0.3, 0.3, 0.25]),
        ];
        let world = World::new(assemble("grid", parts, asp_geom::math::Axis::Z), &WorldConfig::default()).unwrap();
        let grid = PartGrid::new(&world, 0.03, 0.07);
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        for present in [PartSet::full(3), PartSet::from_indices(3, [0, 2]), PartSet::from_indices(3, [1])] {
            for _ in 0..5000 {
                let p = Vec3::new(rng.random_range(-0.3..0.7), rng.random_range(-0.3..0.8), rng.random_range(-0.3..0.6));
                let exact = present
                    .iter()
                    .map(|q| world.shapes().aabb(q))
                    .map(|b| (p - p.clamp(b.mins, b.maxs)).length_squared())
                    .fold(f32::INFINITY, f32::min);
                let lb = grid.distance_squared(p.to_array(), present.words());
                assert!(lb <= exact + 1e-7, "{p}: bound {lb} above the distance {exact}");
                let field = Field::new(present.words().to_vec());
                assert!(field.distance(&grid, p.to_array()) <= exact.sqrt() + 1e-5);
                if exact < 0.07 * 0.07 {
                    assert!((lb - exact).abs() < 1e-6, "{p}: {lb} vs {exact}");
                    let r = exact.sqrt() + 1e-4;
                    assert!(grid.any_near(p.to_array(), r, present.words(), |_, _| true));
                }
            }
        }
    }
}
