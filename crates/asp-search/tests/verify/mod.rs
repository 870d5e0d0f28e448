//! An independent re-check of plans: every step is swept in small increments with static
//! intersection tests of the part shrunk by the same tolerance (its own erosion, static crossing
//! tests at sampled poses) — not the planner's sweeps, caches or blocking rows.

use asp_geom::erode::eroded_mesh;
use asp_geom::feasibility::interpolate_about;
use asp_geom::math::{Pose, Vec3};
use asp_geom::{Motion, PartSet, Stability, World};
use asp_search::{PlanOutcome, Status};
use asp_geom::sweep::meshes_cross_at;
use parry3d::query::PointQuery;
use parry3d::shape::{TriMesh, TriMeshFlags};
use std::collections::HashMap;

fn shrunk(world: &World, p: usize, amount: f32) -> TriMesh {
    let m = world.mesh(p);
    let (v, t) = eroded_mesh(m.vertices(), m.indices(), amount);
    TriMesh::with_flags(v, t, TriMeshFlags::ORIENTED).unwrap()
}

/// Whether part `p` at `pose` penetrates a present part (other than itself) deeper than the
/// tolerance: surfaces crossing, or one inside the other. Each pair shrinks the part the world
/// chose for it (the moving part, or for input overlaps the one that separates more easily).
fn penetrates(world: &World, p: usize, pose: &Pose, present: &PartSet, shrunk_cache: &mut HashMap<(usize, u32), TriMesh>) -> Option<usize> {
    present.iter().filter(|&q| q != p && !world.ignores(p, q)).find(|&q| {
        let (k, amount) = world.pair_erosion(p, q);
        let shrunk_k = shrunk_cache.entry((k, amount.to_bits())).or_insert_with(|| shrunk(world, k, amount)).clone();
        let id = Pose::IDENTITY;
        let (shrunk_pose, raw, raw_pose) = if k == p { (*pose, world.mesh(q).clone(), id) } else { (id, world.mesh(p).clone(), *pose) };
        let closed_raw = world.is_closed(if k == p { q } else { p });
        let (bs, br) = (shrunk_k.aabb(&shrunk_pose), raw.aabb(&raw_pose));
        let nests = |a: &parry3d::bounding_volume::Aabb, b: &parry3d::bounding_volume::Aabb| {
            (0..3).all(|i| a.mins[i] >= b.mins[i] && a.maxs[i] <= b.maxs[i])
        };
        // one wholly inside the other: only for closed surfaces whose boxes nest
        // static crossing tests of the placed meshes (exact triangle pairs; parry's mesh-mesh
        // intersection test reports surfaces a tolerance apart as crossing)
        let crossing = if k == p { meshes_cross_at(&shrunk_k, pose, &raw) } else { meshes_cross_at(&raw, pose, &shrunk_k) };
        crossing
            || (closed_raw && nests(&bs, &br) && raw.contains_point(&raw_pose, shrunk_pose.transform_point(shrunk_k.vertices()[0])))
            || (world.is_closed(k) && nests(&br, &bs) && shrunk_k.contains_point(&shrunk_pose, raw_pose.transform_point(raw.vertices()[0])))
    })
}

/// Re-checks every removal of a found plan: collision-free sweep, bounds cleared at the end,
/// and a stable remainder. Panics with the step on failure.
pub fn verify_plan(world: &World, outcome: &PlanOutcome) {
    assert_eq!(outcome.status, Status::Found, "only found plans are verified");
    let state = verify_removals(world, &outcome.removals);
    assert!(state.iter().all(|p| world.fixed().contains(p)), "plan leaves non-fixed parts");
}

/// Re-checks removals from the full assembly as [`verify_plan`] does (a whole plan or a partial
/// disassembly) and returns the state they reach.
pub fn verify_removals(world: &World, removals: &[asp_search::Step]) -> PartSet {
    let n = world.num_parts();
    let mut state = PartSet::full(n);
    let mut cache = HashMap::new();
    for (k, step) in removals.iter().enumerate() {
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
            if let Some(q) = penetrates(world, p, pose, &present, &mut cache) {
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
    let _ = Vec3::ZERO;
    state
}
