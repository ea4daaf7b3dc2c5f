//! Rounding boundaries: where an exact value lies against the point at which its stage's
//! rounding decision changes ([`RoundingStage::boundary`]), and the search for inputs whose
//! exact value before a quantization lies on or next to that point, at every stage that
//! rounds ([`search`]).
//!
//! A stage that drops `s >= 1` fraction bits decides between `q = floor(x / 2^s)` and `q + 1`
//! from the dropped bits `r = x mod 2^s` (docs/arithmetic.md section 2.1). The decision
//! changes at `r = 2^(s-1)` (the tie) for the round-to-nearest modes and at `r = 0` for `TRN`
//! and `TRN_ZERO`. A value is *on* the boundary when `r` is that residue and *next to* it when
//! `r` is one exact LSB beside it (modulo `2^s`): a quantizer that adds its rounding constant
//! one LSB off, or resolves a tie the wrong way, fails only there, which random inputs reach
//! about once in `2^s` draws per stage.

use std::collections::{BTreeMap, BTreeSet};

use serde::Serialize;

use crate::fixed::Rounding;
use crate::pipeline::datapath::{CutStructure, STAGE_B, STAGE_D, STAGE_SQ0, STAGE_T};
use crate::pipeline::{Datapath, NConstants, ProbeColumns};

/// A stage that quantizes an exact value: its probe, rounding mode, the fraction bits of its
/// exact input and how many of them it drops.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RoundingStage {
    /// The stage's probe index (t, b, a squaring or out).
    pub stage_idx: usize,
    /// Its rounding mode.
    pub rounding: Rounding,
    /// Fraction bits of the exact value it quantizes.
    pub frac_in: i32,
    /// Fraction bits dropped: `frac_in` minus the format's (at most 0: no rounding).
    pub dropped_bits: i64,
}

/// Where an exact value lies against its stage's rounding boundary.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct Boundary {
    /// `0` on the boundary, `-1` one exact LSB below it, `+1` one above (the dropped bits
    /// modulo `2^s`; with `s = 1` the two neighbours are the same residue, counted as `-1`).
    pub offset: i8,
    /// The exact value is negative (`TRN_ZERO`, `RND_ZERO` and `RND_INF` decide by the sign).
    pub negative: bool,
    /// On the boundary of `RND_CONV` or `RND_CONV_ODD`: the truncated quotient is odd (what
    /// those modes decide by); false elsewhere.
    pub odd: bool,
}

impl RoundingStage {
    /// Whether the stage rounds at all (drops at least one bit).
    pub fn rounds(&self) -> bool {
        self.dropped_bits >= 1
    }

    /// Where `x` (a raw with [`RoundingStage::frac_in`] fraction bits, `|x| < 2^126` as
    /// validation guarantees) lies against the boundary; `None` when neither on nor next to
    /// it, or when the stage drops no bits.
    ///
    /// # Examples
    /// ```
    /// use specfx::fixed::Rounding;
    /// use specfx::golden::ties::RoundingStage;
    /// let st = RoundingStage { stage_idx: 1, rounding: Rounding::Rnd, frac_in: 3, dropped_bits: 3 };
    /// assert_eq!(st.boundary(12).unwrap().offset, 0); // 1.5: r = 4, the tie
    /// assert_eq!(st.boundary(-13).unwrap().offset, -1); // r = 3
    /// assert_eq!(st.boundary(5).unwrap().offset, 1);
    /// assert!(st.boundary(6).is_none());
    /// ```
    pub fn boundary(&self, x: i128) -> Option<Boundary> {
        if !self.rounds() {
            return None;
        }
        let s = u32::try_from(self.dropped_bits).unwrap_or(u32::MAX);
        let nearest = !matches!(self.rounding, Rounding::Trn | Rounding::TrnZero);
        let offset = if s <= 128 {
            let mask = if s == 128 {
                u128::MAX
            } else {
                (1u128 << s) - 1
            };
            let r = (x as u128) & mask;
            let b = if nearest { 1u128 << (s - 1) } else { 0 };
            if r == b {
                0
            } else if r == b.wrapping_sub(1) & mask {
                -1
            } else if r == b.wrapping_add(1) & mask {
                1
            } else {
                return None;
            }
        } else if nearest {
            // |x| < 2^126 never comes within one LSB of 2^(s-1) modulo 2^s for s > 128.
            return None;
        } else {
            // The boundary residue 0: x = 0, and its neighbours 2^s - 1 (x = -1) and 1.
            match x {
                0 => 0,
                -1 => -1,
                1 => 1,
                _ => return None,
            }
        };
        let conv = matches!(self.rounding, Rounding::RndConv | Rounding::RndConvOdd);
        let odd = offset == 0 && conv && (x >> s.min(127)) & 1 == 1;
        Some(Boundary {
            offset,
            negative: x < 0,
            odd,
        })
    }
}

/// Every stage that quantizes (t, b, the squarings, out), in pipeline order, whether or not it
/// drops bits. The slope's and offset's fraction bits are the same for every n.
pub fn quantizing_stages(dp: &Datapath) -> Vec<RoundingStage> {
    let cfg = dp.config();
    let (slope_frac, offset_frac) = dp
        .constants()
        .first()
        .map_or((0, 0), |nc| (nc.slope_frac, nc.offset_frac));
    let stage = |stage_idx: usize, spec: &crate::pipeline::StageSpec, frac_in: i32| RoundingStage {
        stage_idx,
        rounding: spec.rounding,
        frac_in,
        dropped_bits: i64::from(frac_in) - i64::from(spec.format.frac_bits()),
    };
    let ft = cfg.t.format.frac_bits();
    let mut v = vec![
        stage(STAGE_T, &cfg.t, cfg.d.format.frac_bits() + slope_frac),
        stage(STAGE_B, &cfg.b, ft.max(offset_frac)),
    ];
    let mut prev = cfg.b.format.frac_bits();
    for (i, spec) in cfg.square.iter().enumerate() {
        v.push(stage(STAGE_SQ0 + i, spec, 2 * prev));
        prev = spec.format.frac_bits();
    }
    v.push(stage(
        dp.stage_out(),
        &cfg.out,
        prev + cfg.coef.format.frac_bits(),
    ));
    v
}

/// The stages that drop at least one bit: [`quantizing_stages`] that round.
pub fn rounding_stages(dp: &Datapath) -> Vec<RoundingStage> {
    quantizing_stages(dp)
        .into_iter()
        .filter(RoundingStage::rounds)
        .collect()
}

/// The exact value stage `stage_idx` quantizes, from the probes of the same evaluation
/// (`value(i)` is probe `i`) and its cut flag: `d * slope`, the aligned `t + offset` (0 when
/// cut), the square of the previous probe, or `sq_k * coef`.
pub fn exact_input(
    dp: &Datapath,
    nc: &NConstants,
    stage_idx: usize,
    value: impl Fn(usize) -> i64,
    cut: bool,
) -> i128 {
    if stage_idx == STAGE_T {
        i128::from(value(STAGE_D)) * i128::from(nc.slope_raw)
    } else if stage_idx == STAGE_B {
        if cut {
            return 0;
        }
        let ft = dp.config().t.format.frac_bits();
        let fs = ft.max(nc.offset_frac);
        (i128::from(value(STAGE_T)) << (fs - ft) as u32)
            + (i128::from(nc.offset_raw) << (fs - nc.offset_frac) as u32)
    } else if stage_idx == dp.stage_out() {
        i128::from(value(dp.stage_last_square())) * i128::from(nc.coef_raw)
    } else {
        let prev = i128::from(value(stage_idx - 1));
        prev * prev
    }
}

/// At most this many inputs per stage and [`Boundary`] class are kept, spread over the n set.
pub const TIES_PER_CLASS: usize = 8;

/// The most input codes the search looks at, over all n (each n gets an equal share, at least
/// [`MIN_CODES_PER_N`]).
pub const SEARCH_CODES: u64 = 1 << 25;

/// The fewest codes the search looks at per n.
pub const MIN_CODES_PER_N: u64 = 1024;

/// Codes per batch of the search.
const CHUNK: i64 = 4096;

/// One rounding stage's part of a search.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct TieStage {
    /// The stage (`t`, `b`, `sq1`.., `out`).
    pub stage: String,
    /// Its rounding mode.
    pub rounding: Rounding,
    /// The fraction bits its quantization drops.
    pub dropped_bits: i64,
    /// How many classes (on the boundary or one LSB below or above it, by sign, and for the
    /// round-to-even modes by the parity of the truncated quotient) some searched input
    /// reaches.
    pub classes: u64,
    /// How many (n, c) inputs are kept for this stage (at most [`TIES_PER_CLASS`] per class).
    pub vectors: u64,
}

/// What the search for rounding-boundary inputs looked at and kept (the manifest's
/// `coverage.directed.ties`).
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct TieSearch {
    /// The distinct (n, c) inputs kept, over every stage.
    pub vectors: u64,
    /// Every input code up to 1.0 of every n was looked at.
    pub exhaustive: bool,
    /// The codes looked at per n: the highest codes up to 1.0 (1.0 included), down from it.
    pub codes_per_n: u64,
    /// The codes looked at, over all n.
    pub codes_searched: u64,
    /// One entry per stage that drops bits, in pipeline order.
    pub stages: Vec<TieStage>,
}

/// For each n: per rounding stage, the highest code found in each class.
type Found = Vec<BTreeMap<Boundary, i64>>;

/// The search's inputs and what it did.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Ties {
    /// The (n, c) inputs kept, sorted.
    pub cases: Vec<(u32, i64)>,
    /// What was searched and kept.
    pub report: TieSearch,
}

/// Searches every n for inputs whose exact value before a quantization lies on or next to the
/// stage's rounding boundary ([`RoundingStage::boundary`]), for every stage that drops bits.
///
/// Per n it looks at the `w` highest codes up to 1.0, down from 1.0, `w = max(SEARCH_CODES /
/// (number of n), MIN_CODES_PER_N)`: every code when that many or fewer lie up to 1.0 (the
/// baseline's 32769 codes for each of its 1009 n). Codes whose base the cutoff is proven to
/// cut (a prefix, [`Datapath::first_live_code`]) are not evaluated past t: from b on their
/// exact values are 0. Per n and class the highest code is kept; per stage and class, at most
/// [`TIES_PER_CLASS`] of those, spread over the n set (the first n, the last and evenly
/// between). The result depends on the datapath alone (no seed), and on no thread count.
///
/// # Examples
/// ```
/// use specfx::golden::ties::search;
/// use specfx::pipeline::{Config, Datapath};
/// let dp = Datapath::new(Config::from_toml("n = \"16,100\"").unwrap()).unwrap();
/// let ties = search(&dp);
/// assert!(ties.report.exhaustive);
/// let names: Vec<&str> = ties.report.stages.iter().map(|s| s.stage.as_str()).collect();
/// assert_eq!(names, ["t", "sq1", "sq2", "sq3", "sq4", "out"]); // b drops no bits
/// ```
pub fn search(dp: &Datapath) -> Ties {
    search_within(dp, SEARCH_CODES)
}

/// [`search`] with another budget of codes over all n.
fn search_within(dp: &Datapath, budget: u64) -> Ties {
    let stages = rounding_stages(dp);
    let ns = dp.constants();
    let codes = dp.input_codes();
    let (lo, hi) = (*codes.start(), *codes.end());
    let top = hi.min(dp.one_code());
    let span = u64::try_from(i128::from(top) - i128::from(lo) + 1).unwrap_or(u64::MAX);
    let window = (budget / ns.len().max(1) as u64)
        .max(MIN_CODES_PER_N)
        .min(span);
    let per_n: Vec<Found> = if stages.is_empty() {
        Vec::new()
    } else {
        crate::engine::map_n(dp, |nc| search_n(dp, nc, &stages, window))
    };
    let mut cases = BTreeSet::new();
    let mut report_stages = Vec::new();
    for (k, st) in stages.iter().enumerate() {
        let mut by_class: BTreeMap<Boundary, Vec<(u32, i64)>> = BTreeMap::new();
        for (nc, found) in ns.iter().zip(&per_n) {
            for (&class, &c) in &found[k] {
                by_class.entry(class).or_default().push((nc.n, c));
            }
        }
        let mut kept = BTreeSet::new();
        for list in by_class.values() {
            kept.extend(spread(list, TIES_PER_CLASS));
        }
        report_stages.push(TieStage {
            stage: dp.stages()[st.stage_idx].name.clone(),
            rounding: st.rounding,
            dropped_bits: st.dropped_bits,
            classes: by_class.len() as u64,
            vectors: kept.len() as u64,
        });
        cases.extend(kept);
    }
    let report = TieSearch {
        vectors: cases.len() as u64,
        exhaustive: window == span,
        codes_per_n: window,
        codes_searched: window.saturating_mul(ns.len() as u64),
        stages: report_stages,
    };
    Ties {
        cases: cases.into_iter().collect(),
        report,
    }
}

/// Up to `k` of `items`: the first, the last and evenly spaced between.
fn spread<T: Copy>(items: &[T], k: usize) -> Vec<T> {
    if items.len() <= k {
        return items.to_vec();
    }
    let last = items.len() - 1;
    (0..k).map(|i| items[i * last / (k - 1)]).collect()
}

/// A class's slot among the 12 a stage can have: offset, sign, parity.
fn slot(b: Boundary) -> usize {
    (b.offset + 1) as usize * 4 + usize::from(b.negative) * 2 + usize::from(b.odd)
}

/// A cheap test that `x` may lie on or next to a stage's boundary: the dropped bits are one of
/// the three residues `b - 1`, `b`, `b + 1` (modulo `2^s`), checked as one subtraction.
/// [`RoundingStage::boundary`] decides on the few that pass.
#[derive(Debug, Clone, Copy)]
struct Filter {
    /// `2^s - 1`, or `None` beyond 128 dropped bits (every value goes to `boundary`).
    mask: Option<u128>,
    /// `b - 1` modulo `2^s`.
    below: u128,
}

impl Filter {
    fn new(st: &RoundingStage) -> Filter {
        let s = u32::try_from(st.dropped_bits).unwrap_or(u32::MAX);
        if s > 128 {
            return Filter {
                mask: None,
                below: 0,
            };
        }
        let mask = if s == 128 {
            u128::MAX
        } else {
            (1u128 << s) - 1
        };
        let b = match st.rounding {
            Rounding::Trn | Rounding::TrnZero => 0,
            _ => 1u128 << (s - 1),
        };
        Filter {
            mask: Some(mask),
            below: b.wrapping_sub(1) & mask,
        }
    }

    #[inline]
    fn passes(&self, x: i128) -> bool {
        match self.mask {
            Some(mask) => ((x as u128).wrapping_sub(self.below) & mask) <= 2,
            None => true,
        }
    }
}

/// One n: the highest code of each class, per stage, among the `window` highest codes up to
/// 1.0.
fn search_n(dp: &Datapath, nc: &NConstants, stages: &[RoundingStage], window: u64) -> Found {
    let mut best: Vec<[Option<i64>; 12]> = vec![[None; 12]; stages.len()];
    let filters: Vec<Filter> = stages.iter().map(Filter::new).collect();
    let mut note = |k: usize, x: i128, c: i64| {
        if let Some(class) = stages[k].boundary(x) {
            let e = &mut best[k][slot(class)];
            *e = Some(e.map_or(c, |old| old.max(c)));
        }
    };
    let lo = *dp.input_codes().start();
    let top = (*dp.input_codes().end()).min(dp.one_code());
    let start = (i128::from(top) - i128::from(window) + 1).max(i128::from(lo));
    let start = i64::try_from(start).expect("between two codes");
    let live = match dp.cut_structure() {
        CutStructure::Prefix => dp.first_live_code(nc, start..top + 1),
        CutStructure::Never | CutStructure::Scan => start,
    };
    // The cut prefix: t as evaluated, every later stage quantizes 0.
    if live > start {
        for (k, st) in stages.iter().enumerate() {
            if st.stage_idx == STAGE_T {
                let slope = i128::from(nc.slope_raw);
                for c in start..live {
                    let (_, d) = dp.op_sub(c);
                    let x = i128::from(d) * slope;
                    if filters[k].passes(x) {
                        note(k, x, c);
                    }
                }
            } else {
                note(k, 0, live - 1);
            }
        }
    }
    let mut cols = ProbeColumns::default();
    let mut chunk = Vec::with_capacity(CHUNK as usize);
    let mut begin = live;
    while begin <= top {
        let end = begin.saturating_add(CHUNK - 1).min(top);
        chunk.clear();
        chunk.extend(begin..=end);
        dp.eval_batch(nc, &chunk, &mut cols);
        for (k, st) in stages.iter().enumerate() {
            let filter = filters[k];
            // exact_input, one column at a time (the same arithmetic, without a branch per
            // element).
            let mut each = |x: i128, i: usize| {
                if filter.passes(x) {
                    note(k, x, chunk[i]);
                }
            };
            let v = &cols.values;
            let idx = st.stage_idx;
            if idx == STAGE_T {
                let slope = i128::from(nc.slope_raw);
                for (i, &d) in v[STAGE_D].iter().enumerate() {
                    each(i128::from(d) * slope, i);
                }
            } else if idx == STAGE_B {
                for (i, &cut) in cols.cut.iter().enumerate() {
                    each(exact_input(dp, nc, idx, |s| v[s][i], cut), i);
                }
            } else if idx == dp.stage_out() {
                let coef = i128::from(nc.coef_raw);
                for (i, &x) in v[dp.stage_last_square()].iter().enumerate() {
                    each(i128::from(x) * coef, i);
                }
            } else {
                for (i, &x) in v[idx - 1].iter().enumerate() {
                    each(i128::from(x) * i128::from(x), i);
                }
            }
        }
        if end == top {
            break;
        }
        begin = end + 1;
    }
    // Back to classes: decode each filled slot.
    best.iter()
        .map(|slots| {
            let mut map = BTreeMap::new();
            for (i, c) in slots.iter().enumerate() {
                if let Some(c) = *c {
                    let class = Boundary {
                        offset: (i / 4) as i8 - 1,
                        negative: i % 4 >= 2,
                        odd: i % 2 == 1,
                    };
                    map.insert(class, c);
                }
            }
            map
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pipeline::fast::quantize_to;
    use crate::pipeline::{Config, StageSpec};

    fn datapath(toml: &str) -> Datapath {
        Datapath::new(Config::from_toml(toml).unwrap()).unwrap()
    }

    /// The boundary class from its definition, with the remainder computed by `rem_euclid`.
    fn by_definition(st: &RoundingStage, x: i128) -> Option<(i8, bool)> {
        let s = st.dropped_bits as u32;
        let m = 1i128 << s;
        let r = x.rem_euclid(m);
        let b = match st.rounding {
            Rounding::Trn | Rounding::TrnZero => 0,
            _ => m / 2,
        };
        [0i8, -1, 1]
            .into_iter()
            .find(|&o| r == (b + i128::from(o)).rem_euclid(m))
            .map(|o| (o, x < 0))
    }

    #[test]
    fn boundary_classes_follow_their_definition() {
        for rounding in Rounding::ALL {
            for s in 1..=6i64 {
                let st = RoundingStage {
                    stage_idx: STAGE_T,
                    rounding,
                    frac_in: 8,
                    dropped_bits: s,
                };
                for x in -200i128..200 {
                    let got = st.boundary(x).map(|b| (b.offset, b.negative));
                    assert_eq!(got, by_definition(&st, x), "{rounding} s = {s} x = {x}");
                }
            }
        }
        // Hand cases at the wide end: s = 127 and 128 with the largest exact values, and
        // beyond 128 bits only TRN's boundary at 0 is reachable.
        let st = |rounding, s| RoundingStage {
            stage_idx: STAGE_T,
            rounding,
            frac_in: 0,
            dropped_bits: s,
        };
        let max = (1i128 << 126) - 1;
        assert_eq!(st(Rounding::Rnd, 127).boundary(max).unwrap().offset, -1);
        assert!(st(Rounding::Rnd, 127).boundary(max - 1).is_none());
        assert!(st(Rounding::Rnd, 128).boundary(max).is_none());
        assert_eq!(st(Rounding::Trn, 128).boundary(-1).unwrap().offset, -1);
        assert_eq!(st(Rounding::Trn, 600).boundary(1).unwrap().offset, 1);
        assert_eq!(st(Rounding::Trn, 600).boundary(0).unwrap().offset, 0);
        assert!(st(Rounding::Rnd, 600).boundary(-max).is_none());
        assert!(st(Rounding::Trn, 600).boundary(2).is_none());
        // Round to even: the parity of the truncated quotient on a tie.
        let conv = st(Rounding::RndConv, 2);
        assert!(!conv.boundary(2).unwrap().odd); // 0.5: q = 0
        assert!(conv.boundary(6).unwrap().odd); // 1.5: q = 1
        assert!(conv.boundary(-2).unwrap().odd); // -0.5: q = -1
        assert!(!st(Rounding::Rnd, 2).boundary(6).unwrap().odd);
    }

    #[test]
    fn exact_inputs_quantize_to_the_probes() {
        // The exact value each stage quantizes, recomputed from the probes, gives the stage's
        // probe through the stage's own quantization, on every code of small datapaths.
        for toml in [
            "n = \"1,7,100\"\n[c]\nformat = \"u1.8\"\n[d]\nformat = \"s1.8\"\n",
            "variant = \"minimax\"\ncutoff = \"paper\"\nk = 2\nn = \"16,33\"\n[c]\nformat = \"s2.7\"\n[d]\nformat = \"s3.9\"\n[t]\nformat = \"s3.10\"\nrounding = \"RND_CONV\"\n[b]\nformat = \"s2.9\"\nrounding = \"TRN_ZERO\"\n",
            "cutoff = \"none\"\nk = 1\nn = \"5\"\n[c]\nformat = \"s2.6\"\n[d]\nformat = \"s3.6\"\n[t]\nformat = \"s4.-1\"\noverflow = \"WRAP\"\n[b]\nformat = \"s3.3\"\noverflow = \"SAT_ZERO\"\n",
        ] {
            let dp = datapath(toml);
            let cfg = dp.config().clone();
            for nc in dp.constants() {
                for c in dp.input_codes() {
                    let p = dp.eval(c, nc);
                    for st in quantizing_stages(&dp) {
                        let x = exact_input(&dp, nc, st.stage_idx, |s| p.values[s], p.cut);
                        let spec: StageSpec = match st.stage_idx {
                            STAGE_T => cfg.t,
                            STAGE_B => cfg.b,
                            i if i == dp.stage_out() => cfg.out,
                            i => cfg.square[i - STAGE_SQ0],
                        };
                        let q = quantize_to(x, st.frac_in, &spec);
                        assert_eq!(q.raw, p.values[st.stage_idx], "{toml} c = {c}");
                    }
                }
            }
        }
    }

    /// Per (stage, class), the (n, c) of every code up to 1.0, from the scalar model.
    fn brute_force(dp: &Datapath) -> BTreeMap<(usize, Boundary), Vec<(u32, i64)>> {
        let mut all: BTreeMap<(usize, Boundary), Vec<(u32, i64)>> = BTreeMap::new();
        let top = (*dp.input_codes().end()).min(dp.one_code());
        for nc in dp.constants() {
            for c in *dp.input_codes().start()..=top {
                let p = dp.eval(c, nc);
                for st in rounding_stages(dp) {
                    let x = exact_input(dp, nc, st.stage_idx, |s| p.values[s], p.cut);
                    if let Some(b) = st.boundary(x) {
                        all.entry((st.stage_idx, b)).or_default().push((nc.n, c));
                    }
                }
            }
        }
        all
    }

    #[test]
    fn the_search_keeps_every_class_a_brute_force_scan_finds() {
        for toml in [
            "n = \"1..=12,100,1000\"\n[c]\nformat = \"u1.9\"\n[d]\nformat = \"s1.9\"\n[out]\nformat = \"u8.4\"\n",
            "cutoff = \"paper\"\nn = \"4,40,400\"\n[c]\nformat = \"u1.8\"\n[d]\nformat = \"s1.8\"\n[[square]]\nrounding = \"TRN\"\nformat = \"u1.6\"\n[[square]]\nrounding = \"RND_CONV\"\nformat = \"u1.9\"\n[[square]]\n[[square]]\nrounding = \"RND_ZERO\"\n",
            "cutoff = \"none\"\nk = 2\nn = \"3,9\"\n[c]\nformat = \"s2.7\"\n[d]\nformat = \"s3.7\"\n[t]\nformat = \"s4.3\"\noverflow = \"WRAP\"\nrounding = \"TRN_ZERO\"\n[b]\nformat = \"s3.2\"\n",
        ] {
            let dp = datapath(toml);
            let want = brute_force(&dp);
            let ties = search(&dp);
            assert!(ties.report.exhaustive, "{toml}");
            let kept: BTreeSet<(u32, i64)> = ties.cases.iter().copied().collect();
            let stages = rounding_stages(&dp);
            for st in &stages {
                let classes: Vec<_> = want.keys().filter(|(s, _)| *s == st.stage_idx).collect();
                let report = ties
                    .report
                    .stages
                    .iter()
                    .find(|r| r.stage == dp.stages()[st.stage_idx].name)
                    .unwrap();
                assert_eq!(
                    report.classes,
                    classes.len() as u64,
                    "{toml} {}",
                    report.stage
                );
                for key in classes {
                    let all = &want[key];
                    // Each class: at least one kept input, at most TIES_PER_CLASS, and every
                    // kept input of the class is the highest code of its n.
                    let mine: Vec<&(u32, i64)> = all.iter().filter(|p| kept.contains(p)).collect();
                    assert!(!mine.is_empty(), "{toml} {key:?}");
                    let n_with: BTreeSet<u32> = all.iter().map(|p| p.0).collect();
                    assert!(
                        mine.len() >= n_with.len().min(TIES_PER_CLASS),
                        "{toml} {key:?}"
                    );
                    for &&(n, c) in &mine {
                        let top = all.iter().filter(|p| p.0 == n).map(|p| p.1).max().unwrap();
                        if c != top {
                            // Kept for another class or stage: the highest of this class and n
                            // is kept too.
                            assert!(kept.contains(&(n, top)), "{toml} {key:?} n = {n}");
                        }
                    }
                }
            }
            // Nothing else is kept.
            let reached: BTreeSet<(u32, i64)> = want.values().flatten().copied().collect();
            assert!(kept.is_subset(&reached), "{toml}");
            assert!(ties.report.vectors <= (stages.len() * 12 * TIES_PER_CLASS) as u64);
        }
    }

    #[test]
    fn a_wide_input_is_searched_near_one() {
        // u1.40: 2^40 + 1 codes per n; with a budget of 8192 codes each n gets the 4096
        // highest up to 1.0.
        let dp = datapath(
            "n = \"17,1024\"\n[c]\nformat = \"u1.40\"\n[d]\nformat = \"s1.40\"\n[t]\nformat = \"s2.30\"\n",
        );
        let ties = search_within(&dp, 8192);
        assert!(!ties.report.exhaustive);
        assert_eq!(ties.report.codes_per_n, 4096);
        assert_eq!(ties.report.codes_searched, 8192);
        let low = dp.one_code() - 4095;
        assert!(ties
            .cases
            .iter()
            .all(|&(_, c)| c >= low && c <= dp.one_code()));
        // t drops 40 + 4 - 30 = 14 bits of the product n * (c - 1): the classes the 4096
        // highest codes reach, from the definition (residues 2^13 and 2^13 +- 1 of 2^14).
        let t = &ties.report.stages[0];
        assert_eq!((t.stage.as_str(), t.dropped_bits), ("t", 14));
        let mut want = BTreeSet::new();
        for nc in dp.constants() {
            for c in low..=dp.one_code() {
                let x = i128::from(c - dp.one_code()) * i128::from(nc.n);
                let r = x.rem_euclid(1 << 14);
                for (o, b) in [(0i8, 1i128 << 13), (-1, (1 << 13) - 1), (1, (1 << 13) + 1)] {
                    if r == b {
                        want.insert((o, x < 0));
                    }
                }
            }
        }
        assert_eq!(t.classes, want.len() as u64);
        assert!(t.classes > 0);
    }
}
