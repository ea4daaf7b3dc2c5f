//! Differential tests against the `fixed` crate wherever both express the same operation.
//!
//! Facts about `fixed` 1.x checked here (from its source, `arith.rs` and `macros_from_to.rs`,
//! and pinned by the hand-computed tests at the bottom):
//! * `wrapping_mul`, `saturating_mul` and `overflowing_mul` compute the exact product in double
//!   width and drop the extra fraction bits with an arithmetic shift: they round toward -inf
//!   (our `TRN`), then wrap or saturate; the overflow flag is raised when the floored product
//!   is out of range.
//! * `from_num` / `wrapping_from_num` / `saturating_from_num` of another fixed-point number
//!   discard extra fraction bits, which also rounds toward -inf (`TRN`).
//! * `from_num` / `wrapping_from_num` / `saturating_from_num` of an `f64` round to nearest,
//!   ties to even (`RND_CONV`).
use fixed::types::extra::{U0, U12, U16, U3, U32, U63, U8};
use fixed::{FixedI16, FixedI32, FixedI64, FixedI8, FixedU16, FixedU32};
use proptest::prelude::*;

use crate::fixed::{quantize, Event, Exact, Format, Overflow, Quantized, Rounding};

fn fmt(text: &str) -> Format {
    text.parse().unwrap()
}

/// Quantize with `TRN`, as `fixed` rounds its products and fixed-to-fixed conversions.
fn trn(x: Exact, f: Format, overflow: Overflow) -> Quantized {
    quantize(x, f, Rounding::Trn, overflow)
}

/// The same operations on one `fixed` type and on our `Exact` + `quantize`.
macro_rules! same_format_ops {
    ($module:ident, $Fix:ty, $Bits:ty, $notation:literal) => {
        mod $module {
            use super::*;

            type Fix = $Fix;

            fn ours(bits: $Bits) -> Exact {
                Exact::from_raw(bits as i64, fmt($notation))
            }

            proptest! {
                #![proptest_config(ProptestConfig::with_cases(1000))]

                #[test]
                fn add_sub_mul_wrap_and_saturate_alike(a in any::<$Bits>(), b in any::<$Bits>()) {
                    let f = fmt($notation);
                    let (fa, fb) = (Fix::from_bits(a), Fix::from_bits(b));
                    let (x, y) = (ours(a), ours(b));

                    let wrapped = trn(x + y, f, Overflow::Wrap);
                    let (theirs, flag) = fa.overflowing_add(fb);
                    prop_assert_eq!(wrapped.raw, fa.wrapping_add(fb).to_bits() as i64);
                    prop_assert_eq!(wrapped.raw, theirs.to_bits() as i64);
                    prop_assert_eq!(wrapped.event == Event::Wrapped, flag);
                    let saturated = trn(x + y, f, Overflow::Sat);
                    prop_assert_eq!(saturated.raw, fa.saturating_add(fb).to_bits() as i64);
                    prop_assert_eq!(saturated.event == Event::Saturated, flag);

                    let wrapped = trn(x - y, f, Overflow::Wrap);
                    let (theirs, flag) = fa.overflowing_sub(fb);
                    prop_assert_eq!(wrapped.raw, fa.wrapping_sub(fb).to_bits() as i64);
                    prop_assert_eq!(wrapped.raw, theirs.to_bits() as i64);
                    prop_assert_eq!(wrapped.event == Event::Wrapped, flag);
                    let saturated = trn(x - y, f, Overflow::Sat);
                    prop_assert_eq!(saturated.raw, fa.saturating_sub(fb).to_bits() as i64);

                    let wrapped = trn(x * y, f, Overflow::Wrap);
                    let (theirs, flag) = fa.overflowing_mul(fb);
                    prop_assert_eq!(wrapped.raw, fa.wrapping_mul(fb).to_bits() as i64);
                    prop_assert_eq!(wrapped.raw, theirs.to_bits() as i64);
                    prop_assert_eq!(wrapped.event == Event::Wrapped, flag);
                    let saturated = trn(x * y, f, Overflow::Sat);
                    prop_assert_eq!(saturated.raw, fa.saturating_mul(fb).to_bits() as i64);
                    prop_assert_eq!(saturated.event == Event::Saturated, flag);
                }

                #[test]
                fn values_agree(a in any::<$Bits>()) {
                    let f = fmt($notation);
                    prop_assert_eq!(f.to_f64(a as i64), Fix::from_bits(a).to_num::<f64>());
                    prop_assert_eq!(ours(a).to_f64(), Fix::from_bits(a).to_num::<f64>());
                    prop_assert_eq!(f.min_raw(), Fix::MIN.to_bits() as i64);
                    prop_assert_eq!(f.max_raw(), Fix::MAX.to_bits() as i64);
                }

                #[test]
                fn from_f64_rounds_to_nearest_even_alike(
                    mantissa in any::<i64>(),
                    exponent in -90i32..=40,
                    tie in any::<bool>(),
                ) {
                    let f = fmt($notation);
                    // Either an arbitrary value, or exactly k + 1/2 LSBs.
                    let x = if tie {
                        ((mantissa >> 40) as f64 + 0.5) * f.lsb()
                    } else {
                        (mantissa >> 11) as f64 * 2f64.powi(exponent)
                    };
                    let exact = Exact::from_f64(x).unwrap();
                    let wrapped = quantize(exact, f, Rounding::RndConv, Overflow::Wrap);
                    let (theirs, flag) = Fix::overflowing_from_num(x);
                    prop_assert_eq!(wrapped.raw, Fix::wrapping_from_num(x).to_bits() as i64);
                    prop_assert_eq!(wrapped.raw, theirs.to_bits() as i64);
                    prop_assert_eq!(wrapped.event == Event::Wrapped, flag);
                    let saturated = quantize(exact, f, Rounding::RndConv, Overflow::Sat);
                    prop_assert_eq!(saturated.raw, Fix::saturating_from_num(x).to_bits() as i64);
                }
            }
        }
    };
}

same_format_ops!(i8_3, FixedI8<U3>, i8, "s5.3");
same_format_ops!(i16_8, FixedI16<U8>, i16, "s8.8");
same_format_ops!(u16_8, FixedU16<U8>, u16, "u8.8");
same_format_ops!(i16_0, FixedI16<U0>, i16, "s16.0");
same_format_ops!(u16_16, FixedU16<U16>, u16, "u0.16");
same_format_ops!(i32_16, FixedI32<U16>, i32, "s16.16");
same_format_ops!(u32_16, FixedU32<U16>, u32, "u16.16");
same_format_ops!(i32_32, FixedI32<U32>, i32, "s0.32");
same_format_ops!(i64_32, FixedI64<U32>, i64, "s32.32");
same_format_ops!(i64_63, FixedI64<U63>, i64, "s1.63");

/// Conversion from one `fixed` type to another against `quantize` with `TRN`.
macro_rules! conversion {
    ($name:ident, $Src:ty, $SrcBits:ty, $src:literal, $Dst:ty, $dst:literal) => {
        proptest! {
            #![proptest_config(ProptestConfig::with_cases(1000))]

            #[test]
            fn $name(bits in any::<$SrcBits>(), scale in 0u32..32) {
                // Spread the magnitudes so that in-range values come up as often as overflows.
                let bits = bits >> (scale % <$SrcBits>::BITS);
                let source = <$Src>::from_bits(bits);
                let x = Exact::from_raw(bits as i64, fmt($src));
                let to = fmt($dst);
                let wrapped = trn(x, to, Overflow::Wrap);
                let (theirs, flag) = <$Dst>::overflowing_from_num(source);
                prop_assert_eq!(wrapped.raw, <$Dst>::wrapping_from_num(source).to_bits() as i64);
                prop_assert_eq!(wrapped.raw, theirs.to_bits() as i64);
                prop_assert_eq!(wrapped.event == Event::Wrapped, flag);
                let saturated = trn(x, to, Overflow::Sat);
                prop_assert_eq!(saturated.raw, <$Dst>::saturating_from_num(source).to_bits() as i64);
                prop_assert_eq!(saturated.event == Event::Saturated, flag);
            }
        }
    };
}

conversion!(
    i32_16_to_i16_8,
    FixedI32<U16>,
    i32,
    "s16.16",
    FixedI16<U8>,
    "s8.8"
);
conversion!(
    i16_8_to_i32_16,
    FixedI16<U8>,
    i16,
    "s8.8",
    FixedI32<U16>,
    "s16.16"
);
conversion!(
    i16_8_to_i16_12,
    FixedI16<U8>,
    i16,
    "s8.8",
    FixedI16<U12>,
    "s4.12"
);
conversion!(
    u32_16_to_i16_8,
    FixedU32<U16>,
    u32,
    "u16.16",
    FixedI16<U8>,
    "s8.8"
);
conversion!(
    i32_16_to_u16_8,
    FixedI32<U16>,
    i32,
    "s16.16",
    FixedU16<U8>,
    "u8.8"
);
conversion!(
    i64_32_to_i8_3,
    FixedI64<U32>,
    i64,
    "s32.32",
    FixedI8<U3>,
    "s5.3"
);
conversion!(
    i64_63_to_i32_32,
    FixedI64<U63>,
    i64,
    "s1.63",
    FixedI32<U32>,
    "s0.32"
);
conversion!(
    u16_16_to_i32_16,
    FixedU16<U16>,
    u16,
    "u0.16",
    FixedI32<U16>,
    "s16.16"
);

type I16F8 = FixedI16<U8>;

#[test]
fn fixed_mul_rounds_toward_minus_infinity() {
    // -1/256 * 1/2 = -1/512: floor gives -1/256 (bits -1); toward zero would give 0.
    let product = I16F8::from_bits(-1).wrapping_mul(I16F8::from_bits(128));
    assert_eq!(product.to_bits(), -1);
    // 3/256 * 1/2 = 1.5/256: floor gives 1, nearest would give 2.
    let product = I16F8::from_bits(3).wrapping_mul(I16F8::from_bits(128));
    assert_eq!(product.to_bits(), 1);
    // Ours with TRN agrees; with RND_CONV it would differ.
    let s88 = fmt("s8.8");
    let x = Exact::from_raw(3, s88) * Exact::from_raw(128, s88);
    assert_eq!(trn(x, s88, Overflow::Wrap).raw, 1);
    assert_eq!(quantize(x, s88, Rounding::RndConv, Overflow::Wrap).raw, 2);
}

#[test]
fn fixed_from_fixed_rounds_toward_minus_infinity() {
    // -2^-16 in s16.16 to s8.8: floor gives -1/256 (bits -1).
    let narrowed = I16F8::from_num(FixedI32::<U16>::from_bits(-1));
    assert_eq!(narrowed.to_bits(), -1);
    // 0x180 * 2^-16 = 1.5/256: floor gives bits 1.
    let narrowed = I16F8::from_num(FixedI32::<U16>::from_bits(0x180));
    assert_eq!(narrowed.to_bits(), 1);
}

#[test]
fn fixed_from_f64_rounds_ties_to_even() {
    let lsb = 1.0 / 256.0;
    assert_eq!(I16F8::from_num(1.5 * lsb).to_bits(), 2);
    assert_eq!(I16F8::from_num(2.5 * lsb).to_bits(), 2);
    assert_eq!(I16F8::from_num(-2.5 * lsb).to_bits(), -2);
    assert_eq!(I16F8::from_num(-1.5 * lsb).to_bits(), -2);
    assert_eq!(I16F8::from_num(2.5000001 * lsb).to_bits(), 3);
    assert_eq!(I16F8::saturating_from_num(1000.0).to_bits(), i16::MAX);
    assert_eq!(I16F8::saturating_from_num(-1000.0).to_bits(), i16::MIN);
}
