//! Helpers shared by the integration tests that drive the built `specfx` binary.

use std::process::{Command, Output};

/// Runs the built `specfx` binary with `args` and returns its output.
pub fn specfx(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_specfx"))
        .args(args)
        .output()
        .expect("the specfx binary runs")
}
