//! Maxima against `cos^n` with `exp` only where it can matter: a bounded approximation of
//! `cos^n` ([`exp_near_all`]) screens out the inputs whose error is provably below the
//! maximum, and only the others are computed exactly, in order, so that every maximum and the
//! first input where it happened are the bits the plain loop gives.
//!
//! The screen. For a column of errors `E_j = |a_j - p cos_j|` (computed in f64 as
//! `(a - p * cos).abs()`, `cos` = `exp(x_j)` by the libm), [`exp_near_all`] gives `cos'_j` with
//! `|cos'_j - cos_j| <= 2^-43 cos'_j + 2^-1009` (below). Then the error computed with `cos'`,
//! `E'_j`, is within `M_j = 2^-36 (p cos'_j + E'_j) + (p + 1) 2^-1000` of `E_j`, with room to
//! spare for the roundings of the products, the differences and the bound itself (each at most
//! 2^-53 relative). So `E'_j - M_j <= E_j <= E'_j + M_j`, and with `V` at most the column's
//! final maximum (the running maximum before the chunk, or the largest `E'_j - M_j` in it: both
//! are at most some `E_j`), every input with `E'_j + M_j < V` has `E_j < V`: it is neither the
//! maximum nor where the maximum first happened, and is left out. A NaN or an infinity never
//! passes the screen (it is looked at exactly).

/// The margin's relative part (see the module's text).
const MARGIN: f64 = 1.0 / (1u64 << 36) as f64;

/// `e^x`, within a relative `2^-43` of the exact value for `x` in `[-700, 700]`; below -700,
/// `e^-700` to that precision (the exact value is then below `2^-1009`).
///
/// The error bound: `x = k ln2 + r` with `k` the integer nearest `x / ln2` (`|k| <= 1010`, so
/// `k * LN2_HI`, 43 bits, is exact, and so is `x - k * LN2_HI` by Sterbenz's lemma) and
/// `|r| <= 0.3466`; `r` is off by at most `2^-53 |r| + 2^-53 |k LN2_LO| + |k| 2^-86`, below
/// `2^-53`. `e^r` by its Taylor polynomial of degree 13 evaluated by Horner's rule (each step
/// one fused multiply-add, or a product and a sum): the remainder is below
/// `e^0.35 0.3466^14 / 14! < 2^-59`, relative; the coefficients' and the 26 operations'
/// roundings below `30 * 2^-53 < 2^-48`. `2^k` is exact and so is the product by it (normal
/// results: `e^-700 > 2^-1010`). In all, below `2^-47` relative; the libm's `exp` (the exact
/// path) is within one ulp, `2^-52`; `2^-43` leaves a factor of 8.
/// `tests::exp_near_is_within_its_bound` measures both paths against the libm.
#[inline(always)]
fn exp_near_with(x: f64, fma: impl Fn(f64, f64, f64) -> f64) -> f64 {
    /// 1.5 * 2^52: adding it rounds to an integer, held in the low bits of the sum.
    const SHIFT: f64 = 6_755_399_441_055_744.0;
    /// ln 2 in two parts (fdlibm's `ln2_hi` and `ln2_lo`): the first with 32 significant bits.
    const LN2_HI: f64 = f64::from_bits(0x3fe6_2e42_fee0_0000);
    const LN2_LO: f64 = f64::from_bits(0x3dea_39ef_3579_3c76);
    const INV_FACTORIALS: [f64; 14] = {
        let mut f = [1.0; 14];
        let mut k = 1;
        while k < 14 {
            f[k] = f[k - 1] / k as f64;
            k += 1;
        }
        f
    };
    let x = x.clamp(-700.0, 700.0);
    let t = x * std::f64::consts::LOG2_E + SHIFT;
    let k = t - SHIFT;
    let r = (x - k * LN2_HI) - k * LN2_LO;
    let mut p = INV_FACTORIALS[13];
    for k in (0..13).rev() {
        p = fma(p, r, INV_FACTORIALS[k]);
    }
    // The low bits of t's representation are k + 2^51: k + 1023, in 1..=2046, shifted into
    // the exponent field is 2^k.
    p * f64::from_bits(t.to_bits().wrapping_add(1023) << 52)
}

/// [`exp_near_with`] without fused operations.
#[inline(always)]
fn exp_near(x: f64) -> f64 {
    exp_near_with(x, |a, b, c| a * b + c)
}

/// Whether the AVX2 and FMA paths run here.
fn simd() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma")
    }
    #[cfg(not(target_arch = "x86_64"))]
    false
}

/// `e^x` of every element, in place, within the bound of [`exp_near_with`].
pub(super) fn exp_near_all(xs: &mut [f64]) {
    exp_near_all_on(xs, simd());
}

/// [`exp_near_all`], on the AVX2 and FMA path when `simd` (the caller has checked the CPU).
fn exp_near_all_on(xs: &mut [f64], simd: bool) {
    #[cfg(target_arch = "x86_64")]
    if simd {
        // SAFETY: the CPU has AVX2 and FMA (the caller's `simd`).
        unsafe { x86::exp_near_all(xs) };
        return;
    }
    debug_assert!(!simd);
    for x in xs {
        *x = exp_near(*x);
    }
}

/// Screens two columns of errors against `cos^n`, `|a_j - p cos_j|` and `|b_j - p cos_j|`,
/// whose running maxima are `floors` (-1 before the first), `near` the columns'
/// [`exp_near_all`] of `cos^n`: calls `visit(j, for_a, for_b)` in increasing `j` for every
/// element that may reach a maximum (`for_a`, `for_b`: which), the others left out. `hi` is
/// scratch.
pub(super) fn screen_two(
    a: &[f64],
    b: &[f64],
    p: f64,
    near: &[f64],
    floors: (f64, f64),
    hi: &mut Vec<f64>,
    visit: impl FnMut(usize, bool, bool),
) {
    screen_two_on(a, b, p, near, floors, hi, visit, simd());
}

/// [`screen_two`], on the AVX2 path when `simd` (the caller has checked the CPU).
#[allow(clippy::too_many_arguments)]
fn screen_two_on(
    a: &[f64],
    b: &[f64],
    p: f64,
    near: &[f64],
    floors: (f64, f64),
    hi: &mut Vec<f64>,
    mut visit: impl FnMut(usize, bool, bool),
    simd: bool,
) {
    let len = near.len();
    let (a, b) = (&a[..len], &b[..len]);
    hi.resize(2 * len, 0.0);
    let (hi_a, hi_b) = hi.split_at_mut(len);
    let tiny = (p + 1.0) * f64::from_bits(((1023 - 1000) as u64) << 52);
    #[cfg(target_arch = "x86_64")]
    let low = if simd {
        // SAFETY: the CPU has AVX2 (the caller's `simd`); the columns are `len` long.
        unsafe { x86::bounds(a, b, p, near, tiny, hi_a, hi_b) }
    } else {
        bounds(a, b, p, near, tiny, hi_a, hi_b)
    };
    #[cfg(not(target_arch = "x86_64"))]
    let low = bounds(a, b, p, near, tiny, hi_a, hi_b);
    let (va, vb) = (floors.0.max(low.0), floors.1.max(low.1));
    let look = |i: usize| (may_reach(hi_a[i], va), may_reach(hi_b[i], vb));
    // Four at a time: most quads have nothing to look at.
    for start in (0..len).step_by(4) {
        let quad = start..(start + 4).min(len);
        if quad.clone().all(|i| hi_a[i] < va && hi_b[i] < vb) {
            continue;
        }
        for i in quad {
            let (for_a, for_b) = look(i);
            if for_a || for_b {
                visit(i, for_a, for_b);
            }
        }
    }
}

/// Whether an error bounded above by `hi` may reach `floor`: also where `hi` is NaN.
#[allow(clippy::neg_cmp_op_on_partial_ord)]
fn may_reach(hi: f64, floor: f64) -> bool {
    !(hi < floor)
}

/// Each element's upper bound `E' + M` of both errors into `hi_a` and `hi_b`; returns the
/// largest lower bound `E' - M` of each (a NaN skipped).
fn bounds(
    a: &[f64],
    b: &[f64],
    p: f64,
    near: &[f64],
    tiny: f64,
    hi_a: &mut [f64],
    hi_b: &mut [f64],
) -> (f64, f64) {
    let (mut low_a, mut low_b) = (f64::NEG_INFINITY, f64::NEG_INFINITY);
    for j in 0..near.len() {
        let pc = p * near[j];
        let (ea, eb) = ((a[j] - pc).abs(), (b[j] - pc).abs());
        let (ma, mb) = (MARGIN * (pc + ea) + tiny, MARGIN * (pc + eb) + tiny);
        hi_a[j] = ea + ma;
        hi_b[j] = eb + mb;
        low_a = low_a.max(ea - ma);
        low_b = low_b.max(eb - mb);
    }
    (low_a, low_b)
}

#[cfg(target_arch = "x86_64")]
mod x86 {
    //! The AVX2 (and FMA) kernels of the screen: the same bounds, four lanes at a time.
    use super::MARGIN;
    use std::arch::x86_64::*;

    /// [`super::exp_near_with`] of every element with fused multiply-adds.
    ///
    /// # Safety
    /// The CPU has AVX2 and FMA.
    #[target_feature(enable = "avx2,fma")]
    pub(super) fn exp_near_all(xs: &mut [f64]) {
        for x in xs {
            *x = super::exp_near_with(*x, f64::mul_add);
        }
    }

    /// [`super::bounds`], four lanes at a time.
    ///
    /// # Safety
    /// The CPU has AVX2; every column is as long as `near`.
    #[target_feature(enable = "avx2")]
    pub(super) fn bounds(
        a: &[f64],
        b: &[f64],
        p: f64,
        near: &[f64],
        tiny: f64,
        hi_a: &mut [f64],
        hi_b: &mut [f64],
    ) -> (f64, f64) {
        let len = near.len();
        assert!(a.len() == len && b.len() == len && hi_a.len() == len && hi_b.len() == len);
        let (vp, margin, vtiny, sign) = (
            _mm256_set1_pd(p),
            _mm256_set1_pd(MARGIN),
            _mm256_set1_pd(tiny),
            _mm256_set1_pd(-0.0),
        );
        let (mut low_a, mut low_b) = (
            _mm256_set1_pd(f64::NEG_INFINITY),
            _mm256_set1_pd(f64::NEG_INFINITY),
        );
        let quads = len / 4;
        for q in 0..quads {
            let j = 4 * q;
            // SAFETY: j + 4 <= len for every column (asserted above): unaligned loads and
            // stores of four elements.
            unsafe {
                let pc = _mm256_mul_pd(vp, _mm256_loadu_pd(near.as_ptr().add(j)));
                let ea =
                    _mm256_andnot_pd(sign, _mm256_sub_pd(_mm256_loadu_pd(a.as_ptr().add(j)), pc));
                let eb =
                    _mm256_andnot_pd(sign, _mm256_sub_pd(_mm256_loadu_pd(b.as_ptr().add(j)), pc));
                let ma = _mm256_add_pd(_mm256_mul_pd(margin, _mm256_add_pd(pc, ea)), vtiny);
                let mb = _mm256_add_pd(_mm256_mul_pd(margin, _mm256_add_pd(pc, eb)), vtiny);
                _mm256_storeu_pd(hi_a.as_mut_ptr().add(j), _mm256_add_pd(ea, ma));
                _mm256_storeu_pd(hi_b.as_mut_ptr().add(j), _mm256_add_pd(eb, mb));
                // max_pd(x, low) is low where x is NaN.
                low_a = _mm256_max_pd(_mm256_sub_pd(ea, ma), low_a);
                low_b = _mm256_max_pd(_mm256_sub_pd(eb, mb), low_b);
            }
        }
        let lanes = |x: __m256d| {
            let mut out = [0.0f64; 4];
            // SAFETY: the store writes the four values of `out`.
            unsafe { _mm256_storeu_pd(out.as_mut_ptr(), x) };
            out
        };
        let tail = 4 * quads;
        let (ta, tb) = super::bounds(
            &a[tail..],
            &b[tail..],
            p,
            &near[tail..],
            tiny,
            &mut hi_a[tail..],
            &mut hi_b[tail..],
        );
        let fold = |l: [f64; 4], t: f64| l.iter().fold(t, |m, &v| m.max(v));
        (fold(lanes(low_a), ta), fold(lanes(low_b), tb))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analysis::accumulate::MaxAt;

    /// A deterministic stream of f64s in [0, 1).
    fn uniform(seed: &mut u64) -> f64 {
        *seed = seed
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (*seed >> 11) as f64 / (1u64 << 53) as f64
    }

    #[test]
    fn exp_near_is_within_its_bound() {
        let mut seed = 7;
        let mut worst: f64 = 0.0;
        let mut xs: Vec<f64> = (0..200_000).map(|_| -700.0 * uniform(&mut seed)).collect();
        // Near the range reduction's half-way points and the ends.
        for k in -1010..=1010 {
            let h = (f64::from(k) + 0.5) * std::f64::consts::LN_2;
            xs.extend([h, h.next_up(), h.next_down()]);
        }
        xs.extend([0.0, -0.0, -700.0, 700.0, -1e-300, 1e-300, -20.0, -16.0]);
        xs.retain(|x| (-700.0..=700.0).contains(x));
        for simd in [false, simd()] {
            let mut near = xs.clone();
            exp_near_all_on(&mut near, simd);
            for (&x, &n) in xs.iter().zip(&near) {
                let e = x.exp();
                worst = worst.max((n - e).abs() / e);
            }
        }
        assert!(worst < 2f64.powi(-49), "relative error {worst:e}");
        // Below -700: e^-700 within the bound, above the exact value.
        let (n, e700) = (exp_near(-5000.0), (-700f64).exp());
        assert!((n - e700).abs() < 2f64.powi(-49) * e700 && e700 < 2f64.powi(-1009));
    }

    /// The screened maxima are the plain loop's maxima and first places, on columns made to
    /// tie and to rise: errors that climb code by code (every element a new maximum), equal
    /// maxima at several places, a running maximum above the whole chunk, NaNs, cos^n of 0.
    #[test]
    fn the_screen_keeps_every_maximum_and_its_first_place() {
        let mut seed = 11;
        for case in 0..400 {
            let len = 1 + (uniform(&mut seed) * 300.0) as usize;
            let p = [1.0, 173.16, 0.5][case % 3];
            let xs: Vec<f64> = (0..len)
                .map(|j| match case % 4 {
                    0 => -16.0 * (1.0 - j as f64 / len as f64),
                    1 => -700.0 * uniform(&mut seed),
                    2 => -2.0 - (j % 5) as f64,
                    _ => f64::NEG_INFINITY,
                })
                .collect();
            let cos: Vec<f64> = xs
                .iter()
                .map(|&x| if x == f64::NEG_INFINITY { 0.0 } else { x.exp() })
                .collect();
            let col = |seed: &mut u64| -> Vec<f64> {
                (0..len)
                    .map(|j| match case % 5 {
                        0 => p * cos[j] + (j as f64) * 1e-9,
                        1 => p * cos[j] + [0.25, -0.25][j % 2],
                        2 if j == len / 2 => f64::NAN,
                        3 => p * cos[j] * (1.0 + 1e-15 * uniform(seed)),
                        _ => uniform(seed) * p,
                    })
                    .collect()
            };
            let (a, b) = (col(&mut seed), col(&mut seed));
            let floors = if case % 7 == 0 {
                (0.3, 0.2)
            } else {
                (-1.0, -1.0)
            };
            let mut looked = 0;
            let plain = |v: &[f64], floor: f64| {
                let mut m = MaxAt::new();
                if floor >= 0.0 {
                    m.add(floor, (0, -1));
                }
                for j in 0..len {
                    m.add((v[j] - p * cos[j]).abs(), (0, j as i64));
                }
                (m.value.to_bits(), m.at)
            };
            for simd in [false, simd()] {
                let mut near = xs.clone();
                exp_near_all_on(&mut near, simd);
                let (mut ma, mut mb) = (MaxAt::new(), MaxAt::new());
                if floors.0 >= 0.0 {
                    ma.add(floors.0, (0, -1));
                    mb.add(floors.1, (0, -1));
                }
                let mut seen = 0;
                screen_two_on(
                    &a,
                    &b,
                    p,
                    &near,
                    (ma.value, mb.value),
                    &mut Vec::new(),
                    |j, for_a, for_b| {
                        seen += 1;
                        if for_a {
                            ma.add((a[j] - p * cos[j]).abs(), (0, j as i64));
                        }
                        if for_b {
                            mb.add((b[j] - p * cos[j]).abs(), (0, j as i64));
                        }
                    },
                    simd,
                );
                let at = format!("case {case}, simd {simd}");
                assert_eq!((ma.value.to_bits(), ma.at), plain(&a, floors.0), "{at}");
                assert_eq!((mb.value.to_bits(), mb.at), plain(&b, floors.1), "{at}");
                looked = looked.max(seen);
            }
            if case % 5 == 4 && len > 100 && floors.0 < 0.0 {
                assert!(looked < len / 2, "case {case}: {looked} of {len} looked at");
            }
        }
    }
}
