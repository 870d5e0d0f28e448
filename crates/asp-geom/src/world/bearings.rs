//! Rolling bearings recognised from their geometry: balls captive between an inner and an outer
//! raced ring. A bought unit: its balls cannot leave the grooves, so no straight motion takes it
//! apart, and a planner that tries ends with the bearing, and whatever it sits in, as a locked
//! core. Recognised, a bearing is planned as one unit (it goes in whole) and its rings are never
//! taken for nuts or washers of a fastener.
//!
//! A bearing is recognised from what any tessellation keeps:
//! - *balls*: parts whose vertices lie on one sphere (fitted, every vertex within 3 % of its
//!   radius or the contact tolerance) and whose bounds are that sphere's cube (no dome, no cap);
//! - *two rings* that every ball of the bearing touches (within the contact distance): one whose
//!   vertices lie mostly inside the balls' pitch circle, one mostly outside;
//! - *the balls' centres* on one or more circles about a common axis (rows): at least three balls
//!   per row, their centres within 3 % of the row's pitch radius and in the row's plane; the axis
//!   is the direction in which the centres spread least;
//! - *the other parts* of the bearing (a cage, shields, seals): parts in contact with its balls
//!   or rings that lie wholly inside the rings' envelope (between the inner ring's bore and the
//!   outer ring's outside, between their faces).

use super::World;
use crate::math::Vec3;
use crate::partset::PartSet;
use std::collections::BTreeMap;

/// How far a ball's vertices may lie off its fitted sphere, as a fraction of its radius (a
/// 12-gon tessellation's sagitta is 3.4 %).
const SPHERE_DEVIATION: f32 = 0.035;
/// How far a ball's bounds may differ from its sphere's cube, as a fraction of its radius.
const SPHERE_BOUNDS: f32 = 0.08;
/// How far the balls of one bearing may differ in radius, and their centres from the row's pitch
/// circle, as a fraction.
const SAME_SIZE: f32 = 0.03;
/// The fewest balls of one row.
const MIN_BALLS: usize = 3;

/// A rolling bearing found in a world: balls between an inner and an outer ring, plus the parts
/// held with them (cage, shields).
#[derive(Clone, Debug, PartialEq)]
pub struct Bearing {
    /// The inner ring and the outer ring (part indices).
    pub rings: [usize; 2],
    /// The balls, in part order.
    pub balls: Vec<usize>,
    /// The other parts of the bearing (cage, shields, seals), in part order.
    pub others: Vec<usize>,
    /// The centre of the balls' centres (on the axis), metres.
    pub centre: Vec3,
    /// The bearing's axis (unit; its sign is arbitrary).
    pub axis: Vec3,
    /// The radius of the circle through the balls' centres, metres.
    pub pitch_radius: f32,
    /// The balls' radius, metres.
    pub ball_radius: f32,
    /// How many rows of balls (circles of ball centres at different places along the axis).
    pub rows: usize,
}

impl Bearing {
    /// Every part of the bearing (rings, balls, others), ascending.
    pub fn parts(&self) -> Vec<usize> {
        let mut all: Vec<usize> = self.rings.iter().chain(&self.balls).chain(&self.others).copied().collect();
        all.sort_unstable();
        all.dedup();
        all
    }
}

/// The sphere `vertices` lie on: its centre and radius, when every vertex lies within
/// [`SPHERE_DEVIATION`] of its radius (or `tolerance`) and their bounds are its cube.
/// Geometric least squares by fixed-point iteration from the vertices' mean.
pub(crate) fn fit_sphere(vertices: &[Vec3], tolerance: f32) -> Option<(Vec3, f32)> {
    if vertices.len() < 12 {
        return None;
    }
    let n = vertices.len() as f32;
    let mut c = vertices.iter().copied().sum::<Vec3>() / n;
    for _ in 0..50 {
        let r = vertices.iter().map(|&v| (v - c).length()).sum::<f32>() / n;
        let next = vertices
            .iter()
            .map(|&v| {
                let d = v - c;
                let l = d.length();
                if l > 0.0 {
                    v - d * (r / l)
                } else {
                    v
                }
            })
            .sum::<Vec3>()
            / n;
        let moved = (next - c).length();
        c = next;
        if moved <= 1e-7 * r.max(f32::MIN_POSITIVE) {
            break;
        }
    }
    let r = vertices.iter().map(|&v| (v - c).length()).sum::<f32>() / n;
    if !(r.is_finite() && r > 0.0) {
        return None;
    }
    let slack = (SPHERE_DEVIATION * r).max(tolerance);
    if vertices.iter().any(|&v| ((v - c).length() - r).abs() > slack) {
        return None;
    }
    // the whole sphere, not a dome: the bounds reach its radius along every axis, both ways
    let (lo, hi) = vertices.iter().fold((Vec3::splat(f32::MAX), Vec3::splat(f32::MIN)), |(lo, hi), &v| (lo.min(v), hi.max(v)));
    let reach = (SPHERE_BOUNDS * r).max(tolerance);
    let whole = (0..3).all(|k| (c[k] - lo[k] - r).abs() <= reach && (hi[k] - c[k] - r).abs() <= reach);
    whole.then_some((c, r))
}

/// The unit eigenvector of the smallest eigenvalue of the covariance of `points` about `mean`
/// (the normal of the plane they spread in; power iteration on `trace·I − C`).
fn least_spread(points: &[Vec3], mean: Vec3) -> Vec3 {
    let mut c = [[0.0f64; 3]; 3];
    for p in points {
        let d = *p - mean;
        let d = [d.x as f64, d.y as f64, d.z as f64];
        for (i, row) in c.iter_mut().enumerate() {
            for (j, x) in row.iter_mut().enumerate() {
                *x += d[i] * d[j];
            }
        }
    }
    let trace = c[0][0] + c[1][1] + c[2][2];
    let m = |v: [f64; 3]| -> [f64; 3] {
        let mut out = [0.0; 3];
        for i in 0..3 {
            out[i] = trace * v[i] - (c[i][0] * v[0] + c[i][1] * v[1] + c[i][2] * v[2]);
        }
        out
    };
    // start off every axis so that no eigenvector is missed by symmetry
    let mut v = [0.577_f64, 0.578, 0.576];
    for _ in 0..200 {
        let w = m(v);
        let l = (w[0] * w[0] + w[1] * w[1] + w[2] * w[2]).sqrt();
        if l == 0.0 {
            break;
        }
        v = [w[0] / l, w[1] / l, w[2] / l];
    }
    Vec3::new(v[0] as f32, v[1] as f32, v[2] as f32).normalize_or(Vec3::Z)
}

/// The distance of `x` from the line through `centre` along unit `axis`, and its coordinate
/// along the axis.
fn radial_axial(x: Vec3, centre: Vec3, axis: Vec3) -> (f32, f32) {
    let d = x - centre;
    let t = d.dot(axis);
    ((d - axis * t).length(), t)
}

/// The median of `values` (not empty).
fn median(mut values: Vec<f32>) -> f32 {
    values.sort_by(f32::total_cmp);
    values[values.len() / 2]
}

impl World {
    /// Every rolling bearing among the parts (see the module documentation), in the order of
    /// their first ball; a part belongs to at most one bearing. Found anew: [`World::bearings`]
    /// holds the ones found with the world.
    pub fn find_bearings(&self) -> Vec<Bearing> {
        let n = self.num_parts();
        // the balls: parts on a sphere (triangle meshes; unions of boxes are not round)
        let balls: BTreeMap<usize, (Vec3, f32)> = (0..n)
            .filter(|&p| self.geoms[p].boxes.is_none())
            .filter_map(|p| fit_sphere(self.geoms[p].mesh.vertices(), self.tolerance).map(|s| (p, s)))
            .collect();
        if balls.len() < MIN_BALLS {
            return Vec::new();
        }
        // per pair of non-ball parts, the balls touching both
        let mut by_pair: BTreeMap<(usize, usize), Vec<usize>> = BTreeMap::new();
        for &b in balls.keys() {
            let others: Vec<usize> = self.contacts[b].iter().filter(|&q| q < n && !balls.contains_key(&q)).collect();
            for (i, &a) in others.iter().enumerate() {
                for &c in &others[i + 1..] {
                    by_pair.entry((a, c)).or_default().push(b);
                }
            }
        }
        let mut used = PartSet::empty(n + 1);
        let mut found = Vec::new();
        // the pairs with the most balls first: a cage touches every ball too, but is no ring
        let mut pairs: Vec<((usize, usize), Vec<usize>)> = by_pair.into_iter().filter(|(_, b)| b.len() >= MIN_BALLS).collect();
        pairs.sort_by(|a, b| b.1.len().cmp(&a.1.len()).then(a.0.cmp(&b.0)));
        for ((a, c), members) in pairs {
            if used.contains(a) || used.contains(c) || members.iter().any(|&b| used.contains(b)) {
                continue;
            }
            if let Some(bearing) = self.bearing_of(a, c, &members, &balls) {
                for p in bearing.parts() {
                    used.insert(p);
                }
                found.push(bearing);
            }
        }
        found.sort_by_key(|b| b.balls[0]);
        found
    }

    /// The bearing of `members` (balls touching both `a` and `c`), if the balls are of one size
    /// on circles about one axis and `a` and `c` are rings on either side of them.
    fn bearing_of(&self, a: usize, c: usize, members: &[usize], balls: &BTreeMap<usize, (Vec3, f32)>) -> Option<Bearing> {
        let n = self.num_parts();
        let radius = median(members.iter().map(|b| balls[b].1).collect());
        let members: Vec<usize> = members.iter().copied().filter(|b| (balls[b].1 - radius).abs() <= SAME_SIZE * radius).collect();
        if members.len() < MIN_BALLS {
            return None;
        }
        let centres: Vec<Vec3> = members.iter().map(|b| balls[b].0).collect();
        let mean = centres.iter().copied().sum::<Vec3>() / centres.len() as f32;
        let axis = least_spread(&centres, mean);
        // rows: the centres' places along the axis, split where they jump by more than a radius
        let mut along: Vec<(f32, usize)> = centres.iter().enumerate().map(|(i, &x)| (radial_axial(x, mean, axis).1, i)).collect();
        along.sort_by(|x, y| x.0.total_cmp(&y.0));
        let mut rows: Vec<Vec<usize>> = vec![vec![along[0].1]];
        for w in along.windows(2) {
            if w[1].0 - w[0].0 > radius {
                rows.push(Vec::new());
            }
            rows.last_mut().expect("one row at least").push(w[1].1);
        }
        let mut pitch = Vec::new();
        for row in &rows {
            if row.len() < MIN_BALLS {
                return None;
            }
            let radial: Vec<f32> = row.iter().map(|&i| radial_axial(centres[i], mean, axis).0).collect();
            let r = radial.iter().sum::<f32>() / radial.len() as f32;
            if r <= radius || radial.iter().any(|x| (x - r).abs() > SAME_SIZE * r) {
                return None;
            }
            pitch.push(r);
        }
        let pitch_radius = pitch.iter().sum::<f32>() / pitch.len() as f32;
        // the rings: one mostly inside the pitch circle, one mostly outside
        let ring_radii =
            |p: usize| -> Vec<(f32, f32)> { self.geoms[p].mesh.vertices().iter().map(|&v| radial_axial(v, mean, axis)).collect() };
        let (ra, rc) = (ring_radii(a), ring_radii(c));
        let (ma, mc) = (median(ra.iter().map(|x| x.0).collect()), median(rc.iter().map(|x| x.0).collect()));
        let margin = 0.3 * radius;
        let (inner, outer, ri, ro) = if ma < mc { (a, c, &ra, &rc) } else { (c, a, &rc, &ra) };
        let (mi, mo) = (ma.min(mc), ma.max(mc));
        if !(mi < pitch_radius - margin && mo > pitch_radius + margin) {
            return None;
        }
        // the envelope of the rings: from the bore out to the outside, between the faces
        let slack = self.contact_distance.max(self.tolerance);
        let bore = ri.iter().map(|x| x.0).fold(f32::MAX, f32::min) - slack;
        let outside = ro.iter().map(|x| x.0).fold(0.0, f32::max) + slack;
        let lo = ri.iter().chain(ro).map(|x| x.1).fold(f32::MAX, f32::min) - slack;
        let hi = ri.iter().chain(ro).map(|x| x.1).fold(f32::MIN, f32::max) + slack;
        let mut held = PartSet::from_indices(n + 1, members.iter().copied().chain([inner, outer]));
        // the other parts: in contact with the bearing and wholly inside its envelope (a cage
        // touching only another cage half counts too: grow until nothing joins)
        let mut others = Vec::new();
        loop {
            let joins: Vec<usize> = (0..n)
                .filter(|&q| !held.contains(q) && !balls.contains_key(&q) && held.iter().any(|h| self.contacts[h].contains(q)))
                .filter(|&q| {
                    self.geoms[q].mesh.vertices().iter().all(|&v| {
                        let (r, t) = radial_axial(v, mean, axis);
                        r >= bore && r <= outside && t >= lo && t <= hi
                    })
                })
                .collect();
            if joins.is_empty() {
                break;
            }
            for q in joins {
                held.insert(q);
                others.push(q);
            }
        }
        others.sort_unstable();
        let mut ball_parts = members;
        ball_parts.sort_unstable();
        // the centre on the axis: the balls' mean, in the middle of the rows
        Some(Bearing {
            rings: [inner, outer],
            balls: ball_parts,
            others,
            centre: mean,
            axis,
            pitch_radius,
            ball_radius: radius,
            rows: rows.len(),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn uv_sphere(c: Vec3, r: f32, rings: u32, segments: u32) -> Vec<Vec3> {
        let mut v = vec![c + Vec3::Z * r, c - Vec3::Z * r];
        for i in 1..rings {
            let phi = std::f32::consts::PI * i as f32 / rings as f32;
            for j in 0..segments {
                let th = std::f32::consts::TAU * j as f32 / segments as f32;
                v.push(c + Vec3::new(phi.sin() * th.cos(), phi.sin() * th.sin(), phi.cos()) * r);
            }
        }
        v
    }

    #[test]
    fn a_sphere_is_fitted_and_a_dome_or_a_box_is_not() {
        let c = Vec3::new(0.01, -0.02, 0.005);
        let (fc, fr) = fit_sphere(&uv_sphere(c, 0.004, 8, 12), 1e-6).expect("a sphere");
        assert!((fc - c).length() < 1e-6 && (fr - 0.004).abs() < 1e-5, "{fc:?} {fr}");
        // the upper half only: on the sphere, but a dome
        let dome: Vec<Vec3> = uv_sphere(c, 0.004, 8, 12).into_iter().filter(|v| v.z >= c.z).collect();
        assert!(fit_sphere(&dome, 1e-6).is_none());
        // a cube's corners and edge midpoints are not on one sphere
        let cube: Vec<Vec3> = (0..27).map(|i| Vec3::new((i % 3) as f32, (i / 3 % 3) as f32, (i / 9) as f32)).collect();
        assert!(fit_sphere(&cube, 1e-6).is_none());
    }

    #[test]
    fn the_least_spread_of_a_circle_is_its_axis() {
        let axis = Vec3::new(1.0, 2.0, 0.5).normalize();
        let u = axis.any_orthonormal_vector();
        let w = axis.cross(u);
        let pts: Vec<Vec3> = (0..7).map(|i| (u * (i as f32).cos() + w * (i as f32).sin()) * 0.02).collect();
        let mean = pts.iter().copied().sum::<Vec3>() / 7.0;
        assert!(least_spread(&pts, mean).dot(axis).abs() > 0.9999);
    }
}
