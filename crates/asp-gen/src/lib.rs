#![doc = include_str!("../README.md")]

pub mod check;
pub mod cuboid;
pub mod error;
pub mod profiles;
pub mod soma;

pub use check::DisassemblyCheck;
pub use error::{GenError, Result};
pub use profiles::{ProfileAssembly, ProfileParams};
pub use soma::{SomaCube, SomaParams};
