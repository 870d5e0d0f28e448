//! Spheres that cover a link's collision shapes: the arm as the fast arm planners see it.
//!
//! [`cover`] returns spheres whose union holds every point of a shape (conservative: a point of
//! the link outside every sphere does not exist), [`enclosing`] one sphere around the whole
//! shape. The removal planner builds both once per planner from the robot's collision shapes
//! (shrunk by its margin) and tests spheres against the parts before it tests a shape exactly:
//! a shape none of whose spheres comes near a part cannot touch it, so the exact test runs only
//! where a sphere does, and the verdict is the exact one ([`crate::removal`]).
//!
//! How each primitive is covered (all along its own z axis, as in URDF; `piece` is the longest
//! piece one sphere covers):
//! * **box** with half extents `h`: cut into `n_i = ceil(2 h_i / piece)` equal cells per axis;
//!   one sphere per cell at its centre with the cell's half diagonal as radius (a cell is the
//!   set of points within its half extents of its centre, hence within its half diagonal);
//! * **capsule** of radius `r` around the segment `z ∈ [−l, l]`: `n = ceil(2 l / piece)` equal
//!   steps, a sphere at each of the `n + 1` ends of the steps with radius `sqrt(r² + (l/n)²)`.
//!   A point `x` of the capsule is within `r` of its nearest segment point `s`, which is within
//!   `l/n` of a centre `c` along the axis; in the cylindrical part `x − s` is perpendicular to
//!   the axis, so `|x − c|² = |x − s|² + |s − c|² ≤ r² + (l/n)²`; in a cap `s` is an end, which
//!   is a centre, so `|x − c| ≤ r`;
//! * **cylinder** of radius `r`, half length `l`: `n = ceil(2 l / piece)` slices of half length
//!   `l/n`, a sphere at each slice's centre with radius `sqrt(r² + (l/n)²)` (a slice's point is
//!   at most `r` off the axis and `l/n` along it from the slice's centre);
//! * **sphere**: itself.
//!
//! Every radius is then grown by [`SPHERE_SLACK`], which covers the rounding of forward
//! kinematics in `f32` (the planner's sphere centres) against `f64` (the exact test's poses).

use asp_geom::math::{Pose, Vec3};

use crate::shape::{LinkShape, ShapeKind};

/// The longest piece of a shape one sphere covers by default, metres.
pub const SPHERE_PIECE: f32 = 0.04;

/// What every covering radius is grown by, metres: more than the error of a link pose computed
/// in `f32` on a chain of a few metres (about 1 µm).
pub const SPHERE_SLACK: f32 = 1e-5;

/// A sphere: centre and radius, metres, in the frame of the link or body that carries it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sphere {
    /// The centre.
    pub centre: Vec3,
    /// The radius.
    pub radius: f32,
}

impl Sphere {
    /// The sphere moved by `pose`.
    pub fn transformed(&self, pose: &Pose) -> Sphere {
        Sphere { centre: pose.transform_point(self.centre), radius: self.radius }
    }

    /// Whether `x` lies inside (or on) the sphere.
    pub fn contains(&self, x: Vec3) -> bool {
        (x - self.centre).length_squared() <= self.radius * self.radius
    }
}

/// Spheres, in the frame of the shape's link, whose union holds every point of `shape` (see the
/// module documentation for how each primitive is cut); no piece longer than `piece` metres.
pub fn cover(shape: &LinkShape, piece: f32) -> Vec<Sphere> {
    let piece = if piece.is_finite() && piece > 0.0 { piece } else { SPHERE_PIECE };
    let pieces = |len: f32| ((len / piece).ceil().max(1.0) as usize).min(1 << 10);
    let mut local = Vec::new();
    match shape.kind {
        ShapeKind::Box { half_extents: h } => {
            let n = [pieces(2.0 * h.x), pieces(2.0 * h.y), pieces(2.0 * h.z)];
            let cell = Vec3::new(h.x / n[0] as f32, h.y / n[1] as f32, h.z / n[2] as f32);
            let radius = cell.length();
            for i in 0..n[0] {
                for j in 0..n[1] {
                    for k in 0..n[2] {
                        let at = |m: usize, half: f32, c: f32| -half + c * (2 * m + 1) as f32;
                        let centre = Vec3::new(at(i, h.x, cell.x), at(j, h.y, cell.y), at(k, h.z, cell.z));
                        local.push(Sphere { centre, radius });
                    }
                }
            }
        }
        ShapeKind::Capsule { radius, half_length } => {
            let n = pieces(2.0 * half_length);
            let step = 2.0 * half_length / n as f32;
            let r = (radius * radius + (0.5 * step) * (0.5 * step)).sqrt();
            for k in 0..=n {
                local.push(Sphere { centre: Vec3::new(0.0, 0.0, -half_length + step * k as f32), radius: r });
            }
        }
        ShapeKind::Cylinder { radius, half_length } => {
            let n = pieces(2.0 * half_length);
            let half = half_length / n as f32;
            let r = (radius * radius + half * half).sqrt();
            for k in 0..n {
                local.push(Sphere { centre: Vec3::new(0.0, 0.0, -half_length + half * (2 * k + 1) as f32), radius: r });
            }
        }
        ShapeKind::Sphere { radius } => local.push(Sphere { centre: Vec3::ZERO, radius }),
    }
    local.into_iter().map(|s| Sphere { centre: shape.local_pose.transform_point(s.centre), radius: s.radius + SPHERE_SLACK }).collect()
}

/// One sphere around the whole of `shape`, in the frame of its link: centred on the shape, with
/// the distance to its farthest point as radius (grown by [`SPHERE_SLACK`]).
pub fn enclosing(shape: &LinkShape) -> Sphere {
    let radius = match shape.kind {
        ShapeKind::Box { half_extents } => half_extents.length(),
        ShapeKind::Capsule { radius, half_length } => radius + half_length,
        ShapeKind::Cylinder { radius, half_length } => (radius * radius + half_length * half_length).sqrt(),
        ShapeKind::Sphere { radius } => radius,
    };
    Sphere { centre: shape.local_pose.translation, radius: radius + SPHERE_SLACK }
}

#[cfg(test)]
mod tests {
    use super::*;
    use asp_geom::math::Rot;
    use rand::{RngExt, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    fn shapes() -> Vec<LinkShape> {
        let pose = Pose::from_parts(Vec3::new(0.1, -0.05, 0.2), Rot::from_axis_angle(Vec3::new(1.0, 2.0, 0.5).normalize(), 0.9));
        [
            ShapeKind::Box { half_extents: Vec3::new(0.03, 0.1, 0.0292) },
            ShapeKind::Box { half_extents: Vec3::new(0.01, 0.01, 0.0273) },
            ShapeKind::Capsule { radius: 0.06, half_length: 0.1 },
            ShapeKind::Capsule { radius: 0.05, half_length: 0.0 },
            ShapeKind::Cylinder { radius: 0.06, half_length: 0.1 },
            ShapeKind::Sphere { radius: 0.02 },
        ]
        .into_iter()
        .map(|kind| LinkShape { local_pose: pose, kind })
        .collect()
    }

    /// Random points of the shape (its own frame): inside the box, capsule, cylinder or ball,
    /// surface points included.
    fn points(kind: ShapeKind, rng: &mut ChaCha8Rng) -> Vec<Vec3> {
        let mut out = Vec::new();
        let bound = match kind {
            ShapeKind::Box { half_extents } => half_extents,
            ShapeKind::Capsule { radius, half_length } => Vec3::new(radius, radius, radius + half_length),
            ShapeKind::Cylinder { radius, half_length } => Vec3::new(radius, radius, half_length),
            ShapeKind::Sphere { radius } => Vec3::splat(radius),
        };
        while out.len() < 4000 {
            let mut x = Vec3::new(rng.random_range(-1.0..=1.0), rng.random_range(-1.0..=1.0), rng.random_range(-1.0..=1.0)) * bound;
            // every fourth point pushed onto the surface (the worst case for a cover)
            let inside = |x: Vec3| match kind {
                ShapeKind::Box { .. } => true,
                ShapeKind::Capsule { radius, half_length } => {
                    let s = Vec3::new(0.0, 0.0, x.z.clamp(-half_length, half_length));
                    (x - s).length() <= radius
                }
                ShapeKind::Cylinder { radius, .. } => x.truncate().length() <= radius,
                ShapeKind::Sphere { radius } => x.length() <= radius,
            };
            if !inside(x) {
                continue;
            }
            if out.len() % 4 == 0 {
                match kind {
                    ShapeKind::Box { half_extents } => x.x = half_extents.x.copysign(x.x),
                    ShapeKind::Capsule { radius, half_length } => {
                        let s = Vec3::new(0.0, 0.0, x.z.clamp(-half_length, half_length));
                        x = s + (x - s).normalize_or(Vec3::X) * radius;
                    }
                    ShapeKind::Cylinder { radius, .. } => {
                        let t = x.truncate().normalize_or(parry3d::math::Vec2::X) * radius;
                        x = Vec3::new(t.x, t.y, x.z);
                    }
                    ShapeKind::Sphere { radius } => x = x.normalize_or(Vec3::X) * radius,
                }
            }
            out.push(x);
        }
        out
    }

    #[test]
    fn every_point_of_a_shape_lies_in_one_of_its_spheres() {
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        for shape in shapes() {
            for piece in [0.02, 0.04, 0.5] {
                let spheres = cover(&shape, piece);
                let around = enclosing(&shape);
                for x in points(shape.kind, &mut rng) {
                    let w = shape.local_pose.transform_point(x);
                    assert!(spheres.iter().any(|s| s.contains(w)), "{:?} piece {piece}: {x} not covered", shape.kind);
                    assert!(around.contains(w), "{:?}: {x} outside the enclosing sphere", shape.kind);
                }
            }
        }
    }

    #[test]
    fn covers_are_tight_enough_to_be_worth_testing() {
        // a capsule of radius 6 cm cut every 4 cm: spheres at most 6.4 cm, one per 4 cm and both ends
        let capsule = LinkShape { local_pose: Pose::IDENTITY, kind: ShapeKind::Capsule { radius: 0.06, half_length: 0.1 } };
        let s = cover(&capsule, 0.04);
        assert_eq!(s.len(), 6);
        assert!(s.iter().all(|s| s.radius < 0.0641), "{s:?}");
        // a 2 x 2 x 5.5 cm finger: two spheres of the half diagonal of 2 x 2 x 2.7 cm cells
        let finger = LinkShape { local_pose: Pose::IDENTITY, kind: ShapeKind::Box { half_extents: Vec3::new(0.01, 0.01, 0.0273) } };
        let s = cover(&finger, 0.04);
        assert_eq!(s.len(), 2);
        assert!((s[0].radius - (0.01f32 * 0.01 * 2.0 + 0.01365 * 0.01365).sqrt()).abs() < 2e-5);
    }
}
