//! asp's errors as the Python exceptions of `asp.errors` (defined in Python, so they pickle,
//! subclass and type-check like any Python exception): `LoadError` for a model that cannot be
//! read or planned as given, `ConfigError` for bad settings, `AspError` (their base) otherwise.

use asp_geom::GeomError;
use asp_search::SearchError;
use pyo3::prelude::*;
use std::path::Path;

/// Which Python exception an error becomes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// `asp.LoadError`: the model (file, folder, its content) is the problem.
    Load,
    /// `asp.ConfigError`: a setting is the problem.
    Config,
    /// `asp.AspError`: anything else.
    Other,
}

impl Kind {
    /// The class name in `asp.errors`.
    pub fn class_name(self) -> &'static str {
        match self {
            Kind::Load => "LoadError",
            Kind::Config => "ConfigError",
            Kind::Other => "AspError",
        }
    }
}

/// An error on its way to Python: its kind, its one-line message and the file it names.
#[derive(Clone, Debug, PartialEq)]
pub struct Error {
    /// Which exception.
    pub kind: Kind,
    /// The message, as the CLI prints it after `error: `.
    pub message: String,
    /// The model file or folder, for load errors.
    pub path: Option<String>,
}

impl Error {
    /// A [`Kind::Config`] error.
    pub fn config(message: impl Into<String>) -> Self {
        Error { kind: Kind::Config, message: message.into(), path: None }
    }

    /// Raises it as its `asp.errors` exception (an `ImportError` if that module is missing).
    pub fn into_py(self, py: Python<'_>) -> PyErr {
        let class = match py.import("asp.errors").and_then(|m| m.getattr(self.kind.class_name())) {
            Ok(class) => class,
            Err(e) => return e,
        };
        let value = match self.kind {
            Kind::Load => class.call1((self.message, self.path)),
            _ => class.call1((self.message,)),
        };
        match value {
            Ok(v) => PyErr::from_value(v),
            Err(e) => e,
        }
    }
}

fn display(path: &Path) -> Option<String> {
    Some(path.display().to_string())
}

impl From<GeomError> for Error {
    fn from(e: GeomError) -> Self {
        let message = e.to_string();
        let (kind, path) = match &e {
            GeomError::Io { path, .. }
            | GeomError::Format { path, .. }
            | GeomError::Assembly { path, .. }
            | GeomError::GrossOverlap { path, .. } => (Kind::Load, display(path)),
            GeomError::Config { .. } => (Kind::Config, None),
            _ => (Kind::Other, None),
        };
        Error { kind, message, path }
    }
}

impl From<SearchError> for Error {
    fn from(e: SearchError) -> Self {
        match e {
            SearchError::Geom(g) => g.into(),
            e @ (SearchError::Config { .. } | SearchError::UnknownObjective { .. } | SearchError::TooLarge { .. }) => {
                Error::config(e.to_string())
            }
            e => Error { kind: Kind::Other, message: e.to_string(), path: None },
        }
    }
}

impl From<asp_app::AppError> for Error {
    fn from(e: asp_app::AppError) -> Self {
        match e {
            // the keys are Python's keyword names already
            asp_app::AppError::Setting { .. } => Error::config(e.render(&|k: &str| k.to_string())),
            asp_app::AppError::Search(s) => s.into(),
            e @ (asp_app::AppError::Learn(_) | asp_app::AppError::Robot(_)) => Error::config(e.to_string()),
            e => Error { kind: Kind::Other, message: e.to_string(), path: None },
        }
    }
}

impl From<asp_gen::GenError> for Error {
    fn from(e: asp_gen::GenError) -> Self {
        match e {
            asp_gen::GenError::Geom(g) => g.into(),
            e @ asp_gen::GenError::Parameter { .. } => Error::config(e.to_string()),
            e => Error { kind: Kind::Other, message: e.to_string(), path: None },
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unreadable_files_are_load_errors_naming_the_file() {
        let e: Error = SearchError::Geom(GeomError::Io {
            path: "no/such.glb".into(),
            source: std::io::Error::new(std::io::ErrorKind::NotFound, "not found"),
        })
        .into();
        assert_eq!(e.kind, Kind::Load);
        assert_eq!(e.path.as_deref(), Some("no/such.glb"));
        assert!(e.message.starts_with("no/such.glb: "), "{}", e.message);
    }

    #[test]
    fn bad_settings_are_config_errors() {
        let e: Error = SearchError::config("the timeout must be a positive number, got -1").into();
        assert_eq!(e.kind, Kind::Config);
        let e: Error = SearchError::Geom(GeomError::config("bad")).into();
        assert_eq!(e.kind, Kind::Config);
        let e: Error = SearchError::UnknownObjective { name: "x".into(), known: "access".into() }.into();
        assert_eq!(e.kind, Kind::Config);
        let e: Error = SearchError::Infeasible { reason: "step 1".into() }.into();
        assert_eq!(e.kind, Kind::Other);
    }
}
