//! 3D aluminium profile assemblies (thesis 4.1).
//!
//! Frame: x runs along the length L, y along the width W, z up along the height H; the
//! assembly occupies `[0, L] × [0, W] × [0, H]`. The pick-up position q lies in front of it on
//! the −x side, so "front" means small x and "back" large x.
//!
//! Construction: a base cuboid of 12 profiles (corner posts of full height, horizontal profiles
//! between them at the bottom and top); support profiles along z, each standing on a bottom and
//! hanging under a top connection profile; then layers, each a frame of four profiles, back
//! profiles and front profiles. A new horizontal profile is laid at full length, split where it
//! crosses existing profiles, and one random segment at least ε_p long is kept. Wherever a
//! profile's end meets another profile's long side a connector is added as its own part: a
//! U-shaped cradle under horizontal profiles, an O-shaped sleeve around vertical ones. Every
//! placement is checked against all existing boxes; a placement that overlaps, or a profile
//! closer than ε_g to a parallel one, is discarded and drawn again.

use crate::check::{check_disassembly, BoxModel, DisassemblyCheck};
use crate::cuboid::{box_union, grid_union, Cuboid};
use crate::error::{GenError, Result};
use asp_geom::math::Axis;
use asp_geom::{Assembly, Mesh, Part, Units};
use rand::seq::IndexedRandom;
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};
use serde_json::json;

mod build;
use build::Builder;

/// Boxes may interpenetrate by at most this much (metres) and still count as touching.
pub const TOLERANCE: f64 = 1e-6;
/// Draws per profile before the whole assembly is started again.
const TRIES_PER_PROFILE: usize = 200;
/// Fresh starts before generation gives up.
const RESTARTS: usize = 50;

/// Parameters of an aluminium profile assembly; lengths in metres. Defaults are the thesis'
/// single-layer dataset (5.5.1); ε_p, ε_g and the connector and grasp sizes are our choices
/// where the thesis gives no number.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ProfileParams {
    /// W, extent along y.
    pub width: f64,
    /// L, extent along x.
    pub length: f64,
    /// H, extent along z.
    pub height: f64,
    /// Layers of profiles between bottom and top, evenly spaced in height.
    pub layers: usize,
    /// Support profiles along z, one per strip of the width.
    pub supports: usize,
    /// Front profiles per layer.
    pub front: usize,
    /// Back profiles per layer.
    pub back: usize,
    /// Edge of the square profile cross-section (20 mm).
    pub profile_size: f64,
    /// ε_p: the shortest profile; shorter segments are dropped.
    pub min_length: f64,
    /// ε_g: the least distance between the centre lines of parallel profiles (grasp clearance).
    pub grasp_clearance: f64,
    /// Wall thickness of the connectors.
    pub connector_thickness: f64,
    /// How far a connector reaches along the profile it holds.
    pub connector_length: f64,
    /// Distance between neighbouring grasp points along a profile.
    pub grasp_spacing: f64,
    /// Distance kept free of grasp points at both ends of a profile.
    pub grasp_margin: f64,
    /// Whether connectors are parts of their own or travel with the profile they hold (the
    /// thesis' 21- and 30-part assemblies, 5.5.1). Left out of the JSON when `separate`, so
    /// older manifests and batch specs read and write unchanged.
    #[serde(default, skip_serializing_if = "ConnectorMode::is_separate")]
    pub connectors: ConnectorMode,
}

/// How connectors become parts.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ConnectorMode {
    /// Every connector is a part of its own (`u_connector_NN`, `o_connector_NN`).
    #[default]
    Separate,
    /// Every connector is merged into the profile it holds ([`Connector::holds`]): its boxes
    /// join that profile's mesh and box list, and the assembly has only profile parts.
    Attached,
}

impl ConnectorMode {
    /// Whether connectors are parts of their own.
    pub fn is_separate(&self) -> bool {
        *self == ConnectorMode::Separate
    }
}

impl Default for ProfileParams {
    fn default() -> Self {
        ProfileParams::single_layer()
    }
}

impl ProfileParams {
    /// The thesis' single-layer assemblies: 0.4 × 0.4 × 0.6 m, 2 supports, one layer of
    /// 4 back and 3 front profiles: 21 removable profiles.
    pub fn single_layer() -> Self {
        ProfileParams {
            width: 0.4,
            length: 0.4,
            height: 0.6,
            layers: 1,
            supports: 2,
            front: 3,
            back: 4,
            profile_size: 0.02,
            min_length: 0.08,
            grasp_clearance: 0.06,
            connector_thickness: 0.003,
            connector_length: 0.02,
            grasp_spacing: 0.02,
            grasp_margin: 0.03,
            connectors: ConnectorMode::Separate,
        }
    }

    /// The thesis' double-layer assemblies: two layers of 3 back and 3 front profiles each:
    /// 30 removable profiles.
    pub fn double_layer() -> Self {
        ProfileParams { layers: 2, back: 3, ..ProfileParams::single_layer() }
    }

    /// The names of the thesis' data sets, as [`ProfileParams::preset`] takes them.
    pub const PRESETS: [&'static str; 2] = ["single-layer", "double-layer"];

    /// The parameters of a thesis data set by name (`single-layer`, `double-layer`).
    pub fn preset(name: &str) -> Option<Self> {
        match name {
            "single-layer" => Some(Self::single_layer()),
            "double-layer" => Some(Self::double_layer()),
            _ => None,
        }
    }

    /// How many profiles are not fixed: 2 front posts and 4 top profiles of the base, a support
    /// and its top connection per support, and per layer its frame of 4 plus back and front.
    pub fn removable_profiles(&self) -> usize {
        6 + 2 * self.supports + self.layers * (4 + self.back + self.front)
    }

    /// The height of layer `l`'s centre plane.
    pub fn layer_height(&self, l: usize) -> f64 {
        self.height * (l + 1) as f64 / (self.layers + 1) as f64
    }

    /// Checks ranges and that the parts fit at all (generation may still fail to place
    /// many profiles in a small assembly; it then says so).
    pub fn validate(&self) -> Result<()> {
        let lengths = [
            ("width", self.width),
            ("length", self.length),
            ("height", self.height),
            ("profile-size", self.profile_size),
            ("min-length", self.min_length),
            ("grasp-clearance", self.grasp_clearance),
            ("connector-thickness", self.connector_thickness),
            ("connector-length", self.connector_length),
            ("grasp-spacing", self.grasp_spacing),
        ];
        for (name, v) in lengths {
            if !(v.is_finite() && v > 0.0 && v <= 100.0) {
                return Err(GenError::parameter(name, format!("must be a length in (0, 100] metres, got {v}")));
            }
        }
        if !(self.grasp_margin.is_finite() && self.grasp_margin >= 0.0) {
            return Err(GenError::parameter("grasp-margin", format!("must be ≥ 0, got {}", self.grasp_margin)));
        }
        let counts = [("layers", self.layers, 0, 16), ("supports", self.supports, 1, 8)];
        let counts = counts.into_iter().chain([("front", self.front, 0, 32), ("back", self.back, 0, 32)]);
        for (name, v, lo, hi) in counts {
            if !(lo..=hi).contains(&v) {
                return Err(GenError::parameter(name, format!("must be {lo} to {hi}, got {v}")));
            }
        }
        let (d, t, c) = (self.profile_size, self.connector_thickness, self.connector_length);
        if self.min_length <= d {
            return Err(GenError::parameter("min-length", format!("must exceed the profile size {d} m")));
        }
        if c <= 2.0 * t || 2.0 * c > self.min_length {
            return Err(GenError::parameter(
                "connector-length",
                format!("must exceed twice the connector thickness {t} m and be at most half of --min-length"),
            ));
        }
        if self.grasp_clearance < d + 2.0 * t {
            return Err(GenError::parameter(
                "grasp-clearance",
                format!("must be at least the profile size plus two connector walls ({} m)", d + 2.0 * t),
            ));
        }
        let strips = self.supports.max(2) as f64;
        if self.width <= strips * self.min_length {
            return Err(GenError::parameter(
                "width",
                format!("must exceed {} × min-length so every support has room", self.supports.max(2)),
            ));
        }
        if self.length <= 2.0 * self.min_length {
            return Err(GenError::parameter("length", "must exceed 2 × min-length so supports have room"));
        }
        let spacing = self.height / (self.layers + 1) as f64;
        if spacing - d / 2.0 - c - t < self.grasp_clearance || self.height - 2.0 * d < self.min_length {
            return Err(GenError::parameter(
                "height",
                format!("too low for {} layers: layers must lie at least --grasp-clearance apart", self.layers),
            ));
        }
        Ok(())
    }
}

/// What a profile is for.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Role {
    /// One of the 12 profiles of the base cuboid.
    Base,
    /// A horizontal profile at the bottom or top that a support stands on or hangs under.
    SupportConnection,
    /// A vertical support profile.
    Support,
    /// One of the four outline profiles of a layer.
    Frame,
    /// A layer profile behind the frontmost support, seen from the pick-up position.
    Back,
    /// A layer profile in front of the backmost support.
    Front,
}

/// One straight profile: a box with a square cross-section, long along `axis`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Profile {
    /// 0 = x, 1 = y, 2 = z.
    pub axis: usize,
    /// The profile's box.
    pub cuboid: Cuboid,
    /// What the profile is for.
    pub role: Role,
    /// The layer of frame, back and front profiles.
    pub layer: Option<usize>,
    /// Bottom profiles and the two back posts of the base stay in place.
    pub fixed: bool,
}

impl Profile {
    /// Length along its axis.
    pub fn length(&self) -> f64 {
        self.cuboid.maxs[self.axis] - self.cuboid.mins[self.axis]
    }

    /// The centre of the cross-section (the coordinate along the axis is the midpoint).
    pub fn centre(&self) -> [f64; 3] {
        [0, 1, 2].map(|a| 0.5 * (self.cuboid.mins[a] + self.cuboid.maxs[a]))
    }
}

/// The two connector shapes of Figure 4.4.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum ConnectorShape {
    /// A cradle under the end of a horizontal profile: a floor plate and two side walls.
    U,
    /// A sleeve around the end of a vertical profile.
    O,
}

/// A connector: where the end of profile `holds` meets the long side of profile `attached_to`.
#[derive(Clone, Debug, PartialEq)]
pub struct Connector {
    /// U for horizontal held profiles, O for vertical ones.
    pub shape: ConnectorShape,
    /// The profile whose end it holds.
    pub holds: usize,
    /// The profile whose long side it is fastened to.
    pub attached_to: usize,
    /// Disjoint boxes whose union is the connector.
    pub cells: Vec<Cuboid>,
    /// Its closed surface.
    pub mesh: Mesh,
    /// Fixed when the profile it holds is fixed.
    pub fixed: bool,
}

/// A grasp for a two-finger gripper: fingers' midpoint, gripper orientation, finger width.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct GraspPoint {
    /// The fingers' midpoint on the profile's centre line (metres).
    pub position: [f64; 3],
    /// Gripper frame as a quaternion `[x, y, z, w]`: its z axis is the approach direction
    /// (into the profile, through one of the four long sides), its y axis the closing
    /// direction of the fingers, its x axis along the profile.
    pub orientation: [f64; 4],
    /// Opening between the fingers (the profile size).
    pub width: f64,
}

/// A generated profile assembly: the profiles, then the connectors.
#[derive(Clone, Debug, PartialEq)]
pub struct ProfileAssembly {
    /// The parameters it was made with.
    pub params: ProfileParams,
    /// All profiles; their indices are part indices.
    pub profiles: Vec<Profile>,
    /// All connectors; connector `k` is part `profiles.len() + k`.
    pub connectors: Vec<Connector>,
}

impl ProfileAssembly {
    /// Generates one assembly from `seed`.
    pub fn generate(params: &ProfileParams, seed: u64) -> Result<Self> {
        params.validate()?;
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let mut last = String::new();
        for _ in 0..RESTARTS {
            let mut b = Builder { p: params, profiles: Vec::new(), connectors: Vec::new(), end_slabs: Vec::new() };
            match b.build(&mut rng) {
                Ok(()) => return Ok(ProfileAssembly { params: params.clone(), profiles: b.profiles, connectors: b.connectors }),
                Err(why) => last = why,
            }
        }
        Err(GenError::Construction {
            seed,
            reason: format!("{last} after {RESTARTS} fresh starts; ask for fewer profiles, fewer supports or a larger assembly"),
        })
    }

    /// The boxes of every part: profiles, then connectors; with attached connectors
    /// ([`ConnectorMode::Attached`]) only profiles, each with the cells of the connectors it
    /// holds after its own box.
    pub fn part_boxes(&self) -> Vec<Vec<Cuboid>> {
        if self.params.connectors == ConnectorMode::Attached {
            return (0..self.profiles.len()).map(|i| self.profile_part_boxes(i)).collect();
        }
        let profiles = self.profiles.iter().map(|p| vec![p.cuboid]);
        profiles.chain(self.connectors.iter().map(|c| c.cells.clone())).collect()
    }

    /// Profile `i`'s box followed by the cells of the connectors that hold it.
    fn profile_part_boxes(&self, i: usize) -> Vec<Cuboid> {
        let held = self.connectors.iter().filter(|c| c.holds == i).flat_map(|c| c.cells.iter().copied());
        std::iter::once(self.profiles[i].cuboid).chain(held).collect()
    }

    /// Whether each part is fixed (profiles, then connectors unless they are attached).
    pub fn fixed(&self) -> Vec<bool> {
        let profiles = self.profiles.iter().map(|p| p.fixed);
        if self.params.connectors == ConnectorMode::Attached {
            return profiles.collect();
        }
        profiles.chain(self.connectors.iter().map(|c| c.fixed)).collect()
    }

    /// The deepest interpenetration between boxes of two different parts (≤ [`TOLERANCE`] in
    /// every generated assembly).
    pub fn max_penetration(&self) -> f64 {
        let parts = self.part_boxes();
        let mut worst = f64::NEG_INFINITY;
        for (i, a) in parts.iter().enumerate() {
            for b in &parts[i + 1..] {
                for x in a {
                    for y in b {
                        worst = worst.max(x.penetration(y));
                    }
                }
            }
        }
        worst
    }

    /// Grasp points of profile `i`: every `grasp_spacing` along the profile, `grasp_margin`
    /// from both ends, approached through each of its four long sides.
    pub fn grasp_points(&self, i: usize) -> Vec<GraspPoint> {
        let Some(profile) = self.profiles.get(i) else { return Vec::new() };
        let p = &self.params;
        let (a, lo) = (profile.axis, profile.cuboid.mins[profile.axis]);
        let usable = profile.length() - 2.0 * p.grasp_margin;
        if usable < -TOLERANCE {
            return Vec::new();
        }
        let n = (usable.max(0.0) / p.grasp_spacing + 1e-9).floor() as usize + 1;
        let (b, c) = ((a + 1) % 3, (a + 2) % 3);
        let mut out = Vec::with_capacity(4 * n);
        for k in 0..n {
            let mut position = profile.centre();
            position[a] = lo + p.grasp_margin + k as f64 * p.grasp_spacing;
            for (side, closing) in [(b, c), (c, b)] {
                for sign in [1.0, -1.0] {
                    let mut approach = [0.0; 3];
                    approach[side] = -sign;
                    let mut close = [0.0; 3];
                    close[closing] = 1.0;
                    let orientation = quaternion(cross(close, approach), close, approach).map(|q| tidy(q, 1e12));
                    out.push(GraspPoint { position: position.map(|x| tidy(x, 1e9)), orientation, width: p.profile_size });
                }
            }
        }
        out
    }

    /// The assembly (metres, +Z up): profiles named `profile_NN`, then connectors named
    /// `u_connector_NN` / `o_connector_NN`, with their metadata in their extras (written to
    /// the file's `extras.asp`): kind, role, exact boxes, grasp points. With attached
    /// connectors there are only profiles: each profile's mesh is the closed surface of its box
    /// and its connectors' cells, `boxes` lists them all (the profile's first), and
    /// `connectors` names each merged connector's shape and the profile it is fastened to.
    pub fn to_assembly(&self, source: &str) -> Assembly {
        let axis_name = |a: usize| ["x", "y", "z"][a];
        let attached = self.params.connectors == ConnectorMode::Attached;
        let shape_name = |s: ConnectorShape| match s {
            ConnectorShape::U => "U",
            ConnectorShape::O => "O",
        };
        let mut parts: Vec<Part> = self
            .profiles
            .iter()
            .enumerate()
            .map(|(i, p)| {
                let mut extras = json!({
                    "kind": "profile",
                    "role": p.role,
                    "layer": p.layer,
                    "axis": axis_name(p.axis),
                    "length": tidy(p.length(), 1e9),
                    "size": self.params.profile_size,
                    "boxes": [box_array(&p.cuboid)],
                    "grasp_points": self.grasp_points(i),
                });
                if !attached {
                    return Part::new(profile_name(i), p.cuboid.mesh(), p.fixed, extras);
                }
                let boxes = self.profile_part_boxes(i);
                extras["boxes"] = json!(boxes.iter().map(box_array).collect::<Vec<_>>());
                let merged: Vec<_> = self
                    .connectors
                    .iter()
                    .filter(|c| c.holds == i)
                    .map(|c| json!({ "shape": shape_name(c.shape), "attached_to": profile_name(c.attached_to) }))
                    .collect();
                extras["connectors"] = json!(merged);
                Part::new(profile_name(i), box_union(&boxes), p.fixed, extras)
            })
            .collect();
        let separate = if attached { &[][..] } else { &self.connectors[..] };
        for (k, c) in separate.iter().enumerate() {
            let shape = match c.shape {
                ConnectorShape::U => "U",
                ConnectorShape::O => "O",
            };
            parts.push(Part::new(
                format!("{}_connector_{k:02}", shape.to_lowercase()),
                c.mesh.clone(),
                c.fixed,
                json!({
                    "kind": "connector",
                    "shape": shape,
                    "holds": profile_name(c.holds),
                    "attached_to": profile_name(c.attached_to),
                    "boxes": c.cells.iter().map(box_array).collect::<Vec<_>>(),
                }),
            ));
        }
        Assembly { parts, units: Units::metres(), up: Axis::Z, source: source.into(), warnings: Vec::new() }
    }

    /// Straight-line disassembly along ±axes on the exact boxes.
    pub fn check_disassembly(&self) -> DisassemblyCheck {
        check_disassembly(&BoxModel::new(self.part_boxes(), self.fixed(), TOLERANCE))
    }
}

/// A box as `[min x, min y, min z, max x, max y, max z]`, to the nanometre.
fn box_array(b: &Cuboid) -> [f64; 6] {
    [b.mins[0], b.mins[1], b.mins[2], b.maxs[0], b.maxs[1], b.maxs[2]].map(|v| tidy(v, 1e9))
}

/// `v` rounded to `1 / per_unit` (e.g. `1e9` per metre: nanometres), without negative zero:
/// short decimals in the file that every JSON reader parses back to the same number.
fn tidy(v: f64, per_unit: f64) -> f64 {
    (v * per_unit).round() / per_unit + 0.0
}

fn profile_name(i: usize) -> String {
    format!("profile_{i:02}")
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

/// The quaternion `[x, y, z, w]` of the rotation whose matrix has columns `x`, `y`, `z`.
fn quaternion(x: [f64; 3], y: [f64; 3], z: [f64; 3]) -> [f64; 4] {
    let m = |r: usize, c: usize| [x, y, z][c][r];
    let trace = m(0, 0) + m(1, 1) + m(2, 2);
    let q = if trace > 0.0 {
        let s = 2.0 * (trace + 1.0).sqrt();
        [(m(2, 1) - m(1, 2)) / s, (m(0, 2) - m(2, 0)) / s, (m(1, 0) - m(0, 1)) / s, 0.25 * s]
    } else if m(0, 0) > m(1, 1) && m(0, 0) > m(2, 2) {
        let s = 2.0 * (1.0 + m(0, 0) - m(1, 1) - m(2, 2)).sqrt();
        [0.25 * s, (m(0, 1) + m(1, 0)) / s, (m(0, 2) + m(2, 0)) / s, (m(2, 1) - m(1, 2)) / s]
    } else if m(1, 1) > m(2, 2) {
        let s = 2.0 * (1.0 + m(1, 1) - m(0, 0) - m(2, 2)).sqrt();
        [(m(0, 1) + m(1, 0)) / s, 0.25 * s, (m(1, 2) + m(2, 1)) / s, (m(0, 2) - m(2, 0)) / s]
    } else {
        let s = 2.0 * (1.0 + m(2, 2) - m(0, 0) - m(1, 1)).sqrt();
        [(m(0, 2) + m(2, 0)) / s, (m(1, 2) + m(2, 1)) / s, 0.25 * s, (m(1, 0) - m(0, 1)) / s]
    };
    // one sign convention (w ≥ 0) so equal rotations print equally
    if q[3] < 0.0 {
        q.map(|v| -v)
    } else {
        q
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quaternion_of_identity_and_a_quarter_turn() {
        assert_eq!(quaternion([1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]), [0.0, 0.0, 0.0, 1.0]);
        // 90° about z: x → y, y → −x
        let q = quaternion([0.0, 1.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 0.0, 1.0]);
        let h = std::f64::consts::FRAC_1_SQRT_2;
        assert!((q[2] - h).abs() < 1e-12 && (q[3] - h).abs() < 1e-12, "{q:?}");
    }

    #[test]
    fn presets_count_the_thesis_profiles() {
        assert_eq!(ProfileParams::single_layer().removable_profiles(), 21);
        assert_eq!(ProfileParams::double_layer().removable_profiles(), 30);
    }

    #[test]
    fn validate_names_the_bad_flag() {
        let bad = |p: ProfileParams| match p.validate() {
            Err(GenError::Parameter { name, .. }) => name,
            other => panic!("{other:?}"),
        };
        assert_eq!(bad(ProfileParams { width: -1.0, ..Default::default() }), "width");
        assert_eq!(bad(ProfileParams { supports: 0, ..Default::default() }), "supports");
        assert_eq!(bad(ProfileParams { layers: 9, ..Default::default() }), "height");
        assert_eq!(bad(ProfileParams { grasp_clearance: 0.021, ..Default::default() }), "grasp-clearance");
        assert!(ProfileParams::double_layer().validate().is_ok());
    }

    #[test]
    fn connectors_are_closed_and_touch_both_profiles() {
        let a = ProfileAssembly::generate(&ProfileParams::single_layer(), 7).unwrap();
        for c in &a.connectors {
            assert!(c.mesh.topology().is_closed_manifold(), "{:?}", c.mesh.topology());
            let volume: f64 = c.cells.iter().map(Cuboid::volume).sum();
            assert!((c.mesh.signed_volume() - volume).abs() < 1e-9);
            for p in [c.holds, c.attached_to] {
                let cuboid = &a.profiles[p].cuboid;
                assert!(c.cells.iter().any(|x| x.touches(cuboid, TOLERANCE)), "{c:?} vs profile {p}");
            }
        }
    }

    #[test]
    fn too_many_profiles_fail_with_a_clear_error() {
        let p = ProfileParams { back: 30, ..ProfileParams::single_layer() };
        let err = ProfileAssembly::generate(&p, 0).unwrap_err().to_string();
        assert!(err.contains("no room") && err.contains("fewer profiles"), "{err}");
    }
}
