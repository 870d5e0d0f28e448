//! Soma cubes of any size (thesis 4.2, Algorithm 1) and the classic 7-piece cube.
//!
//! A cube of S×S×S cells is filled by growing pieces of up to four face-connected cells from
//! random empty cells. Each piece becomes one closed mesh; a fixed floor slab lies under the cube;
//! every piece carries its cells in `extras.asp.cells` so planners may use exact voxel geometry.

use crate::check::{check_disassembly, DisassemblyCheck, RemovalModel};
use crate::error::{GenError, Result};
use asp_geom::math::{Axis, Vec3};
use asp_geom::{Assembly, Mesh, Part, Units};
use rand::RngExt;
use serde::{Deserialize, Serialize};
use serde_json::json;

/// The largest cube edge accepted (262 144 cells).
pub const MAX_SIZE: usize = 64;

/// The cells of the classic Soma cube in one solved arrangement: layer z, row y, column x.
const CLASSIC: [[&str; 3]; 3] = [["VPL", "PPL", "BBT"], ["VPL", "VBT", "ABT"], ["ZZL", "AZZ", "AAT"]];
/// The classic pieces in the order they appear as parts.
const CLASSIC_LETTERS: [char; 7] = ['V', 'L', 'T', 'Z', 'A', 'B', 'P'];

/// Parameters of random Soma cubes.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SomaParams {
    /// Cells along each edge (S ≥ 2). The thesis uses 5 (≈ 38 pieces) and 6 (≈ 58 pieces).
    pub size: usize,
    /// Edge length of one cell in metres.
    pub cell: f64,
}

impl Default for SomaParams {
    fn default() -> Self {
        SomaParams { size: 5, cell: 0.05 }
    }
}

impl SomaParams {
    /// Checks the ranges: 2 ≤ size ≤ [`MAX_SIZE`], cell a positive length.
    pub fn validate(&self) -> Result<()> {
        if !(2..=MAX_SIZE).contains(&self.size) {
            return Err(GenError::parameter("size", format!("must be 2 to {MAX_SIZE}, got {}", self.size)));
        }
        validate_cell(self.cell)
    }
}

/// Checks a cell edge length: positive, finite, at most 10 m.
pub fn validate_cell(cell: f64) -> Result<()> {
    if !(cell.is_finite() && cell > 0.0 && cell <= 10.0) {
        return Err(GenError::parameter("cell", format!("must be a length in (0, 10] metres, got {cell}")));
    }
    Ok(())
}

/// A cube of S×S×S cells partitioned into pieces.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SomaCube {
    size: usize,
    /// Piece index of every cell, index `x + S (y + S z)`.
    labels: Vec<usize>,
    /// The cells of every piece, in the order they were filled.
    pieces: Vec<Vec<[i32; 3]>>,
    /// Part names of the pieces.
    names: Vec<String>,
}

impl SomaCube {
    /// Grows random pieces of up to four face-connected cells until the cube is full
    /// (Algorithm 1 with the neighbourhood bounds `0 ≤ x' < S`).
    pub fn random(size: usize, rng: &mut impl rand::Rng) -> Result<Self> {
        SomaParams { size, cell: 1.0 }.validate()?;
        let n = size * size * size;
        const EMPTY: usize = usize::MAX;
        let mut labels = vec![EMPTY; n];
        // empty cells, with each cell's position in that list for O(1) removal
        let mut empty: Vec<usize> = (0..n).collect();
        let mut slot: Vec<usize> = (0..n).collect();
        let mut pieces = Vec::new();
        while !empty.is_empty() {
            let p = pieces.len();
            let start = empty[rng.random_range(0..empty.len())];
            let mut frontier = vec![start];
            let mut cells = Vec::with_capacity(4);
            for _ in 0..4 {
                if frontier.is_empty() {
                    break;
                }
                let c = frontier.swap_remove(rng.random_range(0..frontier.len()));
                labels[c] = p;
                let last = *empty.last().unwrap_or(&c);
                empty.swap_remove(slot[c]);
                slot[last] = slot[c];
                let xyz = coords(c, size);
                cells.push(xyz);
                for nb in face_neighbours(xyz, size) {
                    let k = index(nb, size);
                    if labels[k] == EMPTY && !frontier.contains(&k) {
                        frontier.push(k);
                    }
                }
            }
            pieces.push(cells);
        }
        let names = (0..pieces.len()).map(|i| format!("piece_{i:02}")).collect();
        Ok(SomaCube { size, labels, pieces, names })
    }

    /// The classic 3×3×3 Soma cube of Piet Hein in one of its solved arrangements: the V piece
    /// of three cells and the L, T, Z, A, B and P pieces of four cells, named `piece_V` etc.
    pub fn classic() -> Self {
        let mut labels = vec![0; 27];
        for (z, layer) in CLASSIC.iter().enumerate() {
            for (y, row) in layer.iter().enumerate() {
                for (x, letter) in row.chars().enumerate() {
                    let p = CLASSIC_LETTERS.iter().position(|&l| l == letter).unwrap_or(0);
                    labels[index([x as i32, y as i32, z as i32], 3)] = p;
                }
            }
        }
        let mut cube = Self::from_labels_unchecked(3, labels);
        cube.names = CLASSIC_LETTERS.iter().map(|l| format!("piece_{l}")).collect();
        cube
    }

    /// Every solved arrangement of the classic Soma cube up to the cube's 48 symmetries
    /// (rotations and reflections; a reflection turns each screw piece into the other):
    /// the 240 distinct solutions of Piet Hein's puzzle, found by exact cover of the 27 cells
    /// (all 11,520 placements of the seven labelled pieces, each solution's class kept once).
    /// Each is given by the representative whose labels (in [`SomaCube::classic`]'s piece
    /// order, cell index `x + 3 (y + 3 z)`) come first lexicographically, in that order.
    pub fn classic_solutions() -> Vec<SomaCube> {
        let mut canonical: Vec<[u8; 27]> = classic_exact_covers().iter().map(canonical_labels).collect();
        canonical.sort_unstable();
        canonical.dedup();
        let names: Vec<String> = CLASSIC_LETTERS.iter().map(|l| format!("piece_{l}")).collect();
        canonical
            .into_iter()
            .map(|labels| {
                let mut cube = Self::from_labels_unchecked(3, labels.iter().map(|&l| l as usize).collect());
                cube.names = names.clone();
                cube
            })
            .collect()
    }

    /// A cube from the piece index of every cell (index `x + S (y + S z)`), e.g. a puzzle
    /// designed by hand. Piece indices must run over `0..n` and every piece must be
    /// face-connected; pieces may have any number of cells.
    pub fn from_labels(size: usize, labels: Vec<usize>) -> Result<Self> {
        SomaParams { size, cell: 1.0 }.validate()?;
        let bad = |reason: String| GenError::parameter("labels", reason);
        if labels.len() != size * size * size {
            return Err(bad(format!("expected {} cells, got {}", size * size * size, labels.len())));
        }
        let n = labels.iter().max().map_or(0, |m| m + 1);
        if n > labels.len() {
            return Err(bad(format!("piece index {} but only {} cells", n - 1, labels.len())));
        }
        let cube = Self::from_labels_unchecked(size, labels);
        if let Some(p) = (0..n).find(|&p| cube.pieces[p].is_empty()) {
            return Err(bad(format!("piece {p} has no cells (indices must run over 0..{n})")));
        }
        if let Some(p) = (0..n).find(|&p| !cube.is_face_connected(p)) {
            return Err(bad(format!("piece {p} is not face-connected")));
        }
        Ok(cube)
    }

    fn from_labels_unchecked(size: usize, labels: Vec<usize>) -> Self {
        let n = labels.iter().max().map_or(0, |m| m + 1);
        let mut pieces = vec![Vec::new(); n];
        for (i, &p) in labels.iter().enumerate() {
            pieces[p].push(coords(i, size));
        }
        let names = (0..n).map(|i| format!("piece_{i:02}")).collect();
        SomaCube { size, labels, pieces, names }
    }

    /// Whether the cells of piece `p` form one face-connected group.
    pub fn is_face_connected(&self, p: usize) -> bool {
        let Some(cells) = self.pieces.get(p) else { return false };
        let Some(&first) = cells.first() else { return false };
        let mut seen = vec![first];
        let mut stack = vec![first];
        while let Some(c) = stack.pop() {
            for nb in face_neighbours(c, self.size) {
                if self.labels[index(nb, self.size)] == p && !seen.contains(&nb) {
                    seen.push(nb);
                    stack.push(nb);
                }
            }
        }
        seen.len() == cells.len()
    }

    /// Cells along each edge.
    pub fn size(&self) -> usize {
        self.size
    }

    /// The cells of every piece (integer coordinates in `0..S`).
    pub fn pieces(&self) -> &[Vec<[i32; 3]>] {
        &self.pieces
    }

    /// The piece that occupies cell `xyz`, or None outside the cube.
    pub fn piece_at(&self, xyz: [i32; 3]) -> Option<usize> {
        let s = self.size as i32;
        xyz.iter().all(|&c| (0..s).contains(&c)).then(|| self.labels[index(xyz, self.size)])
    }

    /// How many pieces have 1, 2, 3 and 4 cells.
    pub fn piece_sizes(&self) -> [usize; 4] {
        let mut counts = [0; 4];
        for p in &self.pieces {
            if let Some(c) = counts.get_mut(p.len().wrapping_sub(1)) {
                *c += 1;
            }
        }
        counts
    }

    /// The cube as an assembly (metres, +Z up): one part per piece, cell `(x, y, z)` occupying
    /// `[x, x+1] × [y, y+1] × [z, z+1]` times `cell`, then a fixed floor slab under the cube.
    pub fn to_assembly(&self, cell: f64, source: &str) -> Assembly {
        let c = cell as f32;
        let mut parts: Vec<Part> = self
            .pieces
            .iter()
            .zip(&self.names)
            .map(|(cells, name)| {
                Part::new(
                    name.clone(),
                    Mesh::from_voxels(cells, Vec3::splat(c), Vec3::ZERO),
                    false,
                    json!({
                        "kind": "soma_piece",
                        "cube_size": self.size,
                        "cell_size": cell,
                        "origin": [0.0, 0.0, 0.0],
                        "cells": cells,
                    }),
                )
            })
            .collect();
        let edge = self.size as f32 * c;
        parts.push(Part::new(
            "floor",
            Mesh::cuboid(Vec3::new(-c, -c, -0.5 * c), Vec3::new(edge + c, edge + c, 0.0)),
            true,
            json!({"kind": "floor"}),
        ));
        Assembly { parts, units: Units::metres(), up: Axis::Z, source: source.into(), warnings: Vec::new() }
    }

    /// Straight-line disassembly of the pieces along ±axes on the voxel grid, with the floor
    /// (the last part, as in [`SomaCube::to_assembly`]) blocking every downward motion.
    pub fn check_disassembly(&self) -> DisassemblyCheck {
        check_disassembly(&VoxelModel::new(self))
    }
}

/// The cube as a [`RemovalModel`]: pieces `0..n`, the floor `n`.
struct VoxelModel<'a> {
    cube: &'a SomaCube,
    contacts: Vec<Vec<usize>>,
}

impl<'a> VoxelModel<'a> {
    fn new(cube: &'a SomaCube) -> Self {
        let n = cube.pieces.len();
        let mut contacts = vec![Vec::new(); n + 1];
        for (p, cells) in cube.pieces.iter().enumerate() {
            for &c in cells {
                let mut touch = |q: usize| {
                    if q != p && !contacts[p].contains(&q) {
                        contacts[p].push(q);
                        contacts[q].push(p);
                    }
                };
                if c[2] == 0 {
                    touch(n);
                }
                for nb in face_neighbours(c, cube.size) {
                    touch(cube.labels[index(nb, cube.size)]);
                }
            }
        }
        VoxelModel { cube, contacts }
    }

    fn floor(&self) -> usize {
        self.cube.pieces.len()
    }
}

impl RemovalModel for VoxelModel<'_> {
    fn num_parts(&self) -> usize {
        self.cube.pieces.len() + 1
    }

    fn is_fixed(&self, i: usize) -> bool {
        i == self.floor()
    }

    /// The pieces with a cell on the ray of any cell of piece `i`; the floor spans the cube's
    /// footprint, so it lies on every −z ray.
    fn blockers(&self, i: usize, axis: Axis) -> Vec<usize> {
        let mut out = Vec::new();
        if i == self.floor() {
            return out;
        }
        if axis.index == 2 && axis.negative {
            out.push(self.floor());
        }
        let step = if axis.negative { -1 } else { 1 };
        for &start in &self.cube.pieces[i] {
            let mut c = start;
            c[axis.index as usize] += step;
            while let Some(q) = self.cube.piece_at(c) {
                if q != i && !out.contains(&q) {
                    out.push(q);
                }
                c[axis.index as usize] += step;
            }
        }
        out
    }

    fn contacts(&self, i: usize) -> &[usize] {
        &self.contacts[i]
    }

    fn bottom(&self, i: usize) -> f64 {
        self.cube.pieces.get(i).map_or(-1.0, |cells| cells.iter().map(|c| c[2]).min().unwrap_or(0) as f64)
    }
}

/// The 48 symmetries of the cube as signed axis permutations: `(perm, signs)` maps cell `c`
/// to `c'[k] = signs[k] * (c[perm[k]] - 1) + 1` (3×3×3, centred on cell 1); `proper` is false
/// for the reflections.
fn cube_symmetries() -> Vec<([usize; 3], [i32; 3], bool)> {
    const PERMS: [([usize; 3], bool); 6] =
        [([0, 1, 2], true), ([1, 2, 0], true), ([2, 0, 1], true), ([0, 2, 1], false), ([2, 1, 0], false), ([1, 0, 2], false)];
    let mut out = Vec::with_capacity(48);
    for (perm, even) in PERMS {
        for bits in 0..8u32 {
            let signs = [0, 1, 2].map(|k| if bits >> k & 1 == 1 { -1 } else { 1 });
            let negatives = bits.count_ones() % 2 == 1;
            out.push((perm, signs, even != negatives));
        }
    }
    out
}

/// Every solution of the classic cube as labels (piece index per cell, [`CLASSIC_LETTERS`]
/// order): exact cover of the 27 cells by one placement of each piece.
fn classic_exact_covers() -> Vec<[u8; 27]> {
    let classic = SomaCube::classic();
    let symmetries: Vec<_> = cube_symmetries().into_iter().filter(|s| s.2).collect();
    // every placement of every piece as a 27-bit mask, listed under its lowest cell
    let mut placements: Vec<Vec<Vec<u32>>> = vec![vec![Vec::new(); 27]; 7];
    for (p, cells) in classic.pieces.iter().enumerate() {
        let mut seen: Vec<u32> = Vec::new();
        for (perm, signs, _) in &symmetries {
            let turned: Vec<[i32; 3]> = cells.iter().map(|c| std::array::from_fn(|k| signs[k] * c[perm[k]])).collect();
            let lo: [i32; 3] = std::array::from_fn(|k| turned.iter().map(|c| c[k]).min().unwrap_or(0));
            for dz in 0..3 {
                for dy in 0..3 {
                    for dx in 0..3 {
                        let shift = [dx, dy, dz];
                        let moved: Vec<[i32; 3]> = turned.iter().map(|c| std::array::from_fn(|k| c[k] - lo[k] + shift[k])).collect();
                        if moved.iter().all(|c| c.iter().all(|&x| (0..3).contains(&x))) {
                            let mask = moved.iter().fold(0u32, |m, &c| m | 1 << index(c, 3));
                            if !seen.contains(&mask) {
                                seen.push(mask);
                                placements[p][mask.trailing_zeros() as usize].push(mask);
                            }
                        }
                    }
                }
            }
        }
    }
    fn cover(filled: u32, used: u8, chosen: &mut Vec<(usize, u32)>, placements: &[Vec<Vec<u32>>], out: &mut Vec<[u8; 27]>) {
        if filled == (1 << 27) - 1 {
            let mut labels = [0u8; 27];
            for &(p, mask) in chosen.iter() {
                for (i, l) in labels.iter_mut().enumerate() {
                    if mask >> i & 1 == 1 {
                        *l = p as u8;
                    }
                }
            }
            out.push(labels);
            return;
        }
        let cell = (!filled).trailing_zeros() as usize;
        for (p, by_cell) in placements.iter().enumerate() {
            if used >> p & 1 == 1 {
                continue;
            }
            for &mask in &by_cell[cell] {
                if mask & filled == 0 {
                    chosen.push((p, mask));
                    cover(filled | mask, used | 1 << p, chosen, placements, out);
                    chosen.pop();
                }
            }
        }
    }
    let mut out = Vec::new();
    cover(0, 0, &mut Vec::new(), &placements, &mut out);
    out
}

/// The least image of a solution's labels under the cube's 48 symmetries (a reflection turns
/// each piece into its mirror image: [`mirror_pieces`]).
fn canonical_labels(labels: &[u8; 27]) -> [u8; 27] {
    let mirror = mirror_pieces();
    cube_symmetries()
        .into_iter()
        .map(|(perm, signs, proper)| {
            let mut image = [0u8; 27];
            for (i, &l) in labels.iter().enumerate() {
                let c = coords(i, 3);
                let to: [i32; 3] = std::array::from_fn(|k| signs[k] * (c[perm[k]] - 1) + 1);
                image[index(to, 3)] = if proper { l } else { mirror[l as usize] };
            }
            image
        })
        .min()
        .unwrap_or(*labels)
}

/// For each classic piece, the piece its mirror image is (up to a rotation): itself for the
/// five achiral pieces, the other for the two screws.
fn mirror_pieces() -> [u8; 7] {
    let pieces = SomaCube::classic().pieces;
    let shape = |cells: &[[i32; 3]]| -> Vec<[i32; 3]> {
        let lo: [i32; 3] = std::array::from_fn(|k| cells.iter().map(|c| c[k]).min().unwrap_or(0));
        let mut v: Vec<[i32; 3]> = cells.iter().map(|c| std::array::from_fn(|k| c[k] - lo[k])).collect();
        v.sort_unstable();
        v
    };
    let turned = |cells: &[[i32; 3]], perm: [usize; 3], signs: [i32; 3]| -> Vec<[i32; 3]> {
        shape(&cells.iter().map(|c| std::array::from_fn(|k| signs[k] * c[perm[k]])).collect::<Vec<_>>())
    };
    let rotations: Vec<_> = cube_symmetries().into_iter().filter(|s| s.2).collect();
    std::array::from_fn(|p| {
        let mirrored = turned(&pieces[p], [0, 1, 2], [-1, 1, 1]);
        (0..pieces.len()).find(|&q| rotations.iter().any(|&(perm, signs, _)| turned(&pieces[q], perm, signs) == mirrored)).unwrap_or(p)
            as u8
    })
}

fn index(c: [i32; 3], size: usize) -> usize {
    c[0] as usize + size * (c[1] as usize + size * c[2] as usize)
}

fn coords(i: usize, size: usize) -> [i32; 3] {
    [(i % size) as i32, (i / size % size) as i32, (i / (size * size)) as i32]
}

/// The face neighbours of `c` inside the cube (`0 ≤ x' < S`, the thesis' bound corrected).
fn face_neighbours(c: [i32; 3], size: usize) -> impl Iterator<Item = [i32; 3]> {
    let s = size as i32;
    (0..3).flat_map(move |axis| {
        [-1, 1].into_iter().filter_map(move |d| {
            let mut n = c;
            n[axis] += d;
            (0..s).contains(&n[axis]).then_some(n)
        })
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;

    #[test]
    fn the_classic_cube_has_240_solutions_up_to_symmetry() {
        // 11,520 labelled solutions = 240 classes of 48 (no solution is symmetric)
        assert_eq!(classic_exact_covers().len(), 11_520);
        let all = SomaCube::classic_solutions();
        assert_eq!(all.len(), 240);
        let classes: std::collections::HashSet<[u8; 27]> =
            all.iter().map(|c| canonical_labels(&std::array::from_fn(|i| c.labels[i] as u8))).collect();
        assert_eq!(classes.len(), 240, "pairwise non-equivalent");
        let classic = SomaCube::classic();
        assert!(classes.contains(&canonical_labels(&std::array::from_fn(|i| classic.labels[i] as u8))), "the classic arrangement is one");
        for cube in &all {
            assert_eq!(cube.piece_sizes(), [0, 0, 1, 6]);
            assert!((0..7).all(|p| cube.is_face_connected(p)));
            // each piece is the classic piece turned (its cells up to a proper rotation)
            assert_eq!(cube.names, classic.names);
        }
    }

    #[test]
    fn a_reflection_swaps_the_mirror_pieces() {
        // the two screws (B and P in this layout) are each other's mirror images
        let letter = |l: char| CLASSIC_LETTERS.iter().position(|&x| x == l).unwrap() as u8;
        let mirror = mirror_pieces();
        for (p, &l) in CLASSIC_LETTERS.iter().enumerate() {
            let expected = match l {
                'B' => letter('P'),
                'P' => letter('B'),
                _ => p as u8,
            };
            assert_eq!(mirror[p], expected, "piece {l}");
        }
        let classic = SomaCube::classic();
        let labels: [u8; 27] = std::array::from_fn(|i| classic.labels[i] as u8);
        // mirrored along x (the screws swapped): the same class
        let mut mirrored = [0u8; 27];
        for (i, &l) in labels.iter().enumerate() {
            let c = coords(i, 3);
            mirrored[index([2 - c[0], c[1], c[2]], 3)] = mirror[l as usize];
        }
        assert_eq!(canonical_labels(&mirrored), canonical_labels(&labels));
        assert_eq!(cube_symmetries().iter().filter(|s| s.2).count(), 24);
    }

    #[test]
    fn neighbours_include_the_zero_boundary() {
        // the printed pseudo-code's `0 < x'` would drop cell 0 and leave it for a new piece
        let n: Vec<_> = face_neighbours([1, 0, 0], 2).collect();
        assert!(n.contains(&[0, 0, 0]));
        assert_eq!(n.len(), 3);
    }

    #[test]
    fn labels_match_pieces() {
        let cube = SomaCube::random(4, &mut ChaCha8Rng::seed_from_u64(3)).unwrap();
        for (p, cells) in cube.pieces().iter().enumerate() {
            for &c in cells {
                assert_eq!(cube.piece_at(c), Some(p));
            }
        }
        assert_eq!(cube.piece_at([4, 0, 0]), None);
        assert_eq!(cube.piece_at([-1, 0, 0]), None);
    }

    #[test]
    fn rejects_bad_sizes() {
        let mut rng = ChaCha8Rng::seed_from_u64(0);
        assert!(matches!(SomaCube::random(1, &mut rng), Err(GenError::Parameter { name: "size", .. })));
        assert!(SomaCube::random(MAX_SIZE + 1, &mut rng).is_err());
        assert!(validate_cell(0.0).is_err() && validate_cell(f64::NAN).is_err());
    }

    #[test]
    fn from_labels_rejects_gaps_and_split_pieces() {
        assert!(SomaCube::from_labels(2, vec![0; 7]).is_err());
        assert!(SomaCube::from_labels(2, vec![0, 0, 0, 0, 0, 0, 0, 2]).is_err());
        // piece 1 in two opposite corners
        assert!(SomaCube::from_labels(2, vec![1, 0, 0, 0, 0, 0, 0, 1]).is_err());
        assert!(SomaCube::from_labels(2, vec![1, 0, 0, 0, 0, 0, 0, 0]).is_ok());
    }

    #[test]
    fn an_enclosed_piece_is_reported_stuck() {
        // piece 1 hooks under and around piece 0: neither can leave first along any axis
        let layers = [["000", "011", "000"], ["110", "010", "000"], ["000", "000", "000"]];
        let labels: Vec<usize> = layers.iter().flat_map(|l| l.iter().flat_map(|r| r.bytes().map(|b| (b - b'0') as usize))).collect();
        let cube = SomaCube::from_labels(3, labels).unwrap();
        let check = cube.check_disassembly();
        assert!(!check.straight_line);
        assert_eq!(check.stuck, vec![0, 1]);
        assert!(check.order.is_empty() && !check.stable_order);
    }

    #[test]
    fn the_floor_blocks_downward_removal() {
        let cube = SomaCube::from_labels(2, vec![0, 0, 0, 0, 1, 1, 1, 1]).unwrap();
        let model = VoxelModel::new(&cube);
        let down = Axis { index: 2, negative: true };
        assert_eq!(model.blockers(0, down), vec![2], "the floor");
        assert_eq!(model.blockers(0, Axis::Z), vec![1], "piece 1 lies on top of piece 0");
        assert_eq!(model.blockers(1, Axis::Z), Vec::<usize>::new());
        assert_eq!(model.blockers(1, down), vec![2, 0]);
        assert!(model.blockers(0, Axis { index: 0, negative: false }).is_empty(), "sliding out sideways");
        assert_eq!(model.contacts(2), &[0]);
    }
}
