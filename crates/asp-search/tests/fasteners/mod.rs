//! Threaded fasteners (issue 9 item 5) in the planner: a bolt in a nut comes apart by screwing,
//! every step re-checked by the independent sweep (the screw steps outside their thread zone).

use crate::verify::verify_plan;
use asp_geom::{fixtures, Checker, CheckerConfig, Motion, World, WorldConfig};
use asp_search::{Budget, Dfs, Planner, Problem, Status};

#[test]
fn issue_9_a_bolt_in_a_nut_on_a_plate_comes_apart_by_screwing_and_every_step_rechecks() {
    for interference in [0.0, 0.0001] {
        let world = World::new(fixtures::bolt_and_nut(interference), &WorldConfig::default()).unwrap();
        let checker = Checker::new(world, CheckerConfig::default());
        let outcome = Dfs::builder().build().solve(&Problem::full(&checker), &Budget::default());
        assert_eq!(outcome.status, Status::Found, "interference {interference}");
        verify_plan(checker.world(), &outcome);
        // the first part off screws (the bolt up out of the nut, or the nut down off the bolt)
        let first = &outcome.removals[0];
        assert!(matches!(first.motion, Motion::Screw { .. }), "{:?}", first.motion);
        let json = asp_search::report::PlanReport::new(checker.world().assembly(), &outcome, checker.world().tolerance(), &[]).to_json();
        assert!(json.contains("\"screw\""), "{json}");
        // without the screw rule: locked
        let world = World::new(fixtures::bolt_and_nut(interference), &WorldConfig { fasteners: false, ..WorldConfig::default() }).unwrap();
        let checker = Checker::new(world, CheckerConfig::default());
        let outcome = Dfs::builder().path_planner(false).build().solve(&Problem::full(&checker), &Budget::default());
        assert!(matches!(outcome.status, Status::NoPlan { .. }), "interference {interference}: {:?}", outcome.status);
    }
}

#[test]
fn issue_9_the_independent_recheck_refuses_screw_steps_that_push_a_head_into_material_or_leave_the_axis() {
    use crate::verify::verify_from;
    use asp_geom::math::Vec3;
    use asp_geom::PartSet;
    let world = World::new(fixtures::bolt_and_nut(0.0001), &WorldConfig::default()).unwrap();
    let (bolt, nut) = (1, 2);
    let t = world.thread(bolt, nut).unwrap();
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
    assert_eq!(caught(PartSet::full(3), world.fixed().clone(), screw(Vec3::Z)), None);
    let on_nut = PartSet::from_indices(4, [nut]);
    assert_eq!(caught(PartSet::from_indices(4, [bolt, nut]), on_nut.clone(), screw(Vec3::Z)), None);
    // screwed downward the head enters the plate (and then the nut below it)
    let e = caught(PartSet::full(3), world.fixed().clone(), screw(-Vec3::Z)).expect("refused");
    assert!(e.contains("'bolt' hits 'plate'") || e.contains("enters 'nut'"), "{e}");
    // without the plate the head comes down onto the nut: the nut is the bolt's threaded partner,
    // and outside the thread zone the strict rule still holds
    let e = caught(PartSet::from_indices(4, [bolt, nut]), on_nut, screw(-Vec3::Z)).expect("refused");
    assert!(e.contains("strict") && e.contains("'nut'"), "{e}");
    // a screw step off the thread's axis is refused
    let e = caught(PartSet::full(3), world.fixed().clone(), screw(Vec3::X)).expect("refused");
    assert!(e.contains("screws off its axis") || e.contains("hits"), "{e}");
}
