//! Integration tests of the `asp` binary (the real executable).

mod cli;
mod optimise;
mod viz;
