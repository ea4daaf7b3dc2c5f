//! The configurable datapath and its bit-accurate functional model (stages, probes).
//!
//! One evaluation follows the hardware exactly (see `docs/arithmetic.md`):
//!
//! 1. `c`: the input cosine in its format; codes above 1.0 are clamped to 1.0.
//! 2. `d = c - 1`, exact.
//! 3. `t = d * slope`: slope n/m (a product with n and a shift by k) or A(n); the exact product
//!    is quantized to t's format with t's rounding and overflow.
//! 4. `b = t + offset` (offset 1, or A(n) + B(n)), exact, then the cutoff (`clamp`: a negative
//!    base becomes 0; `paper`: inputs below a per-n threshold code give 0; `none`), quantized
//!    to b's format.
//! 5. k squarings, each exact (`uI.F x uI.F -> u2I.2F`) then quantized by its own stage.
//! 6. `coef(n)`, a per-n constant rounded once to its format.
//! 7. `out = sq_k * coef`, exact then quantized to the output format.
//!
//! **Invariant:** no I/O here, and nothing fails after [`Datapath::new`] has validated the
//! configuration: overflow is modelled by each stage's mode and counted through [`Probes`].

pub mod config;
pub mod datapath;
pub mod f64_walk;
/// The batch kernels, their proofs and plan: performance internals (hidden from the docs).
#[doc(hidden)]
pub mod fast;
pub mod ports;
pub mod walk;

pub use config::{
    Arch, CoefSpec, Config, Depth, DepthStep, FormatSpec, LatencySpec, MinimaxSpec, StageSpec,
    Variant, DEPTH_BITS,
};
pub use datapath::{
    first_code_where, Datapath, NConstants, OutputScratch, ProbeColumns, Probes, StageInfo,
    MAX_STAGES,
};
pub use fast::EventCounts;
