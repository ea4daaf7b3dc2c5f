//! Batch evaluation: a batch of input codes for one n, stage by stage over columns
//! ([`Datapath::eval_batch`]), and outputs only, the squaring chain tabulated by b's code
//! ([`Datapath::eval_outputs`]); the kernels each stage runs are chosen once ([`BatchPlan`]).

use crate::pipeline::config::Config;
use crate::pipeline::fast::{
    constant_bits, count_event, magnitude_bits, BatchPlan, EventCounts, Kernel, Pre,
};

use super::{Datapath, NConstants, Probes, STAGE_B, STAGE_D, STAGE_SQ0, STAGE_T};

/// The probes of a batch of evaluations, one column per stage (structure of arrays).
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct ProbeColumns {
    /// `values[stage_idx][i]`: raw value of stage `stage_idx` for input `i`.
    pub values: Vec<Vec<i64>>,
    /// `event_counts[stage_idx]`: how many quantizations of the batch wrapped, saturated and
    /// overflowed to zero, in that order.
    pub event_counts: Vec<EventCounts>,
    /// Scratch space for the exact sums of the b stage.
    scratch: Vec<i64>,
    /// `cut[i]`: the cutoff forced the base to zero.
    pub cut: Vec<bool>,
    /// `input_clamped[i]`: the input was above 1.0.
    pub input_clamped: Vec<bool>,
    /// The b..out columns (all but coef) hold zeros written by
    /// [`Datapath::eval_batch_cut`] and nothing has written them since.
    zero_tail: bool,
}

impl ProbeColumns {
    /// Gives every column `len` rows and clears the event counts. The rows keep whatever they
    /// held: every evaluation writes every row of the columns it promises.
    fn reset(&mut self, n_stages: usize, len: usize) {
        let same = self.values.len() == n_stages && self.cut.len() == len;
        if !same {
            self.zero_tail = false;
            self.values.resize_with(n_stages, Vec::new);
            for col in &mut self.values {
                col.resize(len, 0);
            }
            self.cut.resize(len, false);
            self.input_clamped.resize(len, false);
        }
        self.event_counts.clear();
        self.event_counts.resize(n_stages, [0; 3]);
    }

    /// The number of evaluations held.
    pub fn len(&self) -> usize {
        self.cut.len()
    }

    /// Whether no evaluation is held.
    pub fn is_empty(&self) -> bool {
        self.cut.is_empty()
    }

    /// The probes of evaluation `i`, as one [`Probes`] (without the events, which a batch only
    /// counts).
    pub fn row(&self, i: usize) -> Probes {
        let mut p = Probes::default();
        for (stage_idx, col) in self.values.iter().enumerate() {
            p.values[stage_idx] = col[i];
        }
        p.cut = self.cut[i];
        p.input_clamped = self.input_clamped[i];
        p
    }
}

impl Datapath {
    /// Chooses each stage's batch kernel from a bound on its exact input: the magnitude bits
    /// of the formats and constants feeding it (a product adds its factors' bits, a sum takes
    /// the larger aligned term's bits plus one).
    pub(super) fn batch_plan(config: &Config, constants: &[NConstants]) -> BatchPlan {
        // The slope's and offset's fraction bits are the same for every n.
        let (slope_frac, offset_frac) = constants
            .first()
            .map_or((0, 0), |c| (c.slope_frac, c.offset_frac));
        let slope_bits = constant_bits(constants.iter().map(|c| c.slope_raw));
        let offset_bits = constant_bits(constants.iter().map(|c| c.offset_raw));
        let coef_bits = constant_bits(constants.iter().map(|c| c.coef_raw));
        let ft = config.t.format.frac_bits();
        let fb = ft.max(offset_frac);
        let t_align = (fb - ft) as u32;
        let offset_align = (fb - offset_frac) as u32;
        let sum_bits = (magnitude_bits(config.t.format).saturating_add(t_align))
            .max(offset_bits.saturating_add(offset_align))
            .saturating_add(1);
        let mut squares = Vec::with_capacity(config.square.len());
        let mut passes = Vec::with_capacity(config.square.len());
        let mut prev = config.b.format;
        for spec in &config.square {
            squares.push(Kernel::for_stage(
                2 * prev.frac_bits(),
                2 * magnitude_bits(prev),
                spec,
            ));
            passes.push(Kernel::for_stage(
                prev.frac_bits(),
                magnitude_bits(prev),
                spec,
            ));
            prev = spec.format;
        }
        BatchPlan {
            t: Kernel::for_stage(
                config.d.format.frac_bits() + slope_frac,
                magnitude_bits(config.d.format) + slope_bits,
                &config.t,
            ),
            t_align,
            offset_align,
            b: Kernel::for_stage(fb, sum_bits, &config.b),
            squares,
            passes,
            out: Kernel::for_stage(
                prev.frac_bits() + config.coef.format.frac_bits(),
                magnitude_bits(prev) + coef_bits,
                &config.out,
            ),
        }
    }

    /// The batch plan: which stages run the `i64` kernels and which the exact fallback.
    pub fn batch_plan_of(&self) -> &BatchPlan {
        &self.plan
    }

    /// Evaluates a batch of raw input codes for one n into columns, stage by stage: the same
    /// results as [`Datapath::eval`] on each code, several times faster.
    ///
    /// # Examples
    /// ```
    /// use specfx::pipeline::{Config, Datapath, ProbeColumns};
    /// let dp = Datapath::new(Config::baseline()).unwrap();
    /// let nc = dp.constants_for(100).unwrap();
    /// let codes: Vec<i64> = (0..=40_000).collect();
    /// let mut cols = ProbeColumns::default();
    /// dp.eval_batch(nc, &codes, &mut cols);
    /// assert_eq!(cols.row(31_000), dp.eval(31_000, nc));
    /// ```
    pub fn eval_batch(&self, nc: &NConstants, codes: &[i64], cols: &mut ProbeColumns) {
        let n_stages = self.stages.len();
        cols.reset(n_stages, codes.len());
        cols.zero_tail = false;
        let plan = &self.plan;
        self.d_column(codes, &mut cols.values[STAGE_D], &mut cols.input_clamped);
        let stage = |cols: &mut ProbeColumns, kernel: &Kernel, pre: Pre, from: usize, to: usize| {
            let (head, tail) = cols.values.split_at_mut(to);
            kernel.run(pre, &head[from], &mut tail[0], &mut cols.event_counts[to]);
        };
        stage(cols, &plan.t, Pre::Mul(nc.slope_raw), STAGE_D, STAGE_T);
        // The exact sum and the cutoff, then the b stage.
        let (head, tail) = cols.values.split_at_mut(STAGE_B);
        self.b_column(
            nc,
            codes,
            &head[STAGE_T],
            &mut tail[0],
            &mut cols.cut,
            &mut cols.scratch,
            &mut cols.event_counts[STAGE_B],
        );
        for i in 0..plan.squares.len() {
            let (kernel, pre) = plan.square_stage(i, nc.depth);
            stage(cols, kernel, pre, STAGE_SQ0 + i - 1, STAGE_SQ0 + i);
        }
        let coef_idx = STAGE_SQ0 + plan.squares.len();
        cols.values[coef_idx].fill(nc.coef_raw);
        stage(
            cols,
            &plan.out,
            Pre::Mul(nc.coef_raw),
            coef_idx - 1,
            coef_idx + 1,
        );
    }

    /// The d stage over columns: each code clamped to 1.0, then `d = c - 1`, exact.
    fn d_column(&self, codes: &[i64], d: &mut [i64], clamped: &mut [bool]) {
        let one = self.one_raw;
        let d_shift = self.d_shift;
        for ((d, clamped), &code) in d.iter_mut().zip(clamped.iter_mut()).zip(codes) {
            *clamped = code > one;
            *d = (code.min(one) - one) << d_shift;
        }
    }

    /// The b stage over columns: the exact sum `t + offset`, the cutoff, then b's kernel (the
    /// `i64` loop when the sums are proven to fit, [`Datapath::op_add_b`] per element
    /// otherwise).
    #[allow(clippy::too_many_arguments)]
    fn b_column(
        &self,
        nc: &NConstants,
        codes: &[i64],
        t: &[i64],
        b: &mut [i64],
        cut: &mut [bool],
        sums: &mut Vec<i64>,
        counts: &mut EventCounts,
    ) {
        let one = self.one_raw;
        if !self.plan.b.is_fast() {
            for (i, &code) in codes.iter().enumerate() {
                let (q, was_cut) = self.op_add_b(t[i], code.min(one), nc);
                b[i] = q.raw;
                cut[i] = was_cut;
                count_event(counts, q.event);
            }
            return;
        }
        let offset = nc.offset_raw << self.plan.offset_align;
        let t_align = self.plan.t_align;
        let threshold = nc.threshold.unwrap_or(i64::MIN);
        let cutoff = self.config.cutoff;
        sums.clear();
        sums.extend(
            t.iter()
                .zip(codes)
                .zip(cut.iter_mut())
                .map(|((&t, &code), cut)| {
                    let sum = (t << t_align) + offset;
                    *cut = cutoff.cuts(sum < 0, code.min(one) < threshold);
                    if *cut {
                        0
                    } else {
                        sum
                    }
                }),
        );
        self.plan.b.run(Pre::Identity, sums, b, counts);
    }

    /// The last squaring's raw value as a function of b's raw value, tabulated once per
    /// datapath and depth when b has at most [`MAX_CHAIN_TABLE`] codes (the squaring chain
    /// depends on n only through its depth).
    fn chain_table(&self, depth: u32) -> Option<&ChainTable> {
        self.chain[depth as usize]
            .get_or_init(|| {
                let b = self.config.b.format;
                let (lo, hi) = (b.min_raw(), b.max_raw());
                let codes = u64::try_from(i128::from(hi) - i128::from(lo) + 1).ok()?;
                if codes > MAX_CHAIN_TABLE {
                    return None;
                }
                // Every b code through the squaring stages' batch kernels (the same values as
                // `op_stage`, the property tests say so), one column at a time.
                let mut last: Vec<i64> = (lo..=hi).collect();
                let mut next = vec![0; last.len()];
                let mut counts = [0; 3];
                for i in 0..self.plan.squares.len() {
                    let (kernel, pre) = self.plan.square_stage(i, depth);
                    kernel.run(pre, &last, &mut next, &mut counts);
                    std::mem::swap(&mut last, &mut next);
                }
                Some(ChainTable { b_min: lo, last })
            })
            .as_ref()
    }

    /// Evaluates the output code of each input code for one n: the same `out` as
    /// [`Datapath::eval`], without the other probes and the event counts, and faster (the
    /// squaring chain is looked up from b where it is tabulated).
    ///
    /// # Examples
    /// ```
    /// use specfx::pipeline::{Config, Datapath, OutputScratch};
    /// let dp = Datapath::new(Config::baseline()).unwrap();
    /// let nc = dp.constants_for(100).unwrap();
    /// let codes: Vec<i64> = (32_000..=32_768).collect();
    /// let mut out = vec![0; codes.len()];
    /// dp.eval_outputs(nc, &codes, &mut out, &mut OutputScratch::default());
    /// assert_eq!(out[700], dp.eval(32_700, nc).values[dp.stage_out()]);
    /// ```
    pub fn eval_outputs(
        &self,
        nc: &NConstants,
        codes: &[i64],
        out: &mut [i64],
        scratch: &mut OutputScratch,
    ) {
        self.outputs(nc, codes, out, scratch, true);
    }

    /// [`Datapath::eval_outputs`] with the squaring chain run stage by stage, never tabulated:
    /// for a datapath evaluated once over fewer live codes than b has codes (the output-only
    /// check of a datapath with few exponents or a wide b), where building the table would
    /// cost more than it saves. The lobes are left in the scratch ([`OutputScratch::lobes`]).
    pub fn eval_outputs_untabulated(
        &self,
        nc: &NConstants,
        codes: &[i64],
        out: &mut [i64],
        scratch: &mut OutputScratch,
    ) {
        self.outputs(nc, codes, out, scratch, false);
    }

    fn outputs(
        &self,
        nc: &NConstants,
        codes: &[i64],
        out: &mut [i64],
        scratch: &mut OutputScratch,
        tabulate: bool,
    ) {
        let len = codes.len();
        let s = scratch;
        for col in [&mut s.a, &mut s.b] {
            col.clear();
            col.resize(len, 0);
        }
        s.cut.clear();
        s.cut.resize(len, false);
        let one = self.one_raw;
        let d_shift = self.d_shift;
        for (d, &code) in s.a.iter_mut().zip(codes) {
            *d = (code.min(one) - one) << d_shift;
        }
        let mut counts = [0; 3];
        self.plan
            .t
            .run(Pre::Mul(nc.slope_raw), &s.a, &mut s.b, &mut counts);
        // t is in b; the base goes to a.
        self.b_column(
            nc,
            codes,
            &s.b,
            &mut s.a,
            &mut s.cut,
            &mut s.sums,
            &mut counts,
        );
        // Only where tabulating is asked for: building the table costs a pass over every b
        // code and squaring stage, which an untabulated evaluation exists to avoid.
        if let Some(table) = tabulate.then(|| self.chain_table(nc.depth)).flatten() {
            for (sq, &b) in s.b.iter_mut().zip(&s.a) {
                *sq = table.last[(b - table.b_min) as usize];
            }
        } else {
            for i in 0..self.plan.squares.len() {
                let (kernel, pre) = self.plan.square_stage(i, nc.depth);
                kernel.run(pre, &s.a, &mut s.b, &mut counts);
                std::mem::swap(&mut s.a, &mut s.b);
            }
            std::mem::swap(&mut s.a, &mut s.b);
        }
        self.plan
            .out
            .run(Pre::Mul(nc.coef_raw), &s.b, out, &mut counts);
    }

    /// [`Datapath::eval_batch`] for a batch of codes that are all cut (every code below
    /// [`Datapath::first_live_code`]): d and t are evaluated, and every later stage holds
    /// what a cut base gives, 0 (the quantization of 0 is 0 in every format and mode, with no
    /// overflow event). The caller guarantees the codes are cut.
    pub fn eval_batch_cut(&self, nc: &NConstants, codes: &[i64], cols: &mut ProbeColumns) {
        let n_stages = self.stages.len();
        cols.reset(n_stages, codes.len());
        self.d_column(codes, &mut cols.values[STAGE_D], &mut cols.input_clamped);
        let (head, tail) = cols.values.split_at_mut(STAGE_T);
        self.plan.t.run(
            Pre::Mul(nc.slope_raw),
            &head[STAGE_D],
            &mut tail[0],
            &mut cols.event_counts[STAGE_T],
        );
        cols.cut.fill(true);
        let coef_idx = self.stage_coef();
        cols.values[coef_idx].fill(nc.coef_raw);
        if !cols.zero_tail {
            for (stage_idx, col) in cols.values.iter_mut().enumerate().skip(STAGE_B) {
                if stage_idx != coef_idx {
                    col.fill(0);
                }
            }
            cols.zero_tail = true;
        }
    }

    /// [`Datapath::eval_outputs`] over a range of codes, `out[i]` for code `codes.start + i`:
    /// the cut prefix (see [`Datapath::first_live_code`]) is filled with its output, 0, the
    /// rest is evaluated. Returns the length of the cut prefix.
    pub fn eval_outputs_range(
        &self,
        nc: &NConstants,
        codes: std::ops::Range<i64>,
        out: &mut [i64],
        scratch: &mut OutputScratch,
    ) -> usize {
        let live = self.first_live_code(nc, codes.clone());
        self.eval_outputs_from(nc, codes, live, out, scratch)
    }

    /// [`Datapath::eval_outputs_range`] given `live`, [`Datapath::first_live_code`] of a range
    /// that holds `codes` (found once for many batches of it): the codes of `codes` below it
    /// are cut (their output is 0), the others are evaluated. Returns the length of the cut
    /// prefix.
    ///
    /// # Examples
    /// ```
    /// use specfx::pipeline::{Config, Datapath, OutputScratch};
    /// let dp = Datapath::new(Config::baseline()).unwrap();
    /// let nc = dp.constants_for(1024).unwrap();
    /// let live = dp.first_live_code(nc, 0..32769);
    /// let mut out = vec![0; 2048];
    /// let cut = dp.eval_outputs_from(nc, 30720..32768, live, &mut out, &mut OutputScratch::default());
    /// assert_eq!(cut, (live - 30720) as usize);
    /// assert_eq!(out[2047], dp.eval(32767, nc).values[dp.stage_out()]);
    /// ```
    pub fn eval_outputs_from(
        &self,
        nc: &NConstants,
        codes: std::ops::Range<i64>,
        live: i64,
        out: &mut [i64],
        scratch: &mut OutputScratch,
    ) -> usize {
        let live = live.clamp(codes.start, codes.end);
        let n_dead = (live - codes.start) as usize;
        // A cut base is 0, and 0 is every stage's exact value from b on (every rounding mode
        // keeps 0, and every format holds it): the cut output is 0, written at the memory's
        // pace (the check's dead prefix rests on the same fact).
        out[..n_dead].fill(0);
        let mut live_codes = std::mem::take(&mut scratch.codes);
        live_codes.clear();
        live_codes.extend(live..codes.end);
        self.eval_outputs(nc, &live_codes, &mut out[n_dead..], scratch);
        scratch.codes = live_codes;
        n_dead
    }
}

/// The most b codes for which the squaring chain is tabulated (8 MiB of `i64`).
pub const MAX_CHAIN_TABLE: u64 = 1 << 20;

/// The last squaring as a function of b's raw value: `last[b - b_min]`.
#[derive(Debug, Clone)]
pub(super) struct ChainTable {
    b_min: i64,
    last: Vec<i64>,
}

/// Reusable columns for [`Datapath::eval_outputs`].
#[derive(Debug, Clone, Default)]
pub struct OutputScratch {
    codes: Vec<i64>,
    a: Vec<i64>,
    b: Vec<i64>,
    sums: Vec<i64>,
    cut: Vec<bool>,
}

impl OutputScratch {
    /// The lobes (the last squaring's raw values) of the latest [`Datapath::eval_outputs`],
    /// one per code it evaluated.
    pub fn lobes(&self) -> &[i64] {
        &self.b
    }
}
