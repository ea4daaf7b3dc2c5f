//! specfx: a bit-accurate and cycle-level model of a division-free fixed-point specular
//! (cos^n) datapath.
//!
//! Phong-type highlights need cos^n. The datapath modelled here replaces it by
//! `cs_m(c, n) = max(0, (n/m)(c - 1) + 1)^m` with m = 2^k squarings (k = 4 in the paper by
//! Romanyuk, Pavlov and Abramchuk, 2016), times an energy-conserving coefficient coef(n).
//!
//! # The front door
//! An embedder (a testbench, a C or Python face, a design-space script) needs these, all
//! re-exported here:
//! - [`load_datapath`] and [`datapath_from_toml`]: a validated [`Datapath`] from a configuration
//!   (`baseline`, a TOML file or text; [`Config`] is its schema). Nothing fails after it.
//! - [`Datapath::eval_out`] one pair's output, [`Datapath::eval`] every stage's probe
//!   ([`Probes`]), [`eval_outputs`] a slice of pairs in parallel ([`Ns`]: one n or one each);
//!   [`Datapath::constants_for`] the per-n constants ([`NConstants`]) the RTL's inputs carry.
//! - [`check`]: the exhaustive check of every input code and every n ([`CheckReport`]).
//! - [`Lockstep`]: the cycle model stepped one clock cycle at a time, what the RTL's ports
//!   show ([`Ports`]) for either microarchitecture ([`Arch`]).
//! - [`Error`]: every refusal, one line each.
//!
//! The modules below are the rest of the library: [`reference`](mod@reference) the f64 oracle,
//! [`fixed`] formats and quantization, [`pipeline`] the datapath, [`cycle`] the cycle model,
//! [`golden`] vectors, [`hdl`] Verilog parameters and cost models, [`analysis`] budgets, the
//! optimiser, sweeps and the stability map, [`scene`] rendering. `ARCHITECTURE.md` maps them.
//!
//! # Examples
//! ```
//! use specfx::{check, eval_outputs, load_datapath, Arch, Lockstep, Ns};
//!
//! // The paper's datapath: u1.15 input, four squarings, n = 16..=1024.
//! let dp = load_datapath("baseline", None).unwrap();
//! let one = dp.one_code(); // the code of c = 1.0: 2^15
//! assert_eq!(one, 1 << 15);
//!
//! // One pair. At c = 1.0 the lobe is 1: the output is coef(64)'s code.
//! let coef64 = dp.constants_for(64).unwrap().coef_raw;
//! assert_eq!(dp.eval_out(one, 64).unwrap(), coef64);
//!
//! // A slice of pairs, one n for all (in parallel, each pair checked first).
//! let cs = [0, one / 2, one];
//! let mut out = [0i64; 3];
//! eval_outputs(&dp, &cs, Ns::One(64), &mut out).unwrap();
//! assert_eq!((out[0], out[2]), (0, coef64)); // c = 0: (64/16)(0 - 1) + 1 < 0, cut to 0
//!
//! // Every input code at every n: 1009 exponents of 2^15 + 1 codes.
//! let report = check(&dp).unwrap();
//! assert_eq!(report.n_evaluations, 1009 * 32769);
//!
//! // The cycle model, one clock cycle: the pipeline takes an input and shows no output yet.
//! let mut machine = Lockstep::new(&dp, Arch::Pipelined);
//! let ports = machine.cycle(&dp, Some((one, 64)), true).unwrap();
//! assert!(ports.in_ready && ports.out.is_none());
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
// The command line's own: result files on disk, and its renderers and external programs.
#[doc(hidden)]
pub mod output;
pub mod pipeline;
pub mod provenance;
pub mod reference;
#[cfg(feature = "report")]
#[doc(hidden)]
pub mod report;
#[cfg(feature = "scene")]
pub mod scene;
#[doc(hidden)]
pub mod tools;

pub use analysis::check::{check, check_with_progress, CheckReport};
pub use cycle::lockstep::{Lockstep, Ports};
pub use cycle::Arch;
pub use engine::pairs::{eval_outputs, Ns};
pub use error::Error;
pub use input::{datapath_from_toml, load_datapath};
pub use pipeline::{Config, Datapath, NConstants, Probes};
