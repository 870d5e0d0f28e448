//! How distance maps are computed: limits, defaults, the gravity rule and [`MapConfig`].

use crate::assembly::Assembly;
use crate::error::{GeomError, Result};
use crate::overlap::OverlapPolicy;
use crate::world::WorldConfig;

/// Largest supported map resolution `N_M` (`N_M² ≤ 256` directions fit a [`DirMask`](super::DirMask)).
pub const MAX_RESOLUTION: usize = 15;
/// Default map resolution `N_M` (the thesis does not state its value): 9 × 9 = 81 directions.
pub const DEFAULT_RESOLUTION: usize = 9;
/// Largest number of parts distance maps are built for.
pub const MAX_PARTS: usize = 255;
/// The default tolerance and contact distance are the collision world's: one constant each.
pub use crate::world::{DEFAULT_RELATIVE_CONTACT, DEFAULT_RELATIVE_TOLERANCE};

/// Which states stand (the gravity check).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Support {
    /// Thesis 6.3.2: every present part rests on a present part or the floor directly beneath it
    /// — it cannot move along gravity at all (`M(p_j, p_i)(up) = 0`). Fixed parts always stand.
    #[default]
    Below,
    /// The collision world's rule ([`crate::StabilityMode::ContactGraph`]): every present part
    /// is linked through contacts (parts within the contact distance) to a fixed part, or to the
    /// floor when no part is fixed.
    ContactGraph,
}

/// How distance maps are computed. Build with [`MapConfig::builder`].
#[derive(Clone, Debug, PartialEq)]
pub struct MapConfig {
    pub(super) resolution: usize,
    pub(super) d_max: Option<f32>,
    pub(super) tolerance: Option<f32>,
    pub(super) contact_distance: Option<f32>,
    pub(super) support: Support,
    pub(super) exact_boxes: bool,
    pub(super) overlaps: OverlapPolicy,
}

impl Default for MapConfig {
    fn default() -> Self {
        MapConfig {
            resolution: DEFAULT_RESOLUTION,
            d_max: None,
            tolerance: None,
            contact_distance: None,
            support: Support::Below,
            exact_boxes: true,
            overlaps: OverlapPolicy::Strict,
        }
    }
}

impl MapConfig {
    /// The settings of the collision world the maps of `assembly` build for their mesh parts
    /// (tolerance and contact distance resolved to metres): give a world built with them to
    /// [`crate::distmap::DistanceMaps::build_on`].
    pub fn world_config(&self, assembly: &Assembly) -> WorldConfig {
        let diag = assembly.diagonal();
        let tolerance = self.tolerance.unwrap_or(DEFAULT_RELATIVE_TOLERANCE * diag);
        let contact_distance = self.contact_distance.unwrap_or(DEFAULT_RELATIVE_CONTACT * diag);
        WorldConfig {
            tolerance: Some(tolerance.max(f32::MIN_POSITIVE)),
            contact_distance: Some(contact_distance.max(f32::MIN_POSITIVE)),
            overlaps: self.overlaps,
            exact_boxes: self.exact_boxes,
            ..WorldConfig::default()
        }
    }

    /// A builder starting from the defaults.
    pub fn builder() -> MapConfigBuilder {
        MapConfigBuilder { config: MapConfig::default() }
    }

    /// `N_M`: the maps have `N_M × N_M` directions.
    pub fn resolution(&self) -> usize {
        self.resolution
    }

    /// The cap on distances in metres (`None`: the assembly's diagonal).
    pub fn d_max(&self) -> Option<f32> {
        self.d_max
    }

    /// The contact tolerance in metres (`None`: 1e-4 × the assembly's diagonal).
    pub fn tolerance(&self) -> Option<f32> {
        self.tolerance
    }

    /// The contact distance of the contact graph in metres (`None`: 1e-3 × the diagonal).
    pub fn contact_distance(&self) -> Option<f32> {
        self.contact_distance
    }

    /// The gravity check.
    pub fn support(&self) -> Support {
        self.support
    }

    /// How mesh parts that overlap in the input are tested ([`OverlapPolicy`], default strict).
    pub fn overlaps(&self) -> OverlapPolicy {
        self.overlaps
    }
}

/// Builder of [`MapConfig`]; [`MapConfigBuilder::build`] validates.
#[derive(Clone, Debug)]
pub struct MapConfigBuilder {
    config: MapConfig,
}

impl MapConfigBuilder {
    /// `N_M` (odd, 3..=15; default 9).
    pub fn resolution(mut self, n: usize) -> Self {
        self.config.resolution = n;
        self
    }

    /// The cap `d_max` in metres (default: the assembly's bounding-box diagonal).
    pub fn d_max(mut self, d_max: f32) -> Self {
        self.config.d_max = Some(d_max);
        self
    }

    /// The contact tolerance in metres (default: 1e-4 × the diagonal): how deep a motion may push
    /// into another part before it counts as a collision on meshes.
    pub fn tolerance(mut self, tolerance: f32) -> Self {
        self.config.tolerance = Some(tolerance);
        self
    }

    /// Parts closer than this (metres) are in contact for [`Support::ContactGraph`] (default
    /// 1e-3 × the diagonal).
    pub fn contact_distance(mut self, distance: f32) -> Self {
        self.config.contact_distance = Some(distance);
        self
    }

    /// The gravity check (default [`Support::Below`], the thesis' rule).
    pub fn support(mut self, support: Support) -> Self {
        self.config.support = support;
        self
    }

    /// How mesh parts that overlap in the input are tested (default [`OverlapPolicy::Strict`]:
    /// the maps' distance of such a pair is also limited by the strict rule).
    pub fn overlaps(mut self, policy: OverlapPolicy) -> Self {
        self.config.overlaps = policy;
        self
    }

    /// Whether parts that are unions of boxes (voxels, listed boxes, one-box meshes) are swept
    /// as exact boxes; off, every part is swept as a mesh. The collision world's
    /// `WorldConfig::exact_boxes`, one flag for both (default true).
    pub fn exact_boxes(mut self, yes: bool) -> Self {
        self.config.exact_boxes = yes;
        self
    }

    /// Checks the values.
    pub fn build(self) -> Result<MapConfig> {
        let c = self.config;
        let r = c.resolution;
        if !(3..=MAX_RESOLUTION).contains(&r) || r.is_multiple_of(2) {
            return Err(GeomError::config(format!("distance map resolution must be odd and within 3..={MAX_RESOLUTION}, got {r}")));
        }
        if let Some(d) = c.d_max {
            if !(d.is_finite() && d > 0.0) {
                return Err(GeomError::config(format!("d_max must be positive, got {d}")));
            }
        }
        if let Some(t) = c.tolerance {
            if !(t.is_finite() && t >= 0.0) {
                return Err(GeomError::config(format!("tolerance must be >= 0, got {t}")));
            }
        }
        if let Some(t) = c.contact_distance {
            if !(t.is_finite() && t > 0.0) {
                return Err(GeomError::config(format!("contact distance must be positive, got {t}")));
            }
        }
        Ok(c)
    }
}
