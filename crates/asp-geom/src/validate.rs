//! Models that load but cannot be planned, named in asp's words: zero extent, parts without a
//! triangle, parts whose triangles all have zero area, and duplicate parts (the same mesh at the
//! same place). Called once after loading ([`crate::io::load`]); every message names the file
//! (the error's path) and the part and says what to do.
//!
//! A part embedded in another's material — every vertex of it strictly inside the other's closed
//! surface, deeper than a thousandth of the model's diagonal — is refused too: no motion takes it
//! out, so it is an export's artefact (a duplicate body, a simplified envelope). A part that
//! overlaps another only in part (a press fit, a dowel) or sits in a cavity (outside the material)
//! is not: the collision world reports such pairs as overlaps
//! ([`crate::overlap::OverlapKind::Nested`] among them) and the overlap policy decides.

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
        if let Some(reason) = collapsed(part) {
            return Err(err(reason));
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
    if let Some((inner, outer)) = embedded_part(assembly) {
        let (inner, outer) = (&assembly.parts[inner].name, &assembly.parts[outer].name);
        return Err(err(format!(
            "part '{inner}' lies wholly inside the material of part '{outer}' (no motion can take it out); \
             delete one of the two bodies in the file, or export '{outer}' with the hole '{inner}' sits in"
        )));
    }
    Ok(())
}

/// The first part (`inner`, `outer`) whose every vertex lies inside `outer`'s closed surface by
/// more than a thousandth of the model's diagonal; only pairs whose boxes nest are looked at, and
/// only closed containers (an open surface has no inside).
fn embedded_part(assembly: &Assembly) -> Option<(usize, usize)> {
    use parry3d::query::PointQuery;
    use parry3d::shape::{TriMesh, TriMeshFlags};
    let depth = 1e-3 * assembly.diagonal();
    if depth.is_nan() || depth <= 0.0 {
        return None;
    }
    let boxes: Vec<_> = assembly.parts.iter().map(|p| p.mesh.aabb()).collect();
    let nests = |i: usize, o: usize| match (&boxes[i], &boxes[o]) {
        (Some(a), Some(b)) => (0..3).all(|k| a.mins[k] > b.mins[k] + depth && a.maxs[k] < b.maxs[k] - depth),
        _ => false,
    };
    for outer in 0..assembly.parts.len() {
        let candidates: Vec<usize> = (0..assembly.parts.len()).filter(|&i| i != outer && nests(i, outer)).collect();
        if candidates.is_empty() {
            continue;
        }
        let mut m = assembly.parts[outer].mesh.clone();
        m.weld();
        m.orient_outward();
        if !m.topology().is_closed_manifold() {
            continue;
        }
        let Ok(solid) = TriMesh::with_flags(m.vertices, m.triangles, TriMeshFlags::ORIENTED) else { continue };
        for inner in candidates {
            let vertices = &assembly.parts[inner].mesh.vertices;
            let embedded = !vertices.is_empty()
                && vertices.iter().all(|&v| {
                    let p = solid.project_local_point(v, true);
                    p.is_inside && (p.point - v).length() > depth
                });
            if embedded {
                return Some((inner, outer));
            }
        }
    }
    None
}

/// Triangles with three distinct corners and a non-zero normal (what welding keeps).
/// Why `part` cannot be planned when every triangle of it has zero area (what welding its
/// surface leaves: none), naming it and saying what to do; `None` when some triangle has area.
pub(crate) fn collapsed(part: &crate::assembly::Part) -> Option<String> {
    (proper_triangles(&part.mesh) == 0).then(|| {
        format!(
            "part '{}': all its {} triangles have zero area (its vertices collapse to a point or a line); \
             check the export's scale and units or remove the part",
            part.name,
            part.mesh.triangles.len()
        )
    })
}

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
        // a small cube embedded in a big one's material; in a hollow one (a cavity) it is not
        let big = Mesh::cuboid(Vec3::ZERO, Vec3::splat(4.0));
        let inner = Mesh::cuboid(Vec3::splat(1.0), Vec3::splat(2.0));
        let embedded = assembly(vec![("block", big.clone()), ("pin", inner.clone())]);
        assert!(message(&embedded).contains("part 'pin' lies wholly inside the material of part 'block'"), "{}", message(&embedded));
        let mut hollow = big.clone();
        let mut cavity = Mesh::cuboid(Vec3::splat(0.5), Vec3::splat(3.5));
        cavity.triangles.iter_mut().for_each(|t| t.swap(1, 2)); // facing inwards: the cavity's walls
        hollow.append(&cavity);
        assert!(check_model(&assembly(vec![("box", hollow), ("pin", inner.clone())])).is_ok());
        // a pin only half in (a press fit) is the overlap policy's, not refused here
        let half = Mesh::cuboid(Vec3::new(1.0, 1.0, 3.0), Vec3::new(2.0, 2.0, 5.0));
        assert!(check_model(&assembly(vec![("block", big), ("pin", half)])).is_ok());
    }
}
