//! [`GraphConfig`]: the parameters of the graph features, and the `features` string that names them.

use crate::error::{GeomError, Result};

/// Floats of an edge's contact directions (`+u1, +u2, −u1, −u2, +up, −up`).
pub const DIRECTION_BINS: usize = 6;

/// The largest spherical-harmonic degree asp evaluates (the recurrences are tested to here).
pub const MAX_DEGREE: usize = 20;
/// The most radius shells a descriptor may have.
pub const MAX_RADIUS_BINS: usize = 64;
/// The most sample points per part a configuration may ask for.
pub const MAX_POINTS_PER_PART: usize = 1 << 20;

/// Parameters of the graph features (`docs/learning.md`, thesis 3.4.2). A model trained on one
/// configuration only runs on features of the same configuration: compare [`GraphConfig::features`].
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct GraphConfig {
    /// Radius shells of the descriptor (thesis: the bins of `r`). Default 8.
    pub radius_bins: usize,
    /// Highest spherical-harmonic degree `L` (thesis eq. 3.8). Default 8.
    pub degree: usize,
    /// Target number of surface sample points per part (every triangle with area gets at least
    /// one, so a finely meshed part may get more). Default 2048.
    pub points_per_part: usize,
    /// Whether edges carry the six contact directions (feature set `asp-graph/2`; without them
    /// `asp-graph/1`, the features of models trained before). Default true.
    pub contact_directions: bool,
}

impl Default for GraphConfig {
    fn default() -> Self {
        GraphConfig { radius_bins: 8, degree: 8, points_per_part: 2048, contact_directions: true }
    }
}

impl GraphConfig {
    /// A builder starting from the defaults; [`GraphConfigBuilder::build`] validates.
    pub fn builder() -> GraphConfigBuilder {
        GraphConfigBuilder { config: GraphConfig::default() }
    }

    /// Checks the ranges: `1..=64` radius bins, degree `0..=20`, `1..=2^20` points per part.
    pub fn validate(&self) -> Result<()> {
        if !(1..=MAX_RADIUS_BINS).contains(&self.radius_bins) {
            return Err(GeomError::config(format!("graph radius_bins must be 1..={MAX_RADIUS_BINS}, got {}", self.radius_bins)));
        }
        if self.degree > MAX_DEGREE {
            return Err(GeomError::config(format!("graph degree must be 0..={MAX_DEGREE}, got {}", self.degree)));
        }
        if !(1..=MAX_POINTS_PER_PART).contains(&self.points_per_part) {
            return Err(GeomError::config(format!(
                "graph points_per_part must be 1..={MAX_POINTS_PER_PART}, got {}",
                self.points_per_part
            )));
        }
        Ok(())
    }

    /// The name of the feature set with its parameters, e.g.
    /// `asp-graph/2 radius_bins=8 degree=8 points=2048`. Models record it; asp refuses a model
    /// whose string differs from the features it computes.
    pub fn features(&self) -> String {
        format!(
            "asp-graph/{} radius_bins={} degree={} points={}",
            if self.contact_directions { 2 } else { 1 },
            self.radius_bins,
            self.degree,
            self.points_per_part
        )
    }

    /// The configuration a features string names (`asp-graph/1` or `/2` with its three
    /// parameters), or `None` when it names no valid configuration.
    pub fn from_features(features: &str) -> Option<GraphConfig> {
        let mut words = features.split_whitespace();
        let contact_directions = match words.next()? {
            "asp-graph/1" => false,
            "asp-graph/2" => true,
            _ => return None,
        };
        let mut config = GraphConfig { contact_directions, ..GraphConfig::default() };
        let mut seen = 0;
        for w in words {
            let (key, value) = w.split_once('=')?;
            let value: usize = value.parse().ok()?;
            match key {
                "radius_bins" => config.radius_bins = value,
                "degree" => config.degree = value,
                "points" => config.points_per_part = value,
                _ => return None,
            }
            seen += 1;
        }
        (seen == 3 && config.validate().is_ok() && config.features() == features).then_some(config)
    }

    /// Length `D` of one descriptor: `radius_bins × (degree + 1)` (72 by default).
    pub fn descriptor_dim(&self) -> usize {
        self.radius_bins * (self.degree + 1)
    }

    /// Length of a node's attributes: `D + 2` (descriptor, `fixed`, `on_base`).
    pub fn node_dim(&self) -> usize {
        self.descriptor_dim() + 2
    }

    /// Length of an edge's attributes: `2D + 8` (two descriptors, six contact directions,
    /// `above`, `normal_up`), `2D + 2` without contact directions.
    pub fn edge_dim(&self) -> usize {
        let directions = if self.contact_directions { DIRECTION_BINS } else { 0 };
        2 * self.descriptor_dim() + directions + 2
    }
}

/// Builds a validated [`GraphConfig`].
#[derive(Clone, Debug)]
pub struct GraphConfigBuilder {
    config: GraphConfig,
}

impl GraphConfigBuilder {
    /// Sets [`GraphConfig::radius_bins`].
    pub fn radius_bins(mut self, bins: usize) -> Self {
        self.config.radius_bins = bins;
        self
    }

    /// Sets [`GraphConfig::degree`].
    pub fn degree(mut self, degree: usize) -> Self {
        self.config.degree = degree;
        self
    }

    /// Sets [`GraphConfig::points_per_part`].
    pub fn points_per_part(mut self, points: usize) -> Self {
        self.config.points_per_part = points;
        self
    }

    /// The configuration, or a [`GeomError::Config`] naming the value out of range.
    pub fn build(self) -> Result<GraphConfig> {
        self.config.validate()?;
        Ok(self.config)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_name_the_contract_features() {
        let c = GraphConfig::default();
        assert_eq!(c.features(), "asp-graph/2 radius_bins=8 degree=8 points=2048");
        assert_eq!((c.descriptor_dim(), c.node_dim(), c.edge_dim()), (72, 74, 152));
        let c = GraphConfig::builder().radius_bins(4).degree(3).points_per_part(100).build().unwrap();
        assert_eq!(c.features(), "asp-graph/2 radius_bins=4 degree=3 points=100");
        assert_eq!((c.descriptor_dim(), c.node_dim(), c.edge_dim()), (16, 18, 40));
        let old = GraphConfig { contact_directions: false, ..GraphConfig::default() };
        assert_eq!(old.features(), "asp-graph/1 radius_bins=8 degree=8 points=2048");
        assert_eq!(old.edge_dim(), 146);
        for config in [c, old, GraphConfig::default()] {
            assert_eq!(GraphConfig::from_features(&config.features()), Some(config));
        }
        for bad in [
            "asp-graph/3 radius_bins=8 degree=8 points=2048",
            "asp-graph/2 radius_bins=8 degree=8",
            "asp-graph/2 radius_bins=0 degree=8 points=2048",
            "tiny/1",
        ] {
            assert_eq!(GraphConfig::from_features(bad), None, "{bad}");
        }
    }

    #[test]
    fn nonsense_is_rejected_with_the_field_named() {
        let e = GraphConfig::builder().radius_bins(0).build().unwrap_err().to_string();
        assert!(e.contains("radius_bins"), "{e}");
        let e = GraphConfig::builder().degree(21).build().unwrap_err().to_string();
        assert!(e.contains("degree"), "{e}");
        let e = GraphConfig::builder().points_per_part(0).build().unwrap_err().to_string();
        assert!(e.contains("points_per_part"), "{e}");
        assert!(GraphConfig::builder().degree(0).radius_bins(1).points_per_part(1).build().is_ok());
    }
}
