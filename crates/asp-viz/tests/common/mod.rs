//! Plans of fixtures as scenes, and a `no_plan` scene.

use asp_geom::{fixtures, Assembly, Checker, CheckerConfig, World, WorldConfig};
use asp_search::report::{Explanation, NamedPart, PlanReport};
use asp_search::{Budget, Dfs, Problem};
use asp_viz::Scene;
use std::path::Path;

/// The plan of `assembly` (feasibility DFS, path planner on) and its scene.
pub fn planned(assembly: Assembly) -> Scene {
    let checker = Checker::new(World::new(assembly, &WorldConfig::default()).unwrap(), CheckerConfig::default());
    let outcome = Dfs::builder().build().solve(&Problem::full(&checker), &Budget::default());
    let world = checker.world();
    let report = PlanReport::new(world.assembly(), &outcome, world.shapes().tolerance(), world.warnings());
    assert_eq!(report.status, asp_search::report::PlanStatus::Found);
    Scene::new(world.assembly().clone(), report, Path::new("fixture")).unwrap()
}

/// The tube's plan turned into a `no_plan` result as the planner writes one: the handle came
/// off, then the stick was stuck between the receptacle and the cap, and the cap could leave
/// but led nowhere.
pub fn stuck_tube() -> Scene {
    let scene = planned(fixtures::tube());
    let mut report = scene.report.clone();
    let index = |name: &str| report.parts.iter().position(|p| p.name == name).unwrap();
    let (handle, stick, receptacle, cap) = (index("handle"), index("stick"), index("receptacle"), index("cap"));
    report.status = asp_search::report::PlanStatus::NoPlan;
    // format 1.3: the partial plan is the handle's step (its motion as in the found plan)
    report.partial_assembly_sequence = report.assembly_sequence.iter().filter(|s| s.part == handle).cloned().collect();
    report.remaining = Some(vec![stick, receptacle, cap]);
    report.assembly_sequence.clear();
    report.disassembly_sequence = vec![handle];
    report.explanation = vec![
        Explanation {
            part: stick,
            name: "stick".into(),
            reason: asp_search::report::ExplanationReason::Blocked,
            parts: vec![NamedPart { part: receptacle, name: "receptacle".into() }, NamedPart { part: cap, name: "cap".into() }],
            robot: None,
        },
        Explanation { part: cap, name: "cap".into(), reason: asp_search::report::ExplanationReason::DeadEnd, parts: vec![], robot: None },
    ];
    Scene::new(scene.assembly.clone(), report, Path::new("fixture")).unwrap()
}

/// The burr without the grid planner: one step lifts all six pieces, a subassembly that
/// cannot be taken apart, so the plan is `partial` with one locked core.
pub fn locked_burr() -> Scene {
    let checker = Checker::new(World::new(asp_geom::puzzles::burr_level(), &WorldConfig::default()).unwrap(), CheckerConfig::default());
    let outcome = Dfs::builder().path_planner(false).build().solve(&Problem::full(&checker), &Budget::default());
    let world = checker.world();
    let report = PlanReport::new(world.assembly(), &outcome, world.shapes().tolerance(), world.warnings());
    assert_eq!(report.status, asp_search::report::PlanStatus::Partial);
    Scene::new(world.assembly().clone(), report, Path::new("fixture")).unwrap()
}
