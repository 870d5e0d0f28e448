//! Integration tests of the `asp` binary (the real executable).

mod cli;
mod hostile;
mod optimise;
mod viz;
