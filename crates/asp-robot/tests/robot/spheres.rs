//! The arm as spheres: the sphere check never misses a collision the exact shapes find, on
//! random configurations and on configurations near contact (edges from grasps outwards).

use asp_geom::{PartSet, World, WorldConfig};
use asp_robot::{part_grasps, GraspConfig, IkConfig, RemovalConfig, RemovalPlanner, Robot, RobotCell};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

fn profiles(seed: u64) -> asp_geom::Assembly {
    asp_gen::ProfileAssembly::generate(&asp_gen::ProfileParams::single_layer(), seed).unwrap().to_assembly("p")
}

/// Checks `configurations` both ways; returns (sphere free, exact free, disagreements as the
/// configurations the sphere check let through and the exact one refused).
fn compare<W: std::borrow::Borrow<World>>(
    check: &asp_robot::ArmCheck<'_, W>,
    configurations: &[Vec<f64>],
) -> (usize, usize, Vec<Vec<f64>>) {
    let (mut free, mut exact_free, mut missed) = (0, 0, Vec::new());
    for q in configurations {
        let (s, e) = (check.free(q), check.free_exact(q));
        free += s as usize;
        exact_free += e as usize;
        if s && !e {
            missed.push(q.clone());
        }
    }
    (free, exact_free, missed)
}

#[test]
fn the_sphere_check_never_misses_an_exact_collision() {
    let world = World::new(profiles(3), &WorldConfig::default()).unwrap();
    let cell = RobotCell::for_assembly(world.assembly(), Robot::panda(), None, None);
    let robot = cell.robot.clone();
    let planner = RemovalPlanner::new(&world, cell, RemovalConfig::default());
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    let n = world.num_parts();
    let movable: Vec<usize> = (0..n).filter(|&p| !world.fixed().contains(p)).collect();
    let (mut total, mut both_free, mut sphere_free, mut near) = (0, 0, 0, 0);
    for round in 0..6 {
        // a random state holding the part in hand
        let held = movable[rng.random_range(0..movable.len())];
        let mut present = PartSet::full(n);
        for &p in &movable {
            if p != held && rng.random_bool(0.4) {
                present.remove(p);
            }
        }
        let grasps = part_grasps(&world.assembly().parts[held], &GraspConfig::default());
        assert!(!grasps.is_empty(), "part {held} has grasps");
        let grasp = &grasps[rng.random_range(0..grasps.len())];
        // random configurations, and ones near contact: from the grasp's inverse kinematics out
        // towards random configurations, finely
        let mut qs: Vec<Vec<f64>> = (0..400).map(|_| robot.random_configuration(&mut rng)).collect();
        let target = asp_geom::math::Pose::from_parts(grasp.position, grasp.orientation);
        let ik = IkConfig { seed: round, restarts: 8, ..IkConfig::default() };
        if let Some(s) = robot.ik(&target, None, &ik).solution() {
            near += 1;
            for _ in 0..8 {
                let far = robot.random_configuration(&mut rng);
                for i in 0..=60 {
                    let t = i as f64 / 600.0;
                    qs.push(s.joints.iter().zip(&far).map(|(a, b)| a + (b - a) * t).collect());
                }
            }
        }
        let (free, exact_free, missed) = planner.with_arm_check(held, &present, grasp, |check| compare(check, &qs));
        assert!(
            missed.is_empty(),
            "part {held}: the spheres let {} configurations through that collide, e.g. {:?}",
            missed.len(),
            missed[0]
        );
        total += qs.len();
        both_free += exact_free;
        sphere_free += free;
    }
    // the test means something: both verdicts occur, and near contact was reached
    assert!(near >= 3, "inverse kinematics reached only {near} grasps");
    assert!(both_free > total / 20 && both_free < total - total / 20, "{both_free} of {total} free");
    // the sphere check is the exact verdict, not a looser one
    assert_eq!(sphere_free, both_free, "the sphere check refused configurations the exact shapes accept");
}
