//! `asp plan --objective`: single-objective MCTS and Pareto-MCTS end to end, their JSON and
//! trace, reproducibility, and flag errors.

use asp_geom::io::write_glb;
use asp_geom::math::{Axis, Vec3};
use asp_geom::{Assembly, Mesh, Part, Units};
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn asp(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_asp")).args(args).output().expect("asp runs")
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn json(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// A 3×3×3 cube of 5 cm voxels in three layers of three bars, crossing like a Jenga tower;
/// each bar carries its cells in `extras.asp.cells` as the Soma generator writes them.
fn jenga(dir: &Path) -> PathBuf {
    let mut parts = Vec::new();
    for z in 0..3 {
        for k in 0..3 {
            let cells: Vec<[i32; 3]> = (0..3).map(|t| if z % 2 == 0 { [t, k, z] } else { [k, t, z] }).collect();
            parts.push(Part::new(
                format!("bar_{z}{k}"),
                Mesh::from_voxels(&cells, Vec3::splat(0.05), Vec3::ZERO),
                false,
                serde_json::json!({ "asp": { "cells": cells } }),
            ));
        }
    }
    let a = Assembly { parts, units: Units::metres(), up: Axis::Z, source: "jenga".into(), warnings: Vec::new() };
    let path = dir.join("jenga.glb");
    write_glb(&a, &path).unwrap();
    path
}

#[test]
fn single_objective_writes_the_best_sequence() {
    let dir = tempfile::tempdir().unwrap();
    let model = jenga(dir.path());
    let out = dir.path().join("plan.json");
    let o = asp(&[
        "plan",
        model.to_str().unwrap(),
        "--objective",
        "access",
        "--episodes",
        "50",
        "--threads",
        "1",
        "--seed",
        "1",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let table = String::from_utf8(o.stdout).unwrap();
    assert!(table.contains("best access"), "{table}");
    let plan = json(&out);
    assert_eq!(plan["status"], "found");
    assert_eq!(plan["assembly_sequence"].as_array().unwrap().len(), 9);
    assert_eq!(plan["disassembly_sequence"].as_array().unwrap().len(), 9);
    let opt = &plan["optimisation"];
    assert_eq!(opt["method"], "mcts");
    assert_eq!(opt["objectives"], serde_json::json!(["access"]));
    assert!(opt["values"][0].as_f64().unwrap() > 0.0);
    assert!(plan.get("pareto_front").is_none());
    // the removal tests the search ran on the distance maps
    let stats = &plan["stats"];
    assert_eq!(stats["checker"], "distance_maps");
    let tests = stats["removal_tests"].as_u64().unwrap();
    let (collision, gravity) = (stats["failed_collision"].as_u64().unwrap(), stats["failed_gravity"].as_u64().unwrap());
    // every bar slides out along its length; a bar that is the last support of a crossing
    // bar above it may not leave
    assert_eq!(collision, 0, "{stats}");
    assert!(gravity > 0, "{stats}");
    assert!(tests > collision + gravity, "{stats}");
    assert_eq!(stats["path_planner_calls"], 0);
    // the top layer goes first in disassembly: the assembly sequence ends with a top bar
    let last = plan["assembly_sequence"][8]["name"].as_str().unwrap();
    assert!(last.starts_with("bar_2"), "{last}");
    assert_eq!(plan["assembly_sequence"][0]["motion"]["kind"], "linear");
}

#[test]
fn pareto_front_trace_and_reproducibility() {
    let dir = tempfile::tempdir().unwrap();
    let model = jenga(dir.path());
    let run = |k: usize, threads: &str| {
        let out = dir.path().join(format!("front{k}.json"));
        let trace = dir.path().join(format!("hv{k}.csv"));
        let o = asp(&[
            "plan",
            model.to_str().unwrap(),
            "--objective",
            "access,dirchange",
            "--pareto",
            "--episodes",
            "60",
            "--budget",
            "5",
            "--threads",
            threads,
            "--seed",
            "1",
            "--out",
            out.to_str().unwrap(),
            "--trace",
            trace.to_str().unwrap(),
        ]);
        assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
        let mut v = json(&out);
        for key in ["map_seconds", "search_seconds"] {
            v["optimisation"][key] = serde_json::Value::Null;
        }
        v["stats"]["seconds"] = serde_json::Value::Null;
        (v, std::fs::read_to_string(trace).unwrap())
    };
    let (a, trace) = run(0, "2");
    let front = a["pareto_front"].as_array().unwrap();
    assert!(!front.is_empty());
    for e in front {
        assert_eq!(e["objectives"].as_array().unwrap().len(), 2);
        let mut seq: Vec<u64> = e["disassembly_sequence"].as_array().unwrap().iter().map(|v| v.as_u64().unwrap()).collect();
        seq.sort();
        assert_eq!(seq, (0..9).collect::<Vec<u64>>());
    }
    let opt = &a["optimisation"];
    assert_eq!(opt["method"], "pareto_mcts");
    assert_eq!(opt["threads"], 2);
    assert!(opt["hypervolume"].as_f64().unwrap() > 0.0);
    assert_eq!(opt["episodes"], 60);
    let mut lines = trace.lines();
    assert_eq!(lines.next(), Some("episode,iterations,seconds,value,front_size"));
    assert!(lines.count() >= 1);
    // same seed and thread count: the same plan
    let (b, _) = run(1, "2");
    assert_eq!(a, b);
}

#[test]
fn bad_objective_flags_are_errors() {
    let dir = tempfile::tempdir().unwrap();
    let model = jenga(dir.path());
    let m = model.to_str().unwrap();
    let o = asp(&["plan", m, "--objective", "speed"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("unknown objective 'speed'"), "{}", stderr(&o));
    let o = asp(&["plan", m, "--objective", "access,dirchange"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("--pareto"), "{}", stderr(&o));
    let o = asp(&["plan", m, "--objective", "access", "--budget", "0"]);
    assert_eq!(o.status.code(), Some(2));
    let o = asp(&["plan", m, "--objective", "access", "--resolution", "4"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("resolution"), "{}", stderr(&o));
}

/// The optimiser's answers for fixed seeds and thread counts, pinned to the values the search
/// gave before its plug-in points (objective memory, filters, per-thread policies) were opened:
/// refactoring the engine must not change a single result. Update the literals only for a
/// change that is meant to change the search (and say so in the commit).
#[test]
fn optimiser_results_for_a_seed_are_pinned() {
    let dir = tempfile::tempdir().unwrap();
    let o = asp(&["gen", "soma", "--size", "4", "--seed", "5", "--out", dir.path().to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let cube = dir.path().join("soma4_000.glb");
    let plan = |args: &[&str]| {
        let out = dir.path().join("plan.json");
        let mut all = vec!["plan", cube.to_str().unwrap(), "--threads", "2", "--episodes", "300", "--quiet"];
        all.extend_from_slice(args);
        all.extend_from_slice(&["--out", out.to_str().unwrap()]);
        let o = asp(&all);
        assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
        json(&out)
    };
    let seq =
        |v: &serde_json::Value| -> Vec<u64> { v["disassembly_sequence"].as_array().unwrap().iter().map(|x| x.as_u64().unwrap()).collect() };
    // the tree search alone (the local search off) is the search these literals were pinned on
    let pareto = plan(&["--objective", "access,dirchange", "--pareto", "--seed", "1", "--polish", "0"]);
    let opt = &pareto["optimisation"];
    assert_eq!(opt["polished"].as_u64(), Some(0));
    assert_eq!(opt["hypervolume"].as_f64().unwrap(), 107386.34163125232);
    assert_eq!(opt["values"].as_array().unwrap()[0].as_f64().unwrap(), 353.59507842361927);
    assert_eq!(opt["values"].as_array().unwrap()[1].as_f64().unwrap(), 46.0);
    assert_eq!(pareto["pareto_front"].as_array().unwrap().len(), 12);
    assert_eq!(seq(&pareto), vec![10, 8, 12, 7, 3, 11, 18, 19, 5, 15, 16, 13, 17, 2, 9, 1, 4, 0, 6, 14]);
    assert_eq!((opt["iterations"].as_u64(), opt["tree_nodes"].as_u64()), (Some(25860), Some(21517)));
    // the default adds the local search over the answer's sequences (block moves): the same
    // tree search, a larger front
    let polished = plan(&["--objective", "access,dirchange", "--pareto", "--seed", "1"]);
    let opt = &polished["optimisation"];
    assert_eq!((opt["iterations"].as_u64(), opt["tree_nodes"].as_u64()), (Some(25860), Some(21517)));
    assert_eq!(opt["polish"].as_f64(), Some(0.25));
    assert_eq!(opt["hypervolume"].as_f64().unwrap(), 132016.11014830694);
    assert!(opt["polished"].as_u64().unwrap() > 0);
    let path = plan(&["--objective", "pathlen", "--seed", "2", "--polish", "0"]);
    let opt = &path["optimisation"];
    assert_eq!(opt["values"].as_array().unwrap()[0].as_f64().unwrap(), -1.4999999776482582);
    assert_eq!(seq(&path), vec![15, 19, 17, 10, 11, 12, 8, 9, 16, 7, 3, 18, 5, 1, 2, 4, 13, 0, 6, 14]);
    assert_eq!((opt["iterations"].as_u64(), opt["tree_nodes"].as_u64()), (Some(17567), Some(7733)));
    // one objective: the local search keeps the best sequence or finds a better one
    let polished = plan(&["--objective", "pathlen", "--seed", "2"]);
    assert!(polished["optimisation"]["values"][0].as_f64().unwrap() >= -1.4999999776482582);
}

/// `asp collect transitions`: a generated cube's transitions as docs/learning.md describes them
/// (format, version, one line per counted transition), reproducible, and errors naming the file
/// or the flag.
#[test]
fn collect_transitions_writes_the_documented_data_set() {
    let dir = tempfile::tempdir().unwrap();
    let models = dir.path().join("cubes");
    let o = asp(&["gen", "soma", "--size", "3", "--count", "2", "--seed", "4", "--out", models.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let collect = |out: &Path, extra: &[&str]| {
        let mut args = vec![
            "collect",
            "transitions",
            models.to_str().unwrap(),
            "--objective",
            "access,dirchange",
            "--episodes",
            "15",
            "--seed",
            "2",
            "--resolution",
            "5",
            "--out",
            out.to_str().unwrap(),
        ];
        args.extend_from_slice(extra);
        asp(&args)
    };
    let out = dir.path().join("q");
    let o = collect(&out, &[]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let stdout = String::from_utf8(o.stdout).unwrap();
    assert!(stdout.contains("2 models") && stdout.contains("asp-q/1 directions=25 neighbours=8"), "{stdout}");
    let index = json(&out.join("index.json"));
    assert_eq!(index["format"], "asp-transitions");
    assert_eq!(index["version"], 1);
    assert_eq!(index["objectives"], serde_json::json!(["access", "dirchange"]));
    assert_eq!((index["node_dim"].as_u64(), index["edge_dim"].as_u64()), (Some(78), Some(55)));
    assert_eq!(index["episodes"], 15);
    let entries = index["assemblies"].as_array().unwrap();
    assert_eq!(entries.len(), 2);
    let mut total = 0;
    for e in entries {
        assert!(Path::new(e["model"].as_str().unwrap()).is_absolute());
        assert_eq!(e["maps"]["objective"], "access,dirchange");
        assert_eq!(e["maps"]["resolution"], 5);
        assert_eq!(e["reward_ranges"].as_array().unwrap().len(), 2);
        let text = std::fs::read_to_string(out.join(e["dir"].as_str().unwrap()).join("transitions.jsonl")).unwrap();
        let lines: Vec<serde_json::Value> = text.lines().map(|l| serde_json::from_str(l).unwrap()).collect();
        assert_eq!(lines.len() as u64, e["transitions"].as_u64().unwrap());
        assert!(!lines.is_empty());
        let parts = e["parts"].as_u64().unwrap();
        for l in &lines {
            let action = l["action"].as_u64().unwrap();
            assert!(action < parts && l["actions"].as_array().unwrap().iter().any(|a| a.as_u64() == Some(action)));
            // s' = present without the action: every next action is one of its parts
            let present = l["present"].as_array().unwrap();
            assert!(l["next_actions"].as_array().unwrap().iter().all(|p| present.contains(p) && p.as_u64() != Some(action)));
            assert_eq!(l["rewards"].as_array().unwrap().len(), 2);
            assert!(l["kind"] == "expansion" || l["kind"] == "simulation");
        }
        total += lines.len();
    }
    assert!(stdout.contains(&format!("{total} transitions")), "{stdout}");
    // the same seed, the same bytes
    let again = dir.path().join("again");
    assert_eq!(collect(&again, &[]).status.code(), Some(0));
    for e in entries {
        let file = |root: &Path| std::fs::read(root.join(e["dir"].as_str().unwrap()).join("transitions.jsonl")).unwrap();
        assert_eq!(file(&out), file(&again));
    }
    // one-line errors naming the file or the flag
    let missing = dir.path().join("missing.glb");
    let o = asp(&["collect", "transitions", missing.to_str().unwrap(), "--objective", "access", "--out", out.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("missing.glb") && stderr(&o).trim().lines().count() == 1, "{}", stderr(&o));
    let bad = dir.path().join("bad");
    let o = asp(&["collect", "transitions", models.to_str().unwrap(), "--objective", "access,speed", "--out", bad.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("--objective") && stderr(&o).contains("speed"), "{}", stderr(&o));
    // the robot flags of `asp plan`: robot-path needs --robot, a robot setting
    // needs the robot, and the feasibility search's --grippers is refused; nothing is written
    let m = models.to_str().unwrap();
    for (flags, words) in [
        (&["--objective", "robot-path"][..], "robot-path needs a robot (--robot panda or a URDF file)"),
        (&["--objective", "access", "--drop-off", "0,0,1"][..], "--drop-off: needs a robot (--robot)"),
        (&["--objective", "robot-path", "--robot", "panda", "--grippers", "2"][..], "--grippers: applies to the feasibility search only"),
        (&["--objective", "robot-path", "--robot", "/no/such/arm.urdf"][..], "/no/such/arm.urdf"),
    ] {
        let mut args = vec!["collect", "transitions", m, "--out", bad.to_str().unwrap()];
        args.extend_from_slice(flags);
        let o = asp(&args);
        assert_eq!(o.status.code(), Some(2), "{flags:?}");
        assert!(stderr(&o).contains(words) && stderr(&o).trim().lines().count() == 1, "{flags:?}: {}", stderr(&o));
        assert!(!bad.exists(), "{flags:?}");
    }
}

#[test]
fn q_models_are_checked_before_the_search() {
    let dir = tempfile::tempdir().unwrap();
    let model = jenga(dir.path());
    let m = model.to_str().unwrap();
    let removability = concat!(env!("CARGO_MANIFEST_DIR"), "/../asp-learn/tests/data/random_gnn.onnx");
    // a removability model is not a Q model
    let o = asp(&["plan", m, "--objective", "access", "--q", removability]);
    assert_eq!(o.status.code(), Some(2));
    let err = stderr(&o);
    assert!(err.contains("--q") && err.contains("random_gnn.onnx") && err.contains("asp.kind is 'removability', expected 'q'"), "{err}");
    assert_eq!(err.lines().count(), 1, "{err}");
    // one model per objective
    let o = asp(&["plan", m, "--objective", "access,dirchange", "--pareto", "--q", removability]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("1 Q models for 2 objectives"), "{}", stderr(&o));
    // a missing file, and epsilon out of range
    let o = asp(&["plan", m, "--objective", "access", "--q", "no/such.onnx"]);
    assert!(stderr(&o).contains("no/such.onnx: cannot read"), "{}", stderr(&o));
    let o = asp(&["plan", m, "--objective", "access", "--q", removability, "--epsilon", "1.5"]);
    assert!(stderr(&o).contains("--epsilon: must be in [0, 1], got 1.5"), "{}", stderr(&o));
}

/// A setting of the other search is an error naming the one that applies, before any
/// work (`--timeout 10` on an MCTS run used to be ignored while the run went on for its whole
/// episode budget); one line, exit 2, nothing written.
#[test]
fn settings_of_the_other_search_are_refused_naming_what_applies() {
    let dir = tempfile::tempdir().unwrap();
    let model = jenga(dir.path());
    let m = model.to_str().unwrap();
    let out = dir.path().join("plan.json");
    let o_ = out.to_str().unwrap();
    for (args, expected) in [
        (
            vec!["plan", m, "--objective", "access", "--timeout", "10", "--out", o_],
            "error: --timeout: applies to the feasibility search only (without --objective); the optimiser's limit is --time-limit",
        ),
        (
            vec!["plan", m, "--time-limit", "10", "--out", o_],
            "error: --time-limit: applies to the optimiser only (with --objective); the feasibility search's limit is --timeout",
        ),
        (
            vec!["plan", m, "--objective", "access", "--order", "random", "--out", o_],
            "error: --order: applies to the feasibility search only (without --objective)",
        ),
        (vec!["plan", m, "--episodes", "5", "--out", o_], "error: --episodes: applies to the optimiser only (with --objective)"),
        (vec!["plan", m, "--physics-threshold", "0.1", "--out", o_], "error: --physics-threshold: needs --stability physics"),
        (vec!["plan", m, "--drop-off", "1,2", "--out", o_], "error: --drop-off: must be three finite numbers x,y,z"),
    ] {
        let o = asp(&args);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {}", stderr(&o));
        assert_eq!(stderr(&o).trim_end(), expected, "{args:?}");
        assert!(!out.exists(), "{args:?} wrote a plan");
    }
}

/// The plan request as a file: `--settings` gives the keys, flags on the command line win, and
/// the plan is the one the same flags give.
#[test]
fn a_settings_file_plans_like_its_flags() {
    let dir = tempfile::tempdir().unwrap();
    let model = jenga(dir.path());
    let m = model.to_str().unwrap();
    let settings = dir.path().join("settings.json");
    std::fs::write(&settings, r#"{"objective": "access", "episodes": 30, "threads": 1, "seed": 5}"#).unwrap();
    let (a, b) = (dir.path().join("a.json"), dir.path().join("b.json"));
    let o = asp(&["plan", m, "--settings", settings.to_str().unwrap(), "--seed", "6", "--out", a.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let o = asp(&["plan", m, "--objective", "access", "--episodes", "30", "--threads", "1", "--seed", "6", "--out", b.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let (a, b) = (json(&a), json(&b));
    assert_eq!(a["optimisation"]["seed"], 6);
    assert_eq!(a["disassembly_sequence"], b["disassembly_sequence"]);
    assert_eq!(a["optimisation"]["values"], b["optimisation"]["values"]);
    std::fs::write(&settings, r#"{"episode": 30}"#).unwrap();
    let o = asp(&["plan", m, "--settings", settings.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("settings.json: episode: unknown setting (did you mean episodes?)"), "{}", stderr(&o));
}
