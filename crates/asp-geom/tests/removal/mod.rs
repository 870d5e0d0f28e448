//! Straight-line removal, path planning and stability on fixtures with known answers.

use asp_geom::feasibility::interpolate_about;
use asp_geom::math::Vec3;
use asp_geom::rrt::{plan_removal_path, RrtConfig};
use asp_geom::{fixtures, Motion, PartSet, Stability, World, WorldConfig};

fn world(a: asp_geom::Assembly) -> World {
    World::new(a, &WorldConfig::default()).expect("fixture builds")
}

/// The axis directions along which `part` is free in `state` (also used by the overlap tests).
pub(crate) fn free_axes(w: &World, part: usize, state: &PartSet) -> Vec<&'static str> {
    let names = ["+x", "-x", "+y", "-y", "+z", "-z"];
    let axes = [Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, Vec3::Z, -Vec3::Z];
    let row = w.blocking().row(part);
    let present = w.contacts().with_fixed(state);
    axes.iter()
        .zip(names)
        .filter(|(a, _)| {
            let k = w.blocking().directions().iter().position(|d| d.dot(**a) > 0.9999).unwrap();
            !row[k].intersects(&present)
        })
        .map(|(_, n)| n)
        .collect()
}

#[test]
fn stacked_top_box_leaves_up_or_sideways_never_down() {
    let w = world(fixtures::stacked_boxes());
    let all = PartSet::full(3);
    assert_eq!(free_axes(&w, 2, &all), vec!["+x", "-x", "+y", "-y", "+z"]);
    // the lower box slides out sideways under the top one, but not up or down
    assert_eq!(free_axes(&w, 1, &all), vec!["+x", "-x", "+y", "-y"]);
    // once the top box is gone the lower one may also leave upward
    assert_eq!(free_axes(&w, 1, &all.without(2)), vec!["+x", "-x", "+y", "-y", "+z"]);
    // and its removal motion clears the remaining bounds
    match w.removal().linear(2, &all).unwrap() {
        Motion::Linear { direction, distance } => {
            // straight up is the shortest way out of the remaining bounds
            assert_eq!(direction, Vec3::Z);
            assert!(distance > 0.0 && distance < 1.0, "{distance}");
        }
        m => panic!("{m:?}"),
    }
}

#[test]
fn zero_clearance_peg_leaves_only_along_the_hole_axis() {
    let w = world(fixtures::peg_in_hole());
    let all = PartSet::full(2);
    assert_eq!(free_axes(&w, 1, &all), vec!["+z"]);
    // every other candidate direction (clustered normals) is blocked too
    let row = w.blocking().row(1);
    let free: Vec<Vec3> = w.blocking().directions().iter().zip(row).filter(|(_, b)| b.is_empty()).map(|(d, _)| *d).collect();
    assert_eq!(free, vec![Vec3::Z]);
}

#[test]
fn moving_into_a_contact_is_blocked_and_reports_the_blocker() {
    let w = world(fixtures::stacked_boxes());
    // the lower box is blocked along ±z: by the top box and the base
    let k_up = w.blocking().directions().iter().position(|d| *d == Vec3::Z).unwrap();
    let k_down = w.blocking().directions().iter().position(|d| *d == -Vec3::Z).unwrap();
    assert_eq!(w.blocking().row(1)[k_up].iter().collect::<Vec<_>>(), vec![2]);
    assert_eq!(w.blocking().row(1)[k_down].iter().collect::<Vec<_>>(), vec![0]);
}

#[test]
fn tube_stick_is_locked_by_handle_and_cap() {
    let w = world(fixtures::tube());
    let all = PartSet::full(4);
    let blockers = w.removal().linear(1, &all).unwrap_err();
    assert_eq!(blockers.iter().collect::<Vec<_>>(), vec![0, 2, 3]);
    assert!(w.removal().linear(2, &all).is_ok());
    assert!(w.removal().linear(3, &all).is_ok());
    assert_eq!(free_axes(&w, 1, &PartSet::from_indices(4, [0, 1])), vec!["+z", "-z"]);
}

#[test]
fn l_shaped_channel_needs_a_path() {
    let w = world(fixtures::l_path());
    let all = PartSet::full(2);
    assert!(w.removal().linear(1, &all).is_err(), "no straight line leaves the channel");
    let motion = plan_removal_path(&w, 1, &all, &RrtConfig::default(), 7).expect("RRT finds the L");
    let Motion::Path { poses, pivot } = &motion else { panic!("{motion:?}") };
    assert!(poses.len() >= 3, "an L needs a corner: {poses:?}");
    // every pose along the path, finely interpolated, is collision-free, and the last is outside
    for w2 in poses.windows(2) {
        for k in 0..=50 {
            let p = interpolate_about(*pivot, &w2[0], &w2[1], k as f32 / 50.0);
            assert!(w.removal().collision_at(1, &p, &all).is_none(), "collision at {p:?}");
        }
    }
    let last = poses.last().unwrap();
    let out = w.shapes().aabb(1).transform_by(last);
    assert!(out.mins.z >= 5.0 - 1e-3 || out.maxs.x <= 0.0 || out.mins.x >= 5.0, "{out:?}");
}

#[test]
fn arch_keystone_floats_without_pillars() {
    let w = world(fixtures::arch());
    // keystone on one pillar: linked, stable
    assert_eq!(w.contacts().stability(&PartSet::from_indices(4, [2, 3])), Stability::Stable);
    // keystone alone: floating
    assert_eq!(w.contacts().stability(&PartSet::from_indices(4, [3])), Stability::Unstable { floating: PartSet::from_indices(4, [3]) });
}

/// A 0.557 m post on a floor, and a ring of 3 mm wall and zero clearance around its top end,
/// given as voxels in the ring's extras (the ring's mesh alone was falsely blocked sliding up:
/// parry's mesh cast at this scale); `ring_extras` replaces them.
fn post_and_ring(ring_extras: serde_json::Value) -> asp_geom::Assembly {
    use asp_geom::{Mesh, Part};
    let cells: Vec<[i32; 3]> = (0..7)
        .flat_map(|k| (0..6).flat_map(move |i| (0..6).map(move |j| [i, j, k])))
        .filter(|[i, j, _]| !((1..5).contains(i) && (1..5).contains(j)))
        .collect();
    let ring = Mesh::from_voxels(&cells, Vec3::splat(0.003), Vec3::new(0.207, 0.207, 0.536));
    let extras = if ring_extras.is_null() { serde_json::json!({ "cells": cells }) } else { ring_extras };
    let part = |name: &str, mesh: Mesh, fixed: bool, extras: serde_json::Value| Part::new(name, mesh, fixed, extras);
    asp_geom::Assembly {
        parts: vec![
            part("floor", Mesh::cuboid(Vec3::new(0.0, 0.0, -0.01), Vec3::new(0.5, 0.5, 0.0)), true, serde_json::Value::Null),
            part("post", Mesh::cuboid(Vec3::new(0.21, 0.21, 0.0), Vec3::new(0.222, 0.222, 0.557)), false, serde_json::Value::Null),
            part("ring", ring, false, extras),
        ],
        units: asp_geom::Units::metres(),
        up: asp_geom::math::Axis::Z,
        source: "post_and_ring".into(),
        warnings: Vec::new(),
    }
}

#[test]
fn a_zero_clearance_ring_slides_along_its_post_on_exact_boxes() {
    let w = world(post_and_ring(serde_json::Value::Null));
    assert!(w.warnings().is_empty(), "{:?}", w.warnings());
    let all = PartSet::full(3);
    assert_eq!(free_axes(&w, 2, &all), vec!["+z"]);
    // the post leaves upward through the ring, and never down into the floor
    assert_eq!(free_axes(&w, 1, &all), vec!["+z"]);
    assert!(w.contacts().of(2).contains(1) && w.contacts().of(1).contains(0) && !w.contacts().of(2).contains(0));
    assert!(w.overlaps().pairs().is_empty());
}

#[test]
fn boxes_that_do_not_describe_a_part_are_warned_about_and_its_mesh_is_used() {
    let wrong = serde_json::json!({ "boxes": [[0.0, 0.0, 0.0, 1.0, 1.0, 1.0]] });
    let w = world(post_and_ring(wrong));
    assert!(
        w.warnings().iter().any(|m| m.contains("'ring'") && m.contains("extras.asp.boxes") && m.contains("mesh")),
        "{:?}",
        w.warnings()
    );
}

/// The simultaneous BVH descent of the sweeps gives the answers of the per-triangle candidate
/// search it replaced: on the large real meshes (chair, lack, beam), for every pair of parts in
/// contact, the pair's shapes as the removal test uses them, along the candidate directions and
/// random ones, from the assembled pose and from random displaced starts (fixed seed).
#[test]
fn bvh_descent_sweeps_agree_with_the_per_triangle_search() {
    use asp_geom::io::{load, LoadOptions};
    use asp_geom::math::{Axis, Pose};
    use asp_geom::sweep;
    use rand::{RngExt, SeedableRng};
    let data = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tests/data");
    let z = LoadOptions { up: Some(Axis::Z), ..LoadOptions::default() };
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
    let (mut hits, mut misses) = (0, 0);
    for file in ["ikea/chair_bertil_0148.glb", "ikea/table_lack_0825.glb", "beam/beam.glb"] {
        let w = world(load(&data.join(file), &z).unwrap());
        let n = w.num_parts();
        let diag = w.assembly().diagonal();
        for p in 0..n {
            for q in w.contacts().of(p).iter().filter(|&q| q != p && q < n) {
                let (moving, fixed) = w.blocking().pairs().shapes(p, q);
                let mut dirs: Vec<Vec3> = w.blocking().directions().to_vec();
                dirs.extend((0..6).map(|_| {
                    Vec3::new(rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0)).normalize_or_zero()
                }));
                for dir in dirs.into_iter().filter(|d| *d != Vec3::ZERO) {
                    let t_max = diag;
                    let new = sweep::sweep_distance(&moving, dir, &fixed, t_max);
                    let old = sweep::sweep_distance_reference(&moving, dir, &fixed, t_max);
                    assert_eq!(new, old, "{file}: parts {p}, {q} along {dir:?}");
                    if new.is_some() {
                        hits += 1
                    } else {
                        misses += 1
                    }
                    let shift =
                        Vec3::new(rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0)) * (0.02 * diag);
                    let pose = Pose::from_translation(shift);
                    assert_eq!(
                        sweep::sweep_hits_at(&moving, &pose, dir, &fixed, t_max),
                        sweep::sweep_hits_at_reference(&moving, &pose, dir, &fixed, t_max),
                        "{file}: parts {p}, {q} along {dir:?} from {shift:?}"
                    );
                }
            }
        }
    }
    // both answers occur, so the comparison means something
    assert!(hits > 20 && misses > 20, "{hits} hits, {misses} misses");
}

/// Found by the planners' fuzz test (`asp-app/tests/fuzz`, case 103): a part
/// of zero thickness (a flat box: a sheet drawn as a closed surface with no volume) lying on the
/// floor left downward through the ground, and a sheet between two boxes left through them: the
/// tolerance's erosion turned the sheet inside out (its two faces swapped sides), so nothing
/// touching it blocked it. A part thinner than twice the tolerance keeps its shape; its pair
/// tests shrink the other part instead.
#[test]
fn a_sheet_of_zero_thickness_leaves_neither_through_the_floor_nor_through_parts() {
    use asp_geom::fixtures::{assemble, box_part};
    use asp_geom::math::Axis;
    // a box, a flat sheet on the floor beside it, no part fixed (the virtual ground under both)
    let a = assemble(
        "sheet_on_floor",
        vec![box_part("box", [0.0, 0.0, 0.0], [1.0, 1.0, 1.0]), box_part("sheet", [1.5, 0.0, 0.0], [2.0, 1.0, 0.0])],
        Axis::Z,
    );
    let w = world(a);
    let all = PartSet::full(2);
    assert!(!free_axes(&w, 1, &all).contains(&"-z"), "the sheet goes down through the ground: {:?}", free_axes(&w, 1, &all));
    match w.removal().linear(1, &all).unwrap() {
        Motion::Linear { direction, .. } => assert!(direction.z >= 0.0, "the sheet leaves along {direction:?}"),
        other => panic!("{other:?}"),
    }
    // a sheet pressed between two boxes (a gasket) leaves sideways only, never through either
    let a = assemble(
        "gasket",
        vec![
            box_part("below", [0.0, 0.0, 0.0], [1.0, 1.0, 1.0]),
            box_part("gasket", [0.0, 0.0, 1.0], [1.0, 1.0, 1.0]),
            box_part("above", [0.0, 0.0, 1.0], [1.0, 1.0, 2.0]),
        ],
        Axis::Z,
    );
    let w = world(a);
    let all = PartSet::full(3);
    assert_eq!(free_axes(&w, 1, &all), vec!["+x", "-x", "+y", "-y"]);
    // and the boxes do not pass through the sheet either
    assert!(!free_axes(&w, 2, &all).contains(&"-z") && !free_axes(&w, 0, &all).contains(&"+z"));
}

/// Found by the planners' fuzz test (`asp-app/tests/fuzz`): a model built in memory with
/// a part whose triangles all have zero area (collapsed onto a line) was refused with parry's
/// words ("invalid configuration: cannot build a collision mesh: A triangle mesh must contain
/// at least one triangle"); it is refused as the loader refuses it, naming the part and saying
/// what to do.
#[test]
fn a_part_collapsed_onto_a_line_is_refused_in_the_loaders_words() {
    use asp_geom::fixtures::{assemble, box_part, part};
    use asp_geom::math::Axis;
    use asp_geom::mesh::Mesh;
    let line = Mesh::new(vec![Vec3::ZERO, Vec3::splat(1.0), Vec3::splat(2.0)], vec![[0, 1, 2], [2, 1, 0]]);
    let a = assemble("collapsed", vec![box_part("box", [0.0, 0.0, 0.0], [1.0, 1.0, 1.0]), part("line", line, false)], Axis::Z);
    let e = World::new(a, &WorldConfig::default()).err().expect("refused").to_string();
    assert_eq!(
        e,
        "fixture:collapsed: part 'line': all its 2 triangles have zero area (its vertices collapse to a point or a line); \
         check the export's scale and units or remove the part"
    );
}
