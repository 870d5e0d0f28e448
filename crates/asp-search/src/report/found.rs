//! What the collision world found in the model, as the plan JSON reports it: the input overlaps
//! and their handling (format 1.5), the fits (1.12), the rolling bearings (1.13) and the
//! components drawn as several solids (1.14). Each entry is read from the world's components,
//! so the report says what the tests used.

use crate::vocabulary::vocabulary;
use asp_geom::overlap::{OverlapClass, OverlapHandling, OverlapPolicy};
use serde::{Deserialize, Serialize};

/// The input overlaps of a plan (format 1.5).
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct OverlapsEntry {
    /// The overlap policy: `strict`, `lenient` or `error`.
    pub policy: OverlapPolicy,
    /// One entry per overlapping pair.
    pub pairs: Vec<OverlapPair>,
}

/// One pair of parts that overlap in the input.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct OverlapPair {
    /// The two part indices (low, high).
    pub parts: [usize; 2],
    /// Their names.
    pub names: [String; 2],
    /// `crossing`, `nested` or `coincident`.
    pub kind: OverlapKindName,
    /// For `nested`: the part that lies inside the other.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub inner: Option<usize>,
    /// The measured depth in model units: the least shrinking that separates them, or for
    /// `gross` pairs how deep each surface lies inside the other where they overlap (since 1.13;
    /// before, the largest shrinking tried; still that, a lower bound, when `depth_bound`).
    pub depth: f64,
    /// `depth` is a lower bound: a gross pair whose overlap no surface sample found. Since 1.13,
    /// only when true.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub depth_bound: bool,
    /// No shrinking of either part up to 40 % of its thickness separates them.
    pub gross: bool,
    /// `strict` (they separate only along motions that enter no new material), `shrunk` or
    /// `ignored`.
    pub handling: OverlapHandling,
    /// What the pair is by the shape of its overlap: `fit` (a coaxial fit, listed in `fits`),
    /// `tessellation` (two faceted round faces of one surface, no deeper than their sagittas), `planar_slab` (a panel sunk into
    /// another between parallel planar faces) or `interpenetration`. Since 1.13.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub class: Option<OverlapClass>,
    /// For a `planar_slab`: its unit normal, the outward normal of the first part's face (the
    /// second part lifts off the first along it). Since 1.13.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub normal: Option<[f64; 3]>,
}

impl OverlapsEntry {
    /// The overlaps `world` measured; `None` when no pair overlaps.
    pub fn of(world: &asp_geom::World) -> Option<OverlapsEntry> {
        let notes = world.overlaps().notes();
        if notes.is_empty() {
            return None;
        }
        let units = &world.assembly().units;
        let pairs = notes
            .iter()
            .map(|n| OverlapPair {
                parts: [n.parts.0, n.parts.1],
                names: [world.name(n.parts.0).to_string(), world.name(n.parts.1).to_string()],
                kind: match n.kind {
                    asp_geom::overlap::OverlapKind::Crossing => OverlapKindName::Crossing,
                    asp_geom::overlap::OverlapKind::Nested { .. } => OverlapKindName::Nested,
                    asp_geom::overlap::OverlapKind::Coincident => OverlapKindName::Coincident,
                },
                inner: match n.kind {
                    asp_geom::overlap::OverlapKind::Nested { inner } => Some(inner),
                    _ => None,
                },
                depth: units.from_metres(n.depth as f64),
                depth_bound: n.bound,
                gross: n.gross,
                handling: n.handling,
                class: Some(n.class),
                normal: n.normal.map(|v| [v.x as f64, v.y as f64, v.z as f64]),
            })
            .collect();
        Some(OverlapsEntry { policy: world.overlaps().policy(), pairs })
    }
}

/// One coaxial fit of a plan (format 1.10): a shaft of one part in a hole of another.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct FitEntry {
    /// The part with the shaft and the part with the hole.
    pub parts: [usize; 2],
    /// Their names.
    pub names: [String; 2],
    /// `clearance`, `line_to_line`, `press` or `thread` (a thread drawn without its helix).
    pub class: asp_geom::fits::FitClass,
    /// A point on the axis, model units.
    pub point: [f64; 3],
    /// The axis direction (unit).
    pub axis: [f64; 3],
    /// The shaft's and the hole's radius, model units.
    pub radii: [f64; 2],
    /// What each part is: `bolt`, `nut`, `washer`, `pin` or `other`.
    pub roles: [asp_geom::fits::Role; 2],
    /// The part that turns to move along the axis (a nut on its bolt, a screw in its tapped
    /// hole); the other cannot slide along the axis while it is present. Absent: either slides.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub turns: Option<usize>,
}

impl FitEntry {
    /// Every fit `world` found, in pair order.
    pub fn of(world: &asp_geom::World) -> Vec<FitEntry> {
        let units = &world.assembly().units;
        let len = |m: f32| units.from_metres(m as f64);
        let v = |x: asp_geom::math::Vec3| [x.x as f64, x.y as f64, x.z as f64];
        world
            .overlaps()
            .fits()
            .all()
            .values()
            .flatten()
            .map(|f| FitEntry {
                parts: [f.shaft, f.hole],
                names: [world.name(f.shaft).to_string(), world.name(f.hole).to_string()],
                class: f.class,
                point: v(f.point).map(|c| units.from_metres(c)),
                axis: v(f.axis),
                radii: [len(f.shaft_radius), len(f.hole_radius)],
                roles: [world.overlaps().fits().role(f.shaft), world.overlaps().fits().role(f.hole)],
                turns: f.turns,
            })
            .collect()
    }
}

/// A rolling bearing of a plan (format 1.12): balls (or, since 1.14, rollers) captive between an
/// inner and an outer ring (plus a cage, shields), recognised from the geometry and planned as one
/// unit, never taken apart.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct BearingEntry {
    /// Every part of the bearing, ascending.
    pub parts: Vec<usize>,
    /// The inner ring and the outer ring.
    pub rings: [usize; 2],
    /// Their names.
    pub names: [String; 2],
    /// The rolling elements (balls or rollers, as `rolling_elements` says).
    pub balls: Vec<usize>,
    /// What rolls: `balls` or `rollers` (since 1.14; absent before, and then balls).
    #[serde(default = "balls_name")]
    pub rolling_elements: String,
    /// The other parts held with the balls (cage, shields, seals).
    pub others: Vec<usize>,
    /// The centre of the balls' centres, model units.
    pub centre: [f64; 3],
    /// The bearing's axis (unit; either sign).
    pub axis: [f64; 3],
    /// The radius of the circle through the balls' centres, model units.
    pub pitch_radius: f64,
    /// The balls' radius (the rollers' mean radius), model units.
    pub ball_radius: f64,
    /// The rows of rolling elements.
    pub rows: usize,
}

/// What a bearing of a plan written before 1.14 rolls on.
fn balls_name() -> String {
    "balls".into()
}

impl BearingEntry {
    /// Every bearing `world` found.
    pub fn of(world: &asp_geom::World) -> Vec<BearingEntry> {
        let units = &world.assembly().units;
        let len = |m: f32| units.from_metres(m as f64);
        world
            .overlaps()
            .fits()
            .bearings()
            .iter()
            .map(|b| BearingEntry {
                parts: b.parts(),
                rings: b.rings,
                names: b.rings.map(|p| world.name(p).to_string()),
                balls: b.balls.clone(),
                rolling_elements: b.elements.plural().into(),
                others: b.others.clone(),
                centre: [b.centre.x, b.centre.y, b.centre.z].map(len),
                axis: [b.axis.x as f64, b.axis.y as f64, b.axis.z as f64],
                pitch_radius: len(b.pitch_radius),
                ball_radius: len(b.ball_radius),
                rows: b.rows,
            })
            .collect()
    }
}

/// A component of a plan drawn as several solids of one product that interpenetrate (format
/// 1.14; [`asp_geom::world::Overlaps::fused_components`]): planned as one unit, never taken apart.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct ComponentEntry {
    /// Its parts, ascending (the unit's parts).
    pub parts: Vec<usize>,
    /// Their names.
    pub names: Vec<String>,
    /// The product of the file's tree that holds them (the last name of their path).
    pub product: String,
}

impl ComponentEntry {
    /// Every component drawn as several solids that `world` found.
    pub fn of(world: &asp_geom::World) -> Vec<ComponentEntry> {
        world
            .overlaps()
            .fused_components()
            .iter()
            .cloned()
            .map(|parts| ComponentEntry {
                names: parts.iter().map(|&p| world.name(p).to_string()).collect(),
                product: world.assembly().parts[parts[0]].path.last().cloned().unwrap_or_default(),
                parts,
            })
            .collect()
    }
}

vocabulary! {
    /// How two overlapping parts lie in each other (`overlaps.pairs[].kind`).
    OverlapKindName {
        /// Their surfaces cross.
        Crossing => "crossing",
        /// One lies wholly inside the other (`inner`).
        Nested => "nested",
        /// They occupy the same space.
        Coincident => "coincident",
    }
}
