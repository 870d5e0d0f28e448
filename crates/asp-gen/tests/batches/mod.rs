//! Batches: seeds, file names, threads, items one by one, bad arguments.

use super::*;

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
