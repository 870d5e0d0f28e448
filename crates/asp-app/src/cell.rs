//! `asp robot cell MODEL`: which parts the robot cell can take out on their own, before a long
//! search.
//!
//! Each movable part is planned as the robot would take it out if it were the only part left
//! besides the fixed ones (and the ground): a grasp the arm reaches without collision, the lift
//! (up when free, thesis 5.3), and a collision-free path to the drop-off. A part that fails here
//! fails in every state of a search (other parts only add obstacles), so the answer names the
//! parts no plan can take out with this cell, and why; a part that passes may still be blocked
//! by its neighbours in the assembled state.

use crate::error::{AppError, Result};
use crate::pipeline::{checker, load};
use crate::request::PlanRequest;
use crate::resolve;
use asp_geom::PartSet;
use asp_robot::{RemovalPlanner, RobotFailure};
use rayon::prelude::*;
use serde::Serialize;
use std::path::Path;

/// What the cell does with one part on its own.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct CellPart {
    /// Index in the model.
    pub part: usize,
    /// Its name.
    pub name: String,
    /// Grasps the gripper could close on (antipodal pairs within its opening, or declared).
    pub grasps: usize,
    /// `taken_out`, or the reason the robot cannot: `blocked`, `no_reachable_grasp`, `no_path`.
    pub outcome: &'static str,
    /// The path length (tool centre travel, model units) when taken out.
    pub path_length: Option<f64>,
    /// The lift direction (unit, model frame) when taken out.
    pub lift: Option<[f64; 3]>,
    /// The failure in words (`no reachable grasp: of 12 grasps 12 are out of reach, 0 collide`).
    pub detail: Option<String>,
}

/// The cell and every movable part's outcome.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct CellCheck {
    /// The model file.
    pub model: String,
    /// The robot's name.
    pub robot: String,
    /// Where its base stands (model units, model frame).
    pub base: [f64; 3],
    /// Where it puts parts down (model units, model frame).
    pub drop_off: [f64; 3],
    /// Every part that is not fixed, in model order.
    pub parts: Vec<CellPart>,
}

impl CellCheck {
    /// The parts the cell cannot take out on their own.
    pub fn unreachable(&self) -> impl Iterator<Item = &CellPart> {
        self.parts.iter().filter(|p| p.outcome != "taken_out")
    }
}

/// Checks the robot cell of `request` (the shipped `panda` when it names no robot; its base,
/// drop-off and `replans`, the model's loading keys and `seed`) on the model at `path`: every
/// movable part alone, as [`crate::cell`] describes.
pub fn check_cell(path: &Path, request: &PlanRequest) -> Result<CellCheck> {
    let mut request = request.clone();
    request.robot.get_or_insert_with(|| "panda".to_string());
    let settings = resolve::resolve(&request)?;
    let setup = resolve::robot(&request)?.ok_or_else(|| AppError::setting("robot", "no robot"))?;
    let assembly = load(path, &settings)?;
    let checker = checker(assembly, &settings)?;
    let world = checker.world();
    let assembly = world.assembly();
    let cell = setup.cell(assembly);
    let planner = RemovalPlanner::new(world, cell.clone(), setup.config.clone());
    let units = |m: f64| assembly.units.from_metres(m);
    let v3 = |v: asp_geom::math::Vec3| [units(shortest(v.x)), units(shortest(v.y)), units(shortest(v.z))];
    let n = world.num_parts();
    let movable: Vec<usize> = (0..n).filter(|&p| !world.contacts().fixed().contains(p)).collect();
    let parts = movable
        .par_iter()
        .map(|&p| {
            let alone = PartSet::from_indices(n, [p]);
            let grasps = planner.grasps(p).len();
            let planned =
                planner.lift_direction(p, &alone, None).and_then(|d| planner.plan(p, &alone, d, settings.seed, setup.config.replans));
            let name = assembly.parts[p].name.clone();
            match planned {
                Ok(r) => CellPart {
                    part: p,
                    name,
                    grasps,
                    outcome: "taken_out",
                    path_length: Some(units(r.length)),
                    lift: Some([shortest(r.direction.x), shortest(r.direction.y), shortest(r.direction.z)]),
                    detail: None,
                },
                Err(f) => CellPart {
                    part: p,
                    name,
                    grasps,
                    outcome: match f {
                        RobotFailure::Blocked { .. } => "blocked",
                        RobotFailure::NoReachableGrasp { .. } => "no_reachable_grasp",
                        RobotFailure::NoPath { .. } => "no_path",
                    },
                    path_length: None,
                    lift: None,
                    detail: Some(match f {
                        RobotFailure::Blocked { by: Some(by) } => format!("blocked: the lift collides with {}", world.name(by)),
                        other => other.to_string(),
                    }),
                },
            }
        })
        .collect();
    Ok(CellCheck {
        model: path.display().to_string(),
        robot: cell.robot.name.clone(),
        base: v3(cell.robot.base_pose().translation),
        drop_off: v3(cell.drop_off),
        parts,
    })
}

/// `v` as the `f64` its shortest decimal form names (`-0.4`, not `-0.4000000059604645`).
fn shortest(v: f32) -> f64 {
    v.to_string().parse().unwrap_or(v as f64)
}
