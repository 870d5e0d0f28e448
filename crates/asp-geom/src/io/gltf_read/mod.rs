//! glTF 2.0 reader (`.glb`, `.gltf` with external or embedded buffers).
//!
//! Every mesh instance of the default scene (else the first scene) becomes one part, its mesh
//! baked in world coordinates and converted to metres. The `gltf` crate parses and validates the
//! JSON; buffer data is read here with explicit bounds checks, because the crate's accessor
//! iterators panic on some malformed files.

use super::brep_faces::{self, BrepFaces, Surface64};
use super::{lowercase_first, refs, Limits, LoadOptions, MAX_ZERO_FILLED};
use crate::assembly::{Assembly, Part, Units};
use crate::error::{GeomError, Result};
use crate::math::{Axis, Pose, Vec3};
use crate::mesh::Mesh;
use crate::meta::PartMeta;
use crate::surface::{Face, PartFaces, SurfaceSource};
use gltf::accessor::{DataType, Dimensions};
use gltf::mesh::{Mode, Semantic};
use gltf::scene::Transform;
use gltf::{Accessor, Document, Node, Primitive, Scene};
use parry3d::glamx::{DMat4, DQuat, DVec3};
use serde_json::Value;
use std::borrow::Cow;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// Inside this module a failure is just its reason; [`read_gltf_bytes`] adds the file name.
type Res<T> = std::result::Result<T, String>;

mod accessors;
use accessors::{read_accessor, read_indices, read_positions};

/// Reads a `.glb` or `.gltf` file from its bytes: one part per mesh instance of the default
/// scene; `external` reads the files its buffer URIs point to.
pub(crate) fn read_gltf_bytes(path: &Path, bytes: &[u8], options: &LoadOptions, external: &External) -> Result<Assembly> {
    read_gltf(path, bytes, options, external).map_err(|reason| GeomError::format(path, reason))
}

/// Reads an external file a `.gltf` refers to.
pub(crate) type External<'e> = dyn Fn(&Path) -> std::io::Result<Vec<u8>> + 'e;

fn read_gltf(path: &Path, bytes: &[u8], options: &LoadOptions, external: &External) -> Res<Assembly> {
    let (json, blob) = if bytes.starts_with(b"glTF") {
        split_glb(bytes)?
    } else if has_glb_extension(path) {
        return Err("not a glb file (the 'gltf' magic bytes are missing)".into());
    } else {
        (bytes, None)
    };
    let document = parse_document(json)?;
    let brep = match document.extensions_used().any(|e| e == brep_faces::EXTENSION) {
        true => brep_faces::read(json)?,
        false => Vec::new(),
    };
    let buffers = load_buffers(&document, path, blob, options.allow_outside_files, external)?;
    let scene = document.default_scene().or_else(|| document.scenes().next());
    let settings = scene.as_ref().map(scene_settings).transpose()?.unwrap_or_default();
    let units = options.unit.clone().or(settings.unit).unwrap_or_else(Units::metres);
    let up = options.up.or(settings.up).unwrap_or(Axis::Y);
    let mut builder = PartBuilder::new(&document, buffers, units.metres, options.limits, brep);
    if let Some(scene) = &scene {
        check_announced(&document, scene, &options.limits)?;
        builder.add_scene(scene)?;
    }
    Ok(Assembly { parts: builder.parts, units, up, source: path.to_path_buf(), warnings: builder.warnings })
}

fn has_glb_extension(path: &Path) -> bool {
    path.extension().and_then(|e| e.to_str()).is_some_and(|e| e.eq_ignore_ascii_case("glb"))
}

// ---------------------------------------------------------------------------------------------
// Container and document

/// Splits a GLB file into its JSON chunk and its optional BIN chunk.
fn split_glb(bytes: &[u8]) -> Res<(&[u8], Option<&[u8]>)> {
    let (version, length) = match (read_u32(bytes, 4), read_u32(bytes, 8)) {
        (Some(version), Some(length)) => (version, length as usize),
        _ => return Err("truncated glb: the 12-byte header is incomplete".into()),
    };
    if version != 2 {
        return Err(format!("unsupported glb version {version} (expected 2)"));
    }
    if length > bytes.len() {
        return Err(format!("truncated glb: the header announces {length} bytes but the file has {}", bytes.len()));
    }
    let body = &bytes[..length];
    let mut chunks = Vec::new();
    let mut at = 12;
    while at < body.len() {
        let (Some(len), Some(kind)) = (read_u32(body, at), body.get(at + 4..at + 8)) else {
            return Err(format!("truncated glb: incomplete chunk header at byte {at}"));
        };
        let start = at + 8;
        let Some(data) = start.checked_add(len as usize).and_then(|end| body.get(start..end)) else {
            return Err(format!("truncated glb: a chunk announces {len} bytes but only {} remain", body.len() - start));
        };
        chunks.push((kind, data));
        at = start + data.len();
    }
    match chunks.as_slice() {
        [(b"JSON", json), rest @ ..] => {
            let bin = rest.iter().find(|(kind, _)| *kind == b"BIN\0").map(|(_, data)| *data);
            Ok((json, bin))
        }
        _ => Err("corrupted glb: the first chunk is not json".into()),
    }
}

fn read_u32(bytes: &[u8], at: usize) -> Option<u32> {
    let b = bytes.get(at..at.checked_add(4)?)?;
    Some(u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
}

/// Parses and validates the glTF JSON.
fn parse_document(json: &[u8]) -> Res<Document> {
    let root = gltf::json::Root::from_slice(json).map_err(|e| format!("invalid gltf json: {e}"))?;
    // gltf-json's validation indexes the POSITION accessor without a bounds check: check first.
    for (m, mesh) in root.meshes.iter().enumerate() {
        for (p, primitive) in mesh.primitives.iter().enumerate() {
            if let Some(bad) = primitive.attributes.values().find(|a| a.value() >= root.accessors.len()) {
                return Err(format!("invalid gltf: meshes[{m}].primitives[{p}] uses accessor {} which does not exist", bad.value()));
            }
        }
    }
    Document::from_json(root).map_err(|e| match e {
        gltf::Error::Validation(errors) => describe_validation(&errors),
        other => format!("invalid gltf: {}", lowercase_first(&other.to_string())),
    })
}

fn describe_validation(errors: &[(gltf::json::Path, gltf::json::validation::Error)]) -> String {
    let shown: Vec<String> = errors.iter().take(3).map(|(path, error)| format!("{path}: {error}")).collect();
    let more = match errors.len().saturating_sub(shown.len()) {
        0 => String::new(),
        n => format!(" (and {n} more)"),
    };
    format!("invalid gltf: {}{more}", shown.join("; "))
}

// ---------------------------------------------------------------------------------------------
// Buffers

/// The bytes of every buffer, in document order.
fn load_buffers<'a>(
    document: &Document,
    path: &Path,
    blob: Option<&'a [u8]>,
    allow_outside: bool,
    external: &External,
) -> Res<Vec<Cow<'a, [u8]>>> {
    document
        .buffers()
        .map(|buffer| {
            let data = buffer_data(&buffer, path, blob, allow_outside, external)?;
            if data.len() < buffer.length() {
                return Err(format!("truncated buffer {}: {} bytes, expected {}", buffer.index(), data.len(), buffer.length()));
            }
            Ok(data)
        })
        .collect()
}

fn buffer_data<'a>(
    buffer: &gltf::Buffer,
    path: &Path,
    blob: Option<&'a [u8]>,
    allow_outside: bool,
    external: &External,
) -> Res<Cow<'a, [u8]>> {
    let index = buffer.index();
    match buffer.source() {
        gltf::buffer::Source::Bin => {
            blob.map(Cow::Borrowed).ok_or_else(|| format!("buffer {index} has no uri and the file has no binary chunk"))
        }
        gltf::buffer::Source::Uri(uri) if uri.starts_with("data:") => gltf::buffer::Data::from_source(buffer.source(), None)
            .map(|data| Cow::Owned(data.0))
            .map_err(|e| format!("buffer {index}: invalid data uri ({e})")),
        gltf::buffer::Source::Uri(uri) => {
            let reference = external_file(uri).ok_or_else(|| format!("buffer {index}: unsupported uri '{uri}'"))?;
            let folder = path.parent().unwrap_or(Path::new(""));
            let file = refs::resolve_inside(folder, &reference, &[], allow_outside)
                .map_err(|refused| refused.describe(&format!("buffer {index} uri"), uri))?;
            external(&file).map(Cow::Owned).map_err(|e| match e.kind() {
                std::io::ErrorKind::NotFound => {
                    format!("buffer file '{}' is missing", file.display())
                }
                _ => format!("cannot read buffer file '{}': {}", file.display(), lowercase_first(&e.to_string())),
            })
        }
    }
}

/// Where a buffer URI points, relative to the glTF file's folder (a `file:` URI gives an
/// absolute path). None for other schemes.
fn external_file(uri: &str) -> Option<PathBuf> {
    let decoded = percent_decode(uri)?;
    if let Some(rest) = decoded.strip_prefix("file://").or_else(|| decoded.strip_prefix("file:")) {
        return Some(PathBuf::from(rest));
    }
    if decoded.contains("://") {
        return None;
    }
    Some(PathBuf::from(decoded))
}

/// Decodes `%xx` escapes of a URI; None when the result is not UTF-8.
fn percent_decode(uri: &str) -> Option<String> {
    let bytes = uri.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        let hex = bytes.get(i + 1..i + 3).and_then(|h| std::str::from_utf8(h).ok());
        match (bytes[i], hex.and_then(|h| u8::from_str_radix(h, 16).ok())) {
            (b'%', Some(byte)) => {
                out.push(byte);
                i += 3;
            }
            (byte, _) => {
                out.push(byte);
                i += 1;
            }
        }
    }
    String::from_utf8(out).ok()
}

// ---------------------------------------------------------------------------------------------
// Scene settings and node metadata

/// What the scene's `extras.asp` says about the file.
#[derive(Default)]
struct SceneSettings {
    unit: Option<Units>,
    up: Option<Axis>,
}

fn scene_settings(scene: &Scene) -> Res<SceneSettings> {
    let asp = parse_extras(scene.extras(), "scene")?.and_then(|mut e| e.get_mut("asp").map(Value::take));
    let Some(asp) = asp else { return Ok(SceneSettings::default()) };
    let text = |key: &str| match asp.get(key) {
        None | Some(Value::Null) => Ok(None),
        Some(Value::String(s)) => Ok(Some(s.clone())),
        Some(Value::Number(n)) => Ok(Some(n.to_string())),
        Some(other) => Err(format!("scene extras.asp.{key} must be a string, not {other}")),
    };
    let unit = match text("unit")? {
        Some(s) => Some(Units::parse(&s).ok_or_else(|| format!("scene extras.asp.unit '{s}' is not a known unit"))?),
        None => None,
    };
    let up = match text("up")? {
        Some(s) => Some(Axis::parse(&s).ok_or_else(|| format!("scene extras.asp.up '{s}' is not an axis such as +z"))?),
        None => None,
    };
    Ok(SceneSettings { unit, up })
}

/// A node's `extras.asp` object without its `fixed` key (kept in [`Part::fixed`] instead), and
/// the fixed flag. An absent or empty object gives `Value::Null`.
fn node_metadata(node: &Node, label: &str) -> Res<(Value, bool)> {
    let mut asp = parse_extras(node.extras(), label)?.and_then(|mut e| e.get_mut("asp").map(Value::take)).unwrap_or(Value::Null);
    let fixed = match asp.as_object_mut().and_then(|m| m.remove("fixed")) {
        None => false,
        Some(Value::Bool(fixed)) => fixed,
        Some(other) => return Err(format!("{label}: extras.asp.fixed must be true or false, not {other}")),
    };
    if asp.as_object().is_some_and(|m| m.is_empty()) {
        asp = Value::Null;
    }
    Ok((asp, fixed))
}

fn parse_extras(extras: &gltf::json::Extras, label: &str) -> Res<Option<Value>> {
    extras.as_ref().map(|raw| serde_json::from_str(raw.get())).transpose().map_err(|e| format!("{label}: invalid extras ({e})"))
}

// ---------------------------------------------------------------------------------------------
// Parts

/// A mesh's triangle primitives merged, in the mesh's own frame, before any node transform.
#[derive(Clone)]
struct LocalMesh {
    vertices: Vec<DVec3>,
    triangles: Vec<[u32; 3]>,
    /// Descriptions of skipped (point or line) primitives.
    skipped: Vec<String>,
    /// The B-rep face of each triangle and the faces' surfaces (`TM_brep_faces`), when a
    /// primitive of the mesh has them.
    faces: Option<LocalFaces>,
    /// Problems with the mesh's `TM_brep_faces` (one line each, without the part's name).
    face_warnings: Vec<String>,
}

/// A primitive's `TM_brep_faces`: per triangle its face, per face its surface, and how many
/// entries were malformed.
type PrimitiveBrep = (Vec<u32>, Vec<Option<Surface64>>, usize);

/// A mesh's faces in its own frame: per triangle its face, per face its surface.
#[derive(Clone, Default)]
struct LocalFaces {
    triangle_face: Vec<u32>,
    surfaces: Vec<Option<Surface64>>,
}

/// Walks the scene and collects one part per mesh instance.
struct PartBuilder<'a> {
    buffers: Vec<Cow<'a, [u8]>>,
    /// Metres per model unit.
    scale: f64,
    /// Meshes already read, by mesh index (instanced meshes are read once).
    meshes: Vec<Option<LocalMesh>>,
    node_count: usize,
    parts: Vec<Part>,
    warnings: Vec<String>,
    limits: Limits,
    /// Triangles of the parts so far (checked against `limits` before each mesh is baked).
    triangles: usize,
    /// The `TM_brep_faces` extension of each mesh's primitives.
    brep: BrepFaces,
    /// The document (for the accessors the extension names).
    document: &'a Document,
}

impl<'a> PartBuilder<'a> {
    fn new(document: &'a Document, buffers: Vec<Cow<'a, [u8]>>, scale: f64, limits: Limits, brep: BrepFaces) -> Self {
        PartBuilder {
            buffers,
            scale,
            meshes: vec![None; document.meshes().len()],
            node_count: document.nodes().len(),
            parts: Vec::new(),
            warnings: Vec::new(),
            limits,
            triangles: 0,
            brep,
            document,
        }
    }

    /// Visits the scene's node trees depth first (an explicit stack: no recursion limit), in
    /// file order, composing transforms from the roots down.
    fn add_scene(&mut self, scene: &Scene) -> Res<()> {
        let mut seen = vec![false; self.node_count];
        let mut stack: Vec<(Node, DMat4, Arc<Vec<String>>)> =
            scene.nodes().map(|node| (node, DMat4::IDENTITY, Arc::new(Vec::new()))).collect();
        stack.reverse();
        while let Some((node, parent, path)) = stack.pop() {
            if std::mem::replace(&mut seen[node.index()], true) {
                return Err(format!("invalid node hierarchy: node {} is reached twice (a cycle or several parents)", node.index()));
            }
            let world = parent * local_matrix(&node)?;
            if let Some(mesh) = node.mesh() {
                self.add_instance(&node, &mesh, &world, &path)?;
            }
            // a named node with children is an assembly: its name is on its parts' paths
            let inner = match node.name() {
                Some(name) if node.children().len() > 0 => Arc::new(path.iter().cloned().chain([name.to_string()]).collect()),
                _ => path,
            };
            let first_child = stack.len();
            stack.extend(node.children().map(|child| (child, world, inner.clone())));
            stack[first_child..].reverse();
        }
        Ok(())
    }

    fn add_instance(&mut self, node: &Node, mesh: &gltf::Mesh, world: &DMat4, path: &[String]) -> Res<()> {
        let name = node.name().or(mesh.name()).map(str::to_string).unwrap_or_else(|| format!("part_{}", self.parts.len()));
        if name.len() > MAX_NAME_BYTES {
            return Err(format!("node {}: its name has {} bytes (at most {MAX_NAME_BYTES}); shorten it", node.index(), name.len()));
        }
        let label = format!("node '{name}'");
        self.limits.check_parts(self.parts.len() + 1)?;
        let local = self.local_mesh(mesh)?;
        self.triangles += local.triangles.len();
        self.limits.check_triangles(self.triangles).map_err(|e| format!("{label}: {e}"))?;
        if local.triangles.is_empty() && !local.skipped.is_empty() {
            self.warnings.push(format!("{label}: its mesh has only point or line primitives; not a part"));
            return Ok(());
        }
        for skipped in &local.skipped {
            self.warnings.push(format!("part '{name}': skipped {skipped}; only triangles are used"));
        }
        let (extras, fixed) = node_metadata(node, &label)?;
        let mesh = bake(&local, world, self.scale);
        let (meta, problems) = PartMeta::from_extras(&extras);
        for problem in problems {
            self.warnings.push(format!("part '{name}': {problem}"));
        }
        let (_, rotation, translation) = world.to_scale_rotation_translation();
        let pose = Pose::from_parts((translation * self.scale).as_vec3(), rotation.as_quat());
        let mut part = Part::new(name, mesh, fixed, extras);
        part.meta = meta.transformed(&pose, self.scale as f32);
        part.path = path.to_vec();
        for problem in &local.face_warnings {
            self.warnings.push(format!("part '{}': {problem}", part.name));
        }
        if let Some(faces) = &local.faces {
            let s = brep_faces::similarity(world, self.scale);
            if s.is_none() && faces.surfaces.iter().any(Option::is_some) {
                self.warnings.push(format!(
                    "part '{}': its node transform shears or scales unevenly; its faces' exact surfaces are not used",
                    part.name
                ));
            }
            let faces = faces
                .surfaces
                .iter()
                .map(|f| Face {
                    surface: s.and_then(|s| f.as_ref().map(|f| brep_faces::place(f, world, self.scale, s))),
                    source: SurfaceSource::Exact,
                })
                .collect();
            part.faces = Some(Arc::new(PartFaces { triangle_face: faces_of(&local), faces }));
        }
        self.parts.push(part);
        Ok(())
    }

    /// The mesh's triangle primitives merged in its own frame (read once per mesh).
    fn local_mesh(&mut self, mesh: &gltf::Mesh) -> Res<LocalMesh> {
        if let Some(Some(done)) = self.meshes.get(mesh.index()) {
            return Ok(done.clone());
        }
        let label = match mesh.name() {
            Some(name) => format!("mesh '{name}'"),
            None => format!("mesh {}", mesh.index()),
        };
        let mut local =
            LocalMesh { vertices: Vec::new(), triangles: Vec::new(), skipped: Vec::new(), faces: None, face_warnings: Vec::new() };
        let mut faces = LocalFaces::default();
        for primitive in mesh.primitives() {
            let context = format!("{label}, primitive {}", primitive.index());
            if !is_triangles(primitive.mode()) {
                let mode = format!("{:?}", primitive.mode()).to_lowercase();
                local.skipped.push(format!("{context} ({mode})"));
                continue;
            }
            let announced = announced_triangles(&primitive);
            self.limits
                .check_triangles(self.triangles + local.triangles.len() + announced)
                .map_err(|reason| format!("{context}: {reason}"))?;
            let (vertices, triangles) = self.read_primitive(&primitive).map_err(|reason| format!("{context}: {reason}"))?;
            match self.primitive_faces(mesh, &primitive, triangles.len()) {
                Ok(Some((indices, surfaces, malformed))) => {
                    if malformed > 0 {
                        local.face_warnings.push(format!(
                            "{context}: {malformed} faces of {} have malformed surfaces; they are used as free-form faces",
                            brep_faces::EXTENSION
                        ));
                    }
                    let offset = faces.surfaces.len() as u32;
                    faces.triangle_face.extend(indices.iter().map(|f| f + offset));
                    faces.surfaces.extend(surfaces);
                    local.faces = Some(LocalFaces::default());
                }
                outcome => {
                    if let Err(problem) = outcome {
                        local.face_warnings.push(format!("{context}: {problem}; its triangles have no b-rep faces"));
                    }
                    // one face without a surface for the whole primitive
                    faces.triangle_face.extend(std::iter::repeat_n(faces.surfaces.len() as u32, triangles.len()));
                    faces.surfaces.push(None);
                }
            }
            // the running total is checked below, so the previous one fits in u32
            let base = local.vertices.len() as u32;
            local.vertices.extend(vertices);
            if u32::try_from(local.vertices.len()).is_err() {
                return Err(format!("{label}: more than 2^32 vertices"));
            }
            local.triangles.extend(triangles.iter().map(|t| t.map(|i| i + base)));
        }
        if local.faces.is_some() {
            local.faces = Some(faces);
        }
        if let Some(slot) = self.meshes.get_mut(mesh.index()) {
            *slot = Some(local.clone());
        }
        Ok(local)
    }

    /// The `TM_brep_faces` of a primitive of `triangles` triangles: per triangle its face, and
    /// the faces' surfaces (as many as the largest index needs), and how many entries were
    /// malformed. `Ok(None)` without the extension; an error says why it cannot be used.
    fn primitive_faces(&self, mesh: &gltf::Mesh, primitive: &Primitive, triangles: usize) -> Res<Option<PrimitiveBrep>> {
        let Some(ext) = self.brep.get(mesh.index()).and_then(|m| m.get(primitive.index())).and_then(Option::as_ref) else {
            return Ok(None);
        };
        if primitive.mode() != Mode::Triangles {
            return Err(format!("{} applies to triangle lists only", brep_faces::EXTENSION));
        }
        let accessor = self
            .document
            .accessors()
            .nth(ext.face_indices)
            .ok_or_else(|| format!("its faceIndices accessor {} does not exist", ext.face_indices))?;
        let unsigned = matches!(accessor.data_type(), DataType::U8 | DataType::U16 | DataType::U32);
        if accessor.dimensions() != Dimensions::Scalar || !unsigned || accessor.normalized() || accessor.count() != triangles {
            return Err(format!("its faceIndices accessor {} is not one unsigned integer per triangle", ext.face_indices));
        }
        let indices: Vec<u32> = read_accessor(&accessor, &self.buffers)?.into_iter().map(|f| f as u32).collect();
        let count = indices.iter().map(|&f| f as usize + 1).max().unwrap_or(0).max(ext.faces.len());
        let mut surfaces = ext.faces.clone();
        surfaces.resize(count, None);
        Ok(Some((indices, surfaces, ext.malformed)))
    }

    fn read_primitive(&self, primitive: &Primitive) -> Res<(Vec<DVec3>, Vec<[u32; 3]>)> {
        let positions = primitive.get(&Semantic::Positions).ok_or("no position attribute")?;
        let vertices = read_positions(&positions, &self.buffers)?;
        let indices = match primitive.indices() {
            Some(accessor) => read_indices(&accessor, &self.buffers, vertices.len())?,
            None => (0..vertices.len()).map(|i| i as u32).collect(),
        };
        Ok((vertices, triangulate(primitive.mode(), &indices)?))
    }
}

/// Checks the parts and triangles the scene announces (every mesh instance counted, from the
/// accessors' counts) against the caps before any buffer data is read: an instancing bomb (a
/// small mesh placed by thousands of nodes) is refused before it takes memory.
fn check_announced(document: &Document, scene: &Scene, limits: &Limits) -> Res<()> {
    let per_mesh: Vec<usize> = document
        .meshes()
        .map(|m| m.primitives().filter(|p| is_triangles(p.mode())).map(|p| announced_triangles(&p)).fold(0, usize::saturating_add))
        .collect();
    let mut seen = vec![false; document.nodes().len()];
    let mut stack: Vec<Node> = scene.nodes().collect();
    let (mut parts, mut triangles) = (0usize, 0usize);
    while let Some(node) = stack.pop() {
        if std::mem::replace(&mut seen[node.index()], true) {
            continue; // a cycle or a second parent: reported while the scene is read
        }
        if let Some(mesh) = node.mesh() {
            parts += 1;
            triangles = triangles.saturating_add(per_mesh[mesh.index()]);
        }
        stack.extend(node.children());
    }
    limits.check_parts(parts)?;
    limits.check_triangles(triangles)
}

/// The merged face index of each triangle of `local` (checked to match its triangles).
fn faces_of(local: &LocalMesh) -> Vec<u32> {
    local.faces.as_ref().map(|f| f.triangle_face.clone()).unwrap_or_default()
}

/// The longest part name accepted (bytes): names are printed in tables, errors and pages.
const MAX_NAME_BYTES: usize = 1024;

/// The triangles a primitive's header counts announce (before any data is read).
fn announced_triangles(primitive: &Primitive) -> usize {
    let count = match primitive.indices() {
        Some(indices) => indices.count(),
        None => primitive.get(&Semantic::Positions).map_or(0, |p| p.count()),
    };
    match primitive.mode() {
        Mode::Triangles => count / 3,
        _ => count.saturating_sub(2),
    }
}

fn is_triangles(mode: Mode) -> bool {
    matches!(mode, Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan)
}

/// The node's local transform as a matrix (glTF: `matrix`, or translation × rotation × scale).
fn local_matrix(node: &Node) -> Res<DMat4> {
    let finite = match node.transform() {
        Transform::Matrix { matrix } => matrix.iter().flatten().all(|v| v.is_finite()),
        Transform::Decomposed { translation, rotation, scale } => translation.iter().chain(&rotation).chain(&scale).all(|v| v.is_finite()),
    };
    if !finite {
        let name = node.name().map(|n| format!(" ('{n}')")).unwrap_or_default();
        return Err(format!("node {}{name}: its transform has NaN or infinite values", node.index()));
    }
    match node.transform() {
        Transform::Matrix { matrix } => Ok(DMat4::from_cols_array_2d(&matrix.map(|c| c.map(f64::from)))),
        Transform::Decomposed { translation, rotation, scale } => {
            let rotation = DQuat::from_array(rotation.map(f64::from));
            let length = rotation.length();
            if !length.is_finite() || length <= 1e-9 {
                return Err(format!("node {}: rotation is not a unit quaternion", node.index()));
            }
            Ok(DMat4::from_scale_rotation_translation(
                DVec3::from_array(scale.map(f64::from)),
                rotation.normalize(),
                DVec3::from_array(translation.map(f64::from)),
            ))
        }
    }
}

/// The mesh moved by `world` and scaled to metres. A mirroring transform reverses the winding
/// (glTF spec), so triangles are flipped back to keep their outward side.
fn bake(local: &LocalMesh, world: &DMat4, scale: f64) -> Mesh {
    let vertices = local
        .vertices
        .iter()
        .map(|v| {
            let p = world.transform_point3(*v) * scale;
            Vec3::new(p.x as f32, p.y as f32, p.z as f32)
        })
        .collect();
    let mirrored = world.determinant() < 0.0;
    let triangles = local.triangles.iter().map(|&[a, b, c]| if mirrored { [a, c, b] } else { [a, b, c] }).collect();
    Mesh::new(vertices, triangles)
}

/// Triangles from a triangle list, strip or fan (strips and fans drop their degenerate
/// stitching triangles).
fn triangulate(mode: Mode, indices: &[u32]) -> Res<Vec<[u32; 3]>> {
    let n = indices.len();
    let triangles: Vec<[u32; 3]> = match mode {
        Mode::Triangles if !n.is_multiple_of(3) => {
            return Err(format!("{n} triangle indices is not a multiple of 3"));
        }
        Mode::Triangles => {
            return Ok(indices.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect());
        }
        // spec: triangle i of a strip is (p_i, p_{i+1+i%2}, p_{i+2-i%2})
        Mode::TriangleStrip => (0..n.saturating_sub(2)).map(|i| [indices[i], indices[i + 1 + i % 2], indices[i + 2 - i % 2]]).collect(),
        // spec: triangle i of a fan is (p_{i+1}, p_{i+2}, p_0)
        Mode::TriangleFan => (0..n.saturating_sub(2)).map(|i| [indices[i + 1], indices[i + 2], indices[0]]).collect(),
        other => return Err(format!("{other:?} is not a triangle mode").to_lowercase()),
    };
    Ok(triangles.into_iter().filter(|[a, b, c]| a != b && b != c && a != c).collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn strips_and_fans_follow_the_spec_winding() {
        let strip = triangulate(Mode::TriangleStrip, &[0, 1, 2, 3, 4]).unwrap();
        assert_eq!(strip, vec![[0, 1, 2], [1, 3, 2], [2, 3, 4]]);
        let fan = triangulate(Mode::TriangleFan, &[0, 1, 2, 3]).unwrap();
        assert_eq!(fan, vec![[1, 2, 0], [2, 3, 0]]);
        // degenerate stitching triangles are dropped
        assert!(triangulate(Mode::TriangleStrip, &[0, 1, 1, 2]).unwrap().is_empty());
        assert!(triangulate(Mode::Triangles, &[0, 1, 2, 3]).is_err());
    }

    #[test]
    fn percent_decoding() {
        assert_eq!(percent_decode("my%20parts.bin").as_deref(), Some("my parts.bin"));
        assert_eq!(percent_decode("100%").as_deref(), Some("100%"));
        assert_eq!(percent_decode("%ff"), None);
    }

    #[test]
    fn glb_headers_that_lie_are_errors() {
        assert!(split_glb(b"glTF").unwrap_err().contains("truncated"));
        let mut short = b"glTF".to_vec();
        short.extend(2u32.to_le_bytes());
        short.extend(4u32.to_le_bytes()); // length smaller than the header itself
        assert!(split_glb(&short).unwrap_err().contains("not json"));
    }
}
