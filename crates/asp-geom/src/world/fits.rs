//! The fits, threads and bearings among the parts in contact ([`crate::fits`],
//! [`crate::fastener`], [`super::bearings`]), a part of the overlaps component: found when the
//! world is built, their axes among the candidate directions, and the answers the pair tests
//! read along an axis (which fits the motion follows, which partner turns).
//!
//! They live with the overlaps because they are what makes an input overlap meant (a pressed
//! pin, a screw in its thread, a ball in its race) and what the strict sample rule exempts.

use super::bearings::Bearing;
use super::contacts::Contacts;
use super::shapes::Shapes;
use crate::assembly::Assembly;
use crate::fastener::{self, Thread};
use crate::fits::{self, Fit, Role};
use crate::math::{Aabb, Vec3};
use crate::overlap::OverlapNote;
use crate::partset::PartSet;
use rayon::prelude::*;
use std::collections::{BTreeMap, BTreeSet};
use std::sync::OnceLock;

/// A direction is a fit's axis when their cosine exceeds this (0.1°): the exact axis joins the
/// candidates unless one lies this close.
pub(super) const AXIS_ALIGNED: f32 = 0.999_998_5;
/// A direction is along a thread's axis when their cosine exceeds this (0.8°).
pub(super) const SCREW_ALIGNED: f32 = 0.9999;
/// The most directions the pairs' planar contacts add to the candidates.
const MAX_CONTACT_DIRECTIONS: usize = 48;

/// Whether the plane through `point` with unit `normal` meets box `b`.
fn plane_meets_box(point: Vec3, normal: Vec3, b: &Aabb) -> bool {
    let c = (b.mins + b.maxs) * 0.5;
    let h = (b.maxs - b.mins) * 0.5;
    (c - point).dot(normal).abs() <= h.dot(normal.abs())
}

/// The fits, threads, bearings and roles of the parts.
pub struct Fits {
    /// Threaded contacts (ordered pairs).
    threads: BTreeMap<(usize, usize), Thread>,
    /// Coaxial fits per pair (low, high).
    fits: BTreeMap<(usize, usize), Vec<Fit>>,
    /// Per ordered pair with a fit that is not a clearance fit: the first part's samples for the
    /// fit test (whole surface and dense near the other), made when first needed.
    pub(super) samples: BTreeMap<(usize, usize), OnceLock<Vec<Vec3>>>,
    /// What each part is (nut, washer, bolt, pin, other), from its shape and name.
    roles: Vec<Role>,
    /// The rolling bearings among the parts ([`Bearing`]).
    bearings: Vec<Bearing>,
}

impl Fits {
    /// None found yet among `parts` parts.
    pub(super) fn new(parts: usize) -> Fits {
        Fits {
            threads: BTreeMap::new(),
            fits: BTreeMap::new(),
            samples: BTreeMap::new(),
            roles: vec![Role::Other; parts],
            bearings: Vec::new(),
        }
    }

    /// A copy with the same findings and fresh sample caches.
    pub(super) fn share(&self) -> Fits {
        Fits {
            threads: self.threads.clone(),
            fits: self.fits.clone(),
            samples: self.samples.keys().map(|&k| (k, OnceLock::new())).collect(),
            roles: self.roles.clone(),
            bearings: self.bearings.clone(),
        }
    }

    /// Finds the bearings, then the fits (a bearing's rings are no nuts), then the threads among
    /// the parts in contact, adding their axes and the pairs' planar contact directions to
    /// `directions`.
    pub(super) fn find(
        &mut self,
        assembly: &Assembly,
        shapes: &Shapes,
        contacts: &Contacts,
        notes: &[OverlapNote],
        directions: &mut Vec<Vec3>,
    ) {
        self.bearings = super::bearings::find_bearings(shapes, contacts);
        self.find_fits(assembly, shapes, contacts, notes, directions);
        self.find_threads(assembly.len(), shapes, contacts, directions);
    }

    /// Finds every fit between parts in contact (touching or overlapping in the input; meshes
    /// only, unions of boxes have no round faces) and adds each fit's axis, both ways, to the
    /// candidate directions.
    fn find_fits(&mut self, assembly: &Assembly, shapes: &Shapes, contacts: &Contacts, notes: &[OverlapNote], directions: &mut Vec<Vec3>) {
        let n = assembly.len();
        let pairs: Vec<(usize, usize)> = (0..n)
            .flat_map(|p| contacts.of(p).iter().filter(move |&q| q < n && q > p).map(move |q| (p, q)))
            .filter(|&(p, q)| shapes.boxes(p).is_none() && shapes.boxes(q).is_none())
            .collect();
        let parts: BTreeSet<usize> = pairs.iter().flat_map(|&(p, q)| [p, q]).collect();
        // each part's surfaces and role once, in parallel
        let roles: Vec<(usize, Role)> = parts
            .into_iter()
            .collect::<Vec<_>>()
            .par_iter()
            .map(|&p| (p, fits::role(&assembly.parts[p].name, shapes.surfaces(p), shapes.mesh(p).vertices())))
            .collect();
        // a bearing's parts are a bought unit, never a fastener (a ring is no nut)
        let in_bearing: BTreeSet<usize> = self.bearings.iter().flat_map(|b| b.parts()).collect();
        for (p, r) in roles {
            self.roles[p] = if in_bearing.contains(&p) { Role::Other } else { r };
        }
        let found: Vec<((usize, usize), Vec<Fit>)> = pairs
            .par_iter()
            .filter_map(|&(p, q)| {
                let f = fits::fits_between(
                    p,
                    shapes.surfaces(p),
                    self.roles[p],
                    q,
                    shapes.surfaces(q),
                    self.roles[q],
                    shapes.tolerance(),
                    contacts.distance(),
                );
                (!f.is_empty()).then_some(((p, q), f))
            })
            .collect();
        add_contact_directions(shapes, contacts, notes, &pairs, directions);
        for (pair, f) in found {
            for fit in &f {
                for d in [fit.axis, -fit.axis] {
                    if !directions.iter().any(|e| e.dot(d) > AXIS_ALIGNED) {
                        directions.push(d);
                    }
                }
                if fit.class != fits::FitClass::Clearance {
                    self.samples.entry((fit.shaft, fit.hole)).or_default();
                    self.samples.entry((fit.hole, fit.shaft)).or_default();
                }
            }
            self.fits.insert(pair, f);
        }
    }

    /// Finds every threaded contact (ordered pairs of parts in contact, the first with a
    /// symmetry axis; see [`crate::fastener`]) and adds each thread's axis, both ways, to the
    /// candidate `directions`.
    fn find_threads(&mut self, n: usize, shapes: &Shapes, contacts: &Contacts, directions: &mut Vec<Vec3>) {
        let pairs: Vec<(usize, usize)> =
            (0..n).flat_map(|p| contacts.of(p).iter().filter(move |&q| q < n && q != p).map(move |q| (p, q))).collect();
        // each candidate fastener's axis once, in parallel (pairs sharing a part would wait on
        // its cache one after the other)
        let movers: BTreeSet<usize> = pairs.iter().map(|&(p, _)| p).filter(|&p| shapes.boxes(p).is_none()).collect();
        movers.into_iter().collect::<Vec<_>>().par_iter().for_each(|&p| {
            shapes.symmetry_axis(p);
        });
        let found: Vec<((usize, usize), Thread)> = pairs
            .par_iter()
            .filter_map(|&(p, q)| {
                // a union of boxes (voxels, profiles) has no 60° symmetry
                if shapes.boxes(p).is_some() {
                    return None;
                }
                let axis = shapes.symmetry_axis(p)?;
                let t = fastener::threaded_contact(&axis, shapes.mesh(p), shapes.mesh(q), 4.0 * shapes.tolerance())?;
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
                if !directions.iter().any(|e| e.dot(d) > SCREW_ALIGNED) {
                    directions.push(d);
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

    /// The fits between `p` and `q` (either order).
    pub fn between(&self, p: usize, q: usize) -> &[Fit] {
        self.fits.get(&(p.min(q), p.max(q))).map_or(&[], Vec::as_slice)
    }

    /// Every pair with fits, (low, high), and its fits.
    pub fn all(&self) -> &BTreeMap<(usize, usize), Vec<Fit>> {
        &self.fits
    }

    /// The rolling bearings among the parts (balls captive between two rings; see
    /// [`Bearing`]), found with the world when fasteners are (`WorldConfig::fasteners`).
    pub fn bearings(&self) -> &[Bearing] {
        &self.bearings
    }

    /// What part `p` is (a nut, a washer, a bolt, a pin; [`Role::Other`] for parts in no mesh
    /// contact).
    pub fn role(&self, p: usize) -> Role {
        self.roles.get(p).copied().unwrap_or(Role::Other)
    }

    /// The fits of `p` and `q` that are not clearance fits and whose axis the motion along unit
    /// `dir` follows.
    pub(super) fn along(&self, p: usize, q: usize, dir: Vec3) -> Vec<&Fit> {
        self.between(p, q).iter().filter(|f| f.class != fits::FitClass::Clearance && f.axis.dot(dir).abs() > AXIS_ALIGNED).collect()
    }

    /// The partner of `p` among `present` real parts (fewer than `n`) along whose fit axis
    /// `direction` runs and which `p` must turn on (a nut on its bolt, a screw in its tapped
    /// hole): its removal there is a `screw` motion about the fit's axis.
    pub(super) fn turned_on(&self, p: usize, n: usize, present: &PartSet, direction: Vec3) -> Option<&Fit> {
        present
            .iter()
            .filter(|&q| q != p && q < n)
            .find_map(|q| self.between(p, q).iter().find(|f| f.turns == Some(p) && f.axis.dot(direction).abs() > AXIS_ALIGNED))
    }
}

/// Adds the directions the pairs' own planar contacts define: each contact plane's normal
/// (a panel lifts off along it, also when the two are sunk a little into each other) and
/// the line two non-parallel contact planes of one part share (a slide along a rail, in a
/// T-slot or a channel), both ways, unless a candidate lies within 0.1°. Model-wide normal clusters
/// average a lift 2° off an axis into the axis; these are the pair's exact ones. At most
/// [`MAX_CONTACT_DIRECTIONS`] are added, the largest contacts first.
fn add_contact_directions(
    shapes: &Shapes,
    contacts: &Contacts,
    notes: &[OverlapNote],
    pairs: &[(usize, usize)],
    directions: &mut Vec<Vec3>,
) {
    let slack = contacts.distance();
    // per pair, its planar contacts (weight, the first part's outward normal)
    type Planar = Vec<(f32, Vec3)>;
    let per_pair: Vec<((usize, usize), Planar)> = pairs
        .par_iter()
        .map(|&(p, q)| {
            let (ap, aq) = (shapes.aabb(p), shapes.aabb(q));
            let depth = notes.iter().find(|n| n.parts == (p, q)).map_or(0.0, |n| n.depth);
            let reach = slack + depth;
            let common = Aabb::new(ap.mins.max(aq.mins) - Vec3::splat(reach), ap.maxs.min(aq.maxs) + Vec3::splat(reach));
            let large = |planes: &[fits::Plane]| {
                let total: f32 = planes.iter().map(|x| x.area).sum();
                planes.iter().filter(|x| x.area >= 0.005 * total).cloned().collect::<Vec<_>>()
            };
            let (pp, pq) = (large(&shapes.surfaces(p).planes), large(&shapes.surfaces(q).planes));
            // opposite planes of the two parts within reach of each other, meeting the
            // pair's common box: a planar contact (or a slab)
            let mut contacts: Vec<(f32, Vec3)> = Vec::new();
            for a in &pp {
                for b in &pq {
                    if a.normal.dot(b.normal) <= -0.9995
                        && (b.point - a.point).dot(a.normal).abs() <= reach
                        && plane_meets_box(a.point, a.normal, &common)
                    {
                        contacts.push((a.area.min(b.area), a.normal));
                    }
                }
            }
            ((p, q), contacts)
        })
        .collect();
    // per part, the normals of all its planar contacts: each normal, and the line any two
    // non-parallel ones share (the part slides along it between them)
    let mut per_part: BTreeMap<usize, Vec<(f32, Vec3)>> = BTreeMap::new();
    for ((p, q), contacts) in per_pair {
        for (w, n) in contacts {
            per_part.entry(p).or_default().push((w, n));
            per_part.entry(q).or_default().push((w, -n));
        }
    }
    let mut found: Vec<(f32, Vec3)> = Vec::new();
    for (_, mut contacts) in per_part {
        contacts.sort_by(|a, b| b.0.total_cmp(&a.0));
        contacts.truncate(8);
        found.extend(contacts.iter().flat_map(|&(w, n)| [(w, n), (w, -n)]));
        for (i, &(wa, na)) in contacts.iter().enumerate() {
            for &(wb, nb) in &contacts[i + 1..] {
                let line = na.cross(nb);
                if line.length() > 0.05 {
                    let l = line.normalize();
                    found.extend([(wa.min(wb), l), (wa.min(wb), -l)]);
                }
            }
        }
    }
    found.sort_by(|a, b| b.0.total_cmp(&a.0));
    let mut added = 0;
    for (_, d) in found {
        if added >= MAX_CONTACT_DIRECTIONS {
            break;
        }
        if !directions.iter().any(|e| e.dot(d) > AXIS_ALIGNED) {
            directions.push(d);
            added += 1;
        }
    }
}
