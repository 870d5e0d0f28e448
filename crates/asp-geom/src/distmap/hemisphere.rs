//! The sampled half sphere of directions (the hemi-octahedral map).

use super::MAX_RESOLUTION;
use crate::error::{GeomError, Result};
use crate::math::{Axis, Vec3};

/// The `N_M × N_M` directions sampled on the half sphere around the up axis.
#[derive(Clone, Debug)]
pub struct Hemisphere {
    resolution: usize,
    up: Vec3,
    directions: Vec<Vec3>,
}

impl Hemisphere {
    /// Samples `resolution × resolution` directions (odd, 3..=15) around `up`.
    pub fn new(resolution: usize, up: Axis) -> Result<Self> {
        if !(3..=MAX_RESOLUTION).contains(&resolution) || resolution.is_multiple_of(2) {
            return Err(GeomError::config(format!(
                "distance map resolution must be odd and within 3..={MAX_RESOLUTION}, got {resolution}"
            )));
        }
        let upv = up.vector();
        let e1 = Axis { index: (up.index + 1) % 3, negative: false }.vector();
        let e2 = Axis { index: (up.index + 2) % 3, negative: up.negative }.vector();
        let step = 2.0 / (resolution - 1) as f64;
        let mut directions = Vec::with_capacity(resolution * resolution);
        for k in 0..resolution {
            for l in 0..resolution {
                let u = -1.0 + step * k as f64;
                let v = -1.0 + step * l as f64;
                let px = (u + v) / 2.0;
                let py = (u - v) / 2.0;
                let pz = (1.0 - px.abs() - py.abs()).max(0.0);
                let norm = (px * px + py * py + pz * pz).sqrt();
                let snap = |c: f64| if c.abs() < 1e-9 { 0.0 } else { c / norm };
                let (x, y, z) = (snap(px) as f32, snap(py) as f32, snap(pz) as f32);
                directions.push(e1 * x + e2 * y + upv * z);
            }
        }
        Ok(Hemisphere { resolution, up: upv, directions })
    }

    /// `N_M`.
    pub fn resolution(&self) -> usize {
        self.resolution
    }

    /// Number of directions, `N_M²`.
    pub fn len(&self) -> usize {
        self.directions.len()
    }

    /// Whether there are no directions (never: the resolution is at least 3).
    pub fn is_empty(&self) -> bool {
        self.directions.is_empty()
    }

    /// The unit directions, indexed `k * N_M + l`.
    pub fn directions(&self) -> &[Vec3] {
        &self.directions
    }

    /// The index of grid cell `(k, l)`.
    pub fn index(&self, k: usize, l: usize) -> usize {
        k * self.resolution + l
    }

    /// The index of the straight-up direction (the grid's centre).
    pub fn up_index(&self) -> usize {
        let c = self.resolution / 2;
        self.index(c, c)
    }

    /// The up vector.
    pub fn up(&self) -> Vec3 {
        self.up
    }

    /// The index of the sample closest to `direction` (which need not be normalised).
    pub fn nearest(&self, direction: Vec3) -> usize {
        let d = direction.normalize_or_zero();
        let mut best = (f32::NEG_INFINITY, 0);
        for (i, m) in self.directions.iter().enumerate() {
            let c = m.dot(d);
            if c > best.0 {
                best = (c, i);
            }
        }
        best.1
    }
}
