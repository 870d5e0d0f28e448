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

fn cube(size: usize, seed: u64) -> SomaCube {
    SomaCube::random(size, &mut ChaCha8Rng::seed_from_u64(seed)).unwrap()
}

mod attached;
mod batches;
mod profile_assemblies;
mod soma;

fn profiles(params: &ProfileParams, seed: u64) -> ProfileAssembly {
    ProfileAssembly::generate(params, seed).unwrap()
}

// ---------------------------------------------------------------- files and `asp plan`

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
