//! Errors of asp-gen: bad parameters, generation that cannot meet its constraints, failed writes.

use std::path::PathBuf;

/// Everything that can go wrong while generating assemblies.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum GenError {
    /// A parameter is out of range.
    #[error("invalid parameter --{name}: {reason}")]
    Parameter {
        /// The parameter's command-line name, e.g. `size`.
        name: &'static str,
        /// What is wrong, in lowercase words.
        reason: String,
    },
    /// The random construction could not place what was asked for within its attempt budget.
    #[error("could not generate the assembly of seed {seed}: {reason}")]
    Construction {
        /// The assembly's own seed.
        seed: u64,
        /// What could not be placed, and what to change.
        reason: String,
    },
    /// A file or folder could not be written.
    #[error("{path}: {source}")]
    Io {
        /// The file or folder.
        path: PathBuf,
        /// The operating system's error.
        source: std::io::Error,
    },
    /// Writing a model file failed in asp-geom.
    #[error(transparent)]
    Geom(#[from] asp_geom::GeomError),
}

/// Result with [`GenError`].
pub type Result<T> = std::result::Result<T, GenError>;

impl GenError {
    /// Shorthand for a [`GenError::Parameter`].
    pub fn parameter(name: &'static str, reason: impl Into<String>) -> Self {
        GenError::Parameter { name, reason: reason.into() }
    }
}
