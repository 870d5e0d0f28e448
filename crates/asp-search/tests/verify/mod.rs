//! An independent re-check of plans: every step is swept in small increments with static
//! intersection tests of the part shrunk by the same tolerance — not the planner's shape casts,
//! caches or blocking rows.

use asp_geom::erode::eroded_vertices;
use asp_geom::feasibility::interpolate_about;
use asp_geom::math::{Pose, Vec3};
use asp_geom::{Motion, PartSet, Stability, World};
use asp_search::{PlanOutcome, Status};
use parry3d::query::{intersection_test, PointQuery};
use parry3d::shape::{TriMesh, TriMeshFlags};

fn shrunk(world: &World, p: usize, amount: f32) -> TriMesh {
    let m = world.mesh(p);
    let v = eroded_vertices(m.vertices(), m.indices(), amount);
    TriMesh::with_flags(v, m.indices().to_vec(), TriMeshFlags::ORIENTED).unwrap()
}

/// Whether part `p` at `pose` penetrates a present part (other than itself) deeper than the
/// tolerance: surfaces crossing, or one inside the other.
fn penetrates(world: &World, p: usize, pose: &Pose, present: &PartSet) -> Option<usize> {
    present.iter().filter(|&q| q != p).find(|&q| {
        let moving = shrunk(world, p, world.erosion(p, q));
        let other = world.mesh(q);
        let id = Pose::IDENTITY;
        intersection_test(pose, &moving, &id, other).unwrap().intersecting
            || other.contains_local_point(pose.transform_point(moving.vertices()[0]))
            || moving.contains_local_point(pose.inverse_transform_point(other.vertices()[0]))
    })
}

/// Re-checks every removal of a found plan: collision-free sweep, bounds cleared at the end,
/// and a stable remainder. Panics with the step on failure.
pub fn verify_plan(world: &World, outcome: &PlanOutcome) {
    assert_eq!(outcome.status, Status::Found, "only found plans are verified");
    let n = world.num_parts();
    let mut state = PartSet::full(n);
    for (k, step) in outcome.removals.iter().enumerate() {
        let p = step.part;
        assert!(state.contains(p) && !world.fixed().contains(p), "step {k}: part {p} not removable");
        let present = world.with_fixed(&state);
        let size = world.aabb(p).maxs - world.aabb(p).mins;
        let h = (size.min_element() / 4.0).max(world.tolerance());
        let poses: Vec<Pose> = match &step.motion {
            Motion::Linear { direction, distance } => {
                assert!((direction.length() - 1.0).abs() < 1e-4);
                let count = ((distance / h).ceil() as usize).clamp(8, 400);
                (0..=count).map(|i| Pose::from_translation(*direction * (distance * i as f32 / count as f32))).collect()
            }
            Motion::Path { poses, pivot } => poses
                .windows(2)
                .flat_map(|w| (0..20).map(move |i| interpolate_about(*pivot, &w[0], &w[1], i as f32 / 20.0)))
                .chain(poses.last().copied())
                .collect(),
        };
        for pose in &poses {
            if let Some(q) = penetrates(world, p, pose, &present) {
                panic!("step {k}: part '{}' hits '{}' at {pose:?}", world.name(p), world.name(q));
            }
        }
        // at the end, the part's bounds are clear of the other present real parts' bounds
        let end = world.aabb(p).transform_by(poses.last().unwrap());
        for q in state.iter().filter(|&q| q != p) {
            let b = world.aabb(q);
            let overlap = (0..3).all(|i| end.mins[i] < b.maxs[i] - 1e-6 && b.mins[i] < end.maxs[i] - 1e-6);
            assert!(!overlap, "step {k}: part '{}' still inside the bounds of '{}'", world.name(p), world.name(q));
        }
        state.remove(p);
        assert_eq!(world.contact_stability(&state), Stability::Stable, "step {k}: remainder unstable");
    }
    assert!(state.iter().all(|p| world.fixed().contains(p)), "plan leaves non-fixed parts");
    let _ = Vec3::ZERO;
}
