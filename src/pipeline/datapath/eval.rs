//! Plain evaluation: one pair through the walk of the stages, bit for bit ([`Datapath::eval`]),
//! and the operations every interpreter of the datapath shares (`op_sub` .. `op_mul_out`).

use crate::error::Error;
use crate::fixed::Quantized;
use crate::pipeline::fast::quantize_to;
use crate::pipeline::walk::{walk, Arithmetic};

use super::{Datapath, NConstants, Probes, STAGE_B, STAGE_D, STAGE_SQ0, STAGE_T};

impl Datapath {
    /// Evaluates the datapath on one raw input code for one n, bit for bit.
    ///
    /// # Examples
    /// ```
    /// use specfx::pipeline::{Config, Datapath};
    /// let dp = Datapath::new(Config::baseline()).unwrap();
    /// let nc = dp.constants_for(64).unwrap();
    /// // c = 1.0: the lobe is 1 and the output is the coefficient itself.
    /// let p = dp.eval(dp.one_code(), nc);
    /// assert_eq!(p.values[dp.stage_out()], nc.coef_raw);
    /// ```
    ///
    /// This is the plain transcription of the arithmetic (exact intermediates in `i128`,
    /// quantized by [`quantize`]); [`Datapath::eval_batch`] is its fast twin.
    pub fn eval(&self, c_raw: i64, nc: &NConstants) -> Probes {
        let mut p = Probes::default();
        let mut fixed = FixedWalk {
            dp: self,
            nc,
            c_raw,
            c: c_raw,
            probes: &mut p,
        };
        p.cut = walk(
            &mut fixed,
            self.config.cutoff,
            self.config.k as usize,
            nc.depth as usize,
        )
        .cut;
        p
    }

    /// The output code of one pair, the pair checked first: `c_raw` a code of the input
    /// format, `n` in the configuration's exponent set. What a testbench compares with
    /// `out_data`, and what the C and Python faces return for one pair.
    ///
    /// # Errors
    /// [`Error::Domain`] for a code outside the input format or an n outside the set.
    ///
    /// # Examples
    /// ```
    /// let dp = specfx::load_datapath("baseline", None).unwrap();
    /// // c = 0 at n = 16: (16/16)(0 - 1) + 1 = 0, so the output is 0.
    /// assert_eq!(dp.eval_out(0, 16).unwrap(), 0);
    /// // c = 1.0: the lobe is 1 and the output is the coefficient itself.
    /// assert_eq!(dp.eval_out(dp.one_code(), 64).unwrap(), dp.constants_for(64).unwrap().coef_raw);
    /// assert!(dp.eval_out(0, 7).is_err());
    /// ```
    pub fn eval_out(&self, c_raw: i64, n: u32) -> Result<i64, Error> {
        let nc = self.constants_checked(n, "n")?;
        self.check_code(c_raw, "c")?;
        Ok(self.eval(c_raw, nc).values[self.stage_out()])
    }

    /// The exact sum `t + offset` on the larger of their fraction bits (`b_frac`).
    #[inline]
    pub(super) fn exact_sum(&self, t: i64, nc: &NConstants) -> i128 {
        let ft = self.config.t.format.frac_bits();
        let fb = self.b_frac(nc);
        (i128::from(t) << (fb - ft) as u32)
            + (i128::from(nc.offset_raw) << (fb - nc.offset_frac) as u32)
    }

    /// Fraction bits of the exact sum `t + offset`.
    #[inline]
    pub(super) fn b_frac(&self, nc: &NConstants) -> i32 {
        self.config.t.format.frac_bits().max(nc.offset_frac)
    }

    /// Operation `sub`: clamps the input code to 1.0 and returns it with d = c - 1, exact in
    /// d's format.
    #[inline]
    pub fn op_sub(&self, c_raw: i64) -> (i64, i64) {
        let c = c_raw.min(self.one_raw);
        (c, (c - self.one_raw) << self.d_shift)
    }

    /// Operation `mul_t`: t = d * slope, exact (`d.frac + slope_frac` fraction bits), then
    /// quantized by t's stage.
    #[inline]
    pub fn op_mul_t(&self, d: i64, nc: &NConstants) -> Quantized {
        quantize_to(
            i128::from(d) * i128::from(nc.slope_raw),
            self.config.d.format.frac_bits() + nc.slope_frac,
            &self.config.t,
        )
    }

    /// Operation `add_b`: b = t + offset, exact on the larger fraction, then the cutoff (which
    /// needs the clamped input code `c`), then b's stage. Returns b and whether it was cut.
    #[inline]
    pub fn op_add_b(&self, t: i64, c: i64, nc: &NConstants) -> (Quantized, bool) {
        let sum = self.exact_sum(t, nc);
        let cut = self.config.cutoff.cuts(sum < 0, nc.below_threshold(c));
        let base = if cut { 0 } else { sum };
        (quantize_to(base, self.b_frac(nc), &self.config.b), cut)
    }

    /// Operation `square` number `i` (0-based): the exact square of the previous stage's raw
    /// value (doubled fraction bits), quantized by squaring stage `i`.
    #[inline]
    pub fn op_square(&self, i: usize, x: i64) -> Quantized {
        let cfg = &self.config;
        let f_in = if i == 0 {
            cfg.b.format.frac_bits()
        } else {
            cfg.square[i - 1].format.frac_bits()
        };
        quantize_to(i128::from(x) * i128::from(x), 2 * f_in, &cfg.square[i])
    }

    /// Operation `pass` number `i` (0-based): squaring stage `i` bypassed, the previous stage's
    /// raw value quantized by stage `i` (what the stage gives at an n whose depth is at most
    /// `i`).
    #[inline]
    pub fn op_pass(&self, i: usize, x: i64) -> Quantized {
        let cfg = &self.config;
        let f_in = if i == 0 {
            cfg.b.format.frac_bits()
        } else {
            cfg.square[i - 1].format.frac_bits()
        };
        quantize_to(i128::from(x), f_in, &cfg.square[i])
    }

    /// Squaring stage `i` at an n of depth `depth`: [`Datapath::op_square`] below the depth,
    /// [`Datapath::op_pass`] from it on.
    #[inline]
    pub fn op_stage(&self, i: usize, depth: u32, x: i64) -> Quantized {
        if i < depth as usize {
            self.op_square(i, x)
        } else {
            self.op_pass(i, x)
        }
    }

    /// Operation `mul_out`: out = sq_k * coef, exact, then quantized by the output stage.
    #[inline]
    pub fn op_mul_out(&self, s: i64, nc: &NConstants) -> Quantized {
        let cfg = &self.config;
        let fs = cfg.square[cfg.square.len() - 1].format.frac_bits();
        quantize_to(
            i128::from(s) * i128::from(nc.coef_raw),
            fs + cfg.coef.format.frac_bits(),
            &cfg.out,
        )
    }
}

/// The bit-accurate interpreter of the walk: raw values (exact sums in `i128`), every stage's
/// probe and overflow event recorded as the walk goes.
struct FixedWalk<'a> {
    dp: &'a Datapath,
    nc: &'a NConstants,
    c_raw: i64,
    /// The input clamped to 1.0 (set by `sub`).
    c: i64,
    probes: &'a mut Probes,
}

impl FixedWalk<'_> {
    #[inline]
    fn record(&mut self, stage_idx: usize, q: Quantized) -> i128 {
        self.probes.values[stage_idx] = q.raw;
        self.probes.events[stage_idx] = q.event;
        i128::from(q.raw)
    }
}

impl Arithmetic for FixedWalk<'_> {
    type Value = i128;

    #[inline]
    fn sub(&mut self) -> i128 {
        let (c, d) = self.dp.op_sub(self.c_raw);
        self.c = c;
        self.probes.input_clamped = c != self.c_raw;
        self.probes.values[STAGE_D] = d;
        i128::from(d)
    }

    #[inline]
    fn below_threshold(&self) -> bool {
        self.nc.below_threshold(self.c)
    }

    #[inline]
    fn mul_t(&mut self, d: i128) -> i128 {
        let q = self.dp.op_mul_t(d as i64, self.nc);
        self.record(STAGE_T, q)
    }

    #[inline]
    fn add_offset(&mut self, t: i128) -> i128 {
        self.dp.exact_sum(t as i64, self.nc)
    }

    #[inline]
    fn is_negative(&self, sum: i128) -> bool {
        sum < 0
    }

    #[inline]
    fn zero(&self) -> i128 {
        0
    }

    #[inline]
    fn quant_b(&mut self, base: i128) -> i128 {
        let q = quantize_to(base, self.dp.b_frac(self.nc), &self.dp.config.b);
        self.record(STAGE_B, q)
    }

    #[inline]
    fn square(&mut self, i: usize, x: i128) -> i128 {
        let q = self.dp.op_square(i, x as i64);
        self.record(STAGE_SQ0 + i, q)
    }

    #[inline]
    fn pass(&mut self, i: usize, x: i128) -> i128 {
        let q = self.dp.op_pass(i, x as i64);
        self.record(STAGE_SQ0 + i, q)
    }

    #[inline]
    fn mul_out(&mut self, s: i128) -> i128 {
        self.probes.values[self.dp.stage_coef()] = self.nc.coef_raw;
        let q = self.dp.op_mul_out(s as i64, self.nc);
        self.record(self.dp.stage_out(), q)
    }
}
