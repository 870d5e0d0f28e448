//! The removal tests on a built [`World`]: straight-line removal of a part or a group, the
//! two-step removal, contact stability, and the collision queries along a motion.

use super::*;

impl World {
    /// The straight-line removal test of `p` in `state`: the free direction with the shortest
    /// travel (ties go to the direction closest to up), or the union of all blockers when every
    /// direction is blocked.
    pub fn linear_removal(&self, p: usize, state: &PartSet) -> std::result::Result<Motion, PartSet> {
        self.linear_removal_among(p, state, &self.with_fixed(state))
    }

    /// [`World::linear_removal`] among an explicit set of `present` parts (the state plus the
    /// base parts that count as present, e.g. a subassembly on its own base without the ground).
    pub fn linear_removal_among(&self, p: usize, state: &PartSet, present: &PartSet) -> std::result::Result<Motion, PartSet> {
        let row = self.blocking_row(p);
        let motion = self.best_free_direction(|k| row[k].intersection(present), |dir| self.clearance(p, state, dir))?;
        // along the axis of a threaded partner still present, the part screws out
        if let Motion::Linear { direction, distance } = motion {
            let partner = present.iter().filter(|&q| q != p).find_map(|q| self.thread(p, q));
            if let Some(t) = partner.filter(|t| t.axis.direction.dot(direction).abs() > SCREW_ALIGNED) {
                return Ok(Motion::Screw { axis_point: t.axis.point, direction, distance });
            }
            if let Some(f) = self.turned_on(p, present, direction) {
                return Ok(Motion::Screw { axis_point: f.point, direction, distance });
            }
        }
        Ok(motion)
    }

    /// The parts of `present` that block the rigid `group` moving along candidate direction `k`:
    /// straight-line blocking is a property of part pairs, so this is the union of the members'
    /// blocking rows, minus the group.
    pub fn group_blockers(&self, group: &PartSet, k: usize, present: &PartSet) -> PartSet {
        let mut blockers = PartSet::empty(self.geoms.len());
        for p in group.iter().filter(|&p| p < self.num_parts()) {
            blockers.union_with(&self.blocking_row(p)[k].intersection(present));
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
            if p >= self.num_parts() {
                continue; // the ground never moves: a closure that reaches it is refused anyway
            }
            for q in self.blocking_row(p)[k].intersection(present).iter() {
                if !group.contains(q) {
                    group.insert(q);
                    frontier.push(q);
                }
            }
        }
        group
    }

    /// The straight-line removal test of a rigid `group` of parts of `state` among the `present`
    /// parts: the free direction with the shortest travel for the group's bounds to clear the
    /// rest (ties go to the direction closest to up), or every blocker.
    pub fn group_removal_among(&self, group: &PartSet, state: &PartSet, present: &PartSet) -> std::result::Result<Motion, PartSet> {
        self.best_free_direction(|k| self.group_blockers(group, k, present), |dir| self.group_clearance(group, state, dir))
    }

    /// The free candidate direction (no blockers) with the shortest travel, ties to the one
    /// closest to up; or the union of every direction's blockers.
    fn best_free_direction(
        &self,
        blockers_along: impl Fn(usize) -> PartSet,
        travel: impl Fn(Vec3) -> f32,
    ) -> std::result::Result<Motion, PartSet> {
        best_free_direction(&self.directions, self.assembly.up.vector(), self.geoms.len(), blockers_along, travel)
    }

    /// A removal of `p` from `state` by two straight moves in turn when no single straight line
    /// is free (a hooked bracket lifts, then slides out): along a candidate direction as far as
    /// the first contact (less half the tolerance) or half of it, then along another candidate
    /// direction until its bounds clear the rest. Both moves are tested exactly (box intervals,
    /// or triangle sweeps of the pair's shapes); the first that works, in direction order, is a
    /// `Path` of pure translations.
    pub fn two_step_removal(&self, p: usize, state: &PartSet) -> Option<Motion> {
        let present = self.with_fixed(state);
        let others: Vec<usize> = present.iter().filter(|&q| q != p && !self.ignores(p, q)).collect();
        let row = self.blocking_row(p);
        let a = self.geoms[p].aabb;
        let pivot = (a.mins + a.maxs) * 0.5;
        for (k1, &d1) in self.directions.iter().enumerate() {
            let blockers = row[k1].intersection(&present);
            if blockers.is_empty() {
                continue;
            }
            let reach = blockers.iter().filter_map(|q| self.pair_travel(p, q, Vec3::ZERO, d1)).fold(f32::INFINITY, f32::min);
            if !reach.is_finite() || reach <= 2.0 * self.tolerance {
                continue;
            }
            // just short of the contact (half the tolerance: the part clears what it rose
            // above by that much, and presses into nothing deeper than the tolerance), or half way
            for s in [reach - 0.5 * self.tolerance, 0.5 * reach] {
                let shift = d1 * s;
                let moved = Aabb::new(a.mins + shift, a.maxs + shift);
                for &d2 in &self.directions {
                    if d2.dot(d1).abs() > 0.999 {
                        continue;
                    }
                    let length = self.clearance_of(&moved, state.iter().filter(|&q| q != p), d2);
                    if others.iter().all(|&q| self.pair_travel(p, q, shift, d2).is_none_or(|t| t > length))
                        && present.iter().filter(|&q| self.is_strict_pair(p, q)).all(|q| {
                            self.strict_entry(p, q, Vec3::ZERO, d1, s, true).is_none()
                                && self.strict_entry(p, q, shift, d2, length, true).is_none()
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

    /// How far `p`, displaced by `from`, travels along unit `dir` before it first penetrates `q`
    /// deeper than the tolerance (boxes: when they first touch); `None` when never.
    fn pair_travel(&self, p: usize, q: usize, from: Vec3, dir: Vec3) -> Option<f32> {
        let (a, b) = (&self.geoms[p].aabb, &self.geoms[q].aabb);
        let moved = Aabb::new(a.mins + from, a.maxs + from);
        let (_, t1) = sweep_overlap(&moved, dir, b)?;
        if let (Some(bp), Some(bq)) = (&self.geoms[p].boxes, &self.geoms[q].boxes) {
            let (_, amount) = self.pair_erosion(p, q);
            return bp
                .iter()
                .flat_map(|x| bq.iter().map(move |y| (x, y)))
                .filter_map(|(x, y)| boxes::first_overlap(&Aabb::new(x.mins + from, x.maxs + from), dir, y, amount))
                .reduce(f32::min);
        }
        let (moving, fixed) = self.pair_shapes(p, q);
        if from == Vec3::ZERO {
            return sweep::sweep_distance(&moving, dir, &fixed, t1);
        }
        // from a displaced start only whether it hits at all matters (the second move)
        sweep::sweep_hits_at(&moving, &Pose::from_translation(from), dir, &fixed, t1).then_some(0.0)
    }

    /// Contact-graph stability: every present part is linked through contacts to a fixed part.
    pub fn contact_stability(&self, state: &PartSet) -> Stability {
        self.contact_stability_among(&self.with_fixed(state), &self.fixed)
    }

    /// Contact-graph stability of the `present` parts on the `base` parts among them: every
    /// present part is linked through contacts to a present base part.
    pub fn contact_stability_among(&self, present: &PartSet, base: &PartSet) -> Stability {
        let reached = present.intersection(base).reached_within(present, |i| self.contacts[i].iter());
        let floating = PartSet::from_indices(self.geoms.len(), present.iter().filter(|&i| !reached.contains(i)));
        if floating.is_empty() {
            Stability::Stable
        } else {
            Stability::Unstable { floating }
        }
    }

    /// The first present part that part `p` penetrates deeper than the tolerance while moving
    /// from pose `a` to pose `b` (pivot moving straight, rotation by slerp about it; see
    /// [`crate::feasibility::interpolate_about`]) — exact continuous collision detection with
    /// parry's nonlinear shape cast.
    pub fn collision_between(&self, p: usize, a: &Pose, b: &Pose, pivot: Vec3, state: &PartSet) -> Option<usize> {
        let present = self.with_fixed(state);
        let (ca, cb) = (a.transform_point(pivot), b.transform_point(pivot));
        let radius = {
            let bb = &self.geoms[p].aabb;
            (bb.maxs - pivot).abs().max((bb.mins - pivot).abs()).length()
        };
        let region = Aabb::new(ca.min(cb) - Vec3::splat(radius), ca.max(cb) + Vec3::splat(radius));
        let rel = b.rotation * a.rotation.inverse();
        let motion = NonlinearRigidMotion::new(*a, pivot, cb - ca, rel.to_scaled_axis());
        let still = NonlinearRigidMotion::constant_position(Pose::IDENTITY);
        let hit = present.iter().filter(|&q| q != p).find(|&q| {
            let qb = &self.geoms[q].aabb;
            if !(0..3).all(|k| region.mins[k] < qb.maxs[k] && qb.mins[k] < region.maxs[k]) {
                return false;
            }
            if self.is_strict_pair(p, q) {
                // a part overlapping `q` in the input may leave it only along straight motions
                // that enter no new material: rotating edges count as collisions
                let turned = |r: crate::math::Rot| r.angle_between(crate::math::Rot::IDENTITY) >= 1e-6;
                if turned(rel) || turned(a.rotation) {
                    return true;
                }
                let shift = cb - ca;
                let len = shift.length();
                let dir = shift / len.max(f32::MIN_POSITIVE);
                if self.strict_entry(p, q, a.translation, dir, len, true).is_some() {
                    return true;
                }
            }
            if self.ignores(p, q) {
                return false;
            }
            let (moving, fixed) = self.pair_shapes(p, q);
            let fixed = &*fixed;
            if rel.angle_between(crate::math::Rot::IDENTITY) < 1e-6 {
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
        let present = self.with_fixed(state);
        let bb = self.geoms[p].aabb.transform_by(pose);
        let id = Pose::IDENTITY;
        let hit = present.iter().filter(|&q| q != p && !self.ignores(p, q)).find(|&q| {
            let qb = &self.geoms[q].aabb;
            if !(0..3).all(|k| bb.mins[k] < qb.maxs[k] && qb.mins[k] < bb.maxs[k]) {
                return false;
            }
            let (k, amount) = self.pair_erosion(p, q);
            let shrunk = self.eroded(k, amount);
            let (shrunk_pose, raw, raw_pose, raw_closed) = if k == p {
                (*pose, &self.geoms[q].mesh, id, self.geoms[q].closed)
            } else {
                (id, &self.geoms[p].mesh, *pose, self.geoms[p].closed)
            };
            let (bs, br) = (shrunk.aabb(&shrunk_pose), raw.aabb(&raw_pose));
            // surfaces crossing (exact triangle tests, `p` placed by `pose`), or one wholly inside
            // the other: only for closed surfaces whose boxes nest
            let crossing = if k == p { sweep::meshes_cross_at(&shrunk, pose, raw) } else { sweep::meshes_cross_at(raw, pose, &shrunk) };
            crossing
                || (raw_closed
                    && nests(&bs, &br)
                    && contains_point(raw, raw_pose.inverse_transform_point(shrunk_pose.transform_point(shrunk.vertices()[0]))))
                || (self.geoms[k].closed
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
