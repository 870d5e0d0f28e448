//! Graph features of assembly states (thesis 3.4): the graph of the assembled model with
//! spherical-harmonic shape descriptors on its nodes and contact edges, and the graph of a
//! disassembly state as the removability model's inputs. The contract with the Python trainer
//! and the ONNX runner is `docs/learning.md`, "The graph of a state".
//!
//! - [`GraphConfig`]: radius shells, degree, points per part, and the `features` string.
//! - [`sample`]: deterministic area-weighted surface samples `Q_{p_i}` (eq. 3.5's point sets).
//! - [`sh_descriptor`]: the rotation, translation and scale invariant descriptor `h` (eqs. 3.8-3.10).
//! - [`AssemblyGraph`]: nodes (eqs. 3.6, 3.11), contact edges (eqs. 3.5, 3.7) and their
//!   attributes (eq. 3.12), computed once per model.
//! - [`StateGraph`]: the induced subgraph of a state, laid out as `x`, `edge_index`, `edge_attr`.

mod build;
mod config;
mod descriptor;
pub mod harmonics;
mod state;

/// The surface sampler lives in [`crate::sample`] (the removal test's strict rule and the
/// fastener detector use it too); `graph::sample` stays as its old path.
pub use crate::sample::{self, sample_surface, SurfaceSample};
pub use build::{contact_directions, horizontal_frame, AssemblyGraph};
pub use config::DIRECTION_BINS;
pub use config::{GraphConfig, GraphConfigBuilder, MAX_DEGREE, MAX_POINTS_PER_PART, MAX_RADIUS_BINS};
pub use descriptor::sh_descriptor;
pub use state::StateGraph;
