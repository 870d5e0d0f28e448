//! Input overlaps: press fits are data, not errors, and under the default
//! strict policy an overlapping pair separates only along motions that enter no new material.

use crate::removal::free_axes;
use asp_geom::math::Vec3;
use asp_geom::overlap::OverlapKind;
use asp_geom::{
    fixtures, Checker, CheckerConfig, FeasibilityChecker, Motion, MotionKind, Outcome, OverlapPolicy, PartSet, World, WorldConfig,
};

fn world(a: asp_geom::Assembly, overlaps: OverlapPolicy) -> asp_geom::Result<World> {
    World::new(a, &WorldConfig { overlaps, ..WorldConfig::default() })
}

/// Every candidate direction along which `part` is free in `state`.
fn free_directions(w: &World, part: usize, state: &PartSet) -> Vec<Vec3> {
    let row = w.blocking().row(part);
    let present = w.contacts().with_fixed(state);
    w.blocking().directions().iter().enumerate().filter(|(k, _)| !row[*k].intersects(&present)).map(|(_, d)| *d).collect()
}

#[test]
fn a_pressed_peg_leaves_along_its_axis_only() {
    let w = world(fixtures::pressed_peg(), OverlapPolicy::Strict).expect("strict never stops on overlaps");
    let all = PartSet::full(2);
    assert_eq!(free_axes(&w, 1, &all), vec!["+z"]);
    // not only the axes: every free candidate direction is the axis
    let free = free_directions(&w, 1, &all);
    assert!(!free.is_empty() && free.iter().all(|d| d.dot(Vec3::Z) > 0.9999), "{free:?}");
    match w.removal().linear(1, &all).unwrap() {
        Motion::Linear { direction, .. } => assert!(direction.dot(Vec3::Z) > 0.9999),
        m => panic!("{m:?}"),
    }
    // the pair is reported: gross (no shrinking separates them), handled strictly, warned once
    let notes = w.overlaps().notes();
    assert_eq!(notes.len(), 1, "{notes:?}");
    assert_eq!((notes[0].parts, notes[0].gross, notes[0].handling), ((0, 1), true, asp_geom::overlap::OverlapHandling::Strict));
    assert_eq!(notes[0].kind, OverlapKind::Crossing);
    let warned: Vec<&String> = w.warnings().iter().filter(|s| s.contains("'plate' and 'peg'")).collect();
    assert_eq!(warned.len(), 1, "{:?}", w.warnings());
    // measured where they overlap (the peg is 0.5 into the plate), not bounded by shrinking
    assert!(warned[0].contains("by about 0.500 m (measured where they overlap") && warned[0].contains("no new material"), "{}", warned[0]);
    assert_eq!((notes[0].class, notes[0].bound), (asp_geom::overlap::OverlapClass::Interpenetration, false));
}

#[test]
fn the_lenient_policy_lets_the_peg_slide_sideways_and_error_stops() {
    // what strict fixes: ignoring the pair frees every direction but down into the plate's
    // other side... and sideways
    let w = world(fixtures::pressed_peg(), OverlapPolicy::Lenient).unwrap();
    let free = free_axes(&w, 1, &PartSet::full(2));
    assert!(free.contains(&"+x") && free.contains(&"+z"), "{free:?}");
    assert_eq!(w.overlaps().notes()[0].handling, asp_geom::overlap::OverlapHandling::Ignored);
    let err = world(fixtures::pressed_peg(), OverlapPolicy::Error).err().expect("error policy").to_string();
    assert!(err.contains("'plate' and 'peg'") && err.contains("overlaps policy"), "{err}");
}

#[test]
fn a_dowel_in_two_boards_comes_out_after_the_upper_board_both_upward() {
    let w = world(fixtures::dowel_in_two_boards(), OverlapPolicy::Strict).unwrap();
    let all = PartSet::full(3);
    // the dowel is held by both boards; the upper board pulls off it upward only
    assert_eq!(free_axes(&w, 2, &all), Vec::<&str>::new());
    assert_eq!(free_axes(&w, 1, &all), vec!["+z"]);
    assert_eq!(free_axes(&w, 2, &all.without(1)), vec!["+z"]);
    let pairs: Vec<(usize, usize)> = w.overlaps().notes().iter().map(|n| n.parts).collect();
    assert_eq!(pairs, vec![(0, 2), (1, 2)]);
    // and the checker (every place a removal is tested goes through the blocking rows)
    let checker = Checker::new(w, CheckerConfig::default());
    assert!(matches!(checker.test_removal(2, &all, MotionKind::Linear), Outcome::Collision { .. }));
    match checker.test_removal(1, &all, MotionKind::Linear) {
        Outcome::Removed(Motion::Linear { direction, .. }) => assert!(direction.dot(Vec3::Z) > 0.9999),
        o => panic!("{o:?}"),
    }
}

/// A dowel drawn into a large solid panel (no hole modelled) may not slide sideways through it:
/// the panel's whole-surface samples are about 2 cm apart on its 2 m² of surface, and the
/// 8 mm dowel slid between them until the pair's own samples near the dowel came in (the
/// carcasses of `asp gen stress`: the independent replay saw the dowels cut
/// through their side panels).
#[test]
fn a_dowel_drawn_into_a_large_panel_leaves_along_its_axis_only() {
    let mut panel = fixtures::box_part("panel", [0.0, 0.0, 0.0], [1.0, 1.0, 0.018]);
    panel.fixed = true;
    let dowel = fixtures::part("dowel", fixtures::prism(0.37, 0.61, 0.004, 0.003, 0.033, 16), false);
    let w = world(fixtures::assemble("dowel_in_panel", vec![panel, dowel], asp_geom::math::Axis::Z), OverlapPolicy::Strict).unwrap();
    assert!(w.overlaps().notes()[0].gross, "{:?}", w.overlaps().notes());
    let all = PartSet::full(2);
    assert_eq!(free_axes(&w, 1, &all), vec!["+z"]);
    let free = free_directions(&w, 1, &all);
    assert!(!free.is_empty() && free.iter().all(|d| d.dot(Vec3::Z) > 0.9999), "{free:?}");
}

#[test]
fn a_nested_part_is_reported_and_held() {
    // a small box wholly inside a bigger one (a duplicated inner body)
    let mut outer = fixtures::box_part("outer", [0.0, 0.0, 0.0], [2.0, 2.0, 2.0]);
    outer.fixed = true;
    let inner = fixtures::box_part("inner", [0.5, 0.5, 0.5], [1.5, 1.5, 1.5]);
    let w = world(fixtures::assemble("nested", vec![outer, inner], asp_geom::math::Axis::Z), OverlapPolicy::Strict).unwrap();
    let notes = w.overlaps().notes();
    assert_eq!(notes.len(), 1, "{notes:?}");
    assert_eq!(notes[0].kind, OverlapKind::Nested { inner: 1 });
    assert!(w.warnings().iter().any(|s| s.contains("'inner' lies inside the other")), "{:?}", w.warnings());
    assert!(free_directions(&w, 1, &PartSet::full(2)).is_empty(), "embedded in solid material, it cannot leave");
}

#[test]
fn coincident_parts_are_reported_and_separate() {
    let mut a = fixtures::box_part("a", [0.0, 0.0, 0.0], [1.0, 1.0, 1.0]);
    a.fixed = true;
    let b = fixtures::box_part("b", [0.0, 0.0, 0.0], [1.0, 1.0, 1.0]);
    let w = world(fixtures::assemble("coincident", vec![a, b], asp_geom::math::Axis::Z), OverlapPolicy::Strict).unwrap();
    let notes = w.overlaps().notes();
    assert_eq!(notes.len(), 1, "{notes:?}");
    assert_eq!(notes[0].kind, OverlapKind::Coincident);
    // a copy moving out of its twin enters no material the pair did not already share
    assert_eq!(free_axes(&w, 1, &PartSet::full(2)).len(), 6);
}

/// A locked core's lenient rerun tests its pairs in [`World::lenient`], a copy
/// of the strict world that measures nothing again; it must test exactly as a world built with
/// the lenient policy (a small overlap shrunk, a gross one ignored, the rest unchanged).
#[test]
fn the_lenient_copy_of_a_strict_world_tests_as_a_lenient_world() {
    let bolt = fixtures::bolt_and_nut(0.0005);
    for a in [fixtures::pressed_peg(), fixtures::dowel_in_two_boards(), bolt, fixtures::ring_on_locked_post()] {
        let name = a.source.display().to_string();
        let strict = world(a.clone(), OverlapPolicy::Strict).unwrap();
        let built = world(a, OverlapPolicy::Lenient).unwrap();
        let copy = strict.lenient();
        assert_eq!(copy.overlaps().policy(), OverlapPolicy::Lenient);
        assert_eq!(copy.overlaps().notes(), built.overlaps().notes(), "{name}");
        assert_eq!(copy.blocking().directions(), built.blocking().directions(), "{name}");
        assert_eq!(copy.config(), built.config(), "{name}");
        for p in 0..copy.num_parts() {
            assert_eq!(copy.blocking().row(p), built.blocking().row(p), "{name}: part {p}");
            for q in 0..copy.num_parts() {
                assert_eq!(
                    (copy.overlaps().ignores(p, q), copy.overlaps().is_strict(p, q)),
                    (built.overlaps().ignores(p, q), built.overlaps().is_strict(p, q)),
                    "{name}"
                );
            }
        }
    }
    // and the peg it frees is held by the strict world it was copied from
    let strict = world(fixtures::pressed_peg(), OverlapPolicy::Strict).unwrap();
    let all = PartSet::full(2);
    assert_eq!(free_axes(&strict, 1, &all), vec!["+z"]);
    assert!(free_axes(&strict.lenient(), 1, &all).len() > 1);
}

/// A turn off every axis: the boards' slab normal is then no axis.
fn tilt() -> asp_geom::math::Rot {
    asp_geom::math::Rot::from_axis_angle(Vec3::new(1.0, 2.0, 0.5).normalize(), 0.3)
}

/// Depth overstated and false entries: a board sunk 1.5 mm into another along planar
/// faces (a gross pair, tested by the strict rule alone) lifts off along the slab's normal,
/// whatever the holes' tessellation and on or off the axes; sideways, and down into the lower
/// board, it is refused. Samples at the sliver fans' centroids and vertices around the holes
/// inside the slab graze the other board's hole walls as it lifts.
#[test]
fn a_board_sunk_into_another_lifts_off_along_the_slab_normal_only() {
    for (facets, thickness) in [(16, 0.003), (96, 0.003), (16, 0.010), (96, 0.010)] {
        for turn in [asp_geom::math::Rot::IDENTITY, tilt()] {
            let w = world(fixtures::sunk_boards(facets, thickness, turn), OverlapPolicy::Strict).unwrap();
            let n = &w.overlaps().notes()[0];
            assert_eq!(n.class, asp_geom::overlap::OverlapClass::PlanarSlab, "{facets}: {n:?}");
            let normal = n.normal.unwrap();
            let all = PartSet::full(2);
            let free = free_directions(&w, 1, &all);
            assert!(!free.is_empty(), "{facets} facets, turn {turn:?}: the upper board cannot lift off");
            assert!(free.iter().all(|d| d.dot(normal) > 0.9999), "{facets}: only the lift along the normal: {free:?}");
            // every candidate within 0.1° of the normal lifts it too: a grid corner of the lower
            // board lies in the plane of the upper's side face, and parry saw that sample's path
            // "cross" the upper's bottom edge 1e-5° off the normal (a false entry, now a graze)
            for d in w.blocking().directions().iter().filter(|d| d.dot(normal) > 0.999_998_5) {
                assert!(!w.blocking().pair_blocks(1, 0, *d), "{facets}, {thickness} m: the lift along {d:?} is refused");
            }
            // sideways (along the boards) and down, every way refused
            for d in [turn * Vec3::X, -(turn * Vec3::X), turn * Vec3::Y, -(turn * Vec3::Y), -normal] {
                assert!(w.blocking().pair_blocks(1, 0, d), "{facets}: the upper board slides along {d:?}");
            }
            match w.removal().linear(1, &all).unwrap() {
                Motion::Linear { direction, .. } => assert!(direction.dot(normal) > 0.9999, "{direction:?}"),
                m => panic!("{m:?}"),
            }
        }
    }
}

/// The slab's normal joins the candidate directions: with no normal clusters and no planar
/// contact directions (fasteners off), the tilted boards' only lift is the slab's own normal.
#[test]
fn the_slab_normal_is_a_candidate_direction() {
    let config = WorldConfig { normal_clusters: 0, fasteners: false, ..WorldConfig::default() };
    let w = World::new(fixtures::sunk_boards(16, 0.003, tilt()), &config).unwrap();
    let normal = w.overlaps().notes()[0].normal.unwrap();
    let free = free_directions(&w, 1, &PartSet::full(2));
    assert!(!free.is_empty() && free.iter().all(|d| d.dot(normal) > 0.9999), "{free:?}");
}
