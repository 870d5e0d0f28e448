//! One part's collision geometry: its parry mesh, bounds, cached eroded copies, exact boxes,
//! strict-overlap samples and symmetry axis.

use crate::erode::{eroded_mesh, eroded_near};
use crate::error::{GeomError, Result};
use crate::fastener::SymmetryAxis;
use crate::fits::Surfaces;
use crate::math::{Aabb, Vec3};
use crate::mesh::{Mesh, Topology};
use crate::surface::PartFaces;
use crate::sweep;
use parry3d::query::PointQuery;
use parry3d::shape::{TriMesh, TriMeshFlags};
use std::collections::BTreeMap;
use std::sync::{Arc, Mutex, OnceLock};

/// One part's collision geometry.
pub(super) struct Geom {
    pub(super) mesh: Arc<TriMesh>,
    pub(super) aabb: Aabb,
    /// Eroded copies keyed by the erosion amount's bits.
    pub(super) eroded: Mutex<BTreeMap<u32, Arc<TriMesh>>>,
    pub(super) closed: bool,
    /// The part's exact boxes when it is a known union of boxes ([`crate::boxes`]): pairs of
    /// such parts are tested exactly on them instead of on the meshes.
    pub(super) boxes: Option<Vec<Aabb>>,
    /// Surface samples moved inward by the tolerance, for the strict overlap test (made the
    /// first time a strict pair needs them).
    pub(super) samples: OnceLock<Vec<Vec3>>,
    /// The axis of near rotational symmetry (fasteners), made when first needed.
    pub(super) axis: OnceLock<Option<SymmetryAxis>>,
    /// The file's B-rep faces, one face index per triangle of `mesh` (after welding).
    pub(super) faces: Option<PartFaces>,
    /// The part's cylinders and planes ([`crate::fits::recognise`]), made when first needed.
    pub(super) surfaces: OnceLock<Surfaces>,
}

impl Geom {
    /// The collision geometry of `mesh`, and the topology of its welded surface.
    pub(super) fn new(mesh: &Mesh, faces: Option<&PartFaces>) -> Result<(Geom, Topology)> {
        let mut m = mesh.clone();
        let kept = m.weld_keeping();
        // the file's faces follow the triangles that welding keeps
        let faces = faces
            .filter(|f| f.fits(mesh.triangles.len()))
            .map(|f| PartFaces { triangle_face: kept.iter().map(|&k| f.triangle_face[k as usize]).collect(), faces: f.faces.clone() });
        m.orient_outward();
        let topology = m.topology();
        let closed = topology.is_closed_manifold();
        let aabb = m.aabb().ok_or_else(|| GeomError::config("empty mesh"))?;
        let mesh = TriMesh::with_flags(m.vertices, m.triangles, TriMeshFlags::ORIENTED)
            .map_err(|e| GeomError::config(format!("cannot build a collision mesh: {e}")))?;
        let geom = Geom {
            mesh: Arc::new(mesh),
            aabb,
            eroded: Mutex::new(BTreeMap::new()),
            closed,
            boxes: None,
            samples: OnceLock::new(),
            axis: OnceLock::new(),
            faces,
            surfaces: OnceLock::new(),
        };
        Ok((geom, topology))
    }

    /// A copy sharing the meshes, with the caches made so far (for a world that tests the same
    /// geometry under another overlap policy).
    pub(super) fn share(&self) -> Geom {
        Geom {
            mesh: self.mesh.clone(),
            aabb: self.aabb,
            eroded: Mutex::new(self.eroded.lock().unwrap_or_else(|e| e.into_inner()).clone()),
            closed: self.closed,
            boxes: self.boxes.clone(),
            samples: self.samples.clone(),
            axis: self.axis.clone(),
            faces: self.faces.clone(),
            surfaces: self.surfaces.clone(),
        }
    }

    /// The part's cylinders and planes (made once).
    pub(super) fn surfaces(&self) -> &Surfaces {
        self.surfaces.get_or_init(|| crate::fits::recognise::surfaces(self.mesh.vertices(), self.mesh.indices(), self.faces.as_ref()))
    }

    pub(super) fn eroded_cached(&self, amount: f32) -> bool {
        self.eroded.lock().unwrap_or_else(|e| e.into_inner()).contains_key(&amount.to_bits())
    }

    pub(super) fn eroded(&self, amount: f32) -> Arc<TriMesh> {
        let mut cache = self.eroded.lock().unwrap_or_else(|e| e.into_inner());
        cache.entry(amount.to_bits()).or_insert_with(|| Arc::new(self.erode(amount))).clone()
    }

    pub(super) fn erode(&self, amount: f32) -> TriMesh {
        let (v, t) = eroded_mesh(self.mesh.vertices(), self.mesh.indices(), amount);
        if v.len() == self.mesh.vertices().len() && t == self.mesh.indices() {
            // the same triangles with moved vertices (no saddle vertex was split): refit a copy
            // of the part's BVH and keep its topology instead of building both again
            let mut shrunk = (*self.mesh).clone();
            shrunk.set_vertices(&v);
            return shrunk;
        }
        TriMesh::with_flags(v, t, TriMeshFlags::ORIENTED).unwrap_or_else(|_| (*self.mesh).clone())
    }

    /// Whether this part shrunk by `amount` still overlaps `other`: surfaces crossing, or one
    /// wholly inside the other.
    pub(super) fn eroded_hits(&self, amount: f32, other: &Geom) -> bool {
        // the tolerance's erosion is cached (every later test of the part uses it); the deeper
        // trial erosions of overlapping pairs are tested as triangle soups (no BVH to build)
        let shrunk = self.eroded_cached(amount).then(|| self.eroded(amount));
        let (inside, around) = (other.closed && nests(&self.aabb, &other.aabb), self.closed && nests(&other.aabb, &self.aabb));
        let soup;
        let (vertices, triangles): (&[Vec3], &[[u32; 3]]) = match &shrunk {
            Some(m) => (m.vertices(), m.indices()),
            None if inside => {
                // the containment test below asks for the shrunk mesh's first vertex
                soup = eroded_mesh(self.mesh.vertices(), self.mesh.indices(), amount);
                (&soup.0, &soup.1)
            }
            None => {
                // only the triangles that may reach the other part: a trial erosion costs the
                // overlap's neighbourhood, not the whole mesh
                soup = eroded_near(self.mesh.vertices(), self.mesh.indices(), amount, &other.aabb);
                (&soup.0, &soup.1)
            }
        };
        let crosses = match &shrunk {
            // the cached erosion has its BVH: descend both trees together
            Some(m) => sweep::meshes_cross(m, &other.mesh),
            None => sweep::soup_crosses(vertices, triangles, &other.mesh),
        };
        crosses
            || (inside && contains_point(&other.mesh, vertices[0]))
            || (around && {
                let shrunk = shrunk.unwrap_or_else(|| Arc::new(self.erode(amount)));
                contains_point(&shrunk, other.mesh.vertices()[0])
            })
    }
}

/// Whether box `a` lies within box `b`.
pub(super) fn nests(a: &Aabb, b: &Aabb) -> bool {
    (0..3).all(|i| a.mins[i] >= b.mins[i] && a.maxs[i] <= b.maxs[i])
}

/// Whether `point` is inside the closed mesh.
pub(super) fn contains_point(mesh: &TriMesh, point: Vec3) -> bool {
    mesh.local_aabb().contains_local_point(point) && mesh.project_local_point(point, false).is_inside
}
