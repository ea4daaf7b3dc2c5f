//! The batch engine: every analysis's "evaluate this datapath on every code and every n",
//! split into work items (one n, one range of codes), run in parallel and merged in a fixed
//! order, so results do not depend on the number of threads.
//!
//! Work items are `(n index, code range)` pairs in n-major order; [`map_items`] returns one
//! value per item in that order, whatever thread computed it. An analysis folds those values
//! in order (or, for associative figures such as counts and wrapping sums, in any order).
//!
//! **Invariant:** no I/O and no wall-clock time here: the same datapath gives the same values
//! on any machine and with any number of threads.

pub mod pairs;

use std::ops::Range;

use rayon::prelude::*;

use crate::fixed::Event;
use crate::pipeline::{Datapath, NConstants, ProbeColumns, MAX_STAGES};

/// Codes per work item: large enough to amortise scheduling, small enough that a sweep of
/// 1024 exponents splits across cores and each item's columns stay in cache.
pub const ITEM_CODES: usize = 8192;

/// Codes per batch inside a work item (the columns of one kernel pass).
pub const BATCH_CODES: usize = 2048;

/// One unit of work: an exponent (by its index in the datapath's n set) and a range of input
/// codes.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Item {
    /// Index into [`Datapath::constants`].
    pub n_idx: usize,
    /// Raw input codes `start..end`.
    pub codes: Range<i64>,
}

/// The work items covering `codes` for every n of the datapath, in n-major, code order.
///
/// # Examples
/// ```
/// use specfx::engine::{items, ITEM_CODES};
/// use specfx::pipeline::{Config, Datapath};
/// let dp = Datapath::new(Config::baseline()).unwrap();
/// let all = items(&dp, 0..32769);
/// assert_eq!(all.len(), 1009 * 32769usize.div_ceil(ITEM_CODES));
/// assert_eq!(all[0].codes, 0..ITEM_CODES as i64);
/// ```
pub fn items(dp: &Datapath, codes: Range<i64>) -> Vec<Item> {
    let step = ITEM_CODES as i64;
    let mut out = Vec::new();
    for n_idx in 0..dp.constants().len() {
        let mut start = codes.start;
        while start < codes.end {
            let end = start.saturating_add(step).min(codes.end);
            out.push(Item {
                n_idx,
                codes: start..end,
            });
            start = end;
        }
    }
    out
}

/// Runs `work` on every item in parallel and returns the results in item order.
pub fn map_items<T: Send>(
    dp: &Datapath,
    items: &[Item],
    work: impl Fn(&NConstants, Range<i64>) -> T + Sync,
) -> Vec<T> {
    let constants = dp.constants();
    items
        .par_iter()
        .with_min_len(1)
        .map(|item| work(&constants[item.n_idx], item.codes.clone()))
        .collect()
}

/// Runs `work` once per exponent of the datapath, in parallel, and returns the results in the
/// order of the n set: the engine's coarse items, for analyses whose figures are folded over
/// the codes of one n in code order (their sums then do not depend on how codes are split).
///
/// # Examples
/// ```
/// use specfx::engine::map_n;
/// use specfx::pipeline::{Config, Datapath};
/// let dp = Datapath::new(Config::baseline()).unwrap();
/// let ns = map_n(&dp, |nc| nc.n);
/// assert_eq!(ns.len(), 1009);
/// assert_eq!((ns[0], ns[1008]), (16, 1024));
/// ```
pub fn map_n<T: Send>(dp: &Datapath, work: impl Fn(&NConstants) -> T + Sync) -> Vec<T> {
    dp.constants().par_iter().map(&work).collect()
}

/// [`map_n`] with a scratch `init` makes for each worker's run of exponents (columns reused
/// from one n to the next instead of allocated for each); results in n order.
pub fn map_n_with<S, T: Send>(
    dp: &Datapath,
    init: impl Fn() -> S + Sync + Send,
    work: impl Fn(&mut S, &NConstants) -> T + Sync + Send,
) -> Vec<T> {
    dp.constants()
        .par_iter()
        .map_init(init, |s, nc| work(s, nc))
        .collect()
}

/// The input codes a stream evaluates for every n, with `ln c` of each (c clamped to 1.0),
/// computed once and shared by every n: `cos^n = exp(n ln c)`.
#[derive(Debug, Clone, PartialEq)]
pub struct Codes {
    /// Raw input codes, in the order the stream visits them.
    pub codes: Vec<i64>,
    /// `ln c` of each code clamped to 1.0; minus infinity for `c <= 0`, so that
    /// `exp(n ln c)` is 0 there for every n >= 1 (the lobe is max(0, c)^n).
    pub ln_c: Vec<f64>,
}

/// `ln c` of an input `c`, minus infinity for `c <= 0`: `exp(n ln_c(c))` is cos^n of the
/// clamped cosine, 0 at and below 0 for every n >= 1 (a signed input's negative codes, where
/// `ln` alone would give NaN).
pub fn ln_c(c: f64) -> f64 {
    if c > 0.0 {
        c.ln()
    } else {
        f64::NEG_INFINITY
    }
}

impl Codes {
    /// The given codes of a datapath's input.
    pub fn new(dp: &Datapath, codes: Vec<i64>) -> Codes {
        let (one, lsb) = (dp.one_code(), dp.config().c.format.lsb());
        let ln_c = codes
            .iter()
            .map(|&k| ln_c(k.min(one) as f64 * lsb))
            .collect();
        Codes { codes, ln_c }
    }

    /// Every code of the input format from its first up to 1.0.
    pub fn up_to_one(dp: &Datapath) -> Codes {
        let last = (*dp.input_codes().end()).min(dp.one_code());
        Codes::new(dp, (*dp.input_codes().start()..=last).collect())
    }
}

/// Codes per chunk of the stream.
pub const CHUNK_CODES: usize = 4096;

/// One chunk of the stream: an exponent, a run of codes, and what the datapath and the f64
/// reference give for them.
pub struct Chunk<'a> {
    dp: &'a Datapath,
    /// The exponent's constants.
    pub nc: &'a NConstants,
    /// The input codes.
    pub codes: &'a [i64],
    /// `ln c` of each code clamped to 1.0.
    pub ln_c: &'a [f64],
    /// The fixed-point probes: every stage's value, the cut flags and each stage's event
    /// counts over the chunk.
    pub probes: &'a ProbeColumns,
    /// The index of the chunk's first code in the stream's [`Codes`] (for an analysis's own
    /// per-code columns).
    pub start: usize,
    /// The chunk lies below the caller's dead-prefix end: every base is cut, so d and t are
    /// evaluated and b..out hold 0 ([`Datapath::eval_batch_cut`]).
    pub dead: bool,
}

impl Chunk<'_> {
    /// `cos^n` of element `i`, from its `ln c`.
    #[inline]
    pub fn cos_n(&self, i: usize) -> f64 {
        (f64::from(self.nc.n) * self.ln_c[i]).exp()
    }

    /// Whether any stage of any element of the chunk wrapped, saturated or was zeroed.
    pub fn any_event(&self) -> bool {
        self.probes.event_counts.iter().flatten().any(|&x| x > 0)
    }

    /// The overflow event of each stage for element `i` (the batch keeps counts only, so the
    /// element is evaluated alone when the chunk had any event).
    pub fn events(&self, i: usize) -> [Event; MAX_STAGES] {
        if self.any_event() {
            self.dp.eval(self.codes[i], self.nc).events
        } else {
            [Event::None; MAX_STAGES]
        }
    }
}

/// The engine's stream: for every n of the datapath, in parallel, an accumulator made by
/// `init` is fed the chunks of `codes` in order by `step`; the accumulators come back in the
/// order of the n set, so every figure folded from them is the same with any number of
/// threads. `done` is called once per finished n (from any thread), for progress.
///
/// # Examples
/// ```
/// use specfx::engine::{fold_n, Codes};
/// use specfx::pipeline::{Config, Datapath};
/// let dp = Datapath::new(Config::baseline()).unwrap();
/// let codes = Codes::up_to_one(&dp);
/// // The largest output of each n, and cos^n at c = 1.
/// let per_n = fold_n(&dp, &codes, |_| (0, 0.0), |acc, chunk| {
///     let out = &chunk.probes.values[dp.stage_out()];
///     acc.0 = acc.0.max(*out.iter().max().unwrap());
///     acc.1 = chunk.cos_n(chunk.codes.len() - 1);
/// }, &|| {});
/// assert_eq!(per_n.len(), 1009);
/// assert_eq!(per_n[0].1, 1.0);
/// ```
pub fn fold_n<A: Send>(
    dp: &Datapath,
    codes: &Codes,
    init: impl Fn(&NConstants) -> A + Sync,
    step: impl Fn(&mut A, &Chunk<'_>) + Sync,
    done: &(dyn Fn() + Sync),
) -> Vec<A> {
    map_n(dp, |nc| {
        let mut acc = init(nc);
        each_chunk(dp, nc, codes, Span::default(), |chunk| {
            step(&mut acc, chunk)
        });
        done();
        acc
    })
}

/// Which part of the codes [`each_chunk`] streams, in chunks of what size, and where the
/// caller has proven a dead prefix.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Span {
    /// The index of the first code streamed.
    pub from: usize,
    /// Chunks whose codes are all below this code are dead (see [`Chunk::dead`]).
    pub dead_end: i64,
    /// Codes per chunk (figures summed per chunk depend on it).
    pub chunk_codes: usize,
}

impl Default for Span {
    /// Every code, no dead prefix, [`CHUNK_CODES`] codes per chunk.
    fn default() -> Span {
        Span {
            from: 0,
            dead_end: i64::MIN,
            chunk_codes: CHUNK_CODES,
        }
    }
}

/// The stream of one n: the chunks of `codes[span.from..]` in order, each evaluated (a dead
/// chunk with [`Datapath::eval_batch_cut`]) and handed to `f`.
pub fn each_chunk(
    dp: &Datapath,
    nc: &NConstants,
    codes: &Codes,
    span: Span,
    f: impl FnMut(&Chunk<'_>),
) {
    each_chunk_in(dp, nc, codes, span, &mut ProbeColumns::default(), f);
}

/// [`each_chunk`] with the columns of `probes` reused (a thread's, across its exponents).
pub fn each_chunk_in(
    dp: &Datapath,
    nc: &NConstants,
    codes: &Codes,
    span: Span,
    probes: &mut ProbeColumns,
    mut f: impl FnMut(&Chunk<'_>),
) {
    let mut start = span.from;
    while start < codes.codes.len() {
        let end = (start + span.chunk_codes).min(codes.codes.len());
        let chunk = &codes.codes[start..end];
        let dead = chunk[chunk.len() - 1] < span.dead_end;
        if dead {
            dp.eval_batch_cut(nc, chunk, probes);
        } else {
            dp.eval_batch(nc, chunk, probes);
        }
        f(&Chunk {
            dp,
            nc,
            codes: chunk,
            ln_c: &codes.ln_c[start..end],
            probes,
            start,
            dead,
        });
        start = end;
    }
}

/// The output codes of a datapath over a range of input codes for every n: the checksum and
/// count of its evaluations.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct OutputSum {
    /// Evaluations done.
    pub evaluations: u64,
    /// The wrapping (mod 2^64) sum of `out_raw * (c_raw + 1) * n` over every evaluation: a
    /// position-sensitive fingerprint any other model can compute.
    pub checksum: u64,
}

/// Evaluates the output of every code in `codes` for every n of the datapath and fingerprints
/// the results (see [`OutputSum`]).
///
/// # Examples
/// ```
/// use specfx::engine::output_sum;
/// use specfx::pipeline::{Config, Datapath};
/// let dp = Datapath::new(Config::baseline()).unwrap();
/// let sum = output_sum(&dp, 0..32769);
/// assert_eq!(sum.evaluations, 1009 * 32769);
/// ```
pub fn output_sum(dp: &Datapath, codes: Range<i64>) -> OutputSum {
    let all = items(dp, codes);
    let parts = map_items(dp, &all, |nc, range| {
        let mut scratch = crate::pipeline::OutputScratch::default();
        let mut out = vec![0i64; BATCH_CODES];
        // The sum of out * (c + 1), times n once at the end (mod 2^64 either way).
        let mut sum = 0u64;
        let live = dp.first_live_code(nc, range.clone());
        let mut start = range.start;
        while start < range.end {
            let end = (start + BATCH_CODES as i64).min(range.end);
            let out = &mut out[..(end - start) as usize];
            let n_dead = dp.eval_outputs_from(nc, start..end, live, out, &mut scratch);
            // The cut prefix's outputs are 0 and add nothing.
            let first_live = start + n_dead as i64;
            for (c, &o) in (first_live..end).zip(&out[n_dead..]) {
                sum = sum.wrapping_add((o as u64).wrapping_mul((c as u64).wrapping_add(1)));
            }
            start = end;
        }
        OutputSum {
            evaluations: (range.end - range.start) as u64,
            checksum: sum.wrapping_mul(u64::from(nc.n)),
        }
    });
    parts.iter().fold(
        OutputSum {
            evaluations: 0,
            checksum: 0,
        },
        |a, p| OutputSum {
            evaluations: a.evaluations + p.evaluations,
            checksum: a.checksum.wrapping_add(p.checksum),
        },
    )
}
