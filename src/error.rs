//! The library's error types: every way a user's input can be refused.

use thiserror::Error;

/// Parses TOML text into `T`, turning a parse error into [`Error::Toml`] with its line.
pub fn parse_toml<T: serde::de::DeserializeOwned>(text: &str) -> Result<T, Error> {
    toml::from_str(text).map_err(|e: toml::de::Error| {
        let line = e
            .span()
            .map(|s| text[..s.start.min(text.len())].matches('\n').count() + 1)
            .unwrap_or(1);
        Error::Toml {
            line,
            message: one_line(e.message()),
        }
    })
}

/// User text shown in a message: control characters (line breaks, tabs, escapes) are written
/// as Rust escapes (`\n`, `\u{1b}`), and so are the Unicode line and paragraph separators, so
/// that a message stays on one line and shows what was given.
pub(crate) struct OneLine<'a>(pub &'a str);

impl std::fmt::Display for OneLine<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        use std::fmt::Write;
        for c in self.0.chars() {
            if c.is_control() || matches!(c, '\u{2028}' | '\u{2029}') {
                write!(f, "{}", c.escape_debug())?;
            } else {
                f.write_char(c)?;
            }
        }
        Ok(())
    }
}

/// A parser's message on one line: line breaks become spaces, surrounding space is dropped.
pub(crate) fn one_line(message: &str) -> String {
    message.replace(['\n', '\r'], " ").trim().to_string()
}

/// Errors from parsing and validating user input. Arithmetic never fails. New kinds of
/// refusal may be added: match the ones you handle and keep a catch-all arm.
#[derive(Debug, Error, Clone, PartialEq)]
#[non_exhaustive]
pub enum Error {
    /// A name (form, cutoff, source, ...) that is not one of the known ones.
    #[error("unknown {what} '{}': expected {expected}", OneLine(.got))]
    UnknownName {
        /// What kind of name was expected.
        what: &'static str,
        /// The accepted names.
        expected: &'static str,
        /// What was given.
        got: String,
    },
    /// A number outside its allowed range.
    #[error("{what} must be {}, got {}", OneLine(.expected), OneLine(.got))]
    OutOfRange {
        /// What the number is.
        what: &'static str,
        /// The allowed range, in words.
        expected: String,
        /// What was given.
        got: String,
    },
    /// A fixed-point format or mode that cannot be built or parsed.
    #[error(transparent)]
    Fixed(#[from] FixedError),
    /// A configuration key whose value cannot be used.
    #[error("{}: {}", OneLine(.key), OneLine(.problem))]
    Config {
        /// The key, e.g. `t.format` or `square[2].rounding`.
        key: String,
        /// What is wrong, with what was expected and what was given.
        problem: String,
    },
    /// A configuration text that is not valid TOML or has unknown keys.
    #[error("line {line}: {message}")]
    Toml {
        /// The 1-based line of the problem.
        line: usize,
        /// The parser's message, on one line.
        message: String,
    },
    /// An input format with more codes than an exhaustive analysis evaluates.
    #[error(
        "c.format {format} has {n_codes} input codes up to 1.0; an exhaustive check evaluates at most {limit}"
    )]
    TooManyCodes {
        /// The input format.
        format: String,
        /// Its codes up to 1.0.
        n_codes: u64,
        /// The most an exhaustive check evaluates.
        limit: u64,
    },
    /// A vector directory's manifest that cannot be read.
    #[error("{problem}")]
    Manifest {
        /// What is wrong, on one line.
        problem: String,
    },
    /// A sweep shard that is not `I/N` with `0 <= I < N`.
    #[error("expected a shard I/N with 0 <= I < N, got '{}'", OneLine(.got))]
    Shard {
        /// What was given.
        got: String,
    },
    /// A sharding that cannot be resolved: `--shard`, `--shards-per-task`, a scheduler's
    /// array variables, an output path without its `{shard}` placeholder.
    #[error("{option}: {problem}")]
    Cluster {
        /// The option or variable at fault.
        option: String,
        /// What is wrong, with what was expected and what was given.
        problem: String,
    },
    /// Sweep shards that do not form one complete sweep.
    #[error("{problem}")]
    Merge {
        /// What is wrong and what to pass instead.
        problem: String,
    },
    /// A chart or document that could not be drawn.
    #[error("{message}")]
    Render {
        /// The drawing library's complaint.
        message: String,
    },
    /// An external tool (yosys, gappa) failed or answered something that cannot be read.
    #[error("{message}")]
    Tool {
        /// The tool.
        tool: &'static str,
        /// What went wrong.
        message: String,
    },
    /// A formal bound that cannot be proved this way for one exponent.
    #[error("{reason}")]
    Unprovable {
        /// The exponent.
        n: u32,
        /// Why.
        reason: String,
    },
    /// A result file or directory that cannot be written, or an output refused before any
    /// work (it would replace an input, or something that is not an earlier result).
    #[error("{message}")]
    Output {
        /// What went wrong, with the operating system's reason.
        message: String,
    },
    /// An input file or directory that cannot be read or is refused (not a regular file, too
    /// large, not UTF-8, a vector directory that does not verify), named by its argument.
    #[error("{message}")]
    Input {
        /// Which input, what is wrong, with the operating system's reason.
        message: String,
    },
    /// An evaluation asked outside the datapath's domain: an n not in the configuration's set,
    /// a code outside the input format, arrays of different lengths.
    #[error("{message}")]
    Domain {
        /// Which input and what was expected.
        message: String,
    },
    /// A VCD trace that cannot be read, or lacks what a comparison needs.
    #[error("{problem}")]
    Trace {
        /// Which trace: 0 the first, 1 the second.
        which: usize,
        /// What is wrong, e.g. `line 12: ...` or `no signal tb_specfx.clk`.
        problem: String,
    },
    /// A co-simulation stimulus that cannot be made: too long, or not drained.
    #[error("{problem}")]
    Stimulus {
        /// What is wrong and what to change.
        problem: String,
    },
    /// The minimax table has no entry for this (n, k).
    #[error(
        "no minimax constants cached for n = {n}, k = {k}: the table covers n = 1..={n_max}, k = 1..={k_max}"
    )]
    NoMinimaxEntry {
        /// The exponent asked for.
        n: u32,
        /// The number of squarings asked for.
        k: u32,
        /// The largest n in the table.
        n_max: u32,
        /// The largest k in the table.
        k_max: u32,
    },
}

/// Why a [`Format`](crate::fixed::Format), [`Rounding`](crate::fixed::Rounding) or
/// [`Overflow`](crate::fixed::Overflow) could not be built or parsed.
///
/// Only construction and parsing return this error. Arithmetic and quantization never do:
/// an overflow in the datapath is an [`Event`](crate::fixed::Event), not an error.
///
/// # Examples
///
/// ```
/// use specfx::error::FixedError;
/// use specfx::fixed::Format;
///
/// let err = "x1.2".parse::<Format>().unwrap_err();
/// assert_eq!(err, FixedError::BadNotation { got: "x1.2".to_string() });
/// assert_eq!(err.to_string(), "format must look like u1.15 or s2.16, got 'x1.2'");
/// ```
#[derive(Debug, Clone, PartialEq, Eq, Error)]
#[non_exhaustive]
pub enum FixedError {
    /// The text is not in the `u<int>.<frac>` / `s<int>.<frac>` notation.
    #[error("format must look like u1.15 or s2.16, got '{}'", OneLine(.got))]
    BadNotation {
        /// The text that was given.
        got: String,
    },
    /// The total width (int bits + frac bits) is outside `1..=64` (`1..=63` when unsigned).
    #[error("width (int bits + frac bits) of {notation} must be in 1..={max}, got {got}")]
    Width {
        /// The format as it was given, in the usual notation.
        notation: String,
        /// The total width that was given.
        got: i64,
        /// The widest format of that signedness: 64 signed, 63 unsigned.
        max: i64,
    },
    /// An unsigned format is 64 bits wide: its largest raw value would not fit in `i64`.
    #[error(
        "width (int bits + frac bits) of unsigned {notation} must be at most 63 so that raws fit in i64, got {got}"
    )]
    UnsignedWidth {
        /// The format as it was given, in the usual notation.
        notation: String,
        /// The total width that was given.
        got: i64,
    },
    /// The number of fraction bits is outside the supported range.
    #[error("frac bits of {notation} must be in -512..=512, got {got}")]
    FracBits {
        /// The format as it was given, in the usual notation.
        notation: String,
        /// The number of fraction bits that was given.
        got: i64,
    },
    /// The text is not the name of a quantization (rounding) mode.
    #[error("rounding mode must be one of TRN, TRN_ZERO, RND, RND_ZERO, RND_INF, RND_MIN_INF, RND_CONV, RND_CONV_ODD (upper or lower case), got '{}'", OneLine(.got))]
    BadRounding {
        /// The text that was given.
        got: String,
    },
    /// The text is not the name of an overflow mode.
    #[error("overflow mode must be one of WRAP, SAT, SAT_ZERO, SAT_SYM (upper or lower case), got '{}'", OneLine(.got))]
    BadOverflow {
        /// The text that was given.
        got: String,
    },
}

#[cfg(test)]
mod tests {
    use crate::analysis::budget_expr::Budget;
    use crate::fixed::{Format, Rounding};
    use crate::reference::lobe::Cutoff;

    #[test]
    fn user_text_in_messages_is_escaped_onto_one_line() {
        let e = "s10#8\r-2".parse::<Format>().unwrap_err().to_string();
        assert_eq!(e, r"format must look like u1.15 or s2.16, got 's10#8\r-2'");
        let e = "RND\n".parse::<Rounding>().unwrap_err().to_string();
        assert!(e.ends_with(r"got 'RND\n'"), "{e}");
        let e = "clamp\u{2028}x".parse::<Cutoff>().unwrap_err().to_string();
        assert!(e.starts_with(r"unknown cutoff 'clamp\u{2028}x'"), "{e}");
        // Escapes too; quotes and non-ASCII letters are shown as they are. (A budget's words
        // are separated by any white space, a tab included, and shown with one space.)
        let e = "out <=\t1 ulp\u{1b}[2J 'é'".parse::<Budget>().unwrap_err();
        assert_eq!(
            e.to_string(),
            r"budget: 'out <= 1 ulp\u{1b}[2J 'é'' has the unit 'ulp\u{1b}[2J 'é'': out takes ulp (output LSBs), e.g. 'out <= 1 ulp'"
        );
        let e = "s1.2\t".parse::<Format>().unwrap_err().to_string();
        assert!(e.ends_with(r"got 's1.2\t'"), "{e}");
    }
}
