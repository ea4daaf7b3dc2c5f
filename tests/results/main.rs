//! The results: the report, the optimiser, budgets, sweeps, the trade-off, stability maps, scenes and fits, each the same bytes on every run.
//!
//! One test binary of the suite's groups (model, hardware, command_line, results, fuzz_corpus):
//! `cargo test --test results [NAME]` runs it; every file below is one module.

#[path = "../common/mod.rs"]
mod common;

mod budget;
mod determinism;
mod fit;
mod optimize;
mod render;
mod report;
mod stability;
mod sweep;
mod sweep_merge;
mod sweep_plan;
mod tradeoff;
