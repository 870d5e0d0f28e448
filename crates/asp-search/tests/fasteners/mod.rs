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
