//! Axis-aligned boxes in metres (f64), the building blocks of profiles and connectors, and the
//! mesh of a union of cells of a rectilinear grid.

use asp_geom::math::Vec3;
use asp_geom::Mesh;
use serde::{Deserialize, Serialize};

/// An axis-aligned box, world frame, metres.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Cuboid {
    /// The lower corner.
    pub mins: [f64; 3],
    /// The upper corner.
    pub maxs: [f64; 3],
}

impl Cuboid {
    /// The box between two corners.
    pub fn new(mins: [f64; 3], maxs: [f64; 3]) -> Self {
        Cuboid { mins, maxs }
    }

    /// Overlap length of the two boxes along `axis` (negative when apart).
    pub fn overlap_along(&self, other: &Cuboid, axis: usize) -> f64 {
        self.maxs[axis].min(other.maxs[axis]) - self.mins[axis].max(other.mins[axis])
    }

    /// How deep the boxes interpenetrate: the smallest overlap length over the three axes
    /// (zero or negative when they only touch or are apart).
    pub fn penetration(&self, other: &Cuboid) -> f64 {
        (0..3).map(|a| self.overlap_along(other, a)).fold(f64::INFINITY, f64::min)
    }

    /// Whether the boxes share volume deeper than `tol` along every axis.
    pub fn overlaps(&self, other: &Cuboid, tol: f64) -> bool {
        self.penetration(other) > tol
    }

    /// Whether the boxes touch with a face patch of positive area: within `tol` along one axis,
    /// overlapping by more than `tol` along the other two.
    pub fn touches(&self, other: &Cuboid, tol: f64) -> bool {
        let o = [0, 1, 2].map(|a| self.overlap_along(other, a));
        (0..3).any(|a| o[a].abs() <= tol && (0..3).filter(|&b| b != a).all(|b| o[b] > tol))
    }

    /// Volume.
    pub fn volume(&self) -> f64 {
        (0..3).map(|a| self.maxs[a] - self.mins[a]).product()
    }

    /// Whether moving this box along `axis` (towards `negative` or positive infinity) would
    /// push it into `other` deeper than `tol`.
    pub fn sweep_hits(&self, other: &Cuboid, axis: usize, negative: bool, tol: f64) -> bool {
        let ahead = if negative { other.mins[axis] < self.maxs[axis] - tol } else { other.maxs[axis] > self.mins[axis] + tol };
        ahead && (0..3).filter(|&b| b != axis).all(|b| self.overlap_along(other, b) > tol)
    }

    /// The box as a closed, outward-wound mesh.
    pub fn mesh(&self) -> Mesh {
        Mesh::cuboid(vec3(self.mins), vec3(self.maxs))
    }
}

/// The closed surface of a union of cells of a rectilinear grid: cell `[i, j, k]` spans
/// `[lines[0][i], lines[0][i+1]] × [lines[1][j], lines[1][j+1]] × [lines[2][k], lines[2][k+1]]`.
/// Built by [`Mesh::from_voxels`] on unit cells, then moved onto the grid lines; the map is
/// increasing on every axis, so closedness and winding carry over. Returns the mesh and the
/// cells as boxes.
pub fn grid_union(lines: [&[f64]; 3], cells: &[[i32; 3]]) -> (Mesh, Vec<Cuboid>) {
    let mut mesh = Mesh::from_voxels(cells, Vec3::ONE, Vec3::ZERO);
    for v in &mut mesh.vertices {
        for a in 0..3 {
            v[a] = lines[a][v[a].round() as usize] as f32;
        }
    }
    let boxes = cells
        .iter()
        .map(|c| {
            let i = c.map(|k| k as usize);
            Cuboid::new([0, 1, 2].map(|a| lines[a][i[a]]), [0, 1, 2].map(|a| lines[a][i[a] + 1]))
        })
        .collect();
    (mesh, boxes)
}

/// The closed surface of a union of boxes that touch but do not overlap (a profile and the
/// connectors it carries): [`grid_union`] on the grid of all their faces (coordinates rounded to
/// the nanometre, so faces computed two ways meet), keeping the cells whose centre lies in a box.
pub fn box_union(boxes: &[Cuboid]) -> Mesh {
    let round = |v: f64| (v * 1e9).round() / 1e9;
    let lines: [Vec<f64>; 3] = [0, 1, 2].map(|a| {
        let mut l: Vec<f64> = boxes.iter().flat_map(|b| [round(b.mins[a]), round(b.maxs[a])]).collect();
        l.sort_by(f64::total_cmp);
        l.dedup();
        l
    });
    let mut cells = Vec::new();
    for i in 0..lines[0].len().saturating_sub(1) {
        for j in 0..lines[1].len().saturating_sub(1) {
            for k in 0..lines[2].len().saturating_sub(1) {
                let idx = [i, j, k];
                let centre = [0, 1, 2].map(|a| 0.5 * (lines[a][idx[a]] + lines[a][idx[a] + 1]));
                let inside = boxes.iter().any(|b| (0..3).all(|a| round(b.mins[a]) < centre[a] && centre[a] < round(b.maxs[a])));
                if inside {
                    cells.push([i as i32, j as i32, k as i32]);
                }
            }
        }
    }
    grid_union([&lines[0], &lines[1], &lines[2]], &cells).0
}

fn vec3(v: [f64; 3]) -> Vec3 {
    Vec3::new(v[0] as f32, v[1] as f32, v[2] as f32)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn touching_and_overlapping() {
        let a = Cuboid::new([0.0; 3], [1.0; 3]);
        let b = Cuboid::new([1.0, 0.0, 0.0], [2.0, 1.0, 1.0]);
        let edge = Cuboid::new([1.0, 1.0, 0.0], [2.0, 2.0, 1.0]);
        assert!(a.touches(&b, 1e-9) && !a.overlaps(&b, 1e-9));
        assert!(!a.touches(&edge, 1e-9), "an edge contact has no area");
        let c = Cuboid::new([0.5, 0.5, 0.5], [2.0, 2.0, 2.0]);
        assert!(a.overlaps(&c, 1e-9) && (a.penetration(&c) - 0.5).abs() < 1e-12);
    }

    #[test]
    fn sweeps_ignore_sliding_and_things_behind() {
        let a = Cuboid::new([0.0; 3], [1.0; 3]);
        let above = Cuboid::new([0.2, 0.2, 3.0], [0.8, 0.8, 4.0]);
        let beside = Cuboid::new([1.0, 0.0, 0.0], [2.0, 1.0, 5.0]);
        assert!(a.sweep_hits(&above, 2, false, 1e-9));
        assert!(!a.sweep_hits(&above, 2, true, 1e-9));
        assert!(!a.sweep_hits(&beside, 2, false, 1e-9), "sliding along a shared face");
        assert!(a.sweep_hits(&beside, 0, false, 1e-9));
    }

    #[test]
    fn grid_union_is_closed_with_the_boxes_volume() {
        // an L of three cells on an uneven grid
        let (xs, ys, zs) = ([0.0, 0.1, 0.5], [0.0, 0.3, 0.4], [1.0, 1.2]);
        let cells = [[0, 0, 0], [1, 0, 0], [0, 1, 0]];
        let (mesh, boxes) = grid_union([&xs, &ys, &zs], &cells);
        assert!(mesh.topology().is_closed_manifold(), "{:?}", mesh.topology());
        let volume: f64 = boxes.iter().map(Cuboid::volume).sum();
        assert!((mesh.signed_volume() - volume).abs() < 1e-6, "{} vs {volume}", mesh.signed_volume());
        assert!((volume - (0.1 * 0.3 + 0.4 * 0.3 + 0.1 * 0.1) * 0.2).abs() < 1e-12);
    }
}
