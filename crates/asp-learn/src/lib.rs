#![doc = include_str!("../README.md")]

pub mod error;
pub mod model;
pub mod ordering;
pub mod qfunction;
pub mod qnet;

pub use error::{LearnError, Result};
pub use model::{Checker, GraphModel, ModelKind, RemovabilityModel, ShapePolicy};
pub use ordering::{
    shipped_model, GnnFactory, GnnOrdering, GnnSource, ShippedModel, SHIPPED_MODEL, SHIPPED_MODELS, SHIPPED_PHYSICS_MODEL,
    SHIPPED_ROBOT_MODEL,
};
pub use qfunction::{epsilon_greedy, epsilon_greedy_models, open_q_models, shipped_q, OnnxQ, QProduct, SHIPPED_Q, SHIPPED_Q_NAME};
