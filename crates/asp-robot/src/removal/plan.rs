//! The hierarchical removal test itself ([`RemovalPlanner::plan`] and its variants): grasps in
//! order of their bound, the gripper alone, inverse kinematics, the arm at the grasp and lifted
//! poses, the drop-off, then `k` path plans per grasp; the exact check of the path returned.

use super::*;

impl<W: Borrow<World>> RemovalPlanner<W> {
    /// The arm's configurations for grasp `gi` of part `p` lifted along `direction`, computed
    /// once: inverse kinematics of the grasp and lifted poses (seeded by the part and grasp
    /// only, so the same in every state and thread) and of the drop-off poses (the lifted
    /// orientation, then the gripper pointing down, turned twice), each started from the
    /// lifted configuration.
    pub(super) fn grasp_ik(&self, p: usize, gi: usize, direction: Vec3) -> Arc<GraspIk> {
        let key = (p, gi, direction.to_array().map(f32::to_bits));
        if let Some(k) = self.ik_cache.lock().expect("not poisoned").get(&key) {
            return k.clone();
        }
        let robot = &self.cell.robot;
        let g = &self.grasps(p)[gi];
        let tool = Pose::from_parts(g.position, g.orientation);
        let lifted = Pose::from_translation(direction * self.config.lift) * tool;
        let seed = self.config.ik.seed ^ (p as u64).wrapping_mul(0x2545_f491_4f6c_dd1d) ^ (gi as u64).wrapping_mul(0x9e37_79b9);
        // computed once per grasp, so it can afford more restarts than a per-state test did
        let ik = IkConfig { seed, restarts: self.config.ik.restarts.max(12), ..self.config.ik.clone() };
        let arm = robot.ik(&tool, None, &ik).solution().map(|s| s.joints.clone()).and_then(|qg| {
            let ql = robot.ik(&lifted, Some(&qg), &IkConfig { restarts: 0, ..ik.clone() }).solution().map(|s| s.joints.clone())?;
            Some((qg, ql))
        });
        let mut drop = Vec::new();
        if let Some((_, ql)) = &arm {
            let down = Rot::from_rotation_arc(Vec3::Z, -self.cell.up);
            for (k, rot) in [lifted.rotation, down, down * Rot::from_rotation_z(std::f32::consts::FRAC_PI_2)].into_iter().enumerate() {
                let target = Pose::from_parts(self.cell.drop_off, rot);
                let cfg = IkConfig { seed: ik.seed ^ (k as u64 + 1), ..ik.clone() };
                if let Some(s) = robot.ik(&target, Some(ql), &cfg).solution() {
                    drop.push(s.joints.clone());
                }
            }
        }
        let k = Arc::new(GraspIk { arm, drop });
        self.ik_cache.lock().expect("not poisoned").insert(key, k.clone());
        k
    }

    /// The exact check of a path found with the sphere check: every shape exactly against the
    /// parts near it at the re-check's resolution (samples skipped only where the spheres'
    /// clearance proves them free). A refusal is counted ([`PlanStats::exact_refused`]).
    pub(super) fn exact_path_free(&self, p: usize, shrunk: &TriMesh, obstacles: &Obstacles, r: &RobotRemoval) -> bool {
        self.counters.timed(C::Exact, || {
            let grasp = self.cell.robot.tool_pose(&r.joints[0]);
            let exact = ArmSpace::new(self, p, shrunk, grasp, r.grasp.width, obstacles, self.config.check_resolution, Check::Exact);
            let free = r.joints.iter().all(|q| exact.valid(q)) && r.joints.windows(2).all(|w| exact.edge_valid(&w[0], &w[1]));
            if !free {
                self.counters.add(C::ExactRefused, 1);
            }
            free
        })
    }

    #[allow(clippy::too_many_arguments)] // the plan's inputs, the search mode and its bound
    pub(super) fn plan_grasps(
        &self,
        p: usize,
        present: &PartSet,
        direction: Vec3,
        seed: u64,
        replans: usize,
        mode: Mode,
        below: f64,
    ) -> Result<RobotRemoval, RobotFailure> {
        let exhaustive = mode == Mode::Exhaustive;
        let counters = &self.counters;
        counters.add(C::Plans, 1);
        let world = self.world();
        let robot = &self.cell.robot;
        let direction = counters.timed(C::Lift, || self.lift_direction(p, present, Some(direction)))?;
        let lift = Pose::from_translation(direction * self.config.lift);
        let obstacles = self.obstacles(present, p);
        let grasps = self.grasps(p);
        let shrunk = world.shapes().eroded(p, self.config.margin.max(world.shapes().tolerance()));
        // The tool centre travels from the grasp (within the position tolerance) through the
        // lifted pose to the drop-off: the sampled polyline is at least as long as the lift plus
        // the straight distance, less twice the tolerance at each of the three ends.
        let slack = 6.0 * self.config.ik.position_tolerance + 1e-5;
        let mut order: Vec<(f64, usize)> = grasps
            .iter()
            .enumerate()
            .map(|(gi, g)| {
                let lifted = lift * Pose::from_parts(g.position, g.orientation);
                (self.config.lift as f64 + (lifted.translation - self.cell.drop_off).length() as f64 - slack, gi)
            })
            .collect();
        order.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        let cap = if exhaustive { usize::MAX } else { self.config.path_grasps.max(1) };
        let (mut unreachable, mut colliding, mut no_drop, mut reached, mut tried) = (0, 0, 0, 0, 0);
        let mut best: Option<RobotRemoval> = None;
        // every path that was the best when found, shortest last
        let mut candidates: Vec<RobotRemoval> = Vec::new();
        for (n, &(bound, gi)) in order.iter().enumerate() {
            let found = mode == Mode::FirstPath && best.is_some();
            let shortest = best.as_ref().map_or(below, |b| b.length);
            if found || !exhaustive && (tried >= cap || shortest <= bound) {
                counters.add(C::Pruned, (order.len() - n) as u64);
                break;
            }
            counters.add(C::Examined, 1);
            let g = &grasps[gi];
            let tool = Pose::from_parts(g.position, g.orientation);
            let lifted = lift * tool;
            // 1. the gripper alone at the grasp and lifted poses: no inverse kinematics needed
            if self.config.gripper_precheck
                && counters.timed(C::Gripper, || {
                    self.gripper_collides(&tool, g.width, &obstacles) || self.gripper_collides(&lifted, g.width, &obstacles)
                })
            {
                counters.add(C::GripperRejected, 1);
                colliding += 1;
                continue;
            }
            // 2. inverse kinematics of both poses (per grasp and lift, once: it does not depend
            // on the state, so an arm out of reach stays out of reach)
            let ik = counters.timed(C::Ik, || self.grasp_ik(p, gi, direction));
            let Some((qg, ql)) = ik.arm.as_ref() else {
                counters.add(C::Unreachable, 1);
                unreachable += 1;
                continue;
            };
            let (qg, ql) = (qg.clone(), ql.clone());
            // 3. the whole arm and the held part at both poses and between them
            let grasp_pose = robot.tool_pose(&qg);
            let space = ArmSpace::new(self, p, &shrunk, grasp_pose, g.width, &obstacles, self.config.edge_resolution, Check::Spheres);
            if counters.timed(C::Reach, || !space.valid(&qg) || !space.valid(&ql) || !space.edge_valid(&qg, &ql)) {
                colliding += 1;
                continue;
            }
            reached += 1;
            // 4. drop-off: the first of its configurations (lifted orientation, then the
            // gripper pointing down) where the arm and the part in hand are collision-free
            let qd = counters.timed(C::DropOff, || ik.drop.iter().find(|q| space.valid(q)).cloned());
            let Some(qd) = qd else {
                no_drop += 1;
                continue;
            };
            // 5. paths to the drop-off, k times
            tried += 1;
            counters.add(C::Planned, 1);
            // paths are accepted on the sphere check at the re-check's resolution; the exact
            // check then runs on the path returned
            let fine = ArmSpace::new(self, p, &shrunk, grasp_pose, g.width, &obstacles, self.config.check_resolution, Check::Spheres);
            let repair = ArmSpace::new(self, p, &shrunk, grasp_pose, g.width, &obstacles, self.config.repair_resolution, Check::Spheres);
            for r in 0..replans.max(1) {
                let cfg = RrtConnectConfig {
                    seed: seed ^ ((gi as u64) << 20) ^ (r as u64).wrapping_mul(0x5851_f42d_4c95_7f2d),
                    ..self.config.rrt.clone()
                };
                // the tree on coarse edges; when the fine re-check refuses its path, once more
                // on the repair resolution's edges (same seed)
                let mut kept = None;
                for (attempt, tree) in [&space, &repair].into_iter().enumerate() {
                    let Ok(path) = counters.timed(C::Rrt, || rrt_connect(tree, &ql, &qd, &cfg)) else { break };
                    let mut joints = vec![qg.clone()];
                    joints.extend(path);
                    // the length first (forward kinematics only): a path that cannot be the
                    // best needs no re-check
                    let (length, better, valid) = counters.timed(C::Recheck, || {
                        let length = fine.tool_travel_below(&joints, best.as_ref().map_or(below, |b| b.length));
                        let better = length.is_some();
                        (length.unwrap_or(f64::INFINITY), better, better && joints.windows(2).all(|w| fine.edge_valid(&w[0], &w[1])))
                    });
                    if valid {
                        kept = Some((joints, length));
                    } else if better && attempt == 0 {
                        counters.add(C::Refused, 1);
                        continue;
                    }
                    break;
                }
                if let Some((joints, length)) = kept {
                    let gripper_path = repair.tool_samples(&joints);
                    let found = RobotRemoval {
                        grasp: g.clone(),
                        grasp_index: gi,
                        direction,
                        joints,
                        gripper_path,
                        length,
                        reachable_grasps: reached,
                    };
                    if mode == Mode::FirstPath {
                        // the search stops here: the exact check now
                        if self.exact_path_free(p, &shrunk, &obstacles, &found) {
                            best = Some(found);
                            break;
                        }
                        continue;
                    }
                    candidates.push(found.clone());
                    best = Some(found);
                }
            }
        }
        // the exact check on the path returned: the shortest candidate it passes
        if mode != Mode::FirstPath {
            best = None;
            while let Some(b) = candidates.pop() {
                if self.exact_path_free(p, &shrunk, &obstacles, &b) {
                    best = Some(b);
                    break;
                }
            }
        }
        if let Some(mut b) = best {
            b.reachable_grasps = reached;
            return Ok(b);
        }
        if reached == 0 {
            return Err(RobotFailure::NoReachableGrasp { grasps: grasps.len(), unreachable, colliding });
        }
        Err(RobotFailure::NoPath { reachable: reached, drop_off_blocked: no_drop, grasps_tried: tried })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use asp_geom::WorldConfig;

    /// The exact check stands behind every path returned: with spheres deliberately too small
    /// (they miss collisions, so the search accepts paths through parts), what the planner
    /// returns still passes the exact check, because the exact check refused the others.
    #[test]
    fn a_returned_path_always_passes_the_exact_check() {
        let assembly = asp_gen::ProfileAssembly::generate(&asp_gen::ProfileParams::single_layer(), 1).unwrap().to_assembly("p");
        let world = World::new(assembly, &WorldConfig::default()).unwrap();
        let cell = RobotCell::for_assembly(world.assembly(), Robot::panda(), None, None);
        let mut planner = RemovalPlanner::new(&world, cell, RemovalConfig::default());
        // unsound on purpose: every small sphere 2 cm too small, every enclosing one too
        for r in planner.model.spheres.r.iter_mut() {
            *r = (*r - 0.02).max(0.001);
        }
        for s in planner.model.shapes.iter_mut() {
            s.bound.radius = (s.bound.radius - 0.02).max(0.001);
        }
        let state = PartSet::full(world.num_parts());
        let (mut returned, mut refused) = (0, 0);
        for p in (0..world.num_parts()).filter(|&p| !world.contacts().fixed().contains(p)) {
            let Ok(d) = planner.lift_direction(p, &state, None) else { continue };
            for mode in [Mode::Bounded, Mode::FirstPath] {
                let before = planner.stats().exact_refused;
                if let Ok(r) = planner.plan_grasps(p, &state, d, 3, 2, mode, f64::INFINITY) {
                    returned += 1;
                    let at = planner.cell.robot.tool_pose(&r.joints[0]);
                    let grasp = asp_geom::Grasp { position: at.translation, orientation: at.rotation, width: r.grasp.width };
                    let ok = planner.with_arm_check(p, &state, &grasp, |c| {
                        r.joints.iter().all(|q| c.free_exact(q)) && r.joints.windows(2).all(|w| c.edge_free_exact(&w[0], &w[1]))
                    });
                    assert!(ok, "part {p}: a returned path fails the exact check");
                }
                refused += planner.stats().exact_refused - before;
            }
            if returned >= 6 && refused > 0 {
                break;
            }
        }
        assert!(returned > 0, "nothing was returned: the test shows nothing");
        assert!(refused > 0, "the exact check refused nothing: the unsound spheres were never caught");
    }
}
