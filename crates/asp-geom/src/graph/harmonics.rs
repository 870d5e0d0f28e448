//! Real spherical harmonics `Y_l^m` up to degree 20, evaluated in `f64` by the normalised
//! associated-Legendre recurrences (thesis eq. 3.9's basis functions).
//!
//! Convention: orthonormal on the unit sphere, no Condon–Shortley phase, `m > 0` the cosine and
//! `m < 0` the sine harmonics, so that `Y_1^{-1}, Y_1^0, Y_1^1 = √(3/4π) (y, z, x)`. Coefficients
//! are stored at index `l² + l + m`, `(L + 1)²` in all.
//!
//! With `Q_l^m = K_l^m P_l^m(z) / sin^m θ` (the normalised Legendre function without its
//! `sin^m θ` factor, `K_l^m = √((2l+1)/4π · (l-m)!/(l+m)!)`):
//! `Q_0^0 = 1/√(4π)`, `Q_m^m = Q_{m-1}^{m-1} √((2m+1)/2m)`, `Q_{m+1}^m = √(2m+3) z Q_m^m`,
//! `Q_l^m = a (z Q_{l-1}^m − b Q_{l-2}^m)` with `a = √((4l²−1)/(l²−m²))`,
//! `b = √(((l−1)²−m²)/(4(l−1)²−1))`; and `sin^m θ (cos mφ, sin mφ) = (x + iy)^m`. Every step
//! is a ratio of moderate numbers, so nothing over- or underflows at `L = 20`.

/// Number of real harmonics up to degree `degree`: `(degree + 1)²`.
pub fn count(degree: usize) -> usize {
    (degree + 1) * (degree + 1)
}

/// Index of `Y_l^m` in an array of all harmonics: `l² + l + m` (`-l <= m <= l`).
pub fn index(l: usize, m: i64) -> usize {
    (l * l + l).wrapping_add_signed(m as isize)
}

/// Writes `Y_l^m(dir)` for every `l <= degree`, `-l <= m <= l` into `out[index(l, m)]`.
/// `dir` must be a unit vector; `out` must hold at least [`count`]`(degree)` values (extra
/// entries are left alone, and a shorter `out` receives only the degrees that fit). Builds the
/// recurrence coefficients on each call: evaluate many directions with [`RealSh`].
pub fn real_sh(dir: [f64; 3], degree: usize, out: &mut [f64]) {
    let degree = (0..=degree).rev().find(|&l| count(l) <= out.len()).unwrap_or(0);
    if !out.is_empty() {
        RealSh::new(degree).eval(dir, out);
    }
}

/// The real spherical harmonics up to one degree, with their recurrence coefficients computed
/// once (no square roots per direction).
#[derive(Clone, Debug)]
pub struct RealSh {
    degree: usize,
    /// `√((2m+1)/2m)` at `m` (unused at 0).
    diag: Vec<f64>,
    /// `√(2m+3)` at `m`.
    next: Vec<f64>,
    /// `(a, b)` of the three-term recurrence at `index(l, m)`, `l >= m + 2`.
    ab: Vec<(f64, f64)>,
}

impl RealSh {
    /// The harmonics up to `degree`.
    pub fn new(degree: usize) -> RealSh {
        let diag = (0..=degree).map(|m| if m == 0 { 0.0 } else { ((2 * m + 1) as f64 / (2 * m) as f64).sqrt() }).collect();
        let next = (0..=degree).map(|m| ((2 * m + 3) as f64).sqrt()).collect();
        let mut ab = vec![(0.0, 0.0); count(degree)];
        for m in 0..=degree {
            let mf = m as f64;
            for l in (m + 2)..=degree {
                let lf = l as f64;
                let a = ((4.0 * lf * lf - 1.0) / (lf * lf - mf * mf)).sqrt();
                let b = (((lf - 1.0) * (lf - 1.0) - mf * mf) / (4.0 * (lf - 1.0) * (lf - 1.0) - 1.0)).sqrt();
                ab[index(l, m as i64)] = (a, b);
            }
        }
        RealSh { degree, diag, next, ab }
    }

    /// The highest degree.
    pub fn degree(&self) -> usize {
        self.degree
    }

    /// Writes `Y_l^m(dir)` for every `l <= degree()` into `out[index(l, m)]`; `dir` must be a
    /// unit vector. Panics when `out` holds fewer than [`count`]`(degree())` values.
    pub fn eval(&self, dir: [f64; 3], out: &mut [f64]) {
        let [x, y, z] = dir;
        let degree = self.degree;
        let out = &mut out[..count(degree)];
        let sqrt2 = std::f64::consts::SQRT_2;
        let mut qmm = 0.5 / std::f64::consts::PI.sqrt();
        // (c, s) = (x + iy)^m
        let (mut c, mut s) = (1.0f64, 0.0f64);
        for m in 0..=degree {
            if m > 0 {
                qmm *= self.diag[m];
                (c, s) = (c * x - s * y, c * y + s * x);
            }
            let (fc, fs) = (sqrt2 * c, sqrt2 * s);
            let mut put = |l: usize, q: f64| {
                let i = l * l + l;
                if m == 0 {
                    out[i] = q;
                } else {
                    out[i + m] = q * fc;
                    out[i - m] = q * fs;
                }
            };
            put(m, qmm);
            if m == degree {
                break;
            }
            let (mut q2, mut q1) = (qmm, self.next[m] * z * qmm);
            put(m + 1, q1);
            for l in (m + 2)..=degree {
                let (a, b) = self.ab[l * l + l + m];
                let q = a * (z * q1 - b * q2);
                put(l, q);
                (q2, q1) = (q1, q);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{RngExt, SeedableRng};
    use std::f64::consts::PI;

    fn random_dir(rng: &mut rand_chacha::ChaCha8Rng) -> [f64; 3] {
        loop {
            let v: [f64; 3] = [rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0)];
            let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
            if n > 0.1 && n <= 1.0 {
                return v.map(|c| c / n);
            }
        }
    }

    /// Legendre polynomial by Bonnet's recurrence.
    fn legendre(l: usize, t: f64) -> f64 {
        let (mut p0, mut p1) = (1.0, t);
        if l == 0 {
            return 1.0;
        }
        for k in 1..l {
            let kf = k as f64;
            (p0, p1) = (p1, ((2.0 * kf + 1.0) * t * p1 - kf * p0) / (kf + 1.0));
        }
        p1
    }

    #[test]
    fn closed_forms_up_to_degree_two() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(1);
        let mut y = vec![0.0; count(2)];
        for _ in 0..100 {
            let d = random_dir(&mut rng);
            let [x, yy, z] = d;
            real_sh(d, 2, &mut y);
            let expect = [
                (0, 0, 0.5 * (1.0 / PI).sqrt()),
                (1, -1, (3.0 / (4.0 * PI)).sqrt() * yy),
                (1, 0, (3.0 / (4.0 * PI)).sqrt() * z),
                (1, 1, (3.0 / (4.0 * PI)).sqrt() * x),
                (2, -2, 0.5 * (15.0 / PI).sqrt() * x * yy),
                (2, -1, 0.5 * (15.0 / PI).sqrt() * yy * z),
                (2, 0, 0.25 * (5.0 / PI).sqrt() * (3.0 * z * z - 1.0)),
                (2, 1, 0.5 * (15.0 / PI).sqrt() * x * z),
                (2, 2, 0.25 * (15.0 / PI).sqrt() * (x * x - yy * yy)),
            ];
            for (l, m, v) in expect {
                assert!((y[index(l, m)] - v).abs() < 1e-12, "Y_{l}^{m}({d:?}) = {} != {v}", y[index(l, m)]);
            }
        }
    }

    #[test]
    fn addition_theorem_holds_to_degree_twenty() {
        // Σ_m Y_l^m(a) Y_l^m(b) = (2l+1)/4π P_l(a·b): normalisation, cross terms and stability
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(2);
        let (mut ya, mut yb) = (vec![0.0; count(20)], vec![0.0; count(20)]);
        for k in 0..200 {
            let a = random_dir(&mut rng);
            // include the poles, where sin θ = 0
            let b = if k == 0 {
                [0.0, 0.0, 1.0]
            } else if k == 1 {
                [0.0, 0.0, -1.0]
            } else {
                random_dir(&mut rng)
            };
            real_sh(a, 20, &mut ya);
            real_sh(b, 20, &mut yb);
            let dot = a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
            for l in 0..=20usize {
                let sum: f64 = (-(l as i64)..=l as i64).map(|m| ya[index(l, m)] * yb[index(l, m)]).sum();
                let norm: f64 = (-(l as i64)..=l as i64).map(|m| ya[index(l, m)].powi(2)).sum();
                let scale = (2 * l + 1) as f64 / (4.0 * PI);
                assert!((sum - scale * legendre(l, dot)).abs() < 1e-10 * scale, "l={l}: {sum}");
                assert!((norm - scale).abs() < 1e-10 * scale, "l={l}: {norm}");
            }
        }
    }

    #[test]
    fn harmonics_are_orthonormal_under_quadrature() {
        // a product grid exact for polynomials of degree <= 2L in z (Gauss-Legendre, nodes by
        // Newton) and in φ (uniform): ∫ Y_i Y_j = δ_ij for L = 12
        let deg = 12;
        let nz = deg + 1;
        let mut nodes = Vec::new();
        for i in 0..nz {
            let mut t = (PI * (i as f64 + 0.75) / (nz as f64 + 0.5)).cos();
            for _ in 0..100 {
                let p = legendre(nz, t);
                let dp = nz as f64 * (t * p - legendre(nz - 1, t)) / (t * t - 1.0);
                t -= p / dp;
            }
            let dp = nz as f64 * (t * legendre(nz, t) - legendre(nz - 1, t)) / (t * t - 1.0);
            nodes.push((t, 2.0 / ((1.0 - t * t) * dp * dp)));
        }
        let nphi = 2 * deg + 2;
        let n = count(deg);
        let mut gram = vec![0.0; n * n];
        let mut y = vec![0.0; n];
        for &(z, w) in &nodes {
            for k in 0..nphi {
                let phi = 2.0 * PI * k as f64 / nphi as f64;
                let s = (1.0 - z * z).sqrt();
                real_sh([s * phi.cos(), s * phi.sin(), z], deg, &mut y);
                let wk = w * 2.0 * PI / nphi as f64;
                for i in 0..n {
                    for j in 0..n {
                        gram[i * n + j] += wk * y[i] * y[j];
                    }
                }
            }
        }
        for i in 0..n {
            for j in 0..n {
                let want = if i == j { 1.0 } else { 0.0 };
                assert!((gram[i * n + j] - want).abs() < 1e-10, "({i},{j}) {}", gram[i * n + j]);
            }
        }
    }

    #[test]
    fn short_output_gets_the_degrees_that_fit() {
        let mut y = vec![7.0; 5];
        real_sh([0.0, 0.0, 1.0], 8, &mut y);
        assert!((y[index(1, 0)] - (3.0 / (4.0 * PI)).sqrt()).abs() < 1e-12);
        assert_eq!(y[4], 7.0);
        real_sh([0.0, 0.0, 1.0], 3, &mut []);
    }
}
