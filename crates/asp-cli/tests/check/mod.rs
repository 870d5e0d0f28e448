//! `asp check` end to end (exit codes, the text, the JSON report, bad input), and `asp plan
//! --precedence` with its DOT file.

use asp_geom::fixtures;
use asp_geom::io::write_glb;
use std::process::{Command, Output};

fn asp(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_asp")).args(args).output().expect("asp runs")
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

#[test]
fn check_exits_0_1_2_and_writes_the_json_report() {
    let dir = tempfile::tempdir().unwrap();
    let model = dir.path().join("tube.glb");
    write_glb(&fixtures::tube(), &model).unwrap();
    let model = model.to_str().unwrap();
    let seq = |name: &str, text: &str| {
        let p = dir.path().join(name);
        std::fs::write(&p, text).unwrap();
        p.to_str().unwrap().to_string()
    };
    // feasible: exit 0, the text says so
    let good = seq("good.txt", "receptacle  # the base\ncap\nstick -z\nhandle\n");
    let o = asp(&["check", model, &good, "--no-path-planner"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let text = String::from_utf8(o.stdout).unwrap();
    assert!(text.contains("feasible: every step goes in"), "{text}");
    // infeasible: exit 1, the JSON names the step, its blockers and the repair
    let bad = seq("bad.txt", "cap\nhandle\nstick\n");
    let out = dir.path().join("check.json");
    let o = asp(&["check", model, &bad, "--no-path-planner", "--json", "--out", out.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    let printed: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let written: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&out).unwrap()).unwrap();
    for r in [&printed, &written] {
        assert_eq!(r["format_version"], asp_app::check::CHECK_FORMAT_VERSION);
        assert_eq!(r["status"], "infeasible");
        assert_eq!(r["first_failure"], 2);
        assert_eq!(r["steps"][2]["failure"]["reason"], "blocked");
        let blockers: Vec<&str> =
            r["steps"][2]["failure"]["blockers"].as_array().unwrap().iter().map(|b| b["name"].as_str().unwrap()).collect();
        assert!(blockers.contains(&"cap") && blockers.contains(&"handle"), "{blockers:?}");
        assert_eq!(r["repair"]["status"], "found");
        assert_eq!(r["repair"]["moved"], 1);
        assert_eq!(r["repair"]["kendall_tau"], 1);
    }
    // a plan JSON is a sequence too
    let plan = dir.path().join("plan.json");
    let o = asp(&["plan", model, "--no-path-planner", "--out", plan.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let o = asp(&["check", model, plan.to_str().unwrap(), "--no-path-planner", "--json"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    // unknown names: exit 2, one line naming them with the nearest names
    let typo = seq("typo.txt", "cap\nstik\nhandle\n");
    let o = asp(&["check", model, &typo]);
    assert_eq!(o.status.code(), Some(2));
    let err = stderr(&o);
    assert_eq!(err.trim().lines().count(), 1, "{err}");
    assert!(err.contains("'stik' (nearest: stick"), "{err}");
    // a missing sequence file: exit 2
    let o = asp(&["check", model, dir.path().join("none.txt").to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
}

#[test]
fn plan_precedence_adds_the_graph_and_writes_dot() {
    let dir = tempfile::tempdir().unwrap();
    let model = dir.path().join("arch.glb");
    write_glb(&fixtures::arch(), &model).unwrap();
    let out = dir.path().join("plan.json");
    let dot = dir.path().join("plan.dot");
    let o = asp(&["plan", model.to_str().unwrap(), "--precedence-dot", dot.to_str().unwrap(), "--out", out.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let plan: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&out).unwrap()).unwrap();
    assert_eq!(plan["format_version"], "1.15");
    let g = &plan["precedence"];
    assert_eq!(g["stability"]["conservative"], true);
    assert_eq!(g["steps"].as_array().unwrap().len(), 3);
    assert_eq!(g["levels"][0].as_array().unwrap().len(), 2, "{g}");
    assert_eq!(g["critical_path"].as_array().unwrap().len(), 2, "{g}");
    let dot = std::fs::read_to_string(&dot).unwrap();
    assert!(dot.starts_with("digraph precedence {") && dot.contains("keystone"), "{dot}");
    // without the flag, no graph
    let o = asp(&["plan", model.to_str().unwrap(), "--json"]);
    let plan: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert!(plan.get("precedence").is_none());
}
