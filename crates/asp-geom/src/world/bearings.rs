//! Rolling bearings recognised from their geometry: balls or rollers captive between an inner
//! and an outer raced ring. A bought unit: its rolling elements cannot leave the raceways, so no
//! straight motion takes it apart, and a planner that tries ends with the bearing, and whatever it sits in, as a locked
//! core. Recognised, a bearing is planned as one unit (it goes in whole) and its rings are never
//! taken for nuts or washers of a fastener.
//!
//! A bearing is recognised from what any tessellation keeps:
//! - *rolling elements*: balls, parts whose vertices lie on one sphere (fitted, every vertex
//!   within 3 % of its radius or the contact tolerance) and whose bounds are that sphere's cube
//!   (no dome, no cap); or rollers, closed parts that are a solid cylinder or cone frustum
//!   (cylindrical, needle and tapered rollers: about one of their principal axes, every vertex
//!   away from the axis on one straight side line within 3 % of the radius, the vertices near
//!   the axis only at the ends, the volume the solid's within tessellation, 0.5 to 12 diameters
//!   long, tapered by at most 15°), each roller's axis in the plane through the bearing's axis
//!   and its centre, within 45° of the bearing's axis (no pin laid across a circle);
//! - *two rings* that every rolling element of the bearing touches (within the contact distance): one whose
//!   vertices lie mostly inside the balls' pitch circle, one mostly outside;
//! - *the balls' centres* on one or more circles about a common axis (rows): at least three balls
//!   per row, their centres within 3 % of the row's pitch radius and in the row's plane; the axis
//!   is the direction in which the centres spread least;
//! - *the other parts* of the bearing (a cage, shields, seals): parts in contact with its balls
//!   or rings that lie wholly inside the rings' envelope (between the inner ring's bore and the
//!   outer ring's outside, between their faces).

use super::contacts::Contacts;
use super::shapes::Shapes;
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
/// A roller is between this many and [`ROLLER_LONGEST`] diameters long.
const ROLLER_SHORTEST: f32 = 0.5;
/// See [`ROLLER_SHORTEST`] (a needle roller is up to about ten diameters long).
const ROLLER_LONGEST: f32 = 12.0;
/// The steepest side of a tapered roller: tan 15°.
const ROLLER_TAPER: f32 = 0.268;
/// A roller's volume over its fitted solid's: a 12-gon's area is 0.955 of its circle's, and
/// chamfered ends take a little more.
const ROLLER_VOLUME: (f32, f32) = (0.85, 1.05);

/// What rolls between a bearing's rings.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RollingElement {
    /// Balls (a ball bearing).
    Ball,
    /// Cylinders or cone frustums (a cylindrical, needle or tapered roller bearing).
    Roller,
}

impl RollingElement {
    /// `balls` or `rollers`, as the plan and the text name them.
    pub fn plural(self) -> &'static str {
        match self {
            RollingElement::Ball => "balls",
            RollingElement::Roller => "rollers",
        }
    }
}

/// One rolling element found: its centre, its (mean) radius, what it is, and a roller's axis.
#[derive(Clone, Copy, Debug)]
struct Element {
    centre: Vec3,
    radius: f32,
    kind: RollingElement,
    axis: Vec3,
}

/// A rolling bearing found in a world: balls or rollers between an inner and an outer ring, plus
/// the parts held with them (cage, shields).
#[derive(Clone, Debug, PartialEq)]
pub struct Bearing {
    /// The inner ring and the outer ring (part indices).
    pub rings: [usize; 2],
    /// The rolling elements (balls or rollers, as [`Bearing::elements`] says), in part order.
    pub balls: Vec<usize>,
    /// What the rolling elements are.
    pub elements: RollingElement,
    /// The other parts of the bearing (cage, shields, seals), in part order.
    pub others: Vec<usize>,
    /// The centre of the balls' centres (on the axis), metres.
    pub centre: Vec3,
    /// The bearing's axis (unit; its sign is arbitrary).
    pub axis: Vec3,
    /// The radius of the circle through the balls' centres, metres.
    pub pitch_radius: f32,
    /// The balls' radius (a roller's mean radius), metres.
    pub ball_radius: f32,
    /// How many rows of rolling elements (circles of ball centres at different places along the axis).
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
/// (the normal of the plane they spread in).
fn least_spread(points: &[Vec3], mean: Vec3) -> Vec3 {
    principal_axes(points, mean)[0]
}

/// The principal axes of `points` about `mean`: the unit eigenvectors of the covariance's
/// smallest and largest eigenvalues (power iteration on `trace·I − C` and on `C`), and the
/// third, orthogonal to both.
fn principal_axes(points: &[Vec3], mean: Vec3) -> [Vec3; 3] {
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
    let power = |shift: f64, sign: f64| -> Vec3 {
        // start off every axis so that no eigenvector is missed by symmetry
        let mut v = [0.577_f64, 0.578, 0.576];
        for _ in 0..200 {
            let mut w = [0.0; 3];
            for i in 0..3 {
                w[i] = shift * v[i] + sign * (c[i][0] * v[0] + c[i][1] * v[1] + c[i][2] * v[2]);
            }
            let l = (w[0] * w[0] + w[1] * w[1] + w[2] * w[2]).sqrt();
            if l == 0.0 {
                break;
            }
            v = [w[0] / l, w[1] / l, w[2] / l];
        }
        Vec3::new(v[0] as f32, v[1] as f32, v[2] as f32).normalize_or(Vec3::Z)
    };
    let (least, most) = (power(trace, -1.0), power(0.0, 1.0));
    let third = least.cross(most).normalize_or(least.any_orthonormal_vector());
    [least, most, third]
}

/// The roller `vertices` (a closed mesh with `triangles`) are, if they are one: a solid cylinder
/// or cone frustum about one of their principal axes (see the module documentation). Returns its
/// centre (the middle of its axis), its mean radius and its axis.
pub(crate) fn fit_roller(vertices: &[Vec3], triangles: &[[u32; 3]], tolerance: f32) -> Option<(Vec3, f32, Vec3)> {
    if vertices.len() < 12 {
        return None;
    }
    let mean = vertices.iter().copied().sum::<Vec3>() / vertices.len() as f32;
    let volume = triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| (vertices[i as usize] - mean).as_dvec3());
            a.dot(b.cross(c)) / 6.0
        })
        .sum::<f64>()
        .abs() as f32;
    principal_axes(vertices, mean).into_iter().find_map(|axis| {
        let rt: Vec<(f32, f32)> = vertices.iter().map(|&v| radial_axial(v, mean, axis)).collect();
        let rmax = rt.iter().map(|x| x.0).fold(0.0, f32::max);
        let (t0, t1) = rt.iter().fold((f32::MAX, f32::MIN), |(lo, hi), x| (lo.min(x.1), hi.max(x.1)));
        let length = t1 - t0;
        if !(rmax > 0.0 && length > 0.0 && (ROLLER_SHORTEST..=ROLLER_LONGEST).contains(&(length / (2.0 * rmax)))) {
            return None;
        }
        let slack = (SPHERE_DEVIATION * rmax).max(tolerance);
        let near_end = |t: f32| (t - t0).min(t1 - t) <= 0.1 * length + slack;
        // the side: the vertices away from the axis, on one line r = a + b t (least squares,
        // once more without the chamfers' inner edges the first line finds)
        let side: Vec<(f32, f32)> = rt.iter().copied().filter(|x| x.0 > 0.5 * rmax).collect();
        let line = |points: &[(f32, f32)]| -> (f32, f32) {
            let n = points.len() as f32;
            let (mt, mr) = (points.iter().map(|x| x.1).sum::<f32>() / n, points.iter().map(|x| x.0).sum::<f32>() / n);
            let stt: f32 = points.iter().map(|x| (x.1 - mt).powi(2)).sum();
            let b = if stt > 0.0 { points.iter().map(|x| (x.1 - mt) * (x.0 - mr)).sum::<f32>() / stt } else { 0.0 };
            (mr - b * mt, b)
        };
        let (a, b) = line(&side);
        let kept: Vec<(f32, f32)> = side.iter().copied().filter(|&(r, t)| r - (a + b * t) >= -slack || !near_end(t)).collect();
        let (a, b) = if kept.len() >= 6 && kept.len() < side.len() { line(&kept) } else { (a, b) };
        if b.abs() > ROLLER_TAPER {
            return None;
        }
        // chamfered ends lie inside the line, never outside it
        let on_side = side.iter().all(|&(r, t)| {
            let off = r - (a + b * t);
            off.abs() <= slack || (off < 0.0 && near_end(t))
        });
        // near the axis only the ends' centres: no hole, no neck
        let solid_ends = rt.iter().all(|&(r, t)| r > 0.5 * rmax || near_end(t));
        if !(on_side && solid_ends) {
            return None;
        }
        let (r0, r1) = (a + b * t0, a + b * t1);
        let solid = std::f32::consts::PI * length * (r0 * r0 + r0 * r1 + r1 * r1) / 3.0;
        let share = volume / solid;
        (share >= ROLLER_VOLUME.0 && share <= ROLLER_VOLUME.1).then(|| (mean + axis * (0.5 * (t0 + t1)), a + b * 0.5 * (t0 + t1), axis))
    })
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

/// Every rolling bearing among the parts (see the module documentation), in the order of
/// their first ball; a part belongs to at most one bearing. Found anew: the world's
/// [`super::Fits::bearings`] holds the ones found with it.
pub fn find_bearings(shapes: &Shapes, contacts: &Contacts) -> Vec<Bearing> {
    let n = shapes.parts();
    // the rolling elements: parts on a sphere, or closed ones that are a cylinder or a cone
    // (triangle meshes; unions of boxes are not round)
    let elements: BTreeMap<usize, Element> = (0..n)
        .filter(|&p| shapes.boxes(p).is_none())
        .filter_map(|p| {
            let mesh = shapes.mesh(p);
            if let Some((centre, radius)) = fit_sphere(mesh.vertices(), shapes.tolerance()) {
                return Some((p, Element { centre, radius, kind: RollingElement::Ball, axis: Vec3::ZERO }));
            }
            let (centre, radius, axis) =
                shapes.is_closed(p).then(|| fit_roller(mesh.vertices(), mesh.indices(), shapes.tolerance())).flatten()?;
            Some((p, Element { centre, radius, kind: RollingElement::Roller, axis }))
        })
        .collect();
    if elements.len() < MIN_BALLS {
        return Vec::new();
    }
    // per pair of other parts, the elements touching both
    let mut by_pair: BTreeMap<(usize, usize), Vec<usize>> = BTreeMap::new();
    for &b in elements.keys() {
        let others: Vec<usize> = contacts.of(b).iter().filter(|&q| q < n && !elements.contains_key(&q)).collect();
        for (i, &a) in others.iter().enumerate() {
            for &c in &others[i + 1..] {
                by_pair.entry((a, c)).or_default().push(b);
            }
        }
    }
    let mut used = PartSet::empty(n + 1);
    let mut found = Vec::new();
    // the pairs with the most elements first: a cage touches every ball too, but is no ring
    let mut pairs: Vec<((usize, usize), Vec<usize>)> = by_pair.into_iter().filter(|(_, b)| b.len() >= MIN_BALLS).collect();
    pairs.sort_by(|a, b| b.1.len().cmp(&a.1.len()).then(a.0.cmp(&b.0)));
    for ((a, c), members) in pairs {
        if used.contains(a) || used.contains(c) || members.iter().any(|&b| used.contains(b)) {
            continue;
        }
        if let Some(bearing) = bearing_of(shapes, contacts, a, c, &members, &elements) {
            for p in bearing.parts() {
                used.insert(p);
            }
            found.push(bearing);
        }
    }
    found.sort_by_key(|b| b.balls[0]);
    found
}

/// The bearing of `members` (rolling elements touching both `a` and `c`), if they are of one
/// kind and size on circles about one axis (a roller's own axis in the plane through that
/// axis, within 45° of it) and `a` and `c` are rings on either side of them.
fn bearing_of(
    shapes: &Shapes,
    contacts: &Contacts,
    a: usize,
    c: usize,
    members: &[usize],
    elements: &BTreeMap<usize, Element>,
) -> Option<Bearing> {
    let n = shapes.parts();
    let radius = median(members.iter().map(|b| elements[b].radius).collect());
    let kind = elements[&members[0]].kind;
    let members: Vec<usize> =
        members.iter().copied().filter(|b| elements[b].kind == kind && (elements[b].radius - radius).abs() <= SAME_SIZE * radius).collect();
    if members.len() < MIN_BALLS {
        return None;
    }
    let centres: Vec<Vec3> = members.iter().map(|b| elements[b].centre).collect();
    let mean = centres.iter().copied().sum::<Vec3>() / centres.len() as f32;
    let axis = least_spread(&centres, mean);
    if kind == RollingElement::Roller {
        let laid_right = members.iter().all(|b| {
            let e = &elements[b];
            let out = (e.centre - mean - axis * (e.centre - mean).dot(axis)).normalize_or_zero();
            let across = axis.cross(out);
            e.axis.dot(across).abs() <= 0.1 && e.axis.dot(axis).abs() >= std::f32::consts::FRAC_1_SQRT_2
        });
        if !laid_right {
            return None;
        }
    }
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
    let ring_radii = |p: usize| -> Vec<(f32, f32)> { shapes.mesh(p).vertices().iter().map(|&v| radial_axial(v, mean, axis)).collect() };
    let (ra, rc) = (ring_radii(a), ring_radii(c));
    let (ma, mc) = (median(ra.iter().map(|x| x.0).collect()), median(rc.iter().map(|x| x.0).collect()));
    let margin = 0.3 * radius;
    let (inner, outer, ri, ro) = if ma < mc { (a, c, &ra, &rc) } else { (c, a, &rc, &ra) };
    let (mi, mo) = (ma.min(mc), ma.max(mc));
    if !(mi < pitch_radius - margin && mo > pitch_radius + margin) {
        return None;
    }
    // the envelope of the rings: from the bore out to the outside, between the faces
    let slack = contacts.distance().max(shapes.tolerance());
    let bore = ri.iter().map(|x| x.0).fold(f32::MAX, f32::min) - slack;
    let outside = ro.iter().map(|x| x.0).fold(0.0, f32::max) + slack;
    let lo = ri.iter().chain(ro).map(|x| x.1).fold(f32::MAX, f32::min) - slack;
    let hi = ri.iter().chain(ro).map(|x| x.1).fold(f32::MIN, f32::max) + slack;
    let mut held = PartSet::from_indices(n + 1, members.iter().copied().chain([inner, outer]));
    // the other parts: in contact with the bearing and wholly inside its envelope (a cage
    // touching only another cage half counts too: grow until nothing joins); a part that
    // touches at least three of the rolling elements is their cage also where it stands out
    // of the rings' faces by up to an element's radius (a tapered roller bearing's cage)
    let mut others = Vec::new();
    loop {
        let joins: Vec<usize> = (0..n)
            .filter(|&q| !held.contains(q) && !elements.contains_key(&q) && held.iter().any(|h| contacts.of(h).contains(q)))
            .filter(|&q| {
                let cage = members.iter().filter(|&&b| contacts.of(b).contains(q)).count() >= MIN_BALLS;
                let reach = if cage { radius } else { 0.0 };
                shapes.mesh(q).vertices().iter().all(|&v| {
                    let (r, t) = radial_axial(v, mean, axis);
                    r >= bore && r <= outside && t >= lo - reach && t <= hi + reach
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
        elements: kind,
        others,
        centre: mean,
        axis,
        pitch_radius,
        ball_radius: radius,
        rows: rows.len(),
    })
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

    /// A cylinder, a needle and a cone frustum (a tapered roller), about any axis and however
    /// faceted, are rollers; a tube, a box, a ball, a bolt (head and shank), a disc and a rod too
    /// long are not.
    #[test]
    fn cylinders_and_cones_are_rollers_and_tubes_boxes_balls_and_bolts_are_not() {
        use crate::fixtures::{ball_mesh, revolve};
        let mm = 0.001;
        let turn = crate::math::Rot::from_axis_angle(Vec3::new(1.0, 2.0, 3.0).normalize(), 0.7);
        let roller = |profile: &[(f32, f32)], n: u32| -> Option<(Vec3, f32, Vec3)> {
            let m = revolve(profile, n, 0.1, Vec3::ZERO);
            let v: Vec<Vec3> = m.vertices.iter().map(|&x| turn * x + Vec3::new(0.01, 0.02, -0.03)).collect();
            fit_roller(&v, &m.triangles, 1e-6)
        };
        let cylinder = |r: f32, l: f32| vec![(0.0, 0.0), (r, 0.0), (r, l), (0.0, l)];
        for n in [12, 16, 48] {
            let (c, r, axis) = roller(&cylinder(3.0 * mm, 8.0 * mm), n).unwrap_or_else(|| panic!("a {n}-gon cylinder"));
            assert!(axis.dot(turn * Vec3::Z).abs() > 0.9999, "{n}: {axis:?}");
            assert!((c - (turn * Vec3::new(0.0, 0.0, 4.0 * mm) + Vec3::new(0.01, 0.02, -0.03))).length() < 1e-6, "{n}: {c:?}");
            assert!((r - 3.0 * mm).abs() < 0.05 * 3.0 * mm, "{n}: {r}");
        }
        assert!(roller(&cylinder(1.0 * mm, 15.0 * mm), 12).is_some(), "a needle");
        assert!(roller(&cylinder(4.0 * mm, 4.5 * mm), 24).is_some(), "a short roller");
        let chamfered = [(0.0, 0.0), (2.7 * mm, 0.0), (3.0 * mm, 0.3 * mm), (3.0 * mm, 7.7 * mm), (2.7 * mm, 8.0 * mm), (0.0, 8.0 * mm)];
        assert!(roller(&chamfered, 16).is_some(), "a roller with chamfered ends");
        let (_, r, _) = roller(&[(0.0, 0.0), (3.0 * mm, 0.0), (2.6 * mm, 8.0 * mm), (0.0, 8.0 * mm)], 24).expect("a tapered roller");
        assert!((r - 2.8 * mm).abs() < 0.1 * mm, "{r}");
        let tube = [(1.5 * mm, 0.0), (3.0 * mm, 0.0), (3.0 * mm, 8.0 * mm), (1.5 * mm, 8.0 * mm)];
        assert!(roller(&tube, 16).is_none(), "a tube");
        let bolt = [(0.0, 0.0), (5.0 * mm, 0.0), (5.0 * mm, 4.0 * mm), (3.0 * mm, 4.0 * mm), (3.0 * mm, 20.0 * mm), (0.0, 20.0 * mm)];
        assert!(roller(&bolt, 24).is_none(), "a bolt");
        assert!(roller(&cylinder(10.0 * mm, 1.0 * mm), 24).is_none(), "a disc");
        assert!(roller(&cylinder(1.0 * mm, 40.0 * mm), 24).is_none(), "a rod");
        assert!(roller(&[(0.0, 0.0), (3.0 * mm, 0.0), (0.5 * mm, 8.0 * mm), (0.0, 8.0 * mm)], 24).is_none(), "a cone, not a roller");
        let cube = crate::mesh::Mesh::cuboid(Vec3::ZERO, Vec3::new(0.006, 0.006, 0.008));
        assert!(fit_roller(&cube.vertices, &cube.triangles, 1e-6).is_none(), "a box");
        let ball = ball_mesh(Vec3::ZERO, 0.004, 8, 16);
        assert!(fit_roller(&ball.vertices, &ball.triangles, 1e-6).is_none(), "a ball");
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
