//! Fits and fasteners as CAD draws them ([`asp_geom::fits`]): bolts, nuts, tapped holes and
//! pressed pins at one nominal radius, no helix, tessellated coarse and fine, come apart along
//! their axes the way a mechanic takes them apart, and never sideways.

use crate::removal::free_axes;
use asp_geom::fits::{FitClass, Role};
use asp_geom::math::Vec3;
use asp_geom::{fixtures, Motion, PartSet, World, WorldConfig};

fn world(a: asp_geom::Assembly, fasteners: bool) -> World {
    World::new(a, &WorldConfig { fasteners, ..WorldConfig::default() }).unwrap()
}

/// Coarse (as a 0.1 mm export of an M10 joint: a 26-gon bolt) and fine tessellations.
const BOLTED: [[u32; 3]; 3] = [[26, 16, 12], [26, 32, 30], [96, 128, 90]];

#[test]
fn a_bolted_joint_is_two_line_to_line_fits_and_a_nut_that_turns() {
    let (base, top, bolt, nut) = (0, 1, 2, 3);
    for facets in BOLTED {
        let w = world(fixtures::bolted_joint(facets), true);
        assert_eq!((w.overlaps().fits().role(bolt), w.overlaps().fits().role(nut)), (Role::Bolt, Role::Nut), "{facets:?}");
        assert_eq!((w.overlaps().fits().role(base), w.overlaps().fits().role(top)), (Role::Other, Role::Other), "{facets:?}");
        for plate in [base, top] {
            let f = w.overlaps().fits().between(bolt, plate);
            assert_eq!(f.len(), 1, "{facets:?}: {f:?}");
            assert_eq!((f[0].class, f[0].shaft, f[0].hole, f[0].turns), (FitClass::LineToLine, bolt, plate, None), "{facets:?}");
            assert!(f[0].axis.dot(Vec3::Z).abs() > 0.99999 && (f[0].shaft_radius - 0.005).abs() < 2e-5);
        }
        let f = w.overlaps().fits().between(bolt, nut);
        assert_eq!(f.len(), 1, "{facets:?}");
        assert_eq!((f[0].class, f[0].turns), (FitClass::LineToLine, Some(nut)), "{facets:?}");
    }
}

#[test]
fn a_nut_unscrews_first_then_the_bolt_pulls_out_along_its_axis_whatever_the_tessellation() {
    let (top, bolt, nut) = (1, 2, 3);
    for facets in BOLTED {
        let w = world(fixtures::bolted_joint(facets), true);
        let all = PartSet::full(4);
        // the bolt cannot slide out of its nut, nor sideways out of the plates
        assert!(free_axes(&w, bolt, &all).is_empty(), "{facets:?}: {:?}", free_axes(&w, bolt, &all));
        assert!(free_axes(&w, top, &all).is_empty(), "{facets:?}");
        // the nut unscrews downward (upward is the base plate)
        assert_eq!(free_axes(&w, nut, &all), vec!["-z"], "{facets:?}");
        match w.removal().linear(nut, &all) {
            Ok(Motion::Screw { direction, .. }) => assert!(direction.dot(-Vec3::Z) > 0.9999),
            other => panic!("{facets:?}: the nut unscrews, got {other:?}"),
        }
        // then the bolt leaves upward only (its head stops it downward), a straight pull
        let no_nut = PartSet::from_indices(4, [0, top, bolt]);
        assert_eq!(free_axes(&w, bolt, &no_nut), vec!["+z"], "{facets:?}");
        assert!(matches!(w.removal().linear(bolt, &no_nut), Ok(Motion::Linear { direction, .. }) if direction.dot(Vec3::Z) > 0.9999));
        // then the plate lifts
        let plates = PartSet::from_indices(4, [0, top]);
        assert!(free_axes(&w, top, &plates).contains(&"+z"));
    }
}

#[test]
fn without_fits_the_faceted_bolted_joint_is_locked() {
    // what the fits fix: the bolt's facets stand into its nut and holes, so no straight line
    // frees the nut or the bolt
    let w = world(fixtures::bolted_joint([26, 16, 12]), false);
    let all = PartSet::full(4);
    assert!(free_axes(&w, 2, &all).is_empty() && free_axes(&w, 3, &all).is_empty());
}

#[test]
fn a_screw_in_a_tapped_hole_at_the_minor_diameter_unscrews_and_holds_the_block() {
    let (block, plate, screw) = (0, 1, 2);
    for facets in [[26, 16], [90, 128]] {
        let w = world(fixtures::tapped_screw(facets), true);
        let f = w.overlaps().fits().between(screw, block);
        assert_eq!(f.len(), 1, "{facets:?}: {f:?}");
        assert_eq!((f[0].class, f[0].turns), (FitClass::Thread, Some(screw)), "{facets:?}");
        assert_eq!(w.overlaps().fits().between(screw, plate)[0].class, FitClass::LineToLine);
        let all = PartSet::full(3);
        assert_eq!(free_axes(&w, screw, &all), vec!["+z"], "{facets:?}");
        assert!(matches!(w.removal().linear(screw, &all), Ok(Motion::Screw { direction, .. }) if direction.dot(Vec3::Z) > 0.9999));
        // the clamp plate is held down by the screw's head, and the block cannot slide along a
        // screw turned into it
        assert!(free_axes(&w, plate, &all).is_empty());
        assert!(w.blocking().pair_blocks(block, screw, -Vec3::Z) && w.blocking().pair_blocks(block, screw, Vec3::Z));
        assert!(free_axes(&w, plate, &PartSet::from_indices(3, [block, plate])).contains(&"+z"));
    }
}

#[test]
fn a_pressed_pin_is_pressed_out_along_its_axis_and_never_dragged_sideways() {
    // (facets, interference, class): an interference within the two polygons' sagittas (0.15 mm
    // for two 16-gons of 4 mm, 0.05 mm for a 26-gon in a 32-gon) looks like one nominal radius
    let cases = [
        ([16, 16], 0.0, FitClass::LineToLine),
        ([16, 16], 0.0001, FitClass::LineToLine),
        ([26, 32], 0.0, FitClass::LineToLine),
        ([26, 32], 0.0001, FitClass::Press),
        ([90, 128], 0.0, FitClass::LineToLine),
        ([90, 128], 0.00005, FitClass::Press),
        ([90, 128], 0.0001, FitClass::Press),
    ];
    for (facets, interference, expected) in cases {
        {
            let w = world(fixtures::pressed_pin(facets, interference), true);
            let f = w.overlaps().fits().between(1, 0);
            assert_eq!(f.len(), 1, "{facets:?} {interference}: {f:?}");
            assert_eq!(f[0].class, expected, "{facets:?} {interference}");
            let free = free_axes(&w, 1, &PartSet::full(2));
            assert_eq!(free, vec!["+z", "-z"], "{facets:?} {interference}");
            for sideways in [Vec3::X, -Vec3::Y, Vec3::new(1.0, 0.0, 1.0).normalize()] {
                assert!(w.blocking().pair_blocks(1, 0, sideways), "{facets:?} {interference}: {sideways:?}");
            }
        }
    }
}

/// A slider in a closed channel whose axis lies `angle` degrees off +x in the xy plane (floor,
/// ceiling and two walls, fixed, each touching the slider face to face).
fn channel(angle: f32) -> asp_geom::Assembly {
    use asp_geom::fixtures::part;
    use asp_geom::math::{Pose, Rot};
    let turn = Pose::from_parts(Vec3::ZERO, Rot::from_rotation_z(angle.to_radians()));
    let b = |name: &str, lo: [f32; 3], hi: [f32; 3], fixed: bool| {
        part(name, asp_geom::Mesh::cuboid(Vec3::from(lo), Vec3::from(hi)).transformed(&turn), fixed)
    };
    let parts = vec![
        b("floor", [-0.1, -0.03, -0.01], [0.1, 0.03, 0.0], true),
        b("ceiling", [-0.1, -0.03, 0.02], [0.1, 0.03, 0.03], true),
        b("left wall", [-0.1, 0.01, 0.0], [0.1, 0.03, 0.02], true),
        b("right wall", [-0.1, -0.03, 0.0], [0.1, -0.01, 0.02], true),
        b("slider", [-0.02, -0.01, 0.0], [0.02, 0.01, 0.02], false),
    ];
    fixtures::assemble("channel", parts, asp_geom::math::Axis::Z)
}

#[test]
fn a_slide_along_the_line_two_planar_contacts_share_is_tried_a_fraction_of_a_degree_off_an_axis() {
    for angle in [0.4f32, 2.4] {
        let w = world(channel(angle), true);
        let all = PartSet::full(5);
        let u = Vec3::new(angle.to_radians().cos(), angle.to_radians().sin(), 0.0);
        match w.removal().linear(4, &all) {
            Ok(Motion::Linear { direction, .. }) => assert!(direction.dot(u).abs() > 0.99999, "{angle}: {direction:?}"),
            other => panic!("{angle}: the slider slides out along its channel, got {other:?}"),
        }
        // without the pair's own directions only the model's (axes, normal clusters merged
        // within a degree of them) are tried
        if angle < 1.0 {
            let w = world(channel(angle), false);
            assert!(w.removal().linear(4, &all).is_err(), "{angle}");
        }
    }
}
