//! The command line's contract, through the binary: outputs, errors, bad input, inputs never destroyed, child processes, provenance, a real Slurm cluster.
//!
//! One test binary of the suite's groups (model, hardware, command_line, results, fuzz_corpus):
//! `cargo test --test command_line [NAME]` runs it; every file below is one module.

#[path = "../common/mod.rs"]
mod common;

mod arch;
mod calibrate_shards;
mod children;
mod cli;
mod cli_datapath;
mod cli_ux;
mod inputs;
mod provenance;
mod robustness;
mod slurm;
