//! Integration tests of asp-robot.

mod robot;
