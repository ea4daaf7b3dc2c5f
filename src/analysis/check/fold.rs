//! The fold of one exponent's exhaustive check over the stream's chunks ([`NFold`]): each
//! stage's running figures, the shape and normalisation maxima, the cuts and monotonicity.

use super::codes::{
    cos_n_of, dead_prefix_end, overflowed_chunks, reference_base, CodeColumns, CHUNK,
};
use super::report::{MonotonicityViolation, MAX_LISTED_VIOLATIONS};
use super::screen;
use crate::analysis::accumulate::MaxAt;
use crate::analysis::column::{column_figures, Map, Raws, References};
use crate::engine::{each_chunk_in, Chunk, Span};
use crate::pipeline::datapath::{STAGE_B, STAGE_D, STAGE_SQ0, STAGE_T};
use crate::pipeline::fast::EventCounts;
use crate::pipeline::{Datapath, NConstants};
use crate::reference::lobe::Cutoff;
use crate::reference::normalisation::classic_coefficient;

#[derive(Debug, Clone, Copy)]
/// One stage's running figures.
pub(super) struct Acc {
    pub(super) max_abs: f64,
    pub(super) worst: (u32, i64),
    pub(super) sum: f64,
    pub(super) sum_abs: f64,
    pub(super) sum_sq: f64,
    pub(super) n_correct: u64,
    pub(super) n_faithful: u64,
    pub(super) raw_min: i64,
    pub(super) raw_max: i64,
    pub(super) wrapped: u64,
    pub(super) saturated: u64,
    pub(super) zeroed: u64,
}

impl Acc {
    pub(super) fn new() -> Acc {
        Acc {
            max_abs: -1.0,
            worst: (0, 0),
            sum: 0.0,
            sum_abs: 0.0,
            sum_sq: 0.0,
            n_correct: 0,
            n_faithful: 0,
            raw_min: i64::MAX,
            raw_max: i64::MIN,
            wrapped: 0,
            saturated: 0,
            zeroed: 0,
        }
    }

    /// Adds a column of one stage's raw values against their f64 references `map(refs)` (see
    /// [`column_figures`] for the order of the sums, which is part of the figures' bits).
    fn add_column(
        &mut self,
        raws: Raws<'_>,
        lsb: f64,
        refs: References<'_>,
        map: Map,
        codes: &[i64],
        n: u32,
    ) {
        // A hair of slack for the f64 reference's own rounding.
        let half = 0.5 * lsb * (1.0 + 1e-9);
        let one = lsb * (1.0 - 1e-12);
        let f = column_figures(raws, lsb, refs, map, half, one, self.max_abs);
        if let Some(i) = f.worst {
            self.max_abs = f.max_abs;
            self.worst = (n, codes[i]);
        }
        self.sum += f.sum;
        self.sum_abs += f.sum_abs;
        self.sum_sq += f.sum_sq;
        self.n_correct += f.n_correct;
        self.n_faithful += f.n_faithful;
        self.raw_min = self.raw_min.min(f.raw_range.0);
        self.raw_max = self.raw_max.max(f.raw_range.1);
    }

    /// Adds a column whose every error is exactly +0.0, non-decreasing from `raw_first` to
    /// `raw_last`: the same state as [`Acc::add_column`] would reach on it.
    fn add_exact_column(&mut self, raw_first: i64, raw_last: i64, count: u64, at: (u32, i64)) {
        if 0.0 > self.max_abs {
            self.max_abs = 0.0;
            self.worst = at;
        }
        self.n_correct += count;
        self.n_faithful += count;
        self.raw_min = self.raw_min.min(raw_first);
        self.raw_max = self.raw_max.max(raw_last);
    }

    /// Adds `count` evaluations of a constant (the coefficient) against its f64 value.
    fn add_constant(&mut self, raw: i64, lsb: f64, reference: f64, count: u64, at: (u32, i64)) {
        let err = raw as f64 * lsb - reference;
        let abs = err.abs();
        if abs > self.max_abs {
            self.max_abs = abs;
            self.worst = at;
        }
        let w = count as f64;
        self.sum += w * err;
        self.sum_abs += w * abs;
        self.sum_sq += w * err * err;
        self.n_correct += count * u64::from(abs <= 0.5 * lsb * (1.0 + 1e-9));
        self.n_faithful += count * u64::from(abs < lsb * (1.0 - 1e-12));
        self.raw_min = self.raw_min.min(raw);
        self.raw_max = self.raw_max.max(raw);
    }

    /// Adds `count` evaluations whose value and reference are both exactly 0.
    fn add_exact_zeros(&mut self, count: u64) {
        if count > 0 {
            if self.max_abs < 0.0 {
                self.max_abs = 0.0;
            }
            self.n_correct += count;
            self.n_faithful += count;
            self.raw_min = self.raw_min.min(0);
            self.raw_max = self.raw_max.max(0);
        }
    }

    fn add_events(&mut self, counts: &EventCounts) {
        self.wrapped += counts[0];
        self.saturated += counts[1];
        self.zeroed += counts[2];
    }

    pub(super) fn merge(&mut self, o: &Acc) {
        if o.max_abs > self.max_abs {
            self.max_abs = o.max_abs;
            self.worst = o.worst;
        }
        self.sum += o.sum;
        self.sum_abs += o.sum_abs;
        self.sum_sq += o.sum_sq;
        self.n_correct += o.n_correct;
        self.n_faithful += o.n_faithful;
        self.raw_min = self.raw_min.min(o.raw_min);
        self.raw_max = self.raw_max.max(o.raw_max);
        self.wrapped += o.wrapped;
        self.saturated += o.saturated;
        self.zeroed += o.zeroed;
    }
}

/// Everything gathered for one n.
pub(super) struct PerN {
    pub(super) stages: Vec<Acc>,
    pub(super) quant: MaxAt,
    pub(super) approx: MaxAt,
    pub(super) total: MaxAt,
    pub(super) norm: MaxAt,
    pub(super) norm_rel: f64,
    pub(super) norm_approx_rel: f64,
    pub(super) n_violations: u64,
    pub(super) violations: Vec<MonotonicityViolation>,
    pub(super) n_cut: u64,
}

/// One exponent's exhaustive check as a fold over the stream's chunks: the phases of a chunk
/// are methods, in the order [`check_one_n`] calls them.
struct NFold<'a, 's> {
    dp: &'a Datapath,
    nc: &'a NConstants,
    lsb: Vec<f64>,
    /// Each stage's format width in bits.
    width: Vec<u32>,
    c_lsb: f64,
    one: i64,
    last_sq: usize,
    coef_idx: usize,
    out: usize,
    nf: f64,
    threshold: i64,
    norm_peak: f64,
    /// d = c - 1 is exact in its format; when c has at most 52 bits and d at most 53, its f64
    /// reference and its fixed-point value are the same f64 for every code, so every error is
    /// +0.0 and d's figures follow without computing them (the same bits as computing them).
    d_is_exact: bool,
    acc: Vec<Acc>,
    quant: MaxAt,
    approx: MaxAt,
    total: MaxAt,
    norm: MaxAt,
    norm_approx: f64,
    violations: Vec<MonotonicityViolation>,
    n_violations: u64,
    n_cut: u64,
    prev_out: Option<i64>,
    /// The largest code whose fixed and f64 lobes are both 0: cos^n is increasing in c, so
    /// its error there is the largest of all such codes and needs one evaluation at the end.
    zero_lobe_code: Option<(i64, f64)>,
    /// The columns it fills chunk by chunk, a worker's own from one exponent to the next.
    cols: &'s mut FoldColumns,
}

impl<'a, 's> NFold<'a, 's> {
    /// A fold that fills `cols` (whatever they held).
    fn new(dp: &'a Datapath, nc: &'a NConstants, cols: &'s mut FoldColumns) -> NFold<'a, 's> {
        let cfg = dp.config();
        let n_stages = dp.stages().len();
        NFold {
            dp,
            nc,
            lsb: dp.stages().iter().map(|s| s.format.lsb()).collect(),
            width: dp.stages().iter().map(|s| s.format.width()).collect(),
            c_lsb: cfg.c.format.lsb(),
            one: dp.one_code(),
            last_sq: dp.stage_last_square(),
            coef_idx: dp.stage_coef(),
            out: dp.stage_out(),
            nf: f64::from(nc.n),
            threshold: nc.threshold.unwrap_or(i64::MIN),
            norm_peak: classic_coefficient(cfg.coef.form, f64::from(nc.n)),
            d_is_exact: cfg.c.format.width() <= 52 && cfg.d.format.width() <= 53,
            acc: vec![Acc::new(); n_stages],
            quant: MaxAt::new(),
            approx: MaxAt::new(),
            total: MaxAt::new(),
            norm: MaxAt::new(),
            norm_approx: -1.0,
            violations: Vec::new(),
            n_violations: 0,
            n_cut: 0,
            prev_out: None,
            zero_lobe_code: None,
            cols,
        }
    }

    /// Folds one chunk of the stream.
    #[inline]
    fn chunk(&mut self, c: &Chunk<'_>, ref_d: &[f64]) {
        for (a, counts) in self.acc.iter_mut().zip(&c.probes.event_counts) {
            a.add_events(counts);
        }
        self.reference_b(c, ref_d);
        self.fold_d_t_coef(c, ref_d);
        self.find_live(c);
        self.fold_live_stages(c);
        self.fold_cuts_and_monotonicity(c);
    }

    /// The f64 value of b by the same algorithm (see `reference_probes`), only above the dead
    /// prefix (below it every base is cut, and 0 in the f64 model too); d's is shared by every
    /// n and t's is `slope * d`, computed where it is used.
    fn reference_b(&mut self, c: &Chunk<'_>, ref_d: &[f64]) {
        let (nc, cutoff, one, threshold) =
            (self.nc, self.dp.config().cutoff, self.one, self.threshold);
        self.cols.ref_b.clear();
        if c.dead {
            return;
        }
        // `reference_base` with the cutoff decided once for the chunk (the same values).
        let (slope, offset) = (nc.slope, nc.offset);
        match cutoff {
            Cutoff::Clamp => self.cols.ref_b.extend(ref_d.iter().map(|&d| {
                let sum = slope * d + offset;
                if sum < 0.0 {
                    0.0
                } else {
                    sum
                }
            })),
            Cutoff::None => self
                .cols
                .ref_b
                .extend(ref_d.iter().map(|&d| slope * d + offset)),
            Cutoff::Paper => {
                self.cols
                    .ref_b
                    .extend(ref_d.iter().zip(c.codes).map(|(&d, &k)| {
                        reference_base(cutoff, slope * d, offset, k.min(one) < threshold)
                    }))
            }
        }
    }

    /// d's, t's and the coefficient's figures, over every input of the chunk.
    fn fold_d_t_coef(&mut self, c: &Chunk<'_>, ref_d: &[f64]) {
        let (chunk, cols, n) = (c.codes, c.probes, self.nc.n);
        if self.d_is_exact {
            let d = &cols.values[STAGE_D];
            self.acc[STAGE_D].add_exact_column(
                d[0],
                d[d.len() - 1],
                chunk.len() as u64,
                (n, chunk[0]),
            );
        } else {
            self.acc[STAGE_D].add_column(
                Raws::of(&cols.values[STAGE_D], self.width[STAGE_D]),
                self.lsb[STAGE_D],
                References::Column(ref_d),
                Map::Identity,
                chunk,
                n,
            );
        }
        let slope = self.nc.slope;
        self.acc[STAGE_T].add_column(
            Raws::of(&cols.values[STAGE_T], self.width[STAGE_T]),
            self.lsb[STAGE_T],
            References::Column(ref_d),
            Map::Scale(slope),
            chunk,
            n,
        );
        self.acc[self.coef_idx].add_constant(
            self.nc.coef_raw,
            self.lsb[self.coef_idx],
            self.nc.coef,
            chunk.len() as u64,
            (n, chunk[0]),
        );
    }

    /// From b on, an input whose base is 0 in both models stays exactly 0 in both: such
    /// inputs count as exact without being looked at again. Compacts the others ("live")
    /// and remembers the largest dead code.
    fn find_live(&mut self, c: &Chunk<'_>) {
        let (chunk, b) = (c.codes, &c.probes.values[STAGE_B]);
        let ref_b = &self.cols.ref_b;
        let is_live = |i: usize| b[i] != 0 || ref_b[i] != 0.0;
        self.cols.live.clear();
        // The usual live chunk: a run of dead inputs, then only live ones.
        let first_live = if c.dead {
            chunk.len()
        } else {
            (0..chunk.len())
                .find(|&i| is_live(i))
                .unwrap_or(chunk.len())
        };
        let suffix = !c.dead && (first_live..chunk.len()).all(is_live);
        if suffix {
            self.cols.live.extend(first_live..chunk.len());
        } else if !c.dead {
            self.cols
                .live
                .extend((0..chunk.len()).filter(|&i| is_live(i)));
        }
        if self.cols.live.len() < chunk.len() {
            let largest_dead = if c.dead {
                chunk.len() - 1
            } else if suffix {
                first_live - 1
            } else {
                (0..chunk.len())
                    .rev()
                    .find(|&i| b[i] == 0 && ref_b[i] == 0.0)
                    .expect("a dead input exists")
            };
            if self
                .zero_lobe_code
                .is_none_or(|(k, _)| chunk[largest_dead] > k)
            {
                self.zero_lobe_code = Some((chunk[largest_dead], c.ln_c[largest_dead]));
            }
        }
        self.cols.live_codes.clear();
        self.cols.live_refs.clear();
        if suffix {
            self.cols.live_codes.extend_from_slice(&chunk[first_live..]);
            self.cols.live_refs.extend_from_slice(&ref_b[first_live..]);
        } else {
            self.cols
                .live_codes
                .extend(self.cols.live.iter().map(|&i| chunk[i]));
            self.cols
                .live_refs
                .extend(self.cols.live.iter().map(|&i| ref_b[i]));
        }
    }

    /// b, the squarings and the output on the live inputs (the dead ones are exact zeros);
    /// the lobe against cos^n after the last squaring, the normalised output against the
    /// exact normalised cos^n at the output. Where the live inputs are one run of the chunk
    /// (above a cut prefix), the stages' columns are read in place instead of gathered.
    fn fold_live_stages(&mut self, c: &Chunk<'_>) {
        let (chunk, cols, n) = (c.codes, c.probes, self.nc.n);
        let n_dead = (chunk.len() - self.cols.live.len()) as u64;
        let run = match (self.cols.live.first(), self.cols.live.last()) {
            (Some(&a), Some(&b)) if b - a + 1 == self.cols.live.len() => Some(a..b + 1),
            _ => None,
        };
        let mut gathered = std::mem::take(&mut self.cols.live_raws);
        for stage_idx in (STAGE_B..=self.last_sq).chain([self.out]) {
            if stage_idx == self.out {
                // live_refs holds the last squaring's references here.
                for r in &mut self.cols.live_refs {
                    *r *= self.nc.coef;
                }
            } else if stage_idx > STAGE_B && stage_idx - STAGE_SQ0 < self.nc.depth as usize {
                // A squaring stage (a bypassed one passes its reference on as it is).
                for r in &mut self.cols.live_refs {
                    *r *= *r;
                }
            }
            let raws: &[i64] = match &run {
                Some(r) => &cols.values[stage_idx][r.clone()],
                None => {
                    gathered.clear();
                    gathered.extend(self.cols.live.iter().map(|&i| cols.values[stage_idx][i]));
                    &gathered
                }
            };
            self.acc[stage_idx].add_column(
                Raws::of(raws, self.width[stage_idx]),
                self.lsb[stage_idx],
                References::Column(&self.cols.live_refs),
                Map::Identity,
                &self.cols.live_codes,
                n,
            );
            self.acc[stage_idx].add_exact_zeros(n_dead);
            if stage_idx == self.last_sq {
                self.fold_lobe(c, raws);
            }
            if stage_idx == self.out {
                self.fold_normalised(c, raws);
            }
        }
        self.cols.live_raws = gathered;
    }

    /// The normalised output against the exact normalised cos^n, on the live inputs (`raws`
    /// the output's values, `live_refs` the f64 lobe times the f64 coefficient, `live_cos`
    /// [`screen::exp_near_all`] of their cos^n): screened, exact where it may matter.
    fn fold_normalised(&mut self, c: &Chunk<'_>, raws: &[i64]) {
        let lsb_out = self.lsb[self.out];
        let cols = &mut *self.cols;
        cols.live_vals.clear();
        cols.live_vals
            .extend(raws.iter().map(|&r| r as f64 * lsb_out));
        let (peak, n, nf, c_lsb) = (self.norm_peak, self.nc.n, self.nf, self.c_lsb);
        let (norm, norm_approx) = (&mut self.norm, &mut self.norm_approx);
        screen::screen_two(
            &cols.live_vals,
            &cols.live_refs,
            peak,
            &cols.live_cos,
            (norm.value, *norm_approx),
            &mut cols.screen,
            |j, for_norm, for_approx| {
                let i = cols.live[j];
                let cos_n = cos_n_of(c.codes[i], c_lsb, nf, c.ln_c[i]);
                if for_norm {
                    norm.add((cols.live_vals[j] - peak * cos_n).abs(), (n, c.codes[i]));
                }
                if for_approx {
                    *norm_approx = norm_approx.max((cols.live_refs[j] - peak * cos_n).abs());
                }
            },
        );
    }

    /// The lobe against cos^n on the live inputs (`raws` the last squaring's values,
    /// `live_refs` their f64 references): its quantization, approximation and total error, the
    /// last two screened ([`screen`]) and exact where they may reach the maximum. Leaves the
    /// live inputs' [`screen::exp_near_all`] of cos^n in `live_cos`.
    fn fold_lobe(&mut self, c: &Chunk<'_>, raws: &[i64]) {
        let lsb_sq = self.lsb[self.last_sq];
        let (n, nf, c_lsb) = (self.nc.n, self.nf, self.c_lsb);
        let cols = &mut *self.cols;
        cols.live_vals.clear();
        cols.live_vals
            .extend(raws.iter().map(|&r| r as f64 * lsb_sq));
        for (j, &i) in cols.live.iter().enumerate() {
            self.quant.add(
                (cols.live_vals[j] - cols.live_refs[j]).abs(),
                (n, c.codes[i]),
            );
        }
        // exp(n ln c) where c > 0; at and below 0, cos^n is 0 (exp_near of -inf is e^-700).
        cols.live_cos.clear();
        cols.live_cos.extend(cols.live.iter().map(|&i| {
            if c.codes[i] as f64 * c_lsb <= 0.0 {
                f64::NEG_INFINITY
            } else {
                nf * c.ln_c[i]
            }
        }));
        screen::exp_near_all(&mut cols.live_cos);
        let (approx, total) = (&mut self.approx, &mut self.total);
        screen::screen_two(
            &cols.live_refs,
            &cols.live_vals,
            1.0,
            &cols.live_cos,
            (approx.value, total.value),
            &mut cols.screen,
            |j, for_approx, for_total| {
                let i = cols.live[j];
                let cos_n = cos_n_of(c.codes[i], c_lsb, nf, c.ln_c[i]);
                let at = (n, c.codes[i]);
                if for_approx {
                    approx.add((cols.live_refs[j] - cos_n).abs(), at);
                }
                if for_total {
                    total.add((cols.live_vals[j] - cos_n).abs(), at);
                }
            },
        );
    }

    /// Counts the cut inputs and the outputs below the one before them. A dead chunk is all
    /// cut with all outputs 0: only its first output can fall below the one before it.
    fn fold_cuts_and_monotonicity(&mut self, c: &Chunk<'_>) {
        let (n_chunk_cut, checked) = if c.dead {
            (c.codes.len() as u64, 1)
        } else {
            (
                c.probes.cut.iter().filter(|&&cut| cut).count() as u64,
                c.codes.len(),
            )
        };
        self.n_cut += n_chunk_cut;
        let outs = &c.probes.values[self.out][..checked];
        // Most chunks have no violation: one pass that counts them, in the chunk and against
        // the output before it, and the per-output walk only where there is one.
        let inside = outs.windows(2).filter(|w| w[1] < w[0]).count();
        let at_start = self.prev_out.is_some_and(|p| outs[0] < p);
        if inside == 0 && !at_start {
            self.prev_out = Some(outs[checked - 1]);
            return;
        }
        for (&o, &code) in outs.iter().zip(c.codes) {
            if let Some(prev) = self.prev_out {
                if o < prev {
                    self.n_violations += 1;
                    if self.violations.len() < MAX_LISTED_VIOLATIONS {
                        self.violations.push(MonotonicityViolation {
                            n: self.nc.n,
                            c_raw: code,
                            out_before: prev,
                            out_here: o,
                        });
                    }
                }
            }
            self.prev_out = Some(o);
        }
    }

    /// Folds the whole chunks, from the first, that are dead (below `dead_end`) and whose t
    /// overflows below its range at every code ([`overflowed_chunks`]), without evaluating
    /// them; returns the index of the first code left to the stream.
    ///
    /// Such a chunk's figures follow from its codes: d is exact (`d_is_exact`), t is one raw
    /// value with one event at every code, the coefficient is a constant, and from b on every
    /// value is 0 in both models.
    fn overflowed_prefix(&mut self, shared: &CodeColumns, dead_end: i64) -> usize {
        let (dp, nc) = (self.dp, self.nc);
        if !self.d_is_exact {
            return 0;
        }
        let codes = &shared.codes.codes;
        let mut next = 0;
        for (start, end, t, kind) in overflowed_chunks(dp, nc, codes, dead_end) {
            next = end;
            let last = codes[end - 1];
            let chunk = &codes[start..end];
            let (n, len) = (nc.n, chunk.len() as u64);
            let mut counts = [0u64; 3];
            counts[kind] = len;
            self.acc[STAGE_T].add_events(&counts);
            self.acc[STAGE_D].add_exact_column(
                dp.op_sub(chunk[0]).1,
                dp.op_sub(last).1,
                len,
                (n, chunk[0]),
            );
            self.acc[STAGE_T].add_column(
                Raws::Constant(t.raw),
                self.lsb[STAGE_T],
                References::D {
                    first: chunk[0],
                    len: chunk.len(),
                    c_lsb: self.c_lsb,
                },
                Map::Scale(nc.slope),
                chunk,
                n,
            );
            self.acc[self.coef_idx].add_constant(
                nc.coef_raw,
                self.lsb[self.coef_idx],
                nc.coef,
                len,
                (n, chunk[0]),
            );
            // From b on every value is 0 in both models; the largest such code is the
            // chunk's last.
            for stage_idx in (STAGE_B..=self.last_sq).chain([self.out]) {
                self.acc[stage_idx].add_exact_zeros(len);
            }
            if self.zero_lobe_code.is_none_or(|(k, _)| last > k) {
                self.zero_lobe_code = Some((last, shared.codes.ln_c[end - 1]));
            }
            // Every base is cut and every output is 0: none below the one before it.
            self.n_cut += len;
            debug_assert!(
                self.prev_out.is_none_or(|p| p == 0),
                "a prefix of the codes"
            );
            self.prev_out = Some(0);
        }
        next
    }

    /// The exponent's figures, with the largest code of zero lobes counted once.
    fn finish(mut self) -> PerN {
        if let Some((code, lnc)) = self.zero_lobe_code {
            let at = (self.nc.n, code);
            let cos_n = if code <= 0 {
                0.0
            } else {
                (self.nf * lnc).exp()
            };
            self.quant.add(0.0, at);
            self.approx.add(cos_n, at);
            self.total.add(cos_n, at);
            self.norm.add(self.norm_peak * cos_n, at);
            self.norm_approx = self.norm_approx.max(self.norm_peak * cos_n);
        }
        PerN {
            stages: self.acc,
            quant: self.quant,
            approx: self.approx,
            total: self.total,
            norm_rel: self.norm.value / self.norm_peak,
            norm_approx_rel: self.norm_approx / self.norm_peak,
            norm: self.norm,
            n_violations: self.n_violations,
            violations: self.violations,
            n_cut: self.n_cut,
        }
    }
}

/// A worker's columns, reused from one exponent to the next.
#[derive(Default)]
pub(super) struct Scratch {
    probes: crate::pipeline::ProbeColumns,
    fold: FoldColumns,
}

/// The columns an [`NFold`] fills chunk by chunk.
#[derive(Default)]
struct FoldColumns {
    /// b's f64 reference over the chunk (t's is `slope * d`, d's is shared by every n).
    ref_b: Vec<f64>,
    /// Compacted columns of the inputs whose base is not 0 in both models ("live").
    live: Vec<usize>,
    live_codes: Vec<i64>,
    live_raws: Vec<i64>,
    live_refs: Vec<f64>,
    /// [`screen::exp_near_all`] of the live inputs' cos^n.
    live_cos: Vec<f64>,
    /// The live inputs' fixed-point values (the last squaring's, then the output's).
    live_vals: Vec<f64>,
    /// [`screen::screen_two`]'s scratch.
    screen: Vec<f64>,
}

/// One exponent's exhaustive check: every chunk of the stream above the dead prefix's start,
/// folded by [`NFold`].
pub(super) fn check_one_n(
    dp: &Datapath,
    nc: &NConstants,
    shared: &CodeColumns,
    scratch: &mut Scratch,
) -> PerN {
    let dead_end = dead_prefix_end(dp, nc, &shared.codes.codes);
    let mut fold = NFold::new(dp, nc, &mut scratch.fold);
    let span = Span {
        from: fold.overflowed_prefix(shared, dead_end),
        dead_end,
        chunk_codes: CHUNK,
    };
    each_chunk_in(dp, nc, &shared.codes, span, &mut scratch.probes, |c| {
        fold.chunk(c, &shared.ref_d[c.start..c.start + c.codes.len()]);
    });
    fold.finish()
}
