//! The removal tests ([`Removal`], a view the world lends): straight-line removal of a part or a
//! rigid group, the two-step removal, the travel that clears the rest, and the collision queries
//! of the path planner along a motion. They read the blocking rows and the pair tests; they hold
//! no state of their own, so every planner asks the same world the same questions.

use super::blocking::Blocking;
use super::clearance::clearance_past;
use super::contacts::Contacts;
use super::fits::SCREW_ALIGNED;
use super::geom::{contains_point, nests};
use crate::feasibility::Motion;
use crate::math::{Aabb, Pose, Rot, Vec3};
use crate::partset::PartSet;
use crate::sweep;
use parry3d::query::{self, NonlinearRigidMotion};

/// The removal tests on the world's blocking rows and contacts.
#[derive(Clone, Copy)]
pub struct Removal<'a> {
    pub(super) blocking: Blocking<'a>,
    pub(super) contacts: &'a Contacts,
    /// The assembly's up direction (ties between free directions go to the one closest to it).
    pub(super) up: Vec3,
}

impl<'a> Removal<'a> {
    /// The blocking relation these tests read.
    pub fn blocking(&self) -> Blocking<'a> {
        self.blocking
    }

    /// The straight-line removal test of `p` in `state`: the free direction with the shortest
    /// travel (ties go to the direction closest to up), or the union of all blockers when every
    /// direction is blocked.
    pub fn linear(&self, p: usize, state: &PartSet) -> std::result::Result<Motion, PartSet> {
        self.linear_among(p, state, &self.contacts.with_fixed(state))
    }

    /// [`Removal::linear`] among an explicit set of `present` parts (the state plus the base
    /// parts that count as present, e.g. a subassembly on its own base without the ground).
    pub fn linear_among(&self, p: usize, state: &PartSet, present: &PartSet) -> std::result::Result<Motion, PartSet> {
        let row = self.blocking.row(p);
        let motion = self.best_free_direction(|k| row[k].intersection(present), |dir| self.clearance(p, state, dir))?;
        // along the axis of a threaded partner still present, the part screws out
        if let Motion::Linear { direction, distance } = motion {
            let fits = &self.blocking.pairs.overlaps.fits;
            let partner = present.iter().filter(|&q| q != p).find_map(|q| fits.thread(p, q));
            if let Some(t) = partner.filter(|t| t.axis.direction.dot(direction).abs() > SCREW_ALIGNED) {
                return Ok(Motion::Screw { axis_point: t.axis.point, direction, distance });
            }
            if let Some(f) = fits.turned_on(p, self.parts(), present, direction) {
                return Ok(Motion::Screw { axis_point: f.point, direction, distance });
            }
        }
        Ok(motion)
    }

    /// The straight-line removal test of a rigid `group` of parts of `state` among the `present`
    /// parts: the free direction with the shortest travel for the group's bounds to clear the
    /// rest (ties go to the direction closest to up), or every blocker.
    pub fn group_among(&self, group: &PartSet, state: &PartSet, present: &PartSet) -> std::result::Result<Motion, PartSet> {
        self.best_free_direction(|k| self.blocking.group_blockers(group, k, present), |dir| self.group_clearance(group, state, dir))
    }

    /// How far `p` must travel along `dir` for its bounds to clear the bounds of the other
    /// present real parts, plus the contact distance. With no other part left, it clears its own
    /// starting bounds (so the last part is lifted by its size, not by nothing).
    pub fn clearance(&self, p: usize, state: &PartSet, dir: Vec3) -> f32 {
        self.clearance_of(self.shapes().aabb(p), state.iter().filter(|&q| q != p), dir)
    }

    /// [`Removal::clearance`] of a group of parts moving together: its bounds clear the bounds
    /// of the other present real parts.
    pub fn group_clearance(&self, group: &PartSet, state: &PartSet, dir: Vec3) -> f32 {
        let bounds = self.shapes().bounds(group.iter()).expect("a group has parts");
        self.clearance_of(&bounds, state.iter().filter(|&q| !group.contains(q)), dir)
    }

    fn clearance_of(&self, a: &Aabb, others: impl Iterator<Item = usize>, dir: Vec3) -> f32 {
        let n = self.parts();
        let others = self.shapes().bounds(others.filter(|&q| q < n));
        clearance_past(a, others, dir, self.contacts.distance())
    }

    fn shapes(&self) -> &'a super::Shapes {
        self.blocking.pairs.shapes
    }

    fn parts(&self) -> usize {
        self.shapes().parts()
    }

    /// The free candidate direction (no blockers) with the shortest travel, ties to the one
    /// closest to up; or the union of every direction's blockers.
    fn best_free_direction(
        &self,
        blockers_along: impl Fn(usize) -> PartSet,
        travel: impl Fn(Vec3) -> f32,
    ) -> std::result::Result<Motion, PartSet> {
        best_free_direction(self.blocking.directions(), self.up, self.shapes().count(), blockers_along, travel)
    }

    /// A removal of `p` from `state` by two straight moves in turn when no single straight line
    /// is free (a hooked bracket lifts, then slides out): along a candidate direction as far as
    /// the first contact (less half the tolerance) or half of it, then along another candidate
    /// direction until its bounds clear the rest. Both moves are tested exactly (box intervals,
    /// or triangle sweeps of the pair's shapes); the first that works, in direction order, is a
    /// `Path` of pure translations.
    pub fn two_step(&self, p: usize, state: &PartSet) -> Option<Motion> {
        let (shapes, pairs, overlaps) = (self.shapes(), self.blocking.pairs, self.blocking.pairs.overlaps);
        let present = self.contacts.with_fixed(state);
        let others: Vec<usize> = present.iter().filter(|&q| q != p && !overlaps.ignores(p, q)).collect();
        let row = self.blocking.row(p);
        let a = *shapes.aabb(p);
        let pivot = (a.mins + a.maxs) * 0.5;
        for (k1, &d1) in self.blocking.directions().iter().enumerate() {
            let blockers = row[k1].intersection(&present);
            if blockers.is_empty() {
                continue;
            }
            let reach = blockers.iter().filter_map(|q| pairs.travel(p, q, Vec3::ZERO, d1)).fold(f32::INFINITY, f32::min);
            if !reach.is_finite() || reach <= 2.0 * shapes.tolerance() {
                continue;
            }
            // just short of the contact (half the tolerance: the part clears what it rose
            // above by that much, and presses into nothing deeper than the tolerance), or half way
            for s in [reach - 0.5 * shapes.tolerance(), 0.5 * reach] {
                let shift = d1 * s;
                let moved = Aabb::new(a.mins + shift, a.maxs + shift);
                for &d2 in self.blocking.directions() {
                    if d2.dot(d1).abs() > 0.999 {
                        continue;
                    }
                    let length = self.clearance_of(&moved, state.iter().filter(|&q| q != p), d2);
                    if others.iter().all(|&q| pairs.travel(p, q, shift, d2).is_none_or(|t| t > length))
                        && present.iter().filter(|&q| overlaps.is_strict(p, q)).all(|q| {
                            pairs.strict_entry(p, q, Vec3::ZERO, d1, s, true).is_none()
                                && pairs.strict_entry(p, q, shift, d2, length, true).is_none()
                        })
                    {
                        let poses = [Vec3::ZERO, shift, shift + d2 * length].map(Pose::from_translation).to_vec();
                        return Some(Motion::Path { poses, pivot });
                    }
                }
            }
        }
        None
    }

    /// The first present part that part `p` penetrates deeper than the tolerance while moving
    /// from pose `a` to pose `b` (pivot moving straight, rotation by slerp about it; see
    /// [`crate::feasibility::interpolate_about`]) — exact continuous collision detection with
    /// parry's nonlinear shape cast.
    pub fn collision_between(&self, p: usize, a: &Pose, b: &Pose, pivot: Vec3, state: &PartSet) -> Option<usize> {
        let (shapes, pairs, overlaps) = (self.shapes(), self.blocking.pairs, self.blocking.pairs.overlaps);
        let present = self.contacts.with_fixed(state);
        let (ca, cb) = (a.transform_point(pivot), b.transform_point(pivot));
        let radius = {
            let bb = shapes.aabb(p);
            (bb.maxs - pivot).abs().max((bb.mins - pivot).abs()).length()
        };
        let region = Aabb::new(ca.min(cb) - Vec3::splat(radius), ca.max(cb) + Vec3::splat(radius));
        let rel = b.rotation * a.rotation.inverse();
        let motion = NonlinearRigidMotion::new(*a, pivot, cb - ca, rel.to_scaled_axis());
        let still = NonlinearRigidMotion::constant_position(Pose::IDENTITY);
        let hit = present.iter().filter(|&q| q != p).find(|&q| {
            let qb = shapes.aabb(q);
            if !(0..3).all(|k| region.mins[k] < qb.maxs[k] && qb.mins[k] < region.maxs[k]) {
                return false;
            }
            if overlaps.is_strict(p, q) {
                // a part overlapping `q` in the input may leave it only along straight motions
                // that enter no new material: rotating edges count as collisions
                let turned = |r: Rot| r.angle_between(Rot::IDENTITY) >= 1e-6;
                if turned(rel) || turned(a.rotation) {
                    return true;
                }
                let shift = cb - ca;
                let len = shift.length();
                let dir = shift / len.max(f32::MIN_POSITIVE);
                if pairs.strict_entry(p, q, a.translation, dir, len, true).is_some() {
                    return true;
                }
            }
            if overlaps.ignores(p, q) {
                return false;
            }
            let (moving, fixed) = pairs.shapes(p, q);
            let fixed = &*fixed;
            if rel.angle_between(Rot::IDENTITY) < 1e-6 {
                // pure translation: the exact triangle sweep
                let shift = cb - ca;
                let len = shift.length();
                sweep::sweep_hits_at(&moving, a, shift / len.max(f32::MIN_POSITIVE), fixed, len)
            } else {
                query::cast_shapes_nonlinear(&motion, &*moving, &still, fixed, 0.0, 1.0, true).map_or(true, |h| h.is_some())
            }
        });
        hit
    }

    /// The first present part that part `p`, displaced by `pose` (applied to its assembled world
    /// position), penetrates deeper than the tolerance — the static test of the path planner.
    pub fn collision_at(&self, p: usize, pose: &Pose, state: &PartSet) -> Option<usize> {
        let (shapes, overlaps) = (self.shapes(), self.blocking.pairs.overlaps);
        let present = self.contacts.with_fixed(state);
        let bb = shapes.aabb(p).transform_by(pose);
        let id = Pose::IDENTITY;
        let hit = present.iter().filter(|&q| q != p && !overlaps.ignores(p, q)).find(|&q| {
            let qb = shapes.aabb(q);
            if !(0..3).all(|k| bb.mins[k] < qb.maxs[k] && qb.mins[k] < bb.maxs[k]) {
                return false;
            }
            let (k, amount) = overlaps.erosion(p, q);
            let shrunk = shapes.eroded(k, amount);
            let (shrunk_pose, raw, raw_pose, raw_closed) =
                if k == p { (*pose, shapes.mesh(q), id, shapes.is_closed(q)) } else { (id, shapes.mesh(p), *pose, shapes.is_closed(p)) };
            let (bs, br) = (shrunk.aabb(&shrunk_pose), raw.aabb(&raw_pose));
            // surfaces crossing (exact triangle tests, `p` placed by `pose`), or one wholly inside
            // the other: only for closed surfaces whose boxes nest
            let crossing = if k == p { sweep::meshes_cross_at(&shrunk, pose, raw) } else { sweep::meshes_cross_at(raw, pose, &shrunk) };
            crossing
                || (raw_closed
                    && nests(&bs, &br)
                    && contains_point(raw, raw_pose.inverse_transform_point(shrunk_pose.transform_point(shrunk.vertices()[0]))))
                || (shapes.is_closed(k)
                    && nests(&br, &bs)
                    && contains_point(&shrunk, shrunk_pose.inverse_transform_point(raw_pose.transform_point(raw.vertices()[0]))))
        });
        hit
    }
}

/// The free direction of `directions` (no blockers) with the shortest travel, ties to the one
/// closest to `up`; or the union of every direction's blockers (a set with room for `parts`).
/// The one choice the collision world and the voxel checker ([`crate::voxel`]) share.
pub(crate) fn best_free_direction(
    directions: &[Vec3],
    up: Vec3,
    parts: usize,
    blockers_along: impl Fn(usize) -> PartSet,
    travel: impl Fn(Vec3) -> f32,
) -> std::result::Result<Motion, PartSet> {
    let mut best: Option<(f32, Vec3)> = None;
    let mut blockers = PartSet::empty(parts);
    for (k, dir) in directions.iter().enumerate() {
        let b = blockers_along(k);
        if b.is_empty() {
            let d = travel(*dir);
            let better = match best {
                None => true,
                Some((bd, bdir)) => d < bd - 1e-6 * bd.max(1e-9) || (d <= bd + 1e-6 * bd && dir.dot(up) > bdir.dot(up) + 1e-6),
            };
            if better {
                best = Some((d, *dir));
            }
        } else {
            blockers.union_with(&b);
        }
    }
    match best {
        Some((distance, direction)) => Ok(Motion::Linear { direction, distance }),
        None => Err(blockers),
    }
}

#[cfg(test)]
mod tests {
    use crate::feasibility::{Motion, Stability};
    use crate::fixtures::{assemble, part};
    use crate::math::{Axis, Pose, Vec3};
    use crate::mesh::Mesh;
    use crate::partset::PartSet;
    use crate::world::{World, WorldConfig};

    /// Three unit cubes stacked on the ground (index 3).
    fn stack() -> World {
        let cube = |z: f32| part("cube", Mesh::cuboid(Vec3::new(0.0, 0.0, z), Vec3::new(1.0, 1.0, z + 1.0)), false);
        World::new(assemble("stack", vec![cube(0.0), cube(1.0), cube(2.0)], Axis::Z), &WorldConfig::default()).unwrap()
    }

    #[test]
    fn the_top_of_a_stack_lifts_off_by_the_contact_distance() {
        let w = stack();
        let all = PartSet::from_indices(4, [0, 1, 2]);
        let r = w.removal();
        assert_eq!(r.linear(2, &all), Ok(Motion::Linear { direction: Vec3::Z, distance: w.contacts().distance() }));
        // sideways it clears the others' bounds after its own width
        assert!((r.clearance(2, &all, Vec3::X) - 1.0 - w.contacts().distance()).abs() < 1e-6);
        // the two upper cubes as one group lift off the lowest
        let group = PartSet::from_indices(4, [1, 2]);
        assert_eq!(r.group_clearance(&group, &all, Vec3::Z), w.contacts().distance());
        assert!(matches!(r.group_among(&group, &all, &w.contacts().with_fixed(&all)), Ok(Motion::Linear { .. })));
    }

    #[test]
    fn a_cube_pushed_into_the_one_below_collides_with_it_and_a_gap_unsettles_the_top() {
        let w = stack();
        let all = PartSet::from_indices(4, [0, 1, 2]);
        let down = Pose::from_translation(Vec3::new(0.0, 0.0, -0.5));
        assert_eq!(w.removal().collision_at(2, &down, &all), Some(1));
        assert_eq!(w.removal().collision_at(2, &Pose::from_translation(Vec3::Z), &all), None);
        let floating = PartSet::from_indices(4, [2]);
        assert_eq!(w.contacts().stability(&PartSet::from_indices(4, [0, 2])), Stability::Unstable { floating });
    }
}
