//! Analyses over the reference models: the paper reproduction.
pub mod methods;
pub mod paper;
