//! `asp collect removability` as a library: the data set's files, its labels and its
//! reproducibility (format: docs/learning.md).

use asp_app::collect::{collect, CollectSettings};
use asp_geom::{Checker, CheckerConfig, FeasibilityChecker, MotionKind, Outcome, PartSet, World, WorldConfig};
use std::path::{Path, PathBuf};

fn model(dir: &Path, seed: u64) -> PathBuf {
    let mut rng = <rand_chacha::ChaCha8Rng as rand::SeedableRng>::seed_from_u64(seed);
    let a = asp_gen::SomaCube::random(4, &mut rng).unwrap().to_assembly(0.05, "soma");
    let path = dir.join(format!("soma_{seed}.glb"));
    asp_geom::io::write_glb(&a, &path).unwrap();
    path
}

fn npy_shape(bytes: &[u8]) -> (usize, usize) {
    let len = u16::from_le_bytes([bytes[8], bytes[9]]) as usize;
    let header = std::str::from_utf8(&bytes[10..10 + len]).unwrap();
    let shape = header.split("'shape': (").nth(1).unwrap().split(')').next().unwrap();
    let dims: Vec<usize> = shape.split(',').filter(|s| !s.trim().is_empty()).map(|s| s.trim().parse().unwrap()).collect();
    assert_eq!(bytes.len(), 10 + len + 4 * dims[0] * dims[1], "payload size");
    (dims[0], dims[1])
}

#[test]
fn data_set_files_labels_and_reproducibility() {
    let dir = tempfile::tempdir().unwrap();
    let models = vec![model(dir.path(), 1), model(dir.path(), 2)];
    let settings = CollectSettings { runs: 3, seed: 5, ..CollectSettings::default() };
    let out = dir.path().join("rem");
    let index = collect(&models, &out, &settings, &|_| {}).unwrap();
    assert_eq!(index.assemblies.len(), 2);
    let json: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(out.join("index.json")).unwrap()).unwrap();
    assert_eq!(json["format"], "asp-removability");
    assert_eq!(json["version"], 1);
    assert_eq!(json["features"], "asp-graph/2 radius_bins=8 degree=8 points=2048");
    let (node_dim, edge_dim) = (json["node_dim"].as_u64().unwrap() as usize, json["edge_dim"].as_u64().unwrap() as usize);
    for (entry, path) in json["assemblies"].as_array().unwrap().iter().zip(&models) {
        let folder = out.join(entry["dir"].as_str().unwrap());
        let graph: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(folder.join("graph.json")).unwrap()).unwrap();
        let n = graph["parts"].as_array().unwrap().len();
        let edges = graph["edges"].as_array().unwrap();
        assert_eq!(npy_shape(&std::fs::read(folder.join("nodes.npy")).unwrap()), (n, node_dim));
        assert_eq!(npy_shape(&std::fs::read(folder.join("edge_attr.npy")).unwrap()), (edges.len(), edge_dim));
        assert!(!edges.is_empty());
        // every label is what the checker says of that part in that state
        let assembly = asp_geom::io::load(path, &Default::default()).unwrap();
        let checker = Checker::new(World::new(assembly, &WorldConfig::default()).unwrap(), CheckerConfig::default());
        let text = std::fs::read_to_string(folder.join("states.jsonl")).unwrap();
        let lines: Vec<serde_json::Value> = text.lines().map(|l| serde_json::from_str(l).unwrap()).collect();
        assert_eq!(lines.len(), entry["states"].as_u64().unwrap() as usize);
        let runs: std::collections::BTreeSet<u64> = lines.iter().map(|l| l["run"].as_u64().unwrap()).collect();
        assert_eq!(runs.len(), 3, "every run recorded states");
        let (mut positives, mut negatives) = (0, 0);
        for l in lines.iter().step_by(7) {
            let present: Vec<usize> = l["present"].as_array().unwrap().iter().map(|v| v.as_u64().unwrap() as usize).collect();
            let removable: Vec<usize> = l["removable"].as_array().unwrap().iter().map(|v| v.as_u64().unwrap() as usize).collect();
            let state = PartSet::from_indices(n, present.iter().copied());
            for &p in present.iter().filter(|&&p| !checker.is_fixed(p)) {
                let free = matches!(checker.test_removal(p, &state, MotionKind::Linear), Outcome::Removed(_));
                assert_eq!(free, removable.contains(&p), "part {p} in state {present:?}");
                if free {
                    positives += 1
                } else {
                    negatives += 1
                }
            }
            assert!(removable.iter().all(|p| present.contains(p) && !checker.is_fixed(*p)));
        }
        assert!(positives > 0 && negatives > 0, "labels of both kinds ({positives} / {negatives})");
    }
    // the same seed gives the same bytes, another seed other states
    let again = dir.path().join("again");
    collect(&models, &again, &settings, &|_| {}).unwrap();
    let other = dir.path().join("other");
    collect(&models, &other, &CollectSettings { seed: 6, ..settings.clone() }, &|_| {}).unwrap();
    let states = |root: &Path| std::fs::read(root.join("soma_1").join("states.jsonl")).unwrap();
    assert_eq!(states(&out), states(&again));
    assert_ne!(states(&out), states(&other));
    assert_eq!(std::fs::read(out.join("soma_1/nodes.npy")).unwrap(), std::fs::read(other.join("soma_1/nodes.npy")).unwrap());
}

#[test]
fn models_with_one_name_in_two_folders_get_distinct_names() {
    let names = asp_app::collect::unique_names(&[PathBuf::from("a/x.glb"), PathBuf::from("b/x.glb"), PathBuf::from("b/y.glb")]);
    assert_eq!(names, ["a_x", "b_x", "y"]);
}

/// The states of one data set's model, as JSON lines.
fn state_lines(out: &Path, dir: &str) -> Vec<serde_json::Value> {
    std::fs::read_to_string(out.join(dir).join("states.jsonl")).unwrap().lines().map(|l| serde_json::from_str(l).unwrap()).collect()
}

fn parts_of(line: &serde_json::Value, key: &str) -> Vec<usize> {
    line[key].as_array().unwrap_or_else(|| panic!("no '{key}' in {line}")).iter().map(|v| v.as_u64().unwrap() as usize).collect()
}

#[test]
fn labels_record_the_checker_and_why_each_part_failed() {
    use asp_app::pipeline::{PlanSettings, StabilitySetting};
    // the arch: pillar_a (1) slides out sideways, and the keystone (3) then rests on pillar_b
    // alone: the contact graph keeps it, the simulation tips it over
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("arch.glb");
    asp_geom::io::write_glb(&asp_geom::fixtures::arch(), &path).unwrap();
    let physics = PlanSettings { stability: StabilitySetting::Physics { threshold: 0.01 }, ..PlanSettings::default() };
    let runs = |plan: PlanSettings, out: &str| {
        let out = dir.path().join(out);
        let settings = CollectSettings { runs: 2, seed: 3, plan, ..CollectSettings::default() };
        let index = collect(std::slice::from_ref(&path), &out, &settings, &|_| {}).unwrap();
        let json: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(out.join("index.json")).unwrap()).unwrap();
        assert_eq!(json["checker"], index.checker);
        (index.checker, state_lines(&out, "arch"))
    };
    let (checker, lines) = runs(physics, "phys");
    assert_eq!(checker, "physics");
    let full = lines.iter().find(|l| parts_of(l, "present") == [0, 1, 2, 3]).expect("the assembled state is recorded");
    assert_eq!(parts_of(full, "removable"), [3]);
    assert_eq!(parts_of(full, "gravity"), [1, 2], "either pillar out tips the keystone over");
    assert_eq!(parts_of(full, "collision"), Vec::<usize>::new());
    // pillar_b with the keystone on it: the keystone is blocked by nothing, the pillar from above
    for l in &lines {
        let present = parts_of(l, "present");
        let (r, c, g) = (parts_of(l, "removable"), parts_of(l, "collision"), parts_of(l, "gravity"));
        let mut labelled: Vec<usize> = r.iter().chain(&c).chain(&g).copied().collect();
        labelled.sort();
        assert_eq!(labelled, present.iter().copied().filter(|&p| p != 0).collect::<Vec<_>>(), "every part once: {l}");
    }
    let (checker, lines) = runs(PlanSettings::default(), "default");
    assert_eq!(checker, "default");
    let full = lines.iter().find(|l| parts_of(l, "present") == [0, 1, 2, 3]).unwrap();
    assert_eq!(parts_of(full, "removable"), [1, 2, 3], "the contact graph lets either pillar go");
    assert!(parts_of(full, "gravity").is_empty());
    // held parts without a robot: refused, not labelled as the default checker (the robot's
    // labels: tests/robot)
    let held = asp_app::resolve(&asp_app::PlanRequest::from_json(r#"{"grippers": 2}"#).unwrap()).unwrap();
    let settings = CollectSettings { runs: 1, plan: held, ..CollectSettings::default() };
    let err = collect(std::slice::from_ref(&path), &dir.path().join("held"), &settings, &|_| {}).unwrap_err().to_string();
    assert!(err.contains("one gripper") && !err.contains('\n'), "{err}");
    assert!(!dir.path().join("held").join("index.json").exists());
}
