//! Exact geometry for parts that are unions of axis-aligned boxes: voxel parts (Soma cubes),
//! aluminium profiles and their connectors, and any part whose mesh is a single box.
//!
//! Generators know their parts' exact boxes and store them in the node's `extras.asp`:
//! `cells` / `voxels` (integer grid cells) or `boxes` (`[min x, min y, min z, max x, max y, max z]`
//! each). Loading may scale the mesh (`--unit`), so the boxes are fitted to the part's mesh —
//! per axis, their union's bounds onto the mesh's bounds — and accepted only when they describe
//! the mesh: the same volume, and every mesh vertex on a box. A box-box test is then exact
//! interval arithmetic: touching faces are exactly in contact and sliding along them is exactly
//! free, with none of the thresholds of a triangle-mesh query.
//!
//! The box sweeps live here and nowhere else: [`sweep_overlap`] (when two boxes overlap along a
//! translation, the broad phase of every pair test) and [`first_overlap`] (when a box first
//! overlaps another deeper than a tolerance, the exact test of box parts).

use crate::assembly::Part;
use crate::math::{Aabb, Vec3};
use crate::mesh::Mesh;

/// How a part's geometry is tested: the one classification the collision world
/// ([`crate::World`]) and the distance maps ([`crate::distmap::DistanceMaps`]) share.
#[derive(Clone, Debug, PartialEq)]
pub enum PartShape {
    /// Voxels (`extras.asp.cells`) fitted to the mesh: distinct cells, sorted, of the grid
    /// `world = origin + cell * grid`.
    Voxels {
        /// The distinct cells, sorted.
        cells: Vec<[i32; 3]>,
        /// The world position of grid point (0, 0, 0).
        origin: Vec3,
        /// The size of one cell per axis.
        cell: Vec3,
    },
    /// A union of axis-aligned boxes in world coordinates: `extras.asp.boxes` fitted to the
    /// mesh, or the mesh itself being one box.
    Boxes(Vec<Aabb>),
    /// A general triangle mesh.
    Mesh,
}

impl PartShape {
    /// Classifies `part`: its voxels, else its listed boxes, else its mesh as one box, else a
    /// mesh. Extras that do not describe the mesh are not used: the mesh decides (a single box
    /// or a mesh), and the returned warning names the part and the extras. With `exact` false
    /// every part is a mesh (the setting `WorldConfig::exact_boxes`).
    pub fn classify(part: &Part, exact: bool) -> (PartShape, Option<String>) {
        if !exact {
            return (PartShape::Mesh, None);
        }
        let mut warning = None;
        if let Some(cells) = &part.meta.cells {
            let unique = distinct(cells);
            match fit(&unit_boxes(&unique), &part.mesh) {
                Some((_, cell, origin)) => return (PartShape::Voxels { cells: unique, origin, cell }, None),
                None => {
                    warning =
                        Some(format!("part '{}': its voxels (extras.asp.cells) do not match its mesh; its tests use the mesh", part.name))
                }
            }
        } else if let Some(boxes) = &part.meta.boxes {
            match fit_boxes(boxes, &part.mesh) {
                Some(fitted) => return (PartShape::Boxes(fitted), None),
                None => {
                    warning =
                        Some(format!("part '{}': its boxes (extras.asp.boxes) do not match its mesh; its tests use the mesh", part.name))
                }
            }
        }
        let shape = single_box(&part.mesh).map_or(PartShape::Mesh, |b| PartShape::Boxes(vec![b]));
        (shape, warning)
    }

    /// The part's boxes in world coordinates (`None` for a mesh).
    pub fn boxes(&self) -> Option<Vec<Aabb>> {
        match self {
            PartShape::Voxels { cells, origin, cell } => {
                Some(unit_boxes(cells).iter().map(|b| Aabb::new(b.mins * *cell + *origin, b.maxs * *cell + *origin)).collect())
            }
            PartShape::Boxes(boxes) => Some(boxes.clone()),
            PartShape::Mesh => None,
        }
    }
}

/// The boxes of a part in world coordinates, when [`PartShape::classify`] finds it a union of
/// boxes; `Err` names the extras that do not describe the mesh.
pub fn part_boxes(part: &Part) -> Result<Option<Vec<Aabb>>, String> {
    match PartShape::classify(part, true) {
        (_, Some(warning)) => Err(warning),
        (shape, None) => Ok(shape.boxes()),
    }
}

/// Fits the voxel grid of a part to its mesh: the integer bounds of the cells span the mesh's
/// box. Returns (origin, cell size) or `None` when the cells do not describe the mesh.
pub fn fit_voxels(cells: &[[i32; 3]], mesh: &Mesh) -> Option<(Vec3, Vec3)> {
    fit(&unit_boxes(cells), mesh).map(|(_, scale, offset)| (offset, scale))
}

/// Fits listed boxes to a part's mesh (per axis, the union's bounds onto the mesh's bounds) and
/// returns them when they describe the mesh.
pub fn fit_boxes(boxes: &[Aabb], mesh: &Mesh) -> Option<Vec<Aabb>> {
    fit(boxes, mesh).map(|(fitted, _, _)| fitted)
}

/// The distinct cells, sorted.
fn distinct(cells: &[[i32; 3]]) -> Vec<[i32; 3]> {
    let mut unique: Vec<[i32; 3]> = cells.to_vec();
    unique.sort_unstable();
    unique.dedup();
    unique
}

/// Distinct cells as unit boxes of the grid.
fn unit_boxes(cells: &[[i32; 3]]) -> Vec<Aabb> {
    distinct(cells)
        .iter()
        .map(|c| {
            let lo = Vec3::new(c[0] as f32, c[1] as f32, c[2] as f32);
            Aabb::new(lo, lo + Vec3::ONE)
        })
        .collect()
}

/// The boxes mapped per axis (scale, offset) so that their union's bounds are the mesh's
/// bounds, with that scale and offset, when the mapped boxes describe the mesh.
fn fit(boxes: &[Aabb], mesh: &Mesh) -> Option<(Vec<Aabb>, Vec3, Vec3)> {
    let target = mesh.aabb()?;
    let (lo, hi) = boxes.iter().fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), b| (lo.min(b.mins), hi.max(b.maxs)));
    let scale = (target.maxs - target.mins) / (hi - lo);
    if !(scale.is_finite() && scale.min_element() > 0.0) {
        return None;
    }
    let offset = target.mins - lo * scale;
    let fitted: Vec<Aabb> = boxes.iter().map(|b| Aabb::new(b.mins * scale + offset, b.maxs * scale + offset)).collect();
    describes(&fitted, mesh).then_some((fitted, scale, offset))
}

/// Whether disjoint-interior `boxes` describe the closed mesh: the same volume (to 0.1 %), and
/// every vertex of the mesh on or in a box (a rotated or different shape fails one of them).
fn describes(boxes: &[Aabb], mesh: &Mesh) -> bool {
    let Some(bounds) = mesh.aabb() else { return false };
    let eps = 1e-5 * (bounds.maxs - bounds.mins).max_element();
    let volume: f64 = boxes.iter().map(|b| (b.maxs - b.mins).as_dvec3().element_product()).sum();
    let within = |v: &Vec3| boxes.iter().any(|b| (0..3).all(|k| v[k] >= b.mins[k] - eps && v[k] <= b.maxs[k] + eps));
    (mesh.signed_volume().abs() - volume).abs() <= 1e-3 * volume && mesh.vertices.iter().all(within)
}

/// Whether the mesh is exactly one axis-aligned box (its vertices are box corners, its volume
/// the box's volume).
pub fn single_box(mesh: &Mesh) -> Option<Aabb> {
    let b = mesh.aabb()?;
    let ext = b.maxs - b.mins;
    let eps = 1e-5 * ext.max_element().max(f32::MIN_POSITIVE);
    let on = |a: f32, lo: f32, hi: f32| (a - lo).abs() <= eps || (a - hi).abs() <= eps;
    let corners = mesh.vertices.iter().all(|v| on(v.x, b.mins.x, b.maxs.x) && on(v.y, b.mins.y, b.maxs.y) && on(v.z, b.mins.z, b.maxs.z));
    let vol = ext.x as f64 * ext.y as f64 * ext.z as f64;
    (corners && vol > 0.0 && (mesh.signed_volume().abs() - vol).abs() <= 1e-4 * vol).then_some(b)
}

/// The interval of times `t >= 0` during which box `moving` translated by `t * dir`
/// overlaps box `fixed` with positive volume (touching faces do not count).
/// Returns `None` when they never overlap.
pub fn sweep_overlap(moving: &Aabb, dir: Vec3, fixed: &Aabb) -> Option<(f32, f32)> {
    let (mut t0, mut t1) = (0.0f32, f32::INFINITY);
    for i in 0..3 {
        // overlap on axis i when fixed.min < moving.max + t d  and  moving.min + t d < fixed.max
        let lo = fixed.mins[i] - moving.maxs[i];
        let hi = fixed.maxs[i] - moving.mins[i];
        let d = dir[i];
        if d.abs() < 1e-9 {
            if !(lo < 0.0 && hi > 0.0) {
                return None;
            }
        } else {
            let (a, b) = if d > 0.0 { (lo / d, hi / d) } else { (hi / d, lo / d) };
            t0 = t0.max(a);
            t1 = t1.min(b);
        }
    }
    (t0 < t1).then_some((t0, t1))
}

/// Whether box `moving + t * dir` ever (`t >= 0`) overlaps `fixed` deeper than `tol` on every
/// axis (touching or grazing within `tol` is free: the moving box is shrunk by `tol`), and if so
/// when it first touches: the entry time without the tolerance, so exact contact reads 0.
/// `None`: never.
#[inline]
pub fn first_overlap(moving: &Aabb, dir: Vec3, fixed: &Aabb, tol: f32) -> Option<f32> {
    let (mut t0, mut t1) = (0.0f32, f32::INFINITY);
    let mut entry = 0.0f32;
    for i in 0..3 {
        let lo0 = fixed.mins[i] - moving.maxs[i];
        let hi0 = fixed.maxs[i] - moving.mins[i];
        let (lo, hi) = (lo0 + tol, hi0 - tol);
        let d = dir[i];
        if d == 0.0 {
            if !(lo < 0.0 && hi > 0.0) {
                return None;
            }
        } else {
            let (a, b) = if d > 0.0 { (lo / d, hi / d) } else { (hi / d, lo / d) };
            entry = entry.max(if d > 0.0 { lo0 / d } else { hi0 / d });
            t0 = t0.max(a);
            t1 = t1.min(b);
            if t0 >= t1 {
                return None;
            }
        }
    }
    (t0 < t1).then_some(entry.min(t0))
}

/// How deep two boxes overlap: the least shrinking of either that separates them (the smallest,
/// over the axes, of the shorter push out to either side); `<= 0` when they do not overlap.
pub fn overlap_depth(a: &Aabb, b: &Aabb) -> f32 {
    (0..3).map(|k| (a.maxs[k] - b.mins[k]).min(b.maxs[k] - a.mins[k])).fold(f32::INFINITY, f32::min)
}

/// The distance between two boxes given in a frame whose unit along axis `k` is `cell[k]`
/// metres, in metres.
pub fn box_distance(a: &Aabb, b: &Aabb, cell: Vec3) -> f32 {
    let mut sq = 0.0;
    for k in 0..3 {
        let gap = (a.mins[k] - b.maxs[k]).max(b.mins[k] - a.maxs[k]).max(0.0) * cell[k];
        sq += gap * gap;
    }
    sq.sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    fn part(mesh: Mesh, extras: serde_json::Value) -> Part {
        Part::new("p", mesh, false, extras)
    }

    #[test]
    fn voxels_are_fitted_to_a_scaled_mesh() {
        let cells = [[0, 0, 0], [1, 0, 0], [1, 1, 0]];
        // cells of 5 cm, the grid shifted by one cell along z
        let mesh = Mesh::from_voxels(&cells, Vec3::splat(0.05), Vec3::new(0.0, 0.0, 0.05));
        let boxes = part_boxes(&part(mesh, json!({"cells": cells}))).unwrap().unwrap();
        assert_eq!(boxes.len(), 3);
        let b = boxes[2];
        assert!((b.mins - Vec3::new(0.05, 0.05, 0.05)).abs().max_element() < 1e-6, "{b:?}");
        assert!((b.maxs - Vec3::new(0.10, 0.10, 0.10)).abs().max_element() < 1e-6, "{b:?}");
    }

    #[test]
    fn boxes_that_do_not_describe_the_mesh_are_refused() {
        let cells = [[0, 0, 0], [1, 0, 0], [1, 1, 0]];
        let mesh = Mesh::from_voxels(&cells, Vec3::ONE, Vec3::ZERO);
        // the mirrored L has the same bounds and volume, but a vertex off its boxes
        let mirrored = json!({"cells": [[0, 0, 0], [1, 0, 0], [0, 1, 0]]});
        assert!(part_boxes(&part(mesh.clone(), mirrored)).is_err());
        let two = json!({"boxes": [[0, 0, 0, 2, 1, 1], [1, 1, 0, 2, 2, 1]]});
        assert_eq!(part_boxes(&part(mesh.clone(), two)).unwrap().unwrap().len(), 2);
        let wrong = json!({"boxes": [[0, 0, 0, 2, 2, 1]]});
        assert!(part_boxes(&part(mesh, wrong)).is_err());
    }

    #[test]
    fn a_plain_box_mesh_is_a_box_and_other_meshes_are_not() {
        let b = Mesh::cuboid(Vec3::ZERO, Vec3::new(1.0, 2.0, 3.0));
        assert_eq!(part_boxes(&part(b, serde_json::Value::Null)).unwrap().unwrap().len(), 1);
        let l = Mesh::from_voxels(&[[0, 0, 0], [1, 0, 0], [1, 1, 0]], Vec3::ONE, Vec3::ZERO);
        assert!(part_boxes(&part(l, serde_json::Value::Null)).unwrap().is_none());
    }

    #[test]
    fn sweeps_and_depths_of_boxes() {
        let a = Aabb::new(Vec3::ZERO, Vec3::ONE);
        let right = Aabb::new(Vec3::new(2.0, 0.0, 0.0), Vec3::new(3.0, 1.0, 1.0));
        assert_eq!(first_overlap(&a, Vec3::X, &right, 0.0), Some(1.0));
        assert_eq!(first_overlap(&a, Vec3::Z, &right, 0.0), None);
        let top = Aabb::new(Vec3::new(0.0, 0.0, 1.0), Vec3::new(1.0, 1.0, 2.0));
        assert_eq!(first_overlap(&a, Vec3::Z, &top, 1e-3), Some(0.0));
        assert_eq!(first_overlap(&a, Vec3::X, &top, 1e-3), None, "sliding along a face is free");
        assert_eq!(first_overlap(&a, Vec3::Z, &top, 0.0), Some(0.0));
        assert_eq!(first_overlap(&a, Vec3::X, &top, 0.0), None);
        let almost = Aabb::new(Vec3::new(0.0, 0.0, 0.9999), Vec3::new(1.0, 1.0, 2.0));
        assert_eq!(first_overlap(&a, Vec3::X, &almost, 1e-3), None, "an overlap within the tolerance");
        assert!(overlap_depth(&a, &top) <= 0.0);
        let sunk = Aabb::new(Vec3::new(0.0, 0.0, 0.9), Vec3::new(1.0, 1.0, 2.0));
        assert!((overlap_depth(&a, &sunk) - 0.1).abs() < 1e-6);
        assert!((box_distance(&a, &right, Vec3::ONE) - 1.0).abs() < 1e-6);
    }

    #[test]
    fn sweep_overlap_of_boxes() {
        let a = Aabb::new(Vec3::ZERO, Vec3::ONE);
        let b = Aabb::new(Vec3::new(0.0, 0.0, 1.0), Vec3::new(1.0, 1.0, 2.0));
        // a moving up runs into b (touching at t = 0, overlapping until t = 2)
        assert_eq!(sweep_overlap(&a, Vec3::Z, &b), Some((0.0, 2.0)));
        // moving down never overlaps
        assert_eq!(sweep_overlap(&a, -Vec3::Z, &b), None);
        // sliding sideways along the shared face never overlaps with volume
        assert_eq!(sweep_overlap(&a, Vec3::X, &b), None);
    }
}
