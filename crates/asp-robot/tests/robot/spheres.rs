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
    let movable: Vec<usize> = (0..n).filter(|&p| !world.contacts().fixed().contains(p)).collect();
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

/// The edge walk (each shape re-evaluated only where its clearance may have run out, the
/// samples between skipped) gives every edge the verdict of checking each of its samples, and
/// never passes an edge one of whose samples the exact shapes refuse.
#[test]
fn the_edge_walk_gives_each_sample_s_verdict_and_never_passes_an_exact_collision() {
    let world = World::new(profiles(5), &WorldConfig::default()).unwrap();
    let cell = RobotCell::for_assembly(world.assembly(), Robot::panda(), None, None);
    let robot = cell.robot.clone();
    let planner = RemovalPlanner::new(&world, cell, RemovalConfig::default());
    let mut rng = ChaCha8Rng::seed_from_u64(21);
    let n = world.num_parts();
    let movable: Vec<usize> = (0..n).filter(|&p| !world.contacts().fixed().contains(p)).collect();
    let (mut free_edges, mut blocked_edges, mut samples) = (0, 0, 0);
    for round in 0..4 {
        let held = movable[rng.random_range(0..movable.len())];
        let present = PartSet::full(n);
        let grasps = part_grasps(&world.assembly().parts[held], &GraspConfig::default());
        let grasp = &grasps[rng.random_range(0..grasps.len())];
        let target = asp_geom::math::Pose::from_parts(grasp.position, grasp.orientation);
        let ik = IkConfig { seed: round, restarts: 8, ..IkConfig::default() };
        let start = robot.ik(&target, None, &ik).solution().map(|s| s.joints.clone());
        planner.with_arm_check(held, &present, grasp, |check| {
            // edges from the grasp outwards (near contact) and between random free configurations
            let mut ends: Vec<Vec<f64>> = (0..200).map(|_| robot.random_configuration(&mut rng)).filter(|q| check.free(q)).collect();
            let mut edges: Vec<(Vec<f64>, Vec<f64>)> = Vec::new();
            if let Some(s) = start.as_ref().filter(|s| check.free(s)) {
                for e in ends.iter().take(12) {
                    // short edges so that most of them start and end near the parts
                    let t = 0.05 + 0.1 * rng.random::<f64>();
                    let b: Vec<f64> = s.iter().zip(e).map(|(x, y)| x + (y - x) * t).collect();
                    if check.free(&b) {
                        edges.push((s.clone(), b));
                    }
                }
            }
            ends.truncate(24);
            for w in ends.chunks(2).filter(|w| w.len() == 2) {
                edges.push((w[0].clone(), w[1].clone()));
            }
            for (a, b) in &edges {
                let walk = check.edge_free(a, b);
                let qs = check.edge_samples(a, b);
                samples += qs.len();
                let each = qs.iter().all(|q| check.free(q));
                assert_eq!(walk, each, "part {held}: the walk says {walk}, its samples one by one {each}: {a:?} → {b:?}");
                if walk {
                    assert!(qs.iter().all(|q| check.free_exact(q)), "part {held}: the walk passed a sample the exact shapes refuse");
                    free_edges += 1;
                } else {
                    blocked_edges += 1;
                }
            }
        });
    }
    assert!(free_edges >= 5 && blocked_edges >= 5, "{free_edges} free and {blocked_edges} blocked edges ({samples} samples)");
}

/// The arm against itself where it also comes near the parts: a shape whose enclosing sphere
/// is near a part has only some of its small spheres tested against the parts, and its self
/// pairs must still see all of them where they are now (a pair once read the centres of an
/// earlier configuration there). Many random configurations of the whole model, every exact
/// self-collision found.
#[test]
fn the_sphere_check_never_misses_a_self_collision_near_the_parts() {
    let world = World::new(profiles(3), &WorldConfig::default()).unwrap();
    let cell = RobotCell::for_assembly(world.assembly(), Robot::panda(), None, None);
    let robot = cell.robot.clone();
    let planner = RemovalPlanner::new(&world, cell, RemovalConfig::default());
    let mut rng = ChaCha8Rng::seed_from_u64(8);
    let n = world.num_parts();
    let held = (0..n).find(|&p| !world.contacts().fixed().contains(p)).unwrap();
    let grasp = part_grasps(&world.assembly().parts[held], &GraspConfig::default())[0].clone();
    let present = PartSet::full(n);
    let (mut selfs, mut missed) = (0, 0);
    planner.with_arm_check(held, &present, &grasp, |check| {
        for _ in 0..4000 {
            let q = robot.random_configuration(&mut rng);
            let sphere = check.free(&q);
            if planner.self_collision(&q, grasp.width) {
                selfs += 1;
                missed += sphere as usize;
            }
            if sphere {
                assert!(check.free_exact(&q), "{q:?}: the spheres let a collision through");
            }
        }
    });
    assert!(selfs >= 100, "only {selfs} self-collisions: the test shows little");
    assert_eq!(missed, 0, "{missed} of {selfs} self-collisions missed");
}
