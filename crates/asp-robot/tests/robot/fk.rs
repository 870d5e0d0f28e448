//! Forward kinematics of the shipped URDF against a modified-DH chain written from the table.

use asp_robot::Robot;

type M = [[f64; 4]; 4];

fn mul(a: &M, b: &M) -> M {
    let mut c = [[0.0; 4]; 4];
    for i in 0..4 {
        for j in 0..4 {
            c[i][j] = (0..4).map(|k| a[i][k] * b[k][j]).sum();
        }
    }
    c
}
fn rot_x(t: f64) -> M {
    let (s, c) = t.sin_cos();
    [[1.0, 0.0, 0.0, 0.0], [0.0, c, -s, 0.0], [0.0, s, c, 0.0], [0.0, 0.0, 0.0, 1.0]]
}
fn rot_z(t: f64) -> M {
    let (s, c) = t.sin_cos();
    [[c, -s, 0.0, 0.0], [s, c, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0], [0.0, 0.0, 0.0, 1.0]]
}
fn trans(x: f64, y: f64, z: f64) -> M {
    [[1.0, 0.0, 0.0, x], [0.0, 1.0, 0.0, y], [0.0, 0.0, 1.0, z], [0.0, 0.0, 0.0, 1.0]]
}

/// Frames of links 1..=7, then the tool centre, by Craig's convention from the Panda's table.
fn dh_frames(q: &[f64]) -> Vec<M> {
    use std::f64::consts::FRAC_PI_2 as H;
    let a = [0.0, 0.0, 0.0, 0.0825, -0.0825, 0.0, 0.088];
    let d = [0.333, 0.0, 0.316, 0.0, 0.384, 0.0, 0.0];
    let alpha = [0.0, -H, H, H, -H, H, H];
    let mut t = trans(0.0, 0.0, 0.0);
    let mut out = Vec::new();
    for i in 0..7 {
        t = mul(&t, &rot_x(alpha[i]));
        t = mul(&t, &trans(a[i], 0.0, 0.0));
        t = mul(&t, &rot_z(q[i]));
        t = mul(&t, &trans(0.0, 0.0, d[i]));
        out.push(t);
    }
    // flange 0.107 along z, hand turned -pi/4, tool centre 0.103 beyond the flange
    t = mul(&t, &trans(0.0, 0.0, 0.107));
    t = mul(&t, &rot_z(-std::f64::consts::FRAC_PI_4));
    t = mul(&t, &trans(0.0, 0.0, 0.103));
    out.push(t);
    out
}

fn assert_close(pose: &asp_geom::math::Pose, m: &M, what: &str) {
    let p = pose.translation;
    for (i, v) in [p.x, p.y, p.z].into_iter().enumerate() {
        assert!((v as f64 - m[i][3]).abs() < 1e-5, "{what}: translation {i}: {v} vs {}", m[i][3]);
    }
    for (j, e) in [asp_geom::math::Vec3::X, asp_geom::math::Vec3::Y, asp_geom::math::Vec3::Z].into_iter().enumerate() {
        let col = pose.rotation * e;
        for (i, v) in [col.x, col.y, col.z].into_iter().enumerate() {
            assert!((v as f64 - m[i][j]).abs() < 1e-5, "{what}: rotation ({i},{j}): {v} vs {}", m[i][j]);
        }
    }
}

#[test]
fn shipped_urdf_matches_modified_dh_on_random_configurations() {
    let robot = Robot::panda();
    let names: Vec<&str> = robot.links().iter().map(|l| l.name.as_str()).collect();
    for q in super::configurations(&robot, 200, 11) {
        let poses = robot.link_poses(&q);
        let dh = dh_frames(&q);
        for i in 1..=7 {
            let k = names.iter().position(|n| *n == format!("panda_link{i}")).unwrap();
            assert_close(&poses[k], &dh[i - 1], &format!("link {i} at {q:?}"));
        }
        assert_close(&robot.tool_pose(&q), &dh[7], &format!("tool centre at {q:?}"));
    }
}

#[test]
fn base_pose_moves_the_whole_arm() {
    use asp_geom::math::{Pose, Rot, Vec3};
    let base = Pose::from_parts(Vec3::new(0.6, 0.0, 0.1), Rot::from_rotation_z(0.5));
    let robot = Robot::panda().with_base_pose(base);
    let q = vec![0.2, 0.3, -0.1, -1.2, 0.4, 1.5, 0.0];
    let tool = robot.tool_pose(&q);
    let expected = base * Robot::panda().tool_pose(&q);
    assert!((tool.translation - expected.translation).length() < 1e-5);
    assert!(tool.rotation.angle_between(expected.rotation) < 1e-4);
}

#[test]
fn panda_limits_are_the_published_ones() {
    let robot = Robot::panda();
    let expected = [
        (-2.8973, 2.8973),
        (-1.7628, 1.7628),
        (-2.8973, 2.8973),
        (-3.0718, -0.0698),
        (-2.8973, 2.8973),
        (-0.0175, 3.7525),
        (-2.8973, 2.8973),
    ];
    assert_eq!(robot.limits(), expected.to_vec());
}
