#![doc = include_str!("../README.md")]

pub mod error;
pub mod instructions;
pub mod mcap;
pub mod plot;
pub mod render;
pub mod scene;
pub mod view;

pub use error::{Result, VizError};
pub use scene::{Insertion, Move, Scene, Step, MOVE_TIME};
