//! The seam for crates above asp-search (a robot, held parts): an [`MdpExtension`] adds named
//! objectives and feasibility filters to the planning pipeline for a model, and what it plans
//! for the answer to the plan ([`ExtensionReport`]); [`check_objective_names`] and
//! [`resolve_objectives`] look objective names up among the built-in ones and the extensions'.

use crate::annotation::ExtensionReport;
use crate::error::Result;
use crate::mdp::ActionFilter;
use crate::objective::{collect_names, collect_objectives, objective_by_name, unknown, Objective};
use asp_geom::distmap::DistanceMaps;
use asp_geom::Assembly;
use std::fmt::Debug;
use std::sync::Arc;

/// What an [`MdpExtension`] gets to prepare its objectives and filters for one model.
#[derive(Clone, Copy, Debug)]
pub struct ModelContext<'a> {
    /// The assembly (metres, world frame).
    pub assembly: &'a Arc<Assembly>,
    /// Its distance maps.
    pub maps: &'a Arc<DistanceMaps>,
    /// The run's seed.
    pub seed: u64,
}

/// Objectives and filters beyond the built-in ones, for the planning pipeline (e.g. a robot:
/// the `robot-path` objective and the filter "the arm can grasp the part and carry it out").
pub trait MdpExtension: Send + Sync + Debug {
    /// The objective names it provides (for validation and messages).
    fn objective_names(&self) -> Vec<String> {
        Vec::new()
    }

    /// The objective called `name` on this model, or `None` when it does not provide it.
    fn objective(&self, _name: &str, _model: &ModelContext<'_>) -> Result<Option<Arc<dyn Objective>>> {
        Ok(None)
    }

    /// Filters every problem on this model gets, whatever its objectives.
    fn filters(&self, _model: &ModelContext<'_>) -> Result<Vec<Arc<dyn ActionFilter>>> {
        Ok(Vec::new())
    }

    /// What it adds to the plan of `sequence` (removal order) on this model, e.g. a robot's
    /// grasps and paths per step; default `None`.
    fn describe(&self, _model: &ModelContext<'_>, _sequence: &[usize]) -> Result<Option<ExtensionReport>> {
        Ok(None)
    }
}

/// Checks objective names (blanks left out, none an error) against the built-in ones and those
/// the `extensions` provide (before a model is loaded: for early, clear errors).
pub fn check_objective_names<S: AsRef<str>>(names: &[S], extensions: &[Arc<dyn MdpExtension>]) -> Result<()> {
    let provided: Vec<String> = extensions.iter().flat_map(|e| e.objective_names()).collect();
    let names = collect_names(names)?;
    for name in &names {
        if objective_by_name(name).is_err() && !provided.iter().any(|p| p == name.trim()) {
            return Err(unknown(name, &provided));
        }
    }
    Ok(())
}

/// The objectives named by `names` (blanks left out, repeats an error) on one model: the
/// built-in ones by name, the others from the first extension that provides them.
pub fn resolve_objectives<S: AsRef<str>>(
    names: &[S],
    extensions: &[Arc<dyn MdpExtension>],
    model: &ModelContext<'_>,
) -> Result<Vec<Arc<dyn Objective>>> {
    let provided: Vec<String> = extensions.iter().flat_map(|e| e.objective_names()).collect();
    collect_objectives(
        names,
        |name| {
            if let Ok(o) = objective_by_name(name) {
                return Ok(Some(o));
            }
            for e in extensions {
                if let Some(o) = e.objective(name.trim(), model)? {
                    return Ok(Some(o));
                }
            }
            Ok(None)
        },
        &provided,
    )
}
