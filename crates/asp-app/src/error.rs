//! Errors of the composition layer: a setting that is wrong (named by its request key, which
//! each front end spells its own way: `--time-limit` on the command line, `time_limit` in
//! Python), or an error of a crate below.

use asp_search::SearchError;

/// Everything that can go wrong while a request is resolved or run.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum AppError {
    /// A setting of the request is wrong: unknown, of the wrong type, out of range, or not
    /// applicable to the chosen search.
    #[error("{key}: {reason}")]
    Setting {
        /// The request key (`time_limit`, `order`, ...).
        key: String,
        /// What is wrong, in lowercase words (may name other keys in backticks).
        reason: String,
    },
    /// An error of the planners or the geometry (bad model, bad configuration).
    #[error(transparent)]
    Search(#[from] SearchError),
    /// An error of a learned model (a file that is not a model of the expected kind).
    #[error(transparent)]
    Learn(#[from] asp_learn::LearnError),
    /// An error of the robot (a URDF that cannot be used).
    #[error(transparent)]
    Robot(#[from] asp_robot::RobotError),
}

impl AppError {
    /// Shorthand for an [`AppError::Setting`].
    pub fn setting(key: impl Into<String>, reason: impl Into<String>) -> Self {
        AppError::Setting { key: key.into(), reason: reason.into() }
    }

    /// A configuration error of the planners' kind ([`SearchError::Config`]).
    pub fn config(reason: impl Into<String>) -> Self {
        AppError::Search(SearchError::config(reason))
    }

    /// A plug-in's failure ([`SearchError::Plugin`]).
    pub fn plugin(what: impl Into<String>, reason: impl Into<String>) -> Self {
        AppError::Search(SearchError::plugin(what, reason))
    }

    /// The message with the setting keys spelled by `spell` (e.g. as command-line flags):
    /// the failing key leads, and keys quoted in backticks in the reason are respelled too.
    pub fn render(&self, spell: &dyn Fn(&str) -> String) -> String {
        match self {
            AppError::Setting { key, reason } => format!("{}: {}", spell(key), respell(reason, spell)),
            other => other.to_string(),
        }
    }
}

impl From<asp_geom::GeomError> for AppError {
    fn from(e: asp_geom::GeomError) -> Self {
        AppError::Search(SearchError::Geom(e))
    }
}

/// `reason` with every `` `key` `` replaced by `spell(key)`.
fn respell(reason: &str, spell: &dyn Fn(&str) -> String) -> String {
    let mut out = String::with_capacity(reason.len());
    let mut rest = reason;
    while let Some(start) = rest.find('`') {
        let Some(len) = rest[start + 1..].find('`') else { break };
        out.push_str(&rest[..start]);
        out.push_str(&spell(&rest[start + 1..start + 1 + len]));
        rest = &rest[start + len + 2..];
    }
    out.push_str(rest);
    out
}

/// Result with [`AppError`].
pub type Result<T> = std::result::Result<T, AppError>;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn settings_render_in_each_front_ends_spelling() {
        let e = AppError::setting("timeout", "applies to the feasibility search; the optimiser's limit is `time_limit`");
        let flag = |k: &str| format!("--{}", k.replace('_', "-"));
        assert_eq!(e.render(&flag), "--timeout: applies to the feasibility search; the optimiser's limit is --time-limit");
        assert_eq!(e.render(&|k: &str| k.to_string()), "timeout: applies to the feasibility search; the optimiser's limit is time_limit");
        assert_eq!(e.to_string(), "timeout: applies to the feasibility search; the optimiser's limit is `time_limit`");
    }
}
