use super::maps::clear_distance;
use super::*;
use crate::assembly::Assembly;
use crate::assembly::Part;
use crate::feasibility::Stability;
use crate::fixtures;
use crate::math::{Aabb, Axis, Vec3};
use crate::mesh::Mesh;
use crate::partset::PartSet;

fn part(name: &str, mesh: Mesh) -> Part {
    fixtures::part(name, mesh, false)
}

fn assembly(parts: Vec<Part>) -> Assembly {
    fixtures::assemble("test", parts, Axis::Z)
}

#[test]
fn hemisphere_has_the_axes_and_no_duplicates() {
    let h = Hemisphere::new(5, Axis::Z).unwrap();
    assert_eq!(h.len(), 25);
    assert_eq!(h.directions()[h.up_index()], Vec3::Z);
    for axis in [Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y] {
        assert!(h.directions().iter().any(|d| (*d - axis).length() < 1e-6), "{axis:?}");
    }
    for (a, d) in h.directions().iter().enumerate() {
        assert!((d.length() - 1.0).abs() < 1e-5 && d.z >= 0.0);
        for e in &h.directions()[a + 1..] {
            assert!((*d - *e).length() > 1e-3);
        }
    }
    let hy = Hemisphere::new(3, Axis::Y).unwrap();
    assert_eq!(hy.directions()[hy.up_index()], Vec3::Y);
    assert!(hy.directions().iter().all(|d| d.y >= 0.0));
    assert!(Hemisphere::new(4, Axis::Z).is_err());
    assert!(MapConfig::builder().resolution(17).build().is_err());
    assert!(MapConfig::builder().d_max(-1.0).build().is_err());
}

#[test]
fn dirmask_operations() {
    let all = DirMask::first(81);
    assert_eq!(all.len(), 81);
    assert!(all.contains(80) && !all.contains(81));
    let mut m = DirMask::EMPTY;
    m.insert(3);
    m.insert(70);
    assert_eq!(all.and(m).iter().collect::<Vec<_>>(), vec![3, 70]);
    assert_eq!(all.and_not(m).len(), 79);
    assert_eq!(DirMask::first(256).len(), 256);
}

#[test]
fn clear_distance_of_boxes() {
    // (box sweeps themselves are tested in `crate::boxes`)
    let a = Aabb::new(Vec3::ZERO, Vec3::ONE);
    let b = Aabb::new(Vec3::new(2.0, 0.0, 0.0), Vec3::new(3.0, 1.0, 1.0));
    // already apart: nothing to travel
    assert_eq!(clear_distance(&a, Vec3::X, &b), 0.0);
    let rest = Aabb::new(Vec3::ZERO, Vec3::new(3.0, 1.0, 2.0));
    assert_eq!(clear_distance(&a, Vec3::X, &rest), 3.0);
    assert_eq!(clear_distance(&a, Vec3::Z, &rest), 2.0);
}

#[test]
fn stacked_boxes_from_meshes_and_boxes_agree() {
    // Two stacked boxes: the top one leaves upward and sideways, the bottom one only
    // sideways (the top one blocks up).
    let mut top = Mesh::cuboid(Vec3::new(0.0, 0.0, 1.0), Vec3::new(1.0, 1.0, 2.0));
    let bottom = Mesh::cuboid(Vec3::ZERO, Vec3::ONE);
    let boxes = DistanceMaps::build(
        &assembly(vec![part("bottom", bottom.clone()), part("top", top.clone())]),
        &MapConfig::builder().resolution(3).build().unwrap(),
    )
    .unwrap();
    assert_eq!(boxes.geometry(0), PartGeometry::Box);
    // Turn the top box into a general mesh (subdivided) to force exact triangle sweeps.
    let extra = top.vertices.len() as u32;
    top.vertices.push(Vec3::new(0.5, 0.5, 2.0));
    let t = top.triangles.iter().position(|t| t.iter().all(|&v| top.vertices[v as usize].z == 2.0)).unwrap();
    let [a, b, c] = top.triangles.remove(t);
    top.triangles.extend([[a, b, extra], [b, c, extra], [c, a, extra]]);
    assert!(top.topology().is_closed_manifold());
    let meshes = DistanceMaps::build(
        &assembly(vec![part("bottom", bottom), part("top", top)]),
        &MapConfig::builder().resolution(3).build().unwrap(),
    )
    .unwrap();
    assert_eq!(meshes.geometry(1), PartGeometry::Mesh);
    let d_max = boxes.d_max();
    assert!((d_max - 6f32.sqrt()).abs() < 1e-5);
    let h = boxes.hemisphere();
    let up = h.up_index();
    for maps in [&boxes, &meshes] {
        // bottom vs top: moving up hits immediately; horizontal is free
        assert_eq!(maps.map(0, 1)[up], 0.0);
        assert_eq!(maps.map(0, 1)[h.index(2, 2)], d_max); // +x
                                                          // top vs bottom: every half-sphere direction is free
        assert!(maps.map(1, 0).iter().all(|&v| v == d_max));
        // the floor supports the bottom, the bottom supports the top
        assert!(maps.on_floor(0) && !maps.on_floor(1));
        assert_eq!(maps.supporters(1), &[0]);
        let full = PartSet::full(2);
        assert!(maps.is_collision_free(1, &full));
        // the bottom slides out sideways, but that drops the top
        assert!(maps.is_collision_free(0, &full));
        assert!(!maps.free_mask(0, &full).contains(up));
        assert_eq!(maps.stability(&PartSet::from_indices(2, [1])), Stability::Unstable { floating: PartSet::from_indices(2, [1]) });
    }
}

#[test]
fn map_state_tracks_removals() {
    // A column of three boxes: only the top leaves, then the middle, then the bottom.
    let parts = (0..3)
        .map(|k| {
            let z = k as f32;
            part(&format!("b{k}"), Mesh::cuboid(Vec3::new(0.0, 0.0, z), Vec3::new(1.0, 1.0, z + 1.0)))
        })
        .collect();
    let maps = DistanceMaps::build(&assembly(parts), &MapConfig::default()).unwrap();
    let mut s = MapState::new(&maps);
    let mut acts = Vec::new();
    s.feasible_actions(&mut acts);
    assert_eq!(acts, vec![2]);
    let before: f32 = s.min_map(1).iter().sum();
    s.remove(2);
    let after: f32 = s.min_map(1).iter().sum();
    assert!(after > before);
    let direct = maps.min_map(1, &s.present());
    assert_eq!(s.min_map(1), direct.as_slice());
    s.feasible_actions(&mut acts);
    assert_eq!(acts, vec![1]);
    // the middle box is already outside the bottom one's box: no travel, straight up
    let (d, t) = s.clearance(1).unwrap();
    assert_eq!(d, maps.hemisphere().up_index());
    assert_eq!(t, 0.0);
    s.remove(1);
    s.feasible_actions(&mut acts);
    assert_eq!(acts, vec![0]);
    s.remove(0);
    assert!(s.is_complete());
}

#[test]
fn the_world_and_the_maps_classify_parts_alike_under_one_flag() {
    use crate::boxes::PartShape;
    use crate::world::World;
    // "wrong" declares boxes its mesh is not (twice as tall); its mesh is one box. "cells"
    // is two voxels that match; "mesh" is a pyramid.
    let mut wrong = part("wrong", Mesh::cuboid(Vec3::new(2.0, 0.0, 0.0), Vec3::new(3.0, 1.0, 1.0)));
    wrong.meta.boxes =
        Some(vec![Aabb::new(Vec3::ZERO, Vec3::new(1.0, 1.0, 1.0)), Aabb::new(Vec3::new(5.0, 0.0, 0.0), Vec3::new(6.0, 1.0, 1.0))]);
    let mut cells = part("cells", Mesh::cuboid(Vec3::ZERO, Vec3::new(2.0, 1.0, 1.0)));
    cells.meta.cells = Some(vec![[0, 0, 0], [1, 0, 0], [0, 0, 0]]);
    let mut pyramid = Mesh::cuboid(Vec3::new(0.0, 0.0, 1.0), Vec3::new(1.0, 1.0, 2.0));
    let apex = pyramid.vertices.len() as u32;
    pyramid.vertices.push(Vec3::new(0.5, 0.5, 2.5));
    let top = pyramid.triangles.iter().position(|t| t.iter().all(|&v| pyramid.vertices[v as usize].z == 2.0)).unwrap();
    let [a, b, c] = pyramid.triangles.remove(top);
    pyramid.triangles.extend([[a, b, apex], [b, c, apex], [c, a, apex]]);
    let asm = assembly(vec![wrong.clone(), cells.clone(), part("mesh", pyramid)]);

    let (shape, warning) = PartShape::classify(&wrong, true);
    assert_eq!(shape, PartShape::Boxes(vec![Aabb::new(Vec3::new(2.0, 0.0, 0.0), Vec3::new(3.0, 1.0, 1.0))]));
    assert!(warning.is_some_and(|w| w.contains("'wrong'") && w.contains("extras.asp.boxes")));
    let (shape, warning) = PartShape::classify(&cells, true);
    assert!(matches!(&shape, PartShape::Voxels { cells, .. } if cells.len() == 2), "{shape:?}");
    assert!(warning.is_none());
    assert_eq!(PartShape::classify(&cells, false), (PartShape::Mesh, None));

    let config = MapConfig::builder().resolution(3).build().unwrap();
    let world = std::sync::Arc::new(World::new(asm.clone(), &config.world_config(&asm)).unwrap());
    let maps = DistanceMaps::build_on(world.clone(), &config).unwrap();
    let kinds: Vec<PartGeometry> = (0..3).map(|i| maps.geometry(i)).collect();
    assert_eq!(kinds, [PartGeometry::Box, PartGeometry::Voxels, PartGeometry::Mesh]);
    assert_eq!(world.shapes().boxes(0).map(<[Aabb]>::len), Some(1));
    assert_eq!(world.shapes().boxes(1).map(<[Aabb]>::len), Some(2));
    assert!(world.shapes().boxes(2).is_none());
    // the mismatch is said once, though the maps and the world both classified the part
    assert_eq!(maps.warnings().iter().filter(|w| w.contains("extras.asp.boxes")).count(), 1, "{:?}", maps.warnings());

    // one flag: off, the maps and the world both test meshes
    let meshes = MapConfig::builder().resolution(3).exact_boxes(false).build().unwrap();
    let world = std::sync::Arc::new(World::new(asm.clone(), &meshes.world_config(&asm)).unwrap());
    let maps = DistanceMaps::build_on(world.clone(), &meshes).unwrap();
    assert!((0..3).all(|i| maps.geometry(i) == PartGeometry::Mesh && world.shapes().boxes(i).is_none()));
    assert!(DistanceMaps::build_on(world, &config).is_err(), "a world with the other setting is refused");
}

#[test]
fn map_state_clone_from_copies_the_kept_rows_that_differ() {
    // A column of four boxes; two states part ways, then one is copied onto the other.
    let parts = (0..4)
        .map(|k| {
            let z = k as f32;
            part(&format!("b{k}"), Mesh::cuboid(Vec3::new(0.0, 0.0, z), Vec3::new(1.0, 1.0, z + 1.0)))
        })
        .collect();
    let maps = DistanceMaps::build(&assembly(parts), &MapConfig::default()).unwrap();
    let mut a = MapState::new(&maps);
    let mut b = MapState::new(&maps);
    // b keeps rows for the full state, a for the state without the top box
    for i in 0..4 {
        b.min_map(i);
    }
    a.remove(3);
    for i in 0..3 {
        a.min_map(i);
    }
    let mut acts = Vec::new();
    a.feasible_actions(&mut acts);
    b.clone_from(&a);
    assert_eq!(b.present(), a.present());
    assert_eq!(b.counters(), a.counters());
    for i in 0..3 {
        let direct = maps.min_map(i, &a.present());
        assert_eq!(b.min_map(i), direct.as_slice(), "part {i}");
        assert_eq!(b.min_map_sum(i), a.min_map_sum(i), "part {i}");
        assert_eq!(b.free_mask(i), a.free_mask(i), "part {i}");
    }
    let mut again = Vec::new();
    b.feasible_actions(&mut again);
    assert_eq!(again, acts);
    // both go on alike
    a.remove(2);
    b.remove(2);
    a.feasible_actions(&mut acts);
    b.feasible_actions(&mut again);
    assert_eq!(again, acts);
    assert_eq!(b.min_map(1), a.min_map(1));
}

#[test]
fn map_state_kept_sums_answer_like_a_fresh_state() {
    // A 2×2×2 block of unit boxes; one state jumps between subsets (the search's resets), so
    // that rows are recomputed, evicted and found again among the kept sums.
    let mut parts = Vec::new();
    for z in 0..2 {
        for y in 0..2 {
            for x in 0..2 {
                let lo = Vec3::new(x as f32, y as f32, z as f32);
                parts.push(part(&format!("c{x}{y}{z}"), Mesh::cuboid(lo, lo + Vec3::ONE)));
            }
        }
    }
    let maps = DistanceMaps::build(&assembly(parts), &MapConfig::builder().resolution(5).build().unwrap()).unwrap();
    let n = 8;
    let subsets: Vec<PartSet> = [
        vec![0, 1, 2, 3, 4, 5, 6, 7],
        vec![0, 1, 2, 3, 4, 5, 6],
        vec![0, 1, 2, 3, 4, 5],
        vec![0, 1, 2, 3, 5, 6, 7],
        vec![0, 1, 2, 3, 7],
        vec![0, 1, 2, 3, 4],
        vec![0, 1, 2, 3],
        vec![0, 2, 3],
    ]
    .into_iter()
    .map(|v| PartSet::from_indices(n, v))
    .collect();
    let mut s = MapState::new(&maps);
    for round in 0..3 {
        for (k, present) in subsets.iter().enumerate().chain(subsets.iter().enumerate().rev()) {
            s.reset(present);
            let mut fresh = MapState::new(&maps);
            fresh.reset(present);
            for i in present.iter() {
                // free directions first (before any row of this state), then the sum, then again
                assert_eq!(s.free_mask(i), fresh.free_mask(i), "round {round} subset {k} part {i}");
                let want = fresh.min_map_sum(i);
                assert_eq!(s.min_map_sum(i), want, "round {round} subset {k} part {i}");
                assert_eq!(s.free_mask(i), fresh.free_mask(i), "round {round} subset {k} part {i}");
                let direct: f64 = maps.min_map(i, present).iter().map(|&v| v as f64).sum();
                assert!((want - direct).abs() < 1e-3 * direct.abs().max(1.0), "round {round} subset {k} part {i}");
            }
        }
    }
}
