//! The travel of a straight removal: how far a box moves along a direction until it clears the
//! bounds of what remains, plus the contact distance. One rule, shared by the collision world's
//! removal tests ([`super::Removal::clearance`]) and the voxel checker ([`crate::voxel`]), so
//! their motions agree to the bit.

use crate::math::{Aabb, Vec3};

/// How far box `a` travels along unit `dir` until it clears the bounds `others` (its own
/// starting bounds when `None`), plus `contact_distance`.
pub(crate) fn clearance_past(a: &Aabb, others: Option<Aabb>, dir: Vec3, contact_distance: f32) -> f32 {
    let others = others.unwrap_or(*a);
    let t = (0..3)
        .filter(|&i| dir[i].abs() > 1e-6)
        .map(|i| if dir[i] > 0.0 { (others.maxs[i] - a.mins[i]) / dir[i] } else { (a.maxs[i] - others.mins[i]) / -dir[i] })
        .fold(f32::INFINITY, f32::min)
        .max(0.0);
    t + contact_distance
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_box_clears_the_rest_along_its_direction_and_itself_when_alone() {
        let a = Aabb::new(Vec3::ZERO, Vec3::ONE);
        let rest = Aabb::new(Vec3::new(-1.0, -1.0, -1.0), Vec3::new(2.0, 3.0, 1.5));
        assert_eq!(clearance_past(&a, Some(rest), Vec3::Z, 0.25), 1.75);
        assert_eq!(clearance_past(&a, Some(rest), -Vec3::Y, 0.0), 2.0);
        // diagonally, the first axis to clear decides
        let d = Vec3::new(1.0, 1.0, 0.0).normalize();
        assert!((clearance_past(&a, Some(rest), d, 0.0) - 2.0 / d.x).abs() < 1e-5);
        // alone, it clears its own bounds
        assert_eq!(clearance_past(&a, None, Vec3::X, 0.5), 1.5);
    }
}
