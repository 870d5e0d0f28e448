//! Profiles with their connectors attached: one part each, grasps kept clear, planned.

use super::*;

fn attached(params: ProfileParams) -> ProfileParams {
    ProfileParams { connectors: ConnectorMode::Attached, ..params }
}

#[test]
fn attached_profiles_are_the_only_parts_and_carry_their_connectors() {
    for (params, removable) in [(ProfileParams::single_layer(), 21), (ProfileParams::double_layer(), 30)] {
        for seed in 0..3 {
            let separate = profiles(&params, seed);
            let a = profiles(&attached(params.clone()), seed);
            // the same profiles and connectors are drawn; only the parts differ
            assert_eq!(a.profiles, separate.profiles);
            assert_eq!(a.connectors, separate.connectors);
            let asm = a.to_assembly("x");
            assert_eq!(asm.parts.len(), a.profiles.len(), "seed {seed}: only profiles are parts");
            assert_eq!(asm.parts.iter().filter(|p| !p.fixed).count(), removable);
            assert!(asm.parts.iter().all(|p| p.extras["kind"] == "profile"));
            let boxes = a.part_boxes();
            let cells: usize = boxes.iter().map(Vec::len).sum();
            let separate_cells: usize = separate.part_boxes().iter().map(Vec::len).sum();
            assert_eq!(cells, separate_cells, "every connector cell belongs to one profile");
            for (i, (part, cells)) in asm.parts.iter().zip(&boxes).enumerate() {
                // the mesh is the closed surface of the profile and its connectors
                assert!(part.mesh.topology().is_closed_manifold(), "{}", part.name);
                let volume: f64 = cells.iter().map(Cuboid::volume).sum();
                assert!((part.mesh.signed_volume() - volume).abs() < 1e-4 * volume, "{}", part.name);
                let held = a.connectors.iter().filter(|c| c.holds == i).count();
                assert_eq!(part.extras["connectors"].as_array().map(Vec::len), Some(held), "{}", part.name);
                assert_eq!(part.extras["boxes"].as_array().map(Vec::len), Some(cells.len()));
                assert_eq!(part.meta.boxes.as_ref().map(Vec::len), Some(cells.len()), "{}", part.name);
            }
            assert!(a.max_penetration() <= TOLERANCE);
            let check = a.check_disassembly();
            assert!(check.linked && check.straight_line && check.stable_order, "seed {seed}: {check:?}");
        }
    }
}

#[test]
fn attached_connectors_keep_clear_of_every_grasp() {
    // a finger (2 cm along the profile, the shipped panda's pad) centred on any grasp point
    // must not reach into a connector the profile carries: the robot does not test the held
    // part against its own gripper
    let finger_half = 0.01;
    for params in [ProfileParams::single_layer(), ProfileParams::double_layer()] {
        for seed in 0..3 {
            let a = profiles(&attached(params.clone()), seed);
            let boxes = a.part_boxes();
            for (i, p) in a.profiles.iter().enumerate() {
                let grasps = a.grasp_points(i);
                assert!(!grasps.is_empty() || p.length() < 2.0 * params.grasp_margin);
                for g in grasps {
                    let mut zone = p.cuboid;
                    zone.mins[p.axis] = g.position[p.axis] - finger_half;
                    zone.maxs[p.axis] = g.position[p.axis] + finger_half;
                    // the zone widened by the connector walls across the profile
                    for b in 0..3 {
                        if b != p.axis {
                            zone.mins[b] -= 2.0 * params.connector_thickness;
                            zone.maxs[b] += 2.0 * params.connector_thickness;
                        }
                    }
                    // (a support's O sleeve ends exactly where the finger of its lowest grasp
                    // begins: touching, not overlapping)
                    for c in &boxes[i][1..] {
                        assert!(!c.overlaps(&zone, 1e-9), "profile {i}: grasp at {:?} on {c:?}", g.position);
                    }
                }
            }
        }
    }
}

#[test]
fn attached_assemblies_written_and_planned_to_completion() {
    let dir = tempfile::tempdir().unwrap();
    let m = write(Generator::Profiles(attached(ProfileParams::single_layer())), 2, 0, dir.path());
    for e in &m.assemblies {
        assert!(e.checks.passed(), "{e:?}");
        assert_eq!(e.parts, 29);
        plans_to_completion(&dir.path().join(&e.file)).unwrap();
    }
    // the manifest says how the connectors were made; separate batches do not mention it
    let text = std::fs::read_to_string(dir.path().join("manifest.json")).unwrap();
    assert!(text.contains("\"connectors\": \"attached\""), "{text}");
    let sep = tempfile::tempdir().unwrap();
    write(Generator::Profiles(ProfileParams::single_layer()), 1, 0, sep.path());
    assert!(!std::fs::read_to_string(sep.path().join("manifest.json")).unwrap().contains("\"connectors\""));
}
