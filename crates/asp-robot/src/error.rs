//! The one error type of asp-robot: bad robot files and bad configuration.

use std::path::PathBuf;

/// What went wrong loading or configuring a robot. Every message is one line and names the file.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum RobotError {
    /// The robot file could not be read.
    #[error("{}: cannot read robot file: {message}", path.display())]
    Read {
        /// The file.
        path: PathBuf,
        /// The operating system's reason.
        message: String,
    },
    /// The file is not valid URDF XML.
    #[error("{}: not a valid URDF: {message}", path.display())]
    Parse {
        /// The file.
        path: PathBuf,
        /// The parser's reason (flattened to one line).
        message: String,
    },
    /// A joint names a link the file does not define.
    #[error("{}: joint '{joint}' names unknown {role} link '{link}'", path.display())]
    UnknownLink {
        /// The file.
        path: PathBuf,
        /// The joint.
        joint: String,
        /// `parent` or `child`.
        role: &'static str,
        /// The missing link.
        link: String,
    },
    /// A file the robot names (a mesh) is missing or lies outside the allowed folders.
    #[error("{}: {message}", path.display())]
    Reference {
        /// The robot file.
        path: PathBuf,
        /// Which reference and why.
        message: String,
    },
    /// The robot loads but cannot carry out any removal (no gripper).
    #[error("{}: {message}", path.display())]
    Unusable {
        /// The robot file.
        path: PathBuf,
        /// What it lacks.
        message: String,
    },
    /// The links and joints do not form the serial chain asked for.
    #[error("{}: {message}", path.display())]
    Chain {
        /// The file.
        path: PathBuf,
        /// What is wrong with the chain.
        message: String,
    },
}

impl RobotError {
    /// A parse error with the parser's message flattened to one line.
    pub(crate) fn parse(path: PathBuf, message: impl std::fmt::Display) -> Self {
        RobotError::Parse { path, message: one_line(&message.to_string()) }
    }

    /// A chain error.
    pub(crate) fn chain(path: PathBuf, message: impl Into<String>) -> Self {
        RobotError::Chain { path, message: message.into() }
    }
}

/// Joins the lines of `s` with "; " so that an error stays on one line.
pub(crate) fn one_line(s: &str) -> String {
    s.lines().map(str::trim).filter(|l| !l.is_empty()).collect::<Vec<_>>().join("; ")
}

/// `Result` with [`RobotError`].
pub type Result<T> = std::result::Result<T, RobotError>;
