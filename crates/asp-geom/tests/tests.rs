//! The one integration test binary of asp-geom.

mod distmap;
mod fastener;
mod fuzz;
mod graph;
mod grid;
mod loaders;
mod overlap;
mod physics;
mod removal;
