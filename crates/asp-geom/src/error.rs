//! Errors of asp-geom: bad input and bad configuration only.

use std::path::PathBuf;

/// Everything that can go wrong while loading or preparing an assembly.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum GeomError {
    /// A file or folder could not be read.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The operating system's error.
        source: std::io::Error,
    },
    /// A file was read but its content is not a valid model.
    #[error("{path}: {reason}")]
    Format {
        /// The file.
        path: PathBuf,
        /// What is wrong, in lowercase words.
        reason: String,
    },
    /// The assembly as a whole cannot be planned (too few parts, overlapping parts...).
    #[error("{path}: {reason}")]
    Assembly {
        /// The model the assembly came from.
        path: PathBuf,
        /// What is wrong.
        reason: String,
    },
    /// Two parts overlap in the input so far that no shrinking separates them.
    #[error("{path}: {reason}")]
    GrossOverlap {
        /// The model.
        path: PathBuf,
        /// The two parts and the measured overlap.
        reason: String,
    },
    /// A configuration value is out of range.
    #[error("invalid configuration: {reason}")]
    Config {
        /// What is wrong.
        reason: String,
    },
}

/// Result with [`GeomError`].
pub type Result<T> = std::result::Result<T, GeomError>;

impl GeomError {
    /// Shorthand for a [`GeomError::Format`].
    pub fn format(path: impl Into<PathBuf>, reason: impl Into<String>) -> Self {
        GeomError::Format { path: path.into(), reason: reason.into() }
    }
    /// Shorthand for a [`GeomError::Config`].
    pub fn config(reason: impl Into<String>) -> Self {
        GeomError::Config { reason: reason.into() }
    }
}
