//! 2½D distance maps (thesis 6.3.1): for every ordered pair of parts `(p_i, p_j)`, how far `p_i`
//! can translate along each direction of a sampled half sphere before it penetrates `p_j`, capped
//! at `d_max`. From the maps follow collision-free removal (6.3.2, eq. 6.5), the gravity check
//! (6.3.2), the accessibility objective (6.6) and the binary maps of the direction-change
//! objective (6.8).
//!
//! # Directions
//! The half sphere points away from gravity (around the assembly's up axis). An `N_M × N_M` grid
//! `(k, l)` of the square `[-1, 1]²` is mapped onto it with the hemi-octahedral map: the square's
//! centre is straight up, its border the horizon, its corners the four horizontal axes. With an
//! odd `N_M` (required) the five axis directions `up, ±e1, ±e2` are all samples, every sample is
//! distinct, and the set is symmetric (`-m` is a sample for every horizontal `m`).
//!
//! # The floor
//! The floor is a part (index [`DistanceMaps::floor`] = number of parts): a half space below the
//! lowest point of the assembly. No half-sphere direction moves a part into it, so `M(p_i, floor)`
//! is `d_max` everywhere; `M(floor, p_i)` — how far the floor can rise along `m` before touching
//! `p_i` — is what the gravity check reads. Because `M(p_j, p_i)(m)` equals how far `p_i` can move
//! along `-m` relative to `p_j`, the pair of maps also answers questions about downward motion:
//! part `i` is *supported* in state `s` when some present `p_j` (or the floor) has
//! `M(p_j, p_i)(up) = 0`, i.e. `p_i` cannot move down at all.
//!
//! # Geometry
//! * **Boxes (exact).** Parts that carry voxels (`extras.asp.cells`, as the Soma generator
//!   writes them) or boxes (`extras.asp.boxes`, as the profile generator writes them), or whose
//!   mesh is a single axis-aligned box, are unions of boxes ([`crate::boxes`]). Distances are
//!   exact box sweeps; voxels on a shared grid are swept in integer grid coordinates, so touching
//!   faces are exactly zero and sliding is exactly free.
//! * **Meshes.** Other parts use exact triangle sweeps ([`crate::sweep`]): the moving part is eroded by the contact
//!   tolerance (so touching faces do not count as collisions, see `research/parry-removal-test.md`)
//!   and cast against the other part's surface; the tolerance is added back to the distance.
//!
//! # Removability and stability
//! `p_i` is collision-free in state `s` when its minimum map `M̄(p_i, s)` (eq. 6.4) reaches
//! `d_max` in at least one direction. The thesis writes `> d_max`; with values capped at `d_max`
//! we write `>= d_max`, which with the default `d_max` (the assembly's diagonal, the longest
//! possible overlap of two parts inside its box) means "never collides". Fixed parts are always
//! supported and never removed.

mod build;
mod checker;
mod config;
mod dirmask;
mod hemisphere;
mod index;
mod maps;
mod state;
#[cfg(test)]
mod tests;

pub use checker::MapChecker;
pub use config::{
    MapConfig, MapConfigBuilder, Support, DEFAULT_RELATIVE_CONTACT, DEFAULT_RELATIVE_TOLERANCE, DEFAULT_RESOLUTION, MAX_PARTS,
    MAX_RESOLUTION,
};
use dirmask::Bits;
pub use dirmask::DirMask;
pub use hemisphere::Hemisphere;
pub use maps::{DistanceMaps, PartGeometry};
pub use state::{MapCounters, MapState};
