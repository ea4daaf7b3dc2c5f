//! The datapath's stages named once ([`Stage`]) and walked once ([`walk`]), generic over the
//! arithmetic: the bit-accurate model, the `f64` value of the same algorithm and the budget's
//! mixed model are interpreters of the same walk, so the stage order and the cutoff are written
//! here and nowhere else.
//!
//! The walk is the specification of one evaluation (`docs/arithmetic.md` section 3.2):
//!
//! 1. `d = c - 1` from the input clamped to 1.0;
//! 2. `t = Q_t(slope * d)`;
//! 3. `sum = t + offset`, exact; the cutoff decides whether the base is cut
//!    ([`Cutoff::cuts`]); `b = Q_b(cut ? 0 : sum)`;
//! 4. `sq_i = Q_i(sq_{i-1}^2)` for i = 1..j(n) and `sq_i = Q_i(sq_{i-1})` (the stage bypassed)
//!    for i = j(n)+1..k, `sq_0 = b`;
//! 5. `out = Q_out(sq_k * coef)`.
//!
//! What `Q` means (a quantization, or nothing) is the interpreter's business.

use std::fmt;

use crate::pipeline::NConstants;
use crate::reference::lobe::Cutoff;

/// A stage of the datapath: the value a probe, a budget source, a cycle-model operation or a
/// report names.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Stage {
    /// `d = c - 1`, exact.
    D,
    /// `t = slope * d`, quantized.
    T,
    /// `b = t + offset` after the cutoff, quantized.
    B,
    /// Squaring `i` (0-based): `sq_{i+1}`.
    Square(usize),
    /// The coefficient `coef(n)`, a per-n constant.
    Coef,
    /// `out = sq_k * coef`, quantized.
    Out,
}

impl Stage {
    /// Every stage of a datapath with `k` squarings, in pipeline order (the order of
    /// [`crate::pipeline::Datapath::stages`] and of the probes).
    ///
    /// # Examples
    /// ```
    /// use specfx::pipeline::walk::Stage;
    /// let names: Vec<String> = Stage::all(2).iter().map(|s| s.to_string()).collect();
    /// assert_eq!(names, ["d", "t", "b", "sq1", "sq2", "coef", "out"]);
    /// ```
    pub fn all(k: usize) -> Vec<Stage> {
        let mut v = vec![Stage::D, Stage::T, Stage::B];
        v.extend((0..k).map(Stage::Square));
        v.extend([Stage::Coef, Stage::Out]);
        v
    }

    /// The stage's index among the probes of a datapath with `k` squarings.
    pub fn index(self, k: usize) -> usize {
        match self {
            Stage::D => 0,
            Stage::T => 1,
            Stage::B => 2,
            Stage::Square(i) => 3 + i,
            Stage::Coef => 3 + k,
            Stage::Out => 4 + k,
        }
    }
}

impl fmt::Display for Stage {
    /// `d`, `t`, `b`, `sq1`.., `coef`, `out`: the names of reports, vector columns and probes.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Stage::D => f.write_str("d"),
            Stage::T => f.write_str("t"),
            Stage::B => f.write_str("b"),
            Stage::Square(i) => write!(f, "sq{}", i + 1),
            Stage::Coef => f.write_str("coef"),
            Stage::Out => f.write_str("out"),
        }
    }
}

impl NConstants {
    /// Whether the paper cutoff cuts an input whose code, clamped to 1.0, is `c_code`: the
    /// code is below the threshold of this n (never, for the other cutoffs).
    pub fn below_threshold(&self, c_code: i64) -> bool {
        self.threshold.is_some_and(|thr| c_code < thr)
    }
}

/// One arithmetic the walk can run in. Each method is one step of the walk; the interpreter
/// holds the input and whatever it records (probes, events, text).
pub trait Arithmetic {
    /// A value between two steps (a number, or for a script generator the name of one).
    type Value: Clone;
    /// `d = c - 1` of the input clamped to 1.0.
    fn sub(&mut self) -> Self::Value;
    /// Whether the input is below the paper cutoff's threshold.
    fn below_threshold(&self) -> bool;
    /// `t = Q_t(slope * d)`.
    fn mul_t(&mut self, d: Self::Value) -> Self::Value;
    /// `t + offset`, exact.
    fn add_offset(&mut self, t: Self::Value) -> Self::Value;
    /// Whether a sum is negative (the clamp cutoff's test).
    fn is_negative(&self, sum: Self::Value) -> bool;
    /// The base of a cut input, 0.
    fn zero(&self) -> Self::Value;
    /// `b = Q_b(base)`.
    fn quant_b(&mut self, base: Self::Value) -> Self::Value;
    /// `sq_{i+1} = Q_i(x^2)`.
    fn square(&mut self, i: usize, x: Self::Value) -> Self::Value;
    /// `sq_{i+1} = Q_i(x)`: squaring stage `i` bypassed (the exponent's depth is at most `i`).
    fn pass(&mut self, i: usize, x: Self::Value) -> Self::Value;
    /// `out = Q_out(s * coef)`.
    fn mul_out(&mut self, s: Self::Value) -> Self::Value;
}

/// What a walk ends with: the lobe (the last squaring), the output and whether the base was
/// cut.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Walked<V> {
    /// The last squaring, the lobe before the coefficient.
    pub lobe: V,
    /// The output.
    pub out: V,
    /// The cutoff forced the base to zero.
    pub cut: bool,
}

/// Walks the stages of a datapath with `k` squaring stages, of which the first `depth` square
/// and the rest pass their input through, and cutoff `cutoff` in an arithmetic.
#[inline]
pub fn walk<A: Arithmetic>(a: &mut A, cutoff: Cutoff, k: usize, depth: usize) -> Walked<A::Value> {
    let d = a.sub();
    let t = a.mul_t(d);
    let sum = a.add_offset(t);
    let cut = cutoff.cuts(a.is_negative(sum.clone()), a.below_threshold());
    let base = if cut { a.zero() } else { sum };
    let mut s = a.quant_b(base);
    for i in 0..k {
        s = if i < depth {
            a.square(i, s)
        } else {
            a.pass(i, s)
        };
    }
    let out = a.mul_out(s.clone());
    Walked { lobe: s, out, cut }
}
