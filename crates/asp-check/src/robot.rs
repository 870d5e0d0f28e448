//! The independent re-check of a robot removal, shared by asp-robot's tests and asp-app's: no
//! robot code is trusted by it.

use asp_geom::math::{Aabb, Pose, Vec3};
use asp_geom::{PartSet, World};
use asp_robot::{LinkShape, RobotCell, RobotRemoval, ShapeKind};
use parry3d::bounding_volume::BoundingVolume;
use parry3d::query::{self, PointQuery};
use parry3d::shape::TriMesh;

/// Points on the edges of every triangle of `mesh` displaced by `pose`, every `step` metres.
fn edge_points(mesh: &TriMesh, pose: &Pose, step: f32) -> Vec<Vec3> {
    let v = mesh.vertices();
    let mut out = Vec::new();
    for t in mesh.indices() {
        for k in 0..3 {
            let (a, b) = (v[t[k] as usize], v[t[(k + 1) % 3] as usize]);
            let n = ((b - a).length() / step).ceil().max(1.0) as usize;
            for i in 0..=n {
                out.push(pose.transform_point(a.lerp(b, i as f32 / n as f32)));
            }
        }
    }
    out
}

/// `shape` shrunk by `by` on every side (each size kept above 10 µm): where the shrunk shape
/// still meets a part's solid, the shape penetrates it by more than `by`.
fn shrunk(shape: &LinkShape, by: f32) -> LinkShape {
    let k = |x: f32| (x - by).max(1e-5);
    let kind = match shape.kind {
        ShapeKind::Box { half_extents } => {
            ShapeKind::Box { half_extents: Vec3::new(k(half_extents.x), k(half_extents.y), k(half_extents.z)) }
        }
        ShapeKind::Cylinder { radius, half_length } => ShapeKind::Cylinder { radius: k(radius), half_length: k(half_length) },
        ShapeKind::Capsule { radius, half_length } => ShapeKind::Capsule { radius: k(radius), half_length },
        ShapeKind::Sphere { radius } => ShapeKind::Sphere { radius: k(radius) },
    };
    LinkShape { kind, ..*shape }
}

/// How deep `x` lies inside the closed mesh (0 outside).
fn depth_inside(mesh: &TriMesh, x: Vec3) -> f32 {
    let p = mesh.project_local_point(x, true);
    if p.is_inside {
        (p.point - x).length().max(1e-9)
    } else {
        0.0
    }
}

/// Re-checks a robot removal independently of the planner: the trajectory's joints are sampled
/// so that no joint moves more than 0.5 mrad between samples; at each sample every link and
/// finger shape must not penetrate a part still present by more than `allowed` metres (the
/// shape shrunk by `allowed` must neither cross the part's surface nor lie inside it), nor the
/// floor (parry `contact` with the half-space), and the held part's edge points must not lie
/// more than `allowed` inside another part, nor theirs inside it. Returns the first violation.
/// (Not parry's `contact` against the part's mesh: a surface's triangles have no inside, and
/// the depth it reports for a box crossing a thin plate near its edge was 8 mm where the solids
/// overlap by 0.6 mm.)
///
/// Pairs whose bounding boxes (grown by `allowed`) do not meet are skipped: neither a
/// penetration deeper than `allowed` nor a point inside a part can happen outside its box, so
/// the verdict is the one of testing every pair (and the test runs in seconds, not minutes).
pub fn recheck(world: &World, cell: &RobotCell, part: usize, present: &PartSet, r: &RobotRemoval, allowed: f32) -> Result<(), String> {
    let robot = &cell.robot;
    let obstacles: Vec<usize> = world.contacts().with_fixed(present).iter().filter(|&q| q != part).collect();
    // the part is held as it was at the first configuration (the grasp)
    let grasp = robot.tool_pose(&r.joints[0]);
    let base_shapes = robot.links()[0].shapes.len();
    let floor = parry3d::shape::HalfSpace::new(cell.up);
    let floor_pose = Pose::from_translation(cell.up * cell.floor);
    let held = world.shapes().mesh(part);
    let boxes: Vec<Aabb> = obstacles.iter().map(|&o| world.shapes().aabb(o).loosened(allowed)).collect();
    // edge points in each part's own frame, made once
    let held_points = edge_points(held, &Pose::IDENTITY, 0.004);
    let obstacle_points: Vec<Vec<Vec3>> = obstacles.iter().map(|&o| edge_points(world.shapes().mesh(o), &Pose::IDENTITY, 0.004)).collect();
    for (w, pair) in r.joints.windows(2).enumerate() {
        let (a, b) = (&pair[0], &pair[1]);
        let max_step = a.iter().zip(b).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max);
        let n = (max_step / 5e-4).ceil().max(1.0) as usize;
        for i in 0..=n {
            let t = i as f64 / n as f64;
            // on the segment: rounding may not carry a sample past an end (a waypoint exactly
            // at a joint limit, as inverse kinematics leaves one, stays within it)
            let q: Vec<f64> = a.iter().zip(b).map(|(x, y)| (x + (y - x) * t).clamp(x.min(*y), x.max(*y))).collect();
            if !robot.within_limits(&q) {
                return Err(format!("segment {w} sample {i}: outside the joint limits"));
            }
            for (k, (link_pose, shape)) in robot.collision_shapes(&q, r.grasp.width).iter().enumerate() {
                let (pose, s) = shape.world(link_pose);
                let (inner_pose, inner) = shrunk(shape, allowed).world(link_pose);
                if k >= base_shapes {
                    if let Ok(Some(c)) = query::contact(&floor_pose, &floor, &pose, &*s, 0.0) {
                        if c.dist < -allowed {
                            return Err(format!("segment {w} sample {i}: shape {k} {} below the floor", -c.dist));
                        }
                    }
                }
                let shape_box = s.compute_aabb(&pose);
                for (j, &o) in obstacles.iter().enumerate() {
                    if k < base_shapes && world.shapes().ground() == Some(o) {
                        continue;
                    }
                    if !boxes[j].intersects(&shape_box) {
                        continue;
                    }
                    if query::intersection_test(&inner_pose, &*inner, &Pose::IDENTITY, world.shapes().mesh(o))
                        .map_or(true, |i| i.intersecting)
                    {
                        return Err(format!("segment {w} sample {i}: robot shape {k} penetrates part {o} by more than {allowed}"));
                    }
                    // a shrunk shape that crosses no face and whose centre is inside lies inside
                    if depth_inside(world.shapes().mesh(o), inner_pose.translation) > 0.0 {
                        return Err(format!("segment {w} sample {i}: robot shape {k} inside part {o}"));
                    }
                }
            }
            let displacement = robot.tool_pose(&q) * grasp.inverse();
            if i % 4 == 0 || i == n {
                let inv = displacement.inverse();
                let held_box = world.shapes().aabb(part).transform_by(&displacement).loosened(allowed);
                for (j, &o) in obstacles.iter().enumerate() {
                    if !boxes[j].intersects(&held_box) {
                        continue;
                    }
                    let om = world.shapes().mesh(o);
                    if held_points.iter().any(|&x| depth_inside(om, displacement.transform_point(x)) > allowed) {
                        return Err(format!("segment {w} sample {i}: the held part enters part {o}"));
                    }
                    if obstacle_points[j].iter().any(|&x| depth_inside(held, inv.transform_point(x)) > allowed) {
                        return Err(format!("segment {w} sample {i}: part {o} enters the held part"));
                    }
                }
            }
        }
    }
    Ok(())
}
