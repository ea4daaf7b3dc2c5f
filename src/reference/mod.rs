//! The f64 reference: lobe models, minimax constants, normalisation and quadrature.
//!
//! **Invariant:** nothing here uses fixed-point types; this module is the oracle that every
//! fixed-point result is compared with.

pub mod lobe;
pub mod method;
pub mod minimax;
pub mod normalisation;
pub mod quadrature;
