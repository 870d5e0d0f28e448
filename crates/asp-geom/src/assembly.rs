//! The assembly model: named parts with meshes in their assembled pose, units and the up axis.

use crate::error::{GeomError, Result};
use crate::math::{aabb_of, Aabb, Axis};
use crate::mesh::Mesh;
use crate::meta::PartMeta;
use crate::surface::PartFaces;
use std::path::PathBuf;
use std::sync::Arc;

/// How finely OpenCASCADE tessellates a STEP file's B-rep (the STEP reader), kept on each part
/// it tessellated.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tessellation {
    /// The chord tolerance of every edge and face relative to its own size (OpenCASCADE's
    /// relative deflection): a small screw is tessellated as finely, for its size, as a housing.
    pub relative: f64,
    /// The largest angle between neighbouring facets' normals along a curved face, radians.
    pub angular: f64,
}

/// The default relative chord tolerance ([`Tessellation::relative`]).
pub const DEFAULT_RELATIVE: f64 = 0.001;
/// The default angular deflection, radians ([`Tessellation::angular`]): about 25 facets
/// around a full circle.
pub const DEFAULT_ANGULAR: f64 = 0.25;

impl Default for Tessellation {
    fn default() -> Self {
        Tessellation { relative: DEFAULT_RELATIVE, angular: DEFAULT_ANGULAR }
    }
}

impl Tessellation {
    /// Checks that both tolerances are positive and finite (the angle below a half turn).
    pub fn validate(&self) -> std::result::Result<(), String> {
        if !(self.relative.is_finite() && self.relative > 0.0 && self.relative < 1.0) {
            return Err(format!("the relative tessellation tolerance must lie between 0 and 1, got {}", self.relative));
        }
        if !(self.angular.is_finite() && self.angular > 0.0 && self.angular < std::f64::consts::PI) {
            return Err(format!("the angular tessellation tolerance must lie between 0 and pi, got {}", self.angular));
        }
        Ok(())
    }
}

/// One part of an assembly, its mesh baked in its assembled pose (world frame, metres).
#[derive(Clone, Debug)]
pub struct Part {
    /// The part's name (node, mesh or file name; unique within the assembly).
    pub name: String,
    /// The surface, world frame, metres.
    pub mesh: Mesh,
    /// Base parts stay in place and are never removed.
    pub fixed: bool,
    /// Metadata from the file (`extras.asp` of a glTF node: voxels, grasp points, ...), as
    /// written; kept so that writing the model back preserves it.
    pub extras: serde_json::Value,
    /// The same metadata, typed and parsed once ([`PartMeta::from_extras`]).
    pub meta: PartMeta,
    /// The part's faces and their analytic surfaces when the file keeps its B-rep (STEP, glTF
    /// with `TM_brep_faces`), world frame, metres, one face index per triangle of `mesh`; `None`
    /// otherwise (the planner then recognises surfaces from the triangles).
    pub faces: Option<Arc<PartFaces>>,
    /// Where the part sits in the file's product tree: the names of the assemblies that hold
    /// it, outermost first (a STEP file's subassembly instances, a glTF node's named ancestors);
    /// empty when the file has no tree.
    pub path: Vec<String>,
    /// How the part's B-rep was tessellated into `mesh` when asp did it (STEP); `None` for
    /// parts that came as triangles.
    pub tessellation: Option<Tessellation>,
}

impl Part {
    /// A part with its metadata parsed from `extras` (malformed keys are ignored; loaders use
    /// [`PartMeta::from_extras`] themselves to warn about them).
    pub fn new(name: impl Into<String>, mesh: Mesh, fixed: bool, extras: serde_json::Value) -> Part {
        let (meta, _) = PartMeta::from_extras(&extras);
        Part { name: name.into(), mesh, fixed, extras, meta, faces: None, path: Vec::new(), tessellation: None }
    }
}

/// `part`'s name after the innermost `k` assemblies of its path, joined by `/`.
fn qualified(part: &Part, k: usize) -> String {
    let start = part.path.len().saturating_sub(k);
    part.path[start..].iter().chain(std::iter::once(&part.name)).cloned().collect::<Vec<_>>().join("/")
}

/// The unit the model was given in; asp works in metres and reports in this unit.
#[derive(Clone, Debug, PartialEq)]
pub struct Units {
    /// Short name, e.g. `m`, `mm`, `in`.
    pub name: String,
    /// How many metres one model unit is.
    pub metres: f64,
}

impl Units {
    /// Metres.
    pub fn metres() -> Self {
        Units { name: "m".into(), metres: 1.0 }
    }

    /// Parses `m`, `cm`, `mm`, `in`, `ft` or a plain number of metres per unit.
    pub fn parse(s: &str) -> Option<Self> {
        let metres = match s.trim().to_ascii_lowercase().as_str() {
            "m" | "meter" | "metre" | "meters" | "metres" => 1.0,
            "cm" => 0.01,
            "mm" => 0.001,
            "um" | "µm" => 1e-6,
            "in" | "inch" => 0.0254,
            "ft" | "foot" => 0.3048,
            other => other.parse::<f64>().ok().filter(|v| *v > 0.0 && v.is_finite())?,
        };
        Some(Units { name: s.trim().to_string(), metres })
    }

    /// Converts a length in metres to model units.
    pub fn from_metres(&self, metres: f64) -> f64 {
        metres / self.metres
    }
}

/// An assembled product: its parts in their assembled poses.
#[derive(Clone, Debug)]
pub struct Assembly {
    /// The parts, in file order; indices into this list identify parts everywhere in asp.
    pub parts: Vec<Part>,
    /// The unit of the input file.
    pub units: Units,
    /// The up axis; gravity points the other way.
    pub up: Axis,
    /// Where the model came from (for messages and the plan's `model` field).
    pub source: PathBuf,
    /// Non-fatal problems found while loading or preparing (skipped primitives, open meshes...),
    /// one line each, naming the part.
    pub warnings: Vec<String>,
}

impl Assembly {
    /// Number of parts.
    pub fn len(&self) -> usize {
        self.parts.len()
    }

    /// Whether there are no parts.
    pub fn is_empty(&self) -> bool {
        self.parts.is_empty()
    }

    /// The box around every part.
    pub fn aabb(&self) -> Option<Aabb> {
        aabb_of(self.parts.iter().flat_map(|p| p.mesh.vertices.iter().copied()))
    }

    /// The length of the bounding box diagonal, in metres: the model's size.
    pub fn diagonal(&self) -> f32 {
        self.aabb().map(|b| (b.maxs - b.mins).length()).unwrap_or(0.0)
    }

    /// The model of the parts at `indices` alone (in that order; indices past the end are
    /// skipped), with this model's unit, up axis and source, and no warnings: a subassembly or a
    /// core planned on its own.
    pub fn subset(&self, indices: &[usize]) -> Assembly {
        Assembly {
            parts: indices.iter().filter_map(|&i| self.parts.get(i).cloned()).collect(),
            units: self.units.clone(),
            up: self.up,
            source: self.source.clone(),
            warnings: Vec::new(),
        }
    }

    /// The index of the part called `name`.
    pub fn part_index(&self, name: &str) -> Option<usize> {
        self.parts.iter().position(|p| p.name == name)
    }

    /// The fastened pairs `(i, j)`, `i < j`, sorted, from every part's
    /// [`PartMeta::fastened_to`], and one warning per name that names no part (or the part
    /// itself).
    pub fn fastenings(&self) -> (Vec<(usize, usize)>, Vec<String>) {
        let index: std::collections::HashMap<&str, usize> = self.parts.iter().enumerate().map(|(i, p)| (p.name.as_str(), i)).collect();
        let mut pairs = std::collections::BTreeSet::new();
        let mut warnings = Vec::new();
        for (i, p) in self.parts.iter().enumerate() {
            for name in &p.meta.fastened_to {
                match index.get(name.as_str()) {
                    Some(&j) if j != i => {
                        pairs.insert((i.min(j), i.max(j)));
                    }
                    _ => warnings
                        .push(format!("part '{}' says it is fastened to '{name}', which is no other part of the model; ignored", p.name)),
                }
            }
        }
        (pairs.into_iter().collect(), warnings)
    }

    /// Marks the named parts as fixed; an unknown name is an error that lists the known ones.
    pub fn set_fixed<S: AsRef<str>>(&mut self, names: &[S]) -> Result<()> {
        for name in names {
            let name = name.as_ref();
            let i = self.part_index(name).ok_or_else(|| GeomError::Assembly {
                path: self.source.clone(),
                reason: format!(
                    "no part is named '{name}' to fix in place (parts: {})",
                    self.parts.iter().map(|p| p.name.as_str()).collect::<Vec<_>>().join(", ")
                ),
            })?;
            self.parts[i].fixed = true;
        }
        Ok(())
    }

    /// Makes part names unique. Parts of one name in different subassemblies (two instances
    /// of one bolt) are told apart by the innermost assemblies of their [`Part::path`] that
    /// differ (`l-bracket-assembly_1/nut-bolt-assembly_2/bolt_1`); repeats left after that get
    /// `_2`, `_3`, ... appended.
    pub fn dedupe_names(&mut self) {
        let mut by_name = std::collections::BTreeMap::<String, Vec<usize>>::new();
        for (i, p) in self.parts.iter().enumerate() {
            by_name.entry(p.name.clone()).or_default().push(i);
        }
        for group in by_name.into_values().filter(|g| g.len() > 1) {
            let depth = group.iter().map(|&i| self.parts[i].path.len()).max().unwrap_or(0);
            for k in 1..=depth {
                let names: Vec<String> = group.iter().map(|&i| qualified(&self.parts[i], k)).collect();
                let distinct: std::collections::HashSet<&String> = names.iter().collect();
                if distinct.len() == names.len() {
                    for (&i, name) in group.iter().zip(names) {
                        self.parts[i].name = name;
                    }
                    break;
                }
            }
        }
        let mut seen = std::collections::HashMap::<String, usize>::new();
        for p in &mut self.parts {
            let n = seen.entry(p.name.clone()).or_insert(0);
            *n += 1;
            if *n > 1 {
                p.name = format!("{}_{}", p.name, n);
            }
        }
    }

    /// Checks what every planner needs: at least one part, finite non-empty meshes.
    pub fn validate(&self) -> Result<()> {
        let err = |reason: String| GeomError::Assembly { path: self.source.clone(), reason };
        if self.parts.is_empty() {
            return Err(err("the model has no parts (empty scene)".into()));
        }
        for p in &self.parts {
            if p.mesh.triangles.is_empty() {
                return Err(err(format!("part '{}' has no triangles; remove it from the file or export its surface as triangles", p.name)));
            }
            if !p.mesh.is_finite() {
                return Err(err(format!("part '{}' has NaN or infinite vertex coordinates", p.name)));
            }
        }
        Ok(())
    }
}
