//! Analyses over the reference and the datapath: the paper reproduction, method errors, and
//! exhaustive accuracy checks.
pub mod budget;
pub mod check;
pub mod furnace;
pub mod gappa;
pub mod methods;
pub mod optimize;
pub mod paper;
pub mod stability;
pub mod sweep;
pub mod tradeoff;
