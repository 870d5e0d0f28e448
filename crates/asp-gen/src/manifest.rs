//! The `manifest.json` written beside every batch: what was generated, from which seeds, with
//! which parameters, how many parts of each kind, and what the generator's own checks found.

use crate::generator::Generator;
pub use crate::generator::{Checks, PartCounts};
use serde::{Deserialize, Serialize};

/// Version of the manifest layout; bumped on incompatible changes.
pub const FORMAT_VERSION: u32 = 1;

/// One batch.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Manifest {
    /// [`FORMAT_VERSION`].
    pub format_version: u32,
    /// The generator and all its parameters (`kind`: `soma`, `classic_soma` or `profiles`).
    pub generator: Generator,
    /// The preset the parameters started from (`single-layer`, `double-layer`), if any.
    pub preset: Option<String>,
    /// The batch seed; assembly k uses [`assembly_seed`](crate::batch::assembly_seed)`(seed, k)`.
    pub seed: u64,
    /// Number of assemblies.
    pub count: usize,
    /// How many assemblies failed one of their checks (see [`Checks::passed`]).
    pub failed_checks: usize,
    /// One entry per assembly, in index order.
    pub assemblies: Vec<ManifestEntry>,
}

/// One generated assembly.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ManifestEntry {
    /// File name, relative to the manifest.
    pub file: String,
    /// Index in the batch.
    pub index: usize,
    /// The assembly's own seed.
    pub seed: u64,
    /// All parts, fixed ones included.
    pub parts: usize,
    /// Parts that stay in place (floor; bottom profiles, back posts and their connectors).
    pub fixed_parts: usize,
    /// Kind-specific part counts.
    pub counts: PartCounts,
    /// The generator's own checks.
    pub checks: Checks,
}
