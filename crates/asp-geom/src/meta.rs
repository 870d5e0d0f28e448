//! Typed per-part metadata, parsed once when the model is loaded.
//!
//! Generators (and users) describe parts beyond their meshes in the glTF node's `extras.asp`:
//! what the part is (`kind`), its exact voxels (`cells`) or boxes (`boxes`), and where a gripper
//! may hold it (`grasp_points`), and what it is fastened to (`fastened_to`, or the profile
//! generator's `holds` / `attached_to` / `connectors`). [`PartMeta::from_extras`] reads those keys once; everything in
//! asp reads the typed fields instead of the JSON. Malformed metadata is not fatal: the key is
//! ignored and the loader warns, naming the part and the key.

use crate::math::{Aabb, Pose, Rot, Vec3};
use serde_json::Value;

/// What the file says about a part, beyond its mesh.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PartMeta {
    /// What the part is (`profile`, `connector`, `soma_piece`, `floor`, ...), when the file says.
    pub kind: Option<String>,
    /// Integer voxel cells (`cells` or `voxels`): the part is their union. Their size and position
    /// are fitted to the mesh ([`crate::boxes`]), so any cell size and unit work.
    pub cells: Option<Vec<[i32; 3]>>,
    /// Axis-aligned boxes whose union is the part (`boxes`, each `[min x, min y, min z, max x,
    /// max y, max z]`), in the file's coordinates; fitted to the mesh like the cells.
    pub boxes: Option<Vec<Aabb>>,
    /// Where a parallel gripper may hold the part (`grasp_points`, in the node's frame like its
    /// mesh in the file); after loading in the world frame, metres.
    pub grasps: Vec<Grasp>,
    /// Names of the parts this one is fastened to (screwed, clamped, bolted): a joint that holds
    /// while both parts are present. Read from `fastened_to` (a list of part names) and from what
    /// the profile generator writes: a connector part's `holds` and `attached_to`, a profile's
    /// merged `connectors[].attached_to`. `--stability physics` bonds each such pair into one
    /// rigid body ([`crate::physics`]); the removal test ignores it (a fastener is undone before
    /// its part moves).
    pub fastened_to: Vec<String>,
}

/// A grasp of a parallel two-finger gripper.
#[derive(Clone, Debug, PartialEq)]
pub struct Grasp {
    /// The tool centre point, world frame, metres.
    pub position: Vec3,
    /// The gripper's orientation (its z axis the approach, its y axis the closing direction, as
    /// the profile generator writes them).
    pub orientation: Rot,
    /// Opening width in metres.
    pub width: f32,
}

impl PartMeta {
    /// Reads the metadata object of a part (a node's `extras.asp`, or an object with an `asp`
    /// key). Returns the metadata and one message per key that was present but malformed.
    pub fn from_extras(extras: &Value) -> (PartMeta, Vec<String>) {
        let mut problems = Vec::new();
        let mut meta = PartMeta { kind: lookup(extras, "kind").and_then(Value::as_str).map(str::to_string), ..Default::default() };
        if let Some(v) = lookup(extras, "cells").or_else(|| lookup(extras, "voxels")) {
            match parse_cells(v) {
                Some(c) => meta.cells = Some(c),
                None => problems.push("extras.asp.cells is not a list of integer [i, j, k] cells; ignored".to_string()),
            }
        }
        if let Some(v) = lookup(extras, "boxes") {
            match parse_boxes(v) {
                Some(b) => meta.boxes = Some(b),
                None => {
                    problems.push("extras.asp.boxes is not a list of [min x, min y, min z, max x, max y, max z] boxes; ignored".to_string())
                }
            }
        }
        if let Some(v) = lookup(extras, "grasp_points") {
            match parse_grasps(v) {
                Some(g) => meta.grasps = g,
                None => problems.push("extras.asp.grasp_points is not a list of {position, orientation, width}; ignored".to_string()),
            }
        }
        match fastened_to(extras) {
            Some(names) => meta.fastened_to = names,
            None => problems.push(
                "extras.asp.fastened_to (or holds, attached_to, connectors[].attached_to) is not a list of part names; ignored".to_string(),
            ),
        }
        (meta, problems)
    }

    /// The metadata with its world-frame quantities moved by `pose` and scaled by `scale` about
    /// the origin first (as a loader places and converts a part). Cells and boxes are fitted to
    /// the mesh later and stay as they are.
    pub fn transformed(&self, pose: &Pose, scale: f32) -> PartMeta {
        let mut out = self.clone();
        for g in &mut out.grasps {
            g.position = pose.transform_point(g.position * scale);
            g.orientation = (pose.rotation * g.orientation).normalize();
            g.width *= scale;
        }
        out
    }
}

/// The value under `key` in the metadata object, or one level down under `asp`.
fn lookup<'a>(extras: &'a Value, key: &str) -> Option<&'a Value> {
    extras.get(key).or_else(|| extras.get("asp").and_then(|a| a.get(key)))
}

/// The part names under `fastened_to`, `holds`, `attached_to` and `connectors[].attached_to`, in
/// that order, without repeats; `None` when one of those keys is present but malformed.
fn fastened_to(extras: &Value) -> Option<Vec<String>> {
    let mut names: Vec<String> = Vec::new();
    let mut add = |v: &Value| -> Option<()> {
        let name = v.as_str().filter(|s| !s.is_empty())?;
        if !names.iter().any(|n| n == name) {
            names.push(name.to_string());
        }
        Some(())
    };
    if let Some(v) = lookup(extras, "fastened_to") {
        v.as_array()?.iter().try_for_each(&mut add)?;
    }
    for key in ["holds", "attached_to"] {
        if let Some(v) = lookup(extras, key) {
            add(v)?;
        }
    }
    if let Some(v) = lookup(extras, "connectors") {
        for c in v.as_array()? {
            if let Some(to) = c.get("attached_to") {
                add(to)?;
            }
        }
    }
    Some(names)
}

fn parse_cells(v: &Value) -> Option<Vec<[i32; 3]>> {
    let cells = match v {
        Value::Array(a) => a,
        Value::Object(o) => o.get("cells")?.as_array()?,
        _ => return None,
    };
    let mut out = Vec::with_capacity(cells.len());
    for c in cells {
        let c = c.as_array()?;
        if c.len() != 3 {
            return None;
        }
        let mut cell = [0i32; 3];
        for (k, x) in c.iter().enumerate() {
            let f = x.as_f64()?;
            if f.fract() != 0.0 || f.abs() > 1e6 {
                return None;
            }
            cell[k] = f as i32;
        }
        out.push(cell);
    }
    (!out.is_empty()).then_some(out)
}

fn parse_boxes(v: &Value) -> Option<Vec<Aabb>> {
    let list = v.as_array()?;
    let mut out = Vec::with_capacity(list.len());
    for b in list {
        let v: Vec<f32> = b.as_array()?.iter().map(|x| x.as_f64().map(|f| f as f32)).collect::<Option<_>>()?;
        let [x0, y0, z0, x1, y1, z1] = <[f32; 6]>::try_from(v).ok()?;
        let (lo, hi) = (Vec3::new(x0, y0, z0), Vec3::new(x1, y1, z1));
        if !(lo.is_finite() && hi.is_finite() && (hi - lo).min_element() > 0.0) {
            return None;
        }
        out.push(Aabb::new(lo, hi));
    }
    (!out.is_empty()).then_some(out)
}

fn parse_grasps(v: &Value) -> Option<Vec<Grasp>> {
    let floats = |v: &Value, n: usize| -> Option<Vec<f32>> {
        let a = v.as_array()?;
        (a.len() == n).then_some(())?;
        a.iter().map(|x| x.as_f64().map(|f| f as f32).filter(|f| f.is_finite())).collect()
    };
    v.as_array()?
        .iter()
        .map(|g| {
            let p = floats(g.get("position")?, 3)?;
            let q = floats(g.get("orientation")?, 4)?;
            let width = g.get("width")?.as_f64()? as f32;
            let rot = Rot::from_xyzw(q[0], q[1], q[2], q[3]);
            (width.is_finite() && width > 0.0 && (rot.length() - 1.0).abs() < 1e-3).then(|| Grasp {
                position: Vec3::new(p[0], p[1], p[2]),
                orientation: rot.normalize(),
                width,
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    #[test]
    fn reads_what_the_generators_write() {
        let (m, problems) = PartMeta::from_extras(&json!({
            "kind": "profile",
            "boxes": [[0, 0, 0, 1, 0.5, 0.25]],
            "grasp_points": [{"position": [0.5, 0.25, 0.125], "orientation": [0, 0, 0, 1], "width": 0.04}],
        }));
        assert!(problems.is_empty(), "{problems:?}");
        assert_eq!(m.kind.as_deref(), Some("profile"));
        assert_eq!(m.boxes.as_ref().map(Vec::len), Some(1));
        assert_eq!(m.grasps.len(), 1);
        assert_eq!(m.grasps[0].width, 0.04);
        let (m, _) = PartMeta::from_extras(&json!({"asp": {"cells": [[0, 0, 0], [1, 0, 0]]}}));
        assert_eq!(m.cells, Some(vec![[0, 0, 0], [1, 0, 0]]));
    }

    #[test]
    fn malformed_keys_are_reported_and_ignored() {
        let (m, problems) = PartMeta::from_extras(&json!({
            "cells": [[0, 0.5, 0]],
            "boxes": [[1, 1, 1, 0, 0, 0]],
            "grasp_points": [{"position": [0, 0], "orientation": [0, 0, 0, 1], "width": 1}],
        }));
        assert_eq!(m, PartMeta::default());
        assert_eq!(problems.len(), 3, "{problems:?}");
        assert!(problems[0].contains("cells") && problems[1].contains("boxes") && problems[2].contains("grasp_points"));
        assert_eq!(PartMeta::from_extras(&Value::Null), (PartMeta::default(), Vec::new()));
        let (m, problems) = PartMeta::from_extras(&json!({"fastened_to": "plate"}));
        assert!(m.fastened_to.is_empty() && problems.len() == 1 && problems[0].contains("fastened_to"), "{problems:?}");
    }

    #[test]
    fn fastenings_are_read_from_every_key_the_generators_write() {
        let (m, problems) = PartMeta::from_extras(&json!({"asp": {"kind": "connector", "holds": "p1", "attached_to": "p2"}}));
        assert!(problems.is_empty(), "{problems:?}");
        assert_eq!(m.fastened_to, ["p1", "p2"]);
        let (m, _) = PartMeta::from_extras(&json!({
            "fastened_to": ["plate", "p3"],
            "connectors": [{"shape": "U", "attached_to": "p3"}, {"shape": "O", "attached_to": "p4"}],
        }));
        assert_eq!(m.fastened_to, ["plate", "p3", "p4"]);
    }

    #[test]
    fn grasps_move_with_the_part() {
        let (m, _) = PartMeta::from_extras(&json!({
            "grasp_points": [{"position": [1, 0, 0], "orientation": [0, 0, 0, 1], "width": 2}],
        }));
        let pose = Pose::from_parts(Vec3::new(0.0, 0.0, 5.0), Rot::from_rotation_z(std::f32::consts::FRAC_PI_2));
        let g = &m.transformed(&pose, 0.001).grasps[0];
        assert!((g.position - Vec3::new(0.0, 0.001, 5.0)).length() < 1e-6, "{:?}", g.position);
        assert!((g.width - 0.002).abs() < 1e-9);
        assert!((g.orientation * Vec3::X - Vec3::Y).length() < 1e-6);
    }
}
