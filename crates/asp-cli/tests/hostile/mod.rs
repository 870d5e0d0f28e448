//! Hostile input through the `asp` binary: files generated here (nothing downloaded) that a user
//! may receive from someone else. Each must end with exit code 2 and one line on stderr naming
//! the file, within a second, and write nothing.

use asp_geom::fixtures;
use asp_geom::io::write_glb;
use serde_json::json;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::time::{Duration, Instant};

fn asp(args: &[&str]) -> (Output, Duration) {
    let start = Instant::now();
    let o = Command::new(env!("CARGO_BIN_EXE_asp")).args(args).output().expect("asp runs");
    (o, start.elapsed())
}

/// Runs `args`, which name `file`, in `dir` and checks the rules of hostile input: exit 2, one
/// stderr line naming the file and saying `cause`, under a second, no new file in `dir`.
fn refused(dir: &Path, args: &[&str], file: &Path, cause: &str) {
    let before = listing(dir);
    let (o, took) = asp(args);
    let err = String::from_utf8_lossy(&o.stderr).into_owned();
    assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
    assert_eq!(err.trim_end().lines().count(), 1, "{args:?}: not one line: {err}");
    let name = file.file_name().unwrap().to_string_lossy();
    assert!(err.contains(&*name), "{args:?}: does not name {name}: {err}");
    assert!(err.contains(cause), "{args:?}: does not say '{cause}': {err}");
    assert!(err.len() < 2000, "{args:?}: a {}-byte message", err.len());
    assert!(took < Duration::from_secs(1), "{args:?}: took {took:?}");
    assert_eq!(listing(dir), before, "{args:?}: wrote files");
}

fn listing(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() && !p.is_symlink() {
                stack.push(p.clone());
            }
            out.push(p);
        }
    }
    out.sort();
    out
}

/// `asp plan MODEL --out DIR/plan.json` plus `extra`, refused naming the model.
fn plan_refused(dir: &Path, model: &Path, extra: &[&str], cause: &str) {
    plan_refused_naming(dir, model, extra, model, cause);
}

/// `asp plan MODEL --out DIR/plan.json` plus `extra`, refused naming `named` (a flag's file).
fn plan_refused_naming(dir: &Path, model: &Path, extra: &[&str], named: &Path, cause: &str) {
    let out = dir.join("plan.json");
    let mut args = vec!["plan", model.to_str().unwrap(), "--out", out.to_str().unwrap(), "--quiet"];
    args.extend_from_slice(extra);
    refused(dir, &args, named, cause);
}

/// A GLB of `json` and `bin` with honest chunk lengths.
fn glb(json: &[u8], bin: &[u8]) -> Vec<u8> {
    let mut json = json.to_vec();
    json.resize(json.len().next_multiple_of(4), b' ');
    let mut bin = bin.to_vec();
    bin.resize(bin.len().next_multiple_of(4), 0);
    let total = 12 + 8 + json.len() + if bin.is_empty() { 0 } else { 8 + bin.len() };
    let mut out = b"glTF".to_vec();
    out.extend(2u32.to_le_bytes());
    out.extend((total as u32).to_le_bytes());
    out.extend((json.len() as u32).to_le_bytes());
    out.extend(b"JSON");
    out.extend(json);
    if !bin.is_empty() {
        out.extend((bin.len() as u32).to_le_bytes());
        out.extend(b"BIN\0");
        out.extend(bin);
    }
    out
}

/// Three vertices of one triangle, as float bytes.
fn triangle_bin(points: [[f32; 3]; 3]) -> Vec<u8> {
    points.iter().flatten().flat_map(|c| c.to_le_bytes()).collect()
}

const TRIANGLE: [[f32; 3]; 3] = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];

/// A glTF document whose nodes all instance mesh 0 (one triangle, accessor 0 over buffer 0).
fn document(nodes: serde_json::Value, buffer: serde_json::Value) -> serde_json::Value {
    let count = nodes.as_array().map_or(0, Vec::len);
    json!({
        "asset": {"version": "2.0"},
        "scenes": [{"nodes": (0..count).collect::<Vec<_>>()}],
        "nodes": nodes,
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
        "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                       "min": [0, 0, 0], "max": [1, 1, 0]}],
        "bufferViews": [{"buffer": 0, "byteLength": 36}],
        "buffers": [buffer],
    })
}

fn write(dir: &Path, name: &str, bytes: impl AsRef<[u8]>) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, bytes).unwrap();
    p
}

#[test]
fn models_that_reach_outside_their_folder() {
    let dir = tempfile::tempdir().unwrap();
    let model = dir.path().join("model");
    std::fs::create_dir_all(dir.path().join("other")).unwrap();
    std::fs::create_dir(&model).unwrap();
    let secret = write(dir.path(), "other/secret.bin", triangle_bin(TRIANGLE));
    let nodes = json!([{"name": "a", "mesh": 0}]);
    let up = write(&model, "up.gltf", document(nodes.clone(), json!({"uri": "../other/secret.bin", "byteLength": 36})).to_string());
    plan_refused(
        dir.path(),
        &up,
        &[],
        "points outside the model's folder; asp reads only files inside it (allow with --allow-outside-files)",
    );
    let abs = write(&model, "abs.gltf", document(nodes.clone(), json!({"uri": "/etc/passwd", "byteLength": 36})).to_string());
    plan_refused(dir.path(), &abs, &[], "'/etc/passwd' is an absolute path");
    #[cfg(unix)]
    {
        std::os::unix::fs::symlink(&secret, model.join("link.bin")).unwrap();
        let link = write(&model, "link.gltf", document(nodes, json!({"uri": "link.bin", "byteLength": 36})).to_string());
        plan_refused(dir.path(), &link, &[], "points outside the model's folder");
    }
    // the flag lets the same file through (it is then a one-triangle model: refused for its
    // geometry, no longer for the reference)
    let out = dir.path().join("plan.json");
    let (o, _) = asp(&["plan", up.to_str().unwrap(), "--allow-outside-files", "--out", out.to_str().unwrap(), "--quiet"]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!err.contains("outside"), "{err}");
}

#[test]
fn broken_glb_containers_and_accessors() {
    let dir = tempfile::tempdir().unwrap();
    let good = dir.path().join("good.glb");
    write_glb(&fixtures::tube(), &good).unwrap();
    let bytes = std::fs::read(&good).unwrap();
    std::fs::remove_file(&good).unwrap();
    let truncated = write(dir.path(), "truncated.glb", &bytes[..bytes.len() / 2]);
    plan_refused(dir.path(), &truncated, &[], "truncated glb");
    // the file length patched to match, the JSON chunk's length past the end
    let mut past = bytes.clone();
    past[12..16].copy_from_slice(&(bytes.len() as u32 * 4).to_le_bytes());
    let past = write(dir.path(), "chunk_past_end.glb", past);
    plan_refused(dir.path(), &past, &[], "a chunk announces");
    let mut cut = bytes[..bytes.len() - 5].to_vec();
    let n = cut.len() as u32;
    cut[8..12].copy_from_slice(&n.to_le_bytes());
    let cut = write(dir.path(), "chunk_cut.glb", cut);
    plan_refused(dir.path(), &cut, &[], "truncated glb");

    let bin = triangle_bin(TRIANGLE);
    let doc = |nodes: serde_json::Value| document(nodes, json!({"byteLength": 36}));
    // a name that is not UTF-8
    let mut json = doc(json!([{"name": "NAME", "mesh": 0}])).to_string().into_bytes();
    let at = json.windows(4).position(|w| w == b"NAME").unwrap();
    json[at] = 0xff;
    let non_utf8 = write(dir.path(), "non_utf8.glb", glb(&json, &bin));
    plan_refused(dir.path(), &non_utf8, &[], "invalid gltf json");
    // a 1 MB name
    let long = write(dir.path(), "long_name.glb", glb(doc(json!([{"name": "x".repeat(1 << 20), "mesh": 0}])).to_string().as_bytes(), &bin));
    plan_refused(dir.path(), &long, &[], "its name has 1048576 bytes");
    // duplicate names on the same mesh at the same place
    let twice = write(
        dir.path(),
        "duplicate.glb",
        glb(doc(json!([{"name": "a", "mesh": 0}, {"name": "a", "mesh": 0}])).to_string().as_bytes(), &bin),
    );
    // ... is a common export slip: planned with one copy, and a warning in the plan
    let (o, _) = asp(&["plan", twice.to_str().unwrap(), "--json", "--quiet"]);
    assert_ne!(o.status.code(), Some(2), "{}", String::from_utf8_lossy(&o.stderr));
    let plan: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(plan["parts"].as_array().unwrap().len(), 1);
    assert!(plan["warnings"].to_string().contains("parts 'a' and 'a_2' are the same mesh at the same place (a duplicate)"), "{plan}");
    // an accessor count past the buffer's end
    let mut over = doc(json!([{"name": "a", "mesh": 0}]));
    over["accessors"][0]["count"] = json!(3000);
    let over = write(dir.path(), "count_past_end.glb", glb(over.to_string().as_bytes(), &bin));
    plan_refused(dir.path(), &over, &[], "read past the end");
    // ... or announcing more triangles than the cap: refused before anything is read
    let mut huge = doc(json!([{"name": "a", "mesh": 0}]));
    huge["accessors"][0]["count"] = json!(1_000_000_000u64);
    let huge = write(dir.path(), "count_huge.glb", glb(huge.to_string().as_bytes(), &bin));
    plan_refused(
        dir.path(),
        &huge,
        &[],
        "more than 20000000 triangles (the model announces 333333333; raise the cap with --max-triangles)",
    );
    // sparse indices out of range
    let mut sparse = doc(json!([{"name": "a", "mesh": 0}]));
    let mut sbin = bin.clone();
    sbin.extend(200u32.to_le_bytes());
    sbin.extend(triangle_bin(TRIANGLE)[..12].to_vec());
    sparse["bufferViews"] = json!([{"buffer": 0, "byteLength": 36}, {"buffer": 0, "byteOffset": 36, "byteLength": 4},
                                   {"buffer": 0, "byteOffset": 40, "byteLength": 12}]);
    sparse["accessors"][0]["sparse"] = json!({"count": 1, "indices": {"bufferView": 1, "componentType": 5125},
                                               "values": {"bufferView": 2}});
    sparse["buffers"] = json!([{"byteLength": sbin.len()}]);
    let sparse = write(dir.path(), "sparse_out_of_range.glb", glb(sparse.to_string().as_bytes(), &sbin));
    plan_refused(dir.path(), &sparse, &[], "sparse index 200 is out of range");
    // a node cycle
    let mut cycle = doc(json!([{"name": "a", "mesh": 0, "children": [1]}, {"name": "b", "children": [0]}]));
    cycle["scenes"] = json!([{"nodes": [0]}]);
    let cycle = write(dir.path(), "cycle.glb", glb(cycle.to_string().as_bytes(), &bin));
    plan_refused(dir.path(), &cycle, &[], "reached twice");
    // a NaN transform
    let mut nan = doc(json!([{"name": "a", "mesh": 0, "matrix": [1,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,0,1]}]));
    nan["nodes"][0]["matrix"][12] = json!(1e39);
    let nan = write(dir.path(), "infinite_transform.glb", glb(nan.to_string().as_bytes(), &bin));
    plan_refused(dir.path(), &nan, &[], "node 0 ('a'): its transform has NaN or infinite values");
}

#[test]
fn degenerate_models_and_caps() {
    let dir = tempfile::tempdir().unwrap();
    let doc = |points: [[f32; 3]; 3]| (document(json!([{"name": "flat", "mesh": 0}]), json!({"byteLength": 36})), triangle_bin(points));
    let (point, bin) = doc([[1.0, 1.0, 1.0]; 3]);
    let point = write(dir.path(), "point.glb", glb(point.to_string().as_bytes(), &bin));
    plan_refused(dir.path(), &point, &[], "the model has zero extent");
    // a part whose triangles all have zero area beside a proper one
    let mut line = document(json!([{"name": "ok", "mesh": 0}, {"name": "line", "mesh": 1}]), json!({"byteLength": 72}));
    line["meshes"] = json!([{"primitives": [{"attributes": {"POSITION": 0}}]}, {"primitives": [{"attributes": {"POSITION": 1}}]}]);
    line["accessors"] = json!([{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]},
                                {"bufferView": 1, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0, 0, 0], "max": [2, 0, 0]}]);
    line["bufferViews"] = json!([{"buffer": 0, "byteLength": 36}, {"buffer": 0, "byteOffset": 36, "byteLength": 36}]);
    let mut bin = triangle_bin(TRIANGLE);
    bin.extend(triangle_bin([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]]));
    let line = write(dir.path(), "line.glb", glb(line.to_string().as_bytes(), &bin));
    plan_refused(dir.path(), &line, &[], "part 'line': all its 1 triangles have zero area");
    // OBJ indices past the vertex list
    let obj = write(dir.path(), "bad.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 99\n");
    plan_refused(dir.path(), &obj, &[], "index out of bounds");
    // the caps: a real model over --max-triangles / --max-parts
    let tube = dir.path().join("tube.glb");
    write_glb(&fixtures::tube(), &tube).unwrap();
    plan_refused(dir.path(), &tube, &["--max-triangles", "10"], "--max-triangles");
    plan_refused(dir.path(), &tube, &["--max-parts", "2"], "--max-parts");
    // a binary STL whose header announces 100 M triangles (the size does not match: refused as such)
    let mut stl = vec![0u8; 80];
    stl.extend(100_000_000u32.to_le_bytes());
    stl.extend([0u8; 50]);
    let stl = write(dir.path(), "liar.stl", stl);
    plan_refused(dir.path(), &stl, &[], "invalid stl file");
}

/// A one-joint arm; `extra` goes inside `<robot>`.
fn urdf(base_mesh: &str, extra: &str) -> String {
    format!(
        r#"<robot name="r">
          <link name="base"><collision><geometry><mesh filename="{base_mesh}"/></geometry></collision></link>
          <link name="tool0"/>
          <joint name="j1" type="revolute"><parent link="base"/><child link="tool0"/><axis xyz="0 0 1"/>
            <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>{extra}
        </robot>"#
    )
}

#[test]
fn robots_that_cannot_work() {
    let dir = tempfile::tempdir().unwrap();
    let tube = dir.path().join("tube.glb");
    write_glb(&fixtures::tube(), &tube).unwrap();
    write(dir.path(), "base.stl", "solid x\nendsolid x\n");
    let cases = [
        ("abs_mesh.urdf", urdf("/etc/passwd", ""), "is an absolute path"),
        ("pkg_up.urdf", urdf("package://p/../../secret.stl", ""), "--package-path p=DIR"),
        ("missing_mesh.urdf", urdf("gone.stl", ""), "is missing"),
        ("no_gripper.urdf", urdf("base.stl", ""), "no gripper below tool link 'tool0'"),
        (
            "missing_link.urdf",
            urdf("base.stl", r#"<joint name="j2" type="fixed"><parent link="tool0"/><child link="ghost"/></joint>"#),
            "unknown child link 'ghost'",
        ),
        ("loop.urdf", urdf("base.stl", r#"<joint name="j2" type="fixed"><parent link="tool0"/><child link="base"/></joint>"#), "root link"),
        ("inverted.urdf", urdf("base.stl", "").replace(r#"lower="-1" upper="1""#, r#"lower="1" upper="-1""#), "need finite lower"),
        ("not_xml.urdf", "<robot name=\"r\"><link".to_string(), "not a valid URDF"),
    ];
    for (name, text, cause) in cases {
        let file = write(dir.path(), name, text);
        plan_refused_naming(dir.path(), &tube, &["--robot", file.to_str().unwrap()], &file, cause);
    }
    // a package path the user names lets package:// meshes in
    std::fs::create_dir(dir.path().join("pkg")).unwrap();
    write(dir.path(), "pkg/base.stl", "solid x\nendsolid x\n");
    let pkg = write(dir.path(), "pkg.urdf", urdf("package://p/base.stl", ""));
    let flag = format!("p={}", dir.path().join("pkg").display());
    let (o, _) = asp(&["robot", "check", pkg.to_str().unwrap(), "--package-path", &flag, "--samples", "10", "--trials", "2"]);
    assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
}

#[test]
fn onnx_files_and_plan_json_of_other_kinds() {
    let dir = tempfile::tempdir().unwrap();
    let tube = dir.path().join("tube.glb");
    write_glb(&fixtures::tube(), &tube).unwrap();
    let shipped = std::fs::read(concat!(env!("CARGO_MANIFEST_DIR"), "/../../models/removability.onnx")).unwrap();
    let truncated = write(dir.path(), "truncated.onnx", &shipped[..shipped.len() / 3]);
    plan_refused_naming(dir.path(), &tube, &["--order", "gnn", "--model", truncated.to_str().unwrap()], &truncated, "not an ONNX model");
    let garbage = write(dir.path(), "garbage.onnx", b"not a model at all".repeat(10));
    plan_refused_naming(dir.path(), &tube, &["--order", "gnn", "--model", garbage.to_str().unwrap()], &garbage, "not an ONNX model");
    let q = concat!(env!("CARGO_MANIFEST_DIR"), "/../../models/qfunction.onnx");
    if Path::new(q).exists() {
        let other = write(dir.path(), "other_model.onnx", std::fs::read(q).unwrap());
        plan_refused_naming(dir.path(), &tube, &["--order", "gnn", "--model", other.to_str().unwrap()], &other, "");
    }

    // plan JSON: a real plan, truncated, and of another format version
    let plan = dir.path().join("plan.json");
    let (o, _) = asp(&["plan", tube.to_str().unwrap(), "--out", plan.to_str().unwrap(), "--quiet"]);
    assert_eq!(o.status.code(), Some(0));
    let text = std::fs::read_to_string(&plan).unwrap();
    let cut = write(dir.path(), "cut.json", &text[..text.len() / 2]);
    let mut other: serde_json::Value = serde_json::from_str(&text).unwrap();
    other["format_version"] = json!("9.0");
    let other = write(dir.path(), "v9.json", other.to_string());
    for (file, cause) in [(&cut, "not a plan JSON"), (&other, "plan format version 9.0")] {
        for command in ["view", "render"] {
            let out = dir.path().join(if command == "view" { "page.html" } else { "board.png" });
            refused(dir.path(), &[command, file.to_str().unwrap(), "--out", out.to_str().unwrap()], file, cause);
        }
    }
}

/// The peak resident memory (bytes) of `asp ARGS` and its exit code, from `/usr/bin/time`
/// (None where it is not installed).
fn peak_memory(args: &[&str]) -> Option<(u64, Option<i32>)> {
    let time = Path::new("/usr/bin/time");
    if !time.exists() {
        eprintln!("skipped: /usr/bin/time is not installed");
        return None;
    }
    let o = Command::new(time).arg("-f").arg("peak_kb=%M").arg(env!("CARGO_BIN_EXE_asp")).args(args).output().unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    let kb: u64 = err.lines().find_map(|l| l.strip_prefix("peak_kb=")).and_then(|v| v.trim().parse().ok()).expect("a peak");
    // time's own exit code is the command's
    Some((kb * 1024, o.status.code()))
}

#[test]
fn peak_memory_on_hostile_files_stays_within_ten_times_their_size() {
    const FIXED: u64 = 200 << 20;
    let dir = tempfile::tempdir().unwrap();
    // an instancing bomb: one mesh of 2,500 triangles placed by 10,000 nodes (25 M triangles)
    let n = 2500;
    let mut positions = Vec::new();
    for i in 0..n {
        let x = i as f32;
        positions.extend([[x, 0.0, 0.0], [x + 1.0, 0.0, 0.0], [x, 1.0, 0.0]]);
    }
    let bin: Vec<u8> = positions.iter().flatten().flat_map(|c: &f32| c.to_le_bytes()).collect();
    let nodes: Vec<serde_json::Value> = (0..10_000).map(|i| json!({"mesh": 0, "translation": [0, 0, i]})).collect();
    let mut bomb = document(json!(nodes), json!({"byteLength": bin.len()}));
    bomb["accessors"][0]["count"] = json!(3 * n);
    bomb["accessors"][0]["max"] = json!([n, 1, 0]);
    bomb["bufferViews"][0]["byteLength"] = json!(bin.len());
    let bomb = write(dir.path(), "instances.glb", glb(bomb.to_string().as_bytes(), &bin));
    // a position accessor of many zeros without a buffer view (sparse over nothing)
    let mut zeros = document(json!([{"mesh": 0}]), json!({"byteLength": 36}));
    zeros["accessors"][0] = json!({"componentType": 5126, "count": 1u64 << 30, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]});
    let zeros = write(dir.path(), "zeros.glb", glb(zeros.to_string().as_bytes(), &triangle_bin(TRIANGLE)));
    // a binary STL whose header announces 50 M triangles over a file of a few bytes
    let mut stl = vec![0u8; 80];
    stl.extend(50_000_000u32.to_le_bytes());
    stl.extend([0u8; 100]);
    let stl = write(dir.path(), "liar.stl", stl);
    for file in [&bomb, &zeros, &stl] {
        let size = std::fs::metadata(file).unwrap().len();
        let out = dir.path().join("plan.json");
        let Some((peak, code)) =
            peak_memory(&["plan", file.to_str().unwrap(), "--out", out.to_str().unwrap(), "--quiet", "--timeout", "5"])
        else {
            return;
        };
        assert_eq!(code, Some(2), "{} is refused", file.display());
        assert!(peak <= 10 * size + FIXED, "{}: peak {} MB for a file of {} kB", file.display(), peak >> 20, size >> 10);
    }
}
