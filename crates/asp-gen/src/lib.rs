#![doc = include_str!("../README.md")]

pub mod batch;
pub mod check;
pub mod cuboid;
pub mod error;
pub mod generator;
pub mod manifest;
pub mod profiles;
pub mod soma;
pub mod stress;

pub use batch::{assembly_seed, generate_batch, write_batch, Batch, Generated, Generator};
pub use check::DisassemblyCheck;
pub use error::{GenError, Result};
pub use manifest::{Manifest, ManifestEntry};
pub use profiles::{ConnectorMode, ProfileAssembly, ProfileParams};
pub use soma::{SomaCube, SomaParams};
pub use stress::{StressCase, StressKind, StressParams};
