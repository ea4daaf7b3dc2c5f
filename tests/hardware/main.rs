//! The hardware: the reference Verilog in real simulators (co-simulation, cocotb, lint, mutants, traces), yosys and nextpnr figures, the calibration, golden vectors and their manifest.
//!
//! One test binary of the suite's groups (model, hardware, command_line, results, fuzz_corpus):
//! `cargo test --test hardware [NAME]` runs it; every file below is one module.

#[path = "../common/mod.rs"]
mod common;

mod c_abi;
mod calibration;
mod cli_hw;
mod cocotb;
mod cosim;
mod dpi;
mod fusesoc;
mod lint;
mod mutation;
mod python;
mod timing;
mod trace;
mod vectors;
mod vectors_manifest;
