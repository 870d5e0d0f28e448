//! What asp's integration tests share, so that each exists once: the independent re-check of a
//! plan ([`verify`]: every step swept in small increments with static intersection tests, not
//! the planner's sweeps or caches), the independent re-check of a robot removal ([`robot`]) and
//! the test assemblies with known answers ([`fixtures`]). A dev-dependency of every crate whose
//! tests plan; never published, and never a dependency of the library crates.

pub mod fixtures;
pub mod robot;
pub mod verify;
