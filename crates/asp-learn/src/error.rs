//! Errors of asp-learn: a model file that cannot be used, or inputs that do not fit the model.

/// Everything that can go wrong loading or running a learned model.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum LearnError {
    /// The file cannot be read or is not an ONNX model tract can run.
    #[error("{path}: {reason}")]
    Read {
        /// The model file.
        path: String,
        /// What went wrong, in lowercase words.
        reason: String,
    },
    /// The model does not match what asp expects (names, shapes, types, metadata).
    #[error("{path}: {mismatch}")]
    Mismatch {
        /// The model file.
        path: String,
        /// The first mismatch found.
        mismatch: String,
    },
    /// The inputs given to a model are inconsistent (lengths, indices).
    #[error("{path}: bad input: {reason}")]
    Input {
        /// The model file.
        path: String,
        /// What is wrong with the input.
        reason: String,
    },
    /// tract failed while running the model.
    #[error("{path}: inference failed: {reason}")]
    Inference {
        /// The model file.
        path: String,
        /// tract's message, on one line.
        reason: String,
    },
}

/// The result type of asp-learn.
pub type Result<T> = std::result::Result<T, LearnError>;

/// tract's error chain on one line.
pub(crate) fn one_line(err: &tract_onnx::prelude::TractError) -> String {
    let text = format!("{err:#}");
    text.split_whitespace().collect::<Vec<_>>().join(" ")
}
