//! Fixed-point formats, ac_fixed quantization and overflow modes, and exact intermediates; no I/O.
//!
//! A datapath value is a raw two's complement integer read in a [`Format`]:
//! `value = raw * 2^-frac_bits`. Formats are chosen at run time and written in one notation
//! everywhere: `u1.15` is unsigned with 1 integer bit and 15 fraction bits, `s2.16` is two's
//! complement with 2 integer bits (the sign included) and 16 fraction bits.
//!
//! Arithmetic is done exactly on [`Exact`] values (an `i128` raw with its own fraction bits),
//! then brought back into a format by [`quantize`]: first rounding with a [`Rounding`] mode,
//! then overflow handling with an [`Overflow`] mode, exactly as `ac_fixed` does when it assigns
//! a wider value to a narrower type. Overflow is reported as an [`Event`] so that a pipeline can
//! count it per stage.
//!
//! For hot loops where everything fits in `i64`, [`round_shift_i64`], [`overflow_i64`] and
//! [`quantize_i64`] do the same job without `i128` and are tested to agree with [`quantize`].
//!
//! **Invariant:** nothing in this module does I/O, and nothing here returns `Result` after a
//! [`Format`] has been built: arithmetic reports overflow as an [`Event`], never as an error.
//!
//! **Invariant:** every raw value stored in a [`Format`] fits in `i64` (signed widths go up to
//! 64 bits, unsigned widths up to 63).
//!
//! # Examples
//!
//! ```
//! use specfx::fixed::{quantize, Event, Exact, Format, Overflow, Rounding};
//!
//! // u1.16 x u1.16 -> u2.32 exactly, then back to u1.16.
//! let fmt: Format = "u1.16".parse().unwrap();
//! let a = Exact::from_raw(0x1_8000, fmt); // 1.5
//! let b = Exact::from_raw(0x1_4000, fmt); // 1.25
//! let product = a * b; // 1.875, with 32 fraction bits
//! assert_eq!(product.frac_bits, 32);
//! let q = quantize(product, fmt, Rounding::RndConv, Overflow::Sat);
//! assert_eq!(q.raw, 0x1_E000);
//! assert_eq!(q.event, Event::None);
//!
//! // 1.5 * 1.5 = 2.25 does not fit in u1.16: it saturates to the largest code, and says so.
//! let q = quantize(a * a, fmt, Rounding::RndConv, Overflow::Sat);
//! assert_eq!(q.raw, fmt.max_raw());
//! assert_eq!(q.event, Event::Saturated);
//! ```

mod exact;
mod format;
mod mode;
mod quantize;

#[cfg(test)]
mod tests;

pub use exact::Exact;
pub use format::Format;
pub use mode::{Overflow, Rounding};
pub use quantize::{
    overflow_i64, quantize, quantize_f64, quantize_i64, round_shift_i128, round_shift_i64, Event,
    Quantized,
};
