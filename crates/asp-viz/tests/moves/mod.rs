//! Grid plans in the pictures: the steps' `moves` are played after their insertions, so no
//! piece of an interlocking puzzle passes through another at any time of the animation, and
//! every picture (storyboard, MCAP, page data) shows the same poses as `Scene::pose_during`.

use asp_app::pipeline::{plan_assembly, PlanSettings};
use asp_geom::grid::VoxelModel;
use asp_geom::math::Vec3;
use asp_geom::puzzles;
use asp_viz::{Scene, MOVE_TIME};
use std::path::Path;

fn grid_scene(assembly: asp_geom::Assembly) -> Scene {
    let result = plan_assembly(assembly.clone(), &PlanSettings::default(), None).unwrap();
    assert!(result.found(), "{:?}", result.report.explanation);
    Scene::new(assembly, result.report, Path::new("puzzle.json")).unwrap()
}

/// Whether unit cubes at `a` and `b` (cell coordinates, real) share volume.
fn cubes_overlap(a: Vec3, b: Vec3) -> bool {
    (a - b).abs().max_element() < 1.0 - 1e-3
}

/// Samples every step's timeline and checks that no two visible pieces share volume.
fn assert_no_piece_passes_through_another(scene: &Scene, voxels: &VoxelModel) {
    let mut placed: Vec<usize> = scene.initial.clone();
    for (k, step) in scene.steps.iter().enumerate() {
        placed.extend(&step.parts);
        let samples = 64 * step.duration().ceil() as usize;
        for j in 0..=samples {
            let u = step.duration() * j as f32 / samples as f32;
            let cells: Vec<Vec<Vec3>> = placed
                .iter()
                .map(|&i| {
                    let shift = scene.pose_during(k, u, i).translation / voxels.cell;
                    voxels.cells[i].iter().map(|c| Vec3::new(c[0] as f32, c[1] as f32, c[2] as f32) + shift).collect()
                })
                .collect();
            for a in 0..placed.len() {
                for b in a + 1..placed.len() {
                    let hit = cells[a].iter().any(|&x| cells[b].iter().any(|&y| cubes_overlap(x, y)));
                    assert!(
                        !hit,
                        "step {k} at u = {u}: {} and {} share volume",
                        scene.assembly.parts[placed[a]].name, scene.assembly.parts[placed[b]].name
                    );
                }
            }
        }
    }
}

#[test]
fn grid_moves_are_played_so_no_piece_passes_through_another() {
    for assembly in [puzzles::small_puzzle(), puzzles::burr_level()] {
        let voxels = VoxelModel::of(&assembly).expect("a voxel model");
        let scene = grid_scene(assembly);
        let moves: usize = scene.steps.iter().map(|s| s.moves.len()).sum();
        assert!(moves > 0, "{}: a puzzle whose plan needs moves", scene.report.model);
        assert_no_piece_passes_through_another(&scene, &voxels);
        // at the end every part is in its assembled pose
        let last = scene.steps.len() - 1;
        for i in 0..scene.assembly.parts.len() {
            assert!(scene.pose_during(last, scene.steps[last].duration(), i).translation.length() < 1e-6);
            assert_eq!(scene.offset(i, scene.steps.len(), 0), Vec3::ZERO);
        }
        // ignoring the moves (every insertion ending in the assembled pose) is caught
        let mut still = scene.clone();
        still.steps.iter_mut().for_each(|s| s.moves.clear());
        let caught = std::panic::catch_unwind(|| assert_no_piece_passes_through_another(&still, &voxels));
        assert!(caught.is_err(), "without the moves some piece should pass through another");
    }
}

#[test]
fn pictures_show_the_poses_of_the_moves() {
    let scene = grid_scene(puzzles::burr_level());
    let (k, step) = scene.steps.iter().enumerate().find(|(_, s)| !s.moves.is_empty()).unwrap();
    // a move slides only its parts, by its translation, over MOVE_TIME
    let mv = &step.moves[0];
    for i in 0..scene.assembly.parts.len() {
        let before = scene.pose_during(k, 1.0, i).translation;
        let after = scene.pose_during(k, 1.0 + MOVE_TIME, i).translation;
        let expected = if mv.parts.contains(&i) { mv.translation } else { Vec3::ZERO };
        assert!((after - before - expected).length() < 1e-6, "part {i}: {before} -> {after}");
    }
    // the MCAP's last pose of every part is its assembled pose; its log covers every move
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("burr.mcap");
    let options = asp_viz::mcap::McapOptions::default();
    let summary = asp_viz::mcap::write_scene(&path, &scene, &options).unwrap();
    let moves: usize = scene.steps.iter().map(|s| s.moves.len()).sum();
    let expected_ns = options.step_seconds * 1e9 * (scene.steps.len() as f64 + f64::from(MOVE_TIME) * moves as f64);
    assert!(summary.end_ns as f64 >= expected_ns * 0.95, "{} ns for {moves} moves", summary.end_ns);
    let bytes = std::fs::read(&path).unwrap();
    let mut last = std::collections::BTreeMap::<String, Vec<f64>>::new();
    for m in mcap::MessageStream::new(&bytes).unwrap() {
        let m = m.unwrap();
        if m.channel.topic != asp_viz::mcap::TOPIC_TRANSFORMS {
            continue;
        }
        let v: serde_json::Value = serde_json::from_slice(&m.data).unwrap();
        for t in v["transforms"].as_array().unwrap() {
            let tr = &t["translation"];
            last.insert(
                t["child_frame_id"].as_str().unwrap().to_string(),
                ["x", "y", "z"].iter().map(|c| tr[c].as_f64().unwrap()).collect(),
            );
        }
    }
    for i in 0..scene.assembly.parts.len() {
        let t = &last[&format!("part/{i}")];
        assert!(t.iter().all(|c| c.abs() < 1e-6), "part {i} ends at {t:?}");
    }
    // the storyboard: a panel per step, and one more after the last step's moves
    let board = asp_viz::render::storyboard(&scene, &asp_viz::render::RenderOptions::default());
    let last_moves = !scene.steps.last().unwrap().moves.is_empty();
    assert_eq!(board.panels.len(), scene.steps.len() + usize::from(last_moves));
    // the page carries the moves for its script
    let html = asp_viz::view::html(&scene);
    assert!(html.contains("\"moves\":[{\"parts\":"), "the page data has the steps' moves");
}
