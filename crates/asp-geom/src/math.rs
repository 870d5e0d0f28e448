//! The one math vocabulary of asp: parry's glam types (f32).
//!
//! parry3d ≥ 0.26 and rapier3d 0.36 both speak `glamx` (glam) in their public API, so asp uses
//! the same types and never converts on the hot path. All lengths inside asp are metres.

pub use parry3d::bounding_volume::Aabb;
pub use parry3d::math::{Pose3 as Pose, Rot3 as Rot, Vec3};

/// An axis of the model frame with a sign, e.g. `+Z` or `-Y`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
pub struct Axis {
    /// 0 = x, 1 = y, 2 = z.
    pub index: u8,
    /// true for the negative direction.
    pub negative: bool,
}

impl Axis {
    /// +Y, the glTF convention.
    pub const Y: Axis = Axis { index: 1, negative: false };
    /// +Z, the usual CAD convention.
    pub const Z: Axis = Axis { index: 2, negative: false };

    /// The unit vector of this axis.
    pub fn vector(self) -> Vec3 {
        let mut v = Vec3::ZERO;
        v[self.index as usize] = if self.negative { -1.0 } else { 1.0 };
        v
    }

    /// Parses `x`, `+y`, `-z` (case-insensitive).
    pub fn parse(s: &str) -> Option<Axis> {
        let s = s.trim().to_ascii_lowercase();
        let (negative, rest) = match s.strip_prefix('-') {
            Some(r) => (true, r),
            None => (false, s.strip_prefix('+').unwrap_or(&s)),
        };
        let index = match rest {
            "x" => 0,
            "y" => 1,
            "z" => 2,
            _ => return None,
        };
        Some(Axis { index, negative })
    }
}

impl std::fmt::Display for Axis {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let c = ["x", "y", "z"][self.index as usize];
        write!(f, "{}{}", if self.negative { "-" } else { "+" }, c)
    }
}

/// The smallest box holding all `points` (None when there are none).
pub fn aabb_of(points: impl IntoIterator<Item = Vec3>) -> Option<Aabb> {
    let mut it = points.into_iter();
    let first = it.next()?;
    let (mut mins, mut maxs) = (first, first);
    for p in it {
        mins = mins.min(p);
        maxs = maxs.max(p);
    }
    Some(Aabb::new(mins, maxs))
}

/// The interval of times `t >= 0` during which box `moving` translated by `t * dir`
/// overlaps box `fixed` with positive volume (touching faces do not count).
/// Returns `None` when they never overlap.
pub fn sweep_overlap(moving: &Aabb, dir: Vec3, fixed: &Aabb) -> Option<(f32, f32)> {
    let (mut t0, mut t1) = (0.0f32, f32::INFINITY);
    for i in 0..3 {
        // overlap on axis i when fixed.min < moving.max + t d  and  moving.min + t d < fixed.max
        let lo = fixed.mins[i] - moving.maxs[i];
        let hi = fixed.maxs[i] - moving.mins[i];
        let d = dir[i];
        if d.abs() < 1e-9 {
            if !(lo < 0.0 && hi > 0.0) {
                return None;
            }
        } else {
            let (a, b) = if d > 0.0 { (lo / d, hi / d) } else { (hi / d, lo / d) };
            t0 = t0.max(a);
            t1 = t1.min(b);
        }
    }
    (t0 < t1).then_some((t0, t1))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn axis_parse_and_display() {
        assert_eq!(Axis::parse("-Z"), Some(Axis { index: 2, negative: true }));
        assert_eq!(Axis::parse("y"), Some(Axis::Y));
        assert_eq!(Axis::parse("+x").unwrap().to_string(), "+x");
        assert_eq!(Axis::parse("w"), None);
    }

    #[test]
    fn sweep_overlap_of_boxes() {
        let a = Aabb::new(Vec3::ZERO, Vec3::ONE);
        let b = Aabb::new(Vec3::new(0.0, 0.0, 1.0), Vec3::new(1.0, 1.0, 2.0));
        // a moving up runs into b (touching at t = 0, overlapping until t = 2)
        assert_eq!(sweep_overlap(&a, Vec3::Z, &b), Some((0.0, 2.0)));
        // moving down never overlaps
        assert_eq!(sweep_overlap(&a, -Vec3::Z, &b), None);
        // sliding sideways along the shared face never overlaps with volume
        assert_eq!(sweep_overlap(&a, Vec3::X, &b), None);
    }
}
