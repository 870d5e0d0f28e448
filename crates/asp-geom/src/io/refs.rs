//! Files a model names (glTF buffers, the files of an OBJ/STL folder, URDF meshes) stay inside
//! the model's folder or inside roots the user names.
//!
//! A reference is resolved against its folder and canonicalised (symlinks followed, `..`
//! applied), then compared with the canonical folder: an absolute path, a `..` that climbs out or
//! a symlink that points out is refused unless the user allows files outside
//! ([`OUTSIDE_FLAG`]). Paths that do not exist yet are canonicalised as far as they exist and
//! normalised lexically beyond, so a missing file still reads as "missing", not as "outside".

use std::path::{Component, Path, PathBuf};

/// The command-line flag that lets a model read files outside its folder (named in errors).
pub const OUTSIDE_FLAG: &str = "--allow-outside-files";

/// Why a reference was refused: it leaves every allowed root.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Refused {
    /// An absolute path or `file:` URI.
    Absolute,
    /// Relative, but `..` or a symlink takes it out of the allowed roots.
    Outside,
}

impl Refused {
    /// The refusal in words, for `what` ('buffer 0 uri', 'mesh') naming `reference`.
    pub fn describe(&self, what: &str, reference: &str) -> String {
        let why = match self {
            Refused::Absolute => "is an absolute path",
            Refused::Outside => "points outside the model's folder",
        };
        format!("{what} '{reference}' {why}; asp reads only files inside it (allow with {OUTSIDE_FLAG})")
    }
}

/// Resolves `reference` (a relative or absolute path) against `folder` and checks that the
/// result lies inside `folder` or one of `roots`. With `allow_outside`, anything goes.
/// Returns the path to read.
pub fn resolve_inside(folder: &Path, reference: &Path, roots: &[&Path], allow_outside: bool) -> Result<PathBuf, Refused> {
    let joined = folder.join(reference);
    if allow_outside {
        return Ok(joined);
    }
    if reference.is_absolute() || reference.has_root() {
        return Err(Refused::Absolute);
    }
    let target = canonical(&joined);
    let inside = std::iter::once(folder).chain(roots.iter().copied()).any(|root| target.starts_with(canonical(root)));
    if inside {
        Ok(joined)
    } else {
        Err(Refused::Outside)
    }
}

/// `path` made absolute with its existing prefix canonicalised and the rest normalised
/// lexically (`.` dropped, `..` popping a component).
pub fn canonical(path: &Path) -> PathBuf {
    let absolute = std::path::absolute(path).unwrap_or_else(|_| path.to_path_buf());
    let components: Vec<Component> = absolute.components().collect();
    for k in (0..=components.len()).rev() {
        let prefix: PathBuf = components[..k].iter().collect();
        let Ok(mut out) = prefix.canonicalize() else { continue };
        for c in &components[k..] {
            match c {
                Component::ParentDir => {
                    out.pop();
                }
                Component::Normal(name) => out.push(name),
                _ => {}
            }
        }
        return out;
    }
    absolute
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dot_dot_and_absolute_paths_are_refused() {
        let dir = tempfile::tempdir().unwrap();
        let folder = dir.path().join("model");
        std::fs::create_dir(&folder).unwrap();
        std::fs::write(folder.join("a.bin"), b"x").unwrap();
        assert!(resolve_inside(&folder, Path::new("a.bin"), &[], false).is_ok());
        assert!(resolve_inside(&folder, Path::new("sub/../a.bin"), &[], false).is_ok());
        assert!(resolve_inside(&folder, Path::new("missing.bin"), &[], false).is_ok());
        assert_eq!(resolve_inside(&folder, Path::new("../a.bin"), &[], false), Err(Refused::Outside));
        assert_eq!(resolve_inside(&folder, Path::new("x/../../a.bin"), &[], false), Err(Refused::Outside));
        assert_eq!(resolve_inside(&folder, Path::new("/etc/passwd"), &[], false), Err(Refused::Absolute));
        assert!(resolve_inside(&folder, Path::new("/etc/passwd"), &[], true).is_ok());
        // a root the user names
        assert!(resolve_inside(&folder, Path::new("../a.bin"), &[dir.path()], false).is_ok());
    }

    #[cfg(unix)]
    #[test]
    fn symlinks_that_point_out_are_refused() {
        let dir = tempfile::tempdir().unwrap();
        let folder = dir.path().join("model");
        std::fs::create_dir(&folder).unwrap();
        std::fs::write(dir.path().join("secret.bin"), b"x").unwrap();
        std::os::unix::fs::symlink(dir.path().join("secret.bin"), folder.join("link.bin")).unwrap();
        std::os::unix::fs::symlink(dir.path(), folder.join("up")).unwrap();
        assert_eq!(resolve_inside(&folder, Path::new("link.bin"), &[], false), Err(Refused::Outside));
        assert_eq!(resolve_inside(&folder, Path::new("up/secret.bin"), &[], false), Err(Refused::Outside));
    }
}
