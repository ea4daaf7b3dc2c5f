//! A slow, plainly written oracle for rounding and overflow, compared by proptest with
//! `round_shift_i64`, `round_shift_i128`, `overflow_i64`, `quantize` and `quantize_i64`.
use std::cmp::Ordering;

use proptest::prelude::*;

use crate::fixed::{
    overflow_i64, quantize, quantize_i64, round_shift_i128, round_shift_i64, Event, Exact, Format,
    Overflow, Quantized, Rounding,
};

/// `raw / 2^shift` rounded by `mode`: Euclidean division, then `2 * remainder` compared with
/// the divisor. Only for `shift <= 125`, so that every intermediate fits in `i128`.
fn oracle_round(raw: i128, shift: u32, mode: Rounding) -> i128 {
    assert!(shift <= 125, "the oracle only handles shifts up to 125");
    let divisor = 1i128 << shift;
    let down = raw.div_euclid(divisor);
    let remainder = raw.rem_euclid(divisor);
    if remainder == 0 {
        return down;
    }
    let up = down + 1;
    let toward_zero = if raw < 0 { up } else { down };
    let away_from_zero = if raw < 0 { down } else { up };
    let even = if down % 2 == 0 { down } else { up };
    let odd = if down % 2 == 0 { up } else { down };
    let nearest_or = |on_tie: i128| match (2 * remainder).cmp(&divisor) {
        Ordering::Less => down,
        Ordering::Greater => up,
        Ordering::Equal => on_tie,
    };
    match mode {
        Rounding::Trn => down,
        Rounding::TrnZero => toward_zero,
        Rounding::Rnd => nearest_or(up),
        Rounding::RndZero => nearest_or(toward_zero),
        Rounding::RndInf => nearest_or(away_from_zero),
        Rounding::RndMinInf => nearest_or(down),
        Rounding::RndConv => nearest_or(even),
        Rounding::RndConvOdd => nearest_or(odd),
    }
}

/// Overflow handling written from the mode descriptions, on a value that fits in `i128`.
fn oracle_overflow(value: i128, signed: bool, width: u32, mode: Overflow) -> Quantized {
    let (min, max) = if signed {
        (-(1i128 << (width - 1)), (1i128 << (width - 1)) - 1)
    } else {
        (0, (1i128 << width) - 1)
    };
    let in_range = min <= value && value <= max;
    let (raw, event) = match mode {
        Overflow::Wrap => {
            let modulus = 1i128 << width;
            let mut wrapped = value % modulus;
            if wrapped < 0 {
                wrapped += modulus;
            }
            if wrapped > max {
                wrapped -= modulus;
            }
            let event = if in_range {
                Event::None
            } else {
                Event::Wrapped
            };
            (wrapped, event)
        }
        Overflow::Sat => {
            if value > max {
                (max, Event::Saturated)
            } else if value < min {
                (min, Event::Saturated)
            } else {
                (value, Event::None)
            }
        }
        Overflow::SatZero => {
            if in_range {
                (value, Event::None)
            } else {
                (0, Event::Zeroed)
            }
        }
        Overflow::SatSym => {
            // ac_fixed: for signed targets the most negative code is an overflow too, and the
            // negative result is -max, except for 1 bit where it can only be -1.
            let negative_result = if width > 1 { -max } else { min };
            if value > max {
                (max, Event::Saturated)
            } else if signed && value <= min {
                (negative_result, Event::Saturated)
            } else if value < min {
                (min, Event::Saturated)
            } else {
                (value, Event::None)
            }
        }
    };
    Quantized {
        raw: i64::try_from(raw).unwrap(),
        event,
    }
}

/// `raw` with its low `shift` bits replaced by a pattern chosen by `tail`: zero, exactly
/// half, half - 1, half + 1, all ones or 1, so that ties and near-ties come up often.
fn with_tail(raw: i128, shift: u32, tail: u8) -> i128 {
    if shift == 0 || shift >= 127 {
        return raw;
    }
    let mask = (1i128 << shift) - 1;
    let half = 1i128 << (shift - 1);
    let low = match tail % 6 {
        0 => 0,
        1 => half,
        2 => half - 1,
        3 => half + 1,
        4 => mask,
        _ => 1,
    } & mask;
    (raw & !mask) | low
}

fn any_rounding() -> impl Strategy<Value = Rounding> {
    prop::sample::select(Rounding::ALL.to_vec())
}

fn any_overflow() -> impl Strategy<Value = Overflow> {
    prop::sample::select(Overflow::ALL.to_vec())
}

/// A format with any signedness and width, and fraction bits in -70..=70.
fn any_format() -> impl Strategy<Value = Format> {
    (any::<bool>(), 1u32..=64, -70i32..=70).prop_map(|(signed, width, frac_bits)| {
        let width = if signed { width } else { width.min(63) };
        Format::new(signed, width as i32 - frac_bits, frac_bits).unwrap()
    })
}

/// An i128 raw whose magnitude is spread over all sizes, not only near 2^127.
fn any_sized_i128() -> impl Strategy<Value = i128> {
    (any::<i128>(), 0u32..128).prop_map(|(raw, drop)| raw >> drop)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2000))]

    #[test]
    fn round_shift_i64_matches_the_oracle(
        raw in any::<i64>(),
        shift in 0u32..=125,
        tail in any::<u8>(),
        structured in prop::bool::weighted(0.7),
        mode in any_rounding(),
    ) {
        let raw = if structured { with_tail(raw.into(), shift, tail) as i64 } else { raw };
        let expected = oracle_round(raw.into(), shift, mode);
        prop_assert_eq!(i128::from(round_shift_i64(raw, shift, mode)), expected);
        prop_assert_eq!(round_shift_i128(raw.into(), shift, mode), expected);
    }

    #[test]
    fn round_shift_i128_matches_the_oracle(
        raw in any_sized_i128(),
        shift in 0u32..=125,
        tail in any::<u8>(),
        structured in prop::bool::weighted(0.7),
        mode in any_rounding(),
    ) {
        let raw = if structured { with_tail(raw, shift, tail) } else { raw };
        prop_assert_eq!(round_shift_i128(raw, shift, mode), oracle_round(raw, shift, mode));
    }

    #[test]
    fn overflow_i64_matches_the_oracle(
        value in any::<i64>(),
        near_edge in prop::bool::weighted(0.5),
        offset in -3i64..=3,
        at_max in any::<bool>(),
        fmt in any_format(),
        mode in any_overflow(),
    ) {
        // Half the time, a value within 3 of min or max.
        let value = if near_edge {
            let edge = if at_max { fmt.max_raw() } else { fmt.min_raw() };
            edge.saturating_add(offset)
        } else {
            value >> (value as u64 % 64)
        };
        let expected = oracle_overflow(value.into(), fmt.is_signed(), fmt.width(), mode);
        prop_assert_eq!(overflow_i64(value, fmt, mode), expected);
    }

    #[test]
    fn quantize_matches_the_oracle(
        raw in any_sized_i128(),
        shift in -60i32..=125,
        tail in any::<u8>(),
        fmt in any_format(),
        rounding in any_rounding(),
        overflow in any_overflow(),
    ) {
        let frac_bits = fmt.frac_bits() + shift;
        let (raw, rounded) = if shift >= 0 {
            let raw = with_tail(raw, shift as u32, tail);
            (raw, oracle_round(raw, shift as u32, rounding))
        } else {
            // Keep the left-shifted value inside i128 for the oracle.
            let raw = raw >> 64;
            (raw, raw * (1i128 << -shift))
        };
        let expected = oracle_overflow(rounded, fmt.is_signed(), fmt.width(), overflow);
        let x = Exact::new(raw, frac_bits);
        prop_assert_eq!(quantize(x, fmt, rounding, overflow), expected);
    }

    #[test]
    fn quantize_i64_matches_quantize(
        raw in any::<i64>(),
        frac_bits in -150i32..=200,
        tail in any::<u8>(),
        fmt in any_format(),
        rounding in any_rounding(),
        overflow in any_overflow(),
    ) {
        let shift = frac_bits - fmt.frac_bits();
        let raw = raw >> (raw as u64 % 64);
        let raw = if shift > 0 { with_tail(raw.into(), shift as u32, tail) as i64 } else { raw };
        prop_assert_eq!(
            quantize_i64(raw, frac_bits, fmt, rounding, overflow),
            quantize(Exact::new(raw.into(), frac_bits), fmt, rounding, overflow)
        );
    }
}

#[test]
fn the_oracle_itself_agrees_with_hand_values() {
    // A few ties and non-ties computed by hand, so that a broken oracle cannot hide a bug.
    assert_eq!(oracle_round(-5, 1, Rounding::RndZero), -2);
    assert_eq!(oracle_round(-5, 1, Rounding::RndConv), -2);
    assert_eq!(oracle_round(-7, 1, Rounding::RndConv), -4);
    assert_eq!(oracle_round(-6, 2, Rounding::RndConvOdd), -1);
    assert_eq!(oracle_round(-3, 2, Rounding::TrnZero), 0);
    assert_eq!(oracle_round(3, 2, Rounding::RndZero), 1);
    let s4 = |v, mode| oracle_overflow(v, true, 4, mode);
    assert_eq!(
        s4(-8, Overflow::SatSym),
        Quantized {
            raw: -7,
            event: Event::Saturated
        }
    );
    assert_eq!(
        s4(-9, Overflow::Wrap),
        Quantized {
            raw: 7,
            event: Event::Wrapped
        }
    );
    assert_eq!(oracle_overflow(-1, false, 4, Overflow::Wrap).raw, 15);
}
