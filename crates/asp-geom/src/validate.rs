//! Models that load but cannot be planned, named in asp's words: zero extent, parts without a
//! triangle, parts whose triangles all have zero area, and duplicate parts (the same mesh at the
//! same place). Called once after loading ([`crate::io::load`]); every message names the file
//! (the error's path) and the part and says what to do.
//!
//! A part wholly inside another is not refused here: the collision world reports such pairs as
//! nested overlaps ([`crate::overlap::OverlapKind::Nested`]) and the overlap policy decides.

use crate::assembly::Assembly;
use crate::error::{GeomError, Result};
use crate::mesh::Mesh;
use std::collections::HashMap;
use std::hash::{Hash, Hasher};

/// Checks the loaded `assembly` for the degenerate cases of this module.
pub fn check_model(assembly: &Assembly) -> Result<()> {
    let err = |reason: String| GeomError::Assembly { path: assembly.source.clone(), reason };
    for part in &assembly.parts {
        if part.mesh.triangles.is_empty() {
            return Err(err(format!("part '{}' has no triangles; remove it from the file or export its surface as triangles", part.name)));
        }
    }
    if assembly.parts.iter().all(|p| p.mesh.is_finite()) && assembly.diagonal() <= 0.0 {
        return Err(err("the model has zero extent (every vertex lies at one point); check the export's scale and units".into()));
    }
    for part in &assembly.parts {
        let triangles = part.mesh.triangles.len();
        if proper_triangles(&part.mesh) == 0 {
            return Err(err(format!(
                "part '{}': all its {triangles} triangles have zero area (its vertices collapse to a point or a line); \
                 check the export's scale and units or remove the part",
                part.name
            )));
        }
    }
    let mut seen: HashMap<u64, usize> = HashMap::new();
    for (i, part) in assembly.parts.iter().enumerate() {
        let key = mesh_hash(&part.mesh);
        if let Some(&first) = seen.get(&key) {
            let other = &assembly.parts[first];
            if same_mesh(&other.mesh, &part.mesh) {
                return Err(err(format!(
                    "parts '{}' and '{}' are the same mesh at the same place (a duplicate); delete one of them in the file",
                    other.name, part.name
                )));
            }
        } else {
            seen.insert(key, i);
        }
    }
    Ok(())
}

/// Triangles with three distinct corners and a non-zero normal (what welding keeps).
fn proper_triangles(mesh: &Mesh) -> usize {
    let bits = |i: u32| mesh.vertices[i as usize].to_array().map(|c| (c + 0.0).to_bits());
    mesh.triangles
        .iter()
        .filter(|t| {
            let [a, b, c] = t.map(bits);
            a != b && b != c && a != c && mesh.triangle_normal(t).length_squared() > 0.0
        })
        .count()
}

fn mesh_hash(mesh: &Mesh) -> u64 {
    let mut h = std::collections::hash_map::DefaultHasher::new();
    for v in &mesh.vertices {
        v.to_array().map(f32::to_bits).hash(&mut h);
    }
    mesh.triangles.hash(&mut h);
    h.finish()
}

fn same_mesh(a: &Mesh, b: &Mesh) -> bool {
    a.triangles == b.triangles
        && a.vertices.len() == b.vertices.len()
        && a.vertices.iter().zip(&b.vertices).all(|(p, q)| p.to_array().map(f32::to_bits) == q.to_array().map(f32::to_bits))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::assembly::{Part, Units};
    use crate::math::{Axis, Vec3};

    fn assembly(parts: Vec<(&str, Mesh)>) -> Assembly {
        Assembly {
            parts: parts.into_iter().map(|(n, m)| Part::new(n, m, false, serde_json::Value::Null)).collect(),
            units: Units::metres(),
            up: Axis::Z,
            source: "m.glb".into(),
            warnings: Vec::new(),
        }
    }

    fn cube(at: f32) -> Mesh {
        Mesh::cuboid(Vec3::splat(at), Vec3::splat(at + 1.0))
    }

    fn message(a: &Assembly) -> String {
        check_model(a).unwrap_err().to_string()
    }

    #[test]
    fn degenerate_models_are_named() {
        assert!(check_model(&assembly(vec![("a", cube(0.0)), ("b", cube(2.0))])).is_ok());
        let empty = assembly(vec![("a", cube(0.0)), ("e", Mesh::default())]);
        assert!(message(&empty).starts_with("m.glb: part 'e' has no triangles"), "{}", message(&empty));
        let line = Mesh::new(vec![Vec3::ZERO, Vec3::X, Vec3::X * 2.0], vec![[0, 1, 2], [0, 2, 1]]);
        let flat = assembly(vec![("a", cube(0.0)), ("l", line)]);
        assert!(message(&flat).contains("part 'l': all its 2 triangles have zero area"), "{}", message(&flat));
        let mut point = cube(0.0);
        point.scale(0.0);
        assert!(message(&assembly(vec![("p", point.clone())])).contains("the model has zero extent"));
        let mut small = point;
        small.vertices[0] = Vec3::X;
        assert!(message(&assembly(vec![("a", cube(0.0)), ("p", small)])).contains("part 'p': all its 12 triangles have zero area"));
        let twice = assembly(vec![("a", cube(0.0)), ("a_2", cube(0.0)), ("b", cube(2.0))]);
        assert!(message(&twice).contains("parts 'a' and 'a_2' are the same mesh at the same place"), "{}", message(&twice));
        // the same mesh elsewhere is not a duplicate
        assert!(check_model(&assembly(vec![("a", cube(0.0)), ("a_2", cube(1.0))])).is_ok());
    }
}
