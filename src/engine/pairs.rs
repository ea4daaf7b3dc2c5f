//! Evaluation of arbitrary `(c, n)` pairs, as a testbench or a notebook asks for them: every
//! input checked against the datapath's domain first (a code of the input format, an n of the
//! configuration's set), then the outputs computed in parallel by the batch kernels (runs of
//! one n; a run of consecutive codes skips its proven dead prefix), or every stage's probe and
//! event by [`Datapath::eval`]. The C ABI and the Python package are faces of these functions.

use rayon::prelude::*;

use crate::error::Error;
use crate::fixed::Event;
use crate::pipeline::{Datapath, NConstants, OutputScratch, Probes};

/// The exponents of a batch: one for every pair, or one for all.
#[derive(Debug, Clone, Copy)]
pub enum Ns<'a> {
    /// The same n for every c.
    One(u32),
    /// `n[i]` for `c[i]`; as long as the codes.
    Each(&'a [u32]),
}

/// Pairs per parallel piece of a batch: large enough to amortise scheduling.
const PIECE: usize = 1 << 16;

/// Runs of one n shorter than this are evaluated one pair at a time.
const SHORT_RUN: usize = 16;

fn domain(message: String) -> Error {
    Error::Domain { message }
}

/// Every stage's probe and event for one pair, the pair checked first.
///
/// # Examples
/// ```
/// use specfx::engine::pairs::eval_one;
/// let dp = specfx::input::load_datapath("baseline", None).unwrap();
/// let p = eval_one(&dp, dp.one_code(), 64).unwrap();
/// assert_eq!(p.values[dp.stage_out()], dp.constants_for(64).unwrap().coef_raw);
/// assert_eq!(
///     eval_one(&dp, 0, 7).unwrap_err().to_string(),
///     "n = 7 is not in the configuration's exponent set 16..=1024"
/// );
/// ```
pub fn eval_one(dp: &Datapath, c_raw: i64, n: u32) -> Result<Probes, Error> {
    let nc = dp.constants_checked(n, "n")?;
    dp.check_code(c_raw, "c")?;
    Ok(dp.eval(c_raw, nc))
}

/// Checks every pair and returns the index into [`Datapath::constants`] of each n (empty for
/// [`Ns::One`], whose index is the second value).
fn check_pairs(dp: &Datapath, cs: &[i64], ns: Ns) -> Result<(Vec<u32>, u32), Error> {
    let codes = dp.input_codes();
    if let Some(i) = cs.iter().position(|c| !codes.contains(c)) {
        dp.check_code(cs[i], &format!("c[{i}]"))?;
    }
    let index = |n: u32, what: &str| -> Result<u32, Error> {
        dp.constants_checked(n, what)?;
        Ok(dp.config().n.values().binary_search(&n).unwrap_or(0) as u32)
    };
    match ns {
        Ns::One(n) => Ok((Vec::new(), index(n, "n")?)),
        Ns::Each(ns) => {
            if ns.len() != cs.len() {
                return Err(domain(format!(
                    "c has {} elements and n has {}: expected as many (or one n)",
                    cs.len(),
                    ns.len()
                )));
            }
            let values = dp.config().n.values();
            let mut idx = Vec::with_capacity(ns.len());
            for (i, &n) in ns.iter().enumerate() {
                match values.binary_search(&n) {
                    Ok(j) => idx.push(j as u32),
                    Err(_) => {
                        index(n, &format!("n[{i}]"))?;
                    }
                }
            }
            Ok((idx, 0))
        }
    }
}

/// The output code of every pair into `out` (as long as `cs`): the same codes as
/// [`Datapath::eval`], computed by the batch kernels. Nothing is written unless every pair is
/// in the datapath's domain.
///
/// # Examples
/// ```
/// use specfx::engine::pairs::{eval_outputs, Ns};
/// let dp = specfx::input::load_datapath("baseline", None).unwrap();
/// let cs: Vec<i64> = (30_000..=32_768).collect();
/// let mut out = vec![0; cs.len()];
/// eval_outputs(&dp, &cs, Ns::One(100), &mut out).unwrap();
/// let nc = dp.constants_for(100).unwrap();
/// assert_eq!(out[2_000], dp.eval(32_000, nc).values[dp.stage_out()]);
/// ```
pub fn eval_outputs(dp: &Datapath, cs: &[i64], ns: Ns, out: &mut [i64]) -> Result<(), Error> {
    if out.len() != cs.len() {
        return Err(domain(format!(
            "the output has {} elements and c has {}: expected as many",
            out.len(),
            cs.len()
        )));
    }
    let (idx, one) = check_pairs(dp, cs, ns)?;
    let constants = dp.constants();
    out.par_chunks_mut(PIECE)
        .zip(cs.par_chunks(PIECE))
        .enumerate()
        .for_each_init(OutputScratch::default, |scratch, (piece, (out, cs))| {
            let idx = (!idx.is_empty()).then(|| &idx[piece * PIECE..piece * PIECE + cs.len()]);
            let mut start = 0;
            while start < cs.len() {
                let (n_idx, end) = match idx {
                    None => (one, cs.len()),
                    Some(idx) => {
                        let n_idx = idx[start];
                        let len = idx[start..].iter().take_while(|&&j| j == n_idx).count();
                        (n_idx, start + len)
                    }
                };
                let nc = &constants[n_idx as usize];
                run(dp, nc, &cs[start..end], &mut out[start..end], scratch);
                start = end;
            }
        });
    Ok(())
}

/// The outputs of one run of codes with one n: short runs one by one, runs of consecutive
/// codes by [`Datapath::eval_outputs_range`], the others by [`Datapath::eval_outputs`].
fn run(dp: &Datapath, nc: &NConstants, cs: &[i64], out: &mut [i64], scratch: &mut OutputScratch) {
    if cs.len() < SHORT_RUN {
        for (o, &c) in out.iter_mut().zip(cs) {
            *o = dp.eval(c, nc).values[dp.stage_out()];
        }
        return;
    }
    for (out, cs) in out
        .chunks_mut(crate::engine::BATCH_CODES)
        .zip(cs.chunks(crate::engine::BATCH_CODES))
    {
        let first = cs[0];
        let consecutive = cs.iter().enumerate().all(|(i, &c)| c == first + i as i64);
        if consecutive {
            dp.eval_outputs_range(nc, first..first + cs.len() as i64, out, scratch);
        } else {
            dp.eval_outputs(nc, cs, out, scratch);
        }
    }
}

/// Every stage's probe and event of every pair, by [`Datapath::eval`] in parallel, in pair
/// order. Nothing is evaluated unless every pair is in the datapath's domain.
pub fn eval_probes(dp: &Datapath, cs: &[i64], ns: Ns) -> Result<Vec<Probes>, Error> {
    let (idx, one) = check_pairs(dp, cs, ns)?;
    let constants = dp.constants();
    Ok(cs
        .par_iter()
        .enumerate()
        .with_min_len(1024)
        .map(|(i, &c)| {
            let n_idx = if idx.is_empty() { one } else { idx[i] };
            dp.eval(c, &constants[n_idx as usize])
        })
        .collect())
}

/// An overflow event as one small integer, the same in every face: 0 none, 1 wrapped,
/// 2 saturated, 3 zeroed.
pub fn event_code(e: Event) -> u8 {
    match e {
        Event::None => 0,
        Event::Wrapped => 1,
        Event::Saturated => 2,
        Event::Zeroed => 3,
    }
}
