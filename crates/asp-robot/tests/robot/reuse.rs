//! Paths reused across states ([`asp_robot::PathStore`]): a kept path is served only in states
//! whose parts were all present when it was checked, and there it re-checks independently
//! against exactly the parts present; failures hold only in supersets of their state.

use super::recheck::recheck;
use asp_geom::math::Vec3;
use asp_geom::{Motion, PartSet, World, WorldConfig};
use asp_robot::{PathStore, RemovalConfig, RemovalPlanner, Robot, RobotCell, RobotFailure, RobotRemoval};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

fn profiles() -> asp_geom::Assembly {
    asp_gen::ProfileAssembly::generate(&asp_gen::ProfileParams::single_layer(), 1).unwrap().to_assembly("p")
}

/// Whether every part of `a` is in `b`.
fn within(a: &PartSet, b: &PartSet) -> bool {
    a.iter().all(|p| b.contains(p))
}

/// A random state holding `p` and the fixed parts, each other part present with probability
/// `keep`.
fn random_state(world: &World, p: usize, keep: f64, rng: &mut ChaCha8Rng) -> PartSet {
    let mut s = PartSet::full(world.num_parts());
    for q in 0..world.num_parts() {
        if q != p && !world.contacts().fixed().contains(q) && !rng.random_bool(keep) {
            s.remove(q);
        }
    }
    s
}

#[test]
fn reused_paths_never_collide_in_the_state_they_serve() {
    let world = World::new(profiles(), &WorldConfig::default()).unwrap();
    let cell = RobotCell::for_assembly(world.assembly(), Robot::panda(), None, None);
    let planner = RemovalPlanner::new(&world, cell.clone(), RemovalConfig::default());
    let mut rng = ChaCha8Rng::seed_from_u64(24);
    // paths planned in random states of a few parts, each kept with its state
    let mut planned: Vec<(usize, PartSet, RobotRemoval)> = Vec::new();
    let parts: Vec<usize> = (0..world.num_parts()).filter(|&p| !world.contacts().fixed().contains(p)).collect();
    for round in 0..48 {
        if planned.len() >= 10 {
            break;
        }
        let p = parts[round % parts.len()];
        let state = random_state(&world, p, 0.5, &mut rng);
        let Ok(Motion::Linear { direction, .. }) = world.removal().linear(p, &state) else { continue };
        if let Ok(r) = planner.removable(p, &state, direction, round as u64, 1) {
            planned.push((p, state, r));
        }
    }
    assert!(planned.len() >= 3, "only {} paths planned", planned.len());
    // every planned path re-checks in the state it was planned in (the planner's own answer)
    for (p, origin, r) in &planned {
        recheck(&world, &cell, *p, origin, r, 0.003).unwrap_or_else(|e| panic!("part {p} in its own state: {e}"));
    }
    let mut store = PathStore::new();
    for (p, origin, r) in &planned {
        store.learn(*p, origin, r.direction, 1, &Ok(r.clone()));
    }
    // queries: states with fewer and with more parts than the planning states
    let (mut served, mut refused) = (0, 0);
    for (i, (p, origin, _)) in planned.iter().enumerate() {
        for k in 0..6 {
            let query = if k % 2 == 0 {
                // a random subset of the planning state
                let mut s = origin.clone();
                for q in origin.iter() {
                    if q != *p && !world.contacts().fixed().contains(q) && rng.random_bool(0.4) {
                        s.remove(q);
                    }
                }
                s
            } else {
                // more parts than it had (a superset or a mixed state)
                random_state(&world, *p, 0.8, &mut rng)
            };
            let expected: Vec<f64> = planned.iter().filter(|(q, s, _)| q == p && within(&query, s)).map(|(_, _, r)| r.length).collect();
            match store.path(*p, &query).cloned() {
                Some(r) => {
                    assert!(!expected.is_empty(), "query {i}/{k}: served a path from no superset of the state");
                    let shortest = expected.iter().copied().fold(f64::INFINITY, f64::min);
                    assert!(r.length <= shortest + 1e-12, "not the shortest valid kept path");
                    recheck(&world, &cell, *p, &query, &r, 0.003).unwrap_or_else(|e| panic!("query {i}/{k}, part {p}: {e}"));
                    served += 1;
                }
                None => {
                    assert!(expected.is_empty(), "query {i}/{k}: a kept path from a superset was not served");
                    refused += 1;
                }
            }
        }
    }
    assert!(served >= 2 && refused >= 1, "served {served}, refused {refused}");
}

#[test]
fn failures_hold_in_supersets_only_and_with_their_lift() {
    let n = 6;
    let mut store = PathStore::new();
    let state = PartSet::from_indices(n, [0, 1, 2, 3]);
    let bigger = PartSet::from_indices(n, [0, 1, 2, 3, 4]);
    let smaller = PartSet::from_indices(n, [0, 1, 2]);
    let grasp = RobotFailure::NoReachableGrasp { grasps: 4, unreachable: 1, colliding: 3 };
    store.learn(1, &state, Vec3::Z, 1, &Err(grasp.clone()));
    assert_eq!(store.failure(1, &bigger, Vec3::Z, 4), Some(grasp.clone()), "no reachable grasp does not depend on k");
    assert_eq!(store.failure(1, &state, Vec3::Z, 1), Some(grasp));
    assert_eq!(store.failure(1, &smaller, Vec3::Z, 1), None, "fewer parts may free a grasp");
    assert_eq!(store.failure(1, &bigger, Vec3::X, 1), None, "another lift, other grasps");
    assert_eq!(store.failure(2, &bigger, Vec3::Z, 1), None, "another part");
    let no_path = RobotFailure::NoPath { reachable: 2, drop_off_blocked: 0, grasps_tried: 2 };
    store.learn(2, &state, Vec3::Z, 1, &Err(no_path.clone()));
    assert_eq!(store.failure(2, &bigger, Vec3::Z, 1), Some(no_path));
    assert_eq!(store.failure(2, &bigger, Vec3::Z, 4), None, "more plans may find a path");
    // a blocked lift is not kept: it is cheap to test and which lift a state uses may change
    store.learn(3, &state, Vec3::Z, 1, &Err(RobotFailure::Blocked { by: Some(0) }));
    assert_eq!(store.failure(3, &bigger, Vec3::Z, 1), None);
}

/// A stand-in path of `length` metres (the store reads only the length).
fn path(length: f64) -> RobotRemoval {
    RobotRemoval {
        grasp: asp_geom::Grasp { position: Vec3::ZERO, orientation: asp_geom::math::Rot::IDENTITY, width: 0.02 },
        grasp_index: 0,
        direction: Vec3::Z,
        joints: vec![vec![0.0; 7]],
        gripper_path: vec![Vec3::ZERO],
        length,
        reachable_grasps: 1,
    }
}

#[test]
fn paths_serve_subsets_only_and_the_shortest_first() {
    let n = 6;
    let mut store = PathStore::new();
    let state = PartSet::from_indices(n, [0, 1, 2, 3]);
    store.learn(1, &state, Vec3::Z, 1, &Ok(path(1.0)));
    assert_eq!(store.path(1, &PartSet::from_indices(n, [0, 1, 3])).map(|r| r.length), Some(1.0));
    assert_eq!(store.path(1, &state).map(|r| r.length), Some(1.0));
    assert!(store.path(1, &PartSet::from_indices(n, [0, 1, 2, 3, 4])).is_none(), "a part it was not checked against");
    assert!(store.path(1, &PartSet::from_indices(n, [1, 4])).is_none(), "a part it was not checked against");
    assert!(store.path(2, &PartSet::from_indices(n, [0, 1])).is_none(), "another part");
    // a shorter path from a smaller state serves there, the longer one elsewhere
    store.learn(1, &PartSet::from_indices(n, [1, 2]), Vec3::Z, 1, &Ok(path(0.5)));
    assert_eq!(store.path(1, &PartSet::from_indices(n, [1])).map(|r| r.length), Some(0.5));
    assert_eq!(store.path(1, &PartSet::from_indices(n, [0, 1])).map(|r| r.length), Some(1.0));
    // a path no shorter from a subset of a kept one's state adds nothing
    store.learn(1, &PartSet::from_indices(n, [0, 1]), Vec3::Z, 1, &Ok(path(1.2)));
    assert_eq!(store.paths_kept(), 2);
    // a shorter one from a superset replaces the kept ones it dominates
    store.learn(1, &PartSet::from_indices(n, [0, 1, 2, 3, 5]), Vec3::Z, 1, &Ok(path(0.4)));
    assert_eq!(store.paths_kept(), 1);
    assert_eq!(store.path(1, &PartSet::from_indices(n, [0, 1, 2])).map(|r| r.length), Some(0.4));
}
