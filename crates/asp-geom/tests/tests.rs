//! Integration tests of asp-geom (one binary; modules in subfolders).

mod distmap;
