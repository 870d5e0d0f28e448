//! The blocking relation: the candidate removal directions and, per part, which parts block it
//! along each ([`Blocking`], a view the world lends over its cached rows).
//!
//! A translation along `d` collides with a union of obstacles iff it collides with one of them,
//! and a part that hits `q` does so before its bounds clear the bounds of what remains (which
//! contain `q`). So "does `q` block `p` along `d`" is a property of the pair, independent of the
//! state: it is computed once per (part, direction, neighbour), lazily, the first time a part is
//! tested, in parallel, and every later removal test of that part is a few bitset operations.
//! The pair test itself ([`Blocking::pair_blocks`]) is the one place that decides which rule a
//! pair is swept by: a thread's screw, a fit's band, the strict samples, exact boxes or the
//! exact triangle sweep.

use super::fits::{Fits, SCREW_ALIGNED};
use super::pairs::Pairs;
use crate::boxes::{self, sweep_overlap};
use crate::fastener::Thread;
use crate::fits::Fit;
use crate::math::Vec3;
use crate::partset::PartSet;
use crate::sweep;
use rayon::prelude::*;
use std::sync::OnceLock;

/// The candidate directions and the cache of blocking rows (one per real part).
pub(super) struct Rows {
    pub(super) directions: Vec<Vec3>,
    rows: Vec<OnceLock<Vec<PartSet>>>,
}

impl Rows {
    /// No row computed yet, for `parts` real parts along `directions`.
    pub(super) fn new(directions: Vec<Vec3>, parts: usize) -> Rows {
        Rows { directions, rows: (0..parts).map(|_| OnceLock::new()).collect() }
    }
}

/// The directional blocking relation of the world's parts.
#[derive(Clone, Copy)]
pub struct Blocking<'a> {
    pub(super) pairs: Pairs<'a>,
    pub(super) rows: &'a Rows,
}

impl<'a> Blocking<'a> {
    /// Candidate straight-line removal directions (unit vectors).
    pub fn directions(&self) -> &'a [Vec3] {
        &self.rows.directions
    }

    /// The exact tests of one pair of parts.
    pub fn pairs(&self) -> Pairs<'a> {
        self.pairs
    }

    fn fits(&self) -> &'a Fits {
        &self.pairs.overlaps.fits
    }

    /// Whether `q` blocks `p` moving along `dir` (unit) from the assembled pose, to infinity.
    pub fn pair_blocks(&self, p: usize, q: usize, dir: Vec3) -> bool {
        let (shapes, overlaps) = (self.pairs.shapes, self.pairs.overlaps);
        let Some((_, t1)) = sweep_overlap(shapes.aabb(p), dir, shapes.aabb(q)) else {
            return false;
        };
        if let Some(thread) = self.fits().thread(p, q).filter(|t| t.axis.direction.dot(dir).abs() > SCREW_ALIGNED) {
            return self.screw_blocks(p, q, &thread, dir, t1);
        }
        if self.fits().thread(q, p).is_some_and(|t| t.axis.direction.dot(dir).abs() > SCREW_ALIGNED) {
            // a body a fastener is screwed into (a tapped hole drawn smooth at the thread's major
            // diameter, as CAD draws them) would have to turn about the fastener to leave along
            // its axis: the fastener leaves first
            return true;
        }
        let fits = self.fits().along(p, q, dir);
        if !fits.is_empty() {
            // along a fit's axis the fit is carried (pressed out, unscrewed, slid), with the
            // fit's band exempt from the strict rule and nothing else entering new material
            if self.fit_blocks(p, q, &fits, dir, t1) {
                return true;
            }
            if overlaps.ignores(p, q) {
                return false;
            }
            // the samples may miss a collision away from the fits (a collar, a flange): the
            // pair is swept exactly, one part shrunk past the deepest fit's band
            let band = fits.iter().map(|f| f.band.1 - f.band.0).fold(0.0f32, f32::max);
            let (k, amount) = overlaps.erosion(p, q);
            let amount = amount.max(band + shapes.tolerance());
            let g = &shapes.geoms;
            let (moving, fixed) =
                if k == p { (shapes.eroded(p, amount), g[q].mesh.clone()) } else { (g[p].mesh.clone(), shapes.eroded(q, amount)) };
            return sweep::sweep_hits(&moving, dir, &fixed, t1);
        }
        if overlaps.is_strict(p, q) && self.pairs.strict_entry(p, q, Vec3::ZERO, dir, t1, true).is_some() {
            return true;
        }
        if overlaps.ignores(p, q) {
            return false;
        }
        if let (Some(bp), Some(bq)) = (shapes.boxes(p), shapes.boxes(q)) {
            // exact on the boxes, each of `p`'s shrunk by the pair's erosion
            let (_, amount) = overlaps.erosion(p, q);
            return bp.iter().any(|a| bq.iter().any(|b| boxes::first_overlap(a, dir, b, amount).is_some()));
        }
        // exact triangle sweeps (parry's mesh cast calls some slides at tolerance-sized gaps hits)
        let (moving, fixed) = self.pairs.shapes(p, q);
        sweep::sweep_hits(&moving, dir, &fixed, t1)
    }

    /// The pair test of a threaded pair along its axis: the strict sample rule outside the
    /// thread zone (samples of either part closer to the axis than the zone's radius are
    /// exempt: the thread is invariant under the screw motion).
    fn screw_blocks(&self, p: usize, q: usize, thread: &Thread, dir: Vec3, t_max: f32) -> bool {
        let outside = |s: &[Vec3]| -> Vec<Vec3> { s.iter().copied().filter(|&x| thread.axis.radial(x) > thread.radius).collect() };
        let shapes = self.pairs.shapes;
        let (sp, sq) = (outside(shapes.strict_samples(p)), outside(shapes.strict_samples(q)));
        self.pairs.entry(p, q, &sp, &sq, Vec3::ZERO, dir, t_max, true).is_some()
    }

    /// The pair test of `p` moving along unit `dir` (up to `t_max`) against `q` when the motion
    /// follows the axis of their `fits`: blocked when `q` must turn to move along it (the part
    /// holding a fastener's thread, a bolt whose nut is still on), else the strict sample rule
    /// on the samples of both parts outside every fit's band (see [`crate::fits`]).
    fn fit_blocks(&self, p: usize, q: usize, fits: &[&Fit], dir: Vec3, t_max: f32) -> bool {
        if fits.iter().any(|f| f.turns == Some(q)) {
            return true;
        }
        // each band about the line through the fit's axis point along the motion: a sample
        // moving along `dir` keeps its distance from that line
        let outside = |s: &[Vec3]| -> Vec<Vec3> {
            s.iter()
                .copied()
                .filter(|&x| {
                    !fits.iter().any(|f| {
                        let r = crate::surface::radial(x, f.point, dir);
                        r >= f.band.0 && r <= f.band.1
                    })
                })
                .collect()
        };
        let (shapes, overlaps) = (self.pairs.shapes, self.pairs.overlaps);
        let (sp, sq) = (outside(overlaps.fit_pair_samples(shapes, p, q)), outside(overlaps.fit_pair_samples(shapes, q, p)));
        self.pairs.entry(p, q, &sp, &sq, Vec3::ZERO, dir, t_max, true).is_some()
    }

    /// For each candidate direction, every part (ground included) that blocks `p` along it.
    /// Computed once per part, in parallel, then cached.
    pub fn row(&self, p: usize) -> &'a [PartSet] {
        let this = *self;
        self.rows.rows[p].get_or_init(move || {
            let count = this.pairs.shapes.count();
            let directions = this.directions();
            let jobs: Vec<(usize, usize)> =
                (0..directions.len()).flat_map(|k| (0..count).filter(move |&q| q != p).map(move |q| (k, q))).collect();
            let blocked: Vec<bool> = jobs.par_iter().map(|&(k, q)| this.pair_blocks(p, q, directions[k])).collect();
            let mut row = vec![PartSet::empty(count); directions.len()];
            for (&(k, q), b) in jobs.iter().zip(blocked) {
                if b {
                    row[k].insert(q);
                }
            }
            row
        })
    }

    /// The parts of `present` that block the rigid `group` moving along candidate direction `k`:
    /// straight-line blocking is a property of part pairs, so this is the union of the members'
    /// blocking rows, minus the group.
    pub fn group_blockers(&self, group: &PartSet, k: usize, present: &PartSet) -> PartSet {
        let mut blockers = PartSet::empty(self.pairs.shapes.count());
        for p in group.iter().filter(|&p| p < self.pairs.shapes.parts()) {
            blockers.union_with(&self.row(p)[k].intersection(present));
        }
        for p in group.iter() {
            blockers.remove(p);
        }
        blockers
    }

    /// The smallest set of `present` parts that contains `seeds` and can translate along
    /// candidate direction `k` as one rigid body: `seeds` closed under "is blocked by" (a
    /// directional blocking graph's closure). It contains a fixed part when the seeds cannot
    /// leave along `k` without one.
    pub fn group_closure(&self, seeds: &PartSet, k: usize, present: &PartSet) -> PartSet {
        let mut group = seeds.clone();
        let mut frontier: Vec<usize> = seeds.iter().collect();
        while let Some(p) = frontier.pop() {
            if p >= self.pairs.shapes.parts() {
                continue; // the ground never moves: a closure that reaches it is refused anyway
            }
            for q in self.row(p)[k].intersection(present).iter() {
                if !group.contains(q) {
                    group.insert(q);
                    frontier.push(q);
                }
            }
        }
        group
    }
}

#[cfg(test)]
mod tests {
    use crate::fixtures::{assemble, part};
    use crate::math::{Axis, Vec3};
    use crate::mesh::Mesh;
    use crate::partset::PartSet;
    use crate::world::{World, WorldConfig};

    /// Three stacked boxes on the ground: the top one is blocked by nothing upwards, the middle
    /// one by the top one, and the group of both leaves up together.
    #[test]
    fn a_stack_blocks_upwards_one_part_at_a_time_and_its_closure_leaves_together() {
        let cube = |z: f32| part("cube", Mesh::cuboid(Vec3::new(0.0, 0.0, z), Vec3::new(1.0, 1.0, z + 1.0)), false);
        let w = World::new(assemble("stack", vec![cube(0.0), cube(1.0), cube(2.0)], Axis::Z), &WorldConfig::default()).unwrap();
        let b = w.blocking();
        let up = b.directions().iter().position(|&d| d == Vec3::Z).unwrap();
        assert!(b.row(2)[up].is_empty());
        assert_eq!(b.row(1)[up], PartSet::from_indices(4, [2]));
        assert!(b.pair_blocks(1, 2, Vec3::Z) && !b.pair_blocks(2, 1, Vec3::Z));
        let all = PartSet::full(4);
        assert_eq!(b.group_closure(&PartSet::from_indices(4, [0]), up, &all), PartSet::from_indices(4, [0, 1, 2]));
        assert!(b.group_blockers(&PartSet::from_indices(4, [0, 1, 2]), up, &all).is_empty());
    }
}
