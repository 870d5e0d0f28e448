#![doc = include_str!("../README.md")]

pub mod error;
pub mod model;
pub mod ordering;

pub use error::{LearnError, Result};
pub use model::{RemovabilityModel, ShapePolicy};
pub use ordering::{GnnFactory, GnnOrdering, GnnSource, SHIPPED_MODEL};
