//! The pipeline end to end on fixtures: which planner answers which model.

use asp_app::pipeline::{plan_assembly, PlanSettings};

/// The pipeline plans interlocking voxel puzzles by grid moves, straight away
/// when parts must move in turn before anything can leave, and leaves other voxel models to the
/// depth-first search.
#[test]
fn the_pipeline_plans_interlocking_puzzles_by_grid_moves() {
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
        assert_eq!(r.report.format_version, asp_search::report::FORMAT_VERSION);
    }
    // a voxel model the straight-line search answers keeps its plan (no grid entry)
    let r = plan_assembly(asp_geom::puzzles::burr_key(), &settings, None).unwrap();
    assert!(r.found());
    assert!(r.report.grid.is_none(), "{}", r.report.to_json());
    let r = plan_assembly(asp_geom::fixtures::figure_6_2(0.01), &settings, None).unwrap();
    assert!(r.found() && r.report.grid.is_none());
}

/// A plan whose only sequence lifts an interlocked group in one piece is not
/// `found`: without the grid the burr only lifts off the ground as one subassembly that cannot
/// be taken apart (straight lines and groups only), so the plan is `partial` and names the core.
#[test]
fn a_plan_that_lifts_a_locked_core_in_one_piece_is_partial() {
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

/// On a voxel puzzle the grid planner answers before the path planner, with or
/// without a fixed piece (with one fixed, the path planner used to run for half a minute first).
#[test]
fn voxel_puzzles_with_a_fixed_piece_get_the_grid_before_the_path_planner() {
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

/// An optimiser's `no_plan` is explained like the feasibility search's, by its deepest
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
        let o = OptimiseSettings { objectives: vec![objectives.into()], episodes: 50, ..OptimiseSettings::default() };
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

/// The shared pump (tests/data/pump, millimetres).
fn pump() -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tests/data/pump")
}

/// The shared pump, drawn as CAD draws it: its screws sit in their holes at one nominal radius
/// and its shaft in the body, each pair faceted differently, so the polygons overlap by their
/// sagitta (0.04 and 0.12 mm). Recognised as fits, they come apart along their axes and the
/// pump plans `found` (it stayed a locked core of six parts under the strict overlap rule
/// alone): the shaft slides out along its own axis, every screw along its own, and the JSON
/// and the table list each fit with its class and radii.
#[test]
fn the_pump_comes_apart_along_its_fits() {
    use asp_geom::fits::FitClass;
    use asp_search::report::PlanStatus;
    let settings = PlanSettings { unit: Some(asp_geom::Units::parse("mm").unwrap()), ..PlanSettings::default() };
    let r = asp_app::pipeline::plan_file(&pump(), &settings, None).unwrap();
    let json = r.report.to_json();
    assert_eq!(r.report.status, PlanStatus::Found, "{json}");
    assert!(r.report.locked_cores.is_empty(), "{json}");
    let fits = &r.report.fits;
    let fit = |shaft: &str, hole: &str| {
        fits.iter()
            .find(|f| f.names == [format!("PumpAssembly - {shaft}"), format!("PumpAssembly - {hole}")])
            .unwrap_or_else(|| panic!("a fit of {shaft} in {hole}: {json}"))
    };
    let shaft = fit("Shaft-1", "Pump-1");
    assert_eq!(shaft.class, FitClass::LineToLine, "{json}");
    assert!((shaft.radii[0] - 8.5).abs() < 0.05 && (shaft.radii[1] - 8.5).abs() < 0.05, "{json}");
    for k in 1..=8 {
        let f = fit(&format!("Screw{k}-1"), "Pump-1");
        assert!((f.radii[0] - 2.5).abs() < 0.05, "{json}");
    }
    // every step along the axis of the part's fits (a subassembly's parts in its own plan)
    fn steps(s: &[asp_search::report::AssemblyStep]) -> Vec<&asp_search::report::AssemblyStep> {
        s.iter().flat_map(|x| std::iter::once(x).chain(x.subassembly.iter().flat_map(|g| steps(&g.assembly_sequence)))).collect()
    }
    let all = steps(&r.report.assembly_sequence);
    let mut checked = 0;
    for step in &all {
        let Some(f) = fits.iter().find(|f| f.parts[0] == step.part && step.subassembly.is_none()) else { continue };
        let asp_search::report::MotionEntry::Linear { direction, .. } = &step.motion else { panic!("{json}") };
        let along = direction.iter().zip(&f.axis).map(|(a, b)| a * b).sum::<f64>().abs();
        assert!(along > 0.999, "{} leaves along its fit's axis: {json}", step.name);
        checked += 1;
    }
    assert!(checked >= 11, "the shaft and the ten screws: {json}");
    // the shaft is stepped: one fit in the bore of its impeller disc, one along its length
    assert_eq!(fits.iter().filter(|f| f.names[0] == "PumpAssembly - Shaft-1").count(), 2, "{json}");
    assert!(json.contains("\"fits\": [") && json.contains("\"class\": \"line_to_line\""), "{json}");
    let text = r.report.to_text();
    assert!(text.contains("fits (23; a shaft in a hole about one axis, taken apart along it):"), "{text}");
    assert!(
        text.contains(
            "  PumpAssembly - Shaft-1 (other) in PumpAssembly - Pump-1 (other): line-to-line fit (one nominal radius), radii 8.50 / 8.50"
        ),
        "{text}"
    );
}

/// Two bars drawn through each other (a halving joint with no notches modelled: an overlap no
/// shrinking separates) beside a ring on a locked post (a real interlock of cells): two
/// locked cores, each with its own reason.
fn crossed_bars_beside_a_locked_post() -> asp_geom::Assembly {
    use asp_geom::fixtures::box_part;
    let mut a = asp_geom::fixtures::ring_on_locked_post();
    // bar (along x) through the middle of a thicker bar (along y), 20 cm away from the post
    a.parts.push(box_part("bar", [0.20, 0.01, 0.005], [0.23, 0.02, 0.01]));
    a.parts.push(box_part("cross", [0.21, 0.0, 0.0], [0.22, 0.03, 0.015]));
    a
}

/// Locked-core reasons on a generated case: the crossed bars are locked by a modelling artefact
/// (their overlap is deeper than any fit) that `--overlaps lenient` frees; the ring, post and
/// base are locked by their shapes (each blocked along every direction, no overlap), which
/// nothing frees; the model is no voxel model (the bars share cells), but the post's core alone is.
#[test]
fn an_artefact_and_an_interlock_are_told_apart() {
    use asp_search::report::{CoreGridReason, LenientStatus, PlanStatus};
    let settings = PlanSettings { timeout: Some(60.0), ..PlanSettings::default() };
    let r = plan_assembly(crossed_bars_beside_a_locked_post(), &settings, None).unwrap();
    let json = r.report.to_json();
    assert_eq!(r.report.status, PlanStatus::Partial, "{json}");
    let mut cores: Vec<_> = r.report.locked_cores.iter().collect();
    cores.sort_by_key(|c| c.parts.clone());
    assert_eq!(cores.iter().map(|c| c.names.clone()).collect::<Vec<_>>(), [vec!["base", "post", "ring"], vec!["bar", "cross"]], "{json}");
    // the bars: one gross overlap, an artefact; the bar blocked by the cross along every direction
    let bars = cores[1].why.as_ref().unwrap();
    assert_eq!(cores[1].base, 5, "the larger bar is the base");
    assert_eq!(bars.overlaps.len(), 1, "{json}");
    let o = &bars.overlaps[0];
    assert_eq!((o.parts, o.gross, o.artefact), ([4, 5], true, true), "{json}");
    assert!(o.depth > bars.artefact_depth, "{json}");
    assert_eq!(bars.blocks.len(), 1);
    assert_eq!((bars.blocks[0].name.as_str(), bars.blocks[0].free), ("bar", 0), "{json}");
    assert_eq!(bars.blocks[0].by.len(), 1);
    assert_eq!(
        (bars.blocks[0].by[0].part, bars.blocks[0].by[0].directions, bars.blocks[0].by[0].only),
        (5, bars.directions, bars.directions)
    );
    assert_eq!((bars.lenient.status, bars.lenient.frees), (LenientStatus::Found, 1), "{json}");
    assert!(!bars.grid.tried && bars.grid.reason == CoreGridReason::NotOnGrid && bars.grid.core_on_grid == Some(false), "{json}");
    // the post: no overlap, ring and post held by each other and the base, lenient changes nothing
    let post = cores[0].why.as_ref().unwrap();
    assert_eq!(cores[0].base, 0, "the base is the post's core's base");
    assert!(post.overlaps.is_empty(), "{json}");
    assert_eq!(post.blocks.iter().map(|b| b.name.as_str()).collect::<Vec<_>>(), ["post", "ring"]);
    assert!(post.blocks.iter().all(|b| b.free == 0), "{json}");
    let ring = &post.blocks[1];
    let mut by: Vec<&str> = ring.by.iter().map(|q| q.name.as_str()).collect();
    by.sort_unstable();
    assert_eq!(by, ["base", "post"], "{json}");
    assert_eq!((post.lenient.status, post.lenient.frees), (LenientStatus::Unchanged, 0), "{json}");
    assert!(!post.grid.tried && post.grid.core_on_grid == Some(true), "the post's core alone is on one grid: {json}");
    let text = r.report.to_text();
    // the bars' exact boxes say how deep they cross (10 mm: the shorter push out of the cross,
    // the smallest over the axes), and what they are
    assert!(text.contains("    overlap bar / cross (interpenetration): 0.01000 deep"), "{text}");
    assert!(text.contains(": a modelling artefact, not an interlock\n"), "{text}");
    assert!(text.contains("    --overlaps lenient: would free its other part\n"), "{text}");
    assert!(text.contains("    --overlaps lenient: changes nothing (no two of its parts overlap)\n"), "{text}");
    assert!(text.contains("not all on one grid); the core's own parts are\n"), "{text}");
    // planned with lenient overlaps, the bars come apart: the rerun told the truth
    let lenient = PlanSettings { overlaps: asp_geom::OverlapPolicy::Lenient, ..settings.clone() };
    let r = plan_assembly(crossed_bars_beside_a_locked_post(), &lenient, None).unwrap();
    assert_eq!(
        r.report.locked_cores.iter().map(|c| c.names.clone()).collect::<Vec<_>>(),
        [vec!["base", "post", "ring"]],
        "{}",
        r.report.to_json()
    );
}

/// On a voxel model the grid planner runs on a locked core (and finds no moves
/// that take it apart); with `--no-grid` the core says it was not tried, and why.
#[test]
fn a_locked_core_says_whether_the_grid_planner_tried_it() {
    use asp_search::report::CoreGridReason;
    let on = PlanSettings { timeout: Some(60.0), ..PlanSettings::default() };
    let r = plan_assembly(asp_geom::fixtures::ring_on_locked_post(), &on, None).unwrap();
    let json = r.report.to_json();
    assert_eq!(r.report.locked_cores.len(), 1, "{json}");
    let grid = &r.report.locked_cores[0].why.as_ref().unwrap().grid;
    assert!(grid.tried && grid.reason == CoreGridReason::Stuck && grid.core_on_grid.is_none(), "{json}");
    assert!(r.report.to_text().contains("    grid planner: tried: no moves on the grid take it apart\n"));
    let off = PlanSettings { grid: false, ..on };
    let r = plan_assembly(asp_geom::fixtures::ring_on_locked_post(), &off, None).unwrap();
    let grid = &r.report.locked_cores[0].why.as_ref().unwrap().grid;
    assert!(!grid.tried && grid.reason == CoreGridReason::Off, "{}", r.report.to_json());
    assert!(r.report.to_text().contains("    grid planner: not tried (--no-grid)\n"));
}

/// Parts declared one unit (`--unit-group`) are planned as one part on purpose:
/// the locked post's core goes in whole as a `unit` step and the plan is `found`, not `partial`;
/// a unit with a fixed part is part of the base; an unknown name is an error naming the setting.
#[test]
fn a_declared_unit_is_planned_as_one_part_and_the_plan_is_found() {
    use asp_search::report::{PlanStatus, SubassemblyStatus};
    let unit = |names: &[&str]| vec![names.iter().map(|n| n.to_string()).collect::<Vec<_>>()];
    let settings = PlanSettings { timeout: Some(60.0), ..PlanSettings::default() };
    let r = plan_assembly(asp_geom::fixtures::ring_on_locked_post(), &settings, None).unwrap();
    assert_eq!(r.report.status, PlanStatus::Partial, "without the unit: {}", r.report.to_json());
    let declared = PlanSettings { unit_groups: unit(&["base", "post", "ring"]), ..settings.clone() };
    let r = plan_assembly(asp_geom::fixtures::ring_on_locked_post(), &declared, None).unwrap();
    let json = r.report.to_json();
    assert_eq!(r.report.status, PlanStatus::Found, "{json}");
    assert!(r.found() && r.report.locked_cores.is_empty() && r.report.grid.is_none(), "{json}");
    let steps = &r.report.assembly_sequence;
    assert_eq!(steps.len(), 2, "the unit, then the cap: {json}");
    let g = steps[0].subassembly.as_ref().expect("the unit's step");
    assert_eq!((g.parts.clone(), g.status, steps[0].part), (vec![0, 1, 2], SubassemblyStatus::Unit, 0), "{json}");
    assert!(g.assembly_sequence.is_empty() && g.explanation.is_empty());
    assert_eq!((steps[1].name.as_str(), steps[1].subassembly.is_none()), ("cap", true));
    assert!(json.contains("\"status\": \"unit\""));
    let text = r.report.to_text();
    assert!(text.contains("base + 2 more (unit)") && text.contains("declared one unit (--unit-group), not taken apart"), "{text}");
    // a unit with the fixed part is part of the base: the dowel never moves, the board comes off
    let fixed = PlanSettings { unit_groups: unit(&["lower", "dowel"]), ..settings.clone() };
    let r = plan_assembly(asp_geom::fixtures::dowel_in_two_boards(), &fixed, None).unwrap();
    assert_eq!(r.report.status, PlanStatus::Found, "{}", r.report.to_json());
    assert_eq!(r.report.assembly_sequence.iter().map(|s| s.name.as_str()).collect::<Vec<_>>(), ["upper"]);
    // names are checked against the model
    let wrong = PlanSettings { unit_groups: unit(&["base", "nope"]), ..settings };
    let e = plan_assembly(asp_geom::fixtures::ring_on_locked_post(), &wrong, None).unwrap_err();
    assert_eq!(e.to_string(), "unit_group: no part is named 'nope'");
}

/// Unit groups on the shared pump: six of its parts declared one unit go in as one `unit`
/// step; two parts declared one unit stay whole though their fit would let them part, and the
/// ring that goes on between them is then locked in a `partial` core.
#[test]
fn the_pumps_core_declared_one_unit_is_found() {
    use asp_search::report::{LenientStatus, PlanStatus, SubassemblyStatus};
    let p = |n: &str| format!("PumpAssembly - {n}");
    let core = ["BackLid2-1", "LargeScrew1-1", "LargeScrew2-1", "Pump-1", "Ring-1", "Shaft-1"];
    let mm = PlanSettings { unit: Some(asp_geom::Units::parse("mm").unwrap()), ..PlanSettings::default() };
    let declared = PlanSettings { unit_groups: vec![core.iter().map(|n| p(n)).collect()], ..mm.clone() };
    let r = asp_app::pipeline::plan_file(&pump(), &declared, None).unwrap();
    let json = r.report.to_json();
    assert_eq!(r.report.status, PlanStatus::Found, "{json}");
    let units: Vec<_> = r.report.assembly_sequence.iter().filter_map(|s| s.subassembly.as_ref()).collect();
    assert_eq!(units.len(), 1, "{json}");
    assert_eq!((units[0].status, units[0].parts.len()), (SubassemblyStatus::Unit, 6), "{json}");
    // a unit of two parts their fit would have separated stays whole: the ring, which goes on
    // before the shaft, is then trapped on it, and the unit's core stays `partial`; its lenient
    // rerun keeps the unit whole, so it frees nothing
    let pair = PlanSettings { unit_groups: vec![vec![p("Pump-1"), p("Shaft-1")]], ..mm };
    let r = asp_app::pipeline::plan_file(&pump(), &pair, None).unwrap();
    let json = r.report.to_json();
    assert_eq!(r.report.status, PlanStatus::Partial, "{json}");
    assert_eq!(r.report.locked_cores.len(), 1, "{json}");
    assert_eq!(r.report.locked_cores[0].names, [p("Pump-1"), p("Ring-1"), p("Shaft-1")], "{json}");
    let why = r.report.locked_cores[0].why.as_ref().unwrap();
    assert_eq!(why.grid.reason, asp_search::report::CoreGridReason::UnitGroups, "{json}");
    assert_eq!((why.lenient.status, why.lenient.frees), (LenientStatus::NoPlan, 0), "the shaft stays with the body: {json}");
    let text = r.report.to_text();
    assert!(text.contains("\n    grid planner: not tried (units declared with --unit-group)\n"), "{text}");
}

/// Under `--stability physics` the generated profile assemblies plan, single
/// and double layer, connectors attached or as parts: the simulation holds what the connectors
/// fasten (without it the frame collapses in its assembled state and nothing can leave). The
/// plans are `found`: every part gets its own motion (a subassembly's parts in its own plan).
#[test]
fn generated_profile_assemblies_plan_under_physics() {
    use asp_app::pipeline::StabilitySetting;
    use asp_gen::profiles::{ConnectorMode, ProfileAssembly, ProfileParams};
    use asp_search::report::PlanStatus;
    let physics =
        PlanSettings { stability: StabilitySetting::Physics { threshold: 0.01 }, timeout: Some(120.0), ..PlanSettings::default() };
    for (params, connectors, seed) in [
        (ProfileParams::single_layer(), ConnectorMode::Attached, 4242),
        (ProfileParams::single_layer(), ConnectorMode::Separate, 4242),
        (ProfileParams::double_layer(), ConnectorMode::Attached, 17),
    ] {
        let params = ProfileParams { connectors, ..params };
        let a = ProfileAssembly::generate(&params, seed).unwrap().to_assembly("test:profiles");
        let fastened = a.fastenings().0.len();
        assert!(fastened > 0 && a.fastenings().1.is_empty(), "{connectors:?} {seed}: the generator says what is fastened");
        let r = plan_assembly(a, &physics, None).unwrap();
        let what = format!("{connectors:?} seed {seed}: {}", r.report.to_text());
        assert_eq!(r.report.status, PlanStatus::Found, "{what}");
        assert!(r.report.locked_cores.is_empty(), "{what}");
    }
}

/// The plan says which learned guidance ran (format 1.11): the Q models, where they guided and,
/// for guided rollouts, ε; without Q models there is no `guidance`.
#[test]
fn the_plan_says_which_guidance_ran() {
    use asp_app::pipeline::OptimiseSettings;
    use asp_app::QPolicy;
    use asp_search::report::GuidanceEntry;
    use std::sync::Arc;
    let model = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../asp-learn/tests/data/random_q_access.onnx");
    let mut rng = <rand_chacha::ChaCha8Rng as rand::SeedableRng>::seed_from_u64(3);
    let cube = asp_gen::SomaCube::random(3, &mut rng).unwrap().to_assembly(0.05, "soma3");
    let run_at = |policy: Option<QPolicy>, resolution: usize| {
        let o = OptimiseSettings {
            objectives: vec!["access".into()],
            episodes: 5,
            threads: Some(1),
            resolution,
            policy: policy.map(|p| Arc::new(p) as Arc<dyn asp_app::PolicySource>),
            ..OptimiseSettings::default()
        };
        let settings = PlanSettings { optimise: Some(o), ..PlanSettings::default() };
        let r = plan_assembly(cube.clone(), &settings, None).unwrap();
        assert!(r.found(), "{}", r.report.to_json());
        r.report.optimisation.unwrap().guidance
    };
    let run = |policy| run_at(policy, 5);
    assert_eq!(run(None), None);
    for (uses, epsilon) in [(asp_search::QUse::Priors, None), (asp_search::QUse::Rollouts, Some(0.2))] {
        let q = QPolicy::new(std::slice::from_ref(&model), &["access"], 0.2, uses).unwrap();
        let want = GuidanceEntry { kind: "q".into(), models: vec![model.display().to_string()], q_use: uses.name().into(), epsilon };
        assert_eq!(run(Some(q)), Some(want));
    }
    // the shipped Q, by name, on the maps it was trained on: the plan names the built-in file
    let q = QPolicy::new(&["shipped".into()], &["access"], 0.2, asp_search::QUse::Priors).unwrap();
    let want =
        GuidanceEntry { kind: "q".into(), models: vec!["shipped:models/q-access.onnx".into()], q_use: "priors".into(), epsilon: None };
    assert_eq!(run_at(Some(q), 9), Some(want));
}

/// A rolling bearing in a housing on a shaft: its balls never leave their grooves, so taken part
/// by part it would stay a locked core with the housing (`partial`); recognised, it goes in as
/// one unit and the plan is `found`, the shaft through it along the axis.
#[test]
fn a_ball_bearing_goes_in_as_one_unit() {
    use asp_search::report::{PlanStatus, SubassemblyStatus};
    let settings = PlanSettings { timeout: Some(120.0), ..PlanSettings::default() };
    let r = plan_assembly(asp_geom::fixtures::ball_bearing(64, 9, true), &settings, None).unwrap();
    let json = r.report.to_json();
    assert_eq!(r.report.status, PlanStatus::Found, "{json}");
    assert!(r.report.locked_cores.is_empty(), "{json}");
    assert_eq!(r.report.bearings.len(), 1, "{json}");
    let b = &r.report.bearings[0];
    assert_eq!((b.rings, b.balls.len(), b.rows), ([2, 3], 9, 1), "{json}");
    assert_eq!(b.names, ["inner ring".to_string(), "outer ring".to_string()]);
    let steps = &r.report.assembly_sequence;
    assert_eq!(steps.len(), 2, "the bearing and the shaft: {json}");
    let unit = steps.iter().find_map(|s| s.subassembly.as_ref()).expect("the bearing's step");
    assert_eq!((unit.status, unit.parts.len()), (SubassemblyStatus::Unit, 11), "{json}");
    let mut parts = unit.parts.clone();
    parts.sort_unstable();
    assert_eq!(parts, b.parts);
    // both go in along the axis
    for s in steps {
        let d = match &s.motion {
            asp_search::report::MotionEntry::Linear { direction, .. } | asp_search::report::MotionEntry::Screw { direction, .. } => {
                *direction
            }
            other => panic!("{other:?}"),
        };
        assert!(d[2].abs() > 0.999, "{}: {d:?}", s.name);
    }
    assert!(json.contains("\"bearings\""));
    let text = r.report.to_text();
    assert!(text.contains("rolling bearing: inner ring in outer ring, 9 balls in 1 row"), "{text}");
    assert!(text.contains("a rolling bearing (balls captive between two rings), one unit, not taken apart"), "{text}");
}

/// A screw drawn as two solids of one product (its body and a thread solid sunk into it, as
/// bd_warehouse draws threaded fasteners): the two interpenetrate, so no motion separates them;
/// they are one component as drawn, planned as one unit, named in a warning and in the plan's
/// `components`. The same two solids as parts of different products (or of no product) stay a
/// locked core the plan explains.
#[test]
fn solids_of_one_product_that_interpenetrate_go_in_as_one_component() {
    use asp_geom::fixtures::{assemble, box_part};
    use asp_search::report::{PlanStatus, SubassemblyStatus};
    let model = |paths: [&str; 2]| {
        let mut base = box_part("plate", [0.0, 0.0, 0.0], [0.1, 0.1, 0.01]);
        base.fixed = true;
        // a bar drawn through the middle of a thicker one: no motion separates them
        let mut body = box_part("body", [0.04, 0.03, 0.01], [0.05, 0.06, 0.025]);
        let mut thread = box_part("thread", [0.03, 0.04, 0.015], [0.06, 0.05, 0.02]);
        body.path = vec!["bracket".into(), paths[0].into()];
        thread.path = vec!["bracket".into(), paths[1].into()];
        assemble("fused", vec![base, body, thread], asp_geom::math::Axis::Z)
    };
    let settings = PlanSettings { timeout: Some(60.0), ..PlanSettings::default() };
    let r = plan_assembly(model(["screw", "screw"]), &settings, None).unwrap();
    let json = r.report.to_json();
    assert_eq!(r.report.status, PlanStatus::Found, "{json}");
    assert_eq!(r.report.components.len(), 1, "{json}");
    assert_eq!((r.report.components[0].parts.clone(), r.report.components[0].product.as_str()), (vec![1, 2], "screw"));
    let unit = r.report.assembly_sequence.iter().find_map(|s| s.subassembly.as_ref()).expect("the screw's step");
    assert_eq!(unit.status, SubassemblyStatus::Unit, "{json}");
    assert!(r.report.warnings.iter().any(|w| w.contains("parts 'body', 'thread' of 'screw' interpenetrate: one component")), "{json}");
    assert!(r.report.to_text().contains("one component drawn as several interpenetrating solids, one unit"));
    // two products: a lock, explained, not a unit
    let r = plan_assembly(model(["screw", "nut"]), &settings, None).unwrap();
    assert_eq!(r.report.status, PlanStatus::Partial, "{}", r.report.to_json());
    assert!(r.report.components.is_empty());
}

/// A cylindrical roller bearing with ribs on both rings, in a housing on a shaft: without roller
/// bearings recognised the plan is `partial` (the rollers never leave their raceways between
/// the ribs); recognised, the bearing goes in as one unit along the axis and the plan is `found`.
#[test]
fn a_roller_bearing_goes_in_as_one_unit() {
    use asp_search::report::{PlanStatus, SubassemblyStatus};
    let settings = PlanSettings { timeout: Some(120.0), ..PlanSettings::default() };
    let r = plan_assembly(asp_geom::fixtures::roller_bearing(64, 10, true), &settings, None).unwrap();
    let json = r.report.to_json();
    assert_eq!(r.report.status, PlanStatus::Found, "{json}");
    assert!(r.report.locked_cores.is_empty(), "{json}");
    let b = &r.report.bearings[0];
    assert_eq!((b.rings, b.balls.len(), b.rolling_elements.as_str()), ([2, 3], 10, "rollers"), "{json}");
    let steps = &r.report.assembly_sequence;
    assert_eq!(steps.len(), 2, "the bearing and the shaft: {json}");
    let unit = steps.iter().find_map(|s| s.subassembly.as_ref()).expect("the bearing's step");
    assert_eq!((unit.status, unit.parts.len()), (SubassemblyStatus::Unit, 12), "{json}");
    let text = r.report.to_text();
    assert!(text.contains("rolling bearing: inner ring in outer ring, 10 rollers in 1 row"), "{text}");
    assert!(text.contains("roller radius"), "{text}");
    assert!(text.contains("a rolling bearing (rollers captive between two rings), one unit, not taken apart"), "{text}");
}

/// A housing under a fixed roof with a block that must leave along an L, out of the top the roof
/// covers: the search slides the two out from under the roof as one subassembly, whose own plan
/// tries straight lines only and cannot open it; planned as a model of its own (its base fixed),
/// the block comes out along its L, and the plan is `found` with the subassembly built part by
/// part.
#[test]
fn a_core_that_comes_apart_on_its_own_is_planned_as_a_model_of_its_own() {
    use asp_search::report::{PlanStatus, SubassemblyStatus};
    let mut a = asp_geom::fixtures::l_path();
    a.parts[0].fixed = false;
    let mut roof = asp_geom::fixtures::box_part("roof", [0.0, 0.0, 5.0], [5.0, 3.0, 5.5]);
    roof.fixed = true;
    a.parts.push(roof);
    // without the grid planner (which takes the voxel model apart by moves on its own)
    let settings = PlanSettings { timeout: Some(120.0), seed: 1, grid: false, ..PlanSettings::default() };
    let r = plan_assembly(a, &settings, None).unwrap();
    let json = r.report.to_json();
    assert_eq!(r.report.status, PlanStatus::Found, "{json}");
    assert!(r.report.locked_cores.is_empty() && r.report.grid.is_none(), "{json}");
    let steps = &r.report.assembly_sequence;
    assert_eq!(steps.len(), 1, "the housing and the block, slid in under the roof as one: {json}");
    let g = steps[0].subassembly.as_ref().expect("a subassembly step");
    assert_eq!((g.status, steps[0].name.as_str()), (SubassemblyStatus::Found, "housing"), "{json}");
    assert_eq!(g.assembly_sequence.len(), 1, "{json}");
    let block = &g.assembly_sequence[0];
    assert_eq!(block.name, "block");
    // not one straight line: a path, or a line after moves
    let straight = matches!(block.motion, asp_search::report::MotionEntry::Linear { .. }) && block.moves.is_empty();
    assert!(!straight, "the block goes in along its L: {json}");
}

/// End to end: two holed boards sunk 1.5 mm into each other, off the axes, at coarse
/// and fine tessellation, plan `found` with the upper board lifted along the slab's normal; the
/// plan lists the pair as a `planar_slab` 1.5 mm deep with its normal (the table says so too),
/// and a board stabbed 8 mm into another as `interpenetration`.
#[test]
fn boards_sunk_into_each_other_plan_found_lifted_along_the_slab_normal() {
    use asp_geom::overlap::OverlapClass;
    let turn = asp_geom::math::Rot::from_axis_angle(asp_geom::math::Vec3::new(1.0, 2.0, 0.5).normalize(), 0.3);
    let settings = PlanSettings { timeout: Some(60.0), ..PlanSettings::default() };
    for facets in [16, 96] {
        let r = plan_assembly(asp_geom::fixtures::sunk_boards(facets, 0.003, turn), &settings, None).unwrap();
        let json = r.report.to_json();
        assert!(r.found(), "{facets}: {json}");
        let pair = &r.report.overlaps.as_ref().expect("the boards overlap").pairs[0];
        assert_eq!(pair.class, Some(OverlapClass::PlanarSlab), "{json}");
        assert!((pair.depth - 0.0015).abs() <= 0.00015 && !pair.depth_bound, "{json}");
        let n = pair.normal.expect("a slab's normal");
        let up = turn * asp_geom::math::Vec3::Z;
        assert!(n[0] * up.x as f64 + n[1] * up.y as f64 + n[2] * up.z as f64 > 0.99999, "{json}");
        assert!(json.contains("\"class\": \"planar_slab\""), "{json}");
        assert_eq!(r.report.assembly_sequence.len(), 1, "{json}");
        let step = &r.report.assembly_sequence[0];
        assert_eq!(step.part, 1);
        match &step.motion {
            // in assembly order: the board goes in down along the normal
            asp_search::report::MotionEntry::Linear { direction, .. } => {
                let d: f64 = direction.iter().zip(n).map(|(a, b)| a * b).sum();
                assert!(d < -0.9999, "{json}");
            }
            m => panic!("{m:?}"),
        }
        let mut table = Vec::new();
        r.report.write_text(&mut table).unwrap();
        let table = String::from_utf8(table).unwrap();
        assert!(table.contains("a planar slab (normal"), "{table}");
    }
    let r = plan_assembly(asp_geom::fixtures::stabbed_board(16, turn), &settings, None).unwrap();
    let pair = &r.report.overlaps.as_ref().expect("the boards overlap").pairs[0];
    assert_eq!((pair.class, pair.normal), (Some(OverlapClass::Interpenetration), None), "{}", r.report.to_json());
}
