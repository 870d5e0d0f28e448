//! The `manifest.json` written beside every batch: what was generated, from which seeds, with
//! which parameters, how many parts of each kind, and what the generator's own checks found.

use crate::batch::Generator;
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

/// Part counts by kind.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", tag = "kind")]
pub enum PartCounts {
    /// A Soma cube.
    Soma {
        /// Pieces (parts other than the floor).
        pieces: usize,
        /// How many pieces have 1, 2, 3 and 4 cells.
        piece_sizes: [usize; 4],
    },
    /// An aluminium profile assembly.
    Profiles {
        /// All profiles.
        profiles: usize,
        /// Profiles that are not fixed.
        removable_profiles: usize,
        /// U-shaped connectors (under horizontal profiles).
        u_connectors: usize,
        /// O-shaped connectors (around vertical profiles).
        o_connectors: usize,
        /// Grasp points over all profiles.
        grasp_points: usize,
    },
}

/// What the generator verified on its own geometry (voxels or boxes), before any planner.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Checks {
    /// The assembled state is contact-linked to the fixed parts.
    pub contact_linked: bool,
    /// Every non-fixed part comes out along a ±axis straight line, one after the other (exact).
    pub straight_line_disassemblable: bool,
    /// Parts that no ±axis motion frees once everything else that can leave has left.
    pub stuck_parts: Vec<String>,
    /// A top-down removal order was found in which every state stays contact-linked.
    pub stable_order_found: bool,
    /// Deepest interpenetration of two parts in metres (boxes of profile assemblies; 0 for
    /// Soma cubes, whose cells cannot overlap).
    pub max_penetration: f64,
}

impl Checks {
    /// Whether every check passed.
    pub fn passed(&self) -> bool {
        self.contact_linked && self.straight_line_disassemblable && self.stable_order_found
    }
}
