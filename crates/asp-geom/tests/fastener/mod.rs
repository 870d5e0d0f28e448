//! Threaded fasteners: a bolt with a modelled helical thread in a nut with the
//! matching internal thread leaves by screwing along its axis, only the way its head allows.

use crate::removal::free_axes;
use asp_geom::math::Vec3;
use asp_geom::{fastener, fixtures, Motion, PartSet, World, WorldConfig};
use parry3d::query::PointQuery;

const PLATE: usize = 0;
const BOLT: usize = 1;
const NUT: usize = 2;

fn world(interference: f32, fasteners: bool) -> World {
    World::new(fixtures::bolt_and_nut(interference), &WorldConfig { fasteners, ..WorldConfig::default() }).unwrap()
}

#[test]
fn the_fixture_is_a_closed_helical_bolt_in_a_nut_whose_threads_touch() {
    let w = world(0.0, true);
    for p in 0..3 {
        assert!(w.shapes().is_closed(p), "{}", w.name(p));
    }
    // the thread surfaces coincide: the shrunk sweep's erosion of the V-thread leaves them
    // crossing a little (a small overlap, as in CAD), never a gross one
    assert!(w.overlaps().notes().iter().all(|n| !n.gross && n.depth < 0.0002), "{:?}", w.overlaps().notes());
    assert!(w.contacts().of(BOLT).contains(NUT) && w.contacts().of(BOLT).contains(PLATE) && w.contacts().of(NUT).contains(PLATE));
    // the thread is helical: the bolt's surface is not invariant under a pure turn of 180° at
    // a fixed height (the crest lands on the root), only with half a pitch's shift
    let m = w.shapes().mesh(BOLT);
    let axis = w.shapes().symmetry_axis(BOLT).expect("the bolt has an axis");
    assert!(axis.direction.dot(Vec3::Z).abs() > 0.99999, "{axis:?}");
    assert!(axis.radial(Vec3::ZERO) < 1e-5, "{axis:?}");
    // a crest vertex (angle 0, height 0) turned by 180° about the Z axis
    assert!((m.project_local_point(Vec3::new(0.005, 0.0, 0.0), false).point - Vec3::new(0.005, 0.0, 0.0)).length() < 1e-7);
    let turned = Vec3::new(-0.005, 0.0, 0.0);
    let off = (m.project_local_point(turned, false).point - turned).length();
    assert!(off > 0.0003, "a half turn moves the crest {off} off the surface");
    let shifted = turned + Vec3::Z * 0.00075;
    assert!((m.project_local_point(shifted, false).point - shifted).length() < 1e-7);
}

#[test]
fn a_threaded_bolt_in_a_threaded_nut_leaves_by_screwing_only_the_way_its_head_allows() {
    for interference in [0.0, 0.0001] {
        let w = world(interference, true);
        let all = PartSet::full(3);
        let t = w.overlaps().fits().thread(BOLT, NUT).unwrap_or_else(|| panic!("interference {interference}: bolt and nut are threaded"));
        assert!(t.axis.direction.dot(Vec3::Z).abs() > 0.99999);
        // the zone reaches the thread's major radius (plus the contact slack), not the head
        assert!(t.radius > 0.0049 && t.radius < 0.0052, "{t:?}");
        assert!(w.overlaps().fits().thread(NUT, BOLT).is_some(), "the nut turns off the bolt too");
        // the plate's square clearance hole is no thread; the head's bearing face is no flank
        assert!(w.overlaps().fits().thread(BOLT, PLATE).is_none() && w.overlaps().fits().thread(NUT, PLATE).is_none());
        // the bolt: out upward only (its head stops it downward, its thread and the plate's
        // hole sideways), by screwing
        assert_eq!(free_axes(&w, BOLT, &all), vec!["+z"], "interference {interference}");
        match w.removal().linear(BOLT, &all) {
            Ok(Motion::Screw { direction, axis_point, distance }) => {
                assert!(direction.dot(Vec3::Z) > 0.9999, "{direction:?}");
                assert!(t.axis.radial(axis_point) < 1e-5 && distance > 0.0);
            }
            other => panic!("interference {interference}: {other:?}"),
        }
        // the nut: off downward only, by screwing
        assert_eq!(free_axes(&w, NUT, &all), vec!["-z"], "interference {interference}");
        assert!(matches!(w.removal().linear(NUT, &all), Ok(Motion::Screw { direction, .. }) if direction.dot(-Vec3::Z) > 0.9999));
        // with the nut gone the bolt leaves the plate's plain hole upward by a straight line
        let no_nut = PartSet::from_indices(3, [PLATE, BOLT]);
        assert_eq!(free_axes(&w, BOLT, &no_nut), vec!["+z"]);
        assert!(matches!(w.removal().linear(BOLT, &no_nut), Ok(Motion::Linear { .. })));
    }
}

#[test]
fn without_the_screw_rule_the_bolt_and_nut_lock_each_other() {
    for interference in [0.0, 0.0001] {
        let w = world(interference, false);
        let all = PartSet::full(3);
        assert!(w.overlaps().fits().thread(BOLT, NUT).is_none());
        // the flanks stop every straight line along the axis: the pair is locked
        assert_eq!(free_axes(&w, BOLT, &all), Vec::<&str>::new(), "interference {interference}");
        assert_eq!(free_axes(&w, NUT, &all), Vec::<&str>::new(), "interference {interference}");
        let blockers = w.removal().linear(BOLT, &all).expect_err("locked");
        assert!(blockers.contains(NUT), "{blockers:?}");
        let blockers = w.removal().linear(NUT, &all).expect_err("locked");
        assert!(blockers.contains(BOLT), "{blockers:?}");
    }
}

#[test]
fn smooth_pins_are_not_threads_and_the_fit_finds_a_prisms_axis() {
    // a round dowel pressed into two boards is rotationally symmetric and in contact, but has
    // no thread flanks: it leaves by a straight line, as before
    let w = World::new(fixtures::dowel_in_two_boards(), &WorldConfig::default()).unwrap();
    assert!(w.overlaps().fits().threads().is_empty(), "{:?}", w.overlaps().fits().threads());
    // the kinematic fit finds a faceted prism's axis exactly
    let prism = fixtures::prism(1.0, 2.0, 0.3, 0.0, 1.0, 16);
    let (axis, _) = fastener::kinematic_axis(&prism.vertices, &prism.triangles).unwrap();
    assert!(axis.direction.dot(Vec3::Z).abs() > 0.99999 && axis.radial(Vec3::new(1.0, 2.0, 0.0)) < 1e-5, "{axis:?}");
}
