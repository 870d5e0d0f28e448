//! Errors of asp-viz: unreadable or inconsistent input, and files that cannot be written.

use asp_geom::GeomError;
use std::path::PathBuf;

/// Everything that can go wrong while drawing a plan.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum VizError {
    /// A file could not be read or written.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The operating system's reason.
        source: std::io::Error,
    },
    /// An input file is not what it should be (not a plan JSON, a trace CSV without the
    /// expected columns, a model that does not match the plan...).
    #[error("{path}: {reason}")]
    Input {
        /// The file.
        path: PathBuf,
        /// What is wrong, in lowercase words.
        reason: String,
    },
    /// An output could not be produced (encoder or drawing failure).
    #[error("{path}: {reason}")]
    Output {
        /// The file being written.
        path: PathBuf,
        /// What failed.
        reason: String,
    },
    /// Loading the model failed.
    #[error(transparent)]
    Geom(#[from] GeomError),
}

impl VizError {
    /// A [`VizError::Io`] with the message lowercased like every other asp message.
    pub(crate) fn io(path: &std::path::Path, source: std::io::Error) -> Self {
        let text = source.to_string();
        let mut chars = text.chars();
        let text = match chars.next() {
            Some(first) => first.to_lowercase().chain(chars).collect(),
            None => text,
        };
        VizError::Io { path: path.to_path_buf(), source: std::io::Error::new(source.kind(), text) }
    }

    /// A [`VizError::Input`].
    pub(crate) fn input(path: &std::path::Path, reason: impl Into<String>) -> Self {
        VizError::Input { path: path.to_path_buf(), reason: reason.into() }
    }

    /// A [`VizError::Output`].
    pub(crate) fn output(path: &std::path::Path, reason: impl Into<String>) -> Self {
        VizError::Output { path: path.to_path_buf(), reason: reason.into() }
    }
}

/// The result type of asp-viz.
pub type Result<T> = std::result::Result<T, VizError>;
