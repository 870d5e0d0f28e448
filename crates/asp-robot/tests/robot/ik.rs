//! Inverse kinematics: round trips, unreachable poses, joint limits, determinism.

use asp_geom::math::{Pose, Vec3};
use asp_robot::{IkConfig, IkOutcome, Robot};

#[test]
fn ik_round_trips_reachable_poses_within_limits() {
    let robot = Robot::panda();
    let cfg = IkConfig::default();
    let mut failures = 0;
    let configs = super::configurations(&robot, 60, 3);
    for (i, q) in configs.iter().enumerate() {
        let target = robot.tool_pose(q);
        match robot.ik(&target, None, &IkConfig { seed: i as u64, ..cfg.clone() }) {
            IkOutcome::Reached(s) => {
                assert!(robot.within_limits(&s.joints), "limits violated: {:?}", s.joints);
                let p = robot.tool_pose(&s.joints);
                assert!((p.translation - target.translation).length() < 1e-4, "position {:?} vs {:?}", p, target);
                assert!(p.rotation.angle_between(target.rotation) < 1e-3, "rotation {:?} vs {:?}", p, target);
            }
            IkOutcome::Unreachable { .. } => failures += 1,
        }
    }
    // every target is a pose of the arm itself, so a sound solver reaches (nearly) all of them
    assert!(failures <= 1, "{failures} of {} reachable poses not reached", configs.len());
}

#[test]
fn a_pose_two_metres_away_is_unreachable() {
    let robot = Robot::panda();
    let target = Pose::from_translation(Vec3::new(2.0, 0.0, 0.333));
    match robot.ik(&target, None, &IkConfig::default()) {
        IkOutcome::Unreachable { position_error, .. } => assert!(position_error > 0.5),
        IkOutcome::Reached(s) => panic!("reached {:?}", s),
    }
    // also when the reach bound does not reject it: close but pointing through the base
    let inside = Pose::from_translation(Vec3::new(0.0, 0.0, -0.3));
    assert!(matches!(robot.ik(&inside, None, &IkConfig { restarts: 5, ..Default::default() }), IkOutcome::Unreachable { .. }));
}

#[test]
fn ik_respects_limits_even_when_the_start_violates_them() {
    let robot = Robot::panda();
    let q = vec![0.5, 0.4, -0.3, -1.0, 0.2, 2.0, 0.3];
    let target = robot.tool_pose(&q);
    let bad_start = vec![5.0, -5.0, 5.0, 1.0, -5.0, 5.0, 5.0];
    let out = robot.ik(&target, Some(&bad_start), &IkConfig::default());
    let s = out.solution().expect("reachable");
    assert!(robot.within_limits(&s.joints));
}

#[test]
fn same_seed_same_solution() {
    let robot = Robot::panda();
    let q = vec![-0.5, 0.6, 0.3, -2.1, -0.4, 2.4, 1.0];
    let target = robot.tool_pose(&q);
    let cfg = IkConfig { seed: 9, ..Default::default() };
    assert_eq!(robot.ik(&target, None, &cfg), robot.ik(&target, None, &cfg));
}

/// The wrist bound (the last joint's origin, fixed by the target, must lie within the chain's
/// length of the shoulder) rejects without a single descent a target the tool-centre bound lets
/// through, and never rejects a pose the arm takes.
#[test]
fn the_wrist_bound_rejects_at_once_only_what_no_configuration_reaches() {
    let robot = Robot::panda();
    // 0.7 m in front of the shoulder, approaching back towards the robot: the wrist would be
    // 0.91 m away (the chain up to it is 0.80 m long), the tool centre is within its 1.09 m bound
    let target = Pose::from_parts(Vec3::new(0.7, 0.0, 0.333), asp_geom::math::Rot::from_rotation_y(-std::f32::consts::FRAC_PI_2));
    assert!(matches!(robot.ik(&target, None, &IkConfig::default()), IkOutcome::Unreachable { attempts: 0, .. }));
    let cfg = IkConfig { restarts: 0, max_iterations: 1, ..Default::default() };
    for q in super::configurations(&robot, 300, 11) {
        let out = robot.ik(&robot.tool_pose(&q), None, &cfg);
        assert!(!matches!(out, IkOutcome::Unreachable { attempts: 0, .. }), "{q:?} rejected by a bound");
    }
}
