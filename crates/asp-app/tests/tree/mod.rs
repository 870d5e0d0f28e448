//! Plans that follow the file's product tree (`subassemblies` from-file), on STEP conversions
//! read without Python (`tests/data/step/*.glb`, cascadio's GLB of the `.step` beside it).

use asp_app::pipeline::{self, PlanSettings};
use asp_app::tree::tree;
use asp_geom::io::step::assemble;
use asp_geom::io::LoadOptions;
use asp_search::report::{AssemblyStep, PlanStatus, SubassemblyStatus};
use std::path::{Path, PathBuf};

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tests/data/step").join(name)
}

fn step(stem: &str, ext: &str) -> asp_geom::Assembly {
    let path = data(&format!("{stem}.{ext}"));
    let glb = std::fs::read(data(&format!("{stem}.glb"))).unwrap();
    assemble(&path, &std::fs::read(&path).unwrap(), &glb, &LoadOptions::default()).unwrap()
}

fn from_file() -> PlanSettings {
    PlanSettings { from_file: true, ..PlanSettings::default() }
}

/// Every step of `steps`, subassemblies' own steps included.
fn all(steps: &[AssemblyStep]) -> Vec<&AssemblyStep> {
    steps.iter().flat_map(|s| std::iter::once(s).chain(s.subassembly.iter().flat_map(|g| all(&g.assembly_sequence)))).collect()
}

#[test]
fn the_spindle_goes_in_as_one_unit_built_from_its_bearings() {
    let a = step("shaft_bearings", "step");
    let root = tree(&a);
    assert_eq!(root.name, "shaft_bearings");
    assert_eq!(root.children.len(), 1);
    assert_eq!(root.children[0].name, "shaft_bearings/spindle");
    assert_eq!(root.children[0].children.len(), 2, "two bearings of two races each");
    let plan = pipeline::plan_assembly(a.clone(), &from_file(), None).unwrap().report;
    assert_eq!(plan.status, PlanStatus::Found, "{}", plan.to_text());
    // the spindle's step carries the spindle's own plan, which carries each bearing's
    let spindle = all(&plan.assembly_sequence)
        .into_iter()
        .find_map(|s| s.subassembly.as_ref().filter(|g| g.name.as_deref() == Some("shaft_bearings/spindle")))
        .expect("a step puts the spindle in as one unit");
    assert_eq!(spindle.status, SubassemblyStatus::Found);
    assert_eq!(spindle.parts.len(), 5);
    let bearings: Vec<&str> = all(&spindle.assembly_sequence).iter().filter_map(|s| s.subassembly.as_ref()?.name.as_deref()).collect();
    assert_eq!(bearings.len(), 2, "{bearings:?}");
    // every subassembly of the file has its own plan, outermost first
    let names: Vec<&str> = plan.file_subassemblies.iter().map(|g| g.name.as_deref().unwrap()).collect();
    assert_eq!(names, ["shaft_bearings/spindle", "shaft_bearings/spindle/bearing_1", "shaft_bearings/spindle/bearing_2"]);
    // without the tree the same model plans part by part: no named subassemblies
    let flat = pipeline::plan_assembly(a, &PlanSettings::default(), None).unwrap().report;
    assert!(flat.file_subassemblies.is_empty());
    assert!(all(&flat.assembly_sequence).iter().all(|s| s.subassembly.as_ref().is_none_or(|g| g.name.is_none())));
}

#[test]
fn as1_has_a_plan_per_subassembly_and_one_for_the_top() {
    let a = step("as1-oc-214", "stp");
    let plan = pipeline::plan_assembly(a, &from_file(), None).unwrap().report;
    let names: Vec<&str> = plan.file_subassemblies.iter().map(|g| g.name.as_deref().unwrap()).collect();
    assert_eq!(names.len(), 9, "{names:?}");
    assert_eq!(names[0], "as1/rod-assembly_1");
    assert!(names.contains(&"as1/l-bracket-assembly_1") && names.contains(&"as1/l-bracket-assembly_2/nut-bolt-assembly_3"));
    // a nut comes off its bolt
    let nut_bolt =
        plan.file_subassemblies.iter().find(|g| g.name.as_deref() == Some("as1/l-bracket-assembly_1/nut-bolt-assembly_1")).unwrap();
    assert_eq!((nut_bolt.status, nut_bolt.assembly_sequence.len()), (SubassemblyStatus::Found, 1));
    // the file's l-bracket subassemblies cannot go in whole: their bolts pass through the plate
    // and the rod through both brackets, so the top level keeps them together as a locked core
    assert_eq!(plan.status, PlanStatus::Partial, "{}", plan.to_text());
    assert_eq!(plan.parts.len(), 18);
    assert!(plan.parts.iter().all(|p| p.path.first().map(String::as_str) == Some("as1")));
}
