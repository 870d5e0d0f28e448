//! The collision world: every part as a parry triangle mesh, the tolerance policy, candidate
//! removal directions, the contact graph, and the cached pairwise blocking relation.
//!
//! The straight-line removal test rests on one fact: a translation along `d` collides with a
//! union of obstacles iff it collides with one of them, and a part that hits `q` does so before
//! its bounds clear the bounds of what remains (which contain `q`). So "does `q` block `p` along
//! `d`" is a property of the pair, independent of the state. asp computes it once per
//! (part, direction, neighbour) — lazily, the first time a part is tested, in parallel — and every
//! later removal test of that part is a few bitset operations.
//!
//! The folder splits the world by concern: `geom.rs` one part's collision geometry and its eroded
//! copies, `directions.rs` the candidate removal directions, `removal.rs` the removal tests, the
//! contact stability and the collision queries along a motion; this file builds the world
//! (mesh preparation, contacts and overlap measurement, threads) and answers the blocking rows.

mod bearings;
mod classify;
mod directions;
mod fits;
mod fused;
mod geom;
mod removal;

pub(crate) use removal::best_free_direction;

pub use bearings::{Bearing, RollingElement};
use classify::Regions;
pub use directions::candidate_directions;
use geom::{contains_point, nests, Geom};

use crate::assembly::Assembly;
use crate::boxes::{self, PartShape};
use crate::error::{GeomError, Result};
use crate::fastener::{self, SymmetryAxis, Thread};
use crate::feasibility::{Motion, Stability};
use crate::math::{aabb_of, sweep_overlap, Aabb, Pose, Vec3};
use crate::mesh::{Mesh, Topology};
use crate::overlap::{self, OverlapClass, OverlapHandling, OverlapKind, OverlapNote, OverlapPolicy};
use crate::partset::PartSet;
use crate::sweep;
use parry3d::query::{self, ClosestPoints, NonlinearRigidMotion, PointQuery};
use parry3d::shape::{TriMesh, TriMeshFlags};
use rayon::prelude::*;
use std::collections::{BTreeMap, BTreeSet};
use std::sync::{Arc, Mutex, OnceLock};

/// Settings of the collision world. Lengths in metres; `None` means "relative to the model".
#[derive(Clone, Debug, PartialEq)]
pub struct WorldConfig {
    /// Contact tolerance: a motion is blocked only when it pushes a part deeper than this into
    /// another. Default `1e-4 ×` the model's diagonal.
    pub tolerance: Option<f32>,
    /// Parts closer than this are in contact (the stability graph). Default `1e-3 ×` diagonal.
    pub contact_distance: Option<f32>,
    /// How many clustered surface-normal directions join the six axis directions (each with its
    /// opposite). Default 10.
    pub normal_clusters: usize,
    /// Normals within this angle (degrees) fall into one cluster. Default 10.
    pub cluster_angle_deg: f32,
    /// Extra directions sampled evenly on the sphere (Fibonacci lattice). Default 0.
    pub sphere_directions: usize,
    /// Parts that overlap in the input are warned about and each is shrunk, in tests against the
    /// other, until it no longer crosses the other's surface — up to this fraction of its
    /// thinnest extent (default 0.4: shrinking by half the thickness would make it vanish).
    /// What a pair that overlaps beyond the tolerance may do is the policy's (next field).
    pub max_overlap_fraction: f32,
    /// How overlapping pairs are tested ([`OverlapPolicy`]): `Strict` by default (they separate
    /// only along motions that enter no new material), `Lenient` (shrink, or ignore pairs that
    /// no shrinking separates), `Error` (such pairs stop planning).
    pub overlaps: OverlapPolicy,
    /// Test pairs of parts that are known unions of boxes (voxels or boxes in their extras, or a
    /// box-shaped mesh; see [`crate::boxes`]) exactly on their boxes. Default true; false tests
    /// every pair on the meshes.
    pub exact_boxes: bool,
    /// Find threaded fasteners (bolts, screws and nuts with modelled threads, see
    /// [`crate::fastener`]) and let them leave by screwing along their axes (whose directions
    /// join the candidates). Default true; false tests threaded pairs like any other.
    pub fasteners: bool,
}

impl Default for WorldConfig {
    fn default() -> Self {
        WorldConfig {
            tolerance: None,
            contact_distance: None,
            normal_clusters: 10,
            cluster_angle_deg: 10.0,
            sphere_directions: 0,
            max_overlap_fraction: 0.4,
            overlaps: OverlapPolicy::Strict,
            exact_boxes: true,
            fasteners: true,
        }
    }
}

/// The parts of an assembly as collision objects, plus an optional ground plane.
pub struct World {
    assembly: Assembly,
    geoms: Vec<Geom>,
    ground: Option<usize>,
    tolerance: f32,
    contact_distance: f32,
    directions: Vec<Vec3>,
    contacts: Vec<PartSet>,
    /// Unordered pair (low, high) → (the part shrunk in their tests, its extra erosion).
    overlaps: BTreeMap<(usize, usize), (usize, f32)>,
    ignored: BTreeSet<(usize, usize)>,
    /// Ordered pairs (both orders) tested by the strict overlap rule.
    strict: BTreeSet<(usize, usize)>,
    /// Per ordered strict pair `(p, q)` that no shrinking separates (tested by the strict rule
    /// alone): `p`'s samples for their strict test, its whole-surface samples and dense ones near
    /// `q` (made the first time the pair is tested).
    strict_samples: BTreeMap<(usize, usize), OnceLock<Vec<Vec3>>>,
    notes: Vec<OverlapNote>,
    policy: OverlapPolicy,
    /// Threaded contacts (ordered pairs), found with the world.
    threads: BTreeMap<(usize, usize), Thread>,
    /// Coaxial fits per pair (low, high), found with the world ([`crate::fits`]).
    fits: BTreeMap<(usize, usize), Vec<crate::fits::Fit>>,
    /// Per ordered pair with a fit that is not a clearance fit: the first part's samples for the
    /// fit test (whole surface and dense near the other), made when first needed.
    fit_samples: BTreeMap<(usize, usize), OnceLock<Vec<Vec3>>>,
    /// What each part is (nut, washer, bolt, pin, other), from its shape and name.
    roles: Vec<crate::fits::Role>,
    /// The rolling bearings among the parts ([`Bearing`]), found with the world.
    bearings: Vec<Bearing>,
    fixed: PartSet,
    rows: Vec<OnceLock<Vec<PartSet>>>,
    warnings: Vec<String>,
    /// The settings it was built with, `tolerance` and `contact_distance` resolved to metres.
    config: WorldConfig,
}

impl World {
    /// Prepares `assembly` for planning: welds and orients meshes, warns about open or
    /// non-manifold meshes and overlapping parts, adds a ground plane under the lowest point when
    /// no part is fixed, computes candidate directions and the contact graph.
    pub fn new(assembly: Assembly, config: &WorldConfig) -> Result<World> {
        assembly.validate()?;
        let diag = assembly.diagonal().max(f32::MIN_POSITIVE);
        let tolerance = config.tolerance.unwrap_or(DEFAULT_RELATIVE_TOLERANCE * diag);
        let contact_distance = config.contact_distance.unwrap_or(DEFAULT_RELATIVE_CONTACT * diag);
        let positive = |v: f32| v.is_finite() && v > 0.0;
        if !positive(tolerance) || !positive(contact_distance) {
            return Err(GeomError::config("tolerance and contact distance must be positive"));
        }
        let mut warnings = assembly.warnings.clone();
        let mut geoms = Vec::with_capacity(assembly.len() + 1);
        // each part's welding, orientation and BVH in parallel (independent), then in part order
        // the first error and the warnings, as a loop over the parts would give them
        let prepared: Vec<_> = assembly
            .parts
            .par_iter()
            .map(|p| {
                // a part whose welded surface keeps no triangle (models built in memory; the
                // loader refuses them in the same words)
                if let Some(reason) = crate::validate::collapsed(p) {
                    return Err(GeomError::Assembly { path: assembly.source.clone(), reason });
                }
                let made = Geom::new(&p.mesh, p.faces.as_deref())
                    .map_err(|e| GeomError::Assembly { path: assembly.source.clone(), reason: format!("part '{}': {e}", p.name) })?;
                Ok((made, PartShape::classify(p, config.exact_boxes)))
            })
            .collect();
        for (p, made) in assembly.parts.iter().zip(prepared) {
            let ((mut g, t), (shape, warning)) = made?;
            warnings.extend(warning);
            g.boxes = shape.boxes();
            if !t.is_closed_manifold() {
                warnings.push(format!(
                    "part '{}': mesh is not closed and manifold ({} open, {} non-manifold, {} misoriented edges); its removal tests may be conservative",
                    p.name, t.boundary_edges, t.non_manifold_edges, t.misoriented_edges
                ));
            }
            geoms.push(g);
        }
        let n = assembly.len();
        let mut fixed = PartSet::from_indices(n + 1, assembly.parts.iter().enumerate().filter(|(_, p)| p.fixed).map(|(i, _)| i));
        let ground = if fixed.is_empty() {
            let bb = assembly.aabb().expect("validated assembly has vertices");
            let (mut g, _) = Geom::new(&ground_box(&bb, assembly.up.vector(), diag), None)?;
            g.boxes = config.exact_boxes.then(|| vec![g.aabb]);
            geoms.push(g);
            fixed.insert(n);
            Some(n)
        } else {
            None
        };
        let directions = candidate_directions(&assembly, config);
        let rows = (0..n).map(|_| OnceLock::new()).collect();
        let mut world = World {
            assembly,
            geoms,
            ground,
            tolerance,
            contact_distance,
            directions,
            contacts: Vec::new(),
            overlaps: BTreeMap::new(),
            ignored: BTreeSet::new(),
            strict: BTreeSet::new(),
            strict_samples: BTreeMap::new(),
            notes: Vec::new(),
            policy: config.overlaps,
            threads: BTreeMap::new(),
            fits: BTreeMap::new(),
            fit_samples: BTreeMap::new(),
            roles: vec![crate::fits::Role::Other; n],
            bearings: Vec::new(),
            fixed,
            rows,
            warnings,
            config: WorldConfig { tolerance: Some(tolerance), contact_distance: Some(contact_distance), ..config.clone() },
        };
        let regions = world.measure_contacts(config.max_overlap_fraction, config.overlaps)?;
        if config.fasteners {
            // before the fits: a bearing's rings are no nuts
            world.bearings = world.find_bearings();
            world.find_fits();
            world.find_threads();
        }
        // after the fits: a pair with a fit is one
        world.classify_overlaps(regions);
        let fused = world.fused_warnings();
        world.warnings.extend(fused);
        world.prepare_pair_shapes();
        Ok(world)
    }

    /// This world under the lenient overlap policy ([`OverlapPolicy::Lenient`]): the same
    /// geometry, directions, contacts, threads and measured overlaps (shared, not measured
    /// again), only the tests of overlapping pairs differ — a pair some shrinking separates is
    /// tested with one part shrunk, a gross pair ignores their collisions. The same as
    /// [`World::new`] with that policy, at the cost of a copy (blocking rows are computed anew).
    pub fn lenient(&self) -> World {
        let notes = self
            .notes
            .iter()
            .map(|n| OverlapNote { handling: if n.gross { OverlapHandling::Ignored } else { OverlapHandling::Shrunk }, ..n.clone() })
            .collect();
        World {
            assembly: self.assembly.clone(),
            geoms: self.geoms.iter().map(Geom::share).collect(),
            ground: self.ground,
            tolerance: self.tolerance,
            contact_distance: self.contact_distance,
            directions: self.directions.clone(),
            contacts: self.contacts.clone(),
            overlaps: self.overlaps.clone(),
            // gross pairs ignore each other under both policies (strict tests them by its rule)
            ignored: self.notes.iter().filter(|n| n.gross).flat_map(|n| [n.parts, (n.parts.1, n.parts.0)]).collect(),
            strict: BTreeSet::new(),
            strict_samples: BTreeMap::new(),
            notes,
            policy: OverlapPolicy::Lenient,
            threads: self.threads.clone(),
            fits: self.fits.clone(),
            fit_samples: self.fit_samples.keys().map(|&k| (k, OnceLock::new())).collect(),
            roles: self.roles.clone(),
            bearings: self.bearings.clone(),
            fixed: self.fixed.clone(),
            rows: (0..self.num_parts()).map(|_| OnceLock::new()).collect(),
            warnings: self.warnings.clone(),
            config: WorldConfig { overlaps: OverlapPolicy::Lenient, ..self.config.clone() },
        }
    }

    /// Finds contacts (parts within the contact distance) and input overlaps between parts.
    /// Returns the overlap regions it measured (gross mesh pairs), for the classification.
    fn measure_contacts(&mut self, max_overlap_fraction: f32, policy: OverlapPolicy) -> Result<Regions> {
        let count = self.geoms.len();
        let pairs: Vec<(usize, usize)> = (0..count)
            .flat_map(|i| ((i + 1)..count).map(move |j| (i, j)))
            .filter(|&(i, j)| {
                let m = self.contact_distance;
                let a = &self.geoms[i].aabb;
                let b = &self.geoms[j].aabb;
                (0..3).all(|k| a.mins[k] <= b.maxs[k] + m && b.mins[k] <= a.maxs[k] + m)
            })
            .collect();
        // every part a mesh pair measures is shrunk by the tolerance first (each pair's test
        // starts there, and the removal tests use it): once per part, in parallel, instead of
        // inside the pairs, where pairs sharing a part would wait on its cache
        let meshed: BTreeSet<usize> = pairs
            .iter()
            .filter(|&&(i, j)| self.geoms[i].boxes.is_none() || self.geoms[j].boxes.is_none())
            .flat_map(|&(i, j)| [i, j])
            .filter(|&k| !self.geoms[k].eroded_cached(self.tolerance))
            .collect();
        meshed.into_iter().collect::<Vec<_>>().par_iter().for_each(|&k| {
            self.geoms[k].eroded(self.tolerance);
        });
        let limit_of = |k: usize| max_overlap_fraction * (self.geoms[k].aabb.maxs - self.geoms[k].aabb.mins).min_element();
        // (pair, touching, extra erosions, a gross pair's depth: exact on boxes, else measured
        // in its overlap region)
        type Found = (usize, usize, bool, Option<f32>, Option<f32>, Option<f32>, Option<overlap::OverlapRegion>);
        let found: Vec<Found> = pairs
            .par_iter()
            .map(|&(i, j)| {
                if let (Some(bi), Some(bj)) = (&self.geoms[i].boxes, &self.geoms[j].boxes) {
                    // exact: how deep the boxes overlap, and how close they come
                    let pairs = || bi.iter().flat_map(|a| bj.iter().map(move |b| (a, b)));
                    let depth = pairs().map(|(a, b)| boxes::overlap_depth(a, b)).fold(f32::NEG_INFINITY, f32::max);
                    let gap = pairs().map(|(a, b)| boxes::box_distance(a, b, Vec3::ONE)).fold(f32::INFINITY, f32::min);
                    let extra = (depth - self.tolerance).max(0.0);
                    let within = |k: usize| (extra <= limit_of(k)).then_some(extra);
                    return (i, j, gap <= self.contact_distance, within(i), within(j), Some(depth), None);
                }
                let (a, b) = (&*self.geoms[i].mesh, &*self.geoms[j].mesh);
                let id = Pose::IDENTITY;
                // parry's mesh-mesh closest points can miss an overlap: measure every candidate
                let (e_ij, e_ji) = (self.extra_erosion(i, j, limit_of(i)), self.extra_erosion(j, i, limit_of(j)));
                let overlapping = e_ij != Some(0.0) || e_ji != Some(0.0);
                let touching =
                    overlapping || !matches!(query::closest_points(&id, a, &id, b, self.contact_distance), Ok(ClosestPoints::Disjoint));
                // no shrinking separates them: how deep they overlap is measured where they do
                let region = (e_ij.is_none() && e_ji.is_none()).then(|| overlap::overlap_region(a, b, overlap::REGION_SAMPLES));
                let measured = region.as_ref().and_then(|r| r.depth());
                (i, j, touching, e_ij, e_ji, measured, region)
            })
            .collect();
        self.contacts = vec![PartSet::empty(count); count];
        let units = self.assembly.units.clone();
        let len = |m: f32| format!("{} {}", significant(units.from_metres(m as f64), 3), units.name);
        let mut regions = Regions::new();
        for (i, j, touching, e_ij, e_ji, measured, region) in found {
            if touching {
                self.contacts[i].insert(j);
                self.contacts[j].insert(i);
            }
            let (a, b) = (self.name(i).to_string(), self.name(j).to_string());
            // the pair's tests shrink whichever part separates with the least shrinking: a screw
            // through a thin plate's tapped hole is shrunk, not the plate
            let eroder = match (e_ij, e_ji) {
                (Some(x), Some(y)) if x <= y => Some((i, x)),
                (_, Some(y)) => Some((j, y)),
                (Some(x), None) => Some((i, x)),
                (None, None) => None,
            };
            let limit = limit_of(i).max(limit_of(j));
            let (depth, gross, bound) = match eroder {
                _ if e_ij == Some(0.0) && e_ji == Some(0.0) => continue,
                Some((k, 0.0)) => {
                    // only the other part, shrunk by the tolerance, still crosses: shrink this one
                    self.overlaps.insert((i, j), (k, 0.0));
                    continue;
                }
                Some((k, extra)) => {
                    self.overlaps.insert((i, j), (k, extra));
                    (self.tolerance + extra, false, false)
                }
                // the erosion bound overstates thin-walled and detailed parts (a panel 2 mm into
                // another is no shallower for being large): the overlap region says how deep
                None => match measured.filter(|d| d.is_finite() && *d > 0.0) {
                    Some(d) => (d.max(self.tolerance), true, false),
                    None => (self.tolerance + limit, true, true),
                },
            };
            let kind = self.overlap_kind(i, j);
            // coincident parts are as deep as they are thick, which no sample measures
            let (depth, bound) = if gross && kind == OverlapKind::Coincident { (self.tolerance + limit, true) } else { (depth, bound) };
            if let Some(r) = region {
                regions.insert((i, j), r);
            }
            let what = match kind {
                OverlapKind::Crossing => "overlap".to_string(),
                OverlapKind::Nested { inner } => format!("overlap ('{}' lies inside the other)", self.name(inner)),
                OverlapKind::Coincident => "overlap (they occupy the same space)".to_string(),
            };
            let measured = if bound {
                format!(
                    "by more than {} (shrinking either by {:.0}% of its thickness does not separate them)",
                    len(depth),
                    max_overlap_fraction * 100.0
                )
            } else if gross {
                format!(
                    "by about {} (measured where they overlap; shrinking either by {:.0}% of its thickness does not separate them)",
                    len(depth),
                    max_overlap_fraction * 100.0
                )
            } else {
                format!("by about {}", len(depth))
            };
            let handling = match (policy, gross) {
                (OverlapPolicy::Error, true) => {
                    return Err(GeomError::GrossOverlap {
                        path: self.assembly.source.clone(),
                        reason: format!(
                            "parts '{a}' and '{b}' {what} far beyond the tolerance ({}): {measured}; fix the model, raise the tolerance, or plan with the overlaps policy strict or lenient",
                            len(self.tolerance)
                        ),
                    });
                }
                (OverlapPolicy::Strict, _) => {
                    self.strict.insert((i, j));
                    self.strict.insert((j, i));
                    if gross {
                        // no shrunk sweep guards this pair: its samples alone must see a part
                        // cut sideways through the other
                        self.strict_samples.insert((i, j), OnceLock::new());
                        self.strict_samples.insert((j, i), OnceLock::new());
                        self.ignored.insert((i, j));
                        self.ignored.insert((j, i));
                    }
                    OverlapHandling::Strict
                }
                (_, false) => OverlapHandling::Shrunk,
                (OverlapPolicy::Lenient, true) => {
                    self.ignored.insert((i, j));
                    self.ignored.insert((j, i));
                    OverlapHandling::Ignored
                }
            };
            let consequence = match handling {
                OverlapHandling::Strict => "they may separate only along motions that enter no new material of each other".to_string(),
                OverlapHandling::Ignored => "their collisions with each other are ignored".to_string(),
                OverlapHandling::Shrunk => format!("their mutual tests shrink '{}' by that much", self.name(self.pair_erosion(i, j).0)),
            };
            self.warnings
                .push(format!("parts '{a}' and '{b}' {what} in the input {measured} (tolerance {}); {consequence}", len(self.tolerance)));
            // classified with the fits ([`World::classify_overlaps`])
            let class = OverlapClass::Interpenetration;
            self.notes.push(OverlapNote { parts: (i, j), kind, depth, gross, bound, handling, class, normal: None });
        }
        Ok(regions)
    }

    /// Builds, in parallel, the shrunk meshes the removal tests will ask for: each part by the
    /// tolerance, and the part an overlapping pair's tests shrink by the pair's erosion. Built
    /// here once, the first removal test of a part is the sweeps alone (one erosion of a 25k
    /// triangle mesh costs several times a whole blocking row).
    fn prepare_pair_shapes(&self) {
        let mut wanted: BTreeSet<(usize, u32)> = BTreeSet::new();
        for (i, g) in self.geoms.iter().enumerate().take(self.num_parts()) {
            if g.boxes.is_none() {
                wanted.insert((i, self.tolerance.to_bits()));
            }
        }
        for &(k, extra) in self.overlaps.values() {
            wanted.insert((k, (self.tolerance + extra).to_bits()));
        }
        let wanted: Vec<(usize, u32)> = wanted.into_iter().filter(|&(k, a)| !self.geoms[k].eroded_cached(f32::from_bits(a))).collect();
        wanted.par_iter().for_each(|&(k, amount)| {
            self.geoms[k].eroded(f32::from_bits(amount));
        });
    }

    /// How overlapping parts `i` and `j` lie in each other: coincident (bounds equal to within
    /// twice the tolerance), nested (one's bounds inside the other's, its surface clear of the
    /// other's when shrunk by the tolerance, and a vertex inside the other's closed surface), or
    /// crossing.
    fn overlap_kind(&self, i: usize, j: usize) -> OverlapKind {
        let (a, b) = (&self.geoms[i], &self.geoms[j]);
        let slack = 2.0 * self.tolerance;
        if (a.aabb.mins - b.aabb.mins).abs().max_element() <= slack && (a.aabb.maxs - b.aabb.maxs).abs().max_element() <= slack {
            return OverlapKind::Coincident;
        }
        for (inner, x, y) in [(i, a, b), (j, b, a)] {
            if y.closed
                && nests(&x.aabb, &y.aabb)
                && contains_point(&y.mesh, x.mesh.vertices()[0])
                && !sweep::meshes_cross(&x.eroded(self.tolerance), &y.mesh)
            {
                return OverlapKind::Nested { inner };
            }
        }
        OverlapKind::Crossing
    }

    /// The least extra erosion of part `p` (beyond the tolerance, to within a sixteenth) after
    /// which it no longer crosses `q`'s surface: 0 when they merely touch, `None` when even
    /// `limit` does not separate them.
    fn extra_erosion(&self, p: usize, q: usize, limit: f32) -> Option<f32> {
        let (a, b) = (&self.geoms[p], &self.geoms[q]);
        let tol = self.tolerance;
        // the plain tolerance first, from the cache (most pairs merely touch)
        a.eroded(tol);
        depth_search(tol, limit, |extra| !a.eroded_hits(tol + extra, b))
    }

    /// The assembly this world was built from.
    pub fn assembly(&self) -> &Assembly {
        &self.assembly
    }

    /// Number of real parts (the ground, when present, has index `num_parts()`).
    pub fn num_parts(&self) -> usize {
        self.assembly.len()
    }

    /// The index of the virtual ground part, when no part of the model is fixed.
    pub fn ground(&self) -> Option<usize> {
        self.ground
    }

    /// The name of part `i` (`ground` for the virtual ground).
    pub fn name(&self, i: usize) -> &str {
        self.assembly.parts.get(i).map(|p| p.name.as_str()).unwrap_or("ground")
    }

    /// Fixed parts, the ground included.
    pub fn fixed(&self) -> &PartSet {
        &self.fixed
    }

    /// The contact tolerance in metres.
    pub fn tolerance(&self) -> f32 {
        self.tolerance
    }

    /// The contact distance of the stability graph, in metres.
    pub fn contact_distance(&self) -> f32 {
        self.contact_distance
    }

    /// Candidate straight-line removal directions (unit vectors).
    pub fn directions(&self) -> &[Vec3] {
        &self.directions
    }

    /// Parts in contact with part `i` (ground included).
    pub fn contacts(&self, i: usize) -> &PartSet {
        &self.contacts[i]
    }

    /// Pairs (low index, high index) that overlap in the input, with the part their tests shrink
    /// and its extra erosion in metres.
    pub fn overlaps(&self) -> &BTreeMap<(usize, usize), (usize, f32)> {
        &self.overlaps
    }

    /// Every pair that overlaps in the input beyond the tolerance: how they lie, the measured
    /// depth and how their tests treat them (one entry per pair, in pair order).
    pub fn overlap_notes(&self) -> &[OverlapNote] {
        &self.notes
    }

    /// The settings this world was built with (tolerance and contact distance in metres).
    pub fn config(&self) -> &WorldConfig {
        &self.config
    }

    /// The overlap policy this world was built with.
    pub fn overlap_policy(&self) -> OverlapPolicy {
        self.policy
    }

    /// Whether the pair (`p`, `q`) is tested by the strict overlap rule (it overlaps in the input
    /// and the policy is strict).
    pub fn is_strict_pair(&self, p: usize, q: usize) -> bool {
        self.strict.contains(&(p, q))
    }

    /// Part `p`'s surface samples moved inward by the tolerance (made once).
    fn strict_samples(&self, p: usize) -> &[Vec3] {
        self.geoms[p].samples.get_or_init(|| overlap::inward_samples(&self.geoms[p].mesh, STRICT_SAMPLES, self.tolerance))
    }

    /// The strict overlap rule for a pair that overlaps in the input (see [`crate::overlap`]):
    /// how far `p`, displaced by `from`, travels along unit `dir` (up to `t_max`) before a surface
    /// sample of either part (moved inward by the tolerance) enters the other's material; `None`
    /// when none does, and always `None` for pairs the rule does not apply to. With
    /// `first_only`, any entry answers (not the earliest).
    pub fn strict_entry(&self, p: usize, q: usize, from: Vec3, dir: Vec3, t_max: f32, first_only: bool) -> Option<f32> {
        if !self.is_strict_pair(p, q) {
            return None;
        }
        let (sp, sq) = (self.strict_pair_samples(p, q), self.strict_pair_samples(q, p));
        overlap::strict_entry(sp, &self.geoms[p].mesh, sq, &self.geoms[q].mesh, from, dir, t_max, first_only, self.tolerance)
    }

    /// Part `p`'s samples for its strict test with `q`: its whole-surface samples (about
    /// [`STRICT_SAMPLES`], spread over the whole part: centimetres apart on a large panel, where
    /// a dowel drawn into it could slide sideways between them), and, when no shrinking
    /// separates the pair (so no shrunk sweep guards it), its surface near `q` sampled densely
    /// ([`overlap::local_inward_samples`] in the pair's common box).
    fn strict_pair_samples(&self, p: usize, q: usize) -> &[Vec3] {
        let Some(cell) = self.strict_samples.get(&(p, q)) else { return self.strict_samples(p) };
        cell.get_or_init(|| {
            let mut all = self.strict_samples(p).to_vec();
            let (a, b) = (self.geoms[p].mesh.local_aabb(), self.geoms[q].mesh.local_aabb());
            all.extend(overlap::local_inward_samples(&self.geoms[p].mesh, &a, &b, self.tolerance));
            all
        })
    }

    /// Part `p`'s axis of near rotational symmetry (a bolt, screw, nut, washer), if any.
    pub fn symmetry_axis(&self, p: usize) -> Option<SymmetryAxis> {
        let g = self.geoms.get(p)?;
        *g.axis.get_or_init(|| if g.closed && p < self.num_parts() { fastener::symmetry_axis(&g.mesh) } else { None })
    }

    /// Finds every threaded contact (ordered pairs of parts in contact, the first with a
    /// symmetry axis; see [`crate::fastener`]) and adds each thread's axis, both ways, to the
    /// candidate directions.
    fn find_threads(&mut self) {
        let n = self.num_parts();
        let pairs: Vec<(usize, usize)> =
            (0..n).flat_map(|p| self.contacts[p].iter().filter(move |&q| q < n && q != p).map(move |q| (p, q))).collect();
        // each candidate fastener's axis once, in parallel (pairs sharing a part would wait on
        // its cache one after the other)
        let movers: BTreeSet<usize> = pairs.iter().map(|&(p, _)| p).filter(|&p| self.geoms[p].boxes.is_none()).collect();
        movers.into_iter().collect::<Vec<_>>().par_iter().for_each(|&p| {
            self.symmetry_axis(p);
        });
        let found: Vec<((usize, usize), Thread)> = pairs
            .par_iter()
            .filter_map(|&(p, q)| {
                // a union of boxes (voxels, profiles) has no 60° symmetry
                if self.geoms[p].boxes.is_some() {
                    return None;
                }
                let axis = self.symmetry_axis(p)?;
                let t = fastener::threaded_contact(&axis, &self.geoms[p].mesh, &self.geoms[q].mesh, 4.0 * self.tolerance)?;
                Some(((p, q), t))
            })
            .collect();
        // a bolt in a nut: both are threaded in each other, and the zone covers both threads
        // (the nut's roots and the bolt's crests), whichever moves
        let mut found = found;
        let radii: BTreeMap<(usize, usize), f32> = found.iter().map(|&(k, t)| (k, t.radius)).collect();
        for ((p, q), t) in found.iter_mut() {
            if let Some(&r) = radii.get(&(*q, *p)) {
                t.radius = t.radius.max(r);
            }
        }
        for (_, t) in &found {
            for d in [t.axis.direction, -t.axis.direction] {
                if !self.directions.iter().any(|e| e.dot(d) > SCREW_ALIGNED) {
                    self.directions.push(d);
                }
            }
        }
        self.threads = found.into_iter().collect();
    }

    /// The threaded contact of `p` with `q` (see [`crate::fastener`]), found with the world:
    /// `p` and `q` touch or overlap, `p` has a symmetry axis, its side faces touching `q` are
    /// mostly thread flanks, and `q` is symmetric about the axis near it.
    pub fn thread(&self, p: usize, q: usize) -> Option<Thread> {
        self.threads.get(&(p, q)).copied()
    }

    /// Every threaded contact (ordered pairs).
    pub fn threads(&self) -> &BTreeMap<(usize, usize), Thread> {
        &self.threads
    }

    /// The pair test of a threaded pair along its axis: the strict sample rule outside the
    /// thread zone (samples of either part closer to the axis than the zone's radius are
    /// exempt: the thread is invariant under the screw motion).
    fn screw_blocks(&self, p: usize, q: usize, thread: &Thread, dir: Vec3, t_max: f32) -> bool {
        let outside = |s: &[Vec3]| -> Vec<Vec3> { s.iter().copied().filter(|&x| thread.axis.radial(x) > thread.radius).collect() };
        let (sp, sq) = (outside(self.strict_samples(p)), outside(self.strict_samples(q)));
        overlap::strict_entry(&sp, &self.geoms[p].mesh, &sq, &self.geoms[q].mesh, Vec3::ZERO, dir, t_max, true, self.tolerance).is_some()
    }

    /// Whether collisions between `p` and `q` are ignored by the shrunk tests (a pair no
    /// shrinking separates, under the lenient policy; under the strict one such a pair is tested
    /// by the strict rule alone).
    pub fn ignores(&self, p: usize, q: usize) -> bool {
        self.ignored.contains(&(p, q))
    }

    /// Warnings found while preparing (open meshes, overlaps), one line each.
    pub fn warnings(&self) -> &[String] {
        &self.warnings
    }

    /// Whether part `i`'s mesh is closed and manifold.
    pub fn is_closed(&self, i: usize) -> bool {
        self.geoms[i].closed
    }

    /// The bounding box of part `i` (ground included) in its assembled pose.
    pub fn aabb(&self, i: usize) -> &Aabb {
        &self.geoms[i].aabb
    }

    /// The collision mesh of part `i` in its assembled pose.
    pub fn mesh(&self, i: usize) -> &TriMesh {
        &self.geoms[i].mesh
    }

    /// The exact boxes of part `i` in its assembled pose when it is a known union of
    /// axis-aligned boxes that describes its mesh (see [`crate::boxes`]; `None` otherwise, and
    /// always with `WorldConfig::exact_boxes` off).
    pub fn boxes(&self, i: usize) -> Option<&[Aabb]> {
        self.geoms[i].boxes.as_deref()
    }

    /// Which part the tests of the pair (`p`, `q`) shrink, and by how much (metres): normally the
    /// moving part `p` by the tolerance; for parts overlapping in the input, the one that
    /// separates with the least shrinking, by the tolerance plus that.
    pub fn pair_erosion(&self, p: usize, q: usize) -> (usize, f32) {
        match self.overlaps.get(&(p.min(q), p.max(q))) {
            Some(&(k, extra)) => (k, self.tolerance + extra),
            None => (p, self.tolerance),
        }
    }

    /// Part `p` shrunk by `amount` (cached).
    pub fn eroded(&self, p: usize, amount: f32) -> Arc<TriMesh> {
        self.geoms[p].eroded(amount)
    }

    /// The shapes of `p` and `q` for their mutual tests: one of them shrunk (see
    /// [`World::pair_erosion`]), both in their assembled pose.
    pub fn pair_shapes(&self, p: usize, q: usize) -> (Arc<TriMesh>, Arc<TriMesh>) {
        let (k, amount) = self.pair_erosion(p, q);
        if k == p {
            (self.eroded(p, amount), self.geoms[q].mesh.clone())
        } else {
            (self.geoms[p].mesh.clone(), self.eroded(q, amount))
        }
    }

    /// The state plus the fixed parts that are always present (ground included).
    pub fn with_fixed(&self, state: &PartSet) -> PartSet {
        let mut s = state.clone();
        s.union_with(&self.fixed);
        s
    }

    /// Whether `q` blocks `p` moving along `dir` (unit) from the assembled pose, to infinity.
    pub fn pair_blocks(&self, p: usize, q: usize, dir: Vec3) -> bool {
        let Some((_, t1)) = sweep_overlap(&self.geoms[p].aabb, dir, &self.geoms[q].aabb) else {
            return false;
        };
        if let Some(thread) = self.thread(p, q).filter(|t| t.axis.direction.dot(dir).abs() > SCREW_ALIGNED) {
            return self.screw_blocks(p, q, &thread, dir, t1);
        }
        if self.thread(q, p).is_some_and(|t| t.axis.direction.dot(dir).abs() > SCREW_ALIGNED) {
            // a body a fastener is screwed into (a tapped hole drawn smooth at the thread's major
            // diameter, as CAD draws them) would have to turn about the fastener to leave along
            // its axis: the fastener leaves first
            return true;
        }
        let fits = self.fits_along(p, q, dir);
        if !fits.is_empty() {
            // along a fit's axis the fit is carried (pressed out, unscrewed, slid), with the
            // fit's band exempt from the strict rule and nothing else entering new material
            if self.fit_blocks(p, q, &fits, dir, t1) {
                return true;
            }
            if self.ignores(p, q) {
                return false;
            }
            // the samples may miss a collision away from the fits (a collar, a flange): the
            // pair is swept exactly, one part shrunk past the deepest fit's band
            let band = fits.iter().map(|f| f.band.1 - f.band.0).fold(0.0f32, f32::max);
            let (k, amount) = self.pair_erosion(p, q);
            let amount = amount.max(band + self.tolerance);
            let (moving, fixed) = if k == p {
                (self.eroded(p, amount), self.geoms[q].mesh.clone())
            } else {
                (self.geoms[p].mesh.clone(), self.eroded(q, amount))
            };
            return sweep::sweep_hits(&moving, dir, &fixed, t1);
        }
        if self.is_strict_pair(p, q) && self.strict_entry(p, q, Vec3::ZERO, dir, t1, true).is_some() {
            return true;
        }
        if self.ignores(p, q) {
            return false;
        }
        if let (Some(bp), Some(bq)) = (&self.geoms[p].boxes, &self.geoms[q].boxes) {
            // exact on the boxes, each of `p`'s shrunk by the pair's erosion
            let (_, amount) = self.pair_erosion(p, q);
            return bp.iter().any(|a| bq.iter().any(|b| boxes::first_overlap(a, dir, b, amount).is_some()));
        }
        // exact triangle sweeps (parry's mesh cast calls some slides at tolerance-sized gaps hits)
        let (moving, fixed) = self.pair_shapes(p, q);
        sweep::sweep_hits(&moving, dir, &fixed, t1)
    }

    /// For each candidate direction, every part (ground included) that blocks `p` along it.
    /// Computed once per part, in parallel, then cached.
    pub fn blocking_row(&self, p: usize) -> &[PartSet] {
        self.rows[p].get_or_init(|| {
            let count = self.geoms.len();
            let jobs: Vec<(usize, usize)> =
                (0..self.directions.len()).flat_map(|k| (0..count).filter(move |&q| q != p).map(move |q| (k, q))).collect();
            let blocked: Vec<bool> = jobs.par_iter().map(|&(k, q)| self.pair_blocks(p, q, self.directions[k])).collect();
            let mut row = vec![PartSet::empty(count); self.directions.len()];
            for (&(k, q), b) in jobs.iter().zip(blocked) {
                if b {
                    row[k].insert(q);
                }
            }
            row
        })
    }

    /// How far `p` must travel along `dir` for its bounds to clear the bounds of the other
    /// present real parts, plus the contact distance. With no other part left, it clears its own
    /// starting bounds (so the last part is lifted by its size, not by nothing).
    pub fn clearance(&self, p: usize, state: &PartSet, dir: Vec3) -> f32 {
        self.clearance_of(&self.geoms[p].aabb, state.iter().filter(|&q| q != p), dir)
    }

    /// [`World::clearance`] of a group of parts moving together: its bounds clear the bounds of
    /// the other present real parts.
    pub fn group_clearance(&self, group: &PartSet, state: &PartSet, dir: Vec3) -> f32 {
        let bounds = aabb_of(group.iter().flat_map(|q| [self.geoms[q].aabb.mins, self.geoms[q].aabb.maxs])).expect("a group has parts");
        self.clearance_of(&bounds, state.iter().filter(|&q| !group.contains(q)), dir)
    }

    fn clearance_of(&self, a: &Aabb, others: impl Iterator<Item = usize>, dir: Vec3) -> f32 {
        let others = aabb_of(others.filter(|&q| q < self.num_parts()).flat_map(|q| [self.geoms[q].aabb.mins, self.geoms[q].aabb.maxs]));
        clearance_past(a, others, dir, self.contact_distance)
    }
}

/// How far box `a` travels along unit `dir` until it clears the bounds `others` (its own
/// starting bounds when `None`), plus `contact_distance`: the travel of a straight removal,
/// which the collision world and the voxel checker ([`crate::voxel`]) share.
pub(crate) fn clearance_past(a: &Aabb, others: Option<Aabb>, dir: Vec3, contact_distance: f32) -> f32 {
    let others = others.unwrap_or(*a);
    let t = (0..3)
        .filter(|&i| dir[i].abs() > 1e-6)
        .map(|i| if dir[i] > 0.0 { (others.maxs[i] - a.mins[i]) / dir[i] } else { (a.maxs[i] - others.mins[i]) / -dir[i] })
        .fold(f32::INFINITY, f32::min)
        .max(0.0);
    t + contact_distance
}

/// Default contact tolerance ([`WorldConfig::tolerance`], [`crate::distmap::MapConfig`]),
/// relative to the assembly's diagonal.
pub const DEFAULT_RELATIVE_TOLERANCE: f32 = 1e-4;
/// Default contact distance of the contact graph ([`WorldConfig::contact_distance`], the maps'),
/// relative to the diagonal.
pub const DEFAULT_RELATIVE_CONTACT: f32 = 1e-3;

/// About how many surface samples per part the strict overlap rule uses (plus every vertex).
const STRICT_SAMPLES: usize = 4000;
/// A direction is along a thread's axis when their cosine exceeds this (0.8°).
const SCREW_ALIGNED: f32 = 0.9999;

/// `x` rounded to `digits` significant digits, without an exponent (0.000123, 12.3, 1230).
fn significant(x: f64, digits: i32) -> String {
    if x == 0.0 || !x.is_finite() {
        return format!("{x}");
    }
    let decimals = (digits - 1 - x.abs().log10().floor() as i32).max(0) as usize;
    format!("{x:.decimals$}")
}

/// A slab under the model whose top face lies at the model's lowest point along `up`.
pub(crate) fn ground_box(bb: &Aabb, up: Vec3, diag: f32) -> Mesh {
    let centre = (bb.mins + bb.maxs) * 0.5;
    let half = Vec3::splat(1.5 * diag);
    let (mut mins, mut maxs) = (centre - half, centre + half);
    let axis = up.abs().max_position();
    if up[axis] > 0.0 {
        maxs[axis] = bb.mins[axis];
        mins[axis] = bb.mins[axis] - 0.5 * diag;
    } else {
        mins[axis] = bb.maxs[axis];
        maxs[axis] = bb.maxs[axis] + 0.5 * diag;
    }
    Mesh::cuboid(mins, maxs)
}

/// The least extra erosion (within a factor 2^-4 of the first doubling step) at which `clear`
/// holds: 0 when it holds at once, else doubling from `tol` up to `limit` (`None` past it), then
/// four bisections. `clear` must be monotone in the extra erosion.
fn depth_search(tol: f32, limit: f32, clear: impl Fn(f32) -> bool) -> Option<f32> {
    if clear(0.0) {
        return Some(0.0);
    }
    let mut hi = tol;
    while !clear(hi) {
        if hi >= limit {
            return None;
        }
        hi = (hi * 2.0).min(limit);
    }
    let mut lo = hi / 2.0;
    for _ in 0..4 {
        let mid = 0.5 * (lo + hi);
        if clear(mid) {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    Some(hi)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::erode::eroded_mesh;
    use crate::fixtures::{assemble, bolt_and_nut, dowel_in_two_boards, part, pressed_peg};
    use crate::math::{Axis, Rot};

    /// Whether `a` shrunk by `amount` still overlaps `b`, as `Geom::eroded_hits` decided it
    /// before erosion near the region: the whole mesh eroded, as a triangle soup.
    fn hits_by_whole_erosion(a: &Geom, amount: f32, b: &Geom) -> bool {
        let (v, t) = eroded_mesh(a.mesh.vertices(), a.mesh.indices(), amount);
        sweep::soup_crosses(&v, &t, &b.mesh)
            || (b.closed && nests(&a.aabb, &b.aabb) && contains_point(&b.mesh, v[0]))
            || (a.closed && nests(&b.aabb, &a.aabb) && contains_point(&a.erode(amount), b.mesh.vertices()[0]))
    }

    /// `World::extra_erosion`'s search over `hits_by_whole_erosion` (the erosion of the whole part).
    fn depth_by_whole_erosion(w: &World, p: usize, q: usize, limit: f32) -> Option<f32> {
        let (a, b, tol) = (&w.geoms[p], &w.geoms[q], w.tolerance);
        depth_search(tol, limit, |extra| !hits_by_whole_erosion(a, tol + extra, b))
    }

    /// The trial erosions of an overlapping pair shrink only the triangles near
    /// the other part; every pair's measured depth (shallow, deep, gross, nested, threaded) is
    /// the one the whole erosions give, so the warnings and explanations print the same.
    #[test]
    fn overlap_depths_measured_near_the_other_part_are_the_whole_erosions() {
        // a stool's seat and two legs, tessellated (2-unit cells), turned off the axes (no exact
        // boxes), the legs pushed `depth` and a fifth of it into the seat; and a tessellated cube
        // nested in a larger one
        let slab = |n: [i32; 3], origin: [f32; 3]| {
            let cells: Vec<[i32; 3]> = (0..n[0]).flat_map(|x| (0..n[1]).flat_map(move |y| (0..n[2]).map(move |z| [x, y, z]))).collect();
            let mut m = Mesh::from_voxels(&cells, Vec3::splat(2.0), Vec3::from(origin));
            m.vertices.iter_mut().for_each(|v| *v = Rot::from_rotation_z(0.35) * *v);
            part("panel", m, false)
        };
        let stool = |depth: f32| {
            let parts = vec![
                slab([20, 20, 1], [0.0, 0.0, 40.0]),
                slab([1, 20, 20], [0.0, 0.0, depth]),
                slab([1, 20, 20], [38.0, 0.0, 0.2 * depth]),
            ];
            assemble("stool", parts, Axis::Z)
        };
        let nested = assemble("nested", vec![slab([6, 6, 6], [0.0, 0.0, 0.0]), slab([2, 2, 2], [4.0, 4.0, 4.0])], Axis::Z);
        let mut pairs = 0;
        for assembly in [stool(0.3), stool(1.5), nested, pressed_peg(), dowel_in_two_boards(), bolt_and_nut(0.0001)] {
            let w = World::new(assembly, &WorldConfig { exact_boxes: false, ..WorldConfig::default() }).unwrap();
            assert!(!w.overlap_notes().is_empty(), "{}: the fixture overlaps", w.assembly().source.display());
            for i in 0..w.num_parts() {
                for j in w.contacts(i).iter().filter(|&j| j < w.num_parts() && j != i) {
                    let limit = 0.4 * (w.geoms[i].aabb.maxs - w.geoms[i].aabb.mins).min_element();
                    let expected = depth_by_whole_erosion(&w, i, j, limit);
                    assert_eq!(w.extra_erosion(i, j, limit), expected, "{}: {} in {}", w.assembly().source.display(), w.name(i), w.name(j));
                    pairs += usize::from(expected != Some(0.0));
                }
            }
        }
        assert!(pairs >= 8, "{pairs} overlapping ordered pairs measured");
    }

    #[test]
    fn lengths_in_messages_keep_three_significant_digits() {
        assert_eq!(significant(0.000123456, 3), "0.000123");
        assert_eq!(significant(0.0021, 3), "0.00210");
        assert_eq!(significant(12.345, 3), "12.3");
        assert_eq!(significant(1234.5, 3), "1234");
        assert_eq!(significant(0.0, 3), "0");
    }
}
