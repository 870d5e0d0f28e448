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
}
