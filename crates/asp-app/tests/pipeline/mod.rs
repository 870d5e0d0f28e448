//! The pipeline end to end on fixtures: which planner answers which model.

use asp_app::pipeline::{plan_assembly, PlanSettings};

/// Issue 9 item 6: the pipeline plans interlocking voxel puzzles by grid moves, straight away
/// when parts must move in turn before anything can leave, and leaves other voxel models to the
/// depth-first search.
#[test]
fn issue_9_the_pipeline_plans_interlocking_puzzles_by_grid_moves() {
    let settings = PlanSettings { timeout: Some(30.0), ..PlanSettings::default() };
    for (a, moves) in [
        (asp_geom::puzzles::burr_level(), asp_geom::puzzles::BURR_LEVEL_MOVES),
        (asp_geom::puzzles::small_puzzle(), asp_geom::puzzles::SMALL_PUZZLE_MOVES),
    ] {
        let name = a.source.display().to_string();
        let r = plan_assembly(a, &settings, None).unwrap();
        assert!(r.found(), "{name}: {}", r.report.to_json());
        let grid = r.report.grid.as_ref().expect("a grid plan");
        assert_eq!(grid.reason, asp_search::report::GridReason::NeedsMoves, "{name}");
        assert_eq!(grid.first_separation_moves, Some(moves), "{name}");
        // every part is taken out once; the last step in disassembly order carries the moves
        let mut order = r.report.disassembly_sequence.clone();
        order.sort_unstable();
        assert_eq!(order, (0..r.report.parts.len()).collect::<Vec<_>>(), "{name}");
        let last = r.report.assembly_sequence.last().unwrap();
        assert_eq!(last.moves.len(), moves, "{name}: the first separation's moves, in assembly order");
        assert_eq!(r.report.format_version, "1.8");
    }
    // a voxel model the straight-line search answers keeps its plan (no grid entry)
    let r = plan_assembly(asp_geom::puzzles::burr_key(), &settings, None).unwrap();
    assert!(r.found());
    assert!(r.report.grid.is_none(), "{}", r.report.to_json());
    let r = plan_assembly(asp_geom::fixtures::figure_6_2(0.01), &settings, None).unwrap();
    assert!(r.found() && r.report.grid.is_none());
    // without the grid the burr only lifts off the ground in one piece, a subassembly that
    // cannot be taken apart (straight lines and groups only)
    let off = PlanSettings { grid: false, path_planner: false, ..settings.clone() };
    let r = plan_assembly(asp_geom::puzzles::burr_level(), &off, None).unwrap();
    let first = r.report.assembly_sequence.first().and_then(|s| s.subassembly.as_ref());
    assert!(!r.found() || first.is_some_and(|g| g.status == asp_search::report::SubassemblyStatus::NoPlan && g.parts.len() == 6), "{}", r.report.to_json());
}
