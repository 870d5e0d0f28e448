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
        assert_eq!(r.report.format_version, "1.9");
    }
    // a voxel model the straight-line search answers keeps its plan (no grid entry)
    let r = plan_assembly(asp_geom::puzzles::burr_key(), &settings, None).unwrap();
    assert!(r.found());
    assert!(r.report.grid.is_none(), "{}", r.report.to_json());
    let r = plan_assembly(asp_geom::fixtures::figure_6_2(0.01), &settings, None).unwrap();
    assert!(r.found() && r.report.grid.is_none());
}

/// Issue 28 item 1: a plan whose only sequence lifts an interlocked group in one piece is not
/// `found`: without the grid the burr only lifts off the ground as one subassembly that cannot
/// be taken apart (straight lines and groups only), so the plan is `partial` and names the core.
#[test]
fn issue_28_a_plan_that_lifts_a_locked_core_in_one_piece_is_partial() {
    use asp_search::report::{PlanStatus, SubassemblyStatus};
    let off = PlanSettings { grid: false, path_planner: false, timeout: Some(30.0), ..PlanSettings::default() };
    let r = plan_assembly(asp_geom::puzzles::burr_level(), &off, None).unwrap();
    let json = r.report.to_json();
    assert_eq!(r.report.status, PlanStatus::Partial, "{json}");
    assert!(!r.found(), "a partial plan is not found");
    // the sequence is complete: one step, the whole burr as a subassembly its own plan cannot open
    assert_eq!(r.report.assembly_sequence.len(), 1, "{json}");
    let g = r.report.assembly_sequence[0].subassembly.as_ref().expect("a subassembly step");
    assert_eq!(g.status, SubassemblyStatus::NoPlan);
    assert_eq!(g.parts.len(), 6);
    assert!(r.report.remaining.is_none() && r.report.partial_assembly_sequence.is_empty());
    // the locked core: every piece, with the group's own explanation as the reason
    assert_eq!(r.report.locked_cores.len(), 1, "{json}");
    let core = &r.report.locked_cores[0];
    assert_eq!(core.parts, (0..6).collect::<Vec<_>>());
    assert_eq!(core.base, r.report.assembly_sequence[0].part);
    assert_eq!(core.names, r.report.parts.iter().map(|p| p.name.clone()).collect::<Vec<_>>());
    assert_eq!(core.status, SubassemblyStatus::NoPlan);
    assert!(!core.explanation.is_empty() && core.explanation == g.explanation, "{json}");
    assert!(json.contains("\"status\": \"partial\"") && json.contains("\"locked_cores\""));
    // the table says so, as loudly as it says found
    let text = r.report.to_text();
    let header = text.lines().next().unwrap();
    assert!(header.contains(": partial in "), "{text}");
    let names = core.names.join(", ");
    assert_eq!(text.lines().nth(1), Some(format!("planned 0 of 6 parts; 6 stay in 1 locked core: {names}").as_str()), "{text}");
    // with the grid the same burr is taken apart piece by piece: found
    let on = PlanSettings { timeout: Some(30.0), ..PlanSettings::default() };
    let r = plan_assembly(asp_geom::puzzles::burr_level(), &on, None).unwrap();
    assert_eq!(r.report.status, PlanStatus::Found);
    assert!(r.found() && r.report.locked_cores.is_empty());
}

/// Issue 28 item 4: on a voxel puzzle the grid planner answers before the path planner, with or
/// without a fixed piece (with one fixed, the path planner used to run for half a minute first).
#[test]
fn issue_28_voxel_puzzles_with_a_fixed_piece_get_the_grid_before_the_path_planner() {
    let settings = PlanSettings { timeout: Some(60.0), ..PlanSettings::default() };
    use asp_geom::puzzles::{burr_level, small_puzzle, two_small_puzzles};
    for (fixed, puzzle) in
        [(false, burr_level()), (true, burr_level()), (true, small_puzzle()), (false, two_small_puzzles()), (true, two_small_puzzles())]
    {
        let mut a = puzzle;
        if fixed {
            // the largest piece (by volume) is the base
            let largest =
                (0..a.parts.len()).max_by(|&i, &j| a.parts[i].mesh.signed_volume().total_cmp(&a.parts[j].mesh.signed_volume())).unwrap();
            a.parts[largest].fixed = true;
        }
        let name = format!("{} (a fixed piece: {fixed})", a.source.display());
        let started = std::time::Instant::now();
        let r = plan_assembly(a, &settings, None).unwrap();
        assert!(r.found(), "{name}: {}", r.report.to_json());
        assert!(r.report.grid.is_some(), "{name}: a grid plan");
        assert_eq!(r.report.stats.path_planner_calls, 0, "{name}: the path planner ran before the grid");
        assert!(started.elapsed().as_secs_f64() < 10.0, "{name}: {:?}", started.elapsed());
    }
}

/// Issue 23: an optimiser's `no_plan` is explained like the feasibility search's, by its deepest
/// dead end on the maps (not an empty explanation over the whole model): the lid comes off, then
/// the block at the end of the L-shaped channel cannot leave along any straight line.
#[test]
fn an_optimisers_no_plan_is_explained_by_its_deepest_dead_end() {
    use asp_app::pipeline::OptimiseSettings;
    use asp_search::report::{ExplanationReason, PlanStatus};
    let mut parts = asp_geom::fixtures::l_path().parts;
    parts.push(asp_geom::fixtures::box_part("lid", [0.0, 0.0, 5.0], [5.0, 3.0, 6.0]));
    let a = asp_geom::fixtures::assemble("l_path_under_a_lid", parts, asp_geom::math::Axis::Z);
    for objectives in ["access", "dirchange"] {
        let o = OptimiseSettings { objectives: objectives.into(), episodes: 50, ..OptimiseSettings::default() };
        let settings = PlanSettings { optimise: Some(o), ..PlanSettings::default() };
        let r = plan_assembly(a.clone(), &settings, None).unwrap();
        let json = r.report.to_json();
        assert_eq!(r.report.status, PlanStatus::NoPlan, "{json}");
        let names = |steps: &[asp_search::report::AssemblyStep]| steps.iter().map(|s| s.name.clone()).collect::<Vec<_>>();
        assert_eq!(names(&r.report.partial_assembly_sequence), ["lid"], "{json}");
        assert_eq!(r.report.remaining, Some(vec![0, 1]), "{json}");
        assert_eq!(r.report.explanation.len(), 1, "{json}");
        let e = &r.report.explanation[0];
        assert_eq!((e.name.as_str(), e.reason), ("block", ExplanationReason::Blocked), "{json}");
        assert_eq!(e.parts.iter().map(|p| p.name.as_str()).collect::<Vec<_>>(), ["housing"], "{json}");
        let mut text = Vec::new();
        r.report.write_text(&mut text).unwrap();
        let text = String::from_utf8(text).unwrap();
        assert!(text.contains("the search space was exhausted: no complete sequence exists"), "{text}");
        assert!(text.contains("none (no complete sequence)"), "{text}");
    }
}
