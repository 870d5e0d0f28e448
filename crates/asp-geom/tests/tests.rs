//! The one integration test binary of asp-geom.

mod bearings;
mod distmap;
mod fastener;
mod fits;
mod fuzz;
mod graph;
mod loaders;
mod overlap;
mod physics;
mod removal;
mod step;
