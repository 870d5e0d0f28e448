//! Grasps: computed antipodal grasps on boxes, and grasps read from generated profile metadata.

use asp_geom::math::Vec3;
use asp_geom::Mesh;
use asp_robot::{antipodal_grasps, part_grasps, GraspConfig};

/// Distance from `p` to the surface of the box [lo, hi] and the outward normal of the nearest face.
fn box_surface(p: Vec3, lo: Vec3, hi: Vec3) -> (f32, Vec3) {
    let mut best = (f32::INFINITY, Vec3::ZERO);
    for i in 0..3 {
        for (plane, sign) in [(lo[i], -1.0), (hi[i], 1.0)] {
            let d = (p[i] - plane).abs();
            if d < best.0 {
                let mut n = Vec3::ZERO;
                n[i] = sign;
                best = (d, n);
            }
        }
    }
    best
}

#[test]
fn grasps_on_a_box_are_antipodal_and_within_the_opening() {
    let (lo, hi) = (Vec3::new(0.1, -0.02, 0.0), Vec3::new(0.3, 0.02, 0.03));
    let mesh = Mesh::cuboid(lo, hi);
    let cfg = GraspConfig { seed: 5, ..Default::default() };
    let grasps = antipodal_grasps(&mesh, &cfg);
    assert!(grasps.len() >= 8, "only {} grasps", grasps.len());
    let mut widths = std::collections::BTreeSet::new();
    for g in &grasps {
        assert!(g.width <= 0.08 + 1e-6 && g.width > 0.0);
        let y = g.orientation * Vec3::Y;
        for side in [-1.0, 1.0] {
            let contact = g.position + y * (side * 0.5 * g.width);
            let (d, n) = box_surface(contact, lo, hi);
            assert!(d < 1e-4, "finger contact {contact:?} is {d} off the surface");
            assert!(n.dot(y * side) > 0.999, "contact normal {n:?} not along the closing axis {y:?}");
        }
        // the approach is perpendicular to the closing axis
        assert!((g.orientation * Vec3::Z).dot(y).abs() < 1e-4);
        widths.insert((g.width * 1000.0).round() as i32);
    }
    // across the 4 cm and the 3 cm sides, never along the 20 cm length
    assert_eq!(widths.into_iter().collect::<Vec<_>>(), vec![30, 40]);
}

#[test]
fn no_grasps_on_a_part_wider_than_the_opening_everywhere() {
    let mesh = Mesh::cuboid(Vec3::ZERO, Vec3::new(0.1, 0.12, 0.09));
    assert!(antipodal_grasps(&mesh, &GraspConfig::default()).is_empty());
}

#[test]
fn generated_profile_grasps_come_through_the_metadata() {
    let generated = asp_gen::ProfileAssembly::generate(&asp_gen::ProfileParams::single_layer(), 1).unwrap();
    let assembly = generated.to_assembly("p");
    let mut total = 0;
    for (i, _) in generated.profiles.iter().enumerate() {
        let expected = generated.grasp_points(i);
        let part = &assembly.parts[i];
        assert_eq!(part.meta.grasps.len(), expected.len(), "part {}", part.name);
        let grasps = part_grasps(part, &GraspConfig::default());
        assert_eq!(grasps.len(), expected.iter().filter(|g| g.width <= 0.08).count(), "part {}", part.name);
        for (g, e) in grasps.iter().zip(&expected) {
            assert!((g.position - Vec3::new(e.position[0] as f32, e.position[1] as f32, e.position[2] as f32)).length() < 1e-4);
        }
        total += grasps.len();
    }
    assert!(total > 0);
}
