//! Loading assemblies from files (glTF 2.0, folders of OBJ/STL) and writing GLB.

mod folder;
mod gltf_read;
mod glb_write;

pub use glb_write::write_glb;

use crate::assembly::{Assembly, Units};
use crate::error::{GeomError, Result};
use crate::math::Axis;
use std::path::Path;

/// What the user said about the file beyond its content.
#[derive(Clone, Debug, Default)]
pub struct LoadOptions {
    /// The unit of the file's coordinates (default: metres for glTF per its spec, metres for folders).
    pub unit: Option<Units>,
    /// The up axis (default: the file's `extras.asp.up`, else +Y for glTF, +Z for OBJ/STL folders).
    pub up: Option<Axis>,
    /// Names of base parts, on top of those the file marks as fixed.
    pub fixed: Vec<String>,
}

/// Loads `path`: a `.glb`/`.gltf` file or a folder of `.obj`/`.stl` files (one part per file).
/// Meshes come back in metres, world frame, part names unique; the assembly is validated.
pub fn load(path: &Path, options: &LoadOptions) -> Result<Assembly> {
    let meta = std::fs::metadata(path)
        .map_err(|source| GeomError::Io { path: path.to_path_buf(), source })?;
    let mut assembly = if meta.is_dir() {
        folder::load_folder(path, options)?
    } else {
        match path.extension().and_then(|e| e.to_str()).map(|e| e.to_ascii_lowercase()).as_deref() {
            Some("glb") | Some("gltf") => gltf_read::load_gltf(path, options)?,
            Some("obj") | Some("stl") => folder::load_single_file(path, options)?,
            _ => {
                return Err(GeomError::format(
                    path,
                    "unknown file type (expected .glb, .gltf, or a folder of .obj/.stl files)",
                ))
            }
        }
    };
    assembly.dedupe_names();
    assembly.set_fixed(&options.fixed)?;
    assembly.validate()?;
    Ok(assembly)
}
