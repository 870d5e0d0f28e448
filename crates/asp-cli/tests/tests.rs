//! Integration tests of the `asp` binary (the real executable).

mod check;
mod cli;
mod hostile;
mod optimise;
mod viz;
