//! The `TM_brep_faces` glTF extension (cascadio writes it from STEP through OpenCASCADE; trimesh
//! reads and writes it): on a mesh primitive, `faceIndices` is an accessor with the B-rep face of
//! each triangle, and `faces` lists each face's analytic surface (`plane`, `cylinder`, `cone`,
//! `sphere`, `torus`, in the mesh's own frame and the file's unit; `null` for a free-form face).
//!
//! The `gltf` crate keeps no unknown extensions without a feature that changes its build, so the
//! extension's JSON is read here from the document's JSON chunk with serde, once per file.

use crate::math::Vec3;
use crate::surface::Surface;
use parry3d::glamx::{DMat4, DVec3};
use serde::Deserialize;
use serde_json::Value;

/// The extension's name.
pub(crate) const EXTENSION: &str = "TM_brep_faces";

/// One primitive's extension: the accessor of its face indices and its faces' surfaces (local
/// frame, file units; `None` for a free-form face or one whose entry is malformed).
#[derive(Clone, Debug)]
pub(crate) struct PrimitiveFaces {
    /// The accessor of the per-triangle face indices.
    pub face_indices: usize,
    /// The surfaces, by face index.
    pub faces: Vec<Option<Surface64>>,
    /// Entries that were not a known surface with finite, valid parameters (0 for a clean file).
    pub malformed: usize,
}

/// The extension of every primitive: `[mesh][primitive]`.
pub(crate) type BrepFaces = Vec<Vec<Option<PrimitiveFaces>>>;

#[derive(Deserialize)]
struct RootJson {
    #[serde(default)]
    meshes: Vec<MeshJson>,
}

#[derive(Deserialize)]
struct MeshJson {
    #[serde(default)]
    primitives: Vec<PrimitiveJson>,
}

#[derive(Deserialize)]
struct PrimitiveJson {
    #[serde(default)]
    extensions: Option<serde_json::Map<String, Value>>,
}

/// The extension's data of every primitive of the glTF JSON `json`. A primitive whose extension
/// has no valid `faceIndices` gets `None` (its triangles then have no faces).
pub(crate) fn read(json: &[u8]) -> Result<BrepFaces, String> {
    let root: RootJson = serde_json::from_slice(json).map_err(|e| format!("invalid gltf json: {e}"))?;
    Ok(root.meshes.iter().map(|m| m.primitives.iter().map(|p| primitive(p.extensions.as_ref()?.get(EXTENSION)?)).collect()).collect())
}

fn primitive(ext: &Value) -> Option<PrimitiveFaces> {
    let face_indices = usize::try_from(ext.get("faceIndices")?.as_u64()?).ok()?;
    let entries = ext.get("faces").and_then(Value::as_array).map(Vec::as_slice).unwrap_or_default();
    let mut malformed = 0;
    let faces = entries
        .iter()
        .map(|entry| match entry {
            Value::Null => None,
            entry => {
                let surface = surface(entry);
                malformed += usize::from(surface.is_none() && is_analytic(entry));
                surface
            }
        })
        .collect();
    Some(PrimitiveFaces { face_indices, faces, malformed })
}

/// Whether an entry claims an analytic surface (one of the five kinds), so that failing to read
/// it is worth a warning (other kinds, `bspline` and the like, are free-form faces).
fn is_analytic(entry: &Value) -> bool {
    matches!(entry.get("type").and_then(Value::as_str), Some("plane" | "cylinder" | "cone" | "sphere" | "torus"))
}

/// A surface in double precision, before it is placed in the world frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Surface64 {
    Plane { point: DVec3, normal: DVec3 },
    Cylinder { point: DVec3, axis: DVec3, radius: f64 },
    Cone { apex: DVec3, axis: DVec3, half_angle: f64 },
    Sphere { centre: DVec3, radius: f64 },
    Torus { centre: DVec3, axis: DVec3, major: f64, minor: f64 },
}

fn surface(entry: &Value) -> Option<Surface64> {
    let point = |key: &str| -> Option<DVec3> {
        let v = entry.get(key)?.as_array()?;
        let c: Vec<f64> = v.iter().map(Value::as_f64).collect::<Option<_>>()?;
        match c[..] {
            [x, y, z] if c.iter().all(|x| x.is_finite()) => Some(DVec3::new(x, y, z)),
            _ => None,
        }
    };
    let direction = |key: &str| point(key).filter(|d| d.length() > 1e-9).map(DVec3::normalize);
    let length = |key: &str| entry.get(key)?.as_f64().filter(|r| r.is_finite() && *r > 0.0);
    Some(match entry.get("type")?.as_str()? {
        "plane" => Surface64::Plane { point: point("origin")?, normal: direction("normal")? },
        "cylinder" => Surface64::Cylinder { point: point("origin")?, axis: direction("axis")?, radius: length("radius")? },
        "cone" => Surface64::Cone {
            apex: point("apex")?,
            axis: direction("axis")?,
            half_angle: length("semi_angle").filter(|a| *a < std::f64::consts::FRAC_PI_2)?,
        },
        "sphere" => Surface64::Sphere { centre: point("center")?, radius: length("radius")? },
        "torus" => Surface64::Torus {
            centre: point("center")?,
            axis: direction("axis")?,
            major: length("major_radius")?,
            minor: length("minor_radius")?,
        },
        _ => return None,
    })
}

/// How a node's transform times the unit scale moves a surface: a rotation (or reflection) with
/// one uniform scale. `None` when the transform shears or scales unevenly, which does not keep a
/// cylinder a cylinder.
pub(crate) fn similarity(world: &DMat4, scale: f64) -> Option<f64> {
    let cols = [world.x_axis.truncate(), world.y_axis.truncate(), world.z_axis.truncate()];
    let s = cols[0].length();
    let even = cols.iter().all(|c| (c.length() - s).abs() <= 1e-6 * s);
    let square = (cols[0].dot(cols[1]).abs() + cols[1].dot(cols[2]).abs() + cols[0].dot(cols[2]).abs()) <= 1e-6 * s * s;
    (s > 0.0 && even && square).then_some(s * scale)
}

/// `surface` placed by the node transform `world` (a similarity, [`similarity`] = `s` with the
/// unit scale) and scaled to metres by `scale`.
pub(crate) fn place(surface: &Surface64, world: &DMat4, scale: f64, s: f64) -> Surface {
    let p = |x: DVec3| {
        let w = world.transform_point3(x) * scale;
        Vec3::new(w.x as f32, w.y as f32, w.z as f32)
    };
    let d = |x: DVec3| {
        let w = world.transform_vector3(x).normalize_or_zero();
        Vec3::new(w.x as f32, w.y as f32, w.z as f32)
    };
    let r = |x: f64| (x * s) as f32;
    match *surface {
        Surface64::Plane { point, normal } => Surface::Plane { point: p(point), normal: d(normal) },
        Surface64::Cylinder { point, axis, radius } => Surface::Cylinder { point: p(point), axis: d(axis), radius: r(radius) },
        Surface64::Cone { apex, axis, half_angle } => Surface::Cone { apex: p(apex), axis: d(axis), half_angle: half_angle as f32 },
        Surface64::Sphere { centre, radius } => Surface::Sphere { centre: p(centre), radius: r(radius) },
        Surface64::Torus { centre, axis, major, minor } => {
            Surface::Torus { centre: p(centre), axis: d(axis), major: r(major), minor: r(minor) }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use parry3d::glamx::DQuat;

    #[test]
    fn surfaces_are_read_from_the_extension_json() {
        let json = br#"{"meshes": [{"primitives": [
            {"extensions": {"TM_brep_faces": {"faceIndices": 7, "faces": [
                {"type": "plane", "origin": [0, 0, 1], "normal": [0, 0, 2]},
                null,
                {"type": "cylinder", "origin": [0, 0, 0], "axis": [1, 0, 0], "radius": 0.5},
                {"type": "cylinder", "origin": [0, 0, 0], "axis": [0, 0, 0], "radius": 0.5},
                {"type": "bspline"}
            ]}}},
            {}
        ]}]}"#;
        let faces = read(json).unwrap();
        let p = faces[0][0].as_ref().unwrap();
        assert_eq!(p.face_indices, 7);
        assert_eq!(p.faces.len(), 5);
        assert_eq!(p.faces[0], Some(Surface64::Plane { point: DVec3::Z, normal: DVec3::Z }));
        assert_eq!(p.faces[1], None);
        assert!(matches!(p.faces[2], Some(Surface64::Cylinder { radius, .. }) if radius == 0.5));
        assert_eq!(p.faces[3], None, "a zero axis is no cylinder");
        assert_eq!(p.faces[4], None);
        assert_eq!(p.malformed, 1, "the bad cylinder is malformed, the b-spline is free-form");
        assert!(faces[0][1].is_none());
    }

    #[test]
    fn placing_a_cylinder_moves_its_axis_and_scales_its_radius() {
        let world = DMat4::from_scale_rotation_translation(DVec3::splat(2.0), DQuat::from_rotation_z(1.0), DVec3::new(1.0, 0.0, 0.0));
        let s = similarity(&world, 0.001).unwrap();
        assert!((s - 0.002).abs() < 1e-12);
        let cyl = Surface64::Cylinder { point: DVec3::ZERO, axis: DVec3::X, radius: 5.0 };
        let Surface::Cylinder { point, axis, radius } = place(&cyl, &world, 0.001, s) else { panic!() };
        assert!((radius - 0.01).abs() < 1e-7);
        assert!((point - Vec3::new(0.001, 0.0, 0.0)).length() < 1e-7);
        assert!((axis - Vec3::new(1f32.cos(), 1f32.sin(), 0.0)).length() < 1e-6);
        let uneven = DMat4::from_scale(DVec3::new(1.0, 2.0, 1.0));
        assert_eq!(similarity(&uneven, 1.0), None);
    }
}
