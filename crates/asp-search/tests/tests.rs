//! Integration tests of asp-search.

mod conformance;
mod real;
mod verify;
