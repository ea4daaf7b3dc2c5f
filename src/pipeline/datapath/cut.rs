//! Cut proofs: where the cutoff can force the base to zero, proven from the configuration
//! ([`Datapath::cut_structure`]), the first live code found by bisection, and the proof that
//! the lobe is monotone in the input code.

use crate::fixed::{Event, Overflow};
use crate::pipeline::fast::quantize_to;
use crate::reference::lobe::Cutoff;

use super::{CutStructure, Datapath, NConstants};

/// The first code of `codes` from which a monotone predicate holds (false on a prefix, true
/// after it), by bisection; `codes.end` when it never holds.
///
/// # Examples
/// ```
/// use specfx::pipeline::first_code_where;
/// assert_eq!(first_code_where(0..100, |c| c * c >= 50), 8);
/// assert_eq!(first_code_where(0..5, |_| false), 5);
/// assert_eq!(first_code_where(i64::MIN..i64::MAX, |c| c >= -3), -3);
/// ```
pub fn first_code_where(codes: std::ops::Range<i64>, holds: impl Fn(i64) -> bool) -> i64 {
    let (mut lo, mut hi) = (codes.start, codes.end);
    while lo < hi {
        // The midpoint in i128: a 64-bit code range would overflow `hi - lo`.
        let mid = ((i128::from(lo) + i128::from(hi)) >> 1) as i64;
        if holds(mid) {
            hi = mid;
        } else {
            lo = mid + 1;
        }
    }
    lo
}

impl Datapath {
    /// Where the cutoff can cut, as proven from the configuration.
    pub fn cut_structure(&self) -> CutStructure {
        match (self.config.cutoff, self.cut_is_prefix) {
            (Cutoff::None, _) => CutStructure::Never,
            (_, true) => CutStructure::Prefix,
            (_, false) => CutStructure::Scan,
        }
    }

    /// Whether the cutoff forces the base of input `c_raw` to zero for this n.
    pub fn is_cut(&self, c_raw: i64, nc: &NConstants) -> bool {
        let (c, d) = self.op_sub(c_raw);
        let t = self.op_mul_t(d, nc);
        self.op_add_b(t.raw, c, nc).1
    }

    /// The first code of `codes` whose base is not cut, found by bisection where the cut
    /// codes are proven to be a prefix (the paper cutoff; the clamp with a saturating,
    /// non-negative t); `codes.start` otherwise.
    ///
    /// # Examples
    /// ```
    /// use specfx::pipeline::{Config, Datapath};
    /// let dp = Datapath::new(Config::baseline()).unwrap();
    /// let nc = dp.constants_for(1024).unwrap();
    /// // The base (1024/16)(c - 1) + 1 is negative, and cut, below c = 1 - 1/64 (code 32256).
    /// assert_eq!(dp.first_live_code(nc, 0..32769), 32256);
    /// ```
    pub fn first_live_code(&self, nc: &NConstants, codes: std::ops::Range<i64>) -> i64 {
        if !self.cut_is_prefix {
            return codes.start;
        }
        first_code_where(codes, |code| !self.is_cut(code, nc))
    }

    /// Whether the last squaring (the lobe) is proven non-decreasing in the input code up to
    /// 1.0. t saturates and every slope is non-negative, so t is non-decreasing and at most 0
    /// (c <= 1), and the exact sum at most the largest offset. From b on every stage must be
    /// monotone on the values it can receive: every rounding mode is monotone, and so are the
    /// squares of non-negative values and the bypassed stages' requantization; a stage's
    /// overflow is monotone when it saturates, or when the quantization of the largest value
    /// it can receive fits the format (then no value overflows: wrapping and zeroing never
    /// act). Negative bases are cut by the clamp, or reach an unsigned b that saturates them
    /// to 0. Then the codes whose lobe is 0 are a prefix ([`Datapath::first_nonzero_lobe`]).
    pub fn lobe_is_monotone(&self) -> bool {
        self.lobe_monotone
    }

    pub(super) fn prove_lobe_monotone(&self) -> bool {
        let cfg = &self.config;
        let sat = |o: Overflow| matches!(o, Overflow::Sat | Overflow::SatSym);
        if !sat(cfg.t.overflow) || self.constants.iter().any(|c| c.slope_raw < 0) {
            return false;
        }
        if cfg.cutoff != Cutoff::Clamp && !(cfg.b.format.is_signed() || sat(cfg.b.overflow)) {
            return false;
        }
        if cfg.cutoff != Cutoff::Clamp && cfg.b.format.is_signed() {
            return false;
        }
        // The largest exact sum (the largest offset) on the sum's fraction bits, then the
        // largest value each stage can hold, or None once a stage could overflow without
        // saturating.
        let Some(first) = self.constants.first() else {
            return true;
        };
        let fb = self.b_frac(first);
        let top = self
            .constants
            .iter()
            .map(|c| i128::from(c.offset_raw) << (fb - c.offset_frac) as u32)
            .max()
            .unwrap_or(0)
            .max(0);
        let bound = |exact: i128, frac: i32, spec: &crate::pipeline::StageSpec| {
            let q = quantize_to(exact, frac, spec);
            (q.event == Event::None || sat(spec.overflow)).then_some(q.raw.max(0))
        };
        let Some(mut upper) = bound(top, fb, &cfg.b) else {
            return false;
        };
        let mut frac = cfg.b.format.frac_bits();
        for spec in &cfg.square {
            let u = i128::from(upper);
            let (Some(squared), Some(passed)) =
                (bound(u * u, 2 * frac, spec), bound(u, frac, spec))
            else {
                return false;
            };
            upper = squared.max(passed);
            frac = spec.format.frac_bits();
        }
        true
    }

    /// The first code of `codes` whose lobe (the last squaring) is not 0, by bisection where
    /// [`Datapath::lobe_is_monotone`] proves the zero lobes a prefix; `codes.start` otherwise.
    /// Below it every output is 0 too (the quantization of 0 is 0).
    pub fn first_nonzero_lobe(&self, nc: &NConstants, codes: std::ops::Range<i64>) -> i64 {
        if !self.lobe_is_monotone() {
            return codes.start;
        }
        let last = self.stage_last_square();
        first_code_where(codes, |code| self.eval(code, nc).values[last] != 0)
    }
}
