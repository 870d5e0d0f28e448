//! The one integration test binary of asp-geom.

mod loaders;
mod physics;
mod removal;
