//! Physics stability (`--stability physics`): a state stands when the present parts, simulated
//! under gravity with rapier3d for a short while, stay where they are.
//!
//! The fixed parts (and the world's virtual ground) are static; every other present part is a
//! dynamic rigid body of density 1. A moving part's collider is its convex hull when it is
//! convex, else a convex decomposition (V-HACD) of its collision mesh; a fixed part keeps its
//! exact triangle mesh (static colliders need not be solid, and a mesh has no filled holes); the
//! ground is a box. After the simulated time, a part whose centre of mass moved — or which turned
//! by an angle that moves its farthest point — more than a threshold is reported as floating.
//!
//! Two facts of real CAD data shape the simulation:
//! - **Parts rest exactly on each other** (face on face, distance 0). Rapier's speculative
//!   contacts (prediction distance) catch such contacts from the first step, the solver runs
//!   enough iterations for stacks, and the threshold (a fraction of the model's size) is far
//!   above the sinking of soft contacts, so resting stacks do not count as moving.
//! - **Parts overlap.** Two kinds are told apart:
//!   - *Interference fits* — pairs the [`World`] found overlapping in the input deeper than the
//!     tolerance ([`crate::world::Overlaps::pairs`]): a pressed pin, a thread modelled at nominal diameter. Such
//!     a joint carries gravity loads by friction, so the two parts are bonded into one rigid body
//!     (static when one of them is fixed). Simulating them as separate bodies would either push
//!     them apart violently or let a pressed pin slide out of its hole.
//!   - *Approximation overlaps* — convex pieces are a little larger than the mesh they
//!     approximate, so neighbours that only touch may start interpenetrating. Before the first
//!     step asp runs collision detection once (a step of zero length), records the initial depth
//!     of every such pair of convex pieces, and shifts that pair's contacts by it for the whole
//!     simulation (a contact-modification hook): the assembled pose is the pair's rest
//!     configuration, as the removal test shrinks a pair by its input overlap. Nothing is pushed
//!     apart, and support is kept. This works for shallow overlaps, where the contact normal is
//!     still the true one; a piece that swallows a neighbour deeply (the hull of a U around the
//!     part in its notch) gives a meaningless normal — hence the decomposition.
//!
//! One fact of parry shapes it too: a convex part touching a triangle's edge face-on-face may get
//! a false contact metres deep; such contacts with fixed meshes are dropped (see `ContactHook`).
//!
//! - **Parts are fastened.** A connector screwed to the profiles it joins, a bolt in its nut:
//!   what the model says is fastened ([`crate::meta::PartMeta::fastened_to`], written by the
//!   profile generator for every connector) and the threaded contacts the world detects
//!   ([`crate::world::Fits::threads`]) bond their two parts into one rigid body while both are present,
//!   like interference fits. Without that, a profile frame held only by its connectors' side
//!   contacts collapses in its assembled state and no removal is ever stable.
//!
//! Fasteners missing from the model are not guessed: a shelf held only by side contacts with
//! the panels (its dowels or pins not modelled, nothing declared) falls, where the contact graph
//! calls it supported.
//!
//! The rapier world is built per call (so [`PhysicsStability`] is `Send + Sync` and can be used
//! from rayon); only the collider shapes are cached. Rapier is deterministic single-threaded, and
//! bodies are inserted in part order, so the same state always gives the same answer.

use crate::error::{GeomError, Result};
use crate::feasibility::Stability;
use crate::math::{Pose, Vec3};
use crate::partset::PartSet;
use crate::world::World;
use parry3d::shape::TriMesh;
use parry3d::transformation::vhacd::{VHACDParameters, VHACD};
use rapier3d::prelude::{
    ActiveHooks, ColliderBuilder, ContactModificationContext, PhysicsHooks, PhysicsWorld, RigidBodyBuilder, RigidBodyHandle, SharedShape,
};
use std::collections::{BTreeMap, BTreeSet};
use std::sync::OnceLock;

/// Standard gravity, m/s² (lengths inside asp are metres).
const GRAVITY: f32 = 9.81;

/// A closed part whose volume is at least this fraction of its convex hull's is simulated as its
/// hull: exact for boxes, pins and plates, and no decomposition cost.
const CONVEX_VOLUME_RATIO: f32 = 0.99;

/// Most convex pieces one part is decomposed into.
const MAX_CONVEX_PIECES: u32 = 32;

/// Settings of the physics stability check.
#[derive(Clone, Debug, PartialEq)]
pub struct PhysicsConfig {
    /// How long gravity acts, in seconds. Default 1.0: an unsupported part falls 4.9 m in that
    /// time and a part tipping over an edge turns by radians, far beyond any threshold, while
    /// 120 steps stay cheap.
    pub simulated_time: f32,
    /// The integration step, in seconds. Default 1/120 s, half rapier's 1/60 s: a part travels
    /// half as far into its contacts per step, which matters for parts a few millimetres thick.
    pub time_step: f32,
    /// A part is unstable when it moved more than this fraction of the model's diagonal (its
    /// centre of mass, or its farthest point through rotation). Default 0.01. Resting parts
    /// settle by 1e-5 to 1e-4 of the diagonal on the fixtures; an IKEA chair whose rear legs
    /// end 4 mm above its front legs rocks back onto them and moves 0.007 of its diagonal, still
    /// stable. A part falling onto something less than 1% of the diagonal below goes unnoticed;
    /// a free fall covers 1% of a 1 m model in 0.045 s, and a tipping part soon after.
    pub displacement_fraction: f32,
    /// Coulomb friction coefficient of every contact. Default 0.5, rapier's default and a
    /// middle value for dry contacts of wood, plastic and steel.
    pub friction: f32,
    /// Constraint-solver iterations per step. Default 8, what rapier recommends for stacks of
    /// objects (its own default is 4).
    pub solver_iterations: usize,
    /// Whether non-convex moving parts are decomposed into convex pieces (V-HACD); otherwise each
    /// is simulated as its convex hull (faster, but a hull fills holes and notches). Default true.
    pub convex_decomposition: bool,
    /// Voxel resolution of the convex decomposition. Default 32: a part decomposes in tens of
    /// milliseconds (64 took 4 to 10 times as long on the fixtures' voxel parts and still let a
    /// piece bridge the tube's bore).
    /// The pieces are hulls of the mesh's own triangles. V-HACD may still bridge a hole or notch
    /// with one piece; neighbours that start inside such a piece are handled as approximation
    /// overlaps (see the module documentation).
    pub decomposition_resolution: u32,
}

impl Default for PhysicsConfig {
    fn default() -> Self {
        PhysicsConfig {
            simulated_time: 1.0,
            time_step: 1.0 / 120.0,
            displacement_fraction: 0.01,
            friction: 0.5,
            solver_iterations: 8,
            convex_decomposition: true,
            decomposition_resolution: 32,
        }
    }
}

impl PhysicsConfig {
    /// Checks every value is in range: positive finite times with a step no longer than the
    /// simulated time, a positive displacement fraction, a finite non-negative friction, at least
    /// one solver iteration and a decomposition resolution of at least 8.
    pub fn validate(&self) -> Result<()> {
        let positive = |v: f32| v.is_finite() && v > 0.0;
        if !positive(self.simulated_time) || !positive(self.time_step) {
            return Err(GeomError::config("physics simulated time and time step must be positive"));
        }
        if self.time_step > self.simulated_time {
            return Err(GeomError::config("physics time step must not exceed the simulated time"));
        }
        if !positive(self.displacement_fraction) {
            return Err(GeomError::config("physics displacement fraction must be positive"));
        }
        if !(self.friction.is_finite() && self.friction >= 0.0) {
            return Err(GeomError::config("friction must be finite and non-negative"));
        }
        if self.solver_iterations == 0 {
            return Err(GeomError::config("physics needs at least one solver iteration"));
        }
        if self.decomposition_resolution < 8 {
            return Err(GeomError::config("convex decomposition resolution must be at least 8"));
        }
        Ok(())
    }

    /// This configuration, or the default if it is out of range (see [`Self::validate`]).
    fn or_default(&self) -> PhysicsConfig {
        if self.validate().is_ok() {
            self.clone()
        } else {
            PhysicsConfig::default()
        }
    }
}

/// One part's collider in its assembled pose, with what the displacement measure needs.
struct PartShape {
    shape: SharedShape,
    /// The collider's pose relative to its body (bodies start at the identity).
    pose: Pose,
    /// The part's centre of mass in its assembled pose.
    com: Vec3,
    /// The distance from the centre of mass to the farthest corner of the part's bounds.
    radius: f32,
}

/// Judges states by simulating them under gravity; built once per [`World`], it caches each
/// part's collider shape (computed the first time the part is simulated, or all at once by
/// [`Self::prepare`]).
pub struct PhysicsStability {
    config: PhysicsConfig,
    shapes: Vec<OnceLock<Option<PartShape>>>,
    /// Pairs bonded into one rigid body while both are present: interference fits, declared
    /// fastenings and threaded contacts, `(i, j)` with `i < j`, sorted.
    bonds: Vec<(usize, usize)>,
    threshold: f32,
    length_unit: f32,
    gravity: Vec3,
}

impl PhysicsStability {
    /// A physics check for `world` (cheap: shapes are computed on demand). An out-of-range
    /// `config` is replaced by the default; call [`PhysicsConfig::validate`] first to report it.
    pub fn new(world: &World, config: &PhysicsConfig) -> Self {
        let config = config.or_default();
        let count = world.num_parts() + usize::from(world.shapes().ground().is_some());
        let diag = world.assembly().diagonal().max(f32::MIN_POSITIVE);
        // rapier's tolerances are tuned for objects about one length unit in size: use the
        // median part size, so a few tiny screws or one huge base do not skew it
        let mut sizes: Vec<f32> = (0..world.num_parts())
            .map(|i| {
                let b = world.shapes().aabb(i);
                (b.maxs - b.mins).length()
            })
            .filter(|s| s.is_finite() && *s > 0.0)
            .collect();
        sizes.sort_by(f32::total_cmp);
        let length_unit = sizes.get(sizes.len() / 2).copied().unwrap_or(diag);
        let (fastened, _) = world.assembly().fastenings();
        let threaded = world.overlaps().fits().threads().keys().map(|&(p, q)| (p.min(q), p.max(q)));
        let bonds: BTreeSet<(usize, usize)> = world.overlaps().pairs().keys().copied().chain(fastened).chain(threaded).collect();
        PhysicsStability {
            bonds: bonds.into_iter().collect(),
            threshold: config.displacement_fraction * diag,
            config,
            shapes: (0..count).map(|_| OnceLock::new()).collect(),
            length_unit,
            gravity: -world.assembly().up.vector() * GRAVITY,
        }
    }

    /// The settings in use.
    pub fn config(&self) -> &PhysicsConfig {
        &self.config
    }

    /// How far (metres) a part may move before it counts as unstable.
    pub fn threshold(&self) -> f32 {
        self.threshold
    }

    /// Computes every part's collider shape now, in parallel (the convex decompositions are the
    /// expensive part). Call it outside rayon tasks; [`Self::stability`] works without it.
    pub fn prepare(&self, world: &World) {
        use rayon::prelude::*;
        (0..self.shapes.len()).into_par_iter().for_each(|i| {
            self.shape(world, i);
        });
    }

    /// The cached collider of part `i` (ground included).
    fn shape(&self, world: &World, i: usize) -> Option<&PartShape> {
        self.shapes.get(i)?.get_or_init(|| part_shape(world, i, &self.config)).as_ref()
    }

    /// Simulates `state` (plus the fixed parts) under gravity and reports the parts that moved
    /// more than the threshold. `world` must be the one this check was built for.
    pub fn stability(&self, world: &World, state: &PartSet) -> Stability {
        self.stability_holding(world, state, &PartSet::empty(0))
    }

    /// [`PhysicsStability::stability`] with the `held` parts of `state` held in place (static,
    /// like fixed parts: by another gripper or a fixture).
    pub fn stability_holding(&self, world: &World, state: &PartSet, held: &PartSet) -> Stability {
        // a NaN (a blown-up simulation) counts as moved
        let floating =
            self.displacements_holding(world, state, held).into_iter().filter(|&(_, d)| d.is_nan() || d > self.threshold).map(|(i, _)| i);
        let floating = PartSet::from_indices(self.shapes.len(), floating);
        if floating.is_empty() {
            Stability::Stable
        } else {
            Stability::Unstable { floating }
        }
    }

    /// Simulates `state` (plus the fixed parts) under gravity and returns how far (metres) each
    /// moving part went: the larger of its centre of mass's travel and its rotation angle times
    /// the distance from the centre of mass to its farthest bound. Parts that are static (fixed,
    /// or bonded to a fixed part) are left out.
    pub fn displacements(&self, world: &World, state: &PartSet) -> Vec<(usize, f32)> {
        self.displacements_holding(world, state, &PartSet::empty(0))
    }

    /// [`PhysicsStability::displacements`] with the `held` parts static too.
    pub fn displacements_holding(&self, world: &World, state: &PartSet, held: &PartSet) -> Vec<(usize, f32)> {
        let present = world.contacts().with_fixed(state);
        let count = self.shapes.len();
        let parts: Vec<usize> = present.iter().filter(|&i| i < count).collect();
        let group = bonded_groups(&self.bonds, &parts);
        let static_groups: BTreeSet<usize> =
            parts.iter().filter(|&&i| world.contacts().fixed().contains(i) || held.contains(i)).map(|i| group[i]).collect();
        let is_static = |g: usize| static_groups.contains(&g);
        if parts.iter().all(|i| is_static(group[i])) {
            return Vec::new();
        }

        let mut sim = PhysicsWorld::new();
        sim.gravity = self.gravity;
        let params = &mut sim.integration_parameters;
        params.dt = 0.0;
        params.length_unit = self.length_unit;
        params.num_solver_iterations = self.config.solver_iterations;

        let ground = sim.insert_body(RigidBodyBuilder::fixed());
        let mut bodies: BTreeMap<usize, RigidBodyHandle> = BTreeMap::new();
        let mut colliders = Vec::with_capacity(parts.len());
        let mut dynamic: Vec<(usize, RigidBodyHandle)> = Vec::new();
        for &i in &parts {
            let Some(ps) = self.shape(world, i) else { continue };
            let g = group[&i];
            let body = if is_static(g) { ground } else { *bodies.entry(g).or_insert_with(|| sim.insert_body(RigidBodyBuilder::dynamic())) };
            if body != ground {
                dynamic.push((i, body));
            }
            let collider =
                ColliderBuilder::new(ps.shape.clone()).position(ps.pose).density(1.0).friction(self.config.friction).user_data(i as u128);
            colliders.push(sim.insert_collider(collider, Some(body)));
        }

        // shift the contacts of sub-shape pairs that start interpenetrating by their initial
        // depth; a step of zero length only detects the contacts (`detect_collisions` would
        // leave the new bodies out of the next steps' active set)
        sim.step();
        let meshes = parts.iter().filter(|&&i| has_triangle_mesh(world, i)).map(|&i| i as u128);
        let mut hook = ContactHook { meshes: meshes.collect(), max_depth: 2.0 * self.threshold, ..ContactHook::default() };
        for pair in sim.narrow_phase.contact_pairs() {
            let part = |h| sim.colliders.get(h).map_or(0, |c| c.user_data);
            let (a, b) = (part(pair.collider1), part(pair.collider2));
            for m in pair.manifolds() {
                let deepest = m.points.iter().map(|p| p.dist).fold(0.0, f32::min);
                if deepest < 0.0 {
                    hook.insert((a, m.subshape1), (b, m.subshape2), -deepest);
                }
            }
        }
        for &h in &colliders {
            if let Some(c) = sim.colliders.get_mut(h) {
                if hook.meshes.contains(&c.user_data) || hook.shifted.contains(&c.user_data) {
                    c.set_active_hooks(ActiveHooks::MODIFY_SOLVER_CONTACTS);
                }
            }
        }

        sim.integration_parameters.dt = self.config.time_step;
        let steps = (self.config.simulated_time / self.config.time_step).ceil() as usize;
        for _ in 0..steps {
            sim.step_with_events(&hook, &());
            if bodies.values().all(|&h| sim.bodies.get(h).is_none_or(|b| b.is_sleeping())) {
                break;
            }
        }

        dynamic
            .iter()
            .filter_map(|&(i, h)| {
                let ps = self.shape(world, i)?;
                let pose = sim.bodies.get(h)?.position();
                let moved = (pose.transform_point(ps.com) - ps.com).length();
                let turned = pose.rotation.angle_between(crate::math::Rot::IDENTITY) * ps.radius;
                Some((i, moved.max(turned)))
            })
            .collect()
    }
}

/// Groups of present parts joined by `bonds` (interference fits, fastenings, threads): part →
/// group id (the smallest part index of its group).
fn bonded_groups(bonds: &[(usize, usize)], parts: &[usize]) -> BTreeMap<usize, usize> {
    let mut root: BTreeMap<usize, usize> = parts.iter().map(|&i| (i, i)).collect();
    fn find(root: &BTreeMap<usize, usize>, mut i: usize) -> usize {
        while let Some(&r) = root.get(&i).filter(|&&r| r != i) {
            i = r;
        }
        i
    }
    for &(a, b) in bonds {
        if root.contains_key(&a) && root.contains_key(&b) {
            let (ra, rb) = (find(&root, a), find(&root, b));
            root.insert(ra.max(rb), ra.min(rb));
        }
    }
    parts.iter().map(|&i| (i, find(&root, i))).collect()
}

/// The contact-modification hook.
///
/// `depth`: initial interpenetration depths of sub-shape pairs — (part, sub-shape) on each side,
/// the smaller first — by which their contacts are shifted for the whole simulation. Per
/// sub-shape pair, not per part pair: a convex piece swelling into a neighbour must not let the
/// pair's other contacts (say, the face the neighbour rests on) sink by as much.
///
/// Contacts with a triangle mesh (a fixed part) still deeper than `max_depth` (twice the
/// displacement threshold) after the shift are dropped. parry's triangle-versus-polyhedron
/// manifolds report metres of false penetration where a part touches a triangle's edge
/// face-on-face (a shaft in its hole, a cap under a tube; measured on the tube fixture: 2.4 m),
/// and obeying one flings the part. A true contact that deep means one of the two parts already
/// moved more than the threshold, so dropping it cannot turn an unstable state stable.
#[derive(Default)]
struct ContactHook {
    depth: BTreeMap<(SubShape, SubShape), f32>,
    /// Parts with shifted sub-shape pairs.
    shifted: BTreeSet<u128>,
    /// Parts whose collider is a triangle mesh.
    meshes: BTreeSet<u128>,
    max_depth: f32,
}

/// A convex piece of a collider: (part index as the collider's user data, sub-shape index).
type SubShape = (u128, u32);

impl ContactHook {
    fn key(a: SubShape, b: SubShape) -> (SubShape, SubShape) {
        (a.min(b), a.max(b))
    }

    fn insert(&mut self, a: SubShape, b: SubShape, depth: f32) {
        let d = self.depth.entry(Self::key(a, b)).or_insert(0.0);
        *d = d.max(depth);
        self.shifted.extend([a.0, b.0]);
    }
}

impl PhysicsHooks for ContactHook {
    fn modify_solver_contacts(&self, context: &mut ContactModificationContext) {
        let part = |h| context.colliders.get(h).map_or(0, |c| c.user_data);
        let (a, b) = (part(context.collider1), part(context.collider2));
        if let Some(rigid) = context.rigid_mut() {
            let (s1, s2) = (rigid.manifold.subshape1, rigid.manifold.subshape2);
            let depth = self.depth.get(&Self::key((a, s1), (b, s2))).copied().unwrap_or(0.0);
            for contact in rigid.solver_contacts.iter_mut() {
                contact.dist += depth;
            }
            if self.meshes.contains(&a) || self.meshes.contains(&b) {
                rigid.solver_contacts.retain(|c| c.dist >= -self.max_depth);
            }
        }
    }
}

/// Whether part `i`'s collider is a triangle mesh: a fixed part other than the ground.
fn has_triangle_mesh(world: &World, i: usize) -> bool {
    world.contacts().fixed().contains(i) && world.shapes().ground() != Some(i)
}

/// The collider of part `i` (ground included): a box for the ground, the exact triangle mesh for
/// fixed parts (static, so it need not be solid: no filled holes), convex pieces for the others.
fn part_shape(world: &World, i: usize, config: &PhysicsConfig) -> Option<PartShape> {
    let aabb = world.shapes().aabb(i);
    let centre = (aabb.mins + aabb.maxs) * 0.5;
    if world.shapes().ground() == Some(i) {
        let half = (aabb.maxs - aabb.mins) * 0.5;
        return Some(PartShape {
            shape: SharedShape::cuboid(half.x, half.y, half.z),
            pose: Pose::from_translation(centre),
            com: centre,
            radius: half.length(),
        });
    }
    let mesh = world.shapes().mesh(i);
    let shape = if has_triangle_mesh(world, i) {
        static_mesh(mesh)
    } else {
        convex_shape(mesh, world.shapes().is_closed(i), config).unwrap_or_else(|| thin_box(aabb, world.assembly().diagonal()))
    };
    let com = shape.mass_properties(1.0).local_com;
    let com = if com.is_finite() { com } else { centre };
    let radius = (aabb.maxs - com).abs().max((aabb.mins - com).abs()).length();
    Some(PartShape { shape, pose: Pose::IDENTITY, com, radius })
}

/// A fixed part's triangle mesh as the world built it (oriented), without rapier's
/// internal-edge fixing: that made parts resting across the coplanar triangles of voxel-like
/// meshes slide.
fn static_mesh(mesh: &TriMesh) -> SharedShape {
    SharedShape::new(mesh.clone())
}

/// A part's collider: its convex hull when the part is (nearly) convex or decomposition is off,
/// else a V-HACD decomposition (pieces are hulls of the mesh's own triangles), falling back to
/// the hull when the decomposition yields nothing. `None` for a flat part.
fn convex_shape(mesh: &TriMesh, closed: bool, config: &PhysicsConfig) -> Option<SharedShape> {
    let hull = SharedShape::convex_hull(mesh.vertices());
    let hull_volume = hull.as_ref().map_or(0.0, |h| h.mass_properties(1.0).mass());
    let convex = closed && mesh_volume(mesh) >= CONVEX_VOLUME_RATIO * hull_volume;
    if hull.is_some() && (convex || !config.convex_decomposition) {
        return hull;
    }
    let params =
        VHACDParameters { resolution: config.decomposition_resolution, max_convex_hulls: MAX_CONVEX_PIECES, ..VHACDParameters::default() };
    // V-HACD is third-party code on arbitrary CAD meshes: a failure falls back to the hull
    let pieces = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        let decomposition = VHACD::decompose(&params, mesh.vertices(), mesh.indices(), true);
        decomposition
            .compute_exact_convex_hulls(mesh.vertices(), mesh.indices())
            .into_iter()
            .filter_map(|(points, _)| SharedShape::convex_hull(&points))
            .map(|piece| (Pose::IDENTITY, piece))
            .collect::<Vec<_>>()
    }))
    .unwrap_or_default();
    match pieces.len() {
        0 => hull,
        1 => pieces.into_iter().next().map(|(_, piece)| piece),
        _ => Some(SharedShape::compound(pieces)),
    }
}

/// The bounds of a flat (zero-volume) part as a box, thickened to 1e-3 of the model's diagonal.
fn thin_box(aabb: &crate::math::Aabb, diag: f32) -> SharedShape {
    let half = ((aabb.maxs - aabb.mins) * 0.5).max(Vec3::splat(5e-4 * diag.max(f32::MIN_POSITIVE)));
    let shape = SharedShape::cuboid(half.x, half.y, half.z);
    let centre = (aabb.mins + aabb.maxs) * 0.5;
    SharedShape::compound(vec![(Pose::from_translation(centre), shape)])
}

/// The volume enclosed by a closed, outward-oriented mesh.
fn mesh_volume(mesh: &TriMesh) -> f32 {
    let v = mesh.vertices();
    let six_volume: f64 = mesh
        .indices()
        .iter()
        .map(|t| {
            let (a, b, c) = (v[t[0] as usize], v[t[1] as usize], v[t[2] as usize]);
            a.dot(b.cross(c)) as f64
        })
        .sum();
    (six_volume / 6.0).abs() as f32
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn default_config_is_valid_and_bad_values_are_refused() {
        assert!(PhysicsConfig::default().validate().is_ok());
        let bad = PhysicsConfig { time_step: 2.0, ..PhysicsConfig::default() };
        assert!(bad.validate().is_err());
        assert_eq!(bad.or_default(), PhysicsConfig::default());
        assert!(PhysicsConfig { friction: f32::NAN, ..PhysicsConfig::default() }.validate().is_err());
    }

    #[test]
    fn physics_stability_is_send_and_sync() {
        fn check<T: Send + Sync>() {}
        check::<PhysicsStability>();
    }
}
