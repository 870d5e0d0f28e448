//! `--stability physics`: states judged by simulating them under gravity with rapier3d.

use asp_geom::math::{Axis, Vec3};
use asp_geom::{
    fixtures, Assembly, Checker, CheckerConfig, FeasibilityChecker, Mesh, MotionKind, Outcome, Part, PartSet, PhysicsConfig,
    PhysicsStability, Stability, StabilityMode, Units, World, WorldConfig,
};

fn world(a: Assembly) -> World {
    World::new(a, &WorldConfig::default()).expect("fixture builds")
}

fn physics(w: &World) -> PhysicsStability {
    PhysicsStability::new(w, &PhysicsConfig::default())
}

fn set(n: usize, parts: &[usize]) -> PartSet {
    PartSet::from_indices(n, parts.iter().copied())
}

fn unstable(n: usize, parts: &[usize]) -> Stability {
    Stability::Unstable { floating: set(n, parts) }
}

fn part(name: &str, mesh: Mesh, fixed: bool) -> Part {
    Part::new(name, mesh, fixed, serde_json::Value::Null)
}

fn cuboid(mins: [f32; 3], maxs: [f32; 3]) -> Mesh {
    Mesh::cuboid(Vec3::from_array(mins), Vec3::from_array(maxs))
}

/// A +Z-up assembly in metres.
fn assembly(parts: Vec<Part>) -> Assembly {
    Assembly { parts, units: Units::metres(), up: Axis::Z, source: "test:physics".into(), warnings: Vec::new() }
}

/// A fixed base slab with one box on it (`mins`, `maxs` of the box).
fn box_on_base(mins: [f32; 3], maxs: [f32; 3]) -> Assembly {
    assembly(vec![part("base", cuboid([-2.0, -2.0, -0.5], [3.0, 3.0, 0.0]), true), part("box", cuboid(mins, maxs), false)])
}

#[test]
fn stacked_boxes_stand() {
    let w = world(fixtures::stacked_boxes());
    let p = physics(&w);
    assert_eq!(p.stability(&w, &PartSet::full(3)), Stability::Stable);
    // the lower box alone on the base
    assert_eq!(p.stability(&w, &set(3, &[0, 1])), Stability::Stable);
    // the top box without the lower one hangs 1 m above the base: it falls
    assert_eq!(p.stability(&w, &set(3, &[0, 2])), unstable(3, &[2]));
}

#[test]
fn cantilevered_keystone_falls_under_physics_but_not_in_the_contact_graph() {
    let w = world(fixtures::arch());
    let p = physics(&w);
    // base, pillar_a, pillar_b, keystone
    assert_eq!(p.stability(&w, &PartSet::full(4)), Stability::Stable);
    assert_eq!(p.stability(&w, &set(4, &[0, 1, 2])), Stability::Stable);
    // the keystone on pillar_b only: its centre of mass lies over the gap
    let cantilever = set(4, &[0, 2, 3]);
    assert_eq!(w.contacts().stability(&cantilever), Stability::Stable);
    assert_eq!(p.stability(&w, &cantilever), unstable(4, &[3]));
    // same answer every time
    assert_eq!(p.stability(&w, &cantilever), unstable(4, &[3]));
    // the keystone alone floats under both criteria
    let alone = set(4, &[0, 3]);
    assert_eq!(w.contacts().stability(&alone), unstable(4, &[3]));
    assert_eq!(p.stability(&w, &alone), unstable(4, &[3]));
}

#[test]
fn the_tube_cap_falls_and_nothing_else_is_kicked() {
    // receptacle (fixed), stick, handle on the stick, cap under the receptacle: nothing holds
    // the cap up. The stick stays in its zero-clearance hole and the handle on it. Regression:
    // the receptacle's triangle mesh gave the cap and the stick false contacts metres deep at
    // triangle edges, and the stick, pushed out of one, kicked the handle off.
    let w = world(fixtures::tube());
    assert_eq!(physics(&w).stability(&w, &PartSet::full(4)), unstable(4, &[3]));
}

#[test]
fn a_box_above_a_gap_falls() {
    let w = world(box_on_base([0.0, 0.0, 0.1], [1.0, 1.0, 1.1]));
    assert_eq!(physics(&w).stability(&w, &PartSet::full(2)), unstable(2, &[1]));
}

#[test]
fn a_tall_thin_box_balances_on_its_end() {
    let w = world(box_on_base([0.0, 0.0, 0.0], [0.1, 0.1, 2.0]));
    assert_eq!(physics(&w).stability(&w, &PartSet::full(2)), Stability::Stable);
}

#[test]
fn a_box_overhanging_an_edge_stays_while_its_centre_is_supported() {
    // the base ends at x = 3; a box reaching 0.4 past the edge keeps its centre over the base,
    // a box reaching 0.6 past it does not
    let w = world(box_on_base([2.4, 0.0, 0.0], [3.4, 1.0, 1.0]));
    assert_eq!(physics(&w).stability(&w, &PartSet::full(2)), Stability::Stable);
    let w = world(box_on_base([2.6, 0.0, 0.0], [3.6, 1.0, 1.0]));
    assert_eq!(physics(&w).stability(&w, &PartSet::full(2)), unstable(2, &[1]));
}

#[test]
fn a_pressed_plug_holds_in_a_ring() {
    // a fixed frame (7 × 7 cells around a 5 × 5 opening) carries a ring (7 × 7 × 1 around a
    // 3 × 3 hole); a plug 0.02 wider than the hole on each side is pressed through it and hangs
    // into the frame's opening. The interference fit bonds plug and ring; simulated as two
    // bodies, nothing would hold the plug up (the fit's contacts push sideways only)
    let ring = |z: i32, inner: std::ops::Range<i32>| -> Vec<[i32; 3]> {
        (0..7).flat_map(|x| (0..7).map(move |y| [x, y, z])).filter(|c| !inner.contains(&c[0]) || !inner.contains(&c[1])).collect()
    };
    let a = assembly(vec![
        part("frame", Mesh::from_voxels(&ring(-1, 1..6), Vec3::ONE, Vec3::ZERO), true),
        part("ring", Mesh::from_voxels(&ring(0, 2..5), Vec3::ONE, Vec3::ZERO), false),
        part("plug", cuboid([1.98, 1.98, -0.8], [5.02, 5.02, 1.0]), false),
    ]);
    let w = world(a);
    assert!(w.overlaps().pairs().contains_key(&(1, 2)), "the fit is an input overlap: {:?}", w.overlaps().pairs());
    assert!(!w.overlaps().pairs().contains_key(&(0, 2)), "{:?}", w.overlaps().pairs());
    let p = physics(&w);
    assert_eq!(p.stability(&w, &PartSet::full(3)), Stability::Stable);
    // without the ring the plug falls through the frame
    assert_eq!(p.stability(&w, &set(3, &[0, 2])), unstable(3, &[2]));
}

/// What the model says is fastened holds. A bracket touches a post's side only,
/// in mid-air: it falls, unless its extras say it is screwed to the post (`fastened_to`), or the
/// post says it holds the bracket (the connector's `holds`); with the post gone the fastening
/// goes too. A name that is no part of the model is a load warning, not a bond.
#[test]
fn a_fastened_bracket_holds_on_the_side_of_a_post() {
    let model = |bracket_extras: serde_json::Value, post_extras: serde_json::Value| {
        assembly(vec![
            part("base", cuboid([-2.0, -2.0, -0.5], [3.0, 3.0, 0.0]), true),
            Part::new("post", cuboid([0.0, 0.0, 0.0], [0.2, 0.2, 2.0]), false, post_extras),
            Part::new("bracket", cuboid([0.2, 0.0, 1.0], [0.6, 0.2, 1.2]), false, bracket_extras),
        ])
    };
    let null = serde_json::Value::Null;
    let w = world(model(null.clone(), null.clone()));
    assert_eq!(physics(&w).stability(&w, &PartSet::full(3)), unstable(3, &[2]), "nothing holds the bracket");
    for (bracket, post) in [
        (serde_json::json!({"asp": {"fastened_to": ["post"]}}), null.clone()),
        (null.clone(), serde_json::json!({"asp": {"kind": "connector", "holds": "bracket"}})),
    ] {
        let w = world(model(bracket.clone(), post.clone()));
        assert_eq!(w.assembly().fastenings(), (vec![(1, 2)], Vec::new()));
        let p = physics(&w);
        assert_eq!(p.stability(&w, &PartSet::full(3)), Stability::Stable, "{bracket} {post}");
        assert_eq!(p.stability(&w, &set(3, &[0, 2])), unstable(3, &[2]), "the post gone, the bracket falls");
    }
    let a = model(serde_json::json!({"asp": {"fastened_to": ["pillar", "bracket"]}}), null);
    let (pairs, warnings) = a.fastenings();
    assert!(pairs.is_empty());
    assert_eq!(warnings.len(), 2, "{warnings:?}");
    assert!(warnings[0].contains("'bracket'") && warnings[0].contains("'pillar'") && warnings[0].contains("ignored"), "{warnings:?}");
}

/// A cradle (3 × 1 × 2) standing on a fixed base, with a 1 × 1 notch `depth` deep in the middle
/// of its top, and a unit block resting on the notch's floor.
fn cradle(depth: f32) -> Assembly {
    // layers of `depth` thickness, so the notch is one cell deep
    let layers = (2.0 / depth).round() as i32;
    let cells: Vec<[i32; 3]> = (0..3).flat_map(|x| (0..layers).map(move |z| [x, 0, z])).filter(|c| *c != [1, 0, layers - 1]).collect();
    let floor = 2.0 - depth;
    assembly(vec![
        part("base", cuboid([-2.0, -2.0, -0.5], [5.0, 3.0, 0.0]), true),
        part("cradle", Mesh::from_voxels(&cells, Vec3::new(1.0, 1.0, depth), Vec3::ZERO), false),
        part("block", cuboid([1.0, 0.0, floor], [2.0, 1.0, floor + 1.0]), false),
    ])
}

#[test]
fn a_collider_swelling_into_a_neighbour_does_not_push_it_away() {
    // as its convex hull the cradle fills its 0.4-deep notch, so the block starts 0.4 inside it
    // (more than the threshold): that pair's contacts are shifted by the initial depth, and the
    // block stays where it rests instead of being pushed out
    let w = world(cradle(0.4));
    let hulls = PhysicsConfig { convex_decomposition: false, ..PhysicsConfig::default() };
    let p = PhysicsStability::new(&w, &hulls);
    assert!(p.threshold() < 0.4, "{}", p.threshold());
    assert_eq!(p.stability(&w, &PartSet::full(3)), Stability::Stable);
}

#[test]
fn the_convex_decomposition_follows_a_deep_notch() {
    // a U with a notch of half its height: its pieces overlap the block a little where the
    // notch's coarse triangles reach across pieces, but the block stays on the notch's floor
    let w = world(cradle(1.0));
    assert_eq!(physics(&w).stability(&w, &PartSet::full(3)), Stability::Stable);
    // without the cradle the block falls onto the base
    assert_eq!(physics(&w).stability(&w, &set(3, &[0, 2])), unstable(3, &[2]));
}

#[test]
fn checker_reports_a_removal_that_leaves_the_keystone_cantilevered() {
    let config = CheckerConfig { stability: StabilityMode::Physics(PhysicsConfig::default()), ..CheckerConfig::default() };
    let checker = Checker::new(world(fixtures::arch()), config);
    // pillar_a slides out sideways; the keystone then rests on pillar_b alone and tips over
    match checker.test_removal(1, &PartSet::full(4), MotionKind::Linear) {
        Outcome::Unstable { floating, .. } => assert_eq!(floating, set(4, &[3])),
        other => panic!("expected an unstable outcome, got {other:?}"),
    }
    assert_eq!(checker.counters().failed_gravity, 1);
    // the contact graph lets the same removal through
    let graph = Checker::new(world(fixtures::arch()), CheckerConfig::default());
    assert!(matches!(graph.test_removal(1, &PartSet::full(4), MotionKind::Linear), Outcome::Removed(_)));
}
