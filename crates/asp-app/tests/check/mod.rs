//! `asp check`'s library side (issue: check a given sequence): each step tested with the
//! planner's checker, the first failure with its blockers, the repair and its distances.

use crate::verify::verify_removals;
use asp_app::check::{check_assembly, parse_sequence, CheckReport, CheckStatus, Failure, RepairStatus};
use asp_app::pipeline::{self, PlanSettings};
use asp_geom::math::Vec3;
use asp_geom::{fixtures, Assembly, Motion};
use asp_search::report::MotionEntry;
use asp_search::Step;

fn straight() -> PlanSettings {
    PlanSettings { path_planner: false, ..PlanSettings::default() }
}

fn check(a: Assembly, text: &str, settings: &PlanSettings) -> CheckReport {
    check_assembly(a, &parse_sequence(text).unwrap(), settings).unwrap()
}

fn names(r: &asp_app::check::CheckStep) -> Vec<&str> {
    r.parts.iter().map(|p| p.name.as_str()).collect()
}

/// The repair's steps as removals (metres: the fixtures are in metres), for the independent
/// re-check.
fn removals(report: &CheckReport) -> Vec<Step> {
    let repair = report.repair.as_ref().unwrap();
    repair
        .sequence
        .iter()
        .rev()
        .map(|s| {
            let MotionEntry::Linear { direction, distance } = &s.motion else { panic!("straight motions only") };
            let d = -Vec3::new(direction[0] as f32, direction[1] as f32, direction[2] as f32);
            assert_eq!(s.parts.len(), 1);
            Step::single(s.parts[0].part, Motion::Linear { direction: d, distance: *distance as f32 })
        })
        .collect()
}

#[test]
fn check_a_feasible_sequence_reports_every_motion() {
    let r = check(fixtures::tube(), "# the tube, base first\nreceptacle\ncap\nstick\nhandle\n", &straight());
    assert_eq!(r.status, CheckStatus::Feasible, "{}", r.to_text());
    assert_eq!(r.first_failure, None);
    assert!(r.repair.is_none());
    assert_eq!(r.steps.len(), 3, "the base part is no step");
    assert_eq!(r.notes.len(), 1, "{:?}", r.notes);
    assert!(r.steps.iter().all(|s| s.feasible && s.motion.is_some()));
    // the stick goes in along its tube's axis
    let Some(MotionEntry::Linear { direction, .. }) = &r.steps[1].motion else { panic!("{:?}", r.steps[1]) };
    assert!(direction[2].abs() > 0.999, "{direction:?}");
    assert!(r.to_text().contains("feasible: every step goes in"), "{}", r.to_text());
    // a group goes in as one body
    let r = check(fixtures::tube(), "[cap, stick]\nhandle\n", &straight());
    assert_eq!(r.status, CheckStatus::Feasible, "{}", r.to_text());
    assert_eq!(names(&r.steps[0]), ["cap", "stick"]);
}

#[test]
fn check_names_the_first_failing_step_and_its_blockers() {
    // the stick cannot go in after both the cap and the handle close the tube
    let r = check(fixtures::tube(), "cap\nhandle\nstick\n", &straight());
    assert_eq!(r.status, CheckStatus::Infeasible);
    assert_eq!(r.first_failure, Some(2), "{}", r.to_text());
    let Some(Failure::Blocked { along_given: false, blockers, directions, .. }) = &r.steps[2].failure else {
        panic!("{:?}", r.steps[2].failure)
    };
    let mut b: Vec<&str> = blockers.iter().map(|p| p.name.as_str()).collect();
    b.sort_unstable();
    assert!(b.contains(&"cap") && b.contains(&"handle"), "{b:?}");
    // along the tube's axis: the handle from above, the cap from below
    let along = |z: f64| directions.iter().find(|d| (d.direction[2] - z).abs() < 1e-6).unwrap();
    assert!(along(-1.0).blockers.iter().any(|p| p.name == "handle"), "{directions:?}");
    assert!(along(1.0).blockers.iter().any(|p| p.name == "cap"), "{directions:?}");
    assert!(r.steps[0].feasible && r.steps[1].feasible);
    assert!(r.to_text().contains("infeasible: step 3 (stick) fails: blocked by"), "{}", r.to_text());
    // with the path planner the failure is "no path"
    let r = check(fixtures::tube(), "cap\nhandle\nstick\n", &PlanSettings { rrt_iterations: 200, ..PlanSettings::default() });
    assert!(matches!(r.steps[2].failure, Some(Failure::NoPath { .. })), "{:?}", r.steps[2].failure);
}

#[test]
fn check_tests_a_given_direction_only() {
    // in from above (insertion -z): free once the handle is not there yet
    let r = check(fixtures::tube(), "cap\nstick -z\nhandle\n", &straight());
    assert_eq!(r.status, CheckStatus::Feasible, "{}", r.to_text());
    assert_eq!(r.steps[1].given_direction, Some([0.0, 0.0, -1.0]));
    // in from below (insertion +z) is blocked by the cap, though from above is free
    let r = check(fixtures::tube(), "cap\nstick 0,0,2\nhandle\n", &straight());
    assert_eq!(r.first_failure, Some(1), "{}", r.to_text());
    let Some(Failure::Blocked { along_given: true, blockers, free_directions, .. }) = &r.steps[1].failure else {
        panic!("{:?}", r.steps[1].failure)
    };
    assert_eq!(blockers.iter().map(|p| p.name.as_str()).collect::<Vec<_>>(), ["cap"]);
    assert!(free_directions.iter().any(|d| (d[2] + 1.0).abs() < 1e-6), "{free_directions:?}");
    // the repair drops nothing: the same order is feasible along another direction
    let repair = r.repair.as_ref().unwrap();
    assert_eq!((repair.status, repair.moved, repair.kendall_tau), (RepairStatus::Found, 0, 0));
}

#[test]
fn check_finds_an_unstable_step() {
    // the keystone cannot be placed before both its pillars: without pillar_a it would float
    let r = check(fixtures::arch(), "keystone\npillar_a\npillar_b\n", &straight());
    assert_eq!(r.first_failure, Some(1), "{}", r.to_text());
    let Some(Failure::Unstable { floating, .. }) = &r.steps[1].failure else { panic!("{:?}", r.steps[1].failure) };
    assert_eq!(floating.iter().map(|p| p.name.as_str()).collect::<Vec<_>>(), ["keystone"]);
}

#[test]
fn check_repairs_to_a_near_feasible_sequence() {
    let settings = straight();
    let r = check(fixtures::tube(), "cap\nhandle\nstick\n", &settings);
    let repair = r.repair.as_ref().expect("a repair");
    assert_eq!(repair.status, RepairStatus::Found);
    let order: Vec<&str> = repair.sequence.iter().map(|s| s.parts[0].name.as_str()).collect();
    assert_eq!(order, ["cap", "stick", "handle"]);
    assert_eq!((repair.moved, repair.kendall_tau), (1, 1));
    assert_eq!(repair.sequence.iter().filter(|s| s.moved).count(), 1);
    // the repair is feasible: by the check itself and by the independent re-check
    let again = check(fixtures::tube(), &order.join("\n"), &settings);
    assert_eq!(again.status, CheckStatus::Feasible, "{}", again.to_text());
    let world = pipeline::checker(fixtures::tube(), &settings).unwrap();
    let left = verify_removals(world.world(), &removals(&r));
    assert!(left.iter().all(|p| world.world().contacts().fixed().contains(p)));
    // and no farther than the planner's own sequence (which ignores the given order), nearer
    // than the reversed order
    let from_planner = pipeline::plan_assembly(fixtures::tube(), &settings, None).unwrap();
    let given = ["cap", "handle", "stick"];
    let planned: Vec<usize> =
        from_planner.report.assembly_sequence.iter().map(|s| given.iter().position(|g| *g == s.name).unwrap()).collect();
    let (planner_moved, _) = asp_app::check::moved_steps(&planned);
    assert!(repair.moved <= planner_moved && repair.kendall_tau <= asp_app::check::kendall_tau(&planned));
    assert!(repair.moved < asp_app::check::moved_steps(&[2, 1, 0]).0);
    // a feasible sequence needs no repair
    assert!(check(fixtures::tube(), "cap\nstick\nhandle\n", &settings).repair.is_none());
}

#[test]
fn check_rejects_unknown_names_with_the_nearest_ones() {
    let e = check_assembly(fixtures::tube(), &parse_sequence("cap\nstik\nhandel\n").unwrap(), &straight()).unwrap_err();
    let msg = e.to_string();
    assert!(!msg.contains('\n'), "{msg}");
    assert!(msg.contains("'stik' (nearest: stick"), "{msg}");
    assert!(msg.contains("'handel' (nearest: handle"), "{msg}");
    let e = check_assembly(fixtures::tube(), &parse_sequence("cap\nstick\n").unwrap(), &straight()).unwrap_err();
    assert!(e.to_string().contains("leaves out 1: handle"), "{e}");
    let e = check_assembly(fixtures::tube(), &parse_sequence("cap\nstick\nhandle\ncap\n").unwrap(), &straight()).unwrap_err();
    assert!(e.to_string().contains("'cap' is placed twice"), "{e}");
}

#[test]
fn check_reads_a_plan_json() {
    let settings = straight();
    let plan = pipeline::plan_assembly(fixtures::tube(), &settings, None).unwrap();
    let steps = parse_sequence(&plan.report.to_json()).unwrap();
    assert_eq!(steps.len(), 3);
    assert!(steps.iter().all(|s| s.direction.is_some()));
    let r = check_assembly(fixtures::tube(), &steps, &settings).unwrap();
    assert_eq!(r.status, CheckStatus::Feasible, "{}", r.to_text());
}

/// A shipped real model: the IKEA Lack table (four legs, a top pushed onto them, Z up). The top
/// cannot go in before the legs: the first leg after it is blocked by the top in every direction.
#[test]
fn check_on_the_shipped_lack_table() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tests/data/ikea/table_lack_0825.glb");
    let settings = PlanSettings { up: Some(asp_geom::math::Axis::Z), ..PlanSettings::default() };
    let lack = || pipeline::load(&path, &settings).unwrap();
    let r = check(lack(), "0_part0\n1_part1\n2_part2\n3_part3\n4_part4 -z\n", &settings);
    assert_eq!(r.status, CheckStatus::Feasible, "{}", r.to_text());
    let r = check(lack(), "4_part4\n0_part0\n1_part1\n2_part2\n3_part3\n", &settings);
    assert_eq!(r.first_failure, Some(1), "{}", r.to_text());
    let Some(Failure::NoPath { blockers, .. }) = &r.steps[1].failure else { panic!("{:?}", r.steps[1].failure) };
    assert!(blockers.iter().any(|b| b.name == "4_part4"), "{blockers:?}");
    let repair = r.repair.as_ref().unwrap();
    assert_eq!((repair.status, repair.moved, repair.kendall_tau), (RepairStatus::Found, 1, 4));
    assert_eq!(repair.sequence.last().unwrap().parts[0].name, "4_part4");
    assert!(repair.sequence.last().unwrap().moved);
}
