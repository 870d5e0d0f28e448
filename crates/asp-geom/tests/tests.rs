//! Integration tests of asp-geom.

mod removal;
