//! Analyses over the reference and the datapath: the paper reproduction, method errors, and
//! exhaustive accuracy checks.
mod accumulate;
pub mod budget;
pub mod budget_expr;
pub mod check;
pub mod cluster;
mod column;
pub mod frontier;
pub mod furnace;
pub mod gappa;
pub mod methods;
pub mod optimize;
pub mod paper;
pub mod stability;
pub mod sweep;
pub mod tradeoff;

/// One lsb8: 2^-8 of the lobe's peak, one step of an 8-bit display; the unit every error
/// figure of the lobe is printed in.
pub const LSB8: f64 = 1.0 / 256.0;
