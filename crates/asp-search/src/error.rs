//! Errors of asp-search: bad input and bad configuration only (a search that finds nothing is an
//! outcome, not an error).

use asp_geom::GeomError;

/// Everything that can go wrong before or around a search.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum SearchError {
    /// A configuration value is out of range or inconsistent.
    #[error("invalid configuration: {reason}")]
    Config {
        /// What is wrong, in lowercase words.
        reason: String,
    },
    /// An objective name that asp does not know.
    #[error("unknown objective '{name}' (known: {known})")]
    UnknownObjective {
        /// The name given.
        name: String,
        /// The known names, comma separated.
        known: String,
    },
    /// An exact reference was asked for an instance that is too large.
    #[error("too large for exact search: {reason}")]
    TooLarge {
        /// Which limit was hit.
        reason: String,
    },
    /// A sequence given for evaluation is not feasible.
    #[error("infeasible sequence: {reason}")]
    Infeasible {
        /// The first step that fails and why.
        reason: String,
    },
    /// A search plug-in (a rollout or expansion policy, a Q-function, an objective or filter)
    /// failed, or broke its contract (e.g. chose an action that is not on offer).
    #[error("{what}: {reason}")]
    Plugin {
        /// Which plug-in (e.g. `rollout policy`).
        what: String,
        /// What went wrong.
        reason: String,
    },
    /// An error of the geometry layer (loading, distance maps).
    #[error(transparent)]
    Geom(#[from] GeomError),
}

impl SearchError {
    /// Shorthand for a [`SearchError::Config`].
    pub fn config(reason: impl Into<String>) -> Self {
        SearchError::Config { reason: reason.into() }
    }

    /// Shorthand for a [`SearchError::Plugin`].
    pub fn plugin(what: impl Into<String>, reason: impl Into<String>) -> Self {
        SearchError::Plugin { what: what.into(), reason: reason.into() }
    }
}

/// Result with [`SearchError`].
pub type Result<T> = std::result::Result<T, SearchError>;
