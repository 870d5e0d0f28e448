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

/// A free stretch of a line between the profiles it crosses.
#[derive(Clone, Copy, Debug)]
struct Segment {
    lo: f64,
    hi: f64,
    /// The profile that ends the stretch at `lo` / `hi` (None at the line's end).
    lo_end: Option<usize>,
    hi_end: Option<usize>,
}

impl Segment {
    fn length(&self) -> f64 {
        self.hi - self.lo
    }
}

#[derive(Clone, Copy, PartialEq)]
enum Side {
    Back,
    Front,
}

struct Builder<'p> {
    p: &'p ProfileParams,
    profiles: Vec<Profile>,
    connectors: Vec<Connector>,
    /// The last wall thickness of every profile end that meets another profile.
    end_slabs: Vec<Cuboid>,
}

impl Builder<'_> {
    /// The centre height of the bottom profiles: they rest on the floor plates of their
    /// connectors, one wall thickness above the ground.
    fn bottom_plane(&self) -> f64 {
        self.p.connector_thickness + self.p.profile_size / 2.0
    }

    /// Length of a profile laid on `seg`: one wall thickness shorter at every end that meets
    /// another profile, where the connector's end plate sits.
    fn held_length(&self, seg: &Segment) -> f64 {
        let t = self.p.connector_thickness;
        seg.length() - t * (seg.lo_end.is_some() as u8 + seg.hi_end.is_some() as u8) as f64
    }

    fn extent(&self, axis: usize) -> f64 {
        [self.p.length, self.p.width, self.p.height][axis]
    }

    /// The box of a profile along `axis` through point `at` (its `axis` coordinate ignored).
    fn profile_box(&self, axis: usize, at: [f64; 3], lo: f64, hi: f64) -> Cuboid {
        let h = self.p.profile_size / 2.0;
        let mut b = Cuboid::new(at.map(|v| v - h), at.map(|v| v + h));
        (b.mins[axis], b.maxs[axis]) = (lo, hi);
        b
    }

    fn build(&mut self, rng: &mut ChaCha8Rng) -> std::result::Result<(), String> {
        let (d, l, w, h) = (self.p.profile_size, self.p.length, self.p.width, self.p.height);
        // base: posts first, so the horizontal profiles split against them
        for x in [d / 2.0, l - d / 2.0] {
            for y in [d / 2.0, w - d / 2.0] {
                let post = Segment { lo: 0.0, hi: h, lo_end: None, hi_end: None };
                self.add(2, [x, y, 0.0], post, Role::Base, None, x > l / 2.0)?;
            }
        }
        for (z, fixed) in [(self.bottom_plane(), true), (h - d / 2.0, false)] {
            self.frame(z, Role::Base, None, fixed)?;
        }
        let supports = self.supports(rng)?;
        for layer in 0..self.p.layers {
            self.layer(layer, &supports, rng)?;
        }
        Ok(())
    }

    /// Four profiles along the outline at height `z`, between the corner posts.
    fn frame(&mut self, z: f64, role: Role, layer: Option<usize>, fixed: bool) -> std::result::Result<(), String> {
        let (d, l, w) = (self.p.profile_size, self.p.length, self.p.width);
        let lines = [(0, [0.0, d / 2.0, z]), (0, [0.0, w - d / 2.0, z]), (1, [d / 2.0, 0.0, z]), (1, [l - d / 2.0, 0.0, z])];
        for (axis, at) in lines {
            let seg = self.segments(axis, at).into_iter().find(|s| s.lo_end.is_some() && s.hi_end.is_some());
            let seg = seg.ok_or("the outline is blocked")?;
            self.add(axis, at, seg, role, layer, fixed)?;
        }
        Ok(())
    }

    /// Places the supports with their bottom and top connections; returns their indices.
    fn supports(&mut self, rng: &mut ChaCha8Rng) -> std::result::Result<Vec<usize>, String> {
        let (d, l, w, h) = (self.p.profile_size, self.p.length, self.p.width, self.p.height);
        let (eps_p, k) = (self.p.min_length, self.p.supports);
        let mut spots: Vec<[f64; 2]> = Vec::new();
        for i in 0..k {
            let y_lo = eps_p.max(w * i as f64 / k as f64);
            let y_hi = (w - eps_p).min(w * (i + 1) as f64 / k as f64);
            let spot = [rng.random_range(eps_p..=l - eps_p), rng.random_range(y_lo..=y_hi)];
            let clear = spots.iter().all(|s| (s[0] - spot[0]).hypot(s[1] - spot[1]) >= self.p.grasp_clearance);
            if !clear {
                return Err("supports closer than the grasp clearance".into());
            }
            spots.push(spot);
        }
        let mut supports = Vec::new();
        for [x, y] in spots {
            let mut ends = [0; 2];
            for (end, (z, fixed)) in ends.iter_mut().zip([(self.bottom_plane(), true), (h - d / 2.0, false)]) {
                *end = (0..TRIES_PER_PROFILE)
                    .find_map(|_| {
                        let axis = rng.random_range(0..2);
                        let at = [x, y, z];
                        if !self.clear_of_parallels(axis, at) {
                            return None;
                        }
                        let foot = [x, y][axis];
                        let seg = self
                            .segments(axis, at)
                            .into_iter()
                            .find(|s| s.lo <= foot - d / 2.0 + TOLERANCE && s.hi >= foot + d / 2.0 - TOLERANCE)?;
                        if self.held_length(&seg) < eps_p || seg.lo_end.is_none() || seg.hi_end.is_none() {
                            return None;
                        }
                        self.add(axis, at, seg, Role::SupportConnection, None, fixed).ok()
                    })
                    .ok_or("no room for a support connection")?;
            }
            let bottom = self.profiles[ends[0]].cuboid.maxs[2];
            let seg = Segment { lo: bottom, hi: h - d, lo_end: Some(ends[0]), hi_end: Some(ends[1]) };
            supports.push(self.add(2, [x, y, 0.0], seg, Role::Support, None, false)?);
        }
        Ok(supports)
    }

    fn layer(&mut self, layer: usize, supports: &[usize], rng: &mut ChaCha8Rng) -> std::result::Result<(), String> {
        let z = self.p.layer_height(layer);
        self.frame(z, Role::Frame, Some(layer), false)?;
        let xs: Vec<f64> = supports.iter().map(|&s| self.profiles[s].centre()[0]).collect();
        let x_front = xs.iter().copied().fold(f64::INFINITY, f64::min);
        let x_back = xs.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let mut connected = vec![false; supports.len()];
        let sides = std::iter::repeat_n(Side::Back, self.p.back).chain(std::iter::repeat_n(Side::Front, self.p.front));
        for (n, side) in sides.enumerate() {
            let placed =
                (0..TRIES_PER_PROFILE).find_map(|_| self.try_layer_profile(side, z, layer, (x_front, x_back), supports, &connected, rng));
            let index = placed.ok_or_else(|| format!("no room for layer profile {} of layer {}", n + 1, layer + 1))?;
            let p = &self.profiles[index];
            for (k, &s) in supports.iter().enumerate() {
                connected[k] |= p.cuboid.touches(&self.profiles[s].cuboid, TOLERANCE);
            }
        }
        Ok(())
    }

    /// One draw of a back or front profile (thesis 4.1.3); None when it has to be drawn again.
    #[allow(clippy::too_many_arguments)]
    fn try_layer_profile(
        &mut self,
        side: Side,
        z: f64,
        layer: usize,
        (x_front, x_back): (f64, f64),
        supports: &[usize],
        connected: &[bool],
        rng: &mut ChaCha8Rng,
    ) -> Option<usize> {
        let (d, l, w, eps_g) = (self.p.profile_size, self.p.length, self.p.width, self.p.grasp_clearance);
        let axis = rng.random_range(0..2);
        let across = 1 - axis;
        let unconnected: Vec<usize> = (0..supports.len()).filter(|&k| !connected[k]).collect();
        let coordinate = if !unconnected.is_empty() && rng.random_bool(0.5) {
            let &k = unconnected.choose(rng)?;
            self.profiles[supports[k]].centre()[across]
        } else {
            let (lo, hi) = match (axis, side) {
                (0, _) => (d / 2.0 + eps_g, w - d / 2.0 - eps_g),
                (_, Side::Back) => (x_front, l - d / 2.0 - eps_g),
                (_, Side::Front) => (d / 2.0 + eps_g, x_back),
            };
            if lo > hi {
                return None;
            }
            rng.random_range(lo..=hi)
        };
        let mut at = [0.0, 0.0, z];
        at[across] = coordinate;
        if !self.clear_of_parallels(axis, at) {
            return None;
        }
        let allowed = |s: &Segment| match (side, axis) {
            (Side::Back, 0) => s.lo >= x_front - TOLERANCE,
            (Side::Back, _) => coordinate >= x_front - TOLERANCE,
            (Side::Front, 0) => s.hi <= x_back + TOLERANCE,
            (Side::Front, _) => coordinate <= x_back + TOLERANCE,
        };
        let segments: Vec<Segment> = self
            .segments(axis, at)
            .into_iter()
            .filter(|s| s.lo_end.is_some() && s.hi_end.is_some() && allowed(s))
            .filter(|s| self.held_length(s) >= self.p.min_length)
            .collect();
        let &seg = segments.choose(rng)?;
        let role = if side == Side::Back { Role::Back } else { Role::Front };
        self.add(axis, at, seg, role, Some(layer), false).ok()
    }

    /// Whether a profile along `axis` through `at` keeps ε_g from every parallel profile.
    fn clear_of_parallels(&self, axis: usize, at: [f64; 3]) -> bool {
        self.profiles.iter().filter(|p| p.axis == axis).all(|p| {
            let c = p.centre();
            let dist2: f64 = (0..3).filter(|&b| b != axis).map(|b| (c[b] - at[b]).powi(2)).sum();
            dist2.sqrt() >= self.p.grasp_clearance - TOLERANCE
        })
    }

    /// The free stretches of the full-length line along `axis` through `at`, between the
    /// profiles it crosses.
    fn segments(&self, axis: usize, at: [f64; 3]) -> Vec<Segment> {
        let line = self.profile_box(axis, at, 0.0, self.extent(axis));
        let mut hits: Vec<(f64, f64, usize)> = self
            .profiles
            .iter()
            .enumerate()
            .filter(|(_, p)| p.cuboid.overlaps(&line, TOLERANCE))
            .map(|(i, p)| (p.cuboid.mins[axis], p.cuboid.maxs[axis], i))
            .collect();
        hits.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.2.cmp(&b.2)));
        let mut out = Vec::new();
        let (mut cursor, mut cursor_end) = (0.0, None);
        for (lo, hi, i) in hits {
            if lo > cursor + TOLERANCE {
                out.push(Segment { lo: cursor, hi: lo, lo_end: cursor_end, hi_end: Some(i) });
            }
            if hi > cursor {
                (cursor, cursor_end) = (hi, Some(i));
            }
        }
        if self.extent(axis) > cursor + TOLERANCE {
            out.push(Segment { lo: cursor, hi: self.extent(axis), lo_end: cursor_end, hi_end: None });
        }
        out
    }

    /// Adds the profile on `seg` with a connector at each end that meets another profile,
    /// unless something overlaps; returns its index.
    fn add(
        &mut self,
        axis: usize,
        at: [f64; 3],
        seg: Segment,
        role: Role,
        layer: Option<usize>,
        fixed: bool,
    ) -> std::result::Result<usize, String> {
        // horizontal profiles stop one wall short of what they meet; vertical ones stand on it
        let inset = |end: Option<usize>| if end.is_some() && axis != 2 { self.p.connector_thickness } else { 0.0 };
        let (lo, hi) = (seg.lo + inset(seg.lo_end), seg.hi - inset(seg.hi_end));
        let profile = Profile { axis, cuboid: self.profile_box(axis, at, lo, hi), role, layer, fixed };
        let index = self.profiles.len();
        // every end meets exactly one profile (else its connector would hold on to two), and
        // the new profile touches no end of another
        if self.end_slabs.iter().any(|slab| slab.touches(&profile.cuboid, TOLERANCE)) {
            return Err(format!("a {role:?} profile touches the end of another"));
        }
        let mut connectors = Vec::new();
        let mut slabs = Vec::new();
        for (end, other) in [(seg.lo, seg.lo_end), (seg.hi, seg.hi_end)] {
            if let Some(attached_to) = other {
                let mut slab = profile.cuboid;
                let t = self.p.connector_thickness;
                (slab.mins[axis], slab.maxs[axis]) = if end == seg.lo { (end, end + t) } else { (end - t, end) };
                let touches_another = self.profiles.iter().enumerate().any(|(j, q)| j != attached_to && q.cuboid.touches(&slab, TOLERANCE));
                if touches_another {
                    return Err(format!("a {role:?} profile ends against two profiles"));
                }
                slabs.push(slab);
                let (mesh, cells) = self.connector_cells(&profile, end, end == seg.lo);
                let shape = if axis == 2 { ConnectorShape::O } else { ConnectorShape::U };
                connectors.push(Connector { shape, holds: index, attached_to, cells, mesh, fixed });
            }
        }
        let new_boxes = std::iter::once(&profile.cuboid).chain(connectors.iter().flat_map(|c| &c.cells));
        let existing: Vec<&Cuboid> = self.profiles.iter().map(|p| &p.cuboid).chain(self.connectors.iter().flat_map(|c| &c.cells)).collect();
        for b in new_boxes {
            if existing.iter().any(|e| e.overlaps(b, TOLERANCE)) {
                return Err(format!("a {role:?} profile overlaps an existing part"));
            }
        }
        self.profiles.push(profile);
        self.connectors.extend(connectors);
        self.end_slabs.extend(slabs);
        Ok(index)
    }

    /// The cells of the connector at end `end` of the free stretch of `profile` (`at_lo`: its
    /// lower end), i.e. on the face of the profile it meets.
    ///
    /// U (horizontal profiles): an end plate between the profile's end and the face it meets, a
    /// floor plate under the profile reaching `connector_length` from the face, and two side
    /// walls that start two wall thicknesses from the face, so two cradles meeting a post from
    /// perpendicular sides never claim the same corner.
    /// O (vertical profiles): a ring of walls around the profile, `connector_length` high.
    fn connector_cells(&self, profile: &Profile, end: f64, at_lo: bool) -> (Mesh, Vec<Cuboid>) {
        let (d, t, c) = (self.p.profile_size, self.p.connector_thickness, self.p.connector_length);
        let a = profile.axis;
        let centre = profile.centre();
        let around = |v: f64| vec![v - d / 2.0 - t, v - d / 2.0, v + d / 2.0, v + d / 2.0 + t];
        let mut lines: [Vec<f64>; 3] = Default::default();
        let mut cells = Vec::new();
        if a == 2 {
            lines = [around(centre[0]), around(centre[1]), if at_lo { vec![end, end + c] } else { vec![end - c, end] }];
            for i in 0..3 {
                for j in 0..3 {
                    if (i, j) != (1, 1) {
                        cells.push([i, j, 0]);
                    }
                }
            }
        } else {
            let b = 1 - a;
            lines[a] = if at_lo { vec![end, end + t, end + 2.0 * t, end + c] } else { vec![end - c, end - 2.0 * t, end - t, end] };
            lines[b] = around(centre[b]);
            lines[2] = vec![centre[2] - d / 2.0 - t, centre[2] - d / 2.0, centre[2] + d / 2.0];
            let (near, far) = if at_lo { (0, 2) } else { (2, 0) };
            let mut cell = |ia: i32, ib: i32, iz: i32| {
                let mut c = [0; 3];
                (c[a], c[b], c[2]) = (ia, ib, iz);
                cells.push(c);
            };
            cell(near, 1, 1);
            for ia in 0..3 {
                cell(ia, 1, 0);
            }
            for ib in [0, 2] {
                for iz in [0, 1] {
                    cell(far, ib, iz);
                }
            }
        }
        grid_union([&lines[0], &lines[1], &lines[2]], &cells)
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
