//! The robot's collision shapes prepared for the removal planner: shrunk by the margin, placed
//! by forward kinematics, with their boxes in closed form.

use super::*;
use parry3d::shape::Segment;

/// A robot shape ready for collision tests: parry shape shrunk by the margin and its pose in
/// the link frame.
pub(super) struct Prepared {
    /// The shape's pose in the link frame (before parry's own turn of cylinders).
    pub(super) link_pose: Pose,
    /// The parry shape's pose in the link frame.
    pub(super) local: Pose,
    pub(super) shape: SharedShape,
    /// The shape's kind after shrinking, for its box in closed form.
    pub(super) kind: ShapeKind,
}

impl Prepared {
    pub(super) fn new(s: &LinkShape, margin: f32) -> Prepared {
        let (local, shape, kind) = shrunk(s, margin);
        Prepared { link_pose: s.local_pose, local, shape, kind }
    }

    /// Whether this shape at `pose` meets `other` at `at` (touching counts). Parry's
    /// intersection test, except for a capsule: its axis segment's distance to `other` against
    /// its radius (parry's test on the rounded shape reports capsules 2 mm apart as meeting).
    pub(super) fn meets(&self, pose: &Pose, at: &Pose, other: &dyn Shape) -> bool {
        match self.kind {
            ShapeKind::Capsule { radius, half_length } => {
                let axis = Segment::new(Vec3::new(0.0, 0.0, -half_length), Vec3::new(0.0, 0.0, half_length));
                query::distance(pose, &axis, at, other).is_ok_and(|d| d.distance <= radius)
            }
            _ => query::intersection_test(pose, &*self.shape, at, other).is_ok_and(|i| i.intersecting),
        }
    }

    /// [`Prepared::meets`] between two prepared shapes (two capsules in closed form).
    pub(super) fn meets_prepared(&self, pose: &Pose, other: &Prepared, at: &Pose) -> bool {
        match (self.kind, other.kind) {
            (ShapeKind::Capsule { radius: r1, half_length: h1 }, ShapeKind::Capsule { radius: r2, half_length: h2 }) => {
                let (a0, a1) = (pose.transform_point(Vec3::new(0.0, 0.0, -h1)), pose.transform_point(Vec3::new(0.0, 0.0, h1)));
                let (b0, b1) = (at.transform_point(Vec3::new(0.0, 0.0, -h2)), at.transform_point(Vec3::new(0.0, 0.0, h2)));
                segment_distance(a0, a1, b0, b1) <= r1 + r2
            }
            (_, ShapeKind::Capsule { .. }) => other.meets(at, pose, &*self.shape),
            _ => self.meets(pose, at, &*other.shape),
        }
    }

    /// The shape's bounding box at `pose` (closed form for capsules, boxes and spheres).
    pub(super) fn aabb(&self, pose: &Pose) -> Aabb {
        let c = pose.translation;
        let e = match self.kind {
            ShapeKind::Capsule { radius, half_length } => (pose.rotation * Vec3::new(0.0, 0.0, half_length)).abs() + Vec3::splat(radius),
            ShapeKind::Box { half_extents: h } => {
                (pose.rotation * Vec3::X).abs() * h.x + (pose.rotation * Vec3::Y).abs() * h.y + (pose.rotation * Vec3::Z).abs() * h.z
            }
            ShapeKind::Sphere { radius } => Vec3::splat(radius),
            ShapeKind::Cylinder { .. } => return self.shape.compute_aabb(pose),
        };
        Aabb::new(c - e, c + e)
    }
}

/// `s` shrunk by `margin` (each dimension kept above 0.1 mm): its pose in the link frame, the
/// parry shape and its kind.
pub(super) fn shrunk(s: &LinkShape, margin: f32) -> (Pose, SharedShape, ShapeKind) {
    let m = margin;
    let k = match s.kind {
        ShapeKind::Box { half_extents } => ShapeKind::Box { half_extents: (half_extents - Vec3::splat(m)).max(Vec3::splat(1e-4)) },
        ShapeKind::Cylinder { radius, half_length } => {
            ShapeKind::Cylinder { radius: (radius - m).max(1e-4), half_length: (half_length - m).max(1e-4) }
        }
        ShapeKind::Capsule { radius, half_length } => ShapeKind::Capsule { radius: (radius - m).max(1e-4), half_length },
        ShapeKind::Sphere { radius } => ShapeKind::Sphere { radius: (radius - m).max(1e-4) },
    };
    let ls = LinkShape { local_pose: s.local_pose, kind: k };
    let (fix, shape) = ls.to_parry();
    (s.local_pose * fix, shape, k)
}

/// The world pose and box of every prepared shape, their links at `link_poses`.
pub(super) fn world_shapes(arm: &[Prepared], link_poses: &[Pose]) -> Vec<(Pose, Aabb)> {
    link_poses
        .iter()
        .zip(arm)
        .map(|(l, p)| {
            let pose = *l * p.local;
            (pose, p.aabb(&pose))
        })
        .collect()
}

/// The lowest point of a box along `up` (its height above the origin's plane).
pub(super) fn lowest(bb: &Aabb, up: Vec3) -> f32 {
    (0..3).map(|k| (bb.mins[k] * up[k]).min(bb.maxs[k] * up[k])).sum()
}

/// The distance between two boxes (0 when they meet).
pub(super) fn box_gap(a: &Aabb, b: &Aabb) -> f32 {
    let gap = (a.mins - b.maxs).max(b.mins - a.maxs).max(Vec3::ZERO);
    gap.length()
}

/// Whether prepared shapes `i` and `j`, placed as in `placed`, overlap.
pub(super) fn shapes_touch(arm: &[Prepared], placed: &[(Pose, Aabb)], i: usize, j: usize) -> bool {
    placed[i].1.intersects(&placed[j].1) && arm[i].meets_prepared(&placed[i].0, &arm[j], &placed[j].0)
}

/// The distance between the segments `a0 a1` and `b0 b1` (Ericson, Real-Time Collision
/// Detection, 5.1.9).
pub(super) fn segment_distance(a0: Vec3, a1: Vec3, b0: Vec3, b1: Vec3) -> f32 {
    let (d1, d2, r) = (a1 - a0, b1 - b0, a0 - b0);
    let (a, e, f) = (d1.dot(d1), d2.dot(d2), d2.dot(r));
    let eps = 1e-12;
    let (s, t) = if a <= eps && e <= eps {
        (0.0, 0.0)
    } else if a <= eps {
        (0.0, (f / e).clamp(0.0, 1.0))
    } else {
        let c = d1.dot(r);
        if e <= eps {
            ((-c / a).clamp(0.0, 1.0), 0.0)
        } else {
            let b = d1.dot(d2);
            let denom = a * e - b * b;
            let mut s = if denom > eps { ((b * f - c * e) / denom).clamp(0.0, 1.0) } else { 0.0 };
            let mut t = (b * s + f) / e;
            if t < 0.0 {
                t = 0.0;
                s = (-c / a).clamp(0.0, 1.0);
            } else if t > 1.0 {
                t = 1.0;
                s = ((b - c) / a).clamp(0.0, 1.0);
            }
            (s, t)
        }
    };
    ((a0 + d1 * s) - (b0 + d2 * t)).length()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn segment_distance_matches_sampling() {
        let segs = [
            (Vec3::ZERO, Vec3::X, Vec3::new(0.5, 1.0, 0.0), Vec3::new(0.5, 2.0, 0.0), 1.0),
            (Vec3::ZERO, Vec3::X, Vec3::new(0.0, 1.0, 0.0), Vec3::new(1.0, 1.0, 0.0), 1.0),
            (Vec3::ZERO, Vec3::X, Vec3::new(2.0, 0.0, 0.0), Vec3::new(3.0, 0.0, 1.0), 1.0),
            (Vec3::ZERO, Vec3::X, Vec3::new(0.5, -1.0, 0.5), Vec3::new(0.5, 1.0, 0.5), 0.5),
            (Vec3::ZERO, Vec3::ZERO, Vec3::new(0.0, 1.0, 0.0), Vec3::new(0.0, 1.0, 0.0), 1.0),
        ];
        for (a0, a1, b0, b1, want) in segs {
            assert!((segment_distance(a0, a1, b0, b1) - want).abs() < 1e-6, "{a0} {a1} {b0} {b1}");
        }
        // two capsules 2 mm apart do not meet (parry's rounded-shape test said they did)
        let c = |z: f32| {
            Prepared::new(&LinkShape { local_pose: Pose::IDENTITY, kind: ShapeKind::Capsule { radius: 0.05, half_length: 0.1 } }, 0.0)
                .meets_prepared(
                    &Pose::IDENTITY,
                    &Prepared::new(
                        &LinkShape { local_pose: Pose::IDENTITY, kind: ShapeKind::Capsule { radius: 0.05, half_length: 0.1 } },
                        0.0,
                    ),
                    &Pose::from_parts(Vec3::new(0.1 + z, 0.0, 0.0), Rot::from_rotation_x(1.0)),
                )
        };
        assert!(!c(0.002) && c(-0.002));
    }
}
