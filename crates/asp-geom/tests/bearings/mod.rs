//! Rolling bearings recognised from their geometry ([`asp_geom::Bearing`]): balls or rollers
//! captive between two raced rings, whatever the tessellation and the number of them, in a
//! housing on a shaft or alone; and nothing taken for one that is not.

use asp_geom::fits::Role;
use asp_geom::math::Vec3;
use asp_geom::{fixtures, RollingElement, World, WorldConfig};

fn world(a: asp_geom::Assembly, fasteners: bool) -> World {
    World::new(a, &WorldConfig { fasteners, ..WorldConfig::default() }).unwrap()
}

#[test]
fn a_ball_bearing_in_a_housing_on_a_shaft_is_found_whatever_its_facets_and_balls() {
    for (facets, balls) in [(32, 7), (64, 9), (128, 12)] {
        let w = world(fixtures::ball_bearing(facets, balls, true), true);
        let (inner, outer) = (2, 3);
        let b = w.overlaps().fits().bearings();
        assert_eq!(b.len(), 1, "{facets} facets, {balls} balls: {b:?}");
        let b = &b[0];
        assert_eq!(b.rings, [inner, outer], "{facets}/{balls}");
        assert_eq!(b.balls, (4..4 + balls as usize).collect::<Vec<_>>(), "{facets}/{balls}");
        assert!(b.others.is_empty(), "the housing and the shaft are not the bearing's: {:?}", b.others);
        assert_eq!((b.rows, b.elements), (1, RollingElement::Ball));
        assert!(b.axis.dot(Vec3::Z).abs() > 0.9999, "{:?}", b.axis);
        assert!((b.pitch_radius - 0.01675).abs() < 2e-5, "{}", b.pitch_radius);
        assert!((b.ball_radius - 0.003954).abs() < 5e-5, "{}", b.ball_radius);
        assert!((b.centre - Vec3::new(0.0, 0.0, 0.007)).length() < 1e-5, "{:?}", b.centre);
        assert_eq!(b.parts(), (2..4 + balls as usize).collect::<Vec<_>>());
        // the rings are a bearing's, not nuts of a fastener
        assert_eq!((w.overlaps().fits().role(inner), w.overlaps().fits().role(outer)), (Role::Other, Role::Other));
    }
}

/// A cylindrical roller bearing (ribs on both rings) is found as the ball bearing is, however
/// faceted its rings and however many rollers; its rings are no nuts.
#[test]
fn a_roller_bearing_in_a_housing_on_a_shaft_is_found_whatever_its_facets_and_rollers() {
    for (facets, rollers) in [(32, 8), (64, 10), (128, 14)] {
        let w = world(fixtures::roller_bearing(facets, rollers, true), true);
        let b = w.overlaps().fits().bearings();
        assert_eq!(b.len(), 1, "{facets} facets, {rollers} rollers: {b:?}");
        let b = &b[0];
        assert_eq!(b.elements, RollingElement::Roller);
        assert_eq!(b.rings, [2, 3], "{facets}/{rollers}");
        assert_eq!(b.balls, (4..4 + rollers as usize).collect::<Vec<_>>(), "{facets}/{rollers}");
        assert!(b.others.is_empty(), "{:?}", b.others);
        assert_eq!(b.rows, 1);
        assert!(b.axis.dot(Vec3::Z).abs() > 0.9999, "{:?}", b.axis);
        assert!((b.pitch_radius - 0.01675).abs() < 2e-5, "{}", b.pitch_radius);
        assert!((b.ball_radius - 0.003).abs() < 1.5e-4, "{}", b.ball_radius);
        assert!((b.centre - Vec3::new(0.0, 0.0, 0.007)).length() < 1e-5, "{:?}", b.centre);
        assert_eq!((w.overlaps().fits().role(2), w.overlaps().fits().role(3)), (Role::Other, Role::Other));
    }
}

/// A cage that stands out of the rings' faces (as a tapered roller bearing's does) is the
/// bearing's when it touches the rolling elements; a washer against the inner ring that stands out
/// as far is not.
#[test]
fn a_cage_standing_out_of_the_faces_is_the_bearings_and_a_washer_is_not() {
    use asp_geom::fixtures::{part, revolve};
    let mm = 0.001;
    let mut a = fixtures::roller_bearing(64, 10, false);
    // an annulus under the rollers' lower ends (at z = 3 mm), between the ribs, 3.5 mm down to
    // 0.5 mm below the rings' faces
    let cage =
        revolve(&[(15.4 * mm, -0.5 * mm), (18.1 * mm, -0.5 * mm), (18.1 * mm, 3.0 * mm), (15.4 * mm, 3.0 * mm)], 64, 0.0, Vec3::ZERO);
    a.parts.push(part("cage", cage, false));
    // a washer on the inner ring's upper face, 0.5 mm thick, inside the rib
    let washer =
        revolve(&[(10.5 * mm, 14.0 * mm), (14.5 * mm, 14.0 * mm), (14.5 * mm, 14.5 * mm), (10.5 * mm, 14.5 * mm)], 64, 0.0, Vec3::ZERO);
    a.parts.push(part("washer", washer, false));
    let w = world(a, true);
    let b = &w.overlaps().fits().bearings()[0];
    assert_eq!(b.others, vec![12], "the cage, not the washer: {b:?}");
}

/// Rollers laid across their circle (pins tangent to it, not along the axis) between two rings
/// are no bearing: a roller's axis lies in the plane through the bearing's axis.
#[test]
fn rollers_laid_across_their_circle_are_no_bearing() {
    let mut a = fixtures::roller_bearing(64, 10, false);
    let mm = 0.001;
    for (k, p) in a.parts.iter_mut().skip(2).enumerate() {
        // each roller turned 90° about its radial line, so that it lies tangent to the circle
        let angle = std::f32::consts::TAU * k as f32 / 10.0;
        let out = Vec3::new(angle.cos(), angle.sin(), 0.0);
        let centre = out * 16.75 * mm + Vec3::Z * 7.0 * mm;
        let turn = asp_geom::math::Rot::from_axis_angle(out, std::f32::consts::FRAC_PI_2);
        for v in p.mesh.vertices.iter_mut() {
            *v = centre + turn * (*v - centre);
        }
    }
    assert!(world(a, true).overlaps().fits().bearings().is_empty());
}

#[test]
fn a_bearing_alone_is_found_and_not_when_fasteners_are_off() {
    let w = world(fixtures::ball_bearing(64, 8, false), true);
    assert_eq!(w.overlaps().fits().bearings().len(), 1);
    assert_eq!(w.overlaps().fits().bearings()[0].rings, [0, 1]);
    assert!(world(fixtures::ball_bearing(64, 8, false), false).overlaps().fits().bearings().is_empty());
}

#[test]
fn balls_without_rings_or_off_a_circle_are_no_bearing() {
    // the balls of a bearing, without its outer ring: they touch one ring only
    let mut a = fixtures::ball_bearing(64, 8, false);
    a.parts.remove(1);
    assert!(world(a, true).overlaps().fits().bearings().is_empty());
    // two balls are no row
    let mut a = fixtures::ball_bearing(64, 8, false);
    a.parts.truncate(4);
    assert!(world(a, true).overlaps().fits().bearings().is_empty());
    // fasteners and fits without balls
    for a in [fixtures::bolted_joint([26, 16, 12]), fixtures::pressed_pin([32, 32], 0.0), fixtures::ring_on_locked_post()] {
        assert!(world(a, true).overlaps().fits().bearings().is_empty());
    }
}

#[test]
fn a_bearing_written_to_gltf_and_read_back_is_found() {
    use asp_geom::io::{load, write_glb, LoadOptions};
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("bearing.glb");
    write_glb(&fixtures::ball_bearing(64, 9, true), &path).unwrap();
    let a = load(&path, &LoadOptions { up: Some(asp_geom::math::Axis::Z), ..LoadOptions::default() }).unwrap();
    let w = world(a, true);
    assert_eq!(w.overlaps().fits().bearings().len(), 1);
    assert_eq!(w.overlaps().fits().bearings()[0].balls.len(), 9);
    assert_eq!(w.name(w.overlaps().fits().bearings()[0].rings[1]), "outer ring");
    shipped_is(&path, "ball_bearing_6204.glb");
    // the roller bearing too
    let path = dir.path().join("roller.glb");
    write_glb(&fixtures::roller_bearing(64, 10, true), &path).unwrap();
    let w = world(load(&path, &LoadOptions { up: Some(asp_geom::math::Axis::Z), ..LoadOptions::default() }).unwrap(), true);
    assert_eq!(
        (w.overlaps().fits().bearings().len(), w.overlaps().fits().bearings()[0].elements, w.overlaps().fits().bearings()[0].balls.len()),
        (1, RollingElement::Roller, 10)
    );
    shipped_is(&path, "roller_bearing_nup204.glb");
}

/// The shipped example `tests/data/bearing/NAME` is the file at `path` (`ASP_WRITE_EXAMPLES=1`
/// rewrites it).
fn shipped_is(path: &std::path::Path, name: &str) {
    let shipped = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tests/data/bearing").join(name);
    if std::env::var_os("ASP_WRITE_EXAMPLES").is_some() {
        std::fs::create_dir_all(shipped.parent().unwrap()).unwrap();
        std::fs::copy(path, &shipped).unwrap();
    }
    assert_eq!(
        std::fs::read(&shipped).unwrap_or_default(),
        std::fs::read(path).unwrap(),
        "tests/data/bearing/{name} is the fixture's glTF (ASP_WRITE_EXAMPLES=1 rewrites it)"
    );
}
