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

use std::ops::Range;

use rayon::prelude::*;

use crate::pipeline::{Datapath, NConstants};

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
        let mut sum = 0u64;
        let mut start = range.start;
        let n = u64::from(nc.n);
        while start < range.end {
            let end = (start + BATCH_CODES as i64).min(range.end);
            let out = &mut out[..(end - start) as usize];
            dp.eval_outputs_range(nc, start..end, out, &mut scratch);
            for (c, &o) in (start..end).zip(out.iter()) {
                let weight = (c as u64).wrapping_add(1).wrapping_mul(n);
                sum = sum.wrapping_add((o as u64).wrapping_mul(weight));
            }
            start = end;
        }
        OutputSum {
            evaluations: (range.end - range.start) as u64,
            checksum: sum,
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
