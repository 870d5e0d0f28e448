//! Integration tests of asp-search.

mod conformance;
mod verify;
