//! The model, through the library: the datapath against independent oracles, the batch engine, the cycle model, the f64 reference, the minimax table, the paper and the white furnace.
//!
//! One test binary of the suite's groups (model, hardware, command_line, results, fuzz_corpus):
//! `cargo test --test model [NAME]` runs it; every file below is one module.

#[path = "../common/mod.rs"]
mod common;

mod baseline_oracle;
mod batch_edges;
mod check_oracle;
mod cycle_model;
mod datapath_props;
mod depth;
mod engine;
mod furnace;
mod layers;
mod minimax;
mod one_place;
mod oracle;
mod pairs;
mod paper;
mod ports;
mod properties;
