//! The robot's collision shapes prepared for the removal planner: shrunk by the margin, placed
//! by forward kinematics, with their boxes in closed form.

use super::*;

/// A robot shape ready for collision tests: parry shape shrunk by the margin and its pose in
/// the link frame.
pub(super) struct Prepared {
    pub(super) local: Pose,
    pub(super) shape: SharedShape,
    /// The shape's kind after shrinking, for its box in closed form.
    pub(super) kind: ShapeKind,
}

impl Prepared {
    pub(super) fn new(s: &LinkShape, margin: f32) -> Prepared {
        let (local, shape, kind) = shrunk(s, margin);
        Prepared { local, shape, kind }
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
    placed[i].1.intersects(&placed[j].1)
        && query::intersection_test(&placed[i].0, &*arm[i].shape, &placed[j].0, &*arm[j].shape).is_ok_and(|x| x.intersecting)
}
