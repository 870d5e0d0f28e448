//! Subassemblies: groups of parts that leave together along a straight line, locked
//! cores, and the subassemblies' own plans.

use crate::verify::{verify_plan, verify_removals};
use asp_geom::fixtures::ring_on_locked_post;
use asp_geom::{Checker, CheckerConfig, FeasibilityChecker, World, WorldConfig};
use asp_search::report::PlanReport;
use asp_search::{Budget, Dfs, PlanOutcome, Problem, Status, StuckReason};

fn plan(planner: &Dfs) -> (Checker, PlanOutcome) {
    let world = World::new(ring_on_locked_post(), &WorldConfig::default()).unwrap();
    let checker = Checker::new(world, CheckerConfig::default());
    let outcome = planner.solve(&Problem::full(&checker), &Budget::default());
    (checker, outcome)
}

#[test]
fn a_ring_locked_around_a_post_locked_in_a_base_is_a_named_core_with_a_partial_plan() {
    for path_planner in [false, true] {
        let (checker, outcome) = plan(&Dfs::builder().subassemblies(false).path_planner(path_planner).build());
        let Status::NoPlan { stuck, state } = &outcome.status else { panic!("{:?}", outcome.status) };
        let w = checker.world();
        // the cap comes off; base (0), post (1) and ring (2) hold each other
        assert_eq!(outcome.removals.iter().map(|s| w.name(s.part)).collect::<Vec<_>>(), ["cap"]);
        assert_eq!(state.iter().collect::<Vec<_>>(), [0, 1, 2]);
        assert_eq!(verify_removals(w, &outcome.removals), *state);
        for s in stuck {
            let StuckReason::Blocked(b) = &s.reason else { panic!("{s:?}") };
            // blocked only by the core and the ground
            assert!(b.iter().all(|q| q == checker.num_parts() || state.contains(q)), "{s:?}");
            assert!(b.iter().any(|q| q != s.part && q < 3), "{s:?}");
        }
        let report = PlanReport::new(w.assembly(), &outcome, w.shapes().tolerance(), &[]);
        assert_eq!(report.status, asp_search::report::PlanStatus::NoPlan);
        assert_eq!(report.partial_assembly_sequence.len(), 1);
        assert_eq!(report.remaining, Some(vec![0, 1, 2]));
        assert_eq!(report.explanation.iter().map(|e| e.name.as_str()).collect::<Vec<_>>(), ["base", "post", "ring"]);
        // the path planner gets one call per core part at most: its failures are remembered
        assert!(outcome.stats.counters.path_planner_calls <= 3, "{:?}", outcome.stats);
    }
}

#[test]
fn with_subassemblies_the_locked_core_leaves_as_one_group_that_cannot_be_taken_apart() {
    let (checker, outcome) = plan(&Dfs::builder().build());
    assert_eq!(outcome.status, Status::Found);
    verify_plan(checker.world(), &outcome);
    let w = checker.world();
    // the cap, then base + post + ring off the ground together, built on the base
    assert_eq!(outcome.removals.len(), 2);
    assert!(outcome.removals[0].group.is_none());
    let step = &outcome.removals[1];
    let group = step.group.as_ref().expect("a group step");
    assert_eq!(group.parts.iter().collect::<Vec<_>>(), [0, 1, 2]);
    assert_eq!(w.name(step.part), "base", "the largest part is the subassembly's base");
    let inner = group.plan.as_ref().expect("planned");
    let Status::NoPlan { state, .. } = &inner.status else { panic!("{:?}", inner.status) };
    assert_eq!(state.iter().collect::<Vec<_>>(), [0, 1, 2], "nothing comes off the base");
    // in the plan JSON: one step with its parts, status no_plan and the explanation
    // (base, post and ring never get motions of their own, so the plan is partial,
    // with that group as its one locked core)
    let report = PlanReport::new(w.assembly(), &outcome, w.shapes().tolerance(), &[]);
    assert_eq!(report.status, asp_search::report::PlanStatus::Partial);
    assert_eq!(report.locked_cores.len(), 1);
    assert_eq!(report.locked_cores[0].parts, [0, 1, 2]);
    assert_eq!(report.locked_cores[0].base, step.part);
    let entry = report.assembly_sequence[0].subassembly.as_ref().expect("the group goes in first");
    assert_eq!(entry.parts, [0, 1, 2]);
    assert_eq!(entry.status, asp_search::report::SubassemblyStatus::NoPlan);
    assert!(entry.assembly_sequence.is_empty());
    assert_eq!(entry.explanation.iter().map(|e| e.name.as_str()).collect::<Vec<_>>(), ["post", "ring"]);
    assert_eq!(report.disassembly_sequence, [3, 1, 2, 0], "every part once, the base last");
    let back: PlanReport = serde_json::from_str(&report.to_json()).unwrap();
    assert_eq!(back.assembly_sequence[0].subassembly, report.assembly_sequence[0].subassembly);
}

#[test]
fn groups_leave_only_when_no_single_part_can() {
    // the lack table, the beam: plans unchanged by subassemblies (no group steps)
    for fixture in [asp_geom::fixtures::arch(), asp_geom::fixtures::stacked_boxes()] {
        let world = World::new(fixture, &WorldConfig::default()).unwrap();
        let checker = Checker::new(world, CheckerConfig::default());
        let with = Dfs::builder().build().solve(&Problem::full(&checker), &Budget::default());
        let without = Dfs::builder().subassemblies(false).build().solve(&Problem::full(&checker), &Budget::default());
        assert_eq!(with.removals, without.removals);
        assert!(with.removals.iter().all(|s| s.group.is_none()));
    }
}

#[test]
fn a_hooked_bracket_lifts_then_slides_out() {
    let world = World::new(asp_geom::fixtures::hooked_bracket(), &WorldConfig::default()).unwrap();
    let checker = Checker::new(world, CheckerConfig::default());
    let problem = Problem::full(&checker);
    // straight lines only: stuck, held by the wall
    let outcome = Dfs::builder().path_planner(false).build().solve(&problem, &Budget::default());
    assert!(matches!(outcome.status, Status::NoPlan { .. }), "{:?}", outcome.status);
    // two straight moves in turn, before any random sampling: up until the hook clears the lip
    // (10 mm, less half the tolerance), then out along +x
    let outcome = Dfs::builder().build().solve(&problem, &Budget::default());
    assert_eq!(outcome.status, Status::Found);
    verify_plan(checker.world(), &outcome);
    let asp_geom::Motion::Path { poses, .. } = &outcome.removals[0].motion else { panic!("{:?}", outcome.removals[0].motion) };
    assert_eq!(poses.len(), 3);
    assert!(poses.iter().all(|p| p.rotation.angle_between(asp_geom::math::Rot::IDENTITY) < 1e-6), "translations only");
    let lift = poses[1].translation;
    assert!((lift.z - 0.01).abs() < 1e-4 && lift.x.abs() < 1e-6 && lift.y.abs() < 1e-6, "{poses:?}");
    let slide = poses[2].translation - lift;
    // until its bounds clear the wall's: the hook travels from x = 10 mm past the face at 20 mm
    assert!(slide.x > 0.01 && slide.x < 0.0105 && slide.y.abs() < 1e-6 && slide.z.abs() < 1e-6, "{slide:?}");
    assert_eq!(outcome.stats.counters.path_planner_calls, 1);
}
