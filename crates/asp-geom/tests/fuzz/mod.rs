//! Byte-mutation fuzzing of every loader on stable Rust: GLB, glTF with an external `.bin`, OBJ,
//! ASCII STL and binary STL. Seeds are shipped models (`tests/data`) and fixtures; each case
//! applies one to four mutations (bit flips, byte sets, truncation, splices from the input or
//! another seed, integer fields or numbers set to extremes; for GLB and glTF also mutations of
//! the JSON re-wrapped with correct chunk lengths, so they reach past the container checks) and
//! loads the result from memory ([`asp_geom::io::load_bytes_with`]: no temporary files).
//!
//! Every case must end in `Ok` or in an error of one line that names the file; a panic fails
//! the test, naming the case and the file its bytes were saved to. The run is deterministic:
//! `ASP_FUZZ_CASES` (default 10,000 per loader) and `ASP_FUZZ_SEED` (default 9) choose more or
//! other cases; `ASP_FUZZ_CASE=N` runs only case N (to reproduce one).

use asp_geom::io::{load, load_bytes_with, write_glb, LoadOptions};
use asp_geom::{fixtures, Mesh};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde_json::Value;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::{Path, PathBuf};

const DATA: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../tests/data");

fn env_number(name: &str) -> Option<u64> {
    std::env::var(name).ok().map(|v| v.parse().unwrap_or_else(|_| panic!("{name}={v} is not a number")))
}

fn cases() -> u64 {
    env_number("ASP_FUZZ_CASES").unwrap_or(10_000)
}

fn seed() -> u64 {
    env_number("ASP_FUZZ_SEED").unwrap_or(9)
}

// ---------------------------------------------------------------------------------------------
// Seeds

fn read(relative: &str) -> Vec<u8> {
    std::fs::read(Path::new(DATA).join(relative)).unwrap()
}

/// The GLB container's JSON text and BIN chunk.
fn split_glb(glb: &[u8]) -> (Vec<u8>, Vec<u8>) {
    let json_len = u32::from_le_bytes(glb[12..16].try_into().unwrap()) as usize;
    let json = glb[20..20 + json_len].to_vec();
    let bin = glb.get(20 + json_len + 8..).unwrap_or_default().to_vec();
    (json, bin)
}

/// A GLB container around `json` and `bin`, every length right.
fn glb(mut json: Vec<u8>, mut bin: Vec<u8>) -> Vec<u8> {
    while !json.len().is_multiple_of(4) {
        json.push(b' ');
    }
    while !bin.len().is_multiple_of(4) {
        bin.push(0);
    }
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

/// GLB seeds: two small IKEA models and fixtures written by asp (metadata, voxels, fixed parts).
fn glb_seeds() -> Vec<Vec<u8>> {
    let dir = tempfile::tempdir().unwrap();
    let mut seeds = vec![read("ikea/desk_hannes_0529.glb"), read("ikea/bookcase_grevback_0484.glb")];
    for (name, assembly) in [("ring", fixtures::ring_on_locked_post()), ("figure", fixtures::figure_6_2(0.01))] {
        let path = dir.path().join(format!("{name}.glb"));
        write_glb(&assembly, &path).unwrap();
        seeds.push(std::fs::read(&path).unwrap());
    }
    seeds
}

/// The binary STL seeds: two pieces of the shipped cube puzzle.
fn binary_stl_seeds() -> Vec<Vec<u8>> {
    vec![read("cube20/A.STL"), read("cube20/ABF.STL")]
}

/// Meshes for the text formats: the cube pieces and two fixture parts.
fn text_meshes() -> Vec<Mesh> {
    let dir = Path::new(DATA).join("cube20");
    let mut meshes: Vec<Mesh> =
        ["A.STL", "ABF.STL"].iter().map(|f| load(&dir.join(f), &LoadOptions::default()).unwrap().parts[0].mesh.clone()).collect();
    let peg = fixtures::peg_in_hole();
    meshes.extend(peg.parts.iter().map(|p| p.mesh.clone()));
    meshes
}

fn ascii_stl(mesh: &Mesh) -> Vec<u8> {
    let mut out = String::from("solid seed\n");
    for t in &mesh.triangles {
        let n = mesh.triangle_normal(t).normalize_or_zero();
        out += &format!("facet normal {} {} {}\n outer loop\n", n.x, n.y, n.z);
        for &i in t {
            let v = mesh.vertices[i as usize];
            out += &format!("  vertex {} {} {}\n", v.x, v.y, v.z);
        }
        out += " endloop\nendfacet\n";
    }
    out += "endsolid seed\n";
    out.into_bytes()
}

/// An OBJ file with the statements real exports carry: objects, normals, texture coordinates,
/// `v/vt/vn` and `v//vn` face forms, relative (negative) indices, quads and materials.
fn obj(mesh: &Mesh, variant: usize) -> Vec<u8> {
    let mut out = String::from("# seed\nmtllib seed.mtl\no part\n");
    for v in &mesh.vertices {
        out += &format!("v {} {} {}\n", v.x, v.y, v.z);
    }
    out += "vt 0 0\nvt 1 0\nvt 0 1\nvn 0 0 1\nusemtl steel\ns 1\n";
    let count = mesh.vertices.len() as i64;
    for (k, t) in mesh.triangles.iter().enumerate() {
        let i = t.map(|i| i64::from(i) + 1);
        out += &match (k + variant) % 4 {
            0 => format!("f {} {} {}\n", i[0], i[1], i[2]),
            1 => format!("f {}/1/1 {}/2/1 {}/3/1\n", i[0], i[1], i[2]),
            2 => format!("f {}//1 {}//1 {}//1\n", i[0], i[1], i[2]),
            _ => format!("f {} {} {}\n", i[0] - count - 1, i[1] - count - 1, i[2] - count - 1),
        };
    }
    out += "g rest\nf 1 2 3\nl 1 2\n";
    out.into_bytes()
}

// ---------------------------------------------------------------------------------------------
// Mutations

/// Bytes that parsers treat specially.
const INTERESTING_BYTES: &[u8] = b"\x00\xff\x7f\x80\x01-+./0 19eE\n\r\t\"{}[]:,nf";
/// Numbers with meaning to parsers: sign and width limits, zero, huge, non-finite.
const EXTREME_NUMBERS: &[&str] = &[
    "0",
    "-1",
    "1",
    "4294967295",
    "4294967296",
    "2147483647",
    "-2147483648",
    "9223372036854775807",
    "-9223372036854775808",
    "18446744073709551615",
    "99999999999999999999999",
    "1e39",
    "-1e308",
    "1e-45",
    "nan",
    "inf",
    "-0",
    "3.4028236e38",
];
const EXTREME_U32: &[u32] = &[0, 1, 2, 3, 0x7f, 0xff, 0xffff, 0x7fff_ffff, 0x8000_0000, 0xffff_fffe, 0xffff_ffff];

fn mutate(bytes: &mut Vec<u8>, others: &[Vec<u8>], rng: &mut ChaCha8Rng) {
    let len = bytes.len();
    let at = |rng: &mut ChaCha8Rng, len: usize| rng.random_range(0..len.max(1));
    match rng.random_range(0..9u32) {
        // bit flip
        0 if len > 0 => {
            let i = at(rng, len);
            bytes[i] ^= 1 << rng.random_range(0..8u32);
        }
        // byte set, random or special
        1 if len > 0 => {
            let i = at(rng, len);
            bytes[i] = if rng.random_bool(0.5) { rng.random() } else { INTERESTING_BYTES[at(rng, INTERESTING_BYTES.len())] };
        }
        // truncation
        2 => bytes.truncate(at(rng, len + 1)),
        // splice: a run of this or another seed copied over or into a random place
        3 | 4 => {
            let source = if rng.random_bool(0.5) || others.is_empty() { bytes.clone() } else { others[at(rng, others.len())].clone() };
            if source.is_empty() {
                return;
            }
            let from = at(rng, source.len());
            let n = rng.random_range(1..=(source.len() - from).min(256));
            let to = at(rng, len + 1);
            let run = &source[from..from + n];
            if rng.random_bool(0.5) {
                bytes.splice(to..to, run.iter().copied());
            } else {
                let end = (to + n).min(len);
                bytes.splice(to..end, run.iter().copied());
            }
        }
        // a little-endian integer field set to an extreme (binary headers, counts, indices)
        5 if len >= 4 => {
            let i = at(rng, len - 3) & !3;
            let value = EXTREME_U32[at(rng, EXTREME_U32.len())];
            bytes[i..i + 4].copy_from_slice(&value.to_le_bytes());
        }
        // a number in text set to an extreme (OBJ indices, STL coordinates, JSON counts)
        6 | 7 => {
            let starts: Vec<usize> =
                (0..len).filter(|&i| bytes[i].is_ascii_digit() && (i == 0 || !bytes[i - 1].is_ascii_alphanumeric())).collect();
            if starts.is_empty() {
                return;
            }
            let start = starts[at(rng, starts.len())];
            let end = (start..len).find(|&i| !(bytes[i].is_ascii_alphanumeric() || bytes[i] == b'.' || bytes[i] == b'-')).unwrap_or(len);
            let number = EXTREME_NUMBERS[at(rng, EXTREME_NUMBERS.len())];
            bytes.splice(start..end, number.bytes());
        }
        // a run deleted or repeated
        _ if len > 0 => {
            let from = at(rng, len);
            let n = rng.random_range(1..=(len - from).min(64));
            if rng.random_bool(0.5) {
                bytes.drain(from..from + n);
            } else {
                let run = bytes[from..from + n].to_vec();
                bytes.splice(from..from, run);
            }
        }
        _ => {}
    }
}

fn mutate_times(bytes: &mut Vec<u8>, others: &[Vec<u8>], rng: &mut ChaCha8Rng) {
    for _ in 0..rng.random_range(1..=4u32) {
        mutate(bytes, others, rng);
    }
}

// ---------------------------------------------------------------------------------------------
// The harness

/// One fuzz case: the file name, its bytes, and the external files it may refer to.
struct Case {
    file: &'static str,
    bytes: Vec<u8>,
    external: Vec<(&'static str, Vec<u8>)>,
}

/// Runs `cases()` cases built by `make`, each from its own generator (seed, loader, case), and
/// fails with every panicking case (its input saved for a rerun) and every malformed message.
fn fuzz(loader: &str, make: impl Fn(&mut ChaCha8Rng) -> Case) {
    let only = env_number("ASP_FUZZ_CASE");
    let salt = loader.bytes().fold(0u64, |h, b| h.wrapping_mul(131).wrapping_add(u64::from(b)));
    let mut failures = Vec::new();
    let (mut ok, mut errors) = (0usize, 0usize);
    for case in 0..cases() {
        if only.is_some_and(|n| n != case) {
            continue;
        }
        let mut rng = ChaCha8Rng::seed_from_u64(seed() ^ salt.rotate_left(17) ^ case.wrapping_mul(0x9e37_79b9_7f4a_7c15));
        let Case { file, bytes, external } = make(&mut rng);
        let path = PathBuf::from("fuzz").join(file);
        let read_external = |p: &Path| -> std::io::Result<Vec<u8>> {
            external
                .iter()
                .find(|(name, _)| p.file_name().is_some_and(|f| f == *name))
                .map(|(_, b)| b.clone())
                .ok_or_else(|| std::io::Error::new(std::io::ErrorKind::NotFound, "no such file"))
        };
        let result = catch_unwind(AssertUnwindSafe(|| load_bytes_with(&path, &bytes, &LoadOptions::default(), &read_external)));
        match result {
            Ok(Ok(_)) => ok += 1,
            Ok(Err(e)) => {
                errors += 1;
                let message = e.to_string();
                if message.contains('\n') || !message.contains(file) {
                    failures.push(format!("case {case}: message not one line naming {file}: {message:?}"));
                }
            }
            Err(panic) => {
                let what = panic
                    .downcast_ref::<String>()
                    .cloned()
                    .or_else(|| panic.downcast_ref::<&str>().map(|s| s.to_string()))
                    .unwrap_or_default();
                let saved = std::env::temp_dir().join(format!("asp-fuzz-{loader}-{case}-{file}"));
                let _ = std::fs::write(&saved, &bytes);
                for (name, data) in &external {
                    let _ = std::fs::write(std::env::temp_dir().join(format!("asp-fuzz-{loader}-{case}-{name}")), data);
                }
                failures.push(format!("case {case}: panic '{what}' (input saved as {})", saved.display()));
            }
        }
    }
    assert!(
        failures.is_empty(),
        "{loader}: {} of {} cases failed (seed {}; rerun one with ASP_FUZZ_CASE=N):\n{}",
        failures.len(),
        cases(),
        seed(),
        failures.iter().take(20).cloned().collect::<Vec<_>>().join("\n")
    );
    // the mutations must leave some inputs loadable and break others: a fuzzer whose every
    // case fails at the first byte tests nothing
    if only.is_none() && cases() >= 1000 {
        assert!(ok > 0 && errors > 0, "{loader}: {ok} loaded, {errors} errors: the mutations are too mild or too wild");
    }
}

fn pick<'a>(seeds: &'a [Vec<u8>], rng: &mut ChaCha8Rng) -> &'a Vec<u8> {
    &seeds[rng.random_range(0..seeds.len())]
}

#[test]
fn fuzz_glb() {
    let seeds = glb_seeds();
    let parts: Vec<(Vec<u8>, Vec<u8>)> = seeds.iter().map(|s| split_glb(s)).collect();
    let jsons: Vec<Vec<u8>> = parts.iter().map(|p| p.0.clone()).collect();
    fuzz("glb", |rng| {
        let bytes = if rng.random_bool(0.5) {
            let mut bytes = pick(&seeds, rng).clone();
            mutate_times(&mut bytes, &seeds, rng);
            bytes
        } else {
            // the JSON or the BIN chunk mutated, the container rebuilt around them
            let (mut json, mut bin) = parts[rng.random_range(0..parts.len())].clone();
            if rng.random_bool(0.7) {
                mutate_times(&mut json, &jsons, rng);
            } else {
                mutate_times(&mut bin, &[], rng);
            }
            glb(json, bin)
        };
        Case { file: "model.glb", bytes, external: Vec::new() }
    });
}

#[test]
fn fuzz_gltf_with_external_bin() {
    // the GLB seeds as .gltf files whose buffer is the external file model.bin
    let parts: Vec<(Vec<u8>, Vec<u8>)> = glb_seeds()
        .iter()
        .map(|s| {
            let (json, bin) = split_glb(s);
            let mut json: Value = serde_json::from_slice(&json).unwrap();
            json["buffers"][0]["uri"] = Value::from("model.bin");
            (serde_json::to_vec_pretty(&json).unwrap(), bin)
        })
        .collect();
    let jsons: Vec<Vec<u8>> = parts.iter().map(|p| p.0.clone()).collect();
    fuzz("gltf", |rng| {
        let (mut json, mut bin) = parts[rng.random_range(0..parts.len())].clone();
        match rng.random_range(0..4u32) {
            0 => mutate_times(&mut bin, &[], rng),
            1 => {
                mutate_times(&mut json, &jsons, rng);
                mutate_times(&mut bin, &[], rng);
            }
            _ => mutate_times(&mut json, &jsons, rng),
        }
        let external = if rng.random_bool(0.95) { vec![("model.bin", bin)] } else { Vec::new() };
        Case { file: "model.gltf", bytes: json, external }
    });
}

#[test]
fn fuzz_obj() {
    let seeds: Vec<Vec<u8>> = text_meshes().iter().enumerate().map(|(k, m)| obj(m, k)).collect();
    fuzz("obj", |rng| {
        let mut bytes = pick(&seeds, rng).clone();
        mutate_times(&mut bytes, &seeds, rng);
        Case { file: "part.obj", bytes, external: Vec::new() }
    });
}

#[test]
fn fuzz_ascii_stl() {
    let seeds: Vec<Vec<u8>> = text_meshes().iter().map(ascii_stl).collect();
    fuzz("stl-ascii", |rng| {
        let mut bytes = pick(&seeds, rng).clone();
        mutate_times(&mut bytes, &seeds, rng);
        Case { file: "part.stl", bytes, external: Vec::new() }
    });
}

#[test]
fn fuzz_binary_stl() {
    let seeds = binary_stl_seeds();
    fuzz("stl-binary", |rng| {
        let mut bytes = pick(&seeds, rng).clone();
        mutate_times(&mut bytes, &seeds, rng);
        Case { file: "part.stl", bytes, external: Vec::new() }
    });
}

/// The seeds themselves load (else the fuzzing would only test error paths), and the from-bytes
/// entry point gives what loading the file gives.
#[test]
fn fuzz_seeds_load_and_bytes_match_files() {
    let none = |_: &Path| -> std::io::Result<Vec<u8>> { Err(std::io::ErrorKind::NotFound.into()) };
    for (k, seed) in glb_seeds().iter().enumerate() {
        let a =
            load_bytes_with(Path::new("seed.glb"), seed, &LoadOptions::default(), &none).unwrap_or_else(|e| panic!("glb seed {k}: {e}"));
        assert!(a.len() >= 3);
    }
    for m in text_meshes() {
        for (file, bytes) in [("s.obj", obj(&m, 0)), ("s.obj", obj(&m, 3)), ("s.stl", ascii_stl(&m))] {
            let a = load_bytes_with(Path::new(file), &bytes, &LoadOptions::default(), &none).unwrap();
            assert_eq!(a.parts[0].mesh.triangles.len(), m.triangles.len() + usize::from(file.ends_with("obj")), "{file}");
        }
    }
    let path = Path::new(DATA).join("cube20/ABF.STL");
    let from_file = load(&path, &LoadOptions::default()).unwrap();
    let from_bytes = load_bytes_with(&path, &std::fs::read(&path).unwrap(), &LoadOptions::default(), &none).unwrap();
    assert_eq!(from_file.parts[0].mesh.vertices, from_bytes.parts[0].mesh.vertices);
    assert_eq!(from_file.parts[0].name, "ABF");
}
