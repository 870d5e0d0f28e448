//! Integration tests of asp-viz on planned fixtures.

mod common;
mod mcap_file;
mod moves;
mod page;
mod plots;
mod storyboard;
