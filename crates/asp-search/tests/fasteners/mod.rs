//! Threaded fasteners in the planner: a bolt in a nut comes apart by screwing,
//! every step re-checked by the independent sweep (the screw steps outside their thread zone).

use crate::verify::verify_plan;
use asp_geom::{fixtures, Checker, CheckerConfig, Motion, World, WorldConfig};
use asp_search::{Budget, Dfs, Problem, Status};

#[test]
fn a_bolt_in_a_nut_on_a_plate_comes_apart_by_screwing_and_every_step_rechecks() {
    for interference in [0.0, 0.0001] {
        let world = World::new(fixtures::bolt_and_nut(interference), &WorldConfig::default()).unwrap();
        let checker = Checker::new(world, CheckerConfig::default());
        let outcome = Dfs::builder().build().solve(&Problem::full(&checker), &Budget::default());
        assert_eq!(outcome.status, Status::Found, "interference {interference}");
        verify_plan(checker.world(), &outcome);
        // the first part off screws (the bolt up out of the nut, or the nut down off the bolt)
        let first = &outcome.removals[0];
        assert!(matches!(first.motion, Motion::Screw { .. }), "{:?}", first.motion);
        let json =
            asp_search::report::PlanReport::new(checker.world().assembly(), &outcome, checker.world().shapes().tolerance(), &[]).to_json();
        assert!(json.contains("\"screw\""), "{json}");
        // without the screw rule: locked
        let world = World::new(fixtures::bolt_and_nut(interference), &WorldConfig { fasteners: false, ..WorldConfig::default() }).unwrap();
        let checker = Checker::new(world, CheckerConfig::default());
        let outcome = Dfs::builder().path_planner(false).build().solve(&Problem::full(&checker), &Budget::default());
        assert!(matches!(outcome.status, Status::NoPlan { .. }), "interference {interference}: {:?}", outcome.status);
    }
}

#[test]
fn the_independent_recheck_refuses_screw_steps_that_push_a_head_into_material_or_leave_the_axis() {
    use crate::verify::verify_from;
    use asp_geom::math::Vec3;
    use asp_geom::PartSet;
    let world = World::new(fixtures::bolt_and_nut(0.0001), &WorldConfig::default()).unwrap();
    let (bolt, nut) = (1, 2);
    let t = world.overlaps().fits().thread(bolt, nut).unwrap();
    let screw = |d: Vec3| asp_search::Step::single(bolt, Motion::Screw { axis_point: t.axis.point, direction: d, distance: 0.03 });
    let caught = |state: PartSet, base: PartSet, step: asp_search::Step| {
        let w = &world;
        std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
            verify_from(w, state, &base, &[step]);
        }))
        .err()
        .map(|e| e.downcast_ref::<String>().cloned().or_else(|| e.downcast_ref::<&str>().map(|s| s.to_string())).unwrap_or_default())
    };
    // unscrewing upward passes, on the plate and nut or on the nut alone
    assert_eq!(caught(PartSet::full(3), world.contacts().fixed().clone(), screw(Vec3::Z)), None);
    let on_nut = PartSet::from_indices(4, [nut]);
    assert_eq!(caught(PartSet::from_indices(4, [bolt, nut]), on_nut.clone(), screw(Vec3::Z)), None);
    // screwed downward the head enters the plate (and then the nut below it)
    let e = caught(PartSet::full(3), world.contacts().fixed().clone(), screw(-Vec3::Z)).expect("refused");
    assert!(e.contains("'bolt' hits 'plate'") || e.contains("enters 'nut'"), "{e}");
    // without the plate the head comes down onto the nut: the nut is the bolt's threaded partner,
    // and outside the thread zone the strict rule still holds
    let e = caught(PartSet::from_indices(4, [bolt, nut]), on_nut, screw(-Vec3::Z)).expect("refused");
    assert!(e.contains("strict") && e.contains("'nut'"), "{e}");
    // a screw step off the thread's axis is refused
    let e = caught(PartSet::full(3), world.contacts().fixed().clone(), screw(Vec3::X)).expect("refused");
    assert!(e.contains("screws off its axis") || e.contains("hits"), "{e}");
}

/// Plans `assembly` with the default checker and re-checks the plan; returns the removals'
/// (part, motion kind, direction) in removal order.
fn plan_and_recheck(assembly: asp_geom::Assembly) -> Vec<(String, &'static str, asp_geom::math::Vec3)> {
    let source = assembly.source.display().to_string();
    let world = World::new(assembly, &WorldConfig::default()).unwrap();
    let checker = Checker::new(world, CheckerConfig::default());
    let outcome = Dfs::builder().build().solve(&Problem::full(&checker), &Budget::default());
    assert_eq!(outcome.status, Status::Found, "{source}");
    verify_plan(checker.world(), &outcome);
    outcome
        .removals
        .iter()
        .map(|s| {
            let (kind, d) = match s.motion {
                Motion::Linear { direction, .. } => ("linear", direction),
                Motion::Screw { direction, .. } => ("screw", direction),
                Motion::Path { .. } => ("path", asp_geom::math::Vec3::ZERO),
            };
            (checker.world().name(s.part).to_string(), kind, d)
        })
        .collect()
}

#[test]
fn cad_drawn_bolted_joints_come_apart_nut_first_along_the_axis_at_every_tessellation() {
    use asp_geom::math::Vec3;
    for facets in [[26, 16, 12], [26, 32, 30], [96, 128, 90]] {
        let steps = plan_and_recheck(fixtures::bolted_joint(facets));
        let names: Vec<&str> = steps.iter().map(|s| s.0.as_str()).collect();
        assert_eq!(names, ["nut M10", "bolt M10", "top plate"], "{facets:?}");
        assert_eq!((steps[0].1, steps[1].1), ("screw", "linear"), "{facets:?}");
        assert!(steps[0].2.dot(-Vec3::Z) > 0.9999 && steps[1].2.dot(Vec3::Z) > 0.9999, "{steps:?}");
    }
}

#[test]
fn cad_drawn_screws_and_pins_come_out_along_their_axes() {
    use asp_geom::math::Vec3;
    for facets in [[26, 16], [90, 128]] {
        let steps = plan_and_recheck(fixtures::tapped_screw(facets));
        assert_eq!((steps[0].0.as_str(), steps[0].1), ("cap screw", "screw"), "{facets:?}");
        assert!(steps[0].2.dot(Vec3::Z) > 0.9999);
        let steps = plan_and_recheck(fixtures::pressed_pin(facets, 0.0001));
        assert_eq!(steps[0].1, "linear");
        assert!(steps[0].2.dot(Vec3::Z).abs() > 0.9999, "{steps:?}");
    }
}

#[test]
fn the_independent_recheck_refuses_a_pin_dragged_sideways_through_its_bore() {
    use crate::verify::verify_from;
    use asp_geom::math::Vec3;
    use asp_geom::PartSet;
    let world = World::new(fixtures::pressed_pin([26, 32], 0.0001), &WorldConfig::default()).unwrap();
    let step = |d: Vec3| asp_search::Step::single(1, Motion::Linear { direction: d, distance: 0.05 });
    let caught = |s: asp_search::Step| {
        std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
            verify_from(&world, PartSet::full(2), world.contacts().fixed(), &[s]);
        }))
        .is_err()
    };
    assert!(!caught(step(Vec3::Z)), "pressed out along its axis");
    assert!(caught(step(Vec3::X)), "dragged sideways");
    assert!(caught(step(Vec3::new(0.05, 0.0, 1.0).normalize())), "pulled 3 degrees off its axis");
}
