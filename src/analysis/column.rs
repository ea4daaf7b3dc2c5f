//! The error figures of one column of a stage (its raw values against their f64 references) in
//! one pass: four lanes per figure, in an order that is part of the figures' bits, with an AVX2
//! kernel where the CPU has it and the portable loop, its oracle, everywhere.
//!
//! Element `i` of a column goes to lane `i % 4` while whole quads remain and the rest to lane
//! 0; each sum joins its lanes as `(l0 + l1) + (l2 + l3)`. Every output of the exhaustive check
//! is the same bytes from one version to the next and with any number of threads, so neither
//! kernel may change that order, use FMA, or reassociate.

/// The raw values of a column.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Raws<'a> {
    /// One value for every element.
    Constant(i64),
    /// Values whose magnitudes are below 2^51 (formats of at most [`NARROW_BITS`] bits).
    Narrow(&'a [i64]),
    /// Any values.
    Wide(&'a [i64]),
}

impl<'a> Raws<'a> {
    /// A stage's column: narrow when its format has at most [`NARROW_BITS`] bits.
    pub(crate) fn of(column: &'a [i64], width: u32) -> Raws<'a> {
        if width <= NARROW_BITS {
            Raws::Narrow(column)
        } else {
            Raws::Wide(column)
        }
    }
}

/// The widest format whose raw values [`narrow_to_f64`] converts.
pub(crate) const NARROW_BITS: u32 = 51;

/// `x as f64` for `|x| < 2^51`, exact both ways: the bits of `1.5 * 2^52 + x` minus
/// `1.5 * 2^52` (an integer addition and one f64 subtraction, which vectorise where `as f64`
/// of an `i64` does not before AVX-512).
#[inline(always)]
pub(crate) fn narrow_to_f64(x: i64) -> f64 {
    f64::from_bits((x as u64).wrapping_add(MAGIC.to_bits())) - MAGIC
}

/// 1.5 * 2^52.
const MAGIC: f64 = 6_755_399_441_055_744.0;

/// The reference of an element from the column of references: `refs[i]` itself, or
/// `scale * refs[i]` (t's reference from d's, `slope * d`).
#[derive(Debug, Clone, Copy)]
pub(crate) enum Map {
    /// The reference as it is.
    Identity,
    /// The reference times this factor (the factor on the left, as `slope * d`).
    Scale(f64),
}

impl Map {
    #[inline(always)]
    fn apply(self, x: f64) -> f64 {
        match self {
            Map::Identity => x,
            Map::Scale(s) => s * x,
        }
    }
}

/// The f64 references of a column, before their [`Map`].
#[derive(Debug, Clone, Copy)]
pub(crate) enum References<'a> {
    /// One per element.
    Column(&'a [f64]),
    /// d's reference `code * c_lsb - 1` of `len` consecutive codes from `first` (none above
    /// the code of 1.0), computed instead of read: the overflowed prefix of every n reads no
    /// memory.
    D {
        /// The first code.
        first: i64,
        /// How many codes.
        len: usize,
        /// The input's LSB.
        c_lsb: f64,
    },
}

impl References<'_> {
    /// How many references.
    pub(crate) fn len(self) -> usize {
        match self {
            References::Column(r) => r.len(),
            References::D { len, .. } => len,
        }
    }

    /// Reference `i`.
    #[inline(always)]
    fn at(self, i: usize) -> f64 {
        match self {
            References::Column(r) => r[i],
            References::D { first, c_lsb, .. } => (first + i as i64) as f64 * c_lsb - 1.0,
        }
    }
}

/// The figures of one column: the lanes joined, ready to add to a running total.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct ColumnFigures {
    /// max |error|, `-inf` for an empty column (a NaN error is skipped).
    pub(crate) max_abs: f64,
    /// The first element where `max_abs` is reached, if the column is not empty.
    pub(crate) worst: Option<usize>,
    /// Sum of the errors.
    pub(crate) sum: f64,
    /// Sum of |error|.
    pub(crate) sum_abs: f64,
    /// Sum of squared errors.
    pub(crate) sum_sq: f64,
    /// Errors within `half` (correctly rounded).
    pub(crate) n_correct: u64,
    /// Errors below `one` (faithfully rounded).
    pub(crate) n_faithful: u64,
    /// The smallest and the largest raw value (`(i64::MAX, i64::MIN)` for an empty column).
    pub(crate) raw_range: (i64, i64),
}

/// The figures of the column `raws` (value `raw * lsb`) against the references `map(refs)`:
/// errors `raw * lsb - map(ref)`, counted as correct when `|error| <= half` and faithful when
/// `|error| < one`. `worst` is looked for only when `max_abs > above` (the caller's running
/// maximum), since only then is it used.
pub(crate) fn column_figures(
    raws: Raws<'_>,
    lsb: f64,
    refs: References<'_>,
    map: Map,
    half: f64,
    one: f64,
    above: f64,
) -> ColumnFigures {
    if let Raws::Narrow(r) | Raws::Wide(r) = raws {
        assert_eq!(r.len(), refs.len(), "a raw value for every reference");
    }
    if let Some(f) = monotone(raws, lsb, refs, map, half, one, above) {
        return f;
    }
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the CPU has AVX2, checked just above, and the lengths agree (asserted).
        let mut f = unsafe { avx2::figures(raws, lsb, refs, map, half, one) };
        f.worst = f.worst.filter(|_| f.max_abs > above);
        return f;
    }
    portable(raws, lsb, refs, map, half, one, above)
}

/// The figures of a column whose errors are proven non-increasing in the element's index:
/// one raw value against d's references of consecutive codes (increasing), mapped by the
/// identity or a factor of at least 0. Each operation from the code to the error (the code in
/// f64, exact; times the LSB, exact; minus 1, times the factor, the value minus that, each
/// rounded by a monotone rounding) keeps the order, so the largest |error| is at an end, and
/// the elements within `half` or below `one` are one run, found by bisection. Only the three
/// sums look at every element. None where the proof does not hold.
fn monotone(
    raws: Raws<'_>,
    lsb: f64,
    refs: References<'_>,
    map: Map,
    half: f64,
    one: f64,
    above: f64,
) -> Option<ColumnFigures> {
    let (Raws::Constant(raw), References::D { first, len, c_lsb }) = (raws, refs) else {
        return None;
    };
    if let Map::Scale(s) = map {
        if !(s >= 0.0 && s.is_finite()) {
            return None;
        }
    }
    if len == 0 {
        return None;
    }
    let value = raw as f64 * lsb;
    let err = |i: usize| error(raws, lsb, refs, map, i);
    let (e_first, e_last) = (err(0), err(len - 1));
    if !(e_first.is_finite() && e_last.is_finite()) {
        return None;
    }
    // The first index of a suffix where `holds` (a predicate true from some index on).
    let suffix_start = |holds: &dyn Fn(f64) -> bool| {
        let (mut lo, mut hi) = (0usize, len);
        while lo < hi {
            let mid = lo + (hi - lo) / 2;
            if holds(err(mid)) {
                hi = mid;
            } else {
                lo = mid + 1;
            }
        }
        lo
    };
    // The errors e with lo_ok(e) and hi_ok(e): below hi from some index on, above lo up to
    // some index.
    let run = |below: &dyn Fn(f64) -> bool, above_lo: &dyn Fn(f64) -> bool| {
        let from = suffix_start(below);
        let to = suffix_start(&|e| !above_lo(e));
        to.saturating_sub(from) as u64
    };
    let n_correct = run(&|e| e <= half, &|e| e >= -half);
    let n_faithful = run(&|e| e < one, &|e| e > -one);
    // The largest |error| is at the first element, or else on the run of the last value
    // (then negative, and larger in magnitude than every error above it).
    let (max_abs, at) = if e_first.abs() >= e_last.abs() {
        (e_first.abs(), 0)
    } else {
        (e_last.abs(), suffix_start(&|e| e <= e_last))
    };
    let (sum, sum_abs, sum_sq) = monotone_sums(value, map, first, len, c_lsb);
    Some(ColumnFigures {
        max_abs,
        worst: (max_abs > above).then_some(at),
        sum,
        sum_abs,
        sum_sq,
        n_correct,
        n_faithful,
        raw_range: (raw, raw),
    })
}

/// The three sums of [`monotone`]'s column, in the module's lane order.
fn monotone_sums(value: f64, map: Map, first: i64, len: usize, c_lsb: f64) -> (f64, f64, f64) {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the CPU has AVX2, checked just above.
        return unsafe { avx2::monotone_sums(value, map, first, len, c_lsb) };
    }
    monotone_sums_portable(value, map, first, len, c_lsb)
}

/// [`monotone_sums`] element by element.
fn monotone_sums_portable(
    value: f64,
    map: Map,
    first: i64,
    len: usize,
    c_lsb: f64,
) -> (f64, f64, f64) {
    let refs = References::D { first, len, c_lsb };
    let (mut sum, mut sum_abs, mut sum_sq) = ([0.0f64; 4], [0.0f64; 4], [0.0f64; 4]);
    let whole = len / 4 * 4;
    for i in 0..len {
        let lane = if i < whole { i % 4 } else { 0 };
        let e = value - map.apply(refs.at(i));
        sum[lane] += e;
        sum_abs[lane] += e.abs();
        sum_sq[lane] += e * e;
    }
    (join(sum), join(sum_abs), join(sum_sq))
}

/// The error of element `i`.
#[inline(always)]
fn error(raws: Raws<'_>, lsb: f64, refs: References<'_>, map: Map, i: usize) -> f64 {
    let value = match raws {
        Raws::Constant(r) => r as f64 * lsb,
        Raws::Narrow(r) => narrow_to_f64(r[i]) * lsb,
        Raws::Wide(r) => r[i] as f64 * lsb,
    };
    value - map.apply(refs.at(i))
}

/// The largest of the lanes' maxima and the first element where it is reached, from each
/// lane's maximum and the first element where that lane reached it.
fn first_max(max: [f64; 4], first: [usize; 4]) -> (f64, Option<usize>) {
    let m = max[0].max(max[1]).max(max[2].max(max[3]));
    let at = (0..4).filter(|&l| max[l] == m).map(|l| first[l]).min();
    (m, at)
}

/// The portable kernel, element by element: the oracle of the AVX2 one (same bits).
pub(crate) fn portable(
    raws: Raws<'_>,
    lsb: f64,
    refs: References<'_>,
    map: Map,
    half: f64,
    one: f64,
    above: f64,
) -> ColumnFigures {
    let len = refs.len();
    let mut max = [f64::NEG_INFINITY; 4];
    let mut sum = [0.0f64; 4];
    let mut sum_abs = [0.0f64; 4];
    let mut sum_sq = [0.0f64; 4];
    let mut n_correct = 0u64;
    let mut n_faithful = 0u64;
    let mut first = [0usize; 4];
    let whole = len / 4 * 4;
    for i in 0..len {
        let lane = if i < whole { i % 4 } else { 0 };
        let e = error(raws, lsb, refs, map, i);
        let a = e.abs();
        // `f64::max`, since the running maximum is never NaN; the first element kept.
        if a > max[lane] {
            max[lane] = a;
            first[lane] = i;
        }
        sum[lane] += e;
        sum_abs[lane] += a;
        sum_sq[lane] += e * e;
        n_correct += u64::from(a <= half);
        n_faithful += u64::from(a < one);
    }
    let (max_abs, worst) = first_max(max, first);
    ColumnFigures {
        max_abs,
        worst: worst.filter(|_| max_abs > above),
        sum: join(sum),
        sum_abs: join(sum_abs),
        sum_sq: join(sum_sq),
        n_correct,
        n_faithful,
        raw_range: raw_range(raws, len),
    }
}

/// The lanes of a sum joined.
#[inline(always)]
fn join(a: [f64; 4]) -> f64 {
    (a[0] + a[1]) + (a[2] + a[3])
}

/// The smallest and largest raw value.
fn raw_range(raws: Raws<'_>, len: usize) -> (i64, i64) {
    match raws {
        Raws::Constant(r) if len > 0 => (r, r),
        Raws::Constant(_) => (i64::MAX, i64::MIN),
        Raws::Narrow(r) | Raws::Wide(r) => {
            let (mut lo, mut hi) = ([i64::MAX; 4], [i64::MIN; 4]);
            let quads = r.chunks_exact(4);
            let rest = quads.remainder();
            for q in quads {
                for l in 0..4 {
                    lo[l] = lo[l].min(q[l]);
                    hi[l] = hi[l].max(q[l]);
                }
            }
            for &x in rest {
                lo[0] = lo[0].min(x);
                hi[0] = hi[0].max(x);
            }
            (
                lo.into_iter().fold(i64::MAX, i64::min),
                hi.into_iter().fold(i64::MIN, i64::max),
            )
        }
    }
}

#[cfg(target_arch = "x86_64")]
mod avx2 {
    //! The AVX2 kernel: one 256-bit register per figure, its four lanes the four lanes of the
    //! portable loop.
    use super::{join, raw_range, ColumnFigures, Map, Raws, References, MAGIC};
    use std::arch::x86_64::*;

    /// The figures of a column, as [`super::portable`] computes them (`worst` whatever the
    /// caller's running maximum).
    ///
    /// # Safety
    /// The CPU has AVX2, and a column of raw values is as long as `refs`.
    #[target_feature(enable = "avx2")]
    pub(super) fn figures(
        raws: Raws<'_>,
        lsb: f64,
        refs: References<'_>,
        map: Map,
        half: f64,
        one: f64,
    ) -> ColumnFigures {
        let args = Args {
            raws,
            lsb,
            refs,
            map,
            half,
            one,
        };
        let l = _mm256_set1_pd(lsb);
        match raws {
            Raws::Constant(r) => {
                let v = _mm256_set1_pd(r as f64 * lsb);
                mapped(args, |_| v)
            }
            Raws::Narrow(r) => mapped(args, |q| narrow(r, q, l)),
            Raws::Wide(r) => mapped(args, |q| wide(r, q, l)),
        }
    }

    /// [`kernel`] with the map of the references as a closure, `value(q)` the four values of
    /// quad `q`.
    #[target_feature(enable = "avx2")]
    #[inline]
    fn mapped(args: Args<'_>, value: impl Fn(usize) -> __m256d) -> ColumnFigures {
        match args.map {
            Map::Identity => kernel(args, value, |x| x),
            Map::Scale(s) => {
                let s = _mm256_set1_pd(s);
                kernel(args, value, |x| _mm256_mul_pd(s, x))
            }
        }
    }

    /// [`super::monotone_sums`]: the codes counted in f64 (integers below 2^53, exact), no
    /// maximum, no counts.
    #[target_feature(enable = "avx2")]
    pub(super) fn monotone_sums(
        value: f64,
        map: Map,
        first: i64,
        len: usize,
        c_lsb: f64,
    ) -> (f64, f64, f64) {
        let scale = match map {
            Map::Identity => None,
            Map::Scale(s) => Some(_mm256_set1_pd(s)),
        };
        let (v, lsb4, one) = (
            _mm256_set1_pd(value),
            _mm256_set1_pd(c_lsb),
            _mm256_set1_pd(1.0),
        );
        let (sign, four) = (_mm256_set1_pd(-0.0), _mm256_set1_pd(4.0));
        let mut k = _mm256_add_pd(
            _mm256_set1_pd(first as f64),
            _mm256_set_pd(3.0, 2.0, 1.0, 0.0),
        );
        let (mut sum, mut sum_abs, mut sum_sq) = (
            _mm256_setzero_pd(),
            _mm256_setzero_pd(),
            _mm256_setzero_pd(),
        );
        let quads = len / 4;
        for _ in 0..quads {
            let d = _mm256_sub_pd(_mm256_mul_pd(k, lsb4), one);
            let r = match scale {
                Some(s) => _mm256_mul_pd(s, d),
                None => d,
            };
            let e = _mm256_sub_pd(v, r);
            sum = _mm256_add_pd(sum, e);
            sum_abs = _mm256_add_pd(sum_abs, _mm256_andnot_pd(sign, e));
            sum_sq = _mm256_add_pd(sum_sq, _mm256_mul_pd(e, e));
            k = _mm256_add_pd(k, four);
        }
        // SAFETY: the store writes the four values of `out`.
        let lanes = |x: __m256d| {
            let mut out = [0.0f64; 4];
            unsafe { _mm256_storeu_pd(out.as_mut_ptr(), x) };
            out
        };
        let (mut sum, mut sum_abs, mut sum_sq) = (lanes(sum), lanes(sum_abs), lanes(sum_sq));
        let refs = References::D { first, len, c_lsb };
        for i in 4 * quads..len {
            let e = value - map.apply(refs.at(i));
            sum[0] += e;
            sum_abs[0] += e.abs();
            sum_sq[0] += e * e;
        }
        (join(sum), join(sum_abs), join(sum_sq))
    }

    /// The values `raw * lsb` of quad `q` of a narrow column.
    #[target_feature(enable = "avx2")]
    #[inline]
    fn narrow(r: &[i64], q: usize, lsb: __m256d) -> __m256d {
        let quad: &[i64; 4] = r[4 * q..4 * q + 4].try_into().expect("a whole quad");
        // SAFETY: the load reads the four values of `quad` (unaligned).
        let x = unsafe { _mm256_loadu_si256(quad.as_ptr().cast()) };
        let bits = _mm256_add_epi64(x, _mm256_set1_epi64x(MAGIC.to_bits() as i64));
        let v = _mm256_sub_pd(_mm256_castsi256_pd(bits), _mm256_set1_pd(MAGIC));
        _mm256_mul_pd(v, lsb)
    }

    /// The values `raw * lsb` of quad `q` of a wide column (converted one by one).
    #[target_feature(enable = "avx2")]
    #[inline]
    fn wide(r: &[i64], q: usize, lsb: __m256d) -> __m256d {
        let quad = &r[4 * q..4 * q + 4];
        let v = _mm256_set_pd(
            quad[3] as f64,
            quad[2] as f64,
            quad[1] as f64,
            quad[0] as f64,
        );
        _mm256_mul_pd(v, lsb)
    }

    /// The loop: `value(q)` the four values of quad `q`, `scale` the map of four references.
    #[target_feature(enable = "avx2")]
    #[inline]
    fn kernel(
        args: Args<'_>,
        value: impl Fn(usize) -> __m256d,
        scale: impl Fn(__m256d) -> __m256d,
    ) -> ColumnFigures {
        match args.refs {
            References::Column(r) => kernel_with(args, value, |q| {
                let x: &[f64; 4] = r[4 * q..4 * q + 4].try_into().expect("a whole quad");
                // SAFETY: the load reads the four values of `x` (unaligned).
                scale(unsafe { _mm256_loadu_pd(x.as_ptr()) })
            }),
            References::D { first, c_lsb, .. } => {
                let (steps, lsb4) = (_mm256_set_pd(3.0, 2.0, 1.0, 0.0), _mm256_set1_pd(c_lsb));
                let one_v = _mm256_set1_pd(1.0);
                kernel_with(args, value, |q| {
                    // The four codes are integers below 2^53: exact in f64, as is each sum.
                    let k = _mm256_add_pd(_mm256_set1_pd((first + 4 * q as i64) as f64), steps);
                    scale(_mm256_sub_pd(_mm256_mul_pd(k, lsb4), one_v))
                })
            }
        }
    }

    /// The loop of [`kernel`], `reference(q)` the mapped references of quad `q`.
    #[target_feature(enable = "avx2")]
    #[inline]
    fn kernel_with(
        args: Args<'_>,
        value: impl Fn(usize) -> __m256d,
        reference: impl Fn(usize) -> __m256d,
    ) -> ColumnFigures {
        let Args {
            raws,
            lsb,
            refs,
            map,
            half,
            one,
        } = args;
        let len = refs.len();
        let quads = len / 4;
        let sign = _mm256_set1_pd(-0.0);
        let (half4, one4) = (_mm256_set1_pd(half), _mm256_set1_pd(one));
        let mut max = _mm256_set1_pd(f64::NEG_INFINITY);
        // The quad where each lane's maximum was first reached (an integer, exact in f64).
        let mut first = _mm256_setzero_pd();
        let (mut sum, mut sum_abs, mut sum_sq) = (
            _mm256_setzero_pd(),
            _mm256_setzero_pd(),
            _mm256_setzero_pd(),
        );
        let (mut n_correct, mut n_faithful) = (_mm256_setzero_si256(), _mm256_setzero_si256());
        for q in 0..quads {
            let e = _mm256_sub_pd(value(q), reference(q));
            let a = _mm256_andnot_pd(sign, e);
            // max(a, m): a where a > m, else m; m is never NaN, so a NaN error is skipped.
            let gt = _mm256_cmp_pd::<_CMP_GT_OQ>(a, max);
            first = _mm256_blendv_pd(first, _mm256_set1_pd(q as f64), gt);
            max = _mm256_max_pd(a, max);
            sum = _mm256_add_pd(sum, e);
            sum_abs = _mm256_add_pd(sum_abs, a);
            sum_sq = _mm256_add_pd(sum_sq, _mm256_mul_pd(e, e));
            // A true comparison is all ones, -1 as an integer.
            let le = _mm256_castpd_si256(_mm256_cmp_pd::<_CMP_LE_OQ>(a, half4));
            let lt = _mm256_castpd_si256(_mm256_cmp_pd::<_CMP_LT_OQ>(a, one4));
            n_correct = _mm256_sub_epi64(n_correct, le);
            n_faithful = _mm256_sub_epi64(n_faithful, lt);
        }
        // SAFETY (both): the stores write the four values of `out`.
        let lanes = |v: __m256d| {
            let mut out = [0.0f64; 4];
            unsafe { _mm256_storeu_pd(out.as_mut_ptr(), v) };
            out
        };
        let counts = |v: __m256i| {
            let mut out = [0i64; 4];
            unsafe { _mm256_storeu_si256(out.as_mut_ptr().cast(), v) };
            out.iter().map(|&c| c as u64).sum::<u64>()
        };
        let (mut max, mut sum, mut sum_abs, mut sum_sq) =
            (lanes(max), lanes(sum), lanes(sum_abs), lanes(sum_sq));
        let mut first: [usize; 4] = {
            let q = lanes(first);
            std::array::from_fn(|l| 4 * q[l] as usize + l)
        };
        let (mut n_correct, mut n_faithful) = (counts(n_correct), counts(n_faithful));
        for i in 4 * quads..len {
            let e = super::error(raws, lsb, refs, map, i);
            let a = e.abs();
            if a > max[0] {
                max[0] = a;
                first[0] = i;
            }
            sum[0] += e;
            sum_abs[0] += a;
            sum_sq[0] += e * e;
            n_correct += u64::from(a <= half);
            n_faithful += u64::from(a < one);
        }
        let (max_abs, worst) = super::first_max(max, first);
        ColumnFigures {
            max_abs,
            worst,
            sum: join(sum),
            sum_abs: join(sum_abs),
            sum_sq: join(sum_sq),
            n_correct,
            n_faithful,
            raw_range: raw_range(raws, len),
        }
    }

    /// What every step of the kernel is given: the column, its references and their map, and
    /// the bounds of the counts.
    #[derive(Clone, Copy)]
    struct Args<'a> {
        raws: Raws<'a>,
        lsb: f64,
        refs: References<'a>,
        map: Map,
        half: f64,
        one: f64,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// Sums in the order the module promises, written out plainly: the independent oracle of
    /// both kernels' sums.
    fn lane_sums(errs: &[f64]) -> (f64, f64, f64) {
        let mut s = [[0.0f64; 4]; 3];
        let whole = errs.len() / 4 * 4;
        for (i, &e) in errs.iter().enumerate() {
            let l = if i < whole { i % 4 } else { 0 };
            s[0][l] += e;
            s[1][l] += e.abs();
            s[2][l] += e * e;
        }
        let j = |a: [f64; 4]| (a[0] + a[1]) + (a[2] + a[3]);
        (j(s[0]), j(s[1]), j(s[2]))
    }

    fn check_column(raws: &[i64], refs: &[f64], lsb: f64, map: Map, width: u32) {
        let half = 0.5 * lsb;
        let one = lsb;
        let column = Raws::of(raws, width);
        let f = column_figures(column, lsb, References::Column(refs), map, half, one, -1.0);
        let p = portable(column, lsb, References::Column(refs), map, half, one, -1.0);
        assert_eq!(f, p, "the AVX2 kernel and the portable one differ");
        let errs: Vec<f64> = raws
            .iter()
            .zip(refs)
            .map(|(&r, &x)| {
                r as f64 * lsb
                    - match map {
                        Map::Identity => x,
                        Map::Scale(s) => s * x,
                    }
            })
            .collect();
        let (sum, sum_abs, sum_sq) = lane_sums(&errs);
        assert_eq!(f.sum.to_bits(), sum.to_bits());
        assert_eq!(f.sum_abs.to_bits(), sum_abs.to_bits());
        assert_eq!(f.sum_sq.to_bits(), sum_sq.to_bits());
        let max = errs
            .iter()
            .map(|e| e.abs())
            .fold(f64::NEG_INFINITY, f64::max);
        assert_eq!(f.max_abs.to_bits(), max.to_bits());
        assert_eq!(
            f.worst,
            errs.iter().position(|e| e.abs() == max),
            "the first maximum"
        );
        let correct = errs.iter().filter(|e| e.abs() <= half).count() as u64;
        let faithful = errs.iter().filter(|e| e.abs() < one).count() as u64;
        assert_eq!((f.n_correct, f.n_faithful), (correct, faithful));
        if !raws.is_empty() {
            let lo = *raws.iter().min().unwrap();
            let hi = *raws.iter().max().unwrap();
            assert_eq!(f.raw_range, (lo, hi));
        }
    }

    #[test]
    fn narrow_conversion_is_exact_to_the_edges() {
        let edge = (1i64 << 51) - 1;
        for x in [0, 1, -1, 12345, -98765, edge, -edge, edge - 7, -(edge - 7)] {
            assert_eq!(narrow_to_f64(x).to_bits(), (x as f64).to_bits(), "{x}");
        }
    }

    #[test]
    fn constant_column_matches_the_plain_sums() {
        let refs: Vec<f64> = (0..2049).map(|i| -1.0 + f64::from(i) / 2048.0).collect();
        let raws = vec![-131072i64; refs.len()];
        let f = column_figures(
            Raws::Constant(-131072),
            2f64.powi(-16),
            References::Column(&refs),
            Map::Scale(3.5),
            2f64.powi(-17),
            2f64.powi(-16),
            -1.0,
        );
        let g = column_figures(
            Raws::Narrow(&raws),
            2f64.powi(-16),
            References::Column(&refs),
            Map::Scale(3.5),
            2f64.powi(-17),
            2f64.powi(-16),
            -1.0,
        );
        assert_eq!(f, g);
        check_column(&raws, &refs, 2f64.powi(-16), Map::Scale(3.5), 18);
    }

    #[test]
    fn d_computed_from_codes_is_the_column_of_d() {
        // The overflowed prefix's shape (t saturated at -2 against 64 d), then errors that
        // cross zero (so that some are within half an LSB, at code 16384) by the identity and
        // by a factor, each in chunks that start and end anywhere; the computed column of d
        // and its monotone shortcut give the figures of the column read from memory by the
        // full kernels, which the plain order above checks.
        let c_lsb = 2f64.powi(-15);
        let cases = [
            (-131072, Map::Scale(64.0)),
            (-32768, Map::Identity),
            (-32768, Map::Scale(1.0)),
            (-16384, Map::Scale(0.5)),
            (-16384, Map::Scale(0.0)),
        ];
        for (raw, map) in cases {
            for (first, len) in [
                (0i64, 2048usize),
                (4093, 2047),
                (-5, 9),
                (32765, 3),
                (16000, 2048),
                (16383, 2),
                (16384, 1),
                (15360, 1024),
            ] {
                let refs: Vec<f64> = (first..first + len as i64)
                    .map(|k| k as f64 * c_lsb - 1.0)
                    .collect();
                let varying: Vec<i64> = (0..len as i64).map(|i| raw + i % 7).collect();
                for raws in [Raws::Constant(raw), Raws::Narrow(&varying)] {
                    let lsb = 2f64.powi(-16);
                    let run = |refs, above| {
                        column_figures(raws, lsb, refs, map, 2f64.powi(-17), lsb, above)
                    };
                    let computed = References::D { first, len, c_lsb };
                    let read = References::Column(&refs);
                    for above in [-1.0, 0.25, 10.0] {
                        let want = run(read, above);
                        assert_eq!(run(computed, above), want, "{raw} {map:?} {first} {len}");
                        assert_eq!(
                            portable(raws, lsb, computed, map, 2f64.powi(-17), lsb, above),
                            want
                        );
                    }
                    let value = raw as f64 * lsb;
                    assert_eq!(
                        monotone_sums(value, map, first, len, c_lsb),
                        monotone_sums_portable(value, map, first, len, c_lsb)
                    );
                }
            }
        }
    }

    proptest! {
        #[test]
        fn kernels_agree_with_the_plain_order(
            raws in proptest::collection::vec(-(1i64 << 50)..(1i64 << 50), 0..40),
            frac in 0i32..60,
            scale in proptest::option::of(-100.0f64..100.0),
            seed in any::<u64>(),
        ) {
            let lsb = 2f64.powi(-frac);
            let refs: Vec<f64> = raws
                .iter()
                .enumerate()
                .map(|(i, &r)| r as f64 * lsb + ((seed >> (i % 60)) & 7) as f64 * lsb * 0.3)
                .collect();
            let map = scale.map_or(Map::Identity, Map::Scale);
            check_column(&raws, &refs, lsb, map, 51);
            check_column(&raws, &refs, lsb, map, 64);
        }

        #[test]
        fn wide_values_convert_one_by_one(
            raws in proptest::collection::vec(any::<i64>(), 0..20),
        ) {
            let refs: Vec<f64> = raws.iter().map(|&r| r as f64 * 0.5 + 1.0).collect();
            check_column(&raws, &refs, 1.0, Map::Identity, 64);
        }
    }
}
