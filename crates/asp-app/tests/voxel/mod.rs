//! The voxel fast path (`asp_geom::voxel::VoxelChecker`, the pipeline's
//! `plan_on_voxels`) answers as the collision world does, so its plans are the world's plans.
//! Any difference — a blocking row, a contact, a motion's last bit, a counter — fails here.

use asp_app::pipeline::{budget, plan_on_voxels, plan_on_world, PlanSettings};
use asp_gen::SomaCube;
use asp_geom::voxel::VoxelChecker;
use asp_geom::{Assembly, World, WorldConfig};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use serde_json::Value;

/// Generated cubes 3×3×3 to 5×5×5 on their floor (several seeds each), then the 240 classic
/// solutions.
fn models() -> Vec<Assembly> {
    let mut out = Vec::new();
    for size in 3..=5 {
        for seed in 0..6 {
            let cube = SomaCube::random(size, &mut ChaCha8Rng::seed_from_u64(seed)).unwrap();
            out.push(cube.to_assembly(0.05, &format!("soma{size}_{seed}")));
        }
    }
    for (i, cube) in SomaCube::classic_solutions().iter().enumerate() {
        out.push(cube.to_assembly(0.05, &format!("classic_{i:03}")));
    }
    out
}

/// The same model without its fixed floor: the world adds its ground slab.
fn without_floor(mut a: Assembly) -> Assembly {
    a.parts.retain(|p| !p.fixed);
    a
}

/// A plan's JSON without what differs from run to run (times).
fn timeless(report: &asp_search::report::PlanReport) -> Value {
    let mut v: Value = serde_json::from_str(&report.to_json()).unwrap();
    let stats = v["stats"].as_object_mut().unwrap();
    stats.remove("seconds");
    stats.remove("timings");
    v
}

#[test]
fn the_voxel_checker_blocks_and_touches_as_the_world() {
    let config = WorldConfig::default();
    let mut models = models();
    models.extend(models.iter().take(6).cloned().map(without_floor).collect::<Vec<_>>());
    for a in models {
        let name = a.source.display().to_string();
        let voxels = VoxelChecker::new(&a, &config).unwrap_or_else(|| panic!("{name}: a voxel model"));
        let world = World::new(a, &config).unwrap();
        assert_eq!(voxels.tolerance(), world.shapes().tolerance(), "{name}");
        assert_eq!(voxels.warnings(), world.warnings(), "{name}");
        assert_eq!(world.blocking().directions().len(), 6, "{name}");
        for p in 0..world.num_parts() {
            assert_eq!(voxels.blocking_row(p), world.blocking().row(p), "{name}: part {p}'s blockers along ±x, ±y, ±z");
        }
        for p in 0..world.num_parts() + usize::from(world.shapes().ground().is_some()) {
            assert_eq!(voxels.contacts(p), *world.contacts().of(p), "{name}: part {p}'s contacts");
        }
    }
}

#[test]
fn the_voxel_fast_path_plans_as_the_world() {
    let settings = PlanSettings::default();
    let budget = budget(&settings).unwrap();
    let (mut fast, mut declined) = (0, 0);
    let mut models: Vec<(Assembly, PlanSettings)> = models().into_iter().map(|a| (a, settings.clone())).collect();
    // with no fixed part the world's ground slab is the base (the grid planner off: the
    // pipeline sends a pure voxel model to the grid first)
    let no_grid = PlanSettings { grid: false, ..settings.clone() };
    models.extend(models.iter().take(6).map(|(a, _)| (without_floor(a.clone()), no_grid.clone())).collect::<Vec<_>>());
    for (a, s) in models {
        let name = a.source.display().to_string();
        let voxels = plan_on_voxels(&a, &s, &budget, None).unwrap();
        let world = plan_on_world(a, &s, None).unwrap();
        match voxels {
            Some(v) => {
                fast += 1;
                assert_eq!(v.status, world.status, "{name}");
                assert_eq!(timeless(&v.report), timeless(&world.report), "{name}: the fast path's plan differs from the world's");
            }
            None => {
                // declined only where the world's search needed what only the world has
                declined += 1;
                let r = &world.report;
                assert!(!world.found() || r.stats.path_planner_calls > 0, "{name}: declined a plan the voxels answer: {}", r.to_json());
            }
        }
    }
    assert!(fast >= 240, "the fast path answered {fast} models, declined {declined}");
}

#[test]
fn the_fast_path_declines_what_it_cannot_answer() {
    let settings = PlanSettings::default();
    let budget = budget(&settings).unwrap();
    let cube = SomaCube::classic().to_assembly(0.05, "classic");
    assert!(VoxelChecker::new(&cube, &WorldConfig::default()).is_some());
    // a part turned off the axes is no union of boxes
    let mut turned = cube.clone();
    let (s, c) = 0.1f32.sin_cos();
    for v in &mut turned.parts[6].mesh.vertices {
        *v = asp_geom::math::Vec3::new(c * v.x - s * v.y, s * v.x + c * v.y, v.z);
    }
    turned.parts[6].meta.cells = None;
    assert!(VoxelChecker::new(&turned, &WorldConfig::default()).is_none());
    assert!(plan_on_voxels(&turned, &settings, &budget, None).unwrap().is_none());
    // an open mesh (the world warns about it)
    let mut open = cube.clone();
    open.parts[0].mesh.triangles.pop();
    assert!(VoxelChecker::new(&open, &WorldConfig::default()).is_none());
    assert!(World::new(open, &WorldConfig::default()).unwrap().warnings().iter().any(|w| w.contains("not closed")));
    // extra sphere directions are off the lattice's axes
    assert!(VoxelChecker::new(&cube, &WorldConfig { sphere_directions: 8, ..WorldConfig::default() }).is_none());
    // physics stability is the world's
    let physics = PlanSettings { stability: asp_app::pipeline::StabilitySetting::Physics { threshold: 0.05 }, ..settings.clone() };
    assert!(plan_on_voxels(&cube, &physics, &budget, None).unwrap().is_none());
    // overlapping parts: piece 0 pushed half a cell into its neighbours
    let mut overlapping = cube.clone();
    for v in &mut overlapping.parts[0].mesh.vertices {
        v.x += 0.025;
    }
    assert!(asp_geom::boxes::part_boxes(&overlapping.parts[0]).unwrap().is_some(), "its cells still fit its mesh");
    assert!(VoxelChecker::new(&overlapping, &WorldConfig::default()).is_none());
    // a stuck piece: no plan, so the world's search (path planner, cores) answers
    let layers = [["000", "011", "000"], ["110", "010", "000"], ["000", "000", "000"]];
    let labels: Vec<usize> = layers.iter().flat_map(|l| l.iter().flat_map(|r| r.bytes().map(|b| (b - b'0') as usize))).collect();
    let stuck = SomaCube::from_labels(3, labels).unwrap().to_assembly(0.05, "stuck");
    let quick = PlanSettings { path_planner: false, ..settings.clone() };
    assert!(plan_on_voxels(&stuck, &quick, &budget, None).unwrap().is_none());
    // with the default settings too (the pair leaves as a group it cannot take apart: the
    // world's plan is partial)
    let started = std::time::Instant::now();
    assert!(plan_on_voxels(&stuck, &settings, &budget, None).unwrap().is_none());
    assert!(started.elapsed().as_secs_f64() < 1.0);
    let world = plan_on_world(stuck, &settings, None).unwrap();
    assert!(!world.found(), "{}", world.report.to_json());
}
