#![doc = include_str!("../README.md")]

pub mod error;
pub mod model;

pub use error::{LearnError, Result};
pub use model::{RemovabilityModel, ShapePolicy};
