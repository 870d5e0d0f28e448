//! Fits and fasteners as CAD draws them: coaxial cylinders of two parts, classified, and the
//! motions a mechanic would use to take them apart.
//!
//! CAD draws a bolt in its nut, a screw in its tapped hole, a pin in its bore at one nominal
//! radius (or a thread's depth apart) and without the helix. Tessellated, two differently
//! faceted circles of one radius overlap by up to the sum of their chords' sagittas, and a
//! rule that lets no part enter material it did not already overlap forbids the one motion a
//! mechanic makes: along the axis. This module finds every such pair ([`recognise`] the parts'
//! cylinders, from the file's B-rep or from the triangles; pair a shaft with a hole about one
//! axis), classifies it by the radii ([`FitClass`]), and says which part must turn to move along
//! the axis ([`Fit::turns`]: a nut on its bolt, a screw in its tapped hole). The collision world
//! then tests the pair along the axis with the *fit band* exempt: surface samples of either part
//! whose distance from the axis lies within the fit's radii ([`Fit::band`]) carry the fit along;
//! every other sample still may not enter new material (a bolt's head cannot pass its plate, a
//! stepped shaft cannot pass its bore). Across the axis nothing changes: a dowel never slides
//! sideways through its bore.

pub mod recognise;

use crate::math::Vec3;
use crate::surface::SurfaceSource;

/// A cylindrical face of a part (world frame, metres).
#[derive(Clone, Debug, PartialEq)]
pub struct Cylinder {
    /// A point on the axis.
    pub point: Vec3,
    /// Unit axis direction.
    pub axis: Vec3,
    /// The radius.
    pub radius: f32,
    /// Material inside the cylinder (a shaft, a pin, a bolt's shank) rather than outside it (a
    /// hole, a bore, a nut's thread).
    pub convex: bool,
    /// How far the face's triangles stray from the surface (the chords' sagitta).
    pub tolerance: f32,
    /// The face's range along the axis, measured from `point`.
    pub extent: (f32, f32),
    /// The face's area.
    pub area: f32,
    /// The face's triangles (indices into the part's welded collision mesh).
    pub triangles: Vec<u32>,
    /// Where the surface comes from.
    pub source: SurfaceSource,
}

impl Cylinder {
    /// The face's range along the unit direction `axis` (parallel to its own), measured from
    /// the origin.
    fn span_along(&self, axis: Vec3) -> (f32, f32) {
        let s = self.axis.dot(axis).signum();
        let base = self.point.dot(axis);
        let (a, b) = (base + s * self.extent.0, base + s * self.extent.1);
        (a.min(b), a.max(b))
    }
}

/// A planar face of a part.
#[derive(Clone, Debug, PartialEq)]
pub struct Plane {
    /// A point on the plane.
    pub point: Vec3,
    /// Unit outward normal.
    pub normal: Vec3,
    /// The face's area.
    pub area: f32,
    /// The face's triangles (indices into the part's welded collision mesh).
    pub triangles: Vec<u32>,
    /// Where the surface comes from.
    pub source: SurfaceSource,
}

/// The cylinders and planes of one part.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Surfaces {
    /// Cylindrical faces.
    pub cylinders: Vec<Cylinder>,
    /// Planar faces.
    pub planes: Vec<Plane>,
}

/// How a shaft sits in a hole about one axis, by the radii (the plan JSON's names in brackets).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FitClass {
    /// The hole is larger than the shaft beyond the tessellation (`clearance`).
    Clearance,
    /// One nominal radius: the faceted surfaces overlap by no more than their sagittas
    /// (`line_to_line`: a bolt in its nut or its clearance hole as CAD draws it).
    LineToLine,
    /// The shaft is larger than its hole by a small interference (`press`: a pressed pin, a
    /// shaft pressed into a body).
    Press,
    /// The shaft is larger than its hole by about a thread's depth (`thread`: a screw drawn at
    /// its major diameter in a tapped hole drawn at the minor diameter, no helix).
    Thread,
}

impl FitClass {
    /// The class's name in the plan JSON and the tables.
    pub fn name(self) -> &'static str {
        match self {
            FitClass::Clearance => "clearance",
            FitClass::LineToLine => "line_to_line",
            FitClass::Press => "press",
            FitClass::Thread => "thread",
        }
    }

    /// Words a mechanical engineer uses for it.
    pub fn describe(self) -> &'static str {
        match self {
            FitClass::Clearance => "clearance fit",
            FitClass::LineToLine => "line-to-line fit (one nominal radius)",
            FitClass::Press => "press fit",
            FitClass::Thread => "thread drawn without its helix",
        }
    }
}

/// What a part is, from its shape and, as a hint, its name.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Role {
    /// A nut: a short prism around a through hole, a little wider than the hole.
    Nut,
    /// A washer: a thin ring.
    Washer,
    /// A bolt, a screw or a stud: a slender shaft, usually with a head.
    Bolt,
    /// A pin or a dowel: a slender shaft without a head.
    Pin,
    /// Anything else.
    Other,
}

impl Role {
    /// The role's name in the plan JSON.
    pub fn name(self) -> &'static str {
        match self {
            Role::Nut => "nut",
            Role::Washer => "washer",
            Role::Bolt => "bolt",
            Role::Pin => "pin",
            Role::Other => "other",
        }
    }

    /// Whether the part is a fastener (bolt, screw, nut, washer, pin).
    pub fn is_fastener(self) -> bool {
        self != Role::Other
    }
}

/// A shaft of one part in a hole of another about one axis.
#[derive(Clone, Debug, PartialEq)]
pub struct Fit {
    /// The part with the shaft.
    pub shaft: usize,
    /// The part with the hole.
    pub hole: usize,
    /// A point on the shaft's axis.
    pub point: Vec3,
    /// Unit axis direction.
    pub axis: Vec3,
    /// The shaft's radius.
    pub shaft_radius: f32,
    /// The hole's radius.
    pub hole_radius: f32,
    /// How far the two axes lie apart.
    pub offset: f32,
    /// The class by the radii.
    pub class: FitClass,
    /// The radii (from the axis) between which the two parts' surfaces meet: a surface sample
    /// there that enters the other part while the pair moves along the axis carries the fit along.
    pub band: (f32, f32),
    /// The part that must turn to move along the axis against the other (a nut on its bolt, a
    /// screw in its tapped hole): the other part cannot slide along the axis while it is present,
    /// and its own removal along the axis is a `screw` motion. `None`: either slides.
    pub turns: Option<usize>,
}

impl Fit {
    /// Whether the pair's motion along unit `dir` runs along this fit's axis.
    pub fn along(&self, dir: Vec3) -> bool {
        self.axis.dot(dir).abs() > ALONG
    }

    /// Whether `x` lies within the fit's band (its distance from the axis between the band's radii).
    pub fn in_band(&self, x: Vec3) -> bool {
        let r = crate::surface::radial(x, self.point, self.axis);
        r >= self.band.0 && r <= self.band.1
    }

    /// The other part of the fit.
    pub fn other(&self, p: usize) -> usize {
        if p == self.shaft {
            self.hole
        } else {
            self.shaft
        }
    }
}

/// A motion runs along a fit's axis when their cosine exceeds this (about 0.8°).
pub const ALONG: f32 = 0.9999;
/// Two cylinders are coaxial when their axes' directions differ by less than this (degrees)...
const PARALLEL_DEG: f32 = 1.5;
/// ...and their axes lie apart by less than this fraction of the smaller radius (a pin in
/// holes drawn a little off its axis).
const MAX_OFFSET: f32 = 0.1;
/// The most a press fit's shaft exceeds its hole, as a fraction of the radius (beyond it, and up
/// to [`MAX_THREAD`], a thread's depth).
const MAX_PRESS: f32 = 0.03;
/// The most a thread drawn at the minor diameter exceeds its hole, as a fraction of the radius
/// (a coarse metric thread: about 0.17).
const MAX_THREAD: f32 = 0.25;

/// The fits between part `p` (surfaces `sp`, role `rp`) and part `q` (`sq`, `rq`): every shaft of
/// one coaxial with a hole of the other whose faces share a stretch of the axis, classified by
/// the radii; `tolerance` is the world's contact tolerance. A clearance fit is kept only when
/// the gap is within `max_gap` (the contact distance): the axis is then a motion to try.
#[allow(clippy::too_many_arguments)] // two parts' surfaces and roles, the tolerances
pub fn fits_between(p: usize, sp: &Surfaces, rp: Role, q: usize, sq: &Surfaces, rq: Role, tolerance: f32, max_gap: f32) -> Vec<Fit> {
    let mut out: Vec<Fit> = Vec::new();
    let parallel = PARALLEL_DEG.to_radians().cos();
    for (shaft, ss, rs, hole, sh, rh) in [(p, sp, rp, q, sq, rq), (q, sq, rq, p, sp, rp)] {
        for a in ss.cylinders.iter().filter(|c| c.convex) {
            for b in sh.cylinders.iter().filter(|c| !c.convex) {
                if a.axis.dot(b.axis).abs() < parallel {
                    continue;
                }
                let offset = crate::surface::radial(b.point, a.point, a.axis);
                if offset > MAX_OFFSET * a.radius.min(b.radius) {
                    continue;
                }
                let (sa, sb) = (a.span_along(a.axis), b.span_along(a.axis));
                if sa.1.min(sb.1) - sa.0.max(sb.0) <= tolerance {
                    continue; // no shared stretch of the axis
                }
                let sag = a.tolerance + b.tolerance;
                let delta = a.radius - b.radius; // > 0: interference
                let class = if delta < -(sag + offset + 2.0 * tolerance) {
                    if -delta - sag > max_gap {
                        continue;
                    }
                    FitClass::Clearance
                } else if delta <= sag + offset + 2.0 * tolerance {
                    FitClass::LineToLine
                } else if delta <= MAX_PRESS * a.radius + sag + offset {
                    FitClass::Press
                } else if delta <= MAX_THREAD * a.radius {
                    FitClass::Thread
                } else {
                    continue; // real interpenetration, not a fit
                };
                let margin = 2.0 * tolerance + offset;
                let band = (a.radius.min(b.radius) - sag - margin, a.radius.max(b.radius) + margin);
                let turns = match (class, rs, rh) {
                    (_, Role::Bolt, Role::Nut) | (_, Role::Pin, Role::Nut) => Some(hole),
                    (FitClass::Thread, Role::Bolt | Role::Pin, _) => Some(shaft),
                    _ => None,
                };
                // one fit per pair, axis and radius (a stepped shaft in a stepped bore has one
                // per step): the tightest class wins, bands that meet join
                if let Some(f) = out.iter_mut().find(|f| {
                    f.axis.dot(a.axis).abs() >= parallel
                        && crate::surface::radial(a.point, f.point, f.axis) <= MAX_OFFSET * a.radius
                        && f.band.0 <= band.1
                        && band.0 <= f.band.1
                }) {
                    if (f.shaft, f.hole) == (shaft, hole) {
                        f.band = (f.band.0.min(band.0), f.band.1.max(band.1));
                        if class > f.class {
                            f.class = class;
                            f.turns = turns.or(f.turns);
                        }
                        continue;
                    }
                }
                out.push(Fit {
                    shaft,
                    hole,
                    point: a.point,
                    axis: a.axis,
                    shaft_radius: a.radius,
                    hole_radius: b.radius,
                    offset,
                    class,
                    band,
                    turns,
                });
            }
        }
    }
    out
}

/// What part `name` with surfaces `s` and bounding box `aabb` is ([`Role`]): its shape decides,
/// its name breaks ties (a thin ring named "nut" is still a washer; a ring named "washer" is one).
pub fn role(name: &str, s: &Surfaces, vertices: &[Vec3]) -> Role {
    let lower = name.to_ascii_lowercase();
    let named = |words: &[&str]| words.iter().any(|w| lower.contains(w));
    // the part's extent along and about each of its cylinders' axes
    let about = |c: &Cylinder| {
        let (mut lo, mut hi, mut r) = (f32::INFINITY, f32::NEG_INFINITY, 0.0f32);
        for &v in vertices {
            let h = (v - c.point).dot(c.axis);
            lo = lo.min(h);
            hi = hi.max(h);
            r = r.max(crate::surface::radial(v, c.point, c.axis));
        }
        (hi - lo, r)
    };
    // a ring: a hole through the whole part, the part not much wider than the hole
    for c in s.cylinders.iter().filter(|c| !c.convex) {
        let (length, outer) = about(c);
        let through = c.extent.1 - c.extent.0 >= 0.8 * length;
        let d = 2.0 * c.radius;
        if !through || outer > 1.4 * d {
            continue;
        }
        if length <= 0.3 * d || named(&["washer"]) {
            return Role::Washer;
        }
        if length <= 1.6 * d {
            return Role::Nut;
        }
    }
    // a shaft running most of the part's length, slender
    let shafts = s.cylinders.iter().filter(|c| c.convex);
    if let Some(c) = shafts.max_by(|a, b| (a.extent.1 - a.extent.0).total_cmp(&(b.extent.1 - b.extent.0))) {
        let (length, outer) = about(c);
        let shank = c.extent.1 - c.extent.0;
        let d = 2.0 * c.radius;
        if shank >= 1.5 * d && shank >= 0.5 * length && outer <= 2.5 * c.radius {
            let headed = outer > 1.2 * c.radius;
            return if headed || named(&["bolt", "screw", "stud"]) { Role::Bolt } else { Role::Pin };
        }
    }
    Role::Other
}
