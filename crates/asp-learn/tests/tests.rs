//! Integration tests of asp-learn (one binary; modules in folders).

mod model;
mod ordering;
mod qfunction;
