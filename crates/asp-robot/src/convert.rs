//! The one place where asp's math types (glam, f32) and the kinematics' types (nalgebra, f64)
//! meet. Everything public in this crate speaks [`asp_geom::math`]; everything inside computes in
//! nalgebra f64 and converts here.

use asp_geom::math::{Pose, Rot, Vec3};
use nalgebra::{Isometry3, Quaternion, Translation3, UnitQuaternion, Vector3};

/// An asp vector as a nalgebra f64 vector.
pub fn vec_to_na(v: Vec3) -> Vector3<f64> {
    Vector3::new(v.x as f64, v.y as f64, v.z as f64)
}

/// A nalgebra f64 vector as an asp vector.
pub fn vec_from_na(v: &Vector3<f64>) -> Vec3 {
    Vec3::new(v.x as f32, v.y as f32, v.z as f32)
}

/// An asp rotation as a nalgebra unit quaternion.
pub fn rot_to_na(r: Rot) -> UnitQuaternion<f64> {
    UnitQuaternion::from_quaternion(Quaternion::new(r.w as f64, r.x as f64, r.y as f64, r.z as f64))
}

/// A nalgebra unit quaternion as an asp rotation.
pub fn rot_from_na(q: &UnitQuaternion<f64>) -> Rot {
    let q = q.quaternion();
    Rot::from_xyzw(q.i as f32, q.j as f32, q.k as f32, q.w as f32).normalize()
}

/// An asp pose as a nalgebra isometry.
pub fn pose_to_na(p: &Pose) -> Isometry3<f64> {
    Isometry3::from_parts(Translation3::from(vec_to_na(p.translation)), rot_to_na(p.rotation))
}

/// A nalgebra isometry as an asp pose.
pub fn pose_from_na(p: &Isometry3<f64>) -> Pose {
    Pose::from_parts(vec_from_na(&p.translation.vector), rot_from_na(&p.rotation))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip_keeps_pose() {
        let p = Pose::from_parts(Vec3::new(0.1, -0.2, 0.3), Rot::from_axis_angle(Vec3::new(1.0, 2.0, 3.0).normalize(), 0.7));
        let q = pose_from_na(&pose_to_na(&p));
        assert!((p.translation - q.translation).length() < 1e-6);
        assert!(p.rotation.angle_between(q.rotation) < 1e-5);
        // The same point maps the same way through both representations.
        let x = Vec3::new(0.3, 0.1, -0.4);
        let a = p.transform_point(x);
        let b = pose_to_na(&p) * nalgebra::Point3::new(0.3, 0.1, -0.4);
        assert!((a - vec_from_na(&b.coords)).length() < 1e-6);
    }
}
