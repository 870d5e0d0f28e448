//! Loaders and the GLB writer: the real models of `tests/data`, hand-written glTF files checked
//! numerically, broken files of every kind, and write → load round trips.

use asp_geom::io::{load, write_glb, LoadOptions};
use asp_geom::math::{Axis, Vec3};
use asp_geom::{Assembly, Mesh, Part, Units};
use serde_json::{json, Value};
use std::path::{Path, PathBuf};

mod broken;

const DATA: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../tests/data");

fn data(relative: &str) -> PathBuf {
    Path::new(DATA).join(relative)
}

fn with_unit(unit: &str) -> LoadOptions {
    LoadOptions { unit: Units::parse(unit), ..Default::default() }
}

fn size(assembly: &Assembly) -> Vec3 {
    let b = assembly.aabb().expect("an assembly with vertices");
    b.maxs - b.mins
}

fn assert_near(actual: Vec3, expected: Vec3, tolerance: f32) {
    assert!((actual - expected).abs().max_element() <= tolerance, "{actual:?} != {expected:?} (± {tolerance})");
}

fn names(assembly: &Assembly) -> Vec<&str> {
    assembly.parts.iter().map(|p| p.name.as_str()).collect()
}

/// The error message of a load that must fail.
fn load_error(path: &Path) -> String {
    match load(path, &LoadOptions::default()) {
        Ok(a) => panic!("{} loaded with {} parts but should fail", path.display(), a.len()),
        Err(e) => e.to_string(),
    }
}

fn assert_message(message: &str, file: &str, cause: &str) {
    assert!(message.contains(file), "'{message}' does not name '{file}'");
    assert!(message.contains(cause), "'{message}' does not say '{cause}'");
    assert!(!message.contains('\n'), "'{message}' is not one line");
}

// ---------------------------------------------------------------------------------------------
// Real models

#[test]
fn beam_glb_has_five_named_parts() {
    let beam = load(&data("beam/beam.glb"), &with_unit("1")).unwrap();
    assert_eq!(names(&beam), ["part_0", "part_1", "part_2", "part_3", "part_6"]);
    assert_near(size(&beam), Vec3::new(15.24, 7.62, 7.874), 0.01);
    assert_eq!(beam.up, Axis::Y, "the file has no extras.asp.up: glTF's +Y");
    assert!(beam.warnings.is_empty(), "{:?}", beam.warnings);
    assert!(beam.parts.iter().all(|p| !p.fixed && p.mesh.topology().is_closed_manifold()));
}

#[test]
fn ikea_models_have_their_part_counts() {
    let expected = [
        ("bed_dalselv_0270", 10),
        ("bookcase_billy_0191", 11),
        ("bookcase_grevback_0484", 14),
        ("cabinet_akurum_0011", 5),
        ("chair_bertil_0148", 5),
        ("desk_hannes_0529", 9),
        ("table_hemnes_0541", 11),
        ("table_lack_0825", 5),
    ];
    for (model, parts) in expected {
        let assembly = load(&data(&format!("ikea/{model}.glb")), &LoadOptions::default()).unwrap();
        assert_eq!(assembly.len(), parts, "{model}");
        assert_eq!(assembly.units, Units::metres(), "{model}");
        // the only warnings: parts drawn as several bodies (the bed's slats, the chair's legs)
        assert!(assembly.warnings.iter().all(|w| w.contains("separate bodies")), "{model}: {:?}", assembly.warnings);
        // furniture, in metres: between 20 cm and 2 m across
        let diagonal = assembly.diagonal();
        assert!((0.2..2.0).contains(&diagonal), "{model}: diagonal {diagonal}");
        assert!(assembly.parts.iter().all(|p| p.mesh.signed_volume() > 0.0), "{model}: inside-out part");
    }
}

#[test]
fn lack_table_legs_are_placed_by_their_node_transforms() {
    let lack = load(&data("ikea/table_lack_0825.glb"), &LoadOptions::default()).unwrap();
    // the four legs share one shape; their nodes translate them to ±0.305, ±0.105
    let centre = |i: usize| lack.parts[i].mesh.aabb().unwrap().center();
    for (i, (x, y)) in [(0, (-0.305, -0.105)), (2, (0.305, -0.105))] {
        assert_near(Vec3::new(centre(i).x, centre(i).y, 0.0), Vec3::new(x, y, 0.0), 0.02);
    }
}

#[test]
fn pump_folder_has_fifteen_parts_named_after_the_files() {
    let pump = load(&data("pump"), &with_unit("mm")).unwrap();
    assert_eq!(pump.len(), 15);
    assert_eq!(pump.parts[0].name, "PumpAssembly - BackLid2-1");
    assert_eq!(pump.parts[14].name, "PumpAssembly - Shaft-1");
    let mut sorted = names(&pump);
    sorted.sort();
    assert_eq!(sorted, names(&pump), "parts in file-name order");
    assert_near(size(&pump), Vec3::new(0.176, 0.135, 0.135), 0.001);
    assert_eq!(pump.up, Axis::Z);
    assert_eq!(pump.units.name, "mm");
}

// ---------------------------------------------------------------------------------------------
// Hand-written glTF

/// Builds the binary buffer and the accessor / buffer view arrays of a test glTF file.
#[derive(Default)]
struct Fixture {
    bin: Vec<u8>,
    views: Vec<Value>,
    accessors: Vec<Value>,
}

impl Fixture {
    fn view(&mut self, bytes: Vec<u8>) -> usize {
        self.bin.resize(self.bin.len().next_multiple_of(4), 0);
        self.views.push(json!({"buffer": 0, "byteOffset": self.bin.len(), "byteLength": bytes.len()}));
        self.bin.extend(bytes);
        self.views.len() - 1
    }

    fn positions(&mut self, points: &[[f32; 3]]) -> usize {
        let view = self.view(points.iter().flatten().flat_map(|c| c.to_le_bytes()).collect());
        let axis = |k: usize, pick: fn(f32, f32) -> f32| points.iter().map(|p| p[k]).fold(points[0][k], pick);
        let min: Vec<f32> = (0..3).map(|k| axis(k, f32::min)).collect();
        let max: Vec<f32> = (0..3).map(|k| axis(k, f32::max)).collect();
        self.accessor(json!({"bufferView": view, "componentType": 5126, "count": points.len(),
                             "type": "VEC3", "min": min, "max": max}))
    }

    fn indices(&mut self, indices: &[u16]) -> usize {
        let view = self.view(indices.iter().flat_map(|i| i.to_le_bytes()).collect());
        self.accessor(json!({"bufferView": view, "componentType": 5123, "count": indices.len(), "type": "SCALAR"}))
    }

    fn accessor(&mut self, accessor: Value) -> usize {
        self.accessors.push(accessor);
        self.accessors.len() - 1
    }

    /// The complete glTF JSON: `content` (scenes, nodes, meshes) plus the data, whose single
    /// buffer is `buffer` (its `byteLength` is filled in).
    fn document(&self, mut content: Value, mut buffer: Value) -> Value {
        buffer["byteLength"] = json!(self.bin.len());
        content["asset"] = json!({"version": "2.0"});
        content["accessors"] = json!(self.accessors);
        content["bufferViews"] = json!(self.views);
        content["buffers"] = json!([buffer]);
        content
    }

    /// A `.gltf` with the buffer embedded as a base64 data URI.
    fn embedded(&self, content: Value) -> String {
        let uri = format!("data:application/octet-stream;base64,{}", base64(&self.bin));
        self.document(content, json!({"uri": uri})).to_string()
    }

    /// A `.glb` with the buffer in the BIN chunk.
    fn glb(&self, content: Value) -> Vec<u8> {
        glb(self.document(content, json!({})).to_string().into_bytes(), self.bin.clone())
    }
}

/// A GLB file; without a BIN chunk when `bin` is empty.
fn glb(mut json: Vec<u8>, mut bin: Vec<u8>) -> Vec<u8> {
    json.resize(json.len().next_multiple_of(4), b' ');
    bin.resize(bin.len().next_multiple_of(4), 0);
    let mut chunks = vec![(b"JSON", json)];
    if !bin.is_empty() {
        chunks.push((b"BIN\0", bin));
    }
    let total = 12 + chunks.iter().map(|(_, c)| 8 + c.len()).sum::<usize>();
    let mut out = b"glTF".to_vec();
    out.extend(2u32.to_le_bytes());
    out.extend((total as u32).to_le_bytes());
    for (kind, chunk) in chunks {
        out.extend((chunk.len() as u32).to_le_bytes());
        out.extend(kind);
        out.extend(chunk);
    }
    out
}

fn base64(bytes: &[u8]) -> String {
    const ALPHABET: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::new();
    for chunk in bytes.chunks(3) {
        let byte = |k: usize| u32::from(chunk.get(k).copied().unwrap_or(0));
        let n = byte(0) << 16 | byte(1) << 8 | byte(2);
        for k in 0..4 {
            let sextet = (n >> (18 - 6 * k)) as usize & 63;
            out.push(if k <= chunk.len() { ALPHABET[sextet] as char } else { '=' });
        }
    }
    out
}

const TRIANGLE: [[f32; 3]; 3] = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];

/// A scene with nesting, both transform kinds, an instanced mesh, a mirrored instance and a
/// mesh of several primitives (triangles, an unindexed strip, lines); its default scene is the
/// second one, in millimetres with +Z up. Returns the fixture and the JSON content.
fn nested_scene() -> (Fixture, Value) {
    let mut f = Fixture::default();
    let tri_positions = f.positions(&TRIANGLE);
    let tri_indices = f.indices(&[0, 1, 2]);
    let strip = f.positions(&[[0.0, 0.0, 1.0], [1.0, 0.0, 1.0], [0.0, 1.0, 1.0], [1.0, 1.0, 1.0]]);
    let s = std::f32::consts::FRAC_1_SQRT_2;
    let content = json!({
        "scene": 1,
        "scenes": [
            {"nodes": [4]},
            {"nodes": [0, 3, 5], "extras": {"asp": {"unit": "mm", "up": "+z"}}},
        ],
        "nodes": [
            {"name": "parent", "rotation": [0.0, 0.0, s, s], "translation": [10.0, 0.0, 0.0],
             "children": [1, 2]},
            {"name": "child", "mesh": 0,
             "matrix": [2.0, 0.0, 0.0, 0.0, 0.0, 2.0, 0.0, 0.0, 0.0, 0.0, 2.0, 0.0, 0.0, 0.0, 5.0, 1.0]},
            {"mesh": 0, "translation": [0.0, 3.0, 0.0]},
            {"name": "multi", "mesh": 1,
             "extras": {"asp": {"fixed": true, "grasp": [[1, 2, 3]]}, "other_tool": 1}},
            {"name": "not in the default scene", "mesh": 0},
            {"name": "mirror", "mesh": 0, "scale": [-1.0, 1.0, 1.0]},
        ],
        "meshes": [
            {"name": "tri",
             "primitives": [{"attributes": {"POSITION": tri_positions}, "indices": tri_indices}]},
            {"name": "multi_mesh", "primitives": [
                {"attributes": {"POSITION": tri_positions}, "indices": tri_indices},
                {"attributes": {"POSITION": strip}, "mode": 5},
                {"attributes": {"POSITION": tri_positions}, "indices": tri_indices, "mode": 1},
            ]},
        ],
    });
    (f, content)
}

fn vertices(part: &Part) -> Vec<Vec3> {
    part.mesh.vertices.clone()
}

fn assert_points(actual: &[Vec3], expected: &[[f32; 3]], scale: f32) {
    assert_eq!(actual.len(), expected.len());
    for (a, e) in actual.iter().zip(expected) {
        assert_near(*a, Vec3::from_array(*e) * scale, 1e-6 * scale.max(1.0));
    }
}

fn check_nested_scene(assembly: &Assembly) {
    assert_eq!(names(assembly), ["child", "tri", "multi", "mirror"]);
    assert_eq!(assembly.units.name, "mm");
    assert_eq!(assembly.up, Axis::Z);
    let mm = 0.001;
    // parent = T(10,0,0) · Rz(90°): (x, y, z) ↦ (10 − y, x, z)
    // child = T(0,0,5) · S(2)
    assert_points(&vertices(&assembly.parts[0]), &[[10.0, 0.0, 5.0], [10.0, 2.0, 5.0], [8.0, 0.0, 5.0]], mm);
    // unnamed instance of the same mesh, T(0,3,0) under the parent, named after the mesh
    assert_points(&vertices(&assembly.parts[1]), &[[7.0, 0.0, 0.0], [7.0, 1.0, 0.0], [6.0, 0.0, 0.0]], mm);
    // two triangle primitives merged (the strip without indices gives two triangles)
    let multi = &assembly.parts[2];
    assert_eq!(multi.mesh.vertices.len(), 7);
    assert_eq!(multi.mesh.triangles, vec![[0, 1, 2], [3, 4, 5], [4, 6, 5]]);
    assert!(multi.fixed);
    assert_eq!(multi.extras, json!({"grasp": [[1, 2, 3]]}));
    assert!(!assembly.parts[0].fixed && assembly.parts[0].extras.is_null());
    // the line primitive is skipped with a warning naming the part; its two triangle pieces
    // that do not touch are named as separate bodies
    assert_eq!(assembly.warnings.len(), 2, "{:?}", assembly.warnings);
    assert!(assembly.warnings[0].contains("'multi'") && assembly.warnings[0].contains("lines"));
    assert!(assembly.warnings[1].contains("'multi' holds 2 separate bodies"), "{:?}", assembly.warnings);
    // the mirrored instance keeps its outward side: winding flipped back
    let mirror = &assembly.parts[3];
    assert_points(&vertices(mirror), &[[0.0, 0.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 1.0, 0.0]], mm);
    assert!(mirror.mesh.triangle_normal(&mirror.mesh.triangles[0]).z > 0.0);
}

#[test]
fn nested_nodes_give_world_coordinates_in_metres() {
    let dir = tempfile::tempdir().unwrap();
    let (fixture, content) = nested_scene();
    let path = dir.path().join("nested.gltf");
    std::fs::write(&path, fixture.embedded(content.clone())).unwrap();
    check_nested_scene(&load(&path, &LoadOptions::default()).unwrap());

    let glb_path = dir.path().join("nested.glb");
    std::fs::write(&glb_path, fixture.glb(content)).unwrap();
    check_nested_scene(&load(&glb_path, &LoadOptions::default()).unwrap());

    // options override the file: metres and +Y, and more fixed parts
    let options = LoadOptions { unit: Some(Units::metres()), up: Some(Axis::Y), fixed: vec!["tri".into()], ..LoadOptions::default() };
    let assembly = load(&path, &options).unwrap();
    assert_eq!(assembly.up, Axis::Y);
    assert_points(&vertices(&assembly.parts[0]), &[[10.0, 0.0, 5.0], [10.0, 2.0, 5.0], [8.0, 0.0, 5.0]], 1.0);
    assert!(assembly.parts[1].fixed && assembly.parts[2].fixed && !assembly.parts[0].fixed);
}

#[test]
fn gltf_with_an_external_bin_file() {
    let dir = tempfile::tempdir().unwrap();
    let (fixture, content) = nested_scene();
    let document = fixture.document(content, json!({"uri": "my%20parts.bin"}));
    let path = dir.path().join("external.gltf");
    std::fs::write(&path, document.to_string()).unwrap();
    std::fs::write(dir.path().join("my parts.bin"), &fixture.bin).unwrap();
    check_nested_scene(&load(&path, &LoadOptions::default()).unwrap());

    std::fs::remove_file(dir.path().join("my parts.bin")).unwrap();
    assert_message(&load_error(&path), "external.gltf", "buffer file");
    assert_message(&load_error(&path), "my parts.bin", "is missing");
}

#[test]
fn buffers_outside_the_model_folder_are_refused_unless_allowed() {
    let dir = tempfile::tempdir().unwrap();
    let model = dir.path().join("model");
    std::fs::create_dir_all(dir.path().join("other")).unwrap();
    std::fs::create_dir(&model).unwrap();
    let (fixture, content) = nested_scene();
    std::fs::write(dir.path().join("other/secret.bin"), &fixture.bin).unwrap();
    let secret = dir.path().join("other/secret.bin");
    let cases = [
        ("up.gltf", "../other/secret.bin".to_string(), "points outside the model's folder"),
        ("absolute.gltf", secret.display().to_string(), "is an absolute path"),
        ("file_uri.gltf", format!("file://{}", secret.display()), "is an absolute path"),
    ];
    for (name, uri, cause) in cases {
        let path = model.join(name);
        std::fs::write(&path, fixture.document(content.clone(), json!({"uri": uri})).to_string()).unwrap();
        let message = load_error(&path);
        assert_message(&message, name, cause);
        assert_message(&message, &uri, "--allow-outside-files");
        let allowed = LoadOptions { allow_outside_files: true, ..LoadOptions::default() };
        check_nested_scene(&load(&path, &allowed).unwrap());
    }
    #[cfg(unix)]
    {
        std::os::unix::fs::symlink(&secret, model.join("link.bin")).unwrap();
        let path = model.join("link.gltf");
        std::fs::write(&path, fixture.document(content.clone(), json!({"uri": "link.bin"})).to_string()).unwrap();
        assert_message(&load_error(&path), "link.gltf", "points outside the model's folder");
        // a folder of parts whose file is a symlink out
        let parts = dir.path().join("parts");
        std::fs::create_dir(&parts).unwrap();
        std::fs::write(dir.path().join("outside.stl"), ascii_stl(&[[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]])).unwrap();
        std::os::unix::fs::symlink(dir.path().join("outside.stl"), parts.join("a.stl")).unwrap();
        assert_message(&load_error(&parts), "a.stl", "points outside the model's folder");
    }
}

#[test]
fn counts_past_the_caps_are_refused_before_reading() {
    use asp_geom::io::Limits;
    let dir = tempfile::tempdir().unwrap();
    let (fixture, content) = nested_scene();
    let path = write_gltf(dir.path(), "nested.gltf", &fixture, content);
    let small = |max_triangles, max_parts| LoadOptions { limits: Limits { max_triangles, max_parts }, ..LoadOptions::default() };
    assert_message(&load(&path, &small(1, 100)).unwrap_err().to_string(), "nested.gltf", "--max-triangles");
    assert_message(&load(&path, &small(100, 1)).unwrap_err().to_string(), "nested.gltf", "--max-parts");
    check_nested_scene(&load(&path, &small(100, 100)).unwrap());
    // a binary STL header announcing more triangles than the cap
    let stl = dir.path().join("big.stl");
    std::fs::write(&stl, binary_stl(&[[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]; 3])).unwrap();
    assert_message(&load(&stl, &small(2, 100)).unwrap_err().to_string(), "big.stl", "--max-triangles");
}

#[test]
fn non_finite_transforms_name_the_node() {
    let dir = tempfile::tempdir().unwrap();
    let mut f = Fixture::default();
    let positions = f.positions(&TRIANGLE);
    let mut content = single_mesh(positions, None);
    content["nodes"][0]["scale"] = json!([1.0, 1e39, 1.0]);
    let path = write_gltf(dir.path(), "inf.gltf", &f, content);
    assert_message(&load_error(&path), "inf.gltf", "node 0 ('the_part'): its transform has NaN or infinite values");
}

#[test]
fn unnamed_nodes_and_meshes_are_numbered() {
    let dir = tempfile::tempdir().unwrap();
    let mut f = Fixture::default();
    let positions = f.positions(&TRIANGLE);
    let content = json!({
        "scenes": [{"nodes": [0, 1]}],
        "nodes": [{"mesh": 0}, {"mesh": 0, "translation": [0.0, 0.0, 1.0]}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": positions}, "mode": 6}]}],
    });
    let path = dir.path().join("anonymous.gltf");
    std::fs::write(&path, f.embedded(content)).unwrap();
    let assembly = load(&path, &LoadOptions::default()).unwrap();
    assert_eq!(names(&assembly), ["part_0", "part_1"]);
    assert_eq!(assembly.up, Axis::Y);
    assert_eq!(assembly.units, Units::metres());
    // a fan of three vertices is one triangle (p1, p2, p0)
    assert_eq!(assembly.parts[1].mesh.triangles, vec![[1, 2, 0]]);
    assert_near(assembly.parts[1].mesh.vertices[2], Vec3::new(0.0, 1.0, 1.0), 0.0);
}

/// Writes `content` (with the nested-scene data) as an embedded `.gltf` in `dir`.
fn write_gltf(dir: &Path, name: &str, fixture: &Fixture, content: Value) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, fixture.embedded(content)).unwrap();
    path
}

/// One node with one mesh whose position accessor is `positions` (indices from `indices`).
fn single_mesh(positions: usize, indices: Option<usize>) -> Value {
    let mut primitive = json!({"attributes": {"POSITION": positions}});
    if let Some(indices) = indices {
        primitive["indices"] = json!(indices);
    }
    json!({
        "scenes": [{"nodes": [0]}],
        "nodes": [{"name": "the_part", "mesh": 0}],
        "meshes": [{"primitives": [primitive]}],
    })
}

// ---------------------------------------------------------------------------------------------
// OBJ and STL folders

fn ascii_stl(triangles: &[[[f32; 3]; 3]]) -> String {
    let mut out = String::from("solid test\n");
    for t in triangles {
        out += "  facet normal 0 0 0\n    outer loop\n";
        for v in t {
            out += &format!("      vertex {:e} {:e} {:e}\n", v[0], v[1], v[2]);
        }
        out += "    endloop\n  endfacet\n";
    }
    out + "endsolid test\n"
}

/// A binary STL whose 80-byte header starts with "solid", as many CAD tools write them.
fn binary_stl(triangles: &[[[f32; 3]; 3]]) -> Vec<u8> {
    let mut out = b"solid exported by a cad tool".to_vec();
    out.resize(80, b' ');
    out.extend((triangles.len() as u32).to_le_bytes());
    for t in triangles {
        out.extend([0u8; 12]);
        out.extend(t.iter().flatten().flat_map(|c| c.to_le_bytes()));
        out.extend([0u8; 2]);
    }
    out
}

const TETRAHEDRON: [[[f32; 3]; 3]; 4] = [
    [[0.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]],
    [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]],
    [[0.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, 1.0, 0.0]],
    [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
];

/// A unit cube of quads, as two OBJ objects (bottom half of the faces, then the rest).
const CUBE_OBJ: &str = "\
v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1
o first
f 1 4 3 2\nf 1 2 6 5\nf 2 3 7 6
o second
f 3 4 8 7\nf 4 1 5 8\nf 5 6 7 8
";

#[test]
fn folders_of_obj_and_stl_files() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("b_tetra.STL"), ascii_stl(&TETRAHEDRON)).unwrap();
    // the same tetrahedron in binary, 2 units along x (the same mesh at the same place is a duplicate)
    let shifted = TETRAHEDRON.map(|t| t.map(|[x, y, z]| [x + 2.0, y, z]));
    std::fs::write(dir.path().join("c_binary.stl"), binary_stl(&shifted)).unwrap();
    std::fs::write(dir.path().join("a_cube.obj"), CUBE_OBJ).unwrap();
    std::fs::write(dir.path().join("notes.txt"), "ignored").unwrap();
    std::fs::write(dir.path().join("a_cube.mtl"), "ignored").unwrap();

    let assembly = load(dir.path(), &with_unit("cm")).unwrap();
    assert_eq!(names(&assembly), ["a_cube", "b_tetra", "c_binary"]);
    assert_eq!(assembly.up, Axis::Z);
    assert_eq!(assembly.units.name, "cm");
    let cube = &assembly.parts[0].mesh;
    assert_eq!(cube.triangles.len(), 12, "six quads, both objects merged");
    assert_near(cube.aabb().unwrap().maxs, Vec3::splat(0.01), 1e-9);
    assert!((cube.signed_volume() - 1e-6).abs() < 1e-12);
    for tetra in &assembly.parts[1..] {
        assert_eq!(tetra.mesh.triangles.len(), 4);
        assert_eq!(tetra.mesh.vertices.len(), 4, "STL corners are shared");
        assert!(tetra.mesh.topology().is_closed_manifold());
    }
    let (ascii, binary) = (&assembly.parts[1].mesh, &assembly.parts[2].mesh);
    assert_eq!(ascii.triangles, binary.triangles, "ASCII and binary read alike");
    for (a, b) in ascii.vertices.iter().zip(&binary.vertices) {
        assert_near(*b - Vec3::new(0.02, 0.0, 0.0), *a, 1e-7);
    }

    let single = load(&dir.path().join("b_tetra.STL"), &LoadOptions::default()).unwrap();
    assert_eq!(names(&single), ["b_tetra"]);
    assert_eq!(single.units, Units::metres());
}

// ---------------------------------------------------------------------------------------------
// Writing GLB

fn sample_assembly() -> Assembly {
    let base = Mesh::cuboid(Vec3::ZERO, Vec3::new(0.1, 0.05, 0.01));
    let peg = Mesh::cuboid(Vec3::new(0.0123, 0.0101, 0.01), Vec3::new(0.0177, 0.0149, 0.0437));
    Assembly {
        parts: vec![
            Part::new("base", base, true, Value::Null),
            Part::new("peg", peg, false, json!({"grasp": [[15.0, 12.5, 43.7]], "voxels": {"size": 1.5, "cells": [[0, 0, 1]]}})),
        ],
        units: Units::parse("mm").unwrap(),
        up: Axis::Z,
        source: PathBuf::from("sample"),
        warnings: Vec::new(),
    }
}

#[test]
fn written_glb_loads_back_unchanged() {
    let dir = tempfile::tempdir().unwrap();
    let original = sample_assembly();
    let path = dir.path().join("sample.glb");
    write_glb(&original, &path).unwrap();
    let loaded = load(&path, &LoadOptions::default()).unwrap();
    assert_eq!(loaded.units, original.units);
    assert_eq!(loaded.up, original.up);
    assert!(loaded.warnings.is_empty());
    assert_eq!(loaded.len(), original.len());
    for (a, b) in loaded.parts.iter().zip(&original.parts) {
        assert_eq!(a.name, b.name);
        assert_eq!(a.fixed, b.fixed);
        assert_eq!(a.extras, b.extras);
        assert_eq!(a.mesh.triangles, b.mesh.triangles);
        for (u, v) in a.mesh.vertices.iter().zip(&b.mesh.vertices) {
            assert_near(*u, *v, 1e-8);
        }
    }
}

#[test]
fn written_glb_is_valid_and_deterministic() {
    let dir = tempfile::tempdir().unwrap();
    let assembly = sample_assembly();
    let (a, b) = (dir.path().join("a.glb"), dir.path().join("b.glb"));
    write_glb(&assembly, &a).unwrap();
    write_glb(&assembly.clone(), &b).unwrap();
    let bytes = std::fs::read(&a).unwrap();
    assert_eq!(bytes, std::fs::read(&b).unwrap(), "same assembly, same bytes");
    assert_eq!(bytes.len() % 4, 0);

    // the gltf crate validates the document (including the required position min/max)
    let gltf = gltf::Gltf::from_slice(&bytes).unwrap();
    let json_length = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
    let json: Value = serde_json::from_slice(&bytes[20..20 + json_length]).unwrap();
    assert_eq!(json["scenes"][0]["extras"], json!({"asp": {"unit": "mm", "up": "+z"}}));
    assert_eq!(json["nodes"][0]["extras"], json!({"asp": {"fixed": true}}));
    assert_eq!(json["nodes"][1]["extras"]["asp"]["fixed"], json!(false));
    for (mesh, part) in gltf.meshes().zip(&assembly.parts) {
        let positions = mesh.primitives().next().unwrap().get(&gltf::Semantic::Positions).unwrap();
        assert_eq!(positions.data_type(), gltf::accessor::DataType::F32);
        let b = part.mesh.aabb().unwrap();
        let (min, max) = (positions.min().unwrap(), positions.max().unwrap());
        for k in 0..3 {
            // millimetres in the file
            assert!((min[k].as_f64().unwrap() - f64::from(b.mins[k]) * 1000.0).abs() < 1e-4);
            assert!((max[k].as_f64().unwrap() - f64::from(b.maxs[k]) * 1000.0).abs() < 1e-4);
        }
    }
}

#[test]
fn real_models_survive_a_round_trip() {
    let dir = tempfile::tempdir().unwrap();
    let original = load(&data("ikea/chair_bertil_0148.glb"), &LoadOptions::default()).unwrap();
    let path = dir.path().join("chair.glb");
    write_glb(&original, &path).unwrap();
    let loaded = load(&path, &LoadOptions::default()).unwrap();
    assert_eq!(names(&loaded), names(&original));
    assert_eq!(loaded.up, Axis::Y);
    for (a, b) in loaded.parts.iter().zip(&original.parts) {
        assert_eq!(a.mesh, b.mesh, "metres in, metres out: bit-identical");
    }
}

#[test]
fn unwritable_assemblies_are_errors() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("bad.glb");
    let mut assembly = sample_assembly();
    assembly.parts[1].extras = json!([1, 2]);
    assert_message(&write_glb(&assembly, &path).unwrap_err().to_string(), "bad.glb", "part 'peg': extras");

    let mut assembly = sample_assembly();
    assembly.parts[0].mesh.vertices[0].x = f32::NAN;
    assert_message(&write_glb(&assembly, &path).unwrap_err().to_string(), "bad.glb", "part 'base' has NaN");

    let mut assembly = sample_assembly();
    assembly.parts[1].mesh = Mesh::default();
    assert_message(&write_glb(&assembly, &path).unwrap_err().to_string(), "bad.glb", "part 'peg' has no triangles");

    let missing_dir = dir.path().join("missing").join("x.glb");
    assert_message(&write_glb(&sample_assembly(), &missing_dir).unwrap_err().to_string(), "x.glb", "no such file");
    assert!(!path.exists(), "nothing written on error");
}

#[test]
fn sparse_accessors_substitute_values() {
    let dir = tempfile::tempdir().unwrap();
    let mut f = Fixture::default();
    let base = f.view(TRIANGLE.iter().flatten().flat_map(|c| c.to_le_bytes()).collect());
    let sparse_indices = f.view([2u8, 0, 0, 0].to_vec());
    let sparse_values = f.view([5.0f32, 6.0, 7.0].iter().flat_map(|c| c.to_le_bytes()).collect());
    let sparse = json!({"count": 1, "indices": {"bufferView": sparse_indices, "componentType": 5121},
                        "values": {"bufferView": sparse_values}});
    let over_data = f.accessor(json!({"bufferView": base, "componentType": 5126, "count": 3, "type": "VEC3",
                                      "min": [0, 0, 0], "max": [5, 6, 7], "sparse": sparse}));
    // over zeros: two substitutions, so that the triangle has an area
    let two_indices = f.view([1u8, 2, 0, 0].to_vec());
    let two_values = f.view([1.0f32, 0.0, 0.0, 5.0, 6.0, 7.0].iter().flat_map(|c| c.to_le_bytes()).collect());
    let two = json!({"count": 2, "indices": {"bufferView": two_indices, "componentType": 5121},
                     "values": {"bufferView": two_values}});
    let over_zeros = f.accessor(json!({"componentType": 5126, "count": 3, "type": "VEC3",
                                       "min": [0, 0, 0], "max": [5, 6, 7], "sparse": two}));
    for (accessor, first) in [(over_data, TRIANGLE[0]), (over_zeros, [0.0; 3])] {
        let path = write_gltf(dir.path(), "sparse.gltf", &f, single_mesh(accessor, None));
        let part = &load(&path, &LoadOptions::default()).unwrap().parts[0];
        assert_eq!(part.mesh.vertices[0], Vec3::from_array(first));
        assert_eq!(part.mesh.vertices[2], Vec3::new(5.0, 6.0, 7.0));
    }
    let mut bad = sparse.clone();
    bad["count"] = json!(2);
    let too_many = f.accessor(json!({"componentType": 5126, "count": 3, "type": "VEC3",
                                     "min": [0, 0, 0], "max": [5, 6, 7], "sparse": bad}));
    let path = write_gltf(dir.path(), "sparse.gltf", &f, single_mesh(too_many, None));
    assert_message(&load_error(&path), "sparse.gltf", "read past the end");
}
