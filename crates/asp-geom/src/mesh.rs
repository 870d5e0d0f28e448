//! Triangle meshes: the geometry of one part, in world coordinates (metres).

use crate::math::{aabb_of, Aabb, Pose, Vec3};
use std::collections::HashMap;

/// An indexed triangle mesh. Triangles wind counter-clockwise seen from outside when the mesh
/// is closed and oriented (see [`Mesh::orient_outward`]).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Mesh {
    /// Vertex positions.
    pub vertices: Vec<Vec3>,
    /// Vertex indices of each triangle.
    pub triangles: Vec<[u32; 3]>,
}

/// Facts about a mesh's topology, used to warn about meshes the removal test cannot trust.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Topology {
    /// Edges used by one triangle only (holes in the surface).
    pub boundary_edges: usize,
    /// Edges used by more than two triangles.
    pub non_manifold_edges: usize,
    /// Edges whose two triangles traverse them in the same direction (inconsistent winding).
    pub misoriented_edges: usize,
}

impl Topology {
    /// A closed, 2-manifold, consistently wound surface.
    pub fn is_closed_manifold(&self) -> bool {
        self.boundary_edges == 0 && self.non_manifold_edges == 0 && self.misoriented_edges == 0
    }
}

impl Mesh {
    /// A mesh from vertices and triangles.
    pub fn new(vertices: Vec<Vec3>, triangles: Vec<[u32; 3]>) -> Self {
        Mesh { vertices, triangles }
    }

    /// An axis-aligned box, outward wound.
    pub fn cuboid(mins: Vec3, maxs: Vec3) -> Self {
        let mut m = Mesh::default();
        m.push_quad_box(mins, maxs);
        m
    }

    fn push_quad_box(&mut self, a: Vec3, b: Vec3) {
        let base = self.vertices.len() as u32;
        for i in 0..8u32 {
            let pick = |bit: u32, lo: f32, hi: f32| if i & bit != 0 { hi } else { lo };
            self.vertices.push(Vec3::new(pick(1, a.x, b.x), pick(2, a.y, b.y), pick(4, a.z, b.z)));
        }
        // faces as (v0,v1,v2,v3) counter-clockwise from outside
        const FACES: [[u32; 4]; 6] = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]];
        for f in FACES {
            self.triangles.push([base + f[0], base + f[1], base + f[2]]);
            self.triangles.push([base + f[0], base + f[2], base + f[3]]);
        }
    }

    /// The closed surface of a union of unit voxels (integer cell coordinates), scaled by
    /// `cell` and shifted by `origin`. Faces between two occupied cells are left out, and vertices
    /// are shared, so the result is closed and consistently wound whenever the cells are
    /// face-connected without edge-only contacts; each boundary face is split in two triangles.
    pub fn from_voxels(cells: &[[i32; 3]], cell: Vec3, origin: Vec3) -> Self {
        let occupied: std::collections::HashSet<[i32; 3]> = cells.iter().copied().collect();
        let mut index: HashMap<[i32; 3], u32> = HashMap::new();
        let mut mesh = Mesh::default();
        let mut vertex = |mesh: &mut Mesh, c: [i32; 3]| -> u32 {
            *index.entry(c).or_insert_with(|| {
                mesh.vertices.push(origin + Vec3::new(c[0] as f32, c[1] as f32, c[2] as f32) * cell);
                (mesh.vertices.len() - 1) as u32
            })
        };
        let mut sorted: Vec<[i32; 3]> = occupied.iter().copied().collect();
        sorted.sort_unstable();
        for c in sorted {
            for axis in 0..3 {
                for positive in [false, true] {
                    let mut n = c;
                    n[axis] += if positive { 1 } else { -1 };
                    if occupied.contains(&n) {
                        continue;
                    }
                    // the four corners of the face, counter-clockwise seen from outside
                    let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
                    let corner = |du: i32, dv: i32| {
                        let mut p = c;
                        p[axis] += positive as i32;
                        p[u] += du;
                        p[v] += dv;
                        p
                    };
                    let mut quad = [corner(0, 0), corner(1, 0), corner(1, 1), corner(0, 1)];
                    if !positive {
                        quad.reverse();
                    }
                    let q = quad.map(|p| vertex(&mut mesh, p));
                    mesh.triangles.push([q[0], q[1], q[2]]);
                    mesh.triangles.push([q[0], q[2], q[3]]);
                }
            }
        }
        mesh
    }

    /// Appends another mesh (e.g. a second glTF primitive of the same part).
    pub fn append(&mut self, other: &Mesh) {
        let base = self.vertices.len() as u32;
        self.vertices.extend_from_slice(&other.vertices);
        self.triangles.extend(other.triangles.iter().map(|t| t.map(|i| i + base)));
    }

    /// This mesh moved by `pose`.
    pub fn transformed(&self, pose: &Pose) -> Mesh {
        Mesh { vertices: self.vertices.iter().map(|v| pose.transform_point(*v)).collect(), triangles: self.triangles.clone() }
    }

    /// Multiplies every coordinate by `factor` (unit conversion).
    pub fn scale(&mut self, factor: f32) {
        for v in &mut self.vertices {
            *v *= factor;
        }
    }

    /// The bounding box, or None for an empty mesh.
    pub fn aabb(&self) -> Option<Aabb> {
        aabb_of(self.vertices.iter().copied())
    }

    /// Whether every vertex coordinate is finite.
    pub fn is_finite(&self) -> bool {
        self.vertices.iter().all(|v| v.is_finite())
    }

    /// Signed volume (positive for a closed mesh wound outward).
    pub fn signed_volume(&self) -> f64 {
        self.triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| self.vertices[i as usize].as_dvec3());
                a.dot(b.cross(c)) / 6.0
            })
            .sum()
    }

    /// Total surface area.
    pub fn area(&self) -> f64 {
        self.triangles.iter().map(|t| self.triangle_normal(t).length() as f64 * 0.5).sum()
    }

    /// The (unnormalised, length = 2 × area) normal of triangle `t`.
    pub fn triangle_normal(&self, t: &[u32; 3]) -> Vec3 {
        let [a, b, c] = t.map(|i| self.vertices[i as usize]);
        (b - a).cross(c - a)
    }

    /// Flips every triangle when the signed volume is negative, so normals point outward.
    /// Returns true when it flipped.
    pub fn orient_outward(&mut self) -> bool {
        if self.signed_volume() < 0.0 {
            for t in &mut self.triangles {
                t.swap(1, 2);
            }
            true
        } else {
            false
        }
    }

    /// Merges vertices with bit-identical coordinates (real files often duplicate vertices per
    /// face for flat shading) and drops triangles that became degenerate. Exact on purpose: a
    /// grid snap, however fine, can fuse distinct vertices of small features and open holes.
    pub fn weld(&mut self) {
        self.weld_keeping();
    }

    /// [`Mesh::weld`], returning for each triangle kept its index before welding (so per-triangle
    /// data such as B-rep face indices can follow).
    pub fn weld_keeping(&mut self) -> Vec<u32> {
        let mut map: HashMap<[u32; 3], u32> = HashMap::new();
        let mut remap = Vec::with_capacity(self.vertices.len());
        let mut vertices = Vec::new();
        for v in &self.vertices {
            // +0.0 and -0.0 are the same point
            let key = [v.x + 0.0, v.y + 0.0, v.z + 0.0].map(f32::to_bits);
            let id = *map.entry(key).or_insert_with(|| {
                vertices.push(*v);
                (vertices.len() - 1) as u32
            });
            remap.push(id);
        }
        self.vertices = vertices;
        let tris = std::mem::take(&mut self.triangles);
        let (kept, tris): (Vec<u32>, Vec<[u32; 3]>) = tris
            .into_iter()
            .enumerate()
            .map(|(k, t)| (k as u32, t.map(|i| remap[i as usize])))
            .filter(|(_, t)| t[0] != t[1] && t[1] != t[2] && t[0] != t[2] && self.triangle_normal(t).length_squared() > 0.0)
            .unzip();
        self.triangles = tris;
        kept
    }

    /// Counts boundary, non-manifold and misoriented edges.
    pub fn topology(&self) -> Topology {
        // key: undirected edge; value: (uses, uses in the direction lo->hi)
        let mut edges: HashMap<(u32, u32), (u32, u32)> = HashMap::new();
        for t in &self.triangles {
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                let e = edges.entry((a.min(b), a.max(b))).or_default();
                e.0 += 1;
                e.1 += (a < b) as u32;
            }
        }
        let mut topo = Topology::default();
        for (uses, forward) in edges.values() {
            match uses {
                1 => topo.boundary_edges += 1,
                2 => topo.misoriented_edges += (*forward != 1) as usize,
                _ => topo.non_manifold_edges += 1,
            }
        }
        topo
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cuboid_is_closed_and_outward() {
        let m = Mesh::cuboid(Vec3::ZERO, Vec3::new(1.0, 2.0, 3.0));
        assert!(m.topology().is_closed_manifold());
        assert!((m.signed_volume() - 6.0).abs() < 1e-9);
        assert!((m.area() - 22.0).abs() < 1e-5);
    }

    #[test]
    fn voxels_drop_interior_faces() {
        let cells = [[0, 0, 0], [1, 0, 0], [1, 1, 0], [1, 1, 1]];
        let m = Mesh::from_voxels(&cells, Vec3::ONE, Vec3::ZERO);
        assert!(m.topology().is_closed_manifold(), "{:?}", m.topology());
        assert!((m.signed_volume() - 4.0).abs() < 1e-9);
        // 4 cubes × 6 faces − 3 shared pairs × 2 = 18 faces
        assert_eq!(m.triangles.len(), 36);
    }

    #[test]
    fn weld_and_orient_fix_a_flat_shaded_inverted_box() {
        let mut m = Mesh::default();
        let b = Mesh::cuboid(Vec3::ZERO, Vec3::ONE);
        for t in &b.triangles {
            let base = m.vertices.len() as u32;
            m.vertices.extend(t.map(|i| b.vertices[i as usize]));
            m.triangles.push([base, base + 2, base + 1]); // inverted
        }
        assert_eq!(m.topology().boundary_edges, 36);
        m.weld();
        assert_eq!(m.vertices.len(), 8);
        assert!(m.orient_outward());
        assert!(m.topology().is_closed_manifold());
        assert!(m.signed_volume() > 0.0);
    }
}
