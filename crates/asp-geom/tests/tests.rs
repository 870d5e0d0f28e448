//! Integration tests of asp-geom.

mod physics;
mod removal;
