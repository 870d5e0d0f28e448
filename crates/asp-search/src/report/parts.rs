//! The plan's part list: each part's name, its place in the file's product tree, how asp
//! tessellated it, and its faces' analytic surfaces (format 1.10).

use asp_geom::io::Tessellation;
use asp_geom::surface::{Surface, SurfaceSource};
use asp_geom::{Part, Units};
use serde::{Deserialize, Serialize};

/// A part of the model.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct PartEntry {
    /// Index (position in the model).
    pub index: usize,
    /// Name (unique; parts of one name in different subassemblies carry the innermost
    /// assemblies that tell them apart, `l-bracket-assembly_1/nut-bolt-assembly_2/bolt_1`).
    pub name: String,
    /// Base part, never moved.
    pub fixed: bool,
    /// The assemblies of the file's product tree that hold the part, outermost first (STEP
    /// instances, glTF named parent nodes). Since format 1.10.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub path: Vec<String>,
    /// How asp tessellated the part's B-rep (STEP files). Since format 1.10.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tessellation: Option<TessellationEntry>,
    /// The part's faces that lie on an analytic surface, as the file's B-rep gives them (STEP,
    /// glTF with `TM_brep_faces`). Since format 1.10.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub surfaces: Vec<FaceEntry>,
}

/// How a part was tessellated (format 1.10).
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct TessellationEntry {
    /// The chord tolerance of each edge and face relative to its own size.
    pub relative: f64,
    /// The largest angle between neighbouring facets along a curved face, radians.
    pub angular: f64,
    /// The largest distance measured between a triangle (its centroid and edge midpoints) and
    /// its face's exact surface, model units; absent when no face of the part is analytic and
    /// curved (a plane's triangles lie on it).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub chord_error: Option<f64>,
}

/// One face of a part with its analytic surface (format 1.10), model units, model frame.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct FaceEntry {
    /// The face's index in the part's B-rep faces (as its triangles name it).
    pub face: usize,
    /// How many triangles of the part's mesh lie on the face.
    pub triangles: usize,
    /// `exact` (the file's B-rep) or `fitted` (recognised from the triangles).
    pub source: SurfaceSource,
    /// The surface.
    #[serde(flatten)]
    pub surface: SurfaceEntry,
}

/// An analytic surface in the plan (format 1.10), model units.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
#[serde(tag = "kind", rename_all = "lowercase")]
pub enum SurfaceEntry {
    /// A plane through `point` with unit `normal`.
    Plane {
        /// A point on the plane.
        point: [f64; 3],
        /// Unit normal.
        normal: [f64; 3],
    },
    /// A cylinder about the line through `point` along `axis`.
    Cylinder {
        /// A point on the axis.
        point: [f64; 3],
        /// Unit axis.
        axis: [f64; 3],
        /// Radius.
        radius: f64,
    },
    /// A cone with its apex at `apex`, opening along `axis`.
    Cone {
        /// The apex.
        apex: [f64; 3],
        /// Unit axis, from the apex into the cone.
        axis: [f64; 3],
        /// Half angle at the apex, radians.
        half_angle: f64,
    },
    /// A sphere.
    Sphere {
        /// The centre.
        centre: [f64; 3],
        /// Radius.
        radius: f64,
    },
    /// A torus about the line through `centre` along `axis`.
    Torus {
        /// The centre.
        centre: [f64; 3],
        /// Unit axis.
        axis: [f64; 3],
        /// Distance of the tube's centre line from the axis.
        major: f64,
        /// The tube's radius.
        minor: f64,
    },
}

impl PartEntry {
    /// The entry of part `index` of a model in `units`.
    pub fn of(index: usize, part: &Part, units: &Units) -> PartEntry {
        let u = |m: f32| round(units.from_metres(m as f64));
        let p = |v: asp_geom::math::Vec3| [u(v.x), u(v.y), u(v.z)];
        let d = |v: asp_geom::math::Vec3| [round(v.x as f64), round(v.y as f64), round(v.z as f64)];
        let mut surfaces = Vec::new();
        if let Some(faces) = &part.faces {
            let mut triangles = vec![0usize; faces.faces.len()];
            for &f in &faces.triangle_face {
                if let Some(n) = triangles.get_mut(f as usize) {
                    *n += 1;
                }
            }
            for (face, (f, &triangles)) in faces.faces.iter().zip(&triangles).enumerate() {
                let Some(s) = f.surface else { continue };
                let surface = match s {
                    Surface::Plane { point, normal } => SurfaceEntry::Plane { point: p(point), normal: d(normal) },
                    Surface::Cylinder { point, axis, radius } => {
                        SurfaceEntry::Cylinder { point: p(point), axis: d(axis), radius: u(radius) }
                    }
                    Surface::Cone { apex, axis, half_angle } => {
                        SurfaceEntry::Cone { apex: p(apex), axis: d(axis), half_angle: round(half_angle as f64) }
                    }
                    Surface::Sphere { centre, radius } => SurfaceEntry::Sphere { centre: p(centre), radius: u(radius) },
                    Surface::Torus { centre, axis, major, minor } => {
                        SurfaceEntry::Torus { centre: p(centre), axis: d(axis), major: u(major), minor: u(minor) }
                    }
                };
                surfaces.push(FaceEntry { face, triangles, source: f.source, surface });
            }
        }
        let tessellation = part.tessellation.map(|t: Tessellation| TessellationEntry {
            relative: t.relative,
            angular: t.angular,
            chord_error: part.faces.as_ref().and_then(|f| f.chord_error(&part.mesh)).map(u),
        });
        PartEntry { index, name: part.name.clone(), fixed: part.fixed, path: part.path.clone(), tessellation, surfaces }
    }
}

/// A number rounded to 7 significant digits: single-precision geometry printed without its
/// binary noise (0.0099999998 is 0.01).
fn round(x: f64) -> f64 {
    if x == 0.0 || !x.is_finite() {
        return x;
    }
    let digits = 6 - x.abs().log10().floor() as i32;
    let scale = 10f64.powi(digits.clamp(-300, 300));
    (x * scale).round() / scale
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn single_precision_noise_is_rounded_away() {
        assert_eq!(round(0.009999999776482582), 0.01);
        assert_eq!(round(-7.499999832361937), -7.5);
        assert_eq!(round(0.0), 0.0);
        assert_eq!(round(123456.789), 123456.8);
    }
}
