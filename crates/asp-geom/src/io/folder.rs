//! Folders of OBJ / STL files (one file per part, in world coordinates) and single such files.

use super::{io_error, lowercase_first, refs, Limits, LoadOptions};
use crate::assembly::{Assembly, Part, Units};
use crate::error::{GeomError, Result};
use crate::math::{Axis, Vec3};
use crate::mesh::Mesh;
use rayon::prelude::*;
use std::io::{BufReader, Cursor};
use std::path::{Path, PathBuf};

/// The mesh formats a folder may hold.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Format {
    Obj,
    Stl,
}

impl Format {
    /// The format of `path` by its extension (any case), if it is one asp reads.
    fn of(path: &Path) -> Option<Format> {
        let ext = path.extension()?.to_str()?;
        if ext.eq_ignore_ascii_case("obj") {
            Some(Format::Obj)
        } else if ext.eq_ignore_ascii_case("stl") {
            Some(Format::Stl)
        } else {
            None
        }
    }
}

/// Loads every `.obj` / `.stl` file of `dir` as one part named after the file stem, files sorted
/// by name; other files are ignored. Default unit metres, default up +Z.
pub(crate) fn load_folder(dir: &Path, options: &LoadOptions) -> Result<Assembly> {
    let files = mesh_files(dir)?;
    if files.is_empty() {
        return Err(GeomError::format(dir, "the folder has no .obj or .stl files"));
    }
    options.limits.check_parts(files.len()).map_err(|reason| GeomError::format(dir, reason))?;
    for file in &files {
        let name = file.file_name().map(PathBuf::from).unwrap_or_default();
        refs::resolve_inside(dir, &name, &[], options.allow_outside_files)
            .map_err(|refused| GeomError::format(dir, refused.describe("file", &name.to_string_lossy())))?;
    }
    assemble(dir, &files, options)
}

/// One `.obj` / `.stl` file, its bytes in memory, as a one-part assembly.
pub(crate) fn single_file_from_bytes(file: &Path, bytes: &[u8], options: &LoadOptions) -> Result<Assembly> {
    let units = options.unit.clone().unwrap_or_else(Units::metres);
    let mut mesh = mesh_from_bytes(file, bytes, &options.limits)?;
    mesh.scale(units.metres as f32);
    Ok(Assembly {
        parts: vec![Part::new(part_name(file), mesh, false, serde_json::Value::Null)],
        units,
        up: options.up.unwrap_or(Axis::Z),
        source: file.to_path_buf(),
        warnings: Vec::new(),
    })
}

/// A part named after its file's stem.
fn part_name(file: &Path) -> String {
    file.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default()
}

/// The OBJ and STL files directly inside `dir`, sorted by file name.
fn mesh_files(dir: &Path) -> Result<Vec<PathBuf>> {
    let mut files = Vec::new();
    for entry in std::fs::read_dir(dir).map_err(|source| io_error(dir, source))? {
        let path = entry.map_err(|source| io_error(dir, source))?.path();
        if Format::of(&path).is_some() && path.is_file() {
            files.push(path);
        }
    }
    files.sort_by(|a, b| a.file_name().cmp(&b.file_name()));
    Ok(files)
}

fn assemble(source: &Path, files: &[PathBuf], options: &LoadOptions) -> Result<Assembly> {
    let units = options.unit.clone().unwrap_or_else(Units::metres);
    let scale = units.metres as f32;
    let parts = files
        .par_iter()
        .map(|file| {
            let mut mesh = read_mesh(file, &options.limits)?;
            mesh.scale(scale);
            Ok(Part::new(part_name(file), mesh, false, serde_json::Value::Null))
        })
        .collect::<Result<Vec<Part>>>()?;
    let triangles = parts.iter().map(|p| p.mesh.triangles.len()).sum();
    options.limits.check_triangles(triangles).map_err(|reason| GeomError::format(source, reason))?;
    Ok(Assembly { parts, units, up: options.up.unwrap_or(Axis::Z), source: source.to_path_buf(), warnings: Vec::new() })
}

/// The mesh of one file, in the file's units.
fn read_mesh(path: &Path, limits: &Limits) -> Result<Mesh> {
    let bytes = std::fs::read(path).map_err(|source| io_error(path, source))?;
    mesh_from_bytes(path, &bytes, limits)
}

/// The mesh of one file's bytes (`path` gives the format by its extension and names errors).
fn mesh_from_bytes(path: &Path, bytes: &[u8], limits: &Limits) -> Result<Mesh> {
    let mesh = match Format::of(path) {
        Some(Format::Obj) => read_obj(path, bytes)?,
        Some(Format::Stl) => read_stl(path, bytes, limits)?,
        None => return Err(GeomError::format(path, "not an .obj or .stl file")),
    };
    limits.check_triangles(mesh.triangles.len()).map_err(|reason| GeomError::format(path, reason))?;
    Ok(mesh)
}

/// An STL file, ASCII or binary. Identical vertices are shared (STL stores none).
fn read_stl(path: &Path, bytes: &[u8], limits: &Limits) -> Result<Mesh> {
    if is_binary_stl(bytes) {
        let announced = u32::from_le_bytes([bytes[80], bytes[81], bytes[82], bytes[83]]) as usize;
        limits.check_triangles(announced).map_err(|reason| GeomError::format(path, format!("invalid stl file: {reason}")))?;
    }
    let mut bytes = bytes.to_vec();
    if is_binary_stl(&bytes) {
        // Many CAD tools start binary headers with "solid", which stl_io takes for ASCII.
        bytes[..5].fill(0);
    }
    let stl = stl_io::read_stl(&mut Cursor::new(bytes))
        .map_err(|e| GeomError::format(path, format!("invalid stl file: {}", one_line(&lowercase_first(&e.to_string())))))?;
    let vertices = stl.vertices.iter().map(|v| Vec3::new(v.0[0], v.0[1], v.0[2])).collect();
    let triangles = stl.faces.iter().map(|f| f.vertices.map(|i| i as u32)).collect();
    Ok(Mesh::new(vertices, triangles))
}

/// Another library's message on one line (a parser may quote the offending input).
fn one_line(text: &str) -> String {
    text.split_whitespace().collect::<Vec<_>>().join(" ")
}

/// Whether the file size matches a binary STL with the triangle count of its header.
fn is_binary_stl(bytes: &[u8]) -> bool {
    match bytes.get(80..84) {
        Some(c) => {
            let triangles = u64::from(u32::from_le_bytes([c[0], c[1], c[2], c[3]]));
            84 + 50 * triangles == bytes.len() as u64
        }
        None => false,
    }
}

/// An OBJ file, polygons triangulated, all its objects and groups merged; materials are not read.
fn read_obj(path: &Path, bytes: &[u8]) -> Result<Mesh> {
    let text = std::str::from_utf8(bytes)
        .map_err(|e| GeomError::format(path, format!("invalid obj file: not utf-8 text (byte {})", e.valid_up_to())))?;
    let options = tobj::LoadOptions { triangulate: true, ignore_points: true, ignore_lines: true, ..Default::default() };
    let no_materials = |_: &Path| Err(tobj::LoadError::GenericFailure);
    let positions_only = positions_and_faces(text);
    let (models, _) = tobj::load_obj_buf(&mut BufReader::new(positions_only.as_bytes()), &options, no_materials)
        .map_err(|e| GeomError::format(path, format!("invalid obj file: {e}")))?;
    let mut mesh = Mesh::default();
    for model in &models {
        let positions = &model.mesh.positions;
        let vertices: Vec<Vec3> = positions.chunks_exact(3).map(|p| Vec3::new(p[0], p[1], p[2])).collect();
        let count = vertices.len();
        let triangles = model
            .mesh
            .indices
            .chunks_exact(3)
            .map(|t| match [t[0], t[1], t[2]] {
                t if t.iter().all(|&i| (i as usize) < count) => Ok(t),
                _ => Err(GeomError::format(path, format!("invalid obj file: object '{}' has a face index out of range", model.name))),
            })
            .collect::<Result<Vec<_>>>()?;
        mesh.append(&Mesh::new(vertices, triangles));
    }
    Ok(mesh)
}

/// The part of an OBJ file asp reads, for tobj: vertex positions (`v x y z`, colours and
/// weights dropped), faces by their position indices only (`f 1/4/2` → `f 1`), and object and
/// group names. Texture coordinates, normals, materials and every other statement are left out,
/// so tobj never indexes them: tobj 4.0.5 multiplies a face's normal and texture indices without
/// an overflow check ("attempt to multiply with overflow" on `f 1//99999999999999999999`).
fn positions_and_faces(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for line in text.lines() {
        let mut words = line.split_whitespace();
        let keyword = words.next();
        match keyword {
            Some("v") => {
                out.push('v');
                for word in words.take(3) {
                    out.push(' ');
                    out.push_str(word);
                }
            }
            Some("f") => {
                out.push('f');
                for word in words {
                    out.push(' ');
                    out.push_str(word.split('/').next().unwrap_or(word));
                }
            }
            Some(k @ ("o" | "g")) => {
                out.push_str(k);
                for word in words {
                    out.push(' ');
                    out.push_str(word);
                }
            }
            _ => continue,
        }
        out.push('\n');
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn binary_stl_detection_uses_the_size() {
        let mut bytes = b"solid but binary".to_vec();
        bytes.resize(80, b' ');
        bytes.extend(1u32.to_le_bytes());
        bytes.extend([0u8; 50]);
        assert!(is_binary_stl(&bytes));
        bytes.push(0);
        assert!(!is_binary_stl(&bytes));
        assert!(!is_binary_stl(b"solid x\nendsolid x\n"));
    }

    #[test]
    fn obj_text_keeps_positions_faces_and_names_only() {
        let text = "# c\nmtllib x.mtl\no a\nv 1 2 3 1 0.5 0.5\nvt 0 1\nvn 0 0 1\nf 1/1/1 2//1 -1/2\ng b\nl 1 2\n";
        assert_eq!(positions_and_faces(text), "o a\nv 1 2 3\nf 1 2 -1\ng b\n");
    }

    #[test]
    fn huge_normal_and_texture_indices_are_errors_not_overflows() {
        // indices below isize::MAX whose triple (normals) or double (texture coordinates) overflows:
        // tobj 4.0.5 panics on these in builds with overflow checks
        let text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvn 0 0 1\nf 1//1 2//1 3//7777777777777777777\nf 1/1 2/1 3/9000000000000000000\n";
        let mesh = read_obj(Path::new("x.obj"), text.as_bytes()).expect("the positions are valid");
        assert_eq!(mesh.triangles.len(), 2);
        let bad = "v 0 0 0\nf 1 2 99999999999999999999\n";
        assert!(read_obj(Path::new("x.obj"), bad.as_bytes()).unwrap_err().to_string().starts_with("x.obj: invalid obj"));
    }

    #[test]
    fn formats_by_extension_in_any_case() {
        assert!(Format::of(Path::new("a/b.STL")) == Some(Format::Stl));
        assert!(Format::of(Path::new("b.Obj")) == Some(Format::Obj));
        assert!(Format::of(Path::new("b.mtl")).is_none());
        assert!(Format::of(Path::new("stl")).is_none());
    }
}
