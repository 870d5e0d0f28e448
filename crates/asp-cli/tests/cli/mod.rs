//! `asp plan` end to end: exit codes, output files, determinism and bad input.

use asp_geom::io::write_glb;
use asp_geom::{fixtures, Assembly};
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn asp(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_asp")).args(args).output().expect("asp runs")
}

fn data(rel: &str) -> String {
    format!("{}/../../tests/data/{rel}", env!("CARGO_MANIFEST_DIR"))
}

fn fixture_file(dir: &Path, a: &Assembly, name: &str) -> PathBuf {
    let path = dir.join(name);
    write_glb(a, &path).expect("write fixture");
    path
}

fn json(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

#[test]
fn plans_a_fixture_prints_a_table_and_writes_the_json() {
    let dir = tempfile::tempdir().unwrap();
    let model = fixture_file(dir.path(), &fixtures::tube(), "tube.glb");
    let out = dir.path().join("plan.json");
    let o = asp(&["plan", model.to_str().unwrap(), "--out", out.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let table = String::from_utf8(o.stdout).unwrap();
    assert!(table.contains("found"), "{table}");
    assert!(table.contains("stick") && table.contains("handle") && table.contains("cap"), "{table}");
    let plan = json(&out);
    assert_eq!(plan["format_version"], "1.15");
    assert_eq!(plan["stats"]["checker"], "collision_world");
    assert_eq!(plan["status"], "found");
    assert_eq!(plan["up"], "+z");
    assert_eq!(plan["parts"].as_array().unwrap().len(), 4);
    assert_eq!(plan["assembly_sequence"].as_array().unwrap().len(), 3);
    assert_eq!(plan["assembly_sequence"][0]["motion"]["kind"], "linear");
    assert!(plan["stats"]["removal_tests"].as_u64().unwrap() >= 3);
}

#[test]
fn same_input_and_seed_give_identical_json_apart_from_seconds() {
    let dir = tempfile::tempdir().unwrap();
    let model = fixture_file(dir.path(), &fixtures::arch(), "arch.glb");
    let run = |k: usize| {
        let out = dir.path().join(format!("p{k}.json"));
        let o = asp(&["plan", model.to_str().unwrap(), "--order", "random", "--seed", "4", "--out", out.to_str().unwrap()]);
        assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
        let mut v = json(&out);
        v["stats"]["seconds"] = serde_json::Value::Null;
        v["stats"]["timings"] = serde_json::Value::Null;
        serde_json::to_string(&v).unwrap()
    };
    assert_eq!(run(1), run(2));
}

#[test]
fn no_plan_exits_1_and_explains() {
    let dir = tempfile::tempdir().unwrap();
    let model = fixture_file(dir.path(), &fixtures::l_path(), "l.glb");
    let out = dir.path().join("plan.json");
    let o = asp(&["plan", model.to_str().unwrap(), "--no-path-planner", "--no-grid", "--out", out.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    let table = String::from_utf8(o.stdout).unwrap();
    assert!(table.contains("block") && table.contains("blocked by housing"), "{table}");
    let plan = json(&out);
    assert_eq!(plan["status"], "no_plan");
    assert_eq!(plan["explanation"][0]["name"], "block");
    assert_eq!(plan["explanation"][0]["parts"][0]["name"], "housing");
    // with the path planner (and no grid) it is found, along a path
    let o = asp(&["plan", model.to_str().unwrap(), "--no-grid", "--json"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let plan: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(plan["assembly_sequence"][0]["motion"]["kind"], "path");
    assert_eq!(plan["stats"]["path_planner_calls"], 1);
    // the housing and block are a voxel model: the grid search finds the L (a move along +x,
    // then out along +z) once straight lines give up, before the path planner,
    // and without it the same
    for flags in [&[][..], &["--no-path-planner"][..]] {
        let mut args = vec!["plan", model.to_str().unwrap(), "--json"];
        args.extend_from_slice(flags);
        let o = asp(&args);
        assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
        let plan: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
        assert_eq!(plan["grid"]["reason"], "fallback", "{flags:?}");
        assert_eq!(plan["stats"]["path_planner_calls"], 0, "{flags:?}");
        assert_eq!(plan["assembly_sequence"][0]["moves"].as_array().unwrap().len(), 1, "{flags:?}");
    }
}

/// A block near the robot and one 1.7 m from its base at `--robot-base=-0.4,0,0`, on a fixed
/// plate, written to `dir/reach.glb`.
fn reach_model(dir: &Path) -> PathBuf {
    let mut plate = fixtures::box_part("plate", [-0.1, -0.25, -0.02], [1.5, 0.25, 0.0]);
    plate.fixed = true;
    let near = fixtures::box_part("near", [0.1, -0.02, 0.0], [0.14, 0.02, 0.04]);
    let far = fixtures::box_part("far", [1.28, -0.02, 0.0], [1.32, 0.02, 0.04]);
    fixture_file(dir, &fixtures::assemble("reach", vec![plate, near, far], asp_geom::math::Axis::Z), "reach.glb")
}

/// With `--robot`, a part the geometry lets out but the arm
/// cannot take out is explained by the arm's reason, not "blocked by" parts that do not block
/// it: a block out of reach of the base `--robot-base` puts (no reachable grasp), and the L's
/// block, which leaves its housing only along a path: the arm now lifts path motions too (up
/// when free), so what stops it is the grasp: the block is wider than the gripper opens.
#[test]
fn a_robot_refusal_is_explained_by_the_arms_reason() {
    let dir = tempfile::tempdir().unwrap();
    let model = reach_model(dir.path());
    let out = dir.path().join("reach.json");
    let o = asp(&["plan", model.to_str().unwrap(), "--robot", "panda", "--robot-base=-0.4,0,0", "--out", out.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    let table = String::from_utf8(o.stdout).unwrap();
    let line = table.lines().find(|l| l.trim_start().starts_with("far ")).unwrap_or_else(|| panic!("{table}"));
    assert!(line.contains("arm: no reachable grasp (of ") && !line.contains("blocked by"), "{table}");
    let plan = json(&out);
    assert_eq!(plan["status"], "no_plan");
    assert_eq!(plan["disassembly_sequence"], serde_json::json!([1]), "the near block comes off");
    let why = &plan["explanation"][0];
    assert_eq!((&why["name"], &why["reason"], &why["parts"]), (&"far".into(), &"blocked".into(), &serde_json::json!([])), "{why}");
    assert_eq!(why["robot"]["reason"], "no_reachable_grasp", "{why}");

    let model = fixture_file(dir.path(), &fixtures::l_path(), "l.glb");
    let o = asp(&["plan", model.to_str().unwrap(), "--robot", "panda", "--json"]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    let plan: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let why = &plan["explanation"][0];
    assert_eq!((&why["name"], &why["parts"]), (&"block".into(), &serde_json::json!([])), "{why}");
    assert_eq!(
        (&why["robot"]["reason"], &why["robot"]["detail"]),
        (&"no_reachable_grasp".into(), &"no grasp fits the gripper".into()),
        "{why}"
    );
}

/// `asp robot cell` names, before any search, the parts the cell cannot take
/// out even on their own (exit 1), with the arm's reason; `--json -` prints the check; a bad
/// robot base is a one-line error naming its flag (exit 2).
#[test]
fn the_robot_cell_check_names_what_the_arm_cannot_reach() {
    let dir = tempfile::tempdir().unwrap();
    let model = reach_model(dir.path());
    let m = model.to_str().unwrap();
    let o = asp(&["robot", "cell", m, "--robot-base=-0.4,0,0"]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    let table = String::from_utf8(o.stdout).unwrap();
    let line = |name: &str| table.lines().find(|l| l.starts_with(name)).unwrap_or_else(|| panic!("{table}")).to_string();
    assert!(line("near ").contains("taken out, path"), "{table}");
    assert!(line("far ").contains("no reachable grasp") && line("far ").contains("out of reach"), "{table}");
    assert!(table.contains("cannot take 1 of 2 movable parts out even on their own: far"), "{table}");
    let o = asp(&["robot", "cell", m, "--robot-base=-0.4,0,0", "--json", "-"]);
    let text = String::from_utf8(o.stdout).unwrap();
    let check: serde_json::Value = serde_json::from_str(&text[text.find("\n{").unwrap() + 1..]).unwrap();
    assert_eq!(check["parts"][1]["outcome"], "no_reachable_grasp", "{check}");
    let o = asp(&["robot", "cell", m, "--robot-base=1,2"]);
    assert_eq!(o.status.code(), Some(2));
    let err = stderr(&o);
    assert!(err.contains("--robot-base") && err.trim().lines().count() == 1, "{err}");
}

/// Asserts a one-line error naming `needle`, exit code 2, no panic.
fn assert_error(o: &Output, needle: &str) {
    let err = stderr(o);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.starts_with("error: ") && err.trim_end().lines().count() == 1, "{err}");
    assert!(err.contains(needle), "{needle:?} not in {err}");
    assert!(!err.contains("panicked"), "{err}");
}

#[test]
fn bad_input_is_one_line_naming_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let missing = dir.path().join("missing.glb");
    assert_error(&asp(&["plan", missing.to_str().unwrap()]), "missing.glb");
    let truncated = dir.path().join("truncated.glb");
    let good = std::fs::read(data("beam/beam.glb")).unwrap();
    std::fs::write(&truncated, &good[..good.len() / 3]).unwrap();
    assert_error(&asp(&["plan", truncated.to_str().unwrap()]), "truncated.glb");
    let garbage = dir.path().join("garbage.glb");
    std::fs::write(&garbage, b"glTF\x02\x00\x00\x00this is not a model").unwrap();
    assert_error(&asp(&["plan", garbage.to_str().unwrap()]), "garbage.glb");
    let beam = data("beam/beam.glb");
    assert_error(&asp(&["plan", &beam, "--up", "w"]), "--up");
    assert_error(&asp(&["plan", &beam, "--unit", "furlongs"]), "--unit");
    assert_error(&asp(&["plan", &beam, "--fixed", "no_such_part"]), "no_such_part");
    assert_error(&asp(&["plan", &beam, "--tolerance=-1"]), "--tolerance");
}

#[test]
fn parts_overlapping_far_beyond_the_tolerance_leave_along_the_overlap_or_are_an_error_when_asked() {
    let dir = tempfile::tempdir().unwrap();
    let mut a = fixtures::stacked_boxes();
    // push the top box half-way into the lower one
    for v in &mut a.parts[2].mesh.vertices {
        v.z -= 0.5;
    }
    let model = fixture_file(dir.path(), &a, "overlap.glb");
    let o = asp(&["plan", model.to_str().unwrap(), "--overlaps", "error"]);
    assert_error(&o, "overlap");
    assert!(stderr(&o).contains("'lower'") && stderr(&o).contains("'top'"), "{}", stderr(&o));
    // the default (strict) plans it, warns naming the pair, and the top leaves straight up
    // (out of the material it already overlaps), never sideways through the lower box
    let o = asp(&["plan", model.to_str().unwrap(), "--json"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let err = stderr(&o);
    assert!(err.contains("warning") && err.contains("'lower' and 'top' overlap"), "{err}");
    let plan: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let top_index = plan["parts"].as_array().unwrap().iter().find(|p| p["name"] == "top").expect("a part 'top'")["index"].clone();
    let top = plan["assembly_sequence"].as_array().unwrap().iter().find(|s| s["part"] == top_index).expect("the top box is in the plan");
    let d = &top["motion"]["direction"];
    let (x, y, z) = (d[0].as_f64().unwrap(), d[1].as_f64().unwrap(), d[2].as_f64().unwrap());
    assert!(x.abs() < 1e-6 && y.abs() < 1e-6 && z.abs() > 0.99, "top moves along z only: {d}");
}

#[test]
fn small_overlaps_and_open_meshes_are_warnings_naming_the_parts() {
    let dir = tempfile::tempdir().unwrap();
    let mut a = fixtures::stacked_boxes();
    for v in &mut a.parts[2].mesh.vertices {
        v.z -= 0.01; // a press fit: 10 × the default tolerance, far below the error limit
    }
    a.parts[1].mesh.triangles.pop(); // a hole in the lower box
    let model = fixture_file(dir.path(), &a, "warn.glb");
    let o = asp(&["plan", model.to_str().unwrap()]);
    let err = stderr(&o);
    assert!(err.contains("warning") && err.contains("'lower' and 'top' overlap"), "{err}");
    assert!(err.contains("part 'lower': mesh is not closed"), "{err}");
    assert!(!err.contains("panicked"), "{err}");
}

#[test]
fn a_single_part_plans_trivially() {
    let dir = tempfile::tempdir().unwrap();
    let mut a = fixtures::stacked_boxes();
    a.parts.truncate(2);
    a.parts[0].fixed = false;
    a.parts.remove(0);
    let model = fixture_file(dir.path(), &a, "single.glb");
    let o = asp(&["plan", model.to_str().unwrap(), "--json"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let plan: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(plan["assembly_sequence"].as_array().unwrap().len(), 1);
}

#[test]
fn physics_stability_takes_the_keystone_before_a_pillar() {
    let dir = tempfile::tempdir().unwrap();
    let model = fixture_file(dir.path(), &fixtures::arch(), "arch.glb");
    let order = |extra: &[&str]| {
        let mut args = vec!["plan", model.to_str().unwrap(), "--json"];
        args.extend_from_slice(extra);
        let o = asp(&args);
        assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
        let plan: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
        plan["disassembly_sequence"].as_array().unwrap().iter().map(|v| v.as_u64().unwrap()).collect::<Vec<_>>()
    };
    // contact graph: a pillar may go first (the keystone still touches the other one)
    assert_eq!(order(&[]), vec![1, 3, 2]);
    // physics: a keystone on one pillar tips over, so it must leave first
    assert_eq!(order(&["--stability", "physics", "--order", "given"]), vec![3, 1, 2]);
    // the default under physics (`auto`: gnn with bookkeeping) ranks the pillars its own way
    assert_eq!(order(&["--stability", "physics"])[0], 3);
}

/// The default ordering (`auto`) is the learned ordering with bookkeeping under
/// `--stability physics`, decided from the checker and not from a clock: the same seed gives
/// the same plan and the same tests, twice, as `--order gnn --bookkeeping` does.
#[test]
fn the_default_ordering_under_physics_is_gnn_with_bookkeeping_and_repeats() {
    let dir = tempfile::tempdir().unwrap();
    let model = fixture_file(dir.path(), &fixtures::figure_6_2(1.0), "fig.glb");
    let run = |extra: &[&str]| {
        let mut args = vec!["plan", model.to_str().unwrap(), "--json", "--stability", "physics", "--seed", "5"];
        args.extend_from_slice(extra);
        let o = asp(&args);
        assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
        let plan: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
        (plan["disassembly_sequence"].clone(), plan["stats"]["removal_tests"].clone())
    };
    let auto = run(&[]);
    assert_eq!(run(&["--order", "auto"]), auto);
    assert_eq!(run(&[]), auto, "the same seed gives the same plan");
    assert_eq!(run(&["--order", "gnn", "--bookkeeping"]), auto);
}

/// Under `--robot` the default ordering is also the learned one with bookkeeping (the
/// robot checker's shipped model): the same plan and tests as `--order gnn --bookkeeping`, twice
/// for a seed, and fewer tests than the file's order, which tries the bottom of a stack first.
#[test]
fn the_default_ordering_under_the_robot_is_gnn_with_bookkeeping_and_repeats() {
    let dir = tempfile::tempdir().unwrap();
    let mut plate = fixtures::box_part("plate", [-0.1, -0.25, -0.02], [0.5, 0.25, 0.0]);
    plate.fixed = true;
    let bottom = fixtures::box_part("bottom", [0.1, -0.02, 0.0], [0.14, 0.02, 0.04]);
    let top = fixtures::box_part("top", [0.1, -0.02, 0.04], [0.14, 0.02, 0.08]);
    let side = fixtures::box_part("side", [0.1, 0.1, 0.0], [0.14, 0.14, 0.04]);
    let parts = vec![plate, bottom, top, side];
    let model = fixture_file(dir.path(), &fixtures::assemble("stack", parts, asp_geom::math::Axis::Z), "stack.glb");
    let run = |extra: &[&str]| {
        let mut args = vec!["plan", model.to_str().unwrap(), "--json", "--robot", "panda", "--robot-base=-0.4,0,0", "--seed", "3"];
        args.extend_from_slice(extra);
        let o = asp(&args);
        assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
        let plan: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
        (plan["disassembly_sequence"].clone(), plan["stats"]["removal_tests"].as_u64().unwrap())
    };
    let auto = run(&[]);
    assert_eq!(run(&[]), auto, "the same seed gives the same plan");
    assert_eq!(run(&["--order", "gnn", "--bookkeeping"]), auto);
    let given = run(&["--order", "given"]);
    assert!(given.1 > auto.1, "given {given:?}, auto {auto:?}");
}

#[test]
fn ctrl_c_prints_and_writes_the_best_result_so_far() {
    // cube81 one piece at a time: every piece is blocked, and the path planner is tried on each
    // of the 81 in turn (many seconds); Ctrl-C stops it between two path planner calls
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("plan.json");
    let cube = data("cube81");
    let args = ["plan", &cube, "--unit", "mm", "--up", "z", "--no-subassemblies", "--rrt-time", "0.1", "--out", out.to_str().unwrap()];
    let child = Command::new(env!("CARGO_BIN_EXE_asp"))
        .args(args)
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .expect("asp runs");
    // after the world is built and the search has started
    std::thread::sleep(std::time::Duration::from_millis(1500));
    let kill = Command::new("kill").args(["-INT", &child.id().to_string()]).status().expect("kill runs");
    assert!(kill.success());
    let started = std::time::Instant::now();
    let o = child.wait_with_output().unwrap();
    assert!(started.elapsed().as_secs_f64() < 5.0, "it stops soon after Ctrl-C");
    assert_eq!(o.status.code(), Some(130), "{}", stderr(&o));
    let table = String::from_utf8(o.stdout.clone()).unwrap();
    assert!(table.contains("budget exhausted") && table.contains("interrupted (Ctrl-C)"), "{table}");
    assert!(stderr(&o).contains("interrupted"), "{}", stderr(&o));
    let plan = json(&out);
    assert_eq!(plan["status"], "budget_exhausted");
    assert_eq!(plan["stats"]["stopped_by"], "interrupted");
    // (a slow machine may still be building the world at the Ctrl-C: then no call at all)
    assert!(plan["stats"]["path_planner_calls"].as_u64().unwrap() < 81, "stopped before the state was done");
    // written atomically: the plan and nothing else
    let files: Vec<_> = std::fs::read_dir(dir.path()).unwrap().map(|e| e.unwrap().file_name()).collect();
    assert_eq!(files, [std::ffi::OsString::from("plan.json")]);
}

#[test]
fn one_process_plans_many_models_and_exits_with_the_worst_outcome() {
    let dir = tempfile::tempdir().unwrap();
    let tube = fixture_file(dir.path(), &fixtures::tube(), "tube.glb");
    let arch = fixture_file(dir.path(), &fixtures::arch(), "arch.glb");
    let missing = dir.path().join("missing.glb");
    let out = dir.path().join("plans");
    let models = [tube.to_str().unwrap(), arch.to_str().unwrap()];
    let o = asp(&["plan", models[0], models[1], "--out", out.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let table = String::from_utf8(o.stdout.clone()).unwrap();
    assert_eq!(table.matches("found in").count(), 2, "{table}");
    assert!(stderr(&o).contains("2 models in") && stderr(&o).contains("2 found"), "{}", stderr(&o));
    assert_eq!(json(&out.join("tube.json"))["status"], "found");
    assert_eq!(json(&out.join("arch.json"))["status"], "found");
    // a bad model is an error line; the others still plan; the exit code is the worst (2)
    let o = asp(&["plan", models[0], missing.to_str().unwrap(), models[1], "--json"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("missing.glb"), "{}", stderr(&o));
    let all: serde_json::Value = serde_json::from_slice(&o.stdout).expect("a JSON array of plans");
    assert_eq!(all.as_array().unwrap().len(), 2);
    // --each: every model inside a folder (a .glb file, a folder of STL parts)
    let models_dir = dir.path().join("models");
    std::fs::create_dir_all(models_dir.join("pump")).unwrap();
    std::fs::copy(&tube, models_dir.join("tube.glb")).unwrap();
    for f in std::fs::read_dir(data("pump")).unwrap() {
        let f = f.unwrap();
        std::fs::copy(f.path(), models_dir.join("pump").join(f.file_name())).unwrap();
    }
    let o = asp(&[
        "plan",
        "--each",
        models_dir.to_str().unwrap(),
        "--unit",
        "mm",
        "--up",
        "z",
        "--no-subassemblies",
        "--no-path-planner",
        "-q",
    ]);
    assert_eq!(o.status.code(), Some(1), "the pump has no plan without subassemblies: {}", stderr(&o));
    let table = String::from_utf8(o.stdout).unwrap();
    assert!(table.contains("pump: no plan") && table.contains("tube.glb: found"), "{table}");
    let o = asp(&["plan", "--each", &data("pump")]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("one model"), "{}", stderr(&o));
}

/// Replays a plan JSON's steps in disassembly direction on the puzzle's cells (cell size
/// `cell` model units): undo each step's `moves` (last first, negated), then take its parts out
/// along the reversed insertion, every unit cell step checked against the parts present; a
/// subassembly's own steps are replayed on its parts alone. Returns the parts taken out.
fn replay_json(steps: &serde_json::Value, pos: &mut Vec<Vec<[i32; 3]>>, present: &mut Vec<usize>, cell: f64) -> usize {
    let cells_of = |v: &serde_json::Value| -> [i32; 3] {
        let a: Vec<f64> = v.as_array().unwrap().iter().map(|x| x.as_f64().unwrap()).collect();
        std::array::from_fn(|k| (a[k] / cell).round() as i32)
    };
    let hits = |pos: &Vec<Vec<[i32; 3]>>, moving: &[usize], others: &[usize], d: [i32; 3]| {
        let blocked: std::collections::HashSet<[i32; 3]> = others.iter().flat_map(|&p| pos[p].iter().copied()).collect();
        moving.iter().any(|&p| pos[p].iter().any(|c| blocked.contains(&[c[0] + d[0], c[1] + d[1], c[2] + d[2]])))
    };
    let mut out = 0;
    for step in steps.as_array().unwrap().iter().rev() {
        for m in step["moves"].as_array().map(Vec::as_slice).unwrap_or(&[]).iter().rev() {
            let parts: Vec<usize> = m["parts"].as_array().unwrap().iter().map(|p| p.as_u64().unwrap() as usize).collect();
            let t = cells_of(&m["translation"]).map(|x| -x);
            let others: Vec<usize> = present.iter().copied().filter(|p| !parts.contains(p)).collect();
            let len: i32 = t.iter().map(|x| x.abs()).sum();
            for j in 1..=len {
                assert!(!hits(pos, &parts, &others, t.map(|x| x.signum() * j)), "move {m} collides");
            }
            for &p in &parts {
                pos[p] = pos[p].iter().map(|c| [c[0] + t[0], c[1] + t[1], c[2] + t[2]]).collect();
            }
        }
        let parts: Vec<usize> = match step["subassembly"]["parts"].as_array() {
            Some(a) => a.iter().map(|p| p.as_u64().unwrap() as usize).collect(),
            None => vec![step["part"].as_u64().unwrap() as usize],
        };
        let d = cells_of(&step["motion"]["direction"]).map(|x| -x.signum());
        let others: Vec<usize> = present.iter().copied().filter(|p| !parts.contains(p)).collect();
        for j in 1..=40 {
            assert!(!hits(pos, &parts, &others, d.map(|x| x * j)), "removal of {parts:?} collides at {j}");
        }
        if let Some(inner) = step["subassembly"]["assembly_sequence"].as_array() {
            let mut sub = parts.clone();
            out += replay_json(&serde_json::Value::Array(inner.clone()), pos, &mut sub, cell);
        }
        present.retain(|p| !parts.contains(p));
        out += 1;
    }
    out
}

#[test]
fn plans_an_interlocking_burr_by_grid_moves() {
    let dir = tempfile::tempdir().unwrap();
    let a = asp_geom::puzzles::burr_level();
    let model = fixture_file(dir.path(), &a, "burr.glb");
    let out = dir.path().join("plan.json");
    let o = asp(&["plan", model.to_str().unwrap(), "--out", out.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let table = String::from_utf8(o.stdout).unwrap();
    assert!(table.contains("grid plan") && table.contains("move piece"), "{table}");
    let plan = json(&out);
    assert_eq!(plan["format_version"], "1.15");
    assert_eq!(plan["status"], "found");
    assert_eq!(plan["grid"]["reason"], "needs_moves");
    assert_eq!(plan["grid"]["first_separation_moves"], asp_geom::puzzles::BURR_LEVEL_MOVES);
    // the documented rule, replayed on the cells from the JSON alone
    let voxels = asp_geom::grid::VoxelModel::of(&a).unwrap();
    let mut pos = voxels.cells.clone();
    let mut present: Vec<usize> = (0..6).collect();
    replay_json(&plan["assembly_sequence"], &mut pos, &mut present, 0.01);
    assert!(present.is_empty(), "parts never taken out: {present:?}");
    // without the grid search (the planner before the grid search) the burr only lifts off the
    // ground in one piece: a subassembly of all six pieces that cannot be taken apart
    // (so the plan is partial, exit code 1)
    let o = asp(&["plan", model.to_str().unwrap(), "--no-grid", "--no-path-planner", "--json"]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    let plan: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let g = &plan["assembly_sequence"][0]["subassembly"];
    assert_eq!(g["status"], "no_plan", "{plan}");
    assert_eq!(g["parts"].as_array().unwrap().len(), 6);
    assert!(plan["grid"].is_null());
}

/// A plan that lifts a locked core in one piece is `partial`, exit code 1, in
/// the JSON (with the core and why), the table and `--each`'s summary.
#[test]
fn a_plan_with_a_locked_core_is_partial_with_exit_code_1() {
    let dir = tempfile::tempdir().unwrap();
    let models = dir.path().join("models");
    std::fs::create_dir(&models).unwrap();
    let burr = fixture_file(&models, &asp_geom::puzzles::burr_level(), "burr.glb");
    fixture_file(&models, &fixtures::tube(), "tube.glb");
    let out = dir.path().join("plan.json");
    let off = ["--no-grid", "--no-path-planner"];
    let o = asp(&["plan", burr.to_str().unwrap(), off[0], off[1], "--out", out.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    let table = String::from_utf8(o.stdout).unwrap();
    let mut lines = table.lines();
    assert!(lines.next().unwrap().contains(": partial in "), "{table}");
    let plan = json(&out);
    assert_eq!(plan["status"], "partial");
    let cores = plan["locked_cores"].as_array().expect("locked cores");
    assert_eq!(cores.len(), 1, "{plan}");
    let names: Vec<&str> = cores[0]["names"].as_array().unwrap().iter().map(|n| n.as_str().unwrap()).collect();
    assert_eq!(names.len(), 6);
    assert_eq!(cores[0]["status"], "no_plan");
    assert!(!cores[0]["explanation"].as_array().unwrap().is_empty(), "{plan}");
    let line = format!("planned 0 of 6 parts; 6 stay in 1 locked core: {}", names.join(", "));
    assert_eq!(lines.next(), Some(line.as_str()), "{table}");
    // and why (format 1.9): no overlaps, the grid planner turned off, lenient changes nothing
    let why = &cores[0]["why"];
    assert!(why["overlaps"].is_null(), "{plan}");
    assert_eq!(why["grid"], serde_json::json!({ "tried": false, "reason": "off" }), "{plan}");
    assert_eq!(why["lenient"], serde_json::json!({ "status": "unchanged", "frees": 0 }), "{plan}");
    assert_eq!(why["blocks"].as_array().unwrap().len(), 5, "{plan}");
    assert!(lines.next().unwrap().starts_with("  why the core on "), "{table}");
    assert!(table.contains("\n    grid planner: not tried (--no-grid)\n"), "{table}");
    // --each counts partial plans apart; the exit code is the worst (1)
    let o = asp(&["plan", "--each", models.to_str().unwrap(), off[0], off[1]]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stderr(&o).contains("2 models in") && stderr(&o).contains(": 1 found, 1 partial, 0 not found, 0 errors"), "{}", stderr(&o));
}

#[test]
fn grid_subassemblies_with_moves_replay_from_the_json() {
    // two puzzles side by side: the depth-first search only lifts subassemblies it cannot take
    // apart, so the grid plan is the fallback; each puzzle's own plan moves pieces on its frame
    let dir = tempfile::tempdir().unwrap();
    let a = asp_geom::puzzles::two_small_puzzles();
    let model = fixture_file(dir.path(), &a, "two.glb");
    let o = asp(&["plan", model.to_str().unwrap(), "--json"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let plan: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(plan["grid"]["reason"], "fallback", "{plan}");
    let steps = plan["assembly_sequence"].as_array().unwrap();
    let sub = steps.iter().find(|s| !s["subassembly"].is_null()).expect("a subassembly step");
    assert_eq!(sub["subassembly"]["status"], "found");
    assert!(sub["subassembly"]["assembly_sequence"].as_array().unwrap().iter().any(|s| s["moves"].is_array()), "{sub}");
    let voxels = asp_geom::grid::VoxelModel::of(&a).unwrap();
    let mut pos = voxels.cells.clone();
    let mut present: Vec<usize> = (0..6).collect();
    replay_json(&plan["assembly_sequence"], &mut pos, &mut present, 0.01);
    assert!(present.is_empty(), "parts never taken out: {present:?}");
}

#[test]
fn gen_profiles_attaches_connectors_on_request() {
    let dir = tempfile::tempdir().unwrap();
    let parts = |flags: &[&str], sub: &str| {
        let out = dir.path().join(sub);
        let mut args = vec!["gen", "profiles", "--preset", "single-layer", "--seed", "1", "-q", "--out", out.to_str().unwrap()];
        args.extend_from_slice(flags);
        let o = asp(&args);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let m: serde_json::Value = serde_json::from_slice(&std::fs::read(out.join("manifest.json")).unwrap()).unwrap();
        let e = &m["assemblies"][0];
        (e["parts"].as_u64().unwrap(), e["counts"]["u_connectors"].as_u64().unwrap() + e["counts"]["o_connectors"].as_u64().unwrap())
    };
    let (attached, connectors) = parts(&["--connectors", "attached"], "a");
    assert_eq!(attached, 29, "21 removable and 8 fixed profiles, no connector parts");
    assert_eq!(parts(&[], "s"), (29 + connectors, connectors), "separate by default");
    let bad = asp(&["gen", "profiles", "--connectors", "glued", "--out", dir.path().to_str().unwrap()]);
    assert_eq!(bad.status.code(), Some(2));
}

/// `--unit-group` plans the named parts as one part on purpose: the locked
/// post's core goes in whole, the plan is `found` (exit 0); a name the model lacks is an error
/// naming the flag (exit 2).
#[test]
fn unit_group_plans_named_parts_as_one_unit() {
    let dir = tempfile::tempdir().unwrap();
    let model = fixture_file(dir.path(), &fixtures::ring_on_locked_post(), "post.glb");
    let model = model.to_str().unwrap();
    let o = asp(&["plan", model, "--json"]);
    assert_eq!(o.status.code(), Some(1), "without the unit the plan is partial: {}", stderr(&o));
    let o = asp(&["plan", model, "--json", "--unit-group", "base,post,ring"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let plan: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(plan["status"], "found", "{plan}");
    assert!(plan["locked_cores"].is_null(), "{plan}");
    let unit = &plan["assembly_sequence"][0]["subassembly"];
    assert_eq!(unit["status"], "unit", "{plan}");
    assert_eq!(unit["parts"], serde_json::json!([0, 1, 2]));
    let o = asp(&["plan", model, "--unit-group", "base,nope"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("--unit-group: no part is named 'nope'"), "{}", stderr(&o));
    let o = asp(&["plan", model, "--unit-group", "base"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("--unit-group: a unit needs at least two parts"), "{}", stderr(&o));
}

/// `--each` plans its models in parallel; what it prints and writes is the serial loop's, in
/// model order: each model's plan as planning it alone gives it.
#[test]
fn plan_each_in_parallel_prints_in_model_order() {
    let dir = tempfile::tempdir().unwrap();
    let models = dir.path().join("s4");
    let o = asp(&["gen", "soma", "--size", "4", "--count", "6", "--seed", "3", "--out", models.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let mut files: Vec<PathBuf> =
        std::fs::read_dir(&models).unwrap().map(|e| e.unwrap().path()).filter(|p| p.extension().is_some_and(|e| e == "glb")).collect();
    files.sort();
    assert_eq!(files.len(), 6);
    let without_timings = |mut v: serde_json::Value| {
        v["stats"].as_object_mut().unwrap().remove("timings");
        v["stats"].as_object_mut().unwrap().remove("seconds");
        v
    };
    let o = asp(&["plan", "--each", models.to_str().unwrap(), "--json", "-q"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let all: serde_json::Value = serde_json::from_slice(&o.stdout).expect("a JSON array of plans");
    let all = all.as_array().unwrap();
    assert_eq!(all.len(), files.len());
    let o = asp(&["plan", "--each", models.to_str().unwrap(), "-q"]);
    let table = String::from_utf8(o.stdout).unwrap();
    let mut tables = Vec::new();
    for (plan, file) in all.iter().zip(&files) {
        let one = asp(&["plan", file.to_str().unwrap(), "--json"]);
        let alone: serde_json::Value = serde_json::from_slice(&one.stdout).unwrap();
        assert_eq!(without_timings(plan.clone()), without_timings(alone), "{}", file.display());
        tables.push(String::from_utf8(asp(&["plan", file.to_str().unwrap()]).stdout).unwrap());
    }
    let strip = |t: &str| t.lines().filter(|l| !l.contains("found in")).collect::<Vec<_>>().join("\n");
    assert_eq!(strip(&table), strip(&tables.join("\n")));
}

/// `--model` trained on another checker's labels (its `asp.checker`) is one
/// line naming the file and both checkers, exit status 2, for `asp plan` and `asp bench feasible`.
#[test]
fn a_model_of_another_checker_exits_2_naming_both() {
    let dir = tempfile::tempdir().unwrap();
    let model = fixture_file(dir.path(), &fixtures::arch(), "arch.glb");
    // asp-learn's fixture with `asp.checker` = physics appended (ModelProto field 14)
    let mut bytes = std::fs::read(concat!(env!("CARGO_MANIFEST_DIR"), "/../asp-learn/tests/data/random_gnn.onnx")).unwrap();
    let entry = [&[0x0a, 11][..], b"asp.checker", &[0x12, 7], b"physics"].concat();
    bytes.extend_from_slice(&[0x72, entry.len() as u8]);
    bytes.extend_from_slice(&entry);
    let physics = dir.path().join("rem_physics.onnx");
    std::fs::write(&physics, bytes).unwrap();
    let (m, p) = (model.to_str().unwrap(), physics.to_str().unwrap());
    for args in [vec!["plan", m, "--order", "gnn", "--model", p], vec!["bench", "feasible", m, "--orderings", "1", "--model", p]] {
        let o = asp(&args);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {}", stderr(&o));
        let err = stderr(&o);
        assert_eq!(err.trim().lines().count(), 1, "{err}");
        assert!(err.contains(p) && err.contains("trained on labels of the physics checker, this run uses the default checker"), "{err}");
    }
    // the same file under physics plans
    let o = asp(&["plan", m, "--order", "gnn", "--model", p, "--stability", "physics", "--json"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
}

/// A part whose mesh holds several bodies (pins stored beside a shelf in the
/// shelf's mesh) is named in a warning and moves as one; `--split-bodies` plans each body as a
/// part of its own, named `NAME#1`, `NAME#2`, ...
#[test]
fn split_bodies_makes_each_body_a_part() {
    use asp_geom::math::{Axis, Vec3};
    use asp_geom::{Mesh, Part, Units};
    let dir = tempfile::tempdir().unwrap();
    let mut shelf = Mesh::cuboid(Vec3::ZERO, Vec3::new(0.4, 0.2, 0.02));
    shelf.append(&Mesh::cuboid(Vec3::new(0.5, 0.0, 0.0), Vec3::new(0.52, 0.02, 0.1)));
    shelf.append(&Mesh::cuboid(Vec3::new(0.6, 0.0, 0.0), Vec3::new(0.62, 0.02, 0.1)));
    let side = Mesh::cuboid(Vec3::new(0.0, 0.0, 0.02), Vec3::new(0.02, 0.2, 0.3));
    let a = Assembly {
        parts: vec![Part::new("shelf", shelf, false, serde_json::Value::Null), Part::new("side", side, false, serde_json::Value::Null)],
        units: Units::metres(),
        up: Axis::Z,
        source: "shelf.glb".into(),
        warnings: Vec::new(),
    };
    let model = fixture_file(dir.path(), &a, "shelf.glb");
    let path = model.to_str().unwrap();
    let o = asp(&["plan", path, "--json"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let plan: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let names: Vec<&str> = plan["parts"].as_array().unwrap().iter().map(|p| p["name"].as_str().unwrap()).collect();
    assert_eq!(names, ["shelf", "side"]);
    assert!(stderr(&o).contains("part 'shelf' holds 3 separate bodies") && stderr(&o).contains("--split-bodies"), "{}", stderr(&o));
    let o = asp(&["plan", path, "--json", "--split-bodies"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let plan: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let names: Vec<&str> = plan["parts"].as_array().unwrap().iter().map(|p| p["name"].as_str().unwrap()).collect();
    assert_eq!(names, ["shelf#1", "shelf#2", "shelf#3", "side"], "{plan}");
    assert_eq!(plan["status"], "found", "{plan}");
    assert_eq!(plan["assembly_sequence"].as_array().unwrap().len(), 4, "{plan}");
    let err = stderr(&o);
    assert!(err.contains("split into one part per body (--split-bodies): shelf") && !err.contains("holds 3 separate bodies"), "{err}");
    // the same through a plan request file
    let request = dir.path().join("request.json");
    std::fs::write(&request, r#"{"split_bodies": true}"#).unwrap();
    let o = asp(&["plan", path, "--json", "--settings", request.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let plan: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(plan["parts"].as_array().unwrap().len(), 4, "{plan}");
}
