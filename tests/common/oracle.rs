//! An independent, slow oracle of the datapath arithmetic, for tests to check `Datapath::eval`
//! (and anything else that claims to compute the same bits) against.
//!
//! It is transcribed from `docs/arithmetic.md` sections 1 to 3 alone, without looking at the
//! library's quantization or evaluation code, so that it cannot share their mistakes. Every
//! exact intermediate is an unbounded [`BigInt`], every division by a power of two is a plain
//! floor division (`Integer::div_mod_floor`, whose remainder is in `0..2^s`), and every shift is
//! a multiplication or division by an explicitly built `2^s`: shifts of any size (300 bits and
//! more) and formats with negative fraction bits need no special case. It is meant to be simple
//! and obviously correct, not fast.
//!
//! The library is used only for its data types (`Config`, `NConstants`, `Format`'s accessors
//! `width`, `is_signed` and `frac_bits`, and the `Rounding`/`Overflow`/`Event` names). The
//! per-n constants are taken from `NConstants` as given: they are inputs.
//!
//! Use it from a test module with `use crate::common::oracle;`.
#![allow(dead_code)]

use num_bigint::BigInt;
use num_integer::Integer;
use num_traits::{One, ToPrimitive, Zero};
use specfx::fixed::{Event, Format, Overflow, Rounding};
use specfx::pipeline::{Config, NConstants, StageSpec};
use specfx::reference::lobe::Cutoff;

/// The oracle's probes for one evaluation (docs/arithmetic.md section 3.0).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct OracleProbes {
    /// Raw codes of `d`, `t`, `b`, `sq1` .. `sqk`, `coef`, `out`, in that order (`k + 5`).
    pub values: Vec<i64>,
    /// The event of each probe's quantization, same order; `d` and `coef` are always
    /// [`Event::None`].
    pub events: Vec<Event>,
    /// The cutoff forced the base to zero (section 3.2 step 4).
    pub cut: bool,
    /// The input code was above the code of 1.0 (section 3.2 step 1).
    pub input_clamped: bool,
}

/// `2^e` as an unbounded integer.
pub fn pow2(e: u64) -> BigInt {
    let e = usize::try_from(e).expect("exponent fits usize");
    BigInt::one() << e
}

/// The smallest and largest raw codes of a format with this signedness and total width `W`
/// (docs/arithmetic.md section 1.1): signed `-2^(W-1) ..= 2^(W-1) - 1`, unsigned
/// `0 ..= 2^W - 1`. The fraction bits play no part.
pub fn code_range(signed: bool, width: u32) -> (BigInt, BigInt) {
    assert!(width >= 1, "a format has at least one bit");
    let w = u64::from(width);
    if signed {
        let half = pow2(w - 1);
        (-half.clone(), half - 1)
    } else {
        (BigInt::zero(), pow2(w) - 1)
    }
}

/// [`code_range`] of a format (docs/arithmetic.md section 1.1).
pub fn format_codes(fmt: Format) -> (BigInt, BigInt) {
    code_range(fmt.is_signed(), fmt.width())
}

/// Rounds `x / 2^s` to an integer with one rounding mode, dropping `s >= 1` bits
/// (docs/arithmetic.md section 2.1, the table of modes).
///
/// `q = floor(x / 2^s)`, `r = x - q * 2^s` (so `0 <= r < 2^s`), `h = 2^(s-1)`; the result is `q`
/// or `q + 1`, and `r == 0` always gives `q`.
pub fn round_shift(x: &BigInt, s: u64, mode: Rounding) -> BigInt {
    assert!(s >= 1, "round_shift drops at least one bit");
    let divisor = pow2(s);
    let (q, r) = x.div_mod_floor(&divisor);
    // Check the definitions rather than trust the library call.
    assert!(
        r >= BigInt::zero() && r < divisor,
        "floor division remainder out of range"
    );
    assert_eq!(&q * &divisor + &r, *x, "floor division is not exact");
    let h = pow2(s - 1);
    let negative = x < &BigInt::zero();
    let q_odd = q.is_odd();

    let up = if r.is_zero() {
        false
    } else {
        match mode {
            // Toward minus infinity: the bits are dropped.
            Rounding::Trn => false,
            // Toward zero: q + 1 if r > 0 and x < 0.
            Rounding::TrnZero => negative,
            // Nearest, ties toward plus infinity: q + 1 if r >= h.
            Rounding::Rnd => r >= h,
            // Nearest, ties toward zero.
            Rounding::RndZero => {
                if r > h {
                    true
                } else if r == h {
                    negative
                } else {
                    false
                }
            }
            // Nearest, ties away from zero.
            Rounding::RndInf => {
                if r > h {
                    true
                } else if r == h {
                    !negative
                } else {
                    false
                }
            }
            // Nearest, ties toward minus infinity: q + 1 only if r > h.
            Rounding::RndMinInf => r > h,
            // Nearest, ties to even: on a tie, q + 1 if q is odd.
            Rounding::RndConv => {
                if r > h {
                    true
                } else if r == h {
                    q_odd
                } else {
                    false
                }
            }
            // Nearest, ties to odd: on a tie, q + 1 if q is even.
            Rounding::RndConvOdd => {
                if r > h {
                    true
                } else if r == h {
                    !q_odd
                } else {
                    false
                }
            }
        }
    };
    if up {
        q + 1
    } else {
        q
    }
}

/// Applies an overflow mode to the rounded integer `v` for a format of this signedness and
/// width (docs/arithmetic.md section 2.2, including "SAT_SYM and the most negative code").
///
/// In range: `v`, event `None`, except `SAT_SYM` on a signed format with `v == min`, which gives
/// the most negative code with its LSB set (`min + 1 = -max` for `W >= 2`, `-1` for `W = 1`) and
/// event `Saturated`. Out of range: `WRAP` keeps the low `W` bits (two's complement when signed,
/// `Wrapped`); `SAT` clamps to `min`/`max` (`Saturated`); `SAT_ZERO` gives 0 (`Zeroed`);
/// `SAT_SYM` gives `max` above and, below, `-max` (`-1` when `W = 1`) if signed or `0` if
/// unsigned (`Saturated`).
pub fn apply_overflow(v: &BigInt, signed: bool, width: u32, mode: Overflow) -> (BigInt, Event) {
    let (min, max) = code_range(signed, width);
    // ac_fixed's negative symmetric saturation value: the most negative code with its LSB set.
    let sym_neg = if width == 1 {
        BigInt::from(-1)
    } else {
        &min + 1
    };
    if &min <= v && v <= &max {
        if mode == Overflow::SatSym && signed && *v == min {
            return (sym_neg, Event::Saturated);
        }
        return (v.clone(), Event::None);
    }
    match mode {
        Overflow::Wrap => {
            let modulus = pow2(u64::from(width));
            let low = v.mod_floor(&modulus); // 0 <= low < 2^W
            let wrapped = if signed && low >= pow2(u64::from(width) - 1) {
                low - modulus
            } else {
                low
            };
            (wrapped, Event::Wrapped)
        }
        Overflow::Sat => {
            if v > &max {
                (max, Event::Saturated)
            } else {
                (min, Event::Saturated)
            }
        }
        Overflow::SatZero => (BigInt::zero(), Event::Zeroed),
        Overflow::SatSym => {
            if v > &max {
                (max, Event::Saturated)
            } else if signed {
                (sym_neg, Event::Saturated)
            } else {
                (min, Event::Saturated)
            }
        }
    }
}

/// Quantizes the exact value `x * 2^-f` into `fmt` (docs/arithmetic.md section 2): alignment
/// and rounding with `s = f - F` (`s > 0`: [`round_shift`]; `s = 0`: unchanged; `s < 0`: an exact
/// left shift by `-s`, the rounding mode playing no part), then [`apply_overflow`].
///
/// Returns the code as a `BigInt` with its event; the code is always one of `fmt`'s.
pub fn quantize_big(
    x: &BigInt,
    f: i64,
    fmt: Format,
    rounding: Rounding,
    overflow: Overflow,
) -> (BigInt, Event) {
    let s = f - i64::from(fmt.frac_bits());
    let v = if s > 0 {
        round_shift(x, s.unsigned_abs(), rounding)
    } else if s == 0 {
        x.clone()
    } else {
        x * pow2(s.unsigned_abs())
    };
    let (raw, event) = apply_overflow(&v, fmt.is_signed(), fmt.width(), overflow);
    let (min, max) = format_codes(fmt);
    assert!(min <= raw && raw <= max, "quantize produced a non-code");
    (raw, event)
}

/// [`quantize_big`] with the code as an `i64` (every code of a valid format fits one,
/// docs/arithmetic.md section 1.2).
pub fn quantize(
    x: &BigInt,
    f: i64,
    fmt: Format,
    rounding: Rounding,
    overflow: Overflow,
) -> (i64, Event) {
    let (raw, event) = quantize_big(x, f, fmt, rounding, overflow);
    (to_i64(&raw), event)
}

/// [`quantize`] with a stage's format and modes.
pub fn quantize_stage(x: &BigInt, f: i64, spec: &StageSpec) -> (i64, Event) {
    quantize(x, f, spec.format, spec.rounding, spec.overflow)
}

/// Rounds a constant given exactly as `x * 2^-f` once into `fmt` (docs/arithmetic.md section
/// 2.3): there is no overflow mode, so `None` when the rounded integer is not a code of `fmt`.
/// A signed format's most negative code is accepted.
pub fn constant(x: &BigInt, f: i64, fmt: Format, rounding: Rounding) -> Option<i64> {
    let (raw, event) = quantize(x, f, fmt, rounding, Overflow::Sat);
    (event == Event::None).then_some(raw)
}

/// A finite `f64` as the exact pair `(x, f)` with value `x * 2^-f` (docs/arithmetic.md section
/// 2.3), from its IEEE-754 fields: `mantissa * 2^exponent`.
pub fn exact_f64(value: f64) -> (BigInt, i64) {
    assert!(value.is_finite(), "only finite f64 are dyadic rationals");
    let bits = value.to_bits();
    let negative = bits >> 63 == 1;
    let biased = i64::try_from((bits >> 52) & 0x7ff).expect("11 bits");
    let field = bits & ((1u64 << 52) - 1);
    // Normal: (2^52 + field) * 2^(biased - 1075); subnormal: field * 2^-1074.
    let (mantissa, exponent) = if biased == 0 {
        (field, -1074)
    } else {
        (field | (1u64 << 52), biased - 1075)
    };
    let x = BigInt::from(mantissa);
    let x = if negative { -x } else { x };
    (x, -exponent)
}

fn to_i64(v: &BigInt) -> i64 {
    v.to_i64().expect("a code of a valid format fits i64")
}

/// Evaluates the datapath on one raw input code with one n's constants (docs/arithmetic.md
/// section 3.2, steps 1 to 7; the same as the Python `evaluate` of section 3.3).
///
/// `nc` supplies `depth` (j(n)), `slope_raw`, `slope_frac`, `offset_raw`, `offset_frac`,
/// `threshold` (paper cutoff only) and `coef_raw` as given (section 3.1); nothing else of it
/// is read.
pub fn oracle_eval(cfg: &Config, nc: &NConstants, c_raw: i64) -> OracleProbes {
    let k = usize::try_from(cfg.k).expect("k fits usize");
    assert_eq!(cfg.square.len(), k, "one squaring spec per stage");
    let fc = i64::from(cfg.c.format.frac_bits());
    let fd = i64::from(cfg.d.format.frac_bits());
    let ft = i64::from(cfg.t.format.frac_bits());
    let fb = i64::from(cfg.b.format.frac_bits());
    let fcoef = i64::from(cfg.coef.format.frac_bits());
    assert!(
        (0..=62).contains(&fc),
        "validation: the input represents 1.0"
    );
    assert!(fd >= fc, "validation: d has at least c's fraction bits");

    let mut values = Vec::with_capacity(k + 5);
    let mut events = Vec::with_capacity(k + 5);

    // Step 1: input clamp. c = min(c_raw, one); no lower clamp.
    let one = pow2(fc.unsigned_abs());
    let c_in = BigInt::from(c_raw);
    let input_clamped = c_in > one;
    let c = if input_clamped { one.clone() } else { c_in };

    // Step 2: d = (c - one) * 2^(Fd - Fc), exact and stored as is.
    let d = (&c - &one) * pow2((fd - fc).unsigned_abs());
    let (d_min, d_max) = format_codes(cfg.d.format);
    assert!(
        d_min <= d && d <= d_max,
        "validation: d fits its format for every input"
    );
    values.push(to_i64(&d));
    events.push(Event::None);

    // Step 3: t = quantize(d * slope_raw, Fd + slope_frac, t).
    let product = &d * BigInt::from(nc.slope_raw);
    let (t, ev_t) = quantize_stage(&product, fd + i64::from(nc.slope_frac), &cfg.t);
    values.push(t);
    events.push(ev_t);

    // Step 4: sum = t + offset aligned on fs = max(Ft, offset_frac), exact; then the cutoff;
    // then the b quantization.
    let offset_frac = i64::from(nc.offset_frac);
    let fs = ft.max(offset_frac);
    let mut sum = BigInt::from(t) * pow2((fs - ft).unsigned_abs())
        + BigInt::from(nc.offset_raw) * pow2((fs - offset_frac).unsigned_abs());
    let cut = match cfg.cutoff {
        Cutoff::Clamp => sum < BigInt::zero(),
        Cutoff::Paper => {
            let threshold = nc
                .threshold
                .expect("the paper cutoff has a per-n threshold");
            c < BigInt::from(threshold)
        }
        Cutoff::None => false,
    };
    if cut {
        sum = BigInt::zero();
    }
    let (b, ev_b) = quantize_stage(&sum, fs, &cfg.b);
    values.push(b);
    events.push(ev_b);

    // Step 5: k squaring stages, each exact (2 * fprev fraction bits) then quantized by its
    // stage; the stages past j(n) quantize their input as it is (fprev fraction bits).
    let mut s = BigInt::from(b);
    let mut fprev = fb;
    let depth = usize::try_from(nc.depth).expect("depth fits usize");
    assert!((1..=k).contains(&depth), "validation: 1 <= j(n) <= k");
    for (i, spec) in cfg.square.iter().enumerate() {
        let (sq, ev) = if i < depth {
            quantize_stage(&(&s * &s), 2 * fprev, spec)
        } else {
            quantize_stage(&s, fprev, spec)
        };
        fprev = i64::from(spec.format.frac_bits());
        s = BigInt::from(sq);
        values.push(sq);
        events.push(ev);
    }

    // Step 6: the coefficient probe is the constant itself, no event.
    values.push(nc.coef_raw);
    events.push(Event::None);

    // Step 7: out = quantize(sq_k * coef_raw, fprev + Fcoef, out).
    let product = &s * BigInt::from(nc.coef_raw);
    let (out, ev_out) = quantize_stage(&product, fprev + fcoef, &cfg.out);
    values.push(out);
    events.push(ev_out);

    OracleProbes {
        values,
        events,
        cut,
        input_clamped,
    }
}
