//! Integration tests of the generators: the properties the thesis states and the generators promise
//! (docs/generators.md), checked on generated assemblies through the public API.

use asp_gen::batch::file_name;
use asp_gen::cuboid::Cuboid;
use asp_gen::manifest::PartCounts;
use asp_gen::profiles::{ConnectorShape, Role, TOLERANCE};
use asp_gen::*;
use asp_geom::math::Axis;
use asp_geom::{Checker, CheckerConfig, World, WorldConfig};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use std::collections::HashSet;

mod profiles;

fn profiles(params: &ProfileParams, seed: u64) -> ProfileAssembly {
    ProfileAssembly::generate(params, seed).unwrap()
}

fn cube(size: usize, seed: u64) -> SomaCube {
    SomaCube::random(size, &mut ChaCha8Rng::seed_from_u64(seed)).unwrap()
}

// ---------------------------------------------------------------- Soma cubes

#[test]
fn soma_pieces_partition_the_cube_exactly() {
    for size in 2..=6 {
        for seed in 0..10 {
            let c = cube(size, seed);
            let all: Vec<[i32; 3]> = c.pieces().iter().flatten().copied().collect();
            let distinct: HashSet<[i32; 3]> = all.iter().copied().collect();
            assert_eq!(all.len(), size.pow(3), "size {size} seed {seed}: cells covered more than once or missed");
            assert_eq!(distinct.len(), size.pow(3));
            let s = size as i32;
            assert!(distinct.iter().all(|c| c.iter().all(|v| (0..s).contains(v))));
        }
    }
}

#[test]
fn soma_pieces_have_one_to_four_face_connected_cells() {
    for size in 2..=6 {
        for seed in 0..10 {
            let c = cube(size, seed);
            for (p, cells) in c.pieces().iter().enumerate() {
                assert!((1..=4).contains(&cells.len()), "piece of {} cells", cells.len());
                assert!(c.is_face_connected(p));
            }
            assert_eq!(c.piece_sizes().iter().sum::<usize>(), c.pieces().len());
        }
    }
}

#[test]
fn soma_meshes_are_closed_with_the_cells_volume() {
    let cell = 0.05;
    let c = cube(5, 1);
    let a = c.to_assembly(cell, "soma5.glb");
    assert_eq!(a.len(), c.pieces().len() + 1);
    for (part, cells) in a.parts.iter().zip(c.pieces()) {
        let topo = part.mesh.topology();
        assert!(topo.is_closed_manifold(), "{}: {topo:?}", part.name);
        let expected = cells.len() as f64 * cell.powi(3);
        assert!((part.mesh.signed_volume() - expected).abs() < 1e-6 * expected, "{}", part.name);
        assert!(!part.fixed);
    }
    let floor = a.parts.last().unwrap();
    assert!(floor.fixed && floor.name == "floor" && floor.mesh.topology().is_closed_manifold());
    assert_eq!(a.up, Axis::Z);
    // the floor lies right under the cube, touching it
    assert_eq!(floor.mesh.aabb().unwrap().maxs.z, 0.0);
    assert_eq!(a.aabb().unwrap().maxs.z, (5.0 * cell) as f32);
}

#[test]
fn soma_extras_carry_the_voxels() {
    let c = cube(4, 2);
    let a = c.to_assembly(0.03, "x");
    for (part, cells) in a.parts.iter().zip(c.pieces()) {
        let asp = &part.extras;
        assert_eq!(asp["kind"], "soma_piece");
        assert_eq!(asp["cube_size"], 4);
        assert_eq!(asp["cell_size"], 0.03);
        let stored: Vec<[i32; 3]> = serde_json::from_value(asp["cells"].clone()).unwrap();
        assert_eq!(&stored, cells);
    }
    assert_eq!(a.parts.last().unwrap().extras["kind"], "floor");
}

#[test]
fn soma_same_seed_same_cube_other_seed_other_cube() {
    assert_eq!(cube(5, 42), cube(5, 42));
    assert_ne!(cube(5, 42), cube(5, 43));
    let a = cube(4, 9).to_assembly(0.05, "a");
    let b = cube(4, 9).to_assembly(0.05, "a");
    assert!(a.parts.iter().zip(&b.parts).all(|(x, y)| x.mesh == y.mesh && x.extras == y.extras));
}

/// The 24 proper rotations of a piece, each normalised to start at the origin and sorted.
fn canonical(cells: &[[i32; 3]]) -> Vec<[i32; 3]> {
    let mut best: Option<Vec<[i32; 3]>> = None;
    let perms = [[0, 1, 2], [1, 2, 0], [2, 0, 1], [1, 0, 2], [0, 2, 1], [2, 1, 0]];
    for (k, perm) in perms.iter().enumerate() {
        let even = k < 3;
        for signs in 0..8u8 {
            let s = [0, 1, 2].map(|i| if signs & (1 << i) != 0 { -1 } else { 1 });
            let negatives = s.iter().filter(|&&v| v < 0).count();
            if (negatives % 2 == 0) != even {
                continue; // a reflection
            }
            let mut moved: Vec<[i32; 3]> = cells.iter().map(|c| [0, 1, 2].map(|i| s[i] * c[perm[i]])).collect();
            let mins = [0, 1, 2].map(|i| moved.iter().map(|c| c[i]).min().unwrap());
            for c in &mut moved {
                *c = [0, 1, 2].map(|i| c[i] - mins[i]);
            }
            moved.sort();
            if best.as_ref().is_none_or(|b| moved < *b) {
                best = Some(moved);
            }
        }
    }
    best.unwrap()
}

#[test]
fn classic_soma_cube_has_the_seven_pieces() {
    let c = SomaCube::classic();
    assert_eq!(c.size(), 3);
    assert_eq!(c.pieces().len(), 7);
    assert_eq!(c.piece_sizes(), [0, 0, 1, 6], "one V of three cells, six pieces of four");
    let cells: HashSet<[i32; 3]> = c.pieces().iter().flatten().copied().collect();
    assert_eq!(cells.len(), 27);
    // seven different pieces up to rotation (A and B are mirror images, so both count)
    let shapes: HashSet<Vec<[i32; 3]>> = c.pieces().iter().map(|p| canonical(p)).collect();
    assert_eq!(shapes.len(), 7);
    // none of them is flat-straight (no I tetracube, no O square): the Soma set
    for p in c.pieces() {
        let canon = canonical(p);
        assert_ne!(canon, canonical(&[[0, 0, 0], [1, 0, 0], [2, 0, 0], [3, 0, 0]]));
        assert_ne!(canon, canonical(&[[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]]));
    }
    assert!((0..7).all(|p| c.is_face_connected(p)));
    let check = c.check_disassembly();
    assert!(check.straight_line && check.stable_order && check.linked);
    let names: Vec<String> = c.to_assembly(0.05, "x").parts.iter().map(|p| p.name.clone()).collect();
    assert_eq!(names[..7], ["piece_V", "piece_L", "piece_T", "piece_Z", "piece_A", "piece_B", "piece_P"]);
}

#[test]
fn soma_part_counts_match_the_thesis() {
    // thesis 6.1: a 5×5×5 cube of 38 parts; our mean over 40 cubes must be near it. For
    // 6×6×6 the thesis shows one cube of 58 parts; Algorithm 1 as printed (uniformly random
    // empty start cells) gives ≈ 65 (59..70 over 200 seeds), see docs/generators.md.
    let mean = |size: usize| (0..40).map(|s| cube(size, s).pieces().len()).sum::<usize>() as f64 / 40.0;
    let m5 = mean(5);
    assert!((36.0..=40.0).contains(&m5), "5×5×5: mean {m5} pieces");
    let m6 = mean(6);
    assert!((58.0..=70.0).contains(&m6), "6×6×6: mean {m6} pieces");
    for size in 2..=6usize {
        let cells = size.pow(3);
        for seed in 0..10 {
            let n = cube(size, seed).pieces().len();
            assert!(n >= cells.div_ceil(4) && n <= cells / 2 + 2, "size {size}: {n} pieces");
        }
    }
}

#[test]
fn random_soma_cubes_come_apart_along_straight_lines() {
    // the thesis' property of Soma cubes; the manifest would report any cube that breaks it
    for size in 3..=6 {
        for seed in 0..25 {
            let check = cube(size, seed).check_disassembly();
            assert!(check.linked && check.straight_line && check.stable_order, "size {size} seed {seed}: {check:?}");
            assert_eq!(check.order.len(), cube(size, seed).pieces().len());
        }
    }
}

#[test]
fn voxel_rays_agree_with_box_sweeps() {
    // the voxel check (rays through the grid) against the generic box check (cells as boxes)
    use asp_gen::check::{check_disassembly, BoxModel};
    for seed in 0..10 {
        let c = cube(4, seed);
        let mut parts: Vec<Vec<Cuboid>> = c
            .pieces()
            .iter()
            .map(|cells| cells.iter().map(|v| Cuboid::new(v.map(f64::from), v.map(|k| f64::from(k) + 1.0))).collect())
            .collect();
        parts.push(vec![Cuboid::new([-1.0, -1.0, -1.0], [5.0, 5.0, 0.0])]);
        let mut fixed = vec![false; parts.len()];
        fixed[parts.len() - 1] = true;
        let boxes = check_disassembly(&BoxModel::new(parts, fixed, 1e-9));
        assert_eq!(boxes, c.check_disassembly());
    }
}

// ---------------------------------------------------------------- profile assemblies

fn write(generator: Generator, count: usize, seed: u64, out: &std::path::Path) -> Manifest {
    write_batch(&Batch { generator, preset: None, count, seed }, out, &|| {}).unwrap()
}

#[test]
fn written_files_load_with_no_options_and_keep_their_metadata() {
    let dir = tempfile::tempdir().unwrap();
    let generator = Generator::Profiles(ProfileParams::single_layer());
    let manifest = write(generator.clone(), 2, 3, dir.path());
    let from_disk: Manifest = serde_json::from_str(&std::fs::read_to_string(dir.path().join("manifest.json")).unwrap()).unwrap();
    assert_eq!(from_disk, manifest);
    assert_eq!(manifest.generator, generator);
    for entry in &manifest.assemblies {
        let loaded = asp_geom::io::load(&dir.path().join(&entry.file), &Default::default()).unwrap();
        let generated = ProfileAssembly::generate(&ProfileParams::single_layer(), entry.seed).unwrap().to_assembly("x");
        assert_eq!(loaded.up, Axis::Z);
        assert_eq!(loaded.units.metres, 1.0);
        assert_eq!(loaded.len(), entry.parts);
        assert_eq!(loaded.parts.iter().filter(|p| p.fixed).count(), entry.fixed_parts);
        for (l, g) in loaded.parts.iter().zip(&generated.parts) {
            assert_eq!((&l.name, l.fixed), (&g.name, g.fixed));
            if l.extras != g.extras {
                let (a, b) = (l.extras.to_string(), g.extras.to_string());
                let at = a.bytes().zip(b.bytes()).position(|(x, y)| x != y).unwrap_or(0);
                panic!(
                    "{}: extras differ at {}: {} vs {}",
                    l.name,
                    at,
                    &a[at.saturating_sub(60)..(at + 40).min(a.len())],
                    &b[at.saturating_sub(60)..(at + 40).min(b.len())]
                );
            }
            assert_eq!(l.mesh.triangles.len(), g.mesh.triangles.len());
        }
    }
    let dir = tempfile::tempdir().unwrap();
    let manifest = write(Generator::Soma(SomaParams { size: 3, cell: 0.05 }), 1, 0, dir.path());
    let loaded = asp_geom::io::load(&dir.path().join(&manifest.assemblies[0].file), &Default::default()).unwrap();
    assert_eq!(loaded.up, Axis::Z);
    assert_eq!(loaded.parts.iter().filter(|p| p.fixed).map(|p| p.name.as_str()).collect::<Vec<_>>(), ["floor"]);
    assert!(loaded.parts[0].extras["cells"].is_array());
}

#[test]
fn the_same_seed_writes_the_same_bytes() {
    let (a, b) = (tempfile::tempdir().unwrap(), tempfile::tempdir().unwrap());
    for generator in [Generator::Soma(SomaParams { size: 4, cell: 0.05 }), Generator::Profiles(ProfileParams::double_layer())] {
        let manifest = write(generator.clone(), 3, 9, a.path());
        write(generator.clone(), 3, 9, b.path());
        for name in manifest.assemblies.iter().map(|e| e.file.as_str()).chain(["manifest.json"]) {
            let (x, y) = (std::fs::read(a.path().join(name)).unwrap(), std::fs::read(b.path().join(name)).unwrap());
            assert!(x == y, "{name} differs");
        }
        let other = tempfile::tempdir().unwrap();
        let m = write(generator, 1, 10, other.path());
        let x = std::fs::read(a.path().join(&m.assemblies[0].file)).unwrap();
        let y = std::fs::read(other.path().join(&m.assemblies[0].file)).unwrap();
        assert!(x != y, "another seed, another assembly");
    }
}

/// Plans a written file the way `asp plan FILE` does with no flags (within a time budget).
fn plans_to_completion(path: &std::path::Path) -> std::result::Result<(), String> {
    plans_to_completion_with(path, &WorldConfig::default())
}

fn plans_to_completion_with(path: &std::path::Path, config: &WorldConfig) -> std::result::Result<(), String> {
    use asp_search::{Budget, Dfs, Problem, Status};
    let assembly = asp_geom::io::load(path, &Default::default()).map_err(|e| e.to_string())?;
    let world = World::new(assembly, config).map_err(|e| e.to_string())?;
    let checker = Checker::new(world, CheckerConfig::default());
    let budget = Budget { timeout: Some(std::time::Duration::from_secs(60)), ..Budget::default() };
    let outcome = Dfs::builder().build().solve(&Problem::full(&checker), &budget);
    match outcome.status {
        Status::Found => recheck_on_boxes(path, checker.world(), &outcome.removals),
        Status::NoPlan { stuck, .. } => {
            Err(format!("{}: no plan, stuck: {:?}", path.display(), stuck.iter().map(|s| checker.world().name(s.part)).collect::<Vec<_>>()))
        }
        Status::BudgetExhausted => Err(format!("{}: budget exhausted", path.display())),
    }
}

#[test]
fn generated_soma_cubes_plan_to_completion() {
    let dir = tempfile::tempdir().unwrap();
    let classic = write(Generator::ClassicSoma { cell: 0.05 }, 1, 0, dir.path());
    let random = write(Generator::Soma(SomaParams { size: 4, cell: 0.05 }), 4, 0, dir.path());
    for entry in classic.assemblies.iter().chain(&random.assemblies) {
        plans_to_completion(&dir.path().join(&entry.file)).unwrap();
    }
}

#[test]
fn a_batch_of_fifty_5x5x5_cubes_plans_to_completion() {
    // `asp gen soma --size 5 --count 50 --seed 0`: on triangle meshes alone soma5_018 stopped
    // with a false gross overlap and soma5_036 with a false no_plan (saddle vertices of the
    // eroded pieces); the planner now tests voxel pieces exactly on their cells
    let dir = tempfile::tempdir().unwrap();
    let manifest = write(Generator::Soma(SomaParams { size: 5, cell: 0.05 }), 50, 0, dir.path());
    let failures: Vec<String> = manifest.assemblies.iter().filter_map(|e| plans_to_completion(&dir.path().join(&e.file)).err()).collect();
    assert!(failures.is_empty(), "{failures:#?}");
}

#[test]
fn generated_assemblies_also_plan_on_their_meshes_alone() {
    // the tolerant mesh test (erosion, triangle sweeps) must not need the exact boxes: the two
    // cubes whose saddle vertices once broke it (a false gross overlap; a false no_plan), the
    // classic cube, and profile assemblies with zero-clearance connectors
    let meshes = WorldConfig { exact_boxes: false, ..WorldConfig::default() };
    let dir = tempfile::tempdir().unwrap();
    write(Generator::Soma(SomaParams { size: 5, cell: 0.05 }), 50, 0, dir.path());
    write(Generator::ClassicSoma { cell: 0.05 }, 1, 0, dir.path());
    let mut files: Vec<std::path::PathBuf> =
        ["soma5_018.glb", "soma5_036.glb", "soma_classic.glb"].iter().map(|f| dir.path().join(f)).collect();
    let profiles = write(Generator::Profiles(ProfileParams::single_layer()), 2, 0, &dir.path().join("p"));
    files.extend(profiles.assemblies.iter().map(|e| dir.path().join("p").join(&e.file)));
    let failures: Vec<String> = files.iter().filter_map(|f| plans_to_completion_with(f, &meshes).err()).collect();
    assert!(failures.is_empty(), "{failures:#?}");
}

#[test]
fn mesh_and_box_removal_tests_agree_on_generated_assemblies_at_any_scale() {
    // the exact triangle sweeps of the mesh path against the exact boxes: every (part,
    // direction) blocking set equal, on the profiles' zero-clearance connectors and on voxels
    let dir = tempfile::tempdir().unwrap();
    let mut files = Vec::new();
    for (generator, count) in [
        (Generator::Profiles(ProfileParams::single_layer()), 1),
        (Generator::Profiles(ProfileParams::double_layer()), 1),
        (Generator::Soma(SomaParams { size: 5, cell: 0.05 }), 1),
    ] {
        let sub = dir.path().join(files.len().to_string());
        let manifest = write(generator, count, 0, &sub);
        files.extend(manifest.assemblies.iter().map(|e| sub.join(&e.file)));
    }
    for file in &files {
        for scale in [0.1f32, 1.0, 3.0, 100.0] {
            let mut assembly = asp_geom::io::load(file, &Default::default()).unwrap();
            for p in &mut assembly.parts {
                p.mesh.vertices.iter_mut().for_each(|v| *v *= scale);
            }
            let exact = World::new(assembly.clone(), &WorldConfig::default()).unwrap();
            let meshes = World::new(assembly, &WorldConfig { exact_boxes: false, ..WorldConfig::default() }).unwrap();
            assert_eq!(exact.blocking().directions(), meshes.blocking().directions());
            for p in 0..exact.num_parts() {
                for (k, (a, b)) in exact.blocking().row(p).iter().zip(meshes.blocking().row(p)).enumerate() {
                    assert_eq!(a, b, "{} ×{scale}: '{}' along {:?}", file.display(), exact.name(p), exact.blocking().directions()[k]);
                }
            }
        }
    }
}

#[test]
fn generated_profile_assemblies_plan_to_completion() {
    // O connectors slide along the zero-clearance supports they surround: exact on their boxes
    // (parry's mesh cast called that blocked at profile scale)
    let dir = tempfile::tempdir().unwrap();
    for (preset, count) in [(ProfileParams::single_layer(), 4), (ProfileParams::double_layer(), 2)] {
        let manifest = write(Generator::Profiles(preset), count, 0, dir.path());
        for entry in &manifest.assemblies {
            plans_to_completion(&dir.path().join(&entry.file)).unwrap();
        }
    }
}

/// Re-checks a plan of a generated model independently of the planner's sweeps: the moving
/// part's boxes (from the file's extras) are placed at small steps along each straight removal
/// and tested statically against the boxes of every part still present, the moving boxes shrunk
/// by the tolerance; the remainder must stay contact-linked to the fixed parts.
fn recheck_on_boxes(path: &std::path::Path, world: &World, removals: &[asp_search::Step]) -> std::result::Result<(), String> {
    let parts = &world.assembly().parts;
    let boxes: Vec<Vec<asp_geom::math::Aabb>> =
        parts.iter().map(|p| asp_geom::boxes::part_boxes(p).unwrap().expect("generated parts are boxes")).collect();
    let tol = world.shapes().tolerance();
    let mut present: Vec<bool> = vec![true; parts.len()];
    for (k, step) in removals.iter().enumerate() {
        let p = step.part;
        let asp_geom::Motion::Linear { direction, distance } = step.motion else {
            return Err(format!("{}: step {k} is not a straight line", path.display()));
        };
        present[p] = false;
        for i in 0..=200 {
            let shift = direction * (distance * i as f32 / 200.0);
            for q in (0..parts.len()).filter(|&q| present[q]) {
                let hit = boxes[p].iter().any(|a| {
                    boxes[q]
                        .iter()
                        .any(|b| (0..3).all(|c| a.mins[c] + shift[c] + tol < b.maxs[c] && b.mins[c] < a.maxs[c] + shift[c] - tol))
                });
                if hit {
                    return Err(format!("{}: step {k}: '{}' hits '{}'", path.display(), parts[p].name, parts[q].name));
                }
            }
        }
        let state = asp_geom::PartSet::from_indices(parts.len(), (0..parts.len()).filter(|&q| present[q]));
        if world.contacts().stability(&state) != asp_geom::Stability::Stable {
            return Err(format!("{}: step {k}: the remainder is not linked to the fixed parts", path.display()));
        }
    }
    Ok(())
}

// ---------------------------------------------------------------- batches

#[test]
fn assembly_seeds_differ_and_file_names_sort() {
    let seeds: HashSet<u64> = (0..1000).map(|k| assembly_seed(0, k)).collect();
    assert_eq!(seeds.len(), 1000);
    assert_ne!(assembly_seed(0, 1), assembly_seed(1, 0));
    let soma = Generator::Soma(SomaParams { size: 5, cell: 0.05 });
    assert_eq!(file_name(&soma, 7, 8), "soma5_007.glb");
    assert_eq!(file_name(&soma, 7, 5000), "soma5_0007.glb");
    assert_eq!(file_name(&Generator::ClassicSoma { cell: 0.05 }, 0, 1), "soma_classic.glb");
    assert_eq!(file_name(&Generator::Profiles(ProfileParams::default()), 13, 14), "profiles_013.glb");
}

#[test]
fn batches_are_identical_on_any_number_of_threads() {
    let generator = Generator::Profiles(ProfileParams::single_layer());
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        let meshes = std::sync::Mutex::new(Vec::new());
        let done = std::sync::atomic::AtomicUsize::new(0);
        let entries = pool
            .install(|| {
                generate_batch(
                    &generator,
                    4,
                    7,
                    &|g, e| {
                        let m: Vec<_> = g.assembly.parts.iter().map(|p| (p.mesh.clone(), p.extras.clone())).collect();
                        meshes.lock().unwrap().push((e.index, m));
                        Ok(())
                    },
                    &|| {
                        done.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                    },
                )
            })
            .unwrap();
        let mut meshes = meshes.into_inner().unwrap();
        meshes.sort_by_key(|m| m.0);
        assert_eq!(done.into_inner(), 4);
        (entries, meshes)
    };
    let (one, two) = (run(1), run(2));
    assert_eq!(one.0, two.0);
    assert!(one.1 == two.1, "same meshes and extras");
    assert_eq!(one.0.iter().map(|e| e.index).collect::<Vec<_>>(), vec![0, 1, 2, 3]);
    match &one.0[0].counts {
        PartCounts::Profiles { removable_profiles, grasp_points, .. } => {
            assert_eq!(*removable_profiles, 21);
            assert!(*grasp_points > 0);
        }
        other => panic!("{other:?}"),
    }
    assert!(one.0.iter().all(|e| e.checks.passed()));
}

#[test]
fn items_generated_one_by_one_make_the_batch_and_its_manifest() {
    // asp.batch generates items in separate processes, in any order, and writes the manifest
    // from their entries: the same files as write_batch
    let generator = Generator::Soma(SomaParams { size: 3, cell: 0.05 });
    let batch = Batch { generator: generator.clone(), preset: None, count: 3, seed: 9 };
    let whole = tempfile::tempdir().unwrap();
    write_batch(&batch, whole.path(), &|| {}).unwrap();
    let parts = tempfile::tempdir().unwrap();
    let mut entries = Vec::new();
    for index in [2, 0, 1] {
        let (g, e) = asp_gen::batch::generate_item(&generator, index, 3, 9).unwrap();
        asp_geom::io::write_glb(&g.assembly, &parts.path().join(&e.file)).unwrap();
        entries.push(e);
    }
    let missing = asp_gen::batch::write_manifest(&batch, entries[..2].to_vec(), parts.path()).unwrap_err();
    assert!(missing.to_string().contains("one entry for each of the 3"), "{missing}");
    asp_gen::batch::write_manifest(&batch, entries, parts.path()).unwrap();
    for file in ["manifest.json", "soma3_000.glb", "soma3_001.glb", "soma3_002.glb"] {
        let read = |dir: &tempfile::TempDir| std::fs::read(dir.path().join(file)).unwrap();
        assert!(read(&whole) == read(&parts), "{file} differs");
    }
    assert_eq!(ProfileParams::preset("double-layer"), Some(ProfileParams::double_layer()));
    assert_eq!(ProfileParams::preset("triple-layer"), None);
}

#[test]
fn batches_reject_bad_arguments() {
    let ok = |_: &Generated, _: &ManifestEntry| Ok(());
    let soma = Generator::Soma(SomaParams { size: 1, cell: 0.05 });
    let err = generate_batch(&soma, 1, 0, &ok, &|| {}).unwrap_err();
    assert!(err.to_string().contains("--size"), "{err}");
    let soma = Generator::Soma(SomaParams::default());
    let err = generate_batch(&soma, 0, 0, &ok, &|| {}).unwrap_err();
    assert!(err.to_string().contains("--count"), "{err}");
    let profiles = Generator::Profiles(ProfileParams { height: 0.1, ..ProfileParams::default() });
    assert!(generate_batch(&profiles, 1, 0, &ok, &|| {}).is_err());
}

#[test]
fn distance_maps_sweep_every_generated_part_as_exact_boxes() {
    use asp_geom::distmap::{DistanceMaps, MapConfig, PartGeometry};
    let dir = tempfile::tempdir().unwrap();
    for generator in [Generator::Profiles(ProfileParams::double_layer()), Generator::Soma(SomaParams { size: 4, cell: 0.05 })] {
        let manifest = write(generator, 1, 3, dir.path());
        let assembly = asp_geom::io::load(&dir.path().join(&manifest.assemblies[0].file), &Default::default()).unwrap();
        let maps = DistanceMaps::build(&assembly, &MapConfig::default()).unwrap();
        for (i, p) in assembly.parts.iter().enumerate() {
            assert_ne!(maps.geometry(i), PartGeometry::Mesh, "'{}' is swept as a mesh", p.name);
        }
    }
}

// ---------------------------------------------------------------- attached connectors

fn attached(params: ProfileParams) -> ProfileParams {
    ProfileParams { connectors: ConnectorMode::Attached, ..params }
}

#[test]
fn attached_profiles_are_the_only_parts_and_carry_their_connectors() {
    for (params, removable) in [(ProfileParams::single_layer(), 21), (ProfileParams::double_layer(), 30)] {
        for seed in 0..3 {
            let separate = profiles(&params, seed);
            let a = profiles(&attached(params.clone()), seed);
            // the same profiles and connectors are drawn; only the parts differ
            assert_eq!(a.profiles, separate.profiles);
            assert_eq!(a.connectors, separate.connectors);
            let asm = a.to_assembly("x");
            assert_eq!(asm.parts.len(), a.profiles.len(), "seed {seed}: only profiles are parts");
            assert_eq!(asm.parts.iter().filter(|p| !p.fixed).count(), removable);
            assert!(asm.parts.iter().all(|p| p.extras["kind"] == "profile"));
            let boxes = a.part_boxes();
            let cells: usize = boxes.iter().map(Vec::len).sum();
            let separate_cells: usize = separate.part_boxes().iter().map(Vec::len).sum();
            assert_eq!(cells, separate_cells, "every connector cell belongs to one profile");
            for (i, (part, cells)) in asm.parts.iter().zip(&boxes).enumerate() {
                // the mesh is the closed surface of the profile and its connectors
                assert!(part.mesh.topology().is_closed_manifold(), "{}", part.name);
                let volume: f64 = cells.iter().map(Cuboid::volume).sum();
                assert!((part.mesh.signed_volume() - volume).abs() < 1e-4 * volume, "{}", part.name);
                let held = a.connectors.iter().filter(|c| c.holds == i).count();
                assert_eq!(part.extras["connectors"].as_array().map(Vec::len), Some(held), "{}", part.name);
                assert_eq!(part.extras["boxes"].as_array().map(Vec::len), Some(cells.len()));
                assert_eq!(part.meta.boxes.as_ref().map(Vec::len), Some(cells.len()), "{}", part.name);
            }
            assert!(a.max_penetration() <= TOLERANCE);
            let check = a.check_disassembly();
            assert!(check.linked && check.straight_line && check.stable_order, "seed {seed}: {check:?}");
        }
    }
}

#[test]
fn attached_connectors_keep_clear_of_every_grasp() {
    // a finger (2 cm along the profile, the shipped panda's pad) centred on any grasp point
    // must not reach into a connector the profile carries: the robot does not test the held
    // part against its own gripper
    let finger_half = 0.01;
    for params in [ProfileParams::single_layer(), ProfileParams::double_layer()] {
        for seed in 0..3 {
            let a = profiles(&attached(params.clone()), seed);
            let boxes = a.part_boxes();
            for (i, p) in a.profiles.iter().enumerate() {
                let grasps = a.grasp_points(i);
                assert!(!grasps.is_empty() || p.length() < 2.0 * params.grasp_margin);
                for g in grasps {
                    let mut zone = p.cuboid;
                    zone.mins[p.axis] = g.position[p.axis] - finger_half;
                    zone.maxs[p.axis] = g.position[p.axis] + finger_half;
                    // the zone widened by the connector walls across the profile
                    for b in 0..3 {
                        if b != p.axis {
                            zone.mins[b] -= 2.0 * params.connector_thickness;
                            zone.maxs[b] += 2.0 * params.connector_thickness;
                        }
                    }
                    // (a support's O sleeve ends exactly where the finger of its lowest grasp
                    // begins: touching, not overlapping)
                    for c in &boxes[i][1..] {
                        assert!(!c.overlaps(&zone, 1e-9), "profile {i}: grasp at {:?} on {c:?}", g.position);
                    }
                }
            }
        }
    }
}

#[test]
fn attached_assemblies_written_and_planned_to_completion() {
    let dir = tempfile::tempdir().unwrap();
    let m = write(Generator::Profiles(attached(ProfileParams::single_layer())), 2, 0, dir.path());
    for e in &m.assemblies {
        assert!(e.checks.passed(), "{e:?}");
        assert_eq!(e.parts, 29);
        plans_to_completion(&dir.path().join(&e.file)).unwrap();
    }
    // the manifest says how the connectors were made; separate batches do not mention it
    let text = std::fs::read_to_string(dir.path().join("manifest.json")).unwrap();
    assert!(text.contains("\"connectors\": \"attached\""), "{text}");
    let sep = tempfile::tempdir().unwrap();
    write(Generator::Profiles(ProfileParams::single_layer()), 1, 0, sep.path());
    assert!(!std::fs::read_to_string(sep.path().join("manifest.json")).unwrap().contains("\"connectors\""));
}
