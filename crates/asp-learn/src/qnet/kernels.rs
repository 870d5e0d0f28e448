//! The dense kernels of the forward pass: row-major matrix products over `pulp`'s SIMD vectors
//! (compiled once per instruction set), a branch-free `exp`, and the folding of two linear maps
//! into one at load.

use pulp::Simd;

/// A linear map `y = x W + b` with `W` stored `[in, out]` (PyTorch's weight transposed).
#[derive(Clone, Debug)]
pub(super) struct Dense {
    pub(super) input: usize,
    pub(super) output: usize,
    pub(super) w: Vec<f32>,
    pub(super) b: Vec<f32>,
}

impl Dense {
    /// `out[rows, output] = x[rows, input] W (+ b)`, row-major.
    #[inline(always)]
    pub(super) fn apply<S: Simd>(&self, simd: S, x: &[f32], rows: usize, bias: bool, out: &mut [f32]) {
        gemm(simd, x, rows, self.input, &self.w, self.output, bias.then_some(&self.b[..]), &mut out[..rows * self.output]);
    }
}

/// `out[r, :] = bias + x[r, :] W` for row-major `x [rows, k]`, `W [k, cols]` and `out [rows,
/// cols]`. Tiles of four rows by two SIMD vectors of columns (then by one vector) are summed in
/// registers with fused multiply-adds, so each load of a row of `W` serves four rows of `x`;
/// columns past the last whole vector (all of them without SIMD) are summed row by row over
/// contiguous columns, in the same order per value.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
pub(super) fn gemm<S: Simd>(simd: S, x: &[f32], rows: usize, k: usize, w: &[f32], cols: usize, bias: Option<&[f32]>, out: &mut [f32]) {
    let lanes = lanes::<S>();
    // without SIMD (one lane) every column takes the plain loop below: a scalar mul_add would be
    // a library call
    let (two, one) = if lanes > 1 { (cols / (2 * lanes) * 2 * lanes, cols / lanes * lanes) } else { (0, 0) };
    let mut r0 = 0;
    while r0 + 4 <= rows {
        gemm_rows::<S, 4, 2>(simd, x, r0, k, w, cols, 0..two, bias, out);
        gemm_rows::<S, 4, 1>(simd, x, r0, k, w, cols, two..one, bias, out);
        r0 += 4;
    }
    while r0 < rows {
        gemm_rows::<S, 1, 2>(simd, x, r0, k, w, cols, 0..two, bias, out);
        gemm_rows::<S, 1, 1>(simd, x, r0, k, w, cols, two..one, bias, out);
        r0 += 1;
    }
    if one == cols {
        return;
    }
    for r in 0..rows {
        let o = &mut out[r * cols + one..(r + 1) * cols];
        match bias {
            Some(b) => o.copy_from_slice(&b[one..cols]),
            None => o.fill(0.0),
        }
        for (j, row) in w[..k * cols].chunks_exact(cols).enumerate() {
            let xv = x[r * k + j];
            for (o, &wv) in o.iter_mut().zip(&row[one..]) {
                *o += xv * wv;
            }
        }
    }
}

/// `f32` lanes of a SIMD vector of `S`.
#[inline(always)]
fn lanes<S: Simd>() -> usize {
    std::mem::size_of::<S::f32s>() / std::mem::size_of::<f32>()
}

/// Rows `r0..r0 + R` of [`gemm`], the columns `span` (whole tiles of `V` vectors): `R × V`
/// accumulators in registers, so each load of a row of `W` serves `R` rows of `x`.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn gemm_rows<S: Simd, const R: usize, const V: usize>(
    simd: S,
    x: &[f32],
    r0: usize,
    k: usize,
    w: &[f32],
    cols: usize,
    span: std::ops::Range<usize>,
    bias: Option<&[f32]>,
    out: &mut [f32],
) {
    let tile = V * lanes::<S>();
    let xs: [&[f32]; R] = std::array::from_fn(|r| &x[(r0 + r) * k..(r0 + r + 1) * k]);
    for c0 in span.step_by(tile) {
        let c1 = c0 + tile;
        let start = bias.map_or([simd.splat_f32s(0.0); V], |b| vectors::<S, V>(&b[c0..c1]));
        let mut acc = [start; R];
        for (j, row) in w[..k * cols].chunks_exact(cols).enumerate() {
            let wv = vectors::<S, V>(&row[c0..c1]);
            #[allow(clippy::needless_range_loop)] // unrolled: the accumulators stay in registers
            for r in 0..R {
                let xv = simd.splat_f32s(xs[r][j]);
                for v in 0..V {
                    acc[r][v] = simd.mul_add_f32s(xv, wv[v], acc[r][v]);
                }
            }
        }
        for (r, acc) in acc.iter().enumerate() {
            let at = (r0 + r) * cols;
            let o: &mut [S::f32s] = pulp::bytemuck::cast_slice_mut(&mut out[at + c0..at + c1]);
            o.copy_from_slice(acc);
        }
    }
}

/// `V` SIMD vectors from `V · lanes` floats (a function, not a closure: closures are not
/// inlined into the SIMD-compiled caller).
#[inline(always)]
fn vectors<S: Simd, const V: usize>(v: &[f32]) -> [S::f32s; V] {
    let v: &[S::f32s] = pulp::bytemuck::cast_slice(v);
    std::array::from_fn(|k| v[k])
}

/// `e^x` for `x <= SCORE_CLAMP` (Cephes' `expf` polynomial after reduction by `ln 2`; within a
/// few ulp of the correctly rounded value; `x` is clamped to `[-87, 88]`, so far below the
/// range it gives `e^-87`, not 0). Branch-free, so loops of it vectorise, where the C library's
/// `expf` is a call per element.
#[inline(always)]
pub(super) fn exp(x: f32) -> f32 {
    const LOG2E: f32 = std::f32::consts::LOG2_E;
    const LN2_HI: f32 = 0.693_359_4;
    const LN2_LO: f32 = -2.121_944_4e-4;
    // 1.5 · 2^23: adding it rounds to an integer held in the low mantissa bits
    const MAGIC: f32 = 12_582_912.0;
    let x = x.clamp(-87.0, 88.0);
    let t = x * LOG2E + MAGIC;
    let k = t - MAGIC;
    let r = x - k * LN2_HI - k * LN2_LO;
    let mut p = 1.987_569_1e-4f32;
    p = p * r + 1.398_199_9e-3;
    p = p * r + 8.333_452e-3;
    p = p * r + 4.166_579_6e-2;
    p = p * r + 1.666_666_5e-1;
    p = p * r + 0.5;
    let y = p * r * r + r + 1.0;
    // 2^k from the integer in t's mantissa (k in -126..=127 after the clamp)
    // (wrapping u32 arithmetic is the two's complement of k + 127, and has no overflow check
    // that would keep the loop from vectorising)
    let scale = f32::from_bits(t.to_bits().wrapping_sub(MAGIC.to_bits()).wrapping_add(127) << 23);
    y * scale
}

/// `[rows, cols]` row-major to `[cols, rows]`.
pub(super) fn transpose(m: &[f32], rows: usize, cols: usize) -> Vec<f32> {
    let mut t = vec![0.0; m.len()];
    for r in 0..rows {
        for c in 0..cols {
            t[c * rows + r] = m[r * cols + c];
        }
    }
    t
}

/// `first` then `second` as one map (`x W1 W2 + b1 W2 (+ b2)`), products in `f64`.
pub(super) fn compose(first: &Dense, second: &Dense, second_bias: bool) -> Dense {
    let (i, k, o) = (first.input, first.output, second.output);
    let mut w = vec![0.0f32; i * o];
    for r in 0..i {
        for c in 0..o {
            let v: f64 = (0..k).map(|j| f64::from(first.w[r * k + j]) * f64::from(second.w[j * o + c])).sum();
            w[r * o + c] = v as f32;
        }
    }
    let b = (0..o)
        .map(|c| {
            let v: f64 = (0..k).map(|j| f64::from(first.b[j]) * f64::from(second.w[j * o + c])).sum();
            (v + if second_bias { f64::from(second.b[c]) } else { 0.0 }) as f32
        })
        .collect();
    Dense { input: i, output: o, w, b }
}
