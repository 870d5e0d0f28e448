//! The analytic surfaces of a part's faces: planes, cylinders, cones, spheres and tori.
//!
//! A CAD part is a B-rep: faces, each on one surface. When the file keeps them (STEP read through
//! OpenCASCADE, glTF with the `TM_brep_faces` extension) every triangle of the part's mesh knows
//! its face and the face knows its surface exactly ([`SurfaceSource::Exact`]). When it does not
//! (STL, OBJ, glTF without the extension), or when the face is a free-form surface that happens
//! to be a cylinder (some exporters write every round face as a B-spline), the surface is
//! recognised from the triangles ([`SurfaceSource::Fitted`]), with the chord's sagitta as its
//! tolerance. Either way the planner reads the same [`PartFaces`]: which triangles form one face,
//! and what that face is.
//!
//! Everything is in the world frame and in metres, like the part's mesh.

use crate::math::{Pose, Vec3};

/// One analytic surface, world frame, metres.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Surface {
    /// A plane through `point` with unit `normal` (the face's outward normal when the face knows
    /// its side; the mesh's triangles decide otherwise).
    Plane {
        /// A point on the plane.
        point: Vec3,
        /// Unit normal.
        normal: Vec3,
    },
    /// The cylinder of `radius` about the line through `point` along unit `axis`.
    Cylinder {
        /// A point on the axis.
        point: Vec3,
        /// Unit axis direction.
        axis: Vec3,
        /// The radius.
        radius: f32,
    },
    /// The cone with its apex at `apex`, opening along unit `axis` with `half_angle` (radians).
    Cone {
        /// The apex.
        apex: Vec3,
        /// Unit axis direction, from the apex into the cone.
        axis: Vec3,
        /// The half angle at the apex, in radians.
        half_angle: f32,
    },
    /// The sphere of `radius` about `centre`.
    Sphere {
        /// The centre.
        centre: Vec3,
        /// The radius.
        radius: f32,
    },
    /// The torus about the line through `centre` along unit `axis`: tube centres at `major` from
    /// the axis, tube radius `minor`.
    Torus {
        /// The centre.
        centre: Vec3,
        /// Unit axis direction.
        axis: Vec3,
        /// Distance of the tube's centre line from the axis.
        major: f32,
        /// The tube's radius.
        minor: f32,
    },
}

impl Surface {
    /// The surface's kind as the plan JSON and the tables name it: `plane`, `cylinder`, `cone`,
    /// `sphere`, `torus`.
    pub fn kind(&self) -> &'static str {
        match self {
            Surface::Plane { .. } => "plane",
            Surface::Cylinder { .. } => "cylinder",
            Surface::Cone { .. } => "cone",
            Surface::Sphere { .. } => "sphere",
            Surface::Torus { .. } => "torus",
        }
    }

    /// The surface moved by `pose` (a rigid motion; a file's node transform).
    pub fn transformed(&self, pose: &Pose) -> Surface {
        let p = |x: Vec3| pose.transform_point(x);
        let v = |x: Vec3| (pose.rotation * x).normalize_or_zero();
        match *self {
            Surface::Plane { point, normal } => Surface::Plane { point: p(point), normal: v(normal) },
            Surface::Cylinder { point, axis, radius } => Surface::Cylinder { point: p(point), axis: v(axis), radius },
            Surface::Cone { apex, axis, half_angle } => Surface::Cone { apex: p(apex), axis: v(axis), half_angle },
            Surface::Sphere { centre, radius } => Surface::Sphere { centre: p(centre), radius },
            Surface::Torus { centre, axis, major, minor } => Surface::Torus { centre: p(centre), axis: v(axis), major, minor },
        }
    }

    /// The surface scaled by `factor` about the origin (a file's unit to metres).
    pub fn scaled(&self, factor: f32) -> Surface {
        match *self {
            Surface::Plane { point, normal } => Surface::Plane { point: point * factor, normal },
            Surface::Cylinder { point, axis, radius } => Surface::Cylinder { point: point * factor, axis, radius: radius * factor },
            Surface::Cone { apex, axis, half_angle } => Surface::Cone { apex: apex * factor, axis, half_angle },
            Surface::Sphere { centre, radius } => Surface::Sphere { centre: centre * factor, radius: radius * factor },
            Surface::Torus { centre, axis, major, minor } => {
                Surface::Torus { centre: centre * factor, axis, major: major * factor, minor: minor * factor }
            }
        }
    }

    /// The unsigned distance of `x` from the (unbounded) surface.
    pub fn distance(&self, x: Vec3) -> f32 {
        match *self {
            Surface::Plane { point, normal } => (x - point).dot(normal).abs(),
            Surface::Cylinder { point, axis, radius } => (radial(x, point, axis) - radius).abs(),
            Surface::Cone { apex, axis, half_angle } => {
                let r = x - apex;
                let h = r.dot(axis);
                let rho = (r - axis * h).length();
                // the distance to the cone's generator in the plane of x and the axis
                let (s, c) = half_angle.sin_cos();
                (rho * c - h * s).abs()
            }
            Surface::Sphere { centre, radius } => ((x - centre).length() - radius).abs(),
            Surface::Torus { centre, axis, major, minor } => {
                let r = x - centre;
                let h = r.dot(axis);
                let rho = (r - axis * h).length();
                (Vec3::new(rho - major, h, 0.0).length() - minor).abs()
            }
        }
    }
}

/// The distance of `x` from the line through `point` along unit `axis`.
pub fn radial(x: Vec3, point: Vec3, axis: Vec3) -> f32 {
    let r = x - point;
    (r - axis * r.dot(axis)).length()
}

/// Where a face's surface comes from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SurfaceSource {
    /// The file's B-rep says it exactly (STEP, glTF `TM_brep_faces`).
    Exact,
    /// Recognised from the face's triangles (within the tessellation's sagitta).
    Fitted,
}

/// One face of a part: its surface when it is analytic and known, and where that came from.
#[derive(Clone, Debug, PartialEq)]
pub struct Face {
    /// The analytic surface, `None` for free-form faces (B-splines no fit recognised).
    pub surface: Option<Surface>,
    /// Where `surface` comes from.
    pub source: SurfaceSource,
}

/// A part's faces: for each triangle of the part's mesh (in the mesh's triangle order) the index
/// of its face, and the faces.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PartFaces {
    /// Per triangle of the part's mesh, the index of its face in `faces`.
    pub triangle_face: Vec<u32>,
    /// The faces.
    pub faces: Vec<Face>,
}

impl PartFaces {
    /// Whether the faces describe a mesh of `triangles` triangles (one face index per triangle,
    /// every index in range).
    pub fn fits(&self, triangles: usize) -> bool {
        self.triangle_face.len() == triangles && self.triangle_face.iter().all(|&f| (f as usize) < self.faces.len())
    }

    /// The largest distance between a triangle of `mesh` (its centroid and edge midpoints) and
    /// its face's surface, over the faces on curved surfaces (a plane's triangles lie on it):
    /// how far the tessellation strays from the exact shape. `None` when no face is curved and
    /// analytic, or when the faces do not fit the mesh.
    pub fn chord_error(&self, mesh: &crate::mesh::Mesh) -> Option<f32> {
        if !self.fits(mesh.triangles.len()) {
            return None;
        }
        let mut worst: Option<f32> = None;
        for (t, &f) in mesh.triangles.iter().zip(&self.triangle_face) {
            let Some(surface) = self.faces[f as usize].surface else { continue };
            if matches!(surface, Surface::Plane { .. }) {
                continue;
            }
            let [a, b, c] = t.map(|i| mesh.vertices[i as usize]);
            let points = [(a + b + c) / 3.0, (a + b) / 2.0, (b + c) / 2.0, (c + a) / 2.0];
            let d = points.iter().map(|&x| surface.distance(x)).fold(0.0f32, f32::max);
            worst = Some(worst.map_or(d, |w| w.max(d)));
        }
        worst
    }

    /// The faces moved by `pose`.
    pub fn transformed(&self, pose: &Pose) -> PartFaces {
        PartFaces {
            triangle_face: self.triangle_face.clone(),
            faces: self.faces.iter().map(|f| Face { surface: f.surface.map(|s| s.transformed(pose)), source: f.source }).collect(),
        }
    }

    /// The faces scaled by `factor` about the origin.
    pub fn scaled(&self, factor: f32) -> PartFaces {
        PartFaces {
            triangle_face: self.triangle_face.clone(),
            faces: self.faces.iter().map(|f| Face { surface: f.surface.map(|s| s.scaled(factor)), source: f.source }).collect(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Rot;

    #[test]
    fn distances_to_each_surface() {
        let cyl = Surface::Cylinder { point: Vec3::ZERO, axis: Vec3::Z, radius: 2.0 };
        assert!((cyl.distance(Vec3::new(3.0, 0.0, 7.0)) - 1.0).abs() < 1e-6);
        let plane = Surface::Plane { point: Vec3::Z, normal: Vec3::Z };
        assert!((plane.distance(Vec3::new(5.0, 5.0, -1.0)) - 2.0).abs() < 1e-6);
        let cone = Surface::Cone { apex: Vec3::ZERO, axis: Vec3::Z, half_angle: std::f32::consts::FRAC_PI_4 };
        assert!(cone.distance(Vec3::new(1.0, 0.0, 1.0)) < 1e-6);
        assert!((cone.distance(Vec3::new(0.0, 0.0, 1.0)) - std::f32::consts::FRAC_1_SQRT_2).abs() < 1e-6);
        let sphere = Surface::Sphere { centre: Vec3::ONE, radius: 1.0 };
        assert!((sphere.distance(Vec3::new(1.0, 1.0, 3.0)) - 1.0).abs() < 1e-6);
        let torus = Surface::Torus { centre: Vec3::ZERO, axis: Vec3::Z, major: 3.0, minor: 1.0 };
        assert!(torus.distance(Vec3::new(4.0, 0.0, 0.0)) < 1e-6);
        assert!((torus.distance(Vec3::new(3.0, 0.0, 0.0)) - 1.0).abs() < 1e-6);
    }

    #[test]
    fn a_moved_cylinder_keeps_its_points_at_their_distance() {
        let cyl = Surface::Cylinder { point: Vec3::new(1.0, 0.0, 0.0), axis: Vec3::X, radius: 0.5 };
        let pose = Pose::from_parts(Vec3::new(0.0, 2.0, 0.0), Rot::from_rotation_z(0.7));
        let x = Vec3::new(4.0, 0.5, 0.0);
        let moved = cyl.transformed(&pose);
        assert!((moved.distance(pose.transform_point(x)) - cyl.distance(x)).abs() < 1e-5);
        assert!((cyl.scaled(2.0).distance(x * 2.0) - 2.0 * cyl.distance(x)).abs() < 1e-5);
        assert_eq!(moved.kind(), "cylinder");
    }
}
