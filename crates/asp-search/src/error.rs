//! Errors of asp-search: bad configuration only (a plan that is not found is a status).

/// What can be wrong with a planner's configuration.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum SearchError {
    /// A setting is out of range.
    #[error("invalid configuration: {reason}")]
    Config {
        /// What is wrong.
        reason: String,
    },
}

/// Result with [`SearchError`].
pub type Result<T> = std::result::Result<T, SearchError>;
