//! The narrow phase: the exact tests of one pair of parts, read from the shapes and the overlaps
//! together ([`Pairs`], a view the world lends). Which shapes a pair is tested with (one of them
//! shrunk by the pair's erosion), the strict sample rule for pairs that overlap in the input, and
//! how far one travels before it hits the other.
//!
//! Every other test (the blocking rows, the two-step removal, the path planner's collision
//! queries, the distance maps) asks these, so a pair is shrunk and sampled by one rule
//! everywhere.

use super::overlaps::Overlaps;
use super::shapes::Shapes;
use crate::boxes::{self, sweep_overlap};
use crate::math::{Aabb, Pose, Vec3};
use crate::overlap;
use crate::sweep;
use parry3d::shape::TriMesh;
use std::sync::Arc;

/// The pair tests on the world's shapes under its overlap policy.
#[derive(Clone, Copy)]
pub struct Pairs<'a> {
    pub(super) shapes: &'a Shapes,
    pub(super) overlaps: &'a Overlaps,
}

impl<'a> Pairs<'a> {
    /// The shapes of `p` and `q` for their mutual tests: one of them shrunk (see
    /// [`Overlaps::erosion`]), both in their assembled pose.
    pub fn shapes(&self, p: usize, q: usize) -> (Arc<TriMesh>, Arc<TriMesh>) {
        let (k, amount) = self.overlaps.erosion(p, q);
        let g = &self.shapes.geoms;
        if k == p {
            (self.shapes.eroded(p, amount), g[q].mesh.clone())
        } else {
            (g[p].mesh.clone(), self.shapes.eroded(q, amount))
        }
    }

    /// The strict overlap rule for a pair that overlaps in the input (see [`crate::overlap`]):
    /// how far `p`, displaced by `from`, travels along unit `dir` (up to `t_max`) before a surface
    /// sample of either part (moved inward by the tolerance) enters the other's material; `None`
    /// when none does, and always `None` for pairs the rule does not apply to. With
    /// `first_only`, any entry answers (not the earliest).
    pub fn strict_entry(&self, p: usize, q: usize, from: Vec3, dir: Vec3, t_max: f32, first_only: bool) -> Option<f32> {
        if !self.overlaps.is_strict(p, q) {
            return None;
        }
        let (sp, sq) = (self.overlaps.strict_pair_samples(self.shapes, p, q), self.overlaps.strict_pair_samples(self.shapes, q, p));
        self.entry(p, q, sp, sq, from, dir, t_max, first_only)
    }

    /// The strict rule on the given samples of `p` and `q`.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn entry(
        &self,
        p: usize,
        q: usize,
        sp: &[Vec3],
        sq: &[Vec3],
        from: Vec3,
        dir: Vec3,
        t_max: f32,
        first: bool,
    ) -> Option<f32> {
        let g = &self.shapes.geoms;
        overlap::strict_entry(sp, &g[p].mesh, sq, &g[q].mesh, from, dir, t_max, first, self.shapes.tolerance())
    }

    /// How far `p`, displaced by `from`, travels along unit `dir` before it first penetrates `q`
    /// deeper than the tolerance (boxes: when they first touch); `None` when never.
    pub fn travel(&self, p: usize, q: usize, from: Vec3, dir: Vec3) -> Option<f32> {
        let (a, b) = (self.shapes.aabb(p), self.shapes.aabb(q));
        let moved = Aabb::new(a.mins + from, a.maxs + from);
        let (_, t1) = sweep_overlap(&moved, dir, b)?;
        if let (Some(bp), Some(bq)) = (self.shapes.boxes(p), self.shapes.boxes(q)) {
            let (_, amount) = self.overlaps.erosion(p, q);
            return bp
                .iter()
                .flat_map(|x| bq.iter().map(move |y| (x, y)))
                .filter_map(|(x, y)| boxes::first_overlap(&Aabb::new(x.mins + from, x.maxs + from), dir, y, amount))
                .reduce(f32::min);
        }
        let (moving, fixed) = self.shapes(p, q);
        if from == Vec3::ZERO {
            return sweep::sweep_distance(&moving, dir, &fixed, t1);
        }
        // from a displaced start only whether it hits at all matters (the second move)
        sweep::sweep_hits_at(&moving, &Pose::from_translation(from), dir, &fixed, t1).then_some(0.0)
    }
}

#[cfg(test)]
mod tests {
    use crate::fixtures::pressed_peg;
    use crate::math::Vec3;
    use crate::world::{World, WorldConfig};
    use std::sync::Arc;

    /// The pressed peg's tests shrink one part by the pair's erosion and leave the other whole;
    /// the strict rule lets the peg out along its axis and not sideways.
    #[test]
    fn a_pair_is_tested_with_one_part_shrunk_by_its_erosion() {
        let w = World::new(pressed_peg(), &WorldConfig { exact_boxes: false, ..WorldConfig::default() }).unwrap();
        let pairs = w.blocking().pairs();
        let (plate, peg) = (0, 1);
        let (k, amount) = w.overlaps().erosion(plate, peg);
        let (a, b) = pairs.shapes(plate, peg);
        let shrunk = w.shapes().eroded(k, amount);
        assert!(if k == plate { Arc::ptr_eq(&a, &shrunk) } else { Arc::ptr_eq(&b, &shrunk) });
        assert!(pairs.strict_entry(peg, plate, Vec3::ZERO, Vec3::Z, 1.0, true).is_none(), "straight up enters no new material");
        assert!(pairs.strict_entry(peg, plate, Vec3::ZERO, Vec3::X, 1.0, true).is_some(), "sideways cuts the plate");
    }
}
