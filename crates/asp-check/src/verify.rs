//! An independent re-check of plans: every step is swept in small increments with static
//! intersection tests of the part shrunk by the same tolerance (its own erosion, static crossing
//! tests at sampled poses) — not the planner's sweeps, caches or blocking rows.

use asp_geom::erode::eroded_mesh;
use asp_geom::feasibility::interpolate_about;
use asp_geom::math::{Pose, Vec3};
use asp_geom::sweep::meshes_cross_at;
use asp_geom::{Motion, PartSet, Stability, World};
use asp_search::{PlanOutcome, Status};
use parry3d::query::PointQuery;
use parry3d::shape::{TriMesh, TriMeshFlags};
use std::collections::HashMap;

fn shrunk(world: &World, p: usize, amount: f32) -> TriMesh {
    let m = world.shapes().mesh(p);
    let (v, t) = eroded_mesh(m.vertices(), m.indices(), amount);
    TriMesh::with_flags(v, t, TriMeshFlags::ORIENTED).unwrap()
}

/// Whether part `p` at `pose` penetrates a present part (other than itself) deeper than the
/// tolerance: surfaces crossing, or one inside the other. Each pair shrinks the part the world
/// chose for it (the moving part, or for input overlaps the one that separates more easily).
/// A screw step's threaded partners are not tested here (their threads are invariant under the
/// screw motion, which is not a translation); `screw` says whether the step is one.
/// Pairs in `fits` (a coaxial fit along the motion, see [`fit_band`]) are checked by the
/// strict rule with their band instead.
fn penetrates(
    world: &World,
    p: usize,
    pose: &Pose,
    present: &PartSet,
    shrunk_cache: &mut HashMap<(usize, u32), TriMesh>,
    screw: bool,
    fits: &HashMap<(usize, usize), Band>,
) -> Option<usize> {
    present
        .iter()
        .filter(|&q| {
            !(q == p
                || world.overlaps().ignores(p, q)
                || fits.contains_key(&(p, q))
                || screw && world.overlaps().fits().thread(p, q).is_some())
        })
        .find(|&q| {
            let (k, amount) = world.overlaps().erosion(p, q);
            let shrunk_k = shrunk_cache.entry((k, amount.to_bits())).or_insert_with(|| shrunk(world, k, amount)).clone();
            let id = Pose::IDENTITY;
            let (shrunk_pose, raw, raw_pose) =
                if k == p { (*pose, world.shapes().mesh(q).clone(), id) } else { (id, world.shapes().mesh(p).clone(), *pose) };
            let closed_raw = world.shapes().is_closed(if k == p { q } else { p });
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
                || (world.shapes().is_closed(k)
                    && nests(&br, &bs)
                    && shrunk_k.contains_point(&shrunk_pose, raw_pose.transform_point(raw.vertices()[0])))
        })
}

/// Each triangle's centroid and each vertex of part `p`, moved inward by the tolerance (vertices
/// along the mean of their faces' normals): the strict check's samples, made here rather than by
/// the planner's sampler.
fn inner_points(world: &World, p: usize) -> Vec<Vec3> {
    let m = world.shapes().mesh(p);
    let (v, t) = (m.vertices(), m.indices());
    let depth = world.shapes().tolerance();
    let mut normals = vec![Vec3::ZERO; v.len()];
    let mut out = Vec::with_capacity(t.len() + v.len());
    for tri in t {
        let [a, b, c] = tri.map(|i| v[i as usize]);
        let n = (b - a).cross(c - a);
        for &i in tri {
            normals[i as usize] += n;
        }
        if let Some(u) = n.try_normalize() {
            out.push((a + b + c) / 3.0 - u * depth);
        }
    }
    out.extend(v.iter().zip(&normals).filter_map(|(x, n)| n.try_normalize().map(|u| *x - u * depth)));
    out
}

/// A coaxial fit band: samples whose distance from the line through `point` along the motion
/// lies within one of the `rings` (`[lo, hi]`; a stepped shaft in a stepped bore has one per
/// step) carry the fit along.
#[derive(Clone, Debug)]
pub struct Band {
    point: Vec3,
    rings: Vec<(f32, f32)>,
    /// `None`: samples in the rings may enter (the shell was seen all around); `Some(d)`: they
    /// may enter no deeper than `d`, the pair's measured input overlap or the fit band's width,
    /// the larger (a fit the planner reports whose overlap the samples see only in part: the
    /// same fit carried along enters no deeper than its polygons' sagittas).
    max_depth: Option<f32>,
}

/// The band of a fit `world` reports for the pair along unit `dir`, its samples allowed to
/// enter only as deep as the pair overlaps in the input or the band is wide (see
/// [`Band::max_depth`]).
fn reported_band(world: &World, p: usize, q: usize, dir: Vec3) -> Option<Band> {
    let f = world.overlaps().fits().between(p, q).iter().find(|f| f.axis.dot(dir).abs() > 0.9999)?;
    let overlap = world.overlaps().notes().iter().find(|n| n.parts == (p.min(q), p.max(q))).map_or(0.0, |n| n.depth);
    // two polygons drawn at one radius enter each other by up to their sagittas, whether or
    // not the input shows it (the band spans them)
    Some(Band { point: f.point, rings: vec![f.band], max_depth: Some(overlap.max(f.band.1 - f.band.0) + world.shapes().tolerance()) })
}

/// The replay referee's fit band of the pair (`p`, `q`) for a motion along unit `dir`, found
/// from the geometry alone (not the planner's surfaces): the samples of either part (moved
/// inward by the tolerance) that lie inside the other in the input — their overlap — projected
/// on the plane normal to the motion, form thin shells all around one centre (a circle fitted
/// by least squares gives the centre; the distances from it fall into rings, each with no
/// angular gap over a quarter turn). The referee fits one circle, so it sees a stepped shaft
/// (two shells about one axis) as no fit; this re-check takes each step's shell on its own.
/// The referee allows a shell up to 0.35 of its radius wide; this re-check allows a fifth (a
/// coarse thread drawn at its minor diameter overlaps by about 0.17 of the radius), so a pin
/// pulled a few degrees off its axis (whose overlap, seen along the motion, smears into a thick
/// ring) is no fit. `None` for every other pair, and for pairs that do not overlap beyond the
/// tolerance (the shrunk sweep holds them).
fn fit_band(world: &World, p: usize, q: usize, dir: Vec3, samples: &mut HashMap<usize, Vec<Vec3>>) -> Option<Band> {
    let tol = world.shapes().tolerance();
    let mut shell = Vec::new();
    for (a, b) in [(p, q), (q, p)] {
        // the check's own samples and, as the referee takes them, about 6,000 area-weighted
        // surface points moved inward by the tolerance: the overlap of a fit is a thin shell
        // that centroids of long facets miss
        let mut pts = samples.entry(a).or_insert_with(|| inner_points(world, a)).clone();
        let m = world.shapes().mesh(a);
        let dense = asp_geom::sample::sample_triangles(m.vertices(), m.indices(), 6000);
        pts.extend(dense.points.iter().zip(&dense.normals).map(|(x, n)| *x - *n * tol));
        let mesh = world.shapes().mesh(b);
        let bb = world.shapes().aabb(b);
        for x in pts {
            if (0..3).all(|i| x[i] >= bb.mins[i] - 3.0 * tol && x[i] <= bb.maxs[i] + 3.0 * tol) && mesh.contains_local_point(x) {
                shell.push(x);
            }
        }
    }
    if shell.len() < 12 {
        return None;
    }
    let u = dir.any_orthonormal_pair();
    let uv: Vec<[f64; 2]> = shell.iter().map(|x| [x.dot(u.0) as f64, x.dot(u.1) as f64]).collect();
    // algebraic circle fit: u^2 + v^2 + D u + E v + F = 0, normal equations
    let mut m = [[0.0f64; 3]; 3];
    let mut rhs = [0.0f64; 3];
    for c in &uv {
        let row = [c[0], c[1], 1.0];
        let b = -(c[0] * c[0] + c[1] * c[1]);
        for i in 0..3 {
            for j in 0..3 {
                m[i][j] += row[i] * row[j];
            }
            rhs[i] += row[i] * b;
        }
    }
    let det = |m: &[[f64; 3]; 3]| {
        m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
            + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
    };
    let d0 = det(&m);
    if d0.abs() < 1e-300 {
        return None;
    }
    let solve = |k: usize| {
        let mut mk = m;
        for i in 0..3 {
            mk[i][k] = rhs[i];
        }
        det(&mk) / d0
    };
    let (dd, ee, ff) = (solve(0), solve(1), solve(2));
    let (cu, cv) = (-0.5 * dd, -0.5 * ee);
    if cu * cu + cv * cv - ff <= 0.0 {
        return None;
    }
    // (distance from the centre, angle about it), by distance; a new ring starts where the
    // distances jump by more than four tolerances
    let mut polar: Vec<(f64, f64)> = uv.iter().map(|c| ((c[0] - cu).hypot(c[1] - cv), (c[1] - cv).atan2(c[0] - cu))).collect();
    polar.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut rings = Vec::new();
    let mut start = 0;
    for i in 1..=polar.len() {
        if i < polar.len() && polar[i].0 - polar[i - 1].0 <= 4.0 * tol as f64 {
            continue;
        }
        let ring = &polar[start..i];
        start = i;
        let (lo, hi) = (ring[0].0 - tol as f64, ring[ring.len() - 1].0 + tol as f64);
        let mut ang: Vec<f64> = ring.iter().map(|x| x.1).collect();
        ang.sort_by(f64::total_cmp);
        let gap = ang.windows(2).map(|w| w[1] - w[0]).chain([ang[0] + std::f64::consts::TAU - ang[ang.len() - 1]]).fold(0.0, f64::max);
        let r = 0.5 * (lo + hi);
        if ring.len() < 12 || gap > std::f64::consts::FRAC_PI_2 || hi - lo > 0.2 * r {
            return None; // some of the overlap is no thin shell all around the axis
        }
        rings.push((lo as f32, hi as f32));
    }
    let point = u.0 * cu as f32 + u.1 * cv as f32;
    Some(Band { point, rings, max_depth: None })
}

/// The strict overlap rule, re-checked by point containment at the sampled poses (the replay's
/// rule): for each pair of a mover and a present part that overlap in the input under the
/// strict policy, no sample of either (moved inward by the tolerance) that is outside the other
/// at the start is inside it at a later pose.
///
/// A screw step (`screw`) is checked the same way against the mover's threaded partners, on
/// the samples of both parts outside the thread zone (the cylinder about the axis out to the
/// thread's radius, where the threads turn in each other): a bolt's head, a nut's faces, the
/// material around a tapped hole may enter nothing, whether the pair overlaps in the input or
/// only touches. Every other pair of a screw step is checked as for a straight line.
#[allow(clippy::too_many_arguments)] // the step, its parts, poses, caches and motion
fn check_strict(
    world: &World,
    k: usize,
    movers: &[usize],
    others: &PartSet,
    poses: &[Pose],
    samples: &mut HashMap<usize, Vec<Vec3>>,
    screw: Option<Vec3>,
    fits: &HashMap<(usize, usize), Band>,
    dir: Option<Vec3>,
) {
    for &p in movers {
        for q in others.iter() {
            let thread = screw.and_then(|_| world.overlaps().fits().thread(p, q));
            let band = fits.get(&(p, q)).cloned();
            if thread.is_none() && band.is_none() && !world.overlaps().is_strict(p, q) {
                continue;
            }
            if let (Some(t), Some(dir)) = (thread, screw) {
                // the step is along this thread's axis
                assert!(t.axis.direction.dot(dir).abs() > 0.9999, "step {k}: '{}' screws off its axis", world.name(p));
            }
            for (a, b, sign) in [(p, q, 1.0f32), (q, p, -1.0)] {
                let mut pts = samples.entry(a).or_insert_with(|| inner_points(world, a)).clone();
                if let Some(t) = thread {
                    // both parts' samples in the assembled pose: outside the zone only
                    pts.retain(|&x| t.axis.radial(x) > t.radius);
                }
                // how deep each sample may enter: touching is not entering
                let half = 0.5 * world.shapes().tolerance();
                let mut allowed = vec![half; pts.len()];
                if let (Some(b), Some(d)) = (&band, dir) {
                    // a coaxial fit carried along its axis: the band's samples (a sample keeps
                    // its distance from the line along the motion) are exempt, or held to the
                    // pair's input overlap
                    let in_band = |x: Vec3| {
                        let r = x - b.point;
                        let r = (r - d * r.dot(d)).length();
                        b.rings.iter().any(|&(lo, hi)| r >= lo && r <= hi)
                    };
                    let (kept, depths): (Vec<Vec3>, Vec<f32>) = pts
                        .iter()
                        .filter_map(|&x| match (in_band(x), b.max_depth) {
                            (false, _) => Some((x, half)),
                            (true, Some(m)) => Some((x, m)),
                            (true, None) => None,
                        })
                        .unzip();
                    (pts, allowed) = (kept, depths);
                }
                // `a`'s samples in the frame of `b`: the mover's moved by the pose, the other's
                // by its inverse
                let place = |pose: &Pose, x: Vec3| if sign > 0.0 { pose.transform_point(x) } else { pose.inverse_transform_point(x) };
                let mesh = world.shapes().mesh(b);
                let bb = world.shapes().aabb(b);
                let pad = 2.0 * world.shapes().tolerance();
                let near = |x: Vec3| (0..3).all(|i| x[i] >= bb.mins[i] - pad && x[i] <= bb.maxs[i] + pad);
                // a sample on the other's surface (within half the tolerance) counts as inside
                // at the start and outside later: touching is not entering
                let depth = |x: Vec3| (mesh.project_local_point(x, false).point - x).length();
                let start: Vec<bool> = pts.iter().map(|&x| near(x) && (mesh.contains_local_point(x) || depth(x) <= half)).collect();
                for pose in &poses[1..] {
                    if let Some(((x, _), allow)) = pts.iter().zip(&start).zip(&allowed).find(|((x, inside), allow)| {
                        let y = place(pose, **x);
                        !**inside && near(y) && mesh.contains_local_point(y) && depth(y) > **allow
                    }) {
                        panic!(
                            "step {k}: strict: a sample of '{}' at {x:?} enters '{}' deeper than {allow}, which the pair overlaps in the input, at {pose:?}",
                            world.name(a),
                            world.name(b)
                        );
                    }
                }
            }
        }
    }
}

/// Re-checks every removal of a found plan: collision-free sweep, bounds cleared at the end,
/// and a stable remainder. Panics with the step on failure.
pub fn verify_plan(world: &World, outcome: &PlanOutcome) {
    assert_eq!(outcome.status, Status::Found, "only found plans are verified");
    let state = verify_removals(world, &outcome.removals);
    assert!(state.iter().all(|p| world.contacts().fixed().contains(p)), "plan leaves non-fixed parts");
}

/// Re-checks removals from the full assembly as [`verify_plan`] does (a whole plan or a partial
/// disassembly) and returns the state they reach.
pub fn verify_removals(world: &World, removals: &[asp_search::Step]) -> PartSet {
    verify_from(world, PartSet::full(world.num_parts()), world.contacts().fixed(), removals)
}

/// Re-checks removals from the full assembly as [`verify_removals`] does, but not the
/// remainder's stability: the contract of a planner that takes a model apart in the hand (the
/// grid planner tests no gravity).
pub fn verify_removals_in_hand(world: &World, removals: &[asp_search::Step]) -> PartSet {
    Verifier { in_hand: true, ..Verifier::default() }.verify_from(
        world,
        PartSet::full(world.num_parts()),
        world.contacts().fixed(),
        removals,
    )
}

/// Re-checks `removals` from `state` on the `base` parts: each step's parts (one part, or a
/// rigid subassembly's) swept together against the others, bounds cleared at the end, the rest
/// stable on the base; a subassembly's own plan re-checked the same way on its base part.
pub fn verify_from(world: &World, state: PartSet, base: &PartSet, removals: &[asp_search::Step]) -> PartSet {
    Verifier::default().verify_from(world, state, base, removals)
}

/// The re-check with what it learns kept across calls: shrunk meshes and surface samples of
/// each part, and every (step, other part) pair already swept clear. Every test of the sweep is
/// a test of one moving part against one present part, so a step whose motion was swept clear
/// of part `q` once is clear of it in any other order too; re-checking many orders of one plan
/// (the precedence graph's linear extensions) then sweeps each pair once. The bounds at the end
/// and the stability of each state are tested every time.
#[derive(Default)]
pub struct Verifier {
    cache: HashMap<(usize, u32), TriMesh>,
    samples: HashMap<usize, Vec<Vec3>>,
    /// (the step's movers and motion, the other part) swept clear.
    clear: std::collections::HashSet<(String, usize)>,
    /// Whether the remainders' stability is left out (a plan made in the hand).
    in_hand: bool,
}

impl Verifier {
    /// [`verify_removals`] with this verifier's caches.
    #[allow(dead_code)] // asp-app's precedence tests re-check many orders with one verifier
    pub fn verify_removals(&mut self, world: &World, removals: &[asp_search::Step]) -> PartSet {
        self.verify_from(world, PartSet::full(world.num_parts()), world.contacts().fixed(), removals)
    }

    /// [`verify_from`] with this verifier's caches.
    pub fn verify_from(&mut self, world: &World, mut state: PartSet, base: &PartSet, removals: &[asp_search::Step]) -> PartSet {
        for (k, step) in removals.iter().enumerate() {
            let movers = step.parts();
            assert!(movers.contains(&step.part), "step {k}: its part is one of its movers");
            for &p in &movers {
                assert!(state.contains(p) && !base.contains(p), "step {k}: part {p} not removable");
            }
            let mut others = state.clone();
            others.union_with(base);
            for &p in &movers {
                others.remove(p);
            }
            let bounds = movers
                .iter()
                .map(|&p| *world.shapes().aabb(p))
                .reduce(|a, b| parry3d::bounding_volume::Aabb::new(a.mins.min(b.mins), a.maxs.max(b.maxs)))
                .unwrap();
            // steps of a quarter of the thinnest moving part
            let thinnest = movers
                .iter()
                .map(|&p| (world.shapes().aabb(p).maxs - world.shapes().aabb(p).mins).min_element())
                .fold(f32::INFINITY, f32::min);
            let h = (thinnest / 4.0).max(world.shapes().tolerance());
            let poses: Vec<Pose> = match &step.motion {
                Motion::Linear { direction, distance } | Motion::Screw { direction, distance, .. } => {
                    assert!((direction.length() - 1.0).abs() < 1e-4);
                    let count = ((distance / h).ceil() as usize).clamp(8, 400);
                    // and steps of the tolerance over the first 20 tolerances (strict overlaps)
                    let tol = world.shapes().tolerance();
                    let first = (1..=20).map(|i| i as f32 * tol).filter(|&t| t < *distance);
                    let mut ts: Vec<f32> = (0..=count).map(|i| distance * i as f32 / count as f32).chain(first).collect();
                    ts.sort_by(f32::total_cmp);
                    ts.into_iter().map(|t| Pose::from_translation(*direction * t)).collect()
                }
                // every segment, at least 20 samples, and at most `h` apart along its pivot's travel
                Motion::Path { poses, pivot } => poses
                    .windows(2)
                    .flat_map(|w| {
                        let travel = (w[1].transform_point(*pivot) - w[0].transform_point(*pivot)).length();
                        let count = ((travel / h).ceil() as usize).clamp(20, 400);
                        (0..count).map(move |i| interpolate_about(*pivot, &w[0], &w[1], i as f32 / count as f32))
                    })
                    .chain(poses.last().copied())
                    .collect(),
            };
            let screw = match step.motion {
                Motion::Screw { direction, .. } => Some(direction),
                _ => None,
            };
            // straight motions: the pairs that carry a coaxial fit along them, found here
            let dir = match step.motion {
                Motion::Linear { direction, .. } | Motion::Screw { direction, .. } => Some(direction),
                Motion::Path { .. } => None,
            };
            // the pairs this step's motion was not yet swept clear of
            let key = format!("{movers:?} {:?}", step.motion);
            let mut unknown = others.clone();
            for q in others.iter() {
                if self.clear.contains(&(key.clone(), q)) {
                    unknown.remove(q);
                }
            }
            let mut fits = HashMap::new();
            if let Some(d) = dir {
                for &p in &movers {
                    for q in unknown.iter().filter(|&q| q < world.num_parts() && world.contacts().of(p).contains(q)) {
                        if let Some(b) = fit_band(world, p, q, d, &mut self.samples).or_else(|| reported_band(world, p, q, d)) {
                            fits.insert((p, q), b);
                        }
                    }
                }
            }
            if let Motion::Screw { axis_point, direction, .. } = step.motion {
                // a screw step's part has a threaded partner present, and turns about that axis:
                // a modelled thread, or a coaxial fit along the motion (a nut on its bolt as CAD
                // draws it)
                // any threaded partner present will do (in another order than the plan's, another
                // of them may be the one present; each has its own fitted axis)
                let threads: Vec<_> = others.iter().filter_map(|q| world.overlaps().fits().thread(step.part, q)).collect();
                match threads.first() {
                    Some(_) => assert!(
                        threads.iter().any(|t| t.axis.direction.dot(direction).abs() > 0.9999
                            && t.axis.radial(axis_point) < 1e-3 * t.axis.radius.max(1e-9) + 1e-6),
                        "step {k}: '{}' screws off its axis (the axis of every threaded partner present)",
                        world.name(step.part)
                    ),
                    None => assert!(
                        others.iter().any(|q| world
                            .overlaps()
                            .fits()
                            .between(step.part, q)
                            .iter()
                            .any(|f| f.turns == Some(step.part) && f.axis.dot(direction).abs() > 0.9999)),
                        "step {k}: '{}' screws with no threaded partner and no fit it turns on along its motion",
                        world.name(step.part)
                    ),
                }
            }
            check_strict(world, k, &movers, &unknown, &poses, &mut self.samples, screw, &fits, dir);
            for pose in &poses {
                for &p in &movers {
                    if let Some(q) =
                        penetrates(world, p, pose, &unknown, &mut self.cache, matches!(step.motion, Motion::Screw { .. }), &fits)
                    {
                        panic!("step {k}: part '{}' hits '{}' at {pose:?}", world.name(p), world.name(q));
                    }
                }
            }
            for q in unknown.iter() {
                self.clear.insert((key.clone(), q));
            }
            // at the end, the movers' bounds are clear of the other present real parts' bounds
            let end = bounds.transform_by(poses.last().unwrap());
            for q in state.iter().filter(|q| !movers.contains(q)) {
                let b = world.shapes().aabb(q);
                let overlap = (0..3).all(|i| end.mins[i] < b.maxs[i] - 1e-6 && b.mins[i] < end.maxs[i] - 1e-6);
                assert!(!overlap, "step {k}: part '{}' still inside the bounds of '{}'", world.name(step.part), world.name(q));
            }
            for &p in &movers {
                state.remove(p);
            }
            let mut present = state.clone();
            present.union_with(base);
            if !self.in_hand {
                assert_eq!(world.contacts().stability_among(&present, base), Stability::Stable, "step {k}: remainder unstable");
            }
            if let Some(plan) = step.group.as_ref().and_then(|g| g.plan.as_ref()) {
                let group = step.group.as_ref().unwrap();
                let sub_base = PartSet::from_indices(world.num_parts() + 1, [step.part]);
                let mut inner = group.parts.clone();
                inner.remove(step.part);
                let left = self.verify_from(world, inner, &sub_base, &plan.removals);
                if plan.status == Status::Found {
                    assert!(left.is_empty(), "step {k}: its subassembly's plan leaves parts on the base");
                }
            }
        }
        let _ = Vec3::ZERO;
        state
    }
}
