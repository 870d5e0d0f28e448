//! Broken input: missing, truncated and corrupted files, hostile accessors and metadata, each a
//! one-line error naming the file and the cause, never a panic.

use super::*;

#[test]
fn a_missing_file_is_named() {
    let dir = tempfile::tempdir().unwrap();
    for name in ["nope.glb", "nope.gltf", "no_folder"] {
        assert_message(&load_error(&dir.path().join(name)), name, "no such file or directory");
    }
}

#[test]
fn a_truncated_glb_is_reported() {
    let dir = tempfile::tempdir().unwrap();
    let beam = std::fs::read(data("beam/beam.glb")).unwrap();
    for keep in [4, 11, 40, beam.len() / 2, beam.len() - 1] {
        let path = dir.path().join("truncated.glb");
        std::fs::write(&path, &beam[..keep]).unwrap();
        assert_message(&load_error(&path), "truncated.glb", "truncated glb");
    }
}

#[test]
fn a_corrupted_glb_is_reported() {
    let dir = tempfile::tempdir().unwrap();
    let beam = std::fs::read(data("beam/beam.glb")).unwrap();
    let path = dir.path().join("corrupted.glb");

    let mut bad_json = beam.clone();
    bad_json[20..24].copy_from_slice(b"!!!!");
    std::fs::write(&path, &bad_json).unwrap();
    assert_message(&load_error(&path), "corrupted.glb", "invalid gltf json");

    let mut bad_magic = beam.clone();
    bad_magic[0] = b'x';
    std::fs::write(&path, &bad_magic).unwrap();
    assert_message(&load_error(&path), "corrupted.glb", "not a glb file");

    let mut bad_version = beam.clone();
    bad_version[4] = 1;
    std::fs::write(&path, &bad_version).unwrap();
    assert_message(&load_error(&path), "corrupted.glb", "unsupported glb version 1");

    // a binary chunk shorter than the buffer it holds
    let mut f = Fixture::default();
    let positions = f.positions(&TRIANGLE);
    let mut document = f.document(single_mesh(positions, None), json!({}));
    document["buffers"][0]["byteLength"] = json!(f.bin.len() + 100);
    std::fs::write(&path, glb(document.to_string().into_bytes(), f.bin.clone())).unwrap();
    assert_message(&load_error(&path), "corrupted.glb", "truncated buffer 0");

    // the BIN chunk is missing altogether
    std::fs::write(&path, glb(document.to_string().into_bytes(), Vec::new())).unwrap();
    assert_message(&load_error(&path), "corrupted.glb", "no binary chunk");
}

#[test]
fn invalid_accessors_are_errors_not_panics() {
    let dir = tempfile::tempdir().unwrap();
    let mut f = Fixture::default();
    let positions = f.positions(&TRIANGLE);
    let indices = f.indices(&[0, 1, 7]);
    let too_long = f.accessor(json!({"bufferView": 0, "componentType": 5126, "count": 1000, "type": "VEC3",
                                     "min": [0, 0, 0], "max": [1, 1, 0]}));
    let vec2 = f.accessor(json!({"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC2",
                                 "min": [0, 0, 0], "max": [1, 1, 0]}));
    let float_indices = f.accessor(json!({"bufferView": 0, "componentType": 5126, "count": 3, "type": "SCALAR"}));
    let bad_stride_view = f.views.len();
    f.views.push(json!({"buffer": 0, "byteOffset": 0, "byteLength": 36, "byteStride": 8}));
    let bad_stride = f.accessor(json!({"bufferView": bad_stride_view, "componentType": 5126, "count": 3,
                                       "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]}));
    let outside_view = f.views.len();
    f.views.push(json!({"buffer": 0, "byteOffset": 0, "byteLength": 100000}));
    let outside = f.accessor(json!({"bufferView": outside_view, "componentType": 5126, "count": 3,
                                    "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]}));
    let cases = [
        (single_mesh(too_long, None), "read past the end"),
        (single_mesh(vec2, None), "unsupported type vec2"),
        (single_mesh(positions, Some(indices)), "index 7 is out of range"),
        (single_mesh(positions, Some(float_indices)), "expected scalar unsigned integers"),
        (single_mesh(bad_stride, None), "byte stride 8 is smaller"),
        (single_mesh(outside, None), "lies outside buffer 0"),
        (single_mesh(99, None), "accessor 99 which does not exist"),
    ];
    for (content, cause) in cases {
        let path = write_gltf(dir.path(), "accessors.gltf", &f, content);
        assert_message(&load_error(&path), "accessors.gltf", cause);
    }
}

#[test]
fn an_empty_scene_has_no_parts() {
    let dir = tempfile::tempdir().unwrap();
    let mut f = Fixture::default();
    let positions = f.positions(&TRIANGLE);
    let mesh = json!([{"primitives": [{"attributes": {"POSITION": positions}}]}]);
    let cases = [
        json!({"scenes": [{"nodes": []}], "nodes": [{"mesh": 0}], "meshes": mesh}),
        json!({"nodes": [{"mesh": 0}], "meshes": mesh}),
        json!({"scenes": [{"nodes": [0]}], "nodes": [{"name": "empty"}], "meshes": mesh}),
    ];
    for content in cases {
        let path = write_gltf(dir.path(), "empty.gltf", &f, content);
        assert_message(&load_error(&path), "empty.gltf", "the model has no parts");
    }
    // a scene of points only: no part, one warning each, so no parts either
    let points = json!({"scenes": [{"nodes": [0]}], "nodes": [{"name": "dots", "mesh": 0}],
                        "meshes": [{"primitives": [{"attributes": {"POSITION": positions}, "mode": 0}]}]});
    let path = write_gltf(dir.path(), "points.gltf", &f, points);
    assert_message(&load_error(&path), "points.gltf", "the model has no parts");
}

#[test]
fn nan_vertices_name_the_part() {
    let dir = tempfile::tempdir().unwrap();
    let mut f = Fixture::default();
    let positions = f.positions(&[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]);
    // overwrite one coordinate of the buffer with NaN (JSON min/max stay valid numbers)
    f.bin[4..8].copy_from_slice(&f32::NAN.to_le_bytes());
    let path = write_gltf(dir.path(), "nan.gltf", &f, single_mesh(positions, None));
    assert_message(&load_error(&path), "nan.gltf", "part 'the_part' has NaN");
}

#[test]
fn node_cycles_and_bad_metadata_are_errors() {
    let dir = tempfile::tempdir().unwrap();
    let mut f = Fixture::default();
    let positions = f.positions(&TRIANGLE);
    let mesh = json!([{"primitives": [{"attributes": {"POSITION": positions}}]}]);
    let cycle = json!({"scenes": [{"nodes": [0]}], "meshes": mesh,
                       "nodes": [{"mesh": 0, "children": [1]}, {"mesh": 0, "children": [0]}]});
    let path = write_gltf(dir.path(), "cycle.gltf", &f, cycle);
    assert_message(&load_error(&path), "cycle.gltf", "reached twice");

    let bad_fixed = json!({"scenes": [{"nodes": [0]}], "meshes": mesh,
                           "nodes": [{"name": "p", "mesh": 0, "extras": {"asp": {"fixed": "yes"}}}]});
    let path = write_gltf(dir.path(), "fixed.gltf", &f, bad_fixed);
    assert_message(&load_error(&path), "fixed.gltf", "extras.asp.fixed must be true or false");

    let bad_unit = json!({"scenes": [{"nodes": [0], "extras": {"asp": {"unit": "furlong"}}}], "meshes": mesh,
                          "nodes": [{"mesh": 0}]});
    let path = write_gltf(dir.path(), "unit.gltf", &f, bad_unit);
    assert_message(&load_error(&path), "unit.gltf", "'furlong' is not a known unit");
}

#[test]
fn bad_files_in_folders_are_named() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("readme.txt"), "no meshes here").unwrap();
    assert_message(&load_error(dir.path()), &dir.path().display().to_string(), "no .obj or .stl files");

    let stl = dir.path().join("broken.stl");
    std::fs::write(&stl, "solid broken\n facet normal 0 0 1\n  outer loop\n   vertex 0 0 x\n").unwrap();
    assert_message(&load_error(dir.path()), "broken.stl", "invalid stl file");
    std::fs::remove_file(&stl).unwrap();

    let mut truncated = binary_stl(&[TRIANGLE, TRIANGLE]);
    truncated.truncate(100);
    std::fs::write(&stl, truncated).unwrap();
    assert_message(&load_error(&stl), "broken.stl", "invalid stl file");
    std::fs::remove_file(&stl).unwrap();

    let obj = dir.path().join("broken.obj");
    std::fs::write(&obj, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n").unwrap();
    assert_message(&load_error(dir.path()), "broken.obj", "invalid obj file");

    let ply = dir.path().join("model.ply");
    std::fs::write(&ply, "ply").unwrap();
    assert_message(&load_error(&ply), "model.ply", "unknown file type");
}

/// A deterministic pseudo-random sequence (64-bit LCG) for the corruption test.
struct Lcg(u64);

impl Lcg {
    fn below(&mut self, n: usize) -> usize {
        self.0 = self.0.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        ((self.0 >> 33) as usize) % n.max(1)
    }
}

/// Sets a few fields of the document's accessors, views, nodes, meshes... to hostile values.
fn corrupt_json(json: &mut Value, rng: &mut Lcg) {
    let hostile = [
        json!(0),
        json!(-1),
        json!(1),
        json!(3),
        json!(4294967295u64),
        json!(1e30),
        json!(null),
        json!("x"),
        json!(100000),
        json!([0, 1]),
        json!(5121),
        json!(5126),
        json!("VEC3"),
        json!("SCALAR"),
        json!("MAT4"),
        json!({"count": 1}),
    ];
    let arrays = ["accessors", "bufferViews", "nodes", "meshes", "scenes", "buffers"];
    let extra = ["byteStride", "sparse", "children", "matrix", "rotation", "mode", "indices", "byteOffset"];
    for _ in 0..1 + rng.below(3) {
        let array = arrays[rng.below(arrays.len())];
        let len = json[array].as_array().map_or(0, Vec::len);
        let item = &mut json[array][rng.below(len)];
        let keys: Vec<String> = item.as_object().map(|o| o.keys().cloned().collect()).unwrap_or_default();
        let key = match rng.below(3) {
            0 => extra[rng.below(extra.len())].to_string(),
            _ if keys.is_empty() => continue,
            _ => keys[rng.below(keys.len())].clone(),
        };
        item[key.as_str()] = hostile[rng.below(hostile.len())].clone();
    }
}

/// Random byte flips and hostile JSON values give errors, never panics.
#[test]
fn corrupted_files_never_panic() {
    let dir = tempfile::tempdir().unwrap();
    let original = std::fs::read(data("ikea/desk_hannes_0529.glb")).unwrap();
    let json_length = u32::from_le_bytes(original[12..16].try_into().unwrap()) as usize;
    let json: Value = serde_json::from_slice(&original[20..20 + json_length]).unwrap();
    let bin = original[20 + json_length + 8..].to_vec();
    let mut rng = Lcg(12345);
    let path = dir.path().join("corrupted.glb");
    for round in 0..600 {
        let bytes = if round % 2 == 0 {
            let mut bytes = original.clone();
            for _ in 0..1 + rng.below(4) {
                let at = rng.below(bytes.len());
                bytes[at] = rng.below(256) as u8;
            }
            bytes
        } else {
            let mut json = json.clone();
            corrupt_json(&mut json, &mut rng);
            glb(json.to_string().into_bytes(), bin.clone())
        };
        std::fs::write(&path, &bytes).unwrap();
        if let Err(e) = load(&path, &LoadOptions::default()) {
            assert_message(&e.to_string(), "corrupted.glb", "");
        }
    }
}
