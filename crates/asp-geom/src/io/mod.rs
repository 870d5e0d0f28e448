//! Loading assemblies from files (glTF 2.0, STEP through OpenCASCADE, folders of OBJ/STL) and
//! writing GLB.

mod atomic;
mod brep_faces;
mod folder;
mod glb_write;
mod gltf_read;
mod refs;
pub mod step;

pub use atomic::{write_atomic, write_atomic_with};
pub use glb_write::write_glb;
pub use refs::{canonical, resolve_inside, Refused, OUTSIDE_FLAG};
pub use step::Tessellation;

use crate::assembly::{Assembly, Units};
use crate::error::{GeomError, Result};
use crate::math::Axis;
use std::path::Path;

/// What the user said about the file beyond its content.
#[derive(Clone, Debug, Default)]
pub struct LoadOptions {
    /// The unit of the file's coordinates (default: metres for glTF per its spec, metres for folders).
    pub unit: Option<Units>,
    /// The up axis (default: the file's `extras.asp.up`, else +Y for glTF, +Z for STEP and OBJ/STL).
    pub up: Option<Axis>,
    /// Names of base parts, on top of those the file marks as fixed.
    pub fixed: Vec<String>,
    /// Let the model read files outside its folder (absolute buffer paths, `..`, symlinks out).
    /// Off by default: a model from someone else reads only what lies beside it.
    pub allow_outside_files: bool,
    /// Caps on what a file may make asp allocate.
    pub limits: Limits,
    /// Make each separate body of a part's mesh a part of its own (`name#1`, `name#2`, ...).
    pub split_bodies: bool,
    /// How finely a STEP file's B-rep is tessellated (other formats come as triangles).
    pub tessellation: Tessellation,
}

/// The default cap on triangles over all parts ([`Limits::max_triangles`]).
pub const DEFAULT_MAX_TRIANGLES: usize = 20_000_000;
/// The default cap on parts ([`Limits::max_parts`]).
pub const DEFAULT_MAX_PARTS: usize = 10_000;
/// Largest element count accepted for a glTF accessor that has no buffer view (zeros with
/// sparse substitutions): such counts are not backed by file bytes.
pub const MAX_ZERO_FILLED: usize = 1 << 18;

/// Caps on the size of a model, checked against the counts in its headers before memory is taken
/// (`--max-triangles`, `--max-parts` raise them).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Limits {
    /// Triangles over all parts (every instance counted).
    pub max_triangles: usize,
    /// Parts (mesh instances, files of a folder).
    pub max_parts: usize,
}

impl Default for Limits {
    fn default() -> Self {
        Limits { max_triangles: DEFAULT_MAX_TRIANGLES, max_parts: DEFAULT_MAX_PARTS }
    }
}

impl Limits {
    /// Checks `triangles` against the cap; the error names the flag that lifts it.
    pub fn check_triangles(&self, triangles: usize) -> std::result::Result<(), String> {
        if triangles > self.max_triangles {
            return Err(format!(
                "more than {} triangles (the model announces {triangles}; raise the cap with --max-triangles)",
                self.max_triangles
            ));
        }
        Ok(())
    }

    /// Checks `parts` against the cap; the error names the flag that lifts it.
    pub fn check_parts(&self, parts: usize) -> std::result::Result<(), String> {
        if parts > self.max_parts {
            return Err(format!("more than {} parts (raise the cap with --max-parts)", self.max_parts));
        }
        Ok(())
    }
}

/// Loads `path`: a `.glb`/`.gltf` file, a `.step`/`.stp` file ([`step`]) or a folder of
/// `.obj`/`.stl` files (one part per file).
/// Meshes come back in metres, world frame, part names unique; the assembly is validated.
pub fn load(path: &Path, options: &LoadOptions) -> Result<Assembly> {
    let meta = std::fs::metadata(path).map_err(|source| io_error(path, source))?;
    if meta.is_dir() {
        let assembly = folder::load_folder(path, options)?;
        return finish(assembly, options);
    }
    check_extension(path)?;
    let bytes = std::fs::read(path).map_err(|source| io_error(path, source))?;
    load_bytes(path, &bytes, options)
}

/// Loads one model file whose bytes are already in memory: `path` names it (its extension picks
/// the format, every error names it) and locates the external buffers of a `.gltf`, which are
/// read from disk. The same checks and results as [`load`] on that file.
pub fn load_bytes(path: &Path, bytes: &[u8], options: &LoadOptions) -> Result<Assembly> {
    load_bytes_with(path, bytes, options, &|file| std::fs::read(file))
}

/// [`load_bytes`] with the external files a `.gltf` refers to (its `.bin` buffers) read by
/// `external` instead of from disk (given the path the URI resolves to, relative to `path`).
pub fn load_bytes_with(
    path: &Path,
    bytes: &[u8],
    options: &LoadOptions,
    external: &dyn Fn(&Path) -> std::io::Result<Vec<u8>>,
) -> Result<Assembly> {
    let assembly = match check_extension(path)? {
        FileKind::Gltf => gltf_read::read_gltf_bytes(path, bytes, options, external)?,
        FileKind::Mesh => folder::single_file_from_bytes(path, bytes, options)?,
        FileKind::Step => {
            let glb = step::convert(path, bytes, &options.tessellation)?;
            return step::assemble(path, bytes, &glb, options);
        }
    };
    finish(assembly, options)
}

enum FileKind {
    Gltf,
    Mesh,
    Step,
}

fn check_extension(path: &Path) -> Result<FileKind> {
    match path.extension().and_then(|e| e.to_str()).map(|e| e.to_ascii_lowercase()).as_deref() {
        Some("glb") | Some("gltf") => Ok(FileKind::Gltf),
        Some("obj") | Some("stl") => Ok(FileKind::Mesh),
        Some("step") | Some("stp") => Ok(FileKind::Step),
        _ => Err(GeomError::format(path, "unknown file type (expected .glb, .gltf, .step, .stp, or a folder of .obj/.stl files)")),
    }
}

pub(crate) fn finish(mut assembly: Assembly, options: &LoadOptions) -> Result<Assembly> {
    assembly.dedupe_names();
    assembly.set_fixed(&options.fixed)?;
    assembly.validate()?;
    crate::validate::check_model(&mut assembly)?;
    if options.split_bodies {
        let split = crate::validate::split_bodies(&mut assembly);
        if !split.is_empty() {
            assembly.warnings.retain(|w| !split.iter().any(|n| w.starts_with(&format!("part '{n}' holds "))));
            assembly.warnings.push(format!("split into one part per body (--split-bodies): {}", split.join(", ")));
        }
    }
    let (_, unknown) = assembly.fastenings();
    assembly.warnings.extend(unknown);
    Ok(assembly)
}

/// A [`GeomError::Io`] for `path` whose message is lowercase like every other asp message
/// ("no such file or directory" rather than the operating system's capitalised text).
/// The error kind is kept, so callers can still match on it.
pub(crate) fn io_error(path: &Path, source: std::io::Error) -> GeomError {
    let source = std::io::Error::new(source.kind(), lowercase_first(&source.to_string()));
    GeomError::Io { path: path.to_path_buf(), source }
}

/// Another library's message made to read like asp's: first letter in lowercase (unless the
/// first word is an acronym such as "EOF") and no final period.
pub(crate) fn lowercase_first(text: &str) -> String {
    let text = text.trim().trim_end_matches('.');
    let mut chars = text.chars();
    match (chars.next(), chars.next()) {
        (Some(first), second) if !second.is_some_and(char::is_uppercase) => first.to_lowercase().chain(text.chars().skip(1)).collect(),
        _ => text.to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn messages_of_other_libraries_are_lowercased() {
        assert_eq!(lowercase_first("No such file or directory (os error 2)"), "no such file or directory (os error 2)");
        assert_eq!(lowercase_first("EOF while expecting facet."), "EOF while expecting facet");
        assert_eq!(lowercase_first(""), "");
    }
}
