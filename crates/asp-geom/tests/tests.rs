//! The one integration test binary of asp-geom.

mod distmap;
mod loaders;
mod physics;
mod removal;
