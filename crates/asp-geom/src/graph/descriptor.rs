//! The spherical-harmonic shape descriptor of a weighted point cloud (thesis 3.4.2, eqs. 3.8-3.10).
//!
//! 1. Centre the cloud on its weighted centroid and scale it so the farthest point (of positive
//!    weight) is at radius 1 (translation and scale invariance).
//! 2. Split each point's weight linearly between the two nearest of `B = radius_bins` shells,
//!    centred at radii `(b + ½)/B`; points inside the first or beyond the last centre go wholly
//!    to that shell. This is the radial histogram of the thesis with linear instead of hard bins,
//!    so the descriptor changes continuously with the points.
//! 3. Per shell, project the weighted directions onto the real spherical harmonics up to degree
//!    `L` (eq. 3.9): `a_l^m = Σ_k w_k Y_l^m(d_k)`, the limit of the thesis' angular histogram as
//!    its bins shrink. A point exactly at the centre has no direction and counts as the uniform
//!    distribution (degree 0 only).
//! 4. The entry of shell `b` and degree `l` is `√(4π/(2l+1)) · ‖a_l‖₂ / W` (eq. 3.10), `W` the total
//!    weight: rotation invariant (the L2 norm of each frequency component), independent of
//!    the number of points, and in `[0, 1]` — a shell holding weight fraction `f` has degree-0
//!    entry `f`, and a shell whose weight sits in one direction has every entry `f`.
//!
//! Layout: shell-major, `h[b · (L + 1) + l]`, `D = B (L + 1)` floats. An empty cloud (no point of
//! positive finite weight) gives zeros; a cloud of one point, or of equal points, gives `1` at
//! shell 0, degree 0, and zeros elsewhere. Non-finite points and non-positive or non-finite
//! weights are ignored. Never NaN.

use super::config::GraphConfig;
use super::harmonics::{count, index, RealSh};
use crate::math::Vec3;

/// The descriptor of the cloud `points` with `weights` (paired by position; extra items of the
/// longer slice are ignored), `config.descriptor_dim()` floats. See the module documentation.
pub fn sh_descriptor(points: &[Vec3], weights: &[f32], config: &GraphConfig) -> Vec<f32> {
    let mut out = vec![0.0; config.descriptor_dim()];
    descriptor_into(|| points.iter().copied().zip(weights.iter().copied()), config, &mut out, &mut Vec::new());
    out
}

/// The descriptor of the weighted points that `cloud()` yields (called three times: centroid,
/// radius, projection), written into `out` (`config.descriptor_dim()` floats). `scratch` is
/// reused between calls to avoid allocation.
pub(crate) fn descriptor_into<I, F>(cloud: F, config: &GraphConfig, out: &mut [f32], scratch: &mut Vec<f64>)
where
    F: Fn() -> I,
    I: Iterator<Item = (Vec3, f32)>,
{
    let bins = config.radius_bins.max(1);
    let degree = config.degree;
    let dim = bins * (degree + 1);
    let len = dim.min(out.len());
    let out = &mut out[..len];
    out.fill(0.0);
    let valid = || {
        cloud().filter(|(p, w)| p.is_finite() && w.is_finite() && *w > 0.0).map(|(p, w)| ([p.x as f64, p.y as f64, p.z as f64], w as f64))
    };
    // 1. weighted centroid and the farthest point
    let (mut total, mut sum) = (0.0f64, [0.0f64; 3]);
    for (p, w) in valid() {
        total += w;
        sum = [sum[0] + w * p[0], sum[1] + w * p[1], sum[2] + w * p[2]];
    }
    if !(total > 0.0 && total.is_finite()) {
        return;
    }
    let centre = sum.map(|s| s / total);
    let offset = |p: [f64; 3]| [p[0] - centre[0], p[1] - centre[1], p[2] - centre[2]];
    let length = |d: [f64; 3]| (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
    let radius = valid().map(|(p, _)| length(offset(p))).fold(0.0f64, f64::max);
    let nh = count(degree);
    let harmonics = RealSh::new(degree);
    scratch.clear();
    scratch.resize(bins * nh + nh, 0.0);
    let (acc, y) = scratch.split_at_mut(bins * nh);
    // a direction counts as defined when it is above rounding noise of the coordinates
    let tiny = radius * 1e-9;
    if radius > 0.0 && radius.is_finite() {
        for (p, w) in valid() {
            let d = offset(p);
            let r = length(d);
            // 2. linear split between the two nearest shells
            let u = (r / radius * bins as f64 - 0.5).clamp(0.0, (bins - 1) as f64);
            let b0 = (u.floor() as usize).min(bins - 1);
            let t = u - b0 as f64;
            // 3. the harmonics of the direction
            if r > tiny {
                harmonics.eval([d[0] / r, d[1] / r, d[2] / r], y);
            } else {
                y.fill(0.0);
                y[0] = 0.5 / std::f64::consts::PI.sqrt();
            }
            for (b, share) in [(b0, 1.0 - t), ((b0 + 1).min(bins - 1), t)] {
                if share > 0.0 {
                    let wb = w * share;
                    for (a, yv) in acc[b * nh..(b + 1) * nh].iter_mut().zip(y.iter()) {
                        *a += wb * yv;
                    }
                }
            }
        }
    } else {
        // every point at the centroid: the uniform distribution in shell 0
        acc[0] = total * 0.5 / std::f64::consts::PI.sqrt();
    }
    // 4. the L2 norm of each degree, normalised
    for b in 0..bins {
        for l in 0..=degree {
            let sq: f64 = (-(l as i64)..=l as i64).map(|m| acc[b * nh + index(l, m)].powi(2)).sum();
            let scale = (4.0 * std::f64::consts::PI / (2 * l + 1) as f64).sqrt();
            let v = scale * sq.sqrt() / total;
            if let Some(o) = out.get_mut(b * (degree + 1) + l) {
                *o = if v.is_finite() { v as f32 } else { 0.0 };
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cfg() -> GraphConfig {
        GraphConfig::default()
    }

    #[test]
    fn degenerate_clouds_are_finite_and_defined() {
        let c = cfg();
        let zero = sh_descriptor(&[], &[], &c);
        assert_eq!(zero, vec![0.0; 72]);
        let one = sh_descriptor(&[Vec3::new(1.0, 2.0, 3.0)], &[0.5], &c);
        assert_eq!(one[0], 1.0);
        assert!(one[1..].iter().all(|v| *v == 0.0));
        let same = sh_descriptor(&[Vec3::ONE; 5], &[1.0; 5], &c);
        assert_eq!(same, one);
        // zero, negative and NaN weights and NaN points are ignored
        let junk = sh_descriptor(&[Vec3::ONE, Vec3::splat(f32::NAN), Vec3::ZERO, Vec3::X], &[1.0, 1.0, 0.0, -2.0], &c);
        assert_eq!(junk, one);
        let nan_w = sh_descriptor(&[Vec3::ONE, Vec3::X], &[f32::NAN, f32::INFINITY], &c);
        assert_eq!(nan_w, zero);
    }

    #[test]
    fn two_antipodal_points_have_only_even_degrees_in_the_last_shell() {
        let c = cfg();
        let h = sh_descriptor(&[Vec3::X, -Vec3::X], &[1.0, 1.0], &c);
        let last = &h[7 * 9..];
        for (l, v) in last.iter().enumerate() {
            let want = if l % 2 == 0 { 1.0 } else { 0.0 };
            assert!((v - want).abs() < 1e-6, "l={l}: {v}");
        }
        assert!(h[..7 * 9].iter().all(|v| v.abs() < 1e-7));
    }

    #[test]
    fn entries_are_weight_fractions_per_shell_at_degree_zero() {
        let c = cfg();
        let pts: Vec<Vec3> = (0..50).map(|k| Vec3::new((k as f32 * 0.37).sin(), (k as f32).cos(), k as f32 * 0.01)).collect();
        let w: Vec<f32> = (0..50).map(|k| 1.0 + k as f32 * 0.1).collect();
        let h = sh_descriptor(&pts, &w, &c);
        let sum: f32 = (0..8).map(|b| h[b * 9]).sum();
        assert!((sum - 1.0).abs() < 1e-5, "{sum}");
        assert!(h.iter().all(|v| (0.0..=1.0 + 1e-6).contains(v)));
        // duplicating every point with half the weight changes nothing
        let pts2: Vec<Vec3> = pts.iter().flat_map(|p| [*p, *p]).collect();
        let w2: Vec<f32> = w.iter().flat_map(|x| [x * 0.5, x * 0.5]).collect();
        let h2 = sh_descriptor(&pts2, &w2, &c);
        for (a, b) in h.iter().zip(&h2) {
            assert!((a - b).abs() < 1e-6);
        }
    }
}
