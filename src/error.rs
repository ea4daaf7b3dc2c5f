//! The library's error type: every way a user's input can be refused.

use thiserror::Error;

/// Errors from parsing and validating user input. Arithmetic never fails.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum Error {
    /// A name (form, cutoff, source, ...) that is not one of the known ones.
    #[error("unknown {what} '{got}': expected {expected}")]
    UnknownName {
        /// What kind of name was expected.
        what: &'static str,
        /// The accepted names.
        expected: &'static str,
        /// What was given.
        got: String,
    },
    /// A number outside its allowed range.
    #[error("{what} must be {expected}, got {got}")]
    OutOfRange {
        /// What the number is.
        what: &'static str,
        /// The allowed range, in words.
        expected: String,
        /// What was given.
        got: String,
    },
    /// The minimax table has no entry for this (n, k).
    #[error("no minimax constants cached for n = {n}, k = {k}: the table covers n = 1..={n_max}, k = 1..=7")]
    NoMinimaxEntry {
        /// The exponent asked for.
        n: u32,
        /// The number of squarings asked for.
        k: u32,
        /// The largest n in the table.
        n_max: u32,
    },
}
