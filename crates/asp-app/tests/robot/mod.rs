//! The robot in the planners: the depth-first search with `--robot` and the optimiser with
//! `--objective robot-path`; every path of every plan re-checked independently; same seed and
//! thread count, same plan; held parts on the shared beam.

use std::sync::Arc;

use asp_app::pipeline::{plan_assembly, OptimiseSettings, PlanSettings, StabilitySetting};
use asp_geom::fixtures::{assemble, box_part};
use asp_geom::math::{Axis, Pose, Rot, Vec3};
use asp_geom::{Assembly, Grasp, PartSet, World, WorldConfig};
use asp_robot::{CellSetup, RobotCell, RobotExtension, RobotRemoval, RobotSetup};
use asp_search::report::PlanReport;

use asp_check::robot::recheck;

/// Four blocks on a fixed plate in front of the robot: two side by side, one on each.
fn blocks() -> Assembly {
    let mut plate = box_part("plate", [-0.1, -0.25, -0.02], [0.35, 0.25, 0.0]);
    plate.fixed = true;
    assemble(
        "blocks",
        vec![
            plate,
            box_part("a", [0.1, -0.12, 0.0], [0.14, -0.08, 0.04]),
            box_part("b", [0.1, 0.08, 0.0], [0.14, 0.12, 0.04]),
            box_part("a_top", [0.1, -0.12, 0.04], [0.14, -0.08, 0.08]),
            box_part("b_top", [0.1, 0.08, 0.04], [0.14, 0.12, 0.08]),
        ],
        Axis::Z,
    )
}

/// Every robot step of `report` re-checked against the parts present before it.
fn recheck_report(assembly: &Assembly, report: &PlanReport, setup: &RobotSetup) {
    let world = World::new(assembly.clone(), &WorldConfig::default()).unwrap();
    let cell: RobotCell = setup.cell(assembly);
    let robot = report.robot.as_ref().expect("a robot entry");
    assert_eq!(robot.joints.len(), cell.robot.dof());
    let mut state = PartSet::full(world.num_parts());
    let mut total = 0.0;
    let m = assembly.units.metres;
    for (k, &part) in report.disassembly_sequence.iter().enumerate() {
        let step = &report.assembly_sequence[report.assembly_sequence.len() - 1 - k];
        assert_eq!(step.part, part);
        let r = step.robot.as_ref().unwrap_or_else(|| panic!("step {k} (part {part}) has no robot path"));
        let g = r.grasp;
        let removal = RobotRemoval {
            grasp: Grasp {
                position: Vec3::new((g[0] * m) as f32, (g[1] * m) as f32, (g[2] * m) as f32),
                orientation: Rot::from_xyzw(g[3] as f32, g[4] as f32, g[5] as f32, g[6] as f32),
                width: (r.grasp_width * m) as f32,
            },
            grasp_index: 0,
            direction: Vec3::Z,
            joints: r.joint_trajectory.clone(),
            gripper_path: Vec::new(),
            length: r.path_length * m,
            reachable_grasps: 0,
        };
        recheck(&world, &cell, part, &state, &removal, 0.003).unwrap_or_else(|e| panic!("step {k} (part {part}): {e}"));
        // the trajectory starts at the grasp and ends at the drop-off
        let first: Pose = cell.robot.tool_pose(&r.joint_trajectory[0]);
        assert!((first.translation - removal.grasp.position).length() < 1e-3);
        let last = cell.robot.tool_pose(r.joint_trajectory.last().unwrap());
        assert!((last.translation - cell.drop_off).length() < 1e-3);
        total += r.path_length;
        state.remove(part);
    }
    assert!((total - robot.total_path_length).abs() < 1e-9);
}

fn without_times(report: &PlanReport) -> PlanReport {
    let mut r = report.clone();
    r.stats.seconds = 0.0;
    r.stats.timings = None;
    if let Some(o) = r.optimisation.as_mut() {
        o.map_seconds = 0.0;
        o.search_seconds = 0.0;
    }
    r
}

#[test]
fn depth_first_search_with_the_robot_plans_checked_paths_deterministically() {
    let setup = RobotSetup::panda();
    let settings = PlanSettings {
        checker_extension: Some(Arc::new(CellSetup { robot: Some(setup.clone()), grippers: 1 })),
        seed: 3,
        ..PlanSettings::default()
    };
    let a = plan_assembly(blocks(), &settings, None).unwrap();
    assert!(a.found(), "{:?}", a.report.explanation);
    // the tops come off before what they rest on
    let order = &a.report.disassembly_sequence;
    let pos = |p: usize| order.iter().position(|&q| q == p).unwrap();
    assert!(pos(3) < pos(1) && pos(4) < pos(2), "{order:?}");
    recheck_report(&blocks(), &a.report, &setup);
    let b = plan_assembly(blocks(), &settings, None).unwrap();
    assert_eq!(without_times(&a.report), without_times(&b.report));
}

#[test]
fn the_optimiser_minimises_the_robot_path_and_repeats_itself() {
    let setup = RobotSetup::panda();
    let optimise = |threads| OptimiseSettings {
        objectives: vec!["robot-path".into()],
        episodes: 3,
        budget: 2,
        threads: Some(threads),
        resolution: 5,
        extensions: vec![Arc::new(RobotExtension::new(setup.clone()))],
        ..OptimiseSettings::default()
    };
    for threads in [1, 2] {
        let settings = PlanSettings { seed: 5, optimise: Some(optimise(threads)), ..PlanSettings::default() };
        let a = plan_assembly(blocks(), &settings, None).unwrap();
        assert!(a.found());
        let o = a.report.optimisation.as_ref().unwrap();
        assert_eq!(o.objectives, vec!["robot-path".to_string()]);
        // the objective is minus the total path length in metres
        let total = a.report.robot.as_ref().unwrap().total_path_length;
        assert!((o.values[0] + total).abs() < 1e-6, "{} vs {total}", o.values[0]);
        recheck_report(&blocks(), &a.report, &setup);
        let b = plan_assembly(blocks(), &settings, None).unwrap();
        assert_eq!(without_times(&a.report), without_times(&b.report), "threads {threads}");
    }
}

/// A post on a fixed plate carries a bar, the bar a block (metres).
fn post_bar_block() -> Assembly {
    let mut plate = box_part("plate", [-0.3, -0.3, -0.02], [0.3, 0.3, 0.0]);
    plate.fixed = true;
    assemble(
        "held",
        vec![
            plate,
            box_part("post", [0.0, -0.02, 0.0], [0.04, 0.02, 0.1]),
            box_part("bar", [-0.1, -0.02, 0.1], [0.14, 0.02, 0.12]),
            box_part("block", [0.0, -0.02, 0.12], [0.04, 0.02, 0.16]),
        ],
        Axis::Z,
    )
}

/// A post on a fixed plate carries a bar, the bar a block. Taken in the given order (post
/// first), the post's removal leaves bar and block unsupported: refused with one gripper,
/// admitted with two when the bar is held (the block rests on it), and the plan says so.
#[test]
fn a_second_gripper_holds_the_bar_while_the_post_goes_in() {
    let model = post_bar_block;
    let one = plan_assembly(model(), &PlanSettings::default(), None).unwrap();
    assert!(one.found());
    assert_ne!(one.report.disassembly_sequence[0], 1, "the post cannot go first without holding");
    assert!(one.report.assembly_sequence.iter().all(|s| s.held.is_empty()));
    let settings = PlanSettings { checker_extension: Some(Arc::new(CellSetup { robot: None, grippers: 2 })), ..PlanSettings::default() };
    let two = plan_assembly(model(), &settings, None).unwrap();
    assert!(two.found());
    assert_eq!(two.report.disassembly_sequence[0], 1, "{:?}", two.report.disassembly_sequence);
    let last = two.report.assembly_sequence.last().unwrap();
    assert_eq!(last.part, 1);
    assert_eq!(last.held, vec![2], "the bar is held while the post goes in");
}

/// The shared beam (tests/data/beam, 5 parts, nothing fixed) falls apart under physics while
/// it is built part by part on the floor. With one gripper asp builds it as one subassembly on
/// its long beam; more grippers must never lose that plan (the holding checker passes group
/// removals through: with two grippers it used to find none), and with three (ASAP's default
/// `--max-gripper`) it is built part by part, two parts held where needed.
#[test]
fn the_beam_plans_under_physics_with_held_parts() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tests/data/beam/beam.glb");
    let base = PlanSettings { stability: StabilitySetting::Physics { threshold: 0.01 }, ..PlanSettings::default() };
    let with = |grippers: usize| {
        let settings = PlanSettings { checker_extension: Some(Arc::new(CellSetup { robot: None, grippers })), ..base.clone() };
        asp_app::pipeline::plan_file(&path, &settings, None).unwrap()
    };
    let one = asp_app::pipeline::plan_file(&path, &base, None).unwrap();
    assert!(one.found(), "{:?}", one.report.explanation);
    assert!(one.report.assembly_sequence.iter().any(|s| s.subassembly.is_some()), "one gripper needs a subassembly");
    let two = with(2);
    assert!(two.found(), "two grippers lost the plan one gripper finds: {:?}", two.report.explanation);
    let three = with(3);
    assert!(three.found(), "{:?}", three.report.explanation);
    let steps = &three.report.assembly_sequence;
    assert_eq!(steps.len(), 5, "part by part");
    assert!(steps.iter().all(|s| s.subassembly.is_none()));
    assert!(steps.iter().any(|s| s.held.len() == 2), "some step needs two held parts");
    let mut placed = Vec::new();
    for s in steps {
        assert!(s.held.len() <= 2);
        assert!(s.held.iter().all(|h| placed.contains(h)), "held parts are already in place: {s:?}");
        placed.push(s.part);
    }
    assert!(three.report.robot.is_none());
}

/// Four stacks of two blocks on a fixed plate in front of the robot.
fn stacks() -> Assembly {
    let mut plate = box_part("plate", [-0.1, -0.3, -0.02], [0.35, 0.3, 0.0]);
    plate.fixed = true;
    let mut parts = vec![plate];
    for (i, y) in [-0.18f32, -0.06, 0.06, 0.18].into_iter().enumerate() {
        parts.push(box_part(&format!("low{i}"), [0.1, y - 0.02, 0.0], [0.14, y + 0.02, 0.04]));
        parts.push(box_part(&format!("top{i}"), [0.1, y - 0.02, 0.04], [0.14, y + 0.02, 0.08]));
    }
    assemble("stacks", parts, Axis::Z)
}

/// One search of `stacks()` with the robot filter asked lazily or for every candidate: its
/// best sequence and value, the removals put to the filter, and the robot's path searches.
fn robot_search(lazy: bool) -> (Vec<usize>, f64, u64, u64) {
    use asp_app::pipeline::optimiser_problem;
    use asp_search::extension::{MdpExtension, ModelContext};
    use asp_search::Mcts;
    let assembly = Arc::new(stacks());
    let ext = Arc::new(RobotExtension::new(RobotSetup::panda()));
    let o = OptimiseSettings {
        objectives: vec!["robot-path".into()],
        resolution: 5,
        extensions: vec![ext.clone() as Arc<dyn MdpExtension>],
        ..OptimiseSettings::default()
    };
    let settings = PlanSettings { seed: 7, ..PlanSettings::default() };
    let problem = optimiser_problem(&assembly, &settings, &o).unwrap();
    let mdp = problem.mdp;
    let search = Mcts::builder().seed(7).episodes(1).budget(2).threads(1).lazy_filters(lazy).build().unwrap();
    let outcome = search.solve(&mdp).unwrap();
    let best = outcome.best().expect("a complete sequence").clone();
    // the answer replays: every step admitted by the robot again (expansion's k plans)
    mdp.evaluate(&best.sequence).unwrap();
    assert_eq!(best.sequence.len(), 8);
    let model = ext.model(&ModelContext { assembly: &assembly, maps: mdp.maps_arc(), seed: 7 }).unwrap();
    let plans = model.planner().stats().plans;
    (best.sequence, best.values[0], outcome.stats.filter_checks, plans)
}

#[test]
fn lazy_robot_rollouts_repeat_themselves_with_fewer_robot_plans() {
    let lazy = robot_search(true);
    assert_eq!(robot_search(true), lazy, "same seed, same threads: the same search");
    let eager = robot_search(false);
    // lazy rollouts ask the robot only until a drawn removal is admitted
    assert!(lazy.2 < eager.2, "filter checks lazy {} vs eager {}", lazy.2, eager.2);
    assert!(lazy.3 < eager.3, "robot path searches lazy {} vs eager {}", lazy.3, eager.3);
    assert!(lazy.1 < 0.0 && eager.1 < 0.0);
}

#[test]
fn the_robot_reuses_the_maps_world() {
    use asp_geom::distmap::{DistanceMaps, MapConfig};
    use asp_search::extension::ModelContext;
    // a mesh model: the maps build a collision world with the robot's settings, the robot takes it
    let assembly = Arc::new(asp_geom::fixtures::tube());
    let maps = Arc::new(DistanceMaps::build(&assembly, &MapConfig::builder().resolution(5).build().unwrap()).unwrap());
    let world = maps.world().expect("a mesh part: the maps built a world").clone();
    let ext = RobotExtension::new(RobotSetup::panda());
    let model = ext.model(&ModelContext { assembly: &assembly, maps: &maps, seed: 7 }).unwrap();
    assert!(std::ptr::eq(model.planner().world(), &*world), "one World per run");
    // boxes only: the maps keep no world, the robot builds its own
    let boxes = Arc::new(stacks());
    let maps = Arc::new(DistanceMaps::build(&boxes, &MapConfig::builder().resolution(5).build().unwrap()).unwrap());
    assert!(maps.world().is_none());
    let model = RobotExtension::new(RobotSetup::panda()).model(&ModelContext { assembly: &boxes, maps: &maps, seed: 7 }).unwrap();
    assert_eq!(model.planner().world().num_parts(), boxes.len());
}

/// A block near the robot, and a stack of two out of its reach (1.7 m from its base), all on a
/// fixed plate: every block lifts off freely, but the arm reaches only the near one.
fn near_and_far() -> Assembly {
    let mut plate = box_part("plate", [-0.1, -0.25, -0.02], [1.5, 0.25, 0.0]);
    plate.fixed = true;
    assemble(
        "near_and_far",
        vec![
            plate,
            box_part("near", [0.1, -0.02, 0.0], [0.14, 0.02, 0.04]),
            box_part("far_low", [1.28, -0.02, 0.0], [1.32, 0.02, 0.04]),
            box_part("far_top", [1.28, -0.02, 0.04], [1.32, 0.02, 0.08]),
        ],
        Axis::Z,
    )
}

fn robot_plan(setup: RobotSetup) -> PlanReport {
    let settings = PlanSettings {
        checker_extension: Some(Arc::new(CellSetup { robot: Some(setup), grippers: 1 })),
        seed: 3,
        ..PlanSettings::default()
    };
    plan_assembly(near_and_far(), &settings, None).unwrap().report
}

/// When the robot, not the geometry, keeps a part in, the
/// explanation gives the robot's reason and lists no parts as blockers; a part the geometry
/// holds (the low far block would leave the top one unsupported) keeps its own reason.
#[test]
fn the_explanation_names_the_robot_reason_not_parts_that_do_not_block() {
    use asp_search::report::{ExplanationReason, PlanStatus, RobotReason};
    let base = Vec3::new(-0.4, 0.0, 0.0);
    let report = robot_plan(RobotSetup { base: Some(base), ..RobotSetup::panda() });
    assert_eq!(report.status, PlanStatus::NoPlan, "{:?}", report.explanation);
    assert_eq!(report.disassembly_sequence, vec![1], "the near block comes off");
    let why = |name: &str| report.explanation.iter().find(|e| e.name == name).unwrap_or_else(|| panic!("{name}: {:?}", report.explanation));
    let top = why("far_top");
    assert_eq!(top.reason, ExplanationReason::Blocked);
    assert!(top.parts.is_empty(), "no part blocks it: {top:?}");
    let robot = top.robot.as_ref().expect("the robot's reason");
    assert_eq!(robot.reason, RobotReason::NoReachableGrasp);
    assert!(robot.detail.contains("out of reach"), "{}", robot.detail);
    let low = why("far_low");
    assert!(low.robot.is_none(), "the geometry holds it: {low:?}");
    assert_eq!(low.reason, ExplanationReason::Unsupported, "{low:?}");
    assert_eq!(low.parts.iter().map(|p| p.name.as_str()).collect::<Vec<_>>(), ["far_top"]);
    // the JSON and the text table say the same
    let json: serde_json::Value = serde_json::from_str(&report.to_json()).unwrap();
    let entry = json["explanation"].as_array().unwrap().iter().find(|e| e["name"] == "far_top").unwrap().clone();
    assert_eq!(entry["robot"]["reason"], "no_reachable_grasp", "{entry}");
    assert_eq!(entry["parts"], serde_json::json!([]));
    let text = report.to_text();
    let line = text.lines().find(|l| l.trim_start().starts_with("far_top")).unwrap_or_else(|| panic!("{text}"));
    assert!(line.contains("arm: no reachable grasp") && !line.contains("blocked by"), "{line}");

    // a drop-off out of reach: every block is reachable but none can be put down
    let report = robot_plan(RobotSetup { base: Some(base), drop_off: Some(Vec3::new(-3.0, 0.0, 0.4)), ..RobotSetup::panda() });
    assert_eq!(report.status, PlanStatus::NoPlan);
    assert!(report.disassembly_sequence.is_empty(), "{:?}", report.disassembly_sequence);
    let near = report.explanation.iter().find(|e| e.name == "near").unwrap();
    assert!(near.parts.is_empty(), "{near:?}");
    assert_eq!(near.robot.as_ref().map(|r| r.reason), Some(RobotReason::NoDropOff), "{near:?}");
}

/// `asp robot cell` says which parts the cell can take out on their own before
/// any search: the near block, not the two far ones (out of reach); with the drop-off out of
/// reach, none (no path). The same request gives the same answer.
#[test]
fn the_cell_check_names_the_parts_the_arm_cannot_take_out_alone() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("near_and_far.glb");
    asp_geom::io::write_glb(&near_and_far(), &path).unwrap();
    let request = asp_app::PlanRequest { robot_base: Some([-0.4, 0.0, 0.0]), seed: Some(3), ..Default::default() };
    let check = asp_app::cell::check_cell(&path, &request).unwrap();
    assert_eq!(check.robot, "panda", "the shipped arm by default");
    assert_eq!(check.base, [-0.4, 0.0, 0.0]);
    let outcome = |c: &asp_app::cell::CellCheck| c.parts.iter().map(|p| (p.name.clone(), p.outcome)).collect::<Vec<_>>();
    assert_eq!(
        outcome(&check),
        [("near".to_string(), "taken_out"), ("far_low".to_string(), "no_reachable_grasp"), ("far_top".to_string(), "no_reachable_grasp")]
    );
    let near = &check.parts[0];
    assert!(near.path_length.is_some_and(|l| l > 0.05) && near.lift == Some([0.0, 0.0, 1.0]), "{near:?}");
    assert!(check.parts[1].detail.as_deref().is_some_and(|d| d.contains("out of reach")), "{:?}", check.parts[1]);
    assert_eq!(asp_app::cell::check_cell(&path, &request).unwrap(), check, "the same request, the same answer");
    let far_drop = asp_app::PlanRequest { drop_off: Some([-3.0, 0.0, 0.4]), ..request };
    let check = asp_app::cell::check_cell(&path, &far_drop).unwrap();
    assert_eq!(check.parts[0].outcome, "no_path", "{:?}", check.parts[0]);
}

/// `asp bench feasible` runs under the robot checker too: with the arm, the
/// blocks out of its reach make every run fail and its refusals count as failed tests; without
/// it every run finds a plan.
#[test]
fn the_feasibility_bench_runs_under_the_robot_checker() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("near_and_far.glb");
    asp_geom::io::write_glb(&near_and_far(), &path).unwrap();
    let methods = asp_app::bench::parse_methods("vanilla,bk", None, asp_learn::Checker::Robot).unwrap();
    let plain = asp_app::bench::bench_model(&path, "nf", &PlanSettings::default(), &methods, 2).unwrap();
    assert!(plain.iter().all(|r| r.found == 2), "{plain:?}");
    let setup = RobotSetup { base: Some(Vec3::new(-0.4, 0.0, 0.0)), ..RobotSetup::panda() };
    let robot =
        PlanSettings { checker_extension: Some(Arc::new(CellSetup { robot: Some(setup), grippers: 1 })), ..PlanSettings::default() };
    let rows = asp_app::bench::bench_model(&path, "nf", &robot, &methods, 2).unwrap();
    assert!(rows.iter().all(|r| r.found == 0 && r.failed_collision.mean > 0.0), "{rows:?}");
}

/// `asp collect removability --robot` labels by the robot's checker: the near
/// block comes out; the far stack's top block is let out by the geometry but the arm reaches
/// none of its grasps (`arm_no_grasp`); the low one would leave the top one unsupported
/// (`gravity`). Every non-fixed part of a state is in exactly one list, the index says
/// `robot`, and a second collection writes the same files.
#[test]
fn removability_labels_are_collected_under_the_robot_with_the_arms_reasons() {
    use asp_app::collect::{collect, CollectSettings};
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("near_and_far.glb");
    asp_geom::io::write_glb(&near_and_far(), &path).unwrap();
    let plan = resolved(r#"{"robot": "panda", "robot_base": [-0.4, 0.0, 0.0]}"#);
    assert_eq!(plan.label_checker(), asp_learn::Checker::Robot);
    let settings = CollectSettings { runs: 2, seed: 4, plan, ..CollectSettings::default() };
    let out = dir.path().join("rem");
    let index = collect(std::slice::from_ref(&path), &out, &settings, &|_| {}).unwrap();
    assert_eq!(index.checker, "robot");
    let text = std::fs::read_to_string(out.join("near_and_far").join("states.jsonl")).unwrap();
    let lines: Vec<serde_json::Value> = text.lines().map(|l| serde_json::from_str(l).unwrap()).collect();
    let parts = |l: &serde_json::Value, key: &str| -> Vec<usize> {
        l[key].as_array().unwrap_or_else(|| panic!("no '{key}' in {l}")).iter().map(|v| v.as_u64().unwrap() as usize).collect()
    };
    let full = lines.iter().find(|l| parts(l, "present") == [0, 1, 2, 3]).expect("the assembled state is recorded");
    assert_eq!(parts(full, "removable"), [1], "{full}");
    assert_eq!(parts(full, "gravity"), [2], "{full}");
    assert_eq!(parts(full, "arm_no_grasp"), [3], "{full}");
    assert!(parts(full, "collision").is_empty() && parts(full, "arm_blocked").is_empty() && parts(full, "arm_no_path").is_empty());
    for l in &lines {
        let mut labelled: Vec<usize> =
            ["removable", "collision", "gravity", "arm_blocked", "arm_no_grasp", "arm_no_path"].iter().flat_map(|k| parts(l, k)).collect();
        labelled.sort();
        assert_eq!(labelled, parts(l, "present").into_iter().filter(|&p| p != 0).collect::<Vec<_>>(), "every part once: {l}");
    }
    let again = dir.path().join("again");
    collect(std::slice::from_ref(&path), &again, &settings, &|_| {}).unwrap();
    assert_eq!(std::fs::read_to_string(again.join("near_and_far").join("states.jsonl")).unwrap(), text, "deterministic");
}

/// The `robot-path` Q model fixture (`python -m asp.train.fixture --only q`: features `asp-q/1
/// directions=25 neighbours=8`, for maps of resolution 5).
fn robot_q_fixture() -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../asp-learn/tests/data/random_q_robot-path.onnx")
}

/// The settings of a plan request given as JSON (the CLI's and Python's way in).
fn resolved(json: &str) -> PlanSettings {
    asp_app::resolve(&asp_app::PlanRequest::from_json(json).unwrap()).unwrap()
}

/// `asp collect transitions --robot panda --objective robot-path` records robot
/// MCTS with the robot-path rewards, and its index rebuilds the same problem (robot included),
/// as Python's `Assembly.q_graphs(**maps)` does.
#[test]
fn transitions_are_collected_under_the_robot_with_robot_path_rewards() {
    use asp_app::collect_q::{collect_transitions, TransitionSettings};
    let dir = tempfile::tempdir().unwrap();
    let model = dir.path().join("blocks.glb");
    asp_geom::io::write_glb(&blocks(), &model).unwrap();
    let mut plan = resolved(
        r#"{"objective": "robot-path", "robot": "panda", "drop_off": [0.1, 0.45, 0.3], "episodes": 2, "budget": 2, "resolution": 5}"#,
    );
    let optimise = plan.optimise.take().unwrap();
    let settings = TransitionSettings { seed: 1, plan, optimise, ..TransitionSettings::default() };
    let out = dir.path().join("q");
    let index = collect_transitions(std::slice::from_ref(&model), &out, &settings, &|_| {}).unwrap();
    assert_eq!(index.objectives, ["robot-path"]);
    let entry = &index.assemblies[0];
    assert_eq!(entry.reward_ranges, [[-20.0, 0.0]]);
    assert_eq!((entry.removable, entry.episodes_run), (4, 2));
    let json: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(out.join("index.json")).unwrap()).unwrap();
    let maps = &json["assemblies"][0]["maps"];
    assert_eq!(
        *maps,
        serde_json::json!({"objective": "robot-path", "resolution": 5, "d_max": null, "support": "below", "tolerance": null,
                           "contact_distance": null, "overlaps": "strict", "robot": "panda", "drop_off": [0.1, 0.45, 0.3]})
    );
    // every step is one the robot did: minus its path length, within the range
    let text = std::fs::read_to_string(out.join(&entry.dir).join("transitions.jsonl")).unwrap();
    let lines: Vec<serde_json::Value> = text.lines().map(|l| serde_json::from_str(l).unwrap()).collect();
    assert_eq!(lines.len(), entry.transitions);
    assert!(lines.iter().any(|l| l["kind"] == "expansion") && lines.iter().any(|l| l["complete"] == true));
    for l in &lines {
        let r = l["rewards"][0].as_f64().unwrap();
        assert!(r < 0.0 && r > -20.0, "{l}");
        // the learner's contract: the action taken is one of the state's admitted actions
        assert!(l["actions"].as_array().unwrap().contains(&l["action"]), "{l}");
    }
    // the maps' keywords (plus what `q_graphs` adds) resolve to the same problem, robot included
    let mut request = maps.as_object().unwrap().clone();
    request.insert("pareto".into(), true.into());
    let mut again = asp_app::resolve(&asp_app::PlanRequest::from_value(serde_json::Value::Object(request)).unwrap()).unwrap();
    let o = again.optimise.take().unwrap();
    assert_eq!(o.extensions.len(), 1);
    let assembly = Arc::new(asp_app::pipeline::load(&model, &again).unwrap());
    let p = asp_app::pipeline::optimiser_problem(&assembly, &again, &o).unwrap().mdp;
    assert_eq!(p.objective_names(), ["robot-path"]);
    assert_eq!(asp_search::qgraph::QGraphConfig::for_maps(p.maps()).features(), index.features);
}

/// The optimiser under the robot guided by a `robot-path` Q model (ε-greedy
/// rollouts, Q-ordered expansions): a plan whose paths re-check, the same for the same seed, and
/// not the vanilla search's (greedy rollouts and expansions take other removals).
#[test]
fn the_optimiser_under_the_robot_is_guided_by_a_robot_path_q_model() {
    let q = robot_q_fixture();
    let base = r#""objective": "robot-path", "robot": "panda", "episodes": 2, "budget": 2, "resolution": 5, "threads": 1, "seed": 4"#;
    let vanilla = plan_assembly(blocks(), &resolved(&format!("{{{base}}}")), None).unwrap();
    let guided = resolved(&format!(r#"{{{base}, "q": {q:?}, "q_use": "both", "epsilon": 0}}"#));
    assert_eq!(guided.optimise.as_ref().unwrap().policy.as_ref().unwrap().name(), "q");
    let a = plan_assembly(blocks(), &guided, None).unwrap();
    assert!(a.found(), "{:?}", a.report.explanation);
    recheck_report(&blocks(), &a.report, &RobotSetup::panda());
    let b = plan_assembly(blocks(), &guided, None).unwrap();
    assert_eq!(without_times(&a.report), without_times(&b.report));
    assert_ne!(without_times(&a.report), without_times(&vanilla.report));
}

/// A Q model of another objective is refused before the search, naming the file
/// and both objectives; so is the robot-path model for another objective.
#[test]
fn a_q_model_of_another_objective_is_refused_under_the_robot() {
    let access = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../asp-learn/tests/data/random_q_access.onnx");
    for (objective, q, estimates) in [("robot-path", access, "access"), ("access", robot_q_fixture(), "robot-path")] {
        let json = format!(r#"{{"objective": "{objective}", "robot": "panda", "episodes": 1, "resolution": 5, "q": {q:?}}}"#);
        let e = plan_assembly(blocks(), &resolved(&json), None).unwrap_err().to_string();
        assert!(e.starts_with("q: ") && e.contains(q.file_name().unwrap().to_str().unwrap()), "{e}");
        assert!(e.contains(&format!("estimates objective '{estimates}'")) && e.contains(&format!("that of '{objective}'")), "{e}");
    }
}

/// `asp check --robot`: a sequence the arm can carry out is feasible with every step's grasp and
/// path, each re-checked on the exact geometry; a cube too wide for the gripper, free to go in,
/// fails with the robot's reason, and no order of the same steps is feasible.
#[test]
fn check_with_the_robot_carries_out_every_step_or_says_why_not() {
    use asp_app::check::{check_assembly, parse_sequence, CheckStatus, Failure, RepairStatus};
    let setup = RobotSetup::panda();
    let settings = PlanSettings {
        checker_extension: Some(Arc::new(CellSetup { robot: Some(setup.clone()), grippers: 1 })),
        seed: 3,
        ..PlanSettings::default()
    };
    let r = check_assembly(blocks(), &parse_sequence("a\nb\na_top\nb_top\n").unwrap(), &settings).unwrap();
    assert_eq!(r.status, CheckStatus::Feasible, "{}", r.to_text());
    assert_eq!(r.robot.as_ref().map(|e| e.name.as_str()), Some(setup.robot.name.as_str()));
    assert!(r.to_text().contains("robot path"), "{}", r.to_text());
    // each step's arm path, in disassembly order, against the parts present before it
    let world = World::new(blocks(), &WorldConfig::default()).unwrap();
    let cell: RobotCell = setup.cell(&blocks());
    let mut state = PartSet::full(world.num_parts());
    for s in r.steps.iter().rev() {
        let part = s.parts[0].part;
        let e = s.robot.as_ref().unwrap_or_else(|| panic!("step {} has no robot path", s.step));
        let g = e.grasp;
        let removal = RobotRemoval {
            grasp: Grasp {
                position: Vec3::new(g[0] as f32, g[1] as f32, g[2] as f32),
                orientation: Rot::from_xyzw(g[3] as f32, g[4] as f32, g[5] as f32, g[6] as f32),
                width: e.grasp_width as f32,
            },
            grasp_index: 0,
            direction: Vec3::Z,
            joints: e.joint_trajectory.clone(),
            gripper_path: Vec::new(),
            length: e.path_length,
            reachable_grasps: 0,
        };
        recheck(&world, &cell, part, &state, &removal, 0.003).unwrap_or_else(|err| panic!("step {}: {err}", s.step));
        state.remove(part);
    }
    // without the robot the same check has no robot entries
    let plain = check_assembly(blocks(), &parse_sequence("a\nb\na_top\nb_top\n").unwrap(), &PlanSettings::default()).unwrap();
    assert!(plain.robot.is_none() && plain.steps.iter().all(|s| s.robot.is_none()));

    // a 15 cm cube: nothing stops it going in from above, but no grasp fits the gripper
    let mut parts = blocks().parts;
    parts.push(box_part("crate", [0.18, -0.075, 0.0], [0.33, 0.075, 0.15]));
    let wide = assemble("wide", parts, Axis::Z);
    let text = "a\nb\ncrate -z\na_top\nb_top\n";
    let geometry = check_assembly(wide.clone(), &parse_sequence(text).unwrap(), &PlanSettings::default()).unwrap();
    assert_eq!(geometry.status, CheckStatus::Feasible, "{}", geometry.to_text());
    let r = check_assembly(wide, &parse_sequence(text).unwrap(), &settings).unwrap();
    assert_eq!(r.status, CheckStatus::Infeasible, "{}", r.to_text());
    let k = r.first_failure.unwrap();
    assert_eq!(r.steps[k].parts[0].name, "crate", "{}", r.to_text());
    let Some(Failure::Robot { robot_reason, .. }) = &r.steps[k].failure else { panic!("{:?}", r.steps[k].failure) };
    assert_eq!(robot_reason, "no reachable grasp");
    assert!(r.to_text().contains("but the robot cannot: no reachable grasp"), "{}", r.to_text());
    assert_eq!(r.repair.as_ref().unwrap().status, RepairStatus::None, "no order lets the arm carry the crate");
}

/// `asp check --grippers 2`: bar, block, then the post under them stands only while the bar is
/// held; with one gripper the block's step is the first that does not stand.
#[test]
fn check_with_two_grippers_names_the_held_part() {
    use asp_app::check::{check_assembly, parse_sequence, CheckStatus, Failure};
    let model = post_bar_block;
    let text = "bar\nblock\npost\n";
    let one = check_assembly(model(), &parse_sequence(text).unwrap(), &PlanSettings::default()).unwrap();
    assert_eq!(one.status, CheckStatus::Infeasible);
    assert_eq!(one.first_failure, Some(1), "{}", one.to_text());
    assert!(matches!(one.steps[1].failure, Some(Failure::Unstable { .. })), "{}", one.to_text());
    let settings = PlanSettings { checker_extension: Some(Arc::new(CellSetup { robot: None, grippers: 2 })), ..PlanSettings::default() };
    let two = check_assembly(model(), &parse_sequence(text).unwrap(), &settings).unwrap();
    assert_eq!(two.status, CheckStatus::Feasible, "{}", two.to_text());
    let held: Vec<&str> = two.steps[2].held.iter().map(|p| p.name.as_str()).collect();
    assert_eq!(held, ["bar"], "{}", two.to_text());
    assert!(two.to_text().contains("holding bar"), "{}", two.to_text());
}

/// Held-out double-layer assembly 17 of `asp gen profiles --preset double-layer --count 20
/// --seed 900 --connectors attached` (its seed from that run's manifest). Its profiles' metadata
/// grasps close across the four long sides only; with those alone the robot refused removals
/// the geometry allows and the search ran out of its time (at 60 s, `budget_exhausted`). With
/// grasps on every pair of parallel faces (the connectors' faces, the profile with its
/// connector's wall) it plans, every path re-checked, and some steps hold a part by faces its
/// metadata has no grasp on.
#[test]
fn a_double_layer_assembly_plans_with_grasps_on_faces_its_metadata_lacks() {
    let params = asp_gen::ProfileParams { connectors: asp_gen::ConnectorMode::Attached, ..asp_gen::ProfileParams::double_layer() };
    let assembly = asp_gen::ProfileAssembly::generate(&params, 242_557_999_537_143_880).unwrap().to_assembly("profiles_017");
    let setup = RobotSetup::panda();
    let settings = PlanSettings {
        checker_extension: Some(Arc::new(CellSetup { robot: Some(setup.clone()), grippers: 1 })),
        timeout: Some(30.0),
        ..PlanSettings::default()
    };
    let plan = plan_assembly(assembly.clone(), &settings, None).unwrap();
    assert!(plan.found(), "{:?} {:?}", plan.report.status, plan.report.explanation);
    recheck_report(&assembly, &plan.report, &setup);
    // steps whose grasp is none of the part's metadata grasps
    let off_metadata = plan
        .report
        .assembly_sequence
        .iter()
        .filter(|s| {
            let g = s.robot.as_ref().unwrap().grasp;
            let at = Vec3::new(g[0] as f32, g[1] as f32, g[2] as f32);
            let rot = Rot::from_xyzw(g[3] as f32, g[4] as f32, g[5] as f32, g[6] as f32);
            !assembly.parts[s.part].meta.grasps.iter().any(|m| (m.position - at).length() < 1e-4 && m.orientation.angle_between(rot) < 1e-3)
        })
        .count();
    assert!(off_metadata > 0, "every step held its part by a metadata grasp");
}

/// A block walled in by fixed walls 5 mm away: the geometry lets it out (up), the robot finds
/// no grasp. The dead end's explanation names what the gripper meets (the walls, by name),
/// and says a second gripper would not change it.
#[test]
fn a_refused_part_explanation_names_the_parts_its_grasps_meet() {
    use asp_search::report::RobotReason;
    let walled = asp_geom::fixtures::walled_block();
    let setup = RobotSetup { base: Some(Vec3::new(-0.35, 0.0, -0.02)), ..RobotSetup::panda() };
    let settings =
        PlanSettings { checker_extension: Some(Arc::new(CellSetup { robot: Some(setup), grippers: 1 })), ..PlanSettings::default() };
    let report = plan_assembly(walled, &settings, None).unwrap().report;
    let block = report.explanation.iter().find(|e| e.name == "block").unwrap_or_else(|| panic!("{:?}", report.explanation));
    let robot = block.robot.as_ref().expect("the robot's reason");
    assert_eq!(robot.reason, RobotReason::NoReachableGrasp);
    assert!(robot.detail.contains("the gripper alone collides at") && robot.detail.contains("'wall_"), "{}", robot.detail);
    assert!(robot.detail.contains("--grippers 2"), "{}", robot.detail);
    assert!(!robot.detail.contains("'block'"), "{}", robot.detail);
}
