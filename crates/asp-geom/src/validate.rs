//! Models that load but cannot be planned, named in asp's words: zero extent, parts without a
//! triangle, parts whose triangles all have zero area. Called once after loading
//! ([`crate::io::load`]); every message names the file (the error's path) and the part and says
//! what to do.
//!
//! Two common export slips are warnings, not errors: a duplicate part (the same mesh at the same
//! place) is left out, one copy planned; a part whose mesh holds several separate bodies (shelf
//! pins stored inside a shelf's mesh) is named, and split into one part per body on request
//! ([`split_bodies`], `LoadOptions::split_bodies`, `--split-bodies`).
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

/// Checks the loaded `assembly` for the degenerate cases of this module; leaves duplicate parts
/// out and warns about them and about parts of several bodies.
pub fn check_model(assembly: &mut Assembly) -> Result<()> {
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
    let mut duplicate = vec![false; assembly.parts.len()];
    for (i, part) in assembly.parts.iter().enumerate() {
        let key = mesh_hash(&part.mesh);
        if let Some(&first) = seen.get(&key) {
            let other = &assembly.parts[first];
            if (part.fixed || !other.fixed) && same_mesh(&other.mesh, &part.mesh) {
                assembly.warnings.push(format!(
                    "parts '{}' and '{}' are the same mesh at the same place (a duplicate); '{}' is left out and one copy planned",
                    other.name, part.name, part.name
                ));
                duplicate[i] = true;
            }
        } else {
            seen.insert(key, i);
        }
    }
    if duplicate.iter().any(|&d| d) {
        let mut k = 0;
        assembly.parts.retain(|_| {
            k += 1;
            !duplicate[k - 1]
        });
    }
    for part in &assembly.parts {
        let n = bodies(&part.mesh).len();
        if n > 1 {
            assembly.warnings.push(format!(
                "part '{}' holds {n} separate bodies (pieces of its mesh that do not touch); they move as one part (--split-bodies plans each as a part of its own)",
                part.name
            ));
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

/// The separate bodies of `mesh`: its connected pieces (triangles sharing vertices, after
/// welding), each with the pieces whose bounds lie inside its own (a hollow body's inner shell,
/// a hole's lining), as lists of triangle indices into the welded mesh; one body for a mesh of
/// one piece.
pub fn bodies(mesh: &Mesh) -> Vec<Vec<u32>> {
    let mut m = mesh.clone();
    let kept = m.weld_keeping();
    let n = m.vertices.len();
    let mut parent: Vec<usize> = (0..n).collect();
    fn find(p: &mut [usize], mut i: usize) -> usize {
        while p[i] != i {
            p[i] = p[p[i]];
            i = p[i];
        }
        i
    }
    for t in &m.triangles {
        let a = find(&mut parent, t[0] as usize);
        for &v in &t[1..] {
            let b = find(&mut parent, v as usize);
            if a != b {
                parent[b] = a;
            }
        }
    }
    let mut pieces: Vec<(usize, Vec<u32>)> = Vec::new();
    for (k, t) in m.triangles.iter().enumerate() {
        let root = find(&mut parent, t[0] as usize);
        match pieces.iter_mut().find(|(r, _)| *r == root) {
            Some((_, ts)) => ts.push(kept[k]),
            None => pieces.push((root, vec![kept[k]])),
        }
    }
    if pieces.len() < 2 {
        return pieces.into_iter().map(|(_, t)| t).collect();
    }
    let bounds: Vec<crate::math::Aabb> = pieces
        .iter()
        .map(|(_, ts)| {
            crate::math::aabb_of(ts.iter().flat_map(|&t| mesh.triangles[t as usize].map(|i| mesh.vertices[i as usize])))
                .expect("a piece has triangles")
        })
        .collect();
    // a piece whose bounds lie within another's belongs to the outermost such piece
    let inside = |a: &crate::math::Aabb, b: &crate::math::Aabb| (0..3).all(|k| a.mins[k] >= b.mins[k] && a.maxs[k] <= b.maxs[k]);
    let owner: Vec<usize> = (0..pieces.len())
        .map(|i| {
            (0..pieces.len())
                .filter(|&j| j != i && inside(&bounds[i], &bounds[j]) && !(inside(&bounds[j], &bounds[i]) && j > i))
                .max_by(|&a, &b| (bounds[a].maxs - bounds[a].mins).length().total_cmp(&(bounds[b].maxs - bounds[b].mins).length()))
                .unwrap_or(i)
        })
        .collect();
    let mut out: Vec<(usize, Vec<u32>)> = Vec::new();
    for (i, (_, ts)) in pieces.into_iter().enumerate() {
        match out.iter_mut().find(|(o, _)| *o == owner[i]) {
            Some((_, all)) => all.extend(ts),
            None => out.push((owner[i], ts)),
        }
    }
    out.into_iter()
        .map(|(_, mut t)| {
            t.sort_unstable();
            t
        })
        .collect()
}

/// Splits every part of several bodies ([`bodies`]) into one part per body, named
/// `name#1`, `name#2`, ... in the order of their first triangle; the file's metadata stays with
/// the first body. Returns the names of the parts split.
pub fn split_bodies(assembly: &mut Assembly) -> Vec<String> {
    let mut split = Vec::new();
    let mut parts = Vec::with_capacity(assembly.parts.len());
    for part in std::mem::take(&mut assembly.parts) {
        let pieces = bodies(&part.mesh);
        if pieces.len() < 2 {
            parts.push(part);
            continue;
        }
        split.push(part.name.clone());
        for (k, tris) in pieces.iter().enumerate() {
            let mut mesh = Mesh::new(part.mesh.vertices.clone(), tris.iter().map(|&t| part.mesh.triangles[t as usize]).collect());
            mesh.weld();
            let extras = if k == 0 { part.extras.clone() } else { serde_json::Value::Null };
            let mut p = crate::assembly::Part::new(format!("{}#{}", part.name, k + 1), mesh, part.fixed, extras);
            if k == 0 {
                p.meta = part.meta.clone();
            }
            parts.push(p);
        }
    }
    assembly.parts = parts;
    split
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
        check_model(&mut a.clone()).unwrap_err().to_string()
    }

    fn check(mut a: Assembly) -> Result<Assembly> {
        check_model(&mut a).map(|_| a)
    }

    #[test]
    fn degenerate_models_are_named() {
        assert!(check(assembly(vec![("a", cube(0.0)), ("b", cube(2.0))])).is_ok());
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
        // a duplicate is left out with a warning, one copy planned
        let twice = check(assembly(vec![("a", cube(0.0)), ("a_2", cube(0.0)), ("b", cube(2.0))])).unwrap();
        assert_eq!(twice.parts.iter().map(|p| p.name.as_str()).collect::<Vec<_>>(), ["a", "b"]);
        assert!(
            twice.warnings[0].contains("parts 'a' and 'a_2' are the same mesh at the same place (a duplicate); 'a_2' is left out"),
            "{:?}",
            twice.warnings
        );
        // the same mesh elsewhere is not a duplicate
        assert!(check(assembly(vec![("a", cube(0.0)), ("a_2", cube(1.0))])).is_ok());
        // a small cube embedded in a big one's material; in a hollow one (a cavity) it is not
        let big = Mesh::cuboid(Vec3::ZERO, Vec3::splat(4.0));
        let inner = Mesh::cuboid(Vec3::splat(1.0), Vec3::splat(2.0));
        let embedded = assembly(vec![("block", big.clone()), ("pin", inner.clone())]);
        assert!(message(&embedded).contains("part 'pin' lies wholly inside the material of part 'block'"), "{}", message(&embedded));
        let mut hollow = big.clone();
        let mut cavity = Mesh::cuboid(Vec3::splat(0.5), Vec3::splat(3.5));
        cavity.triangles.iter_mut().for_each(|t| t.swap(1, 2)); // facing inwards: the cavity's walls
        hollow.append(&cavity);
        let with_cavity = check(assembly(vec![("box", hollow.clone()), ("pin", inner.clone())])).unwrap();
        // a hollow body's inner shell is no second body
        assert!(with_cavity.warnings.is_empty(), "{:?}", with_cavity.warnings);
        assert_eq!(bodies(&hollow).len(), 1);
        // a pin only half in (a press fit) is the overlap policy's, not refused here
        let half = Mesh::cuboid(Vec3::new(1.0, 1.0, 3.0), Vec3::new(2.0, 2.0, 5.0));
        assert!(check(assembly(vec![("block", big), ("pin", half)])).is_ok());
    }

    #[test]
    fn a_part_of_several_bodies_is_named_and_split_on_request() {
        // a shelf whose mesh also holds two pins beside it
        let mut shelf = Mesh::cuboid(Vec3::ZERO, Vec3::new(4.0, 2.0, 0.2));
        shelf.append(&Mesh::cuboid(Vec3::new(5.0, 0.0, 0.0), Vec3::new(5.2, 0.2, 1.0)));
        shelf.append(&Mesh::cuboid(Vec3::new(6.0, 0.0, 0.0), Vec3::new(6.2, 0.2, 1.0)));
        let a = check(assembly(vec![("shelf", shelf), ("side", cube(8.0))])).unwrap();
        assert!(a.warnings.iter().any(|w| w.starts_with("part 'shelf' holds 3 separate bodies")), "{:?}", a.warnings);
        let mut a = a;
        assert_eq!(split_bodies(&mut a), ["shelf"]);
        let names: Vec<&str> = a.parts.iter().map(|p| p.name.as_str()).collect();
        assert_eq!(names, ["shelf#1", "shelf#2", "shelf#3", "side"]);
        assert_eq!(a.parts[0].mesh.triangles.len(), 12);
        assert!(a.parts.iter().all(|p| bodies(&p.mesh).len() == 1));
    }
}
