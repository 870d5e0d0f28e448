//! Coaxial fits in the collision world ([`crate::fits`]): found with the world, their axes
//! among the candidate directions, and the pair test along an axis with the fit band exempt.

use super::*;
use crate::fits::{self, Fit, Role};

/// A direction is a fit's axis when their cosine exceeds this (0.1°): the exact axis joins the
/// candidates unless one lies this close.
pub(super) const AXIS_ALIGNED: f32 = 0.999_998_5;
/// The most directions the pairs' planar contacts add to the candidates.
const MAX_CONTACT_DIRECTIONS: usize = 48;

/// Whether the plane through `point` with unit `normal` meets box `b`.
fn plane_meets_box(point: Vec3, normal: Vec3, b: &Aabb) -> bool {
    let c = (b.mins + b.maxs) * 0.5;
    let h = (b.maxs - b.mins) * 0.5;
    (c - point).dot(normal).abs() <= h.dot(normal.abs())
}

impl World {
    /// Finds every fit between parts in contact (touching or overlapping in the input; meshes
    /// only, unions of boxes have no round faces) and adds each fit's axis, both ways, to the
    /// candidate directions.
    pub(super) fn find_fits(&mut self) {
        let n = self.num_parts();
        let pairs: Vec<(usize, usize)> = (0..n)
            .flat_map(|p| self.contacts[p].iter().filter(move |&q| q < n && q > p).map(move |q| (p, q)))
            .filter(|&(p, q)| self.geoms[p].boxes.is_none() && self.geoms[q].boxes.is_none())
            .collect();
        let parts: BTreeSet<usize> = pairs.iter().flat_map(|&(p, q)| [p, q]).collect();
        // each part's surfaces and role once, in parallel
        let roles: Vec<(usize, Role)> = parts
            .into_iter()
            .collect::<Vec<_>>()
            .par_iter()
            .map(|&p| {
                let g = &self.geoms[p];
                (p, fits::role(self.name(p), g.surfaces(), g.mesh.vertices()))
            })
            .collect();
        // a bearing's parts are a bought unit, never a fastener (a ring is no nut)
        let in_bearing: BTreeSet<usize> = self.bearings.iter().flat_map(|b| b.parts()).collect();
        for (p, r) in roles {
            self.roles[p] = if in_bearing.contains(&p) { Role::Other } else { r };
        }
        let found: Vec<((usize, usize), Vec<Fit>)> = pairs
            .par_iter()
            .filter_map(|&(p, q)| {
                let (gp, gq) = (&self.geoms[p], &self.geoms[q]);
                let f = fits::fits_between(
                    p,
                    gp.surfaces(),
                    self.roles[p],
                    q,
                    gq.surfaces(),
                    self.roles[q],
                    self.tolerance,
                    self.contact_distance,
                );
                (!f.is_empty()).then_some(((p, q), f))
            })
            .collect();
        self.add_contact_directions(&pairs);
        for (pair, f) in found {
            for fit in &f {
                for d in [fit.axis, -fit.axis] {
                    if !self.directions.iter().any(|e| e.dot(d) > AXIS_ALIGNED) {
                        self.directions.push(d);
                    }
                }
                if fit.class != fits::FitClass::Clearance {
                    self.fit_samples.entry((fit.shaft, fit.hole)).or_default();
                    self.fit_samples.entry((fit.hole, fit.shaft)).or_default();
                }
            }
            self.fits.insert(pair, f);
        }
    }

    /// Adds the directions the pairs' own planar contacts define: each contact plane's normal
    /// (a panel lifts off along it, also when the two are sunk a little into each other) and
    /// the line two non-parallel contact planes of one part share (a slide along a rail, in a
    /// T-slot or a channel), both ways, unless a candidate lies within 0.1°. Model-wide normal clusters
    /// average a lift 2° off an axis into the axis; these are the pair's exact ones. At most
    /// [`MAX_CONTACT_DIRECTIONS`] are added, the largest contacts first.
    fn add_contact_directions(&mut self, pairs: &[(usize, usize)]) {
        let slack = self.contact_distance;
        // per pair, its planar contacts (weight, the first part's outward normal)
        type Contacts = Vec<(f32, Vec3)>;
        let per_pair: Vec<((usize, usize), Contacts)> = pairs
            .par_iter()
            .map(|&(p, q)| {
                let (gp, gq) = (&self.geoms[p], &self.geoms[q]);
                let depth = self.notes.iter().find(|n| n.parts == (p, q)).map_or(0.0, |n| n.depth);
                let reach = slack + depth;
                let common =
                    Aabb::new(gp.aabb.mins.max(gq.aabb.mins) - Vec3::splat(reach), gp.aabb.maxs.min(gq.aabb.maxs) + Vec3::splat(reach));
                let large = |planes: &[fits::Plane]| {
                    let total: f32 = planes.iter().map(|x| x.area).sum();
                    planes.iter().filter(|x| x.area >= 0.005 * total).cloned().collect::<Vec<_>>()
                };
                let (pp, pq) = (large(&gp.surfaces().planes), large(&gq.surfaces().planes));
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
            if !self.directions.iter().any(|e| e.dot(d) > AXIS_ALIGNED) {
                self.directions.push(d);
                added += 1;
            }
        }
    }

    /// Part `p`'s cylinders and planes ([`crate::fits::recognise`]; made once when first asked).
    pub fn surfaces(&self, p: usize) -> &fits::Surfaces {
        self.geoms[p].surfaces()
    }

    /// The fits between `p` and `q` (either order).
    pub fn fits(&self, p: usize, q: usize) -> &[Fit] {
        self.fits.get(&(p.min(q), p.max(q))).map_or(&[], Vec::as_slice)
    }

    /// Every pair with fits, (low, high), and its fits.
    pub fn all_fits(&self) -> &BTreeMap<(usize, usize), Vec<Fit>> {
        &self.fits
    }

    /// The rolling bearings among the parts (balls captive between two rings; see
    /// [`super::Bearing`]), found with the world when fasteners are (`WorldConfig::fasteners`).
    pub fn bearings(&self) -> &[super::Bearing] {
        &self.bearings
    }

    /// What part `p` is (a nut, a washer, a bolt, a pin; [`Role::Other`] for parts in no mesh
    /// contact).
    pub fn role(&self, p: usize) -> Role {
        self.roles.get(p).copied().unwrap_or(Role::Other)
    }

    /// The fits of `p` and `q` that are not clearance fits and whose axis the motion along unit
    /// `dir` follows.
    pub(super) fn fits_along(&self, p: usize, q: usize, dir: Vec3) -> Vec<&Fit> {
        self.fits(p, q).iter().filter(|f| f.class != fits::FitClass::Clearance && f.axis.dot(dir).abs() > AXIS_ALIGNED).collect()
    }

    /// The pair test of `p` moving along unit `dir` (up to `t_max`) against `q` when the motion
    /// follows the axis of their `fits`: blocked when `q` must turn to move along it (the part
    /// holding a fastener's thread, a bolt whose nut is still on), else the strict sample rule
    /// on the samples of both parts outside every fit's band (see [`crate::fits`]).
    pub(super) fn fit_blocks(&self, p: usize, q: usize, fits: &[&Fit], dir: Vec3, t_max: f32) -> bool {
        if fits.iter().any(|f| f.turns == Some(q)) {
            return true;
        }
        // each band about the line through the fit's axis point along the motion: a sample
        // moving along `dir` keeps its distance from that line
        let outside = |s: &[Vec3]| -> Vec<Vec3> {
            s.iter()
                .copied()
                .filter(|&x| {
                    !fits.iter().any(|f| {
                        let r = crate::surface::radial(x, f.point, dir);
                        r >= f.band.0 && r <= f.band.1
                    })
                })
                .collect()
        };
        let (sp, sq) = (outside(self.fit_pair_samples(p, q)), outside(self.fit_pair_samples(q, p)));
        overlap::strict_entry(&sp, &self.geoms[p].mesh, &sq, &self.geoms[q].mesh, Vec3::ZERO, dir, t_max, true, self.tolerance).is_some()
    }

    /// Part `p`'s samples for its fit tests with `q`: its whole-surface samples and dense ones
    /// near `q` (made once per pair).
    fn fit_pair_samples(&self, p: usize, q: usize) -> &[Vec3] {
        let Some(cell) = self.fit_samples.get(&(p, q)) else { return self.strict_pair_samples(p, q) };
        cell.get_or_init(|| {
            let mut all = self.strict_samples(p).to_vec();
            let (a, b) = (self.geoms[p].mesh.local_aabb(), self.geoms[q].mesh.local_aabb());
            all.extend(overlap::local_inward_samples(&self.geoms[p].mesh, &a, &b, self.tolerance));
            all
        })
    }

    /// The partner of `p` among `present` along whose fit axis `direction` runs and which `p`
    /// must turn on (a nut on its bolt, a screw in its tapped hole): its removal there is a
    /// `screw` motion about the fit's axis.
    pub(super) fn turned_on(&self, p: usize, present: &PartSet, direction: Vec3) -> Option<&Fit> {
        present
            .iter()
            .filter(|&q| q != p && q < self.num_parts())
            .find_map(|q| self.fits(p, q).iter().find(|f| f.turns == Some(p) && f.axis.dot(direction).abs() > AXIS_ALIGNED))
    }
}
