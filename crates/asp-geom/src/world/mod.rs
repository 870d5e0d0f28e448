//! The collision world: an assembly prepared for removal tests, composed of parts that each
//! own one concern and can be read, tested and replaced alone (rapier composes its physics world
//! the same way):
//!
//! - [`Shapes`] (`shapes.rs`): every part's parry mesh, bounds, exact boxes, closedness and the
//!   cache of its shrunk copies, and the ground slab;
//! - [`Contacts`] (`contacts.rs`): the contact graph, the fixed parts and contact stability;
//! - [`Overlaps`] (`overlaps.rs`, measured with the contacts in `measure.rs`, classified in
//!   `classify.rs`): the input overlaps and the policy's handling of each, the fused components
//!   (`fused.rs`), and the [`Fits`] (`fits.rs`, `bearings.rs`): fits, threads and bearings;
//! - [`Pairs`] (`pairs.rs`): the exact tests of one pair (which shapes, the strict sample rule,
//!   the travel to first contact);
//! - [`Blocking`] (`blocking.rs`): the candidate directions (`directions.rs`) and the cached
//!   blocking rows;
//! - [`Removal`] (`removal.rs`, the travel in `clearance.rs`): the removal tests and the path
//!   planner's collision queries.
//!
//! `World` builds them in order (shapes, then contacts and overlaps in one measurement, then
//! fits, threads and the overlap classes, which add candidate directions) and lends them out;
//! it answers nothing itself. A new concern becomes a new component with its own file, built in
//! [`World::new`] from the ones it needs and reached through one accessor.

mod bearings;
mod blocking;
mod classify;
mod clearance;
mod contacts;
mod directions;
mod fits;
mod fused;
mod geom;
mod measure;
mod overlaps;
mod pairs;
mod removal;
mod shapes;

pub(crate) use clearance::clearance_past;
pub(crate) use removal::best_free_direction;
pub(crate) use shapes::ground_box;

pub use bearings::{find_bearings, Bearing, RollingElement};
pub use blocking::Blocking;
pub use contacts::Contacts;
pub use directions::candidate_directions;
pub use fits::Fits;
pub use overlaps::Overlaps;
pub use pairs::Pairs;
pub use removal::Removal;
pub use shapes::Shapes;

use crate::assembly::Assembly;
use crate::error::{GeomError, Result};
use crate::overlap::OverlapPolicy;
use crate::partset::PartSet;
use blocking::Rows;

/// Settings of the collision world. Lengths in metres; `None` means "relative to the model".
#[derive(Clone, Debug, PartialEq)]
pub struct WorldConfig {
    /// Contact tolerance: a motion is blocked only when it pushes a part deeper than this into
    /// another. Default `1e-4 ×` the model's diagonal.
    pub tolerance: Option<f32>,
    /// Parts closer than this are in contact (the stability graph). Default `1e-3 ×` diagonal.
    pub contact_distance: Option<f32>,
    /// How many clustered surface-normal directions join the six axis directions (each with its
    /// opposite). Default 10.
    pub normal_clusters: usize,
    /// Normals within this angle (degrees) fall into one cluster. Default 10.
    pub cluster_angle_deg: f32,
    /// Extra directions sampled evenly on the sphere (Fibonacci lattice). Default 0.
    pub sphere_directions: usize,
    /// Parts that overlap in the input are warned about and each is shrunk, in tests against the
    /// other, until it no longer crosses the other's surface — up to this fraction of its
    /// thinnest extent (default 0.4: shrinking by half the thickness would make it vanish).
    /// What a pair that overlaps beyond the tolerance may do is the policy's (next field).
    pub max_overlap_fraction: f32,
    /// How overlapping pairs are tested ([`OverlapPolicy`]): `Strict` by default (they separate
    /// only along motions that enter no new material), `Lenient` (shrink, or ignore pairs that
    /// no shrinking separates), `Error` (such pairs stop planning).
    pub overlaps: OverlapPolicy,
    /// Test pairs of parts that are known unions of boxes (voxels or boxes in their extras, or a
    /// box-shaped mesh; see [`crate::boxes`]) exactly on their boxes. Default true; false tests
    /// every pair on the meshes.
    pub exact_boxes: bool,
    /// Find threaded fasteners (bolts, screws and nuts with modelled threads, see
    /// [`crate::fastener`]) and let them leave by screwing along their axes (whose directions
    /// join the candidates). Default true; false tests threaded pairs like any other.
    pub fasteners: bool,
}

impl Default for WorldConfig {
    fn default() -> Self {
        WorldConfig {
            tolerance: None,
            contact_distance: None,
            normal_clusters: 10,
            cluster_angle_deg: 10.0,
            sphere_directions: 0,
            max_overlap_fraction: 0.4,
            overlaps: OverlapPolicy::Strict,
            exact_boxes: true,
            fasteners: true,
        }
    }
}

/// The parts of an assembly as collision objects, plus an optional ground plane.
pub struct World {
    assembly: Assembly,
    shapes: Shapes,
    contacts: Contacts,
    overlaps: Overlaps,
    rows: Rows,
    warnings: Vec<String>,
    /// The settings it was built with, `tolerance` and `contact_distance` resolved to metres.
    config: WorldConfig,
}

impl World {
    /// Prepares `assembly` for planning: welds and orients meshes, warns about open or
    /// non-manifold meshes and overlapping parts, adds a ground plane under the lowest point when
    /// no part is fixed, computes candidate directions and the contact graph.
    pub fn new(assembly: Assembly, config: &WorldConfig) -> Result<World> {
        assembly.validate()?;
        let diag = assembly.diagonal().max(f32::MIN_POSITIVE);
        let tolerance = config.tolerance.unwrap_or(DEFAULT_RELATIVE_TOLERANCE * diag);
        let contact_distance = config.contact_distance.unwrap_or(DEFAULT_RELATIVE_CONTACT * diag);
        let positive = |v: f32| v.is_finite() && v > 0.0;
        if !positive(tolerance) || !positive(contact_distance) {
            return Err(GeomError::config("tolerance and contact distance must be positive"));
        }
        let mut warnings = assembly.warnings.clone();
        let (shapes, found) = Shapes::build(&assembly, config.exact_boxes, tolerance)?;
        warnings.extend(found);
        let n = assembly.len();
        let fixed =
            PartSet::from_indices(n + 1, assembly.parts.iter().enumerate().filter(|(_, p)| p.fixed).map(|(i, _)| i).chain(shapes.ground()));
        let mut directions = candidate_directions(&assembly, config);
        let measured = measure::measure(&assembly, &shapes, contact_distance, config.max_overlap_fraction, config.overlaps)?;
        let contacts = Contacts::new(measured.sets, contact_distance, fixed);
        let mut overlaps = measured.overlaps;
        warnings.extend(measured.warnings);
        if config.fasteners {
            overlaps.fits.find(&assembly, &shapes, &contacts, &overlaps.notes, &mut directions);
        }
        // after the fits: a pair with a fit is one
        classify::classify_overlaps(&mut overlaps, &shapes, contact_distance, &mut directions, measured.regions);
        overlaps.fused = fused::fused_components(&assembly, &overlaps.notes, overlaps.fits.bearings());
        warnings.extend(fused::fused_warnings(&assembly, &overlaps.fused));
        // the shrunk meshes the removal tests will ask for, built here once and in parallel: the
        // first removal test of a part is then the sweeps alone (one erosion of a 25k triangle
        // mesh costs several times a whole blocking row)
        shapes.erode_all(overlaps.wanted_erosions(&shapes, n));
        let rows = Rows::new(directions, n);
        let config = WorldConfig { tolerance: Some(tolerance), contact_distance: Some(contact_distance), ..config.clone() };
        Ok(World { assembly, shapes, contacts, overlaps, rows, warnings, config })
    }

    /// This world under the lenient overlap policy ([`OverlapPolicy::Lenient`]): the same
    /// geometry, directions, contacts, threads and measured overlaps (shared, not measured
    /// again), only the tests of overlapping pairs differ — a pair some shrinking separates is
    /// tested with one part shrunk, a gross pair ignores their collisions. The same as
    /// [`World::new`] with that policy, at the cost of a copy (blocking rows are computed anew).
    pub fn lenient(&self) -> World {
        World {
            assembly: self.assembly.clone(),
            shapes: self.shapes.share(),
            contacts: self.contacts.clone(),
            overlaps: self.overlaps.lenient(),
            rows: Rows::new(self.rows.directions.clone(), self.num_parts()),
            warnings: self.warnings.clone(),
            config: WorldConfig { overlaps: OverlapPolicy::Lenient, ..self.config.clone() },
        }
    }

    /// The assembly this world was built from.
    pub fn assembly(&self) -> &Assembly {
        &self.assembly
    }

    /// Number of real parts (the ground, when present, has index `num_parts()`).
    pub fn num_parts(&self) -> usize {
        self.assembly.len()
    }

    /// The name of part `i` (`ground` for the virtual ground).
    pub fn name(&self, i: usize) -> &str {
        self.assembly.parts.get(i).map(|p| p.name.as_str()).unwrap_or("ground")
    }

    /// The settings this world was built with (tolerance and contact distance in metres).
    pub fn config(&self) -> &WorldConfig {
        &self.config
    }

    /// Warnings found while preparing (open meshes, overlaps), one line each.
    pub fn warnings(&self) -> &[String] {
        &self.warnings
    }

    /// The parts' collision shapes.
    pub fn shapes(&self) -> &Shapes {
        &self.shapes
    }

    /// The contact graph and the fixed parts.
    pub fn contacts(&self) -> &Contacts {
        &self.contacts
    }

    /// The input overlaps and their handling, with the fits, threads and bearings.
    pub fn overlaps(&self) -> &Overlaps {
        &self.overlaps
    }

    /// The candidate directions and the blocking relation.
    pub fn blocking(&self) -> Blocking<'_> {
        Blocking { pairs: Pairs { shapes: &self.shapes, overlaps: &self.overlaps }, rows: &self.rows }
    }

    /// The removal tests and the collision queries along a motion.
    pub fn removal(&self) -> Removal<'_> {
        Removal { blocking: self.blocking(), contacts: &self.contacts, up: self.assembly.up.vector() }
    }
}

/// Default contact tolerance ([`WorldConfig::tolerance`], [`crate::distmap::MapConfig`]),
/// relative to the assembly's diagonal.
pub const DEFAULT_RELATIVE_TOLERANCE: f32 = 1e-4;
/// Default contact distance of the contact graph ([`WorldConfig::contact_distance`], the maps'),
/// relative to the diagonal.
pub const DEFAULT_RELATIVE_CONTACT: f32 = 1e-3;
