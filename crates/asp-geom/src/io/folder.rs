//! Folders of OBJ / STL files (one file per part, in world coordinates) and single such files.

use super::{io_error, lowercase_first, LoadOptions};
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
    assemble(dir, &files, options)
}

/// Loads one `.obj` / `.stl` file as a one-part assembly.
pub(crate) fn load_single_file(file: &Path, options: &LoadOptions) -> Result<Assembly> {
    assemble(file, &[file.to_path_buf()], options)
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
            let mut mesh = read_mesh(file)?;
            mesh.scale(scale);
            let name = file.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
            Ok(Part::new(name, mesh, false, serde_json::Value::Null))
        })
        .collect::<Result<Vec<Part>>>()?;
    Ok(Assembly {
        parts,
        units,
        up: options.up.unwrap_or(Axis::Z),
        source: source.to_path_buf(),
        warnings: Vec::new(),
    })
}

/// The mesh of one file, in the file's units.
fn read_mesh(path: &Path) -> Result<Mesh> {
    match Format::of(path) {
        Some(Format::Obj) => read_obj(path),
        Some(Format::Stl) => read_stl(path),
        None => Err(GeomError::format(path, "not an .obj or .stl file")),
    }
}

/// An STL file, ASCII or binary. Identical vertices are shared (STL stores none).
fn read_stl(path: &Path) -> Result<Mesh> {
    let mut bytes = std::fs::read(path).map_err(|source| io_error(path, source))?;
    if is_binary_stl(&bytes) {
        // Many CAD tools start binary headers with "solid", which stl_io takes for ASCII.
        bytes[..5].fill(0);
    }
    let stl = stl_io::read_stl(&mut Cursor::new(bytes)).map_err(|e| {
        GeomError::format(path, format!("invalid stl file: {}", lowercase_first(&e.to_string())))
    })?;
    let vertices = stl.vertices.iter().map(|v| Vec3::new(v.0[0], v.0[1], v.0[2])).collect();
    let triangles = stl.faces.iter().map(|f| f.vertices.map(|i| i as u32)).collect();
    Ok(Mesh::new(vertices, triangles))
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
fn read_obj(path: &Path) -> Result<Mesh> {
    let file = std::fs::File::open(path).map_err(|source| io_error(path, source))?;
    let options = tobj::LoadOptions {
        triangulate: true,
        ignore_points: true,
        ignore_lines: true,
        ..Default::default()
    };
    let no_materials = |_: &Path| Err(tobj::LoadError::GenericFailure);
    let (models, _) = tobj::load_obj_buf(&mut BufReader::new(file), &options, no_materials)
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
                _ => Err(GeomError::format(
                    path,
                    format!("invalid obj file: object '{}' has a face index out of range", model.name),
                )),
            })
            .collect::<Result<Vec<_>>>()?;
        mesh.append(&Mesh::new(vertices, triangles));
    }
    Ok(mesh)
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
    fn formats_by_extension_in_any_case() {
        assert!(Format::of(Path::new("a/b.STL")) == Some(Format::Stl));
        assert!(Format::of(Path::new("b.Obj")) == Some(Format::Obj));
        assert!(Format::of(Path::new("b.mtl")).is_none());
        assert!(Format::of(Path::new("stl")).is_none());
    }
}
