//! Writing an assembly as GLB (binary glTF 2.0), by hand: the `gltf` crate only reads.
//!
//! One node per part (named after the part, one mesh of f32 positions and u32 triangle
//! indices), coordinates in the assembly's units, the fixed flag and metadata in the node's
//! `extras.asp`, the unit and up axis in the scene's `extras.asp`, so that
//! [`load`](super::load) reads the file back with no extra options. The output depends only on
//! the assembly: the same assembly gives the same bytes.

use super::io_error;
use crate::assembly::{Assembly, Part, Units};
use crate::error::{GeomError, Result};
use serde_json::{json, Map, Value};
use std::path::Path;

/// glTF constants: component types and buffer view targets.
const FLOAT: u32 = 5126;
const UNSIGNED_INT: u32 = 5125;
const ARRAY_BUFFER: u32 = 34962;
const ELEMENT_ARRAY_BUFFER: u32 = 34963;
const TRIANGLES: u32 = 4;

/// Writes `assembly` to `path` as a GLB file that [`load`](super::load) reads back unchanged
/// (names, fixed flags, part extras, units, up axis, and vertex positions up to f32 rounding).
///
/// Fails when a part has no triangles, non-finite vertices or out-of-range indices, or when its
/// extras are neither null nor a JSON object.
pub fn write_glb(assembly: &Assembly, path: &Path) -> Result<()> {
    let bytes = glb_bytes(assembly).map_err(|reason| GeomError::format(path, reason))?;
    std::fs::write(path, bytes).map_err(|source| io_error(path, source))
}

/// The whole GLB file.
fn glb_bytes(assembly: &Assembly) -> std::result::Result<Vec<u8>, String> {
    if assembly.parts.is_empty() {
        return Err("cannot write an assembly with no parts".into());
    }
    let mut doc = GltfBuilder::default();
    for part in &assembly.parts {
        doc.add_part(part, &assembly.units)?;
    }
    let scene_extras = json!({"asp": {"up": assembly.up.to_string(), "unit": unit_label(&assembly.units)}});
    let json = json!({
        "asset": {"version": "2.0", "generator": "asp"},
        "scene": 0,
        "scenes": [{"nodes": (0..assembly.parts.len()).collect::<Vec<_>>(), "extras": scene_extras}],
        "nodes": doc.nodes,
        "meshes": doc.meshes,
        "accessors": doc.accessors,
        "bufferViews": doc.views,
        "buffers": [{"byteLength": doc.bin.len()}],
    });
    let json = serde_json::to_vec(&json).map_err(|e| format!("cannot encode the gltf json: {e}"))?;
    container(json, doc.bin)
}

/// The unit name, when [`Units::parse`] gives it back; otherwise the number of metres per unit.
fn unit_label(units: &Units) -> String {
    match Units::parse(&units.name) {
        Some(parsed) if (parsed.metres - units.metres).abs() <= 1e-12 * units.metres => units.name.clone(),
        _ => units.metres.to_string(),
    }
}

/// The JSON arrays and the binary buffer, filled part by part.
#[derive(Default)]
struct GltfBuilder {
    nodes: Vec<Value>,
    meshes: Vec<Value>,
    accessors: Vec<Value>,
    views: Vec<Value>,
    bin: Vec<u8>,
}

impl GltfBuilder {
    fn add_part(&mut self, part: &Part, units: &Units) -> std::result::Result<(), String> {
        check_part(part)?;
        let positions: Vec<[f32; 3]> =
            part.mesh.vertices.iter().map(|v| [v.x, v.y, v.z].map(|c| units.from_metres(f64::from(c)) as f32)).collect();
        let (min, max) = bounds(&positions);
        let indices: Vec<u32> = part.mesh.triangles.iter().flatten().copied().collect();
        let position = self.add_accessor(
            positions.iter().flatten().flat_map(|c| c.to_le_bytes()).collect(),
            ARRAY_BUFFER,
            json!({"componentType": FLOAT, "count": positions.len(), "type": "VEC3", "min": min, "max": max}),
        );
        let index_range = (indices.iter().min(), indices.iter().max());
        let index = self.add_accessor(
            indices.iter().flat_map(|i| i.to_le_bytes()).collect(),
            ELEMENT_ARRAY_BUFFER,
            json!({"componentType": UNSIGNED_INT, "count": indices.len(), "type": "SCALAR",
                   "min": [index_range.0], "max": [index_range.1]}),
        );
        let mesh = self.meshes.len();
        self.meshes.push(json!({
            "name": part.name,
            "primitives": [{"attributes": {"POSITION": position}, "indices": index, "mode": TRIANGLES}],
        }));
        self.nodes.push(json!({"name": part.name, "mesh": mesh, "extras": node_extras(part)?}));
        Ok(())
    }

    /// Appends `data` as a new buffer view and an accessor over it; returns the accessor index.
    fn add_accessor(&mut self, data: Vec<u8>, target: u32, mut accessor: Value) -> usize {
        accessor["bufferView"] = json!(self.views.len());
        self.views.push(json!({"buffer": 0, "byteOffset": self.bin.len(), "byteLength": data.len(), "target": target}));
        self.bin.extend(data);
        self.accessors.push(accessor);
        self.accessors.len() - 1
    }
}

/// What a valid glTF mesh needs: triangles, finite coordinates, indices in range.
fn check_part(part: &Part) -> std::result::Result<(), String> {
    let mesh = &part.mesh;
    if mesh.triangles.is_empty() {
        return Err(format!("part '{}' has no triangles", part.name));
    }
    if !mesh.is_finite() {
        return Err(format!("part '{}' has NaN or infinite vertex coordinates", part.name));
    }
    if mesh.triangles.iter().flatten().any(|&i| i as usize >= mesh.vertices.len()) {
        return Err(format!("part '{}' has a triangle index out of range", part.name));
    }
    Ok(())
}

/// Per-axis minimum and maximum (the accessor `min`/`max` that glTF requires for positions).
fn bounds(points: &[[f32; 3]]) -> ([f32; 3], [f32; 3]) {
    let mut min = [f32::INFINITY; 3];
    let mut max = [f32::NEG_INFINITY; 3];
    for p in points {
        for k in 0..3 {
            min[k] = min[k].min(p[k]);
            max[k] = max[k].max(p[k]);
        }
    }
    (min, max)
}

/// `{"asp": {...part.extras..., "fixed": <bool>}}`.
fn node_extras(part: &Part) -> std::result::Result<Value, String> {
    let mut asp = match &part.extras {
        Value::Null => Map::new(),
        Value::Object(map) => map.clone(),
        _ => return Err(format!("part '{}': extras must be a json object or null", part.name)),
    };
    asp.insert("fixed".into(), Value::Bool(part.fixed));
    Ok(json!({ "asp": asp }))
}

/// The GLB container: 12-byte header, JSON chunk padded with spaces, BIN chunk padded with
/// zeros, every chunk 4-byte aligned.
fn container(mut json: Vec<u8>, mut bin: Vec<u8>) -> std::result::Result<Vec<u8>, String> {
    pad(&mut json, b' ');
    pad(&mut bin, 0);
    let total = 12 + 8 + json.len() + 8 + bin.len();
    let too_large = |_| format!("the model is too large for a glb file ({total} bytes)");
    let total32 = u32::try_from(total).map_err(too_large)?;
    let mut out = Vec::with_capacity(total);
    out.extend(b"glTF");
    out.extend(2u32.to_le_bytes());
    out.extend(total32.to_le_bytes());
    for (kind, data) in [(b"JSON", &json), (b"BIN\0", &bin)] {
        // both lengths are below `total`, which fits in u32
        out.extend((data.len() as u32).to_le_bytes());
        out.extend(kind);
        out.extend(data.iter());
    }
    Ok(out)
}

fn pad(data: &mut Vec<u8>, with: u8) {
    data.resize(data.len().next_multiple_of(4), with);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn container_is_aligned_and_sized() {
        let glb = container(b"{}".to_vec(), vec![1, 2, 3, 4, 5]).unwrap();
        assert_eq!(glb.len() % 4, 0);
        assert_eq!(u32::from_le_bytes(glb[8..12].try_into().unwrap()) as usize, glb.len());
        assert_eq!(&glb[20..24], b"{}  ");
        assert_eq!(&glb[24..28], &8u32.to_le_bytes());
        assert_eq!(&glb[36..40], &[5, 0, 0, 0]);
    }

    #[test]
    fn unknown_unit_names_are_written_as_numbers() {
        assert_eq!(unit_label(&Units::parse("mm").unwrap()), "mm");
        assert_eq!(unit_label(&Units { name: "furlong".into(), metres: 201.168 }), "201.168");
    }
}
