//! From flags to the plan request and back to words: the flags given become request keys, a
//! `--settings` file underneath them, and an error about a setting names its flag.

use crate::flags::{flag, Map};
use anyhow::Context;
use asp_app::{AppError, PlanRequest, PlanSettings};
use std::path::Path;

/// An asp-app error for the command line: a setting's error names its flag (`--time-limit`),
/// others keep their type (the exit code and hints look at it).
pub fn cli_error(e: AppError) -> anyhow::Error {
    match e {
        AppError::Setting { .. } => anyhow::anyhow!(e.render(&flag)),
        other => anyhow::Error::new(other),
    }
}

/// The request of the flags given (`map`), over the settings file's, if any.
pub fn request(map: Map, settings: Option<&Path>) -> anyhow::Result<PlanRequest> {
    let mut merged = match settings {
        Some(path) => {
            let text = std::fs::read_to_string(path).with_context(|| format!("{}: cannot read the settings", path.display()))?;
            match serde_json::from_str::<serde_json::Value>(&text) {
                Ok(serde_json::Value::Object(m)) => m,
                Ok(_) => anyhow::bail!("{}: the settings must be a JSON object of plan-request keys", path.display()),
                Err(e) => anyhow::bail!("{}: not JSON: {e}", path.display()),
            }
        }
        None => Map::new(),
    };
    let from_flags: Vec<String> = map.keys().cloned().collect();
    merged.extend(map);
    PlanRequest::from_value(serde_json::Value::Object(merged)).map_err(|e| match (settings, &e) {
        (Some(path), AppError::Setting { key, .. }) if !from_flags.contains(key) => {
            anyhow::anyhow!("{}: {}", path.display(), e.render(&|k: &str| k.to_string()))
        }
        _ => cli_error(e),
    })
}

/// The pipeline's settings of `request`.
pub fn resolve(request: &PlanRequest) -> anyhow::Result<PlanSettings> {
    asp_app::resolve(request).map_err(cli_error)
}

/// The pipeline's settings of the model flags (and `extra` request keys).
pub(crate) fn model_settings(args: &crate::flags::ModelArgs, extra: Map) -> anyhow::Result<PlanSettings> {
    let mut map = Map::new();
    args.put(&mut map);
    map.extend(extra);
    resolve(&request(map, None)?)
}
