//! specfx: a bit-accurate model of a division-free fixed-point specular (cos^n) datapath.
//!
//! Phong-type highlights need cos^n. The datapath modelled here replaces it by
//! `cs_m(c, n) = max(0, (n/m)(c - 1) + 1)^m` with m = 2^k squarings (k = 4 in the paper by
//! Romanyuk, Pavlov and Abramchuk, 2016), times an energy-conserving coefficient coef(n).
//!
//! - [`reference`](mod@reference): the f64 oracle (lobes, minimax constants, normalisation,
//!   quadrature).
//! - [`analysis`]: computations over the reference, such as the reproduction of the paper.
//! - [`report`]: renders results as text tables into any writer.
//!
//! # Examples
//! ```
//! use specfx::reference::lobe::{cos_pow, cs_m, Cutoff};
//! let (c, n) = (0.99, 128.0);
//! let approx = cs_m(c, n, 4, Cutoff::Clamp);
//! assert!((approx - cos_pow(c, n)).abs() < 0.02);
//! ```

#![warn(missing_docs)]

pub mod analysis;
pub mod csv_dialect;
pub mod cycle;
pub mod engine;
pub mod error;
pub mod fixed;
pub mod golden;
pub mod hdl;
pub mod input;
mod names;
pub mod nset;
pub mod output;
pub mod pipeline;
pub mod provenance;
pub mod reference;
pub mod report;
pub mod scene;
pub mod tools;

pub use error::Error;
