//! Collision shapes of robot links: the primitives a URDF `<collision>` element can hold.

use asp_geom::math::{Pose, Rot, Vec3};
use parry3d::shape::SharedShape;

/// A primitive collision shape in its own frame. Cylinders and capsules run along their local z
/// axis, as in URDF.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ShapeKind {
    /// A box with these half extents.
    Box {
        /// Half the size along x, y and z.
        half_extents: Vec3,
    },
    /// A cylinder along z.
    Cylinder {
        /// Radius.
        radius: f32,
        /// Half its length.
        half_length: f32,
    },
    /// A capsule along z: a cylinder of `2 * half_length` with hemispheres on both ends.
    Capsule {
        /// Radius.
        radius: f32,
        /// Half the length of its cylindrical part.
        half_length: f32,
    },
    /// A sphere.
    Sphere {
        /// Radius.
        radius: f32,
    },
}

/// One collision shape of a link: the shape and where it sits in the link's frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LinkShape {
    /// The shape's pose in the link frame.
    pub local_pose: Pose,
    /// The shape.
    pub kind: ShapeKind,
}

impl LinkShape {
    /// The shape as a parry shape in its own frame (parry's cylinders run along y, so a cylinder
    /// comes back with the rotation that turns it onto z; compose it with the link pose).
    pub fn to_parry(&self) -> (Pose, SharedShape) {
        match self.kind {
            ShapeKind::Box { half_extents: h } => (Pose::IDENTITY, SharedShape::cuboid(h.x, h.y, h.z)),
            ShapeKind::Sphere { radius } => (Pose::IDENTITY, SharedShape::ball(radius)),
            ShapeKind::Capsule { radius, half_length } => (Pose::IDENTITY, SharedShape::capsule_z(half_length, radius)),
            ShapeKind::Cylinder { radius, half_length } => (
                Pose::from_parts(Vec3::ZERO, Rot::from_rotation_x(std::f32::consts::FRAC_PI_2)),
                SharedShape::cylinder(half_length, radius),
            ),
        }
    }

    /// The parry shape and its world pose, for a link at `link_pose` (world frame).
    pub fn world(&self, link_pose: &Pose) -> (Pose, SharedShape) {
        let (fix, shape) = self.to_parry();
        (*link_pose * self.local_pose * fix, shape)
    }

    /// The largest distance from the link frame's origin to a point of the shape (a bound for
    /// quick rejection tests).
    pub fn reach(&self) -> f32 {
        let c = self.local_pose.translation.length();
        c + match self.kind {
            ShapeKind::Box { half_extents } => half_extents.length(),
            ShapeKind::Cylinder { radius, half_length } => (radius * radius + half_length * half_length).sqrt(),
            ShapeKind::Capsule { radius, half_length } => radius + half_length,
            ShapeKind::Sphere { radius } => radius,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cylinder_runs_along_z() {
        let s = LinkShape { local_pose: Pose::IDENTITY, kind: ShapeKind::Cylinder { radius: 0.05, half_length: 0.2 } };
        let (pose, shape) = s.world(&Pose::IDENTITY);
        assert!(shape.contains_point(&pose, Vec3::new(0.0, 0.0, 0.19)));
        assert!(!shape.contains_point(&pose, Vec3::new(0.0, 0.19, 0.0)));
        let c = LinkShape { local_pose: Pose::IDENTITY, kind: ShapeKind::Capsule { radius: 0.05, half_length: 0.2 } };
        let (pose, shape) = c.world(&Pose::IDENTITY);
        assert!(shape.contains_point(&pose, Vec3::new(0.0, 0.0, 0.24)));
        assert!(!shape.contains_point(&pose, Vec3::new(0.0, 0.24, 0.0)));
    }
}
