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

/// The index into [`Datapath::constants`] of every exponent, as a table (n is at most 65535:
/// `nset` refuses more).
struct NIndex {
    /// `table[n]`: the index of n, or `u32::MAX` when n is not in the set.
    table: Vec<u32>,
}

impl NIndex {
    fn new(dp: &Datapath) -> NIndex {
        let values = dp.config().n.values();
        let max = values.last().copied().unwrap_or(0);
        let mut table = vec![u32::MAX; max as usize + 1];
        for (i, &n) in values.iter().enumerate() {
            table[n as usize] = i as u32;
        }
        NIndex { table }
    }

    #[inline]
    fn of(&self, n: u32) -> Option<usize> {
        match self.table.get(n as usize) {
            Some(&i) if i != u32::MAX => Some(i as usize),
            _ => None,
        }
    }
}

/// The index of the first element where `bad` holds, scanning pieces in parallel (each a
/// plain loop).
fn first_where<T: Sync>(xs: &[T], bad: impl Fn(&T) -> bool + Sync) -> Option<usize> {
    xs.par_chunks(PIECE)
        .enumerate()
        .filter_map(|(k, piece)| piece.iter().position(&bad).map(|i| k * PIECE + i))
        .min()
}

/// Checks every pair (in parallel): the first code outside the input format, else the first
/// n outside the set, is the error.
fn check_pairs(dp: &Datapath, index: &NIndex, cs: &[i64], ns: Ns) -> Result<(), Error> {
    let codes = dp.input_codes();
    let (lo, hi) = (*codes.start(), *codes.end());
    if let Some(i) = first_where(cs, |&c| c < lo || c > hi) {
        dp.check_code(cs[i], &format!("c[{i}]"))?;
    }
    match ns {
        Ns::One(n) => {
            dp.constants_checked(n, "n")?;
        }
        Ns::Each(ns) => {
            if ns.len() != cs.len() {
                return Err(domain(format!(
                    "c has {} elements and n has {}: expected as many (or one n)",
                    cs.len(),
                    ns.len()
                )));
            }
            if let Some(i) = first_where(ns, |&n| index.of(n).is_none()) {
                dp.constants_checked(ns[i], &format!("n[{i}]"))?;
            }
        }
    }
    Ok(())
}

/// Checks every pair against the datapath's domain, in parallel, with the error the
/// evaluations name (the first code outside the input format, else the lengths or the first n
/// outside the set): for a face that checks a large batch whole before evaluating it piece by
/// piece.
///
/// # Examples
/// ```
/// use specfx::engine::pairs::{check_domain, Ns};
/// let dp = specfx::input::load_datapath("baseline", None).unwrap();
/// assert!(check_domain(&dp, &[0, 32768], Ns::One(16)).is_ok());
/// assert_eq!(
///     check_domain(&dp, &[0, 1], Ns::Each(&[16, 3])).unwrap_err().to_string(),
///     "n[1] = 3 is not in the configuration's exponent set 16..=1024"
/// );
/// ```
pub fn check_domain(dp: &Datapath, cs: &[i64], ns: Ns) -> Result<(), Error> {
    check_pairs(dp, &NIndex::new(dp), cs, ns)
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
    let index = NIndex::new(dp);
    check_pairs(dp, &index, cs, ns)?;
    out.par_chunks_mut(PIECE)
        .zip(cs.par_chunks(PIECE))
        .enumerate()
        .for_each_init(OutputScratch::default, |scratch, (piece, (out, cs))| {
            eval_piece(dp, &index, piece, cs, ns, out, scratch, false);
        });
    Ok(())
}

/// The outputs of piece number `piece` (`cs`, into `out`) of a batch, by runs of one n; with
/// `check`, each run is checked first (its n once, its codes at their ends when they are
/// consecutive) and the piece stops at the first run outside the domain, returning false.
#[allow(clippy::too_many_arguments)]
fn eval_piece(
    dp: &Datapath,
    index: &NIndex,
    piece: usize,
    cs: &[i64],
    ns: Ns,
    out: &mut [i64],
    scratch: &mut OutputScratch,
    check: bool,
) -> bool {
    let constants = dp.constants();
    let codes = dp.input_codes();
    let (lo, hi) = (*codes.start(), *codes.end());
    let start_at = piece * PIECE;
    let mut start = 0;
    while start < cs.len() {
        let (n, end) = match ns {
            Ns::One(n) => (n, cs.len()),
            Ns::Each(ns) => {
                let ns = &ns[start_at..start_at + cs.len()];
                let n = ns[start];
                let len = ns[start..].iter().take_while(|&&m| m == n).count();
                (n, start + len)
            }
        };
        let Some(n_idx) = index.of(n) else {
            return false;
        };
        let run_cs = &cs[start..end];
        let first = run_cs[0];
        let consecutive = run_cs
            .iter()
            .enumerate()
            .all(|(i, &c)| c == first.wrapping_add(i as i64));
        if check {
            let last = run_cs[run_cs.len() - 1];
            let in_format = if consecutive {
                first >= lo && last <= hi && first <= last
            } else {
                run_cs.iter().all(|&c| c >= lo && c <= hi)
            };
            if !in_format {
                return false;
            }
        }
        run(
            dp,
            &constants[n_idx],
            run_cs,
            &mut out[start..end],
            scratch,
            consecutive,
        );
        start = end;
    }
    true
}

/// [`eval_outputs`] into a new vector: each piece is checked just before it is evaluated (one
/// pass over the inputs instead of two; a batch with an input outside the domain returns the
/// same error and no vector).
///
/// # Examples
/// ```
/// use specfx::engine::pairs::{eval_outputs_vec, Ns};
/// let dp = specfx::input::load_datapath("baseline", None).unwrap();
/// let out = eval_outputs_vec(&dp, &[32768, 0], Ns::Each(&[64, 16])).unwrap();
/// assert_eq!(out[0], dp.constants_for(64).unwrap().coef_raw);
/// assert!(eval_outputs_vec(&dp, &[0], Ns::One(7)).is_err());
/// ```
pub fn eval_outputs_vec(dp: &Datapath, cs: &[i64], ns: Ns) -> Result<Vec<i64>, Error> {
    let mut out = vec![0i64; cs.len()];
    eval_outputs_streaming(dp, cs, ns, &mut out)?;
    Ok(out)
}

/// [`eval_outputs`] in one pass: each piece is checked just before it is evaluated, so that
/// an error (the same one) may come after some outputs were written; `out`'s contents are
/// then unspecified (as with numpy's `out=`). For a caller that discards `out` on an error.
///
/// # Examples
/// ```
/// use specfx::engine::pairs::{eval_outputs_streaming, Ns};
/// let dp = specfx::input::load_datapath("baseline", None).unwrap();
/// let mut out = vec![0; 2];
/// eval_outputs_streaming(&dp, &[32768, 0], Ns::Each(&[64, 16]), &mut out).unwrap();
/// assert_eq!(out[0], dp.constants_for(64).unwrap().coef_raw);
/// let err = eval_outputs_streaming(&dp, &[0, 1 << 20], Ns::One(16), &mut out).unwrap_err();
/// assert!(err.to_string().starts_with("c[1] = 1048576 is not a code"));
/// ```
pub fn eval_outputs_streaming(
    dp: &Datapath,
    cs: &[i64],
    ns: Ns,
    out: &mut [i64],
) -> Result<(), Error> {
    if out.len() != cs.len() {
        return Err(domain(format!(
            "the output has {} elements and c has {}: expected as many",
            out.len(),
            cs.len()
        )));
    }
    let index = NIndex::new(dp);
    let length_ok = match ns {
        Ns::One(n) => index.of(n).is_some(),
        Ns::Each(ns) => ns.len() == cs.len(),
    };
    let all_in_domain = length_ok
        && out
            .par_chunks_mut(PIECE)
            .zip(cs.par_chunks(PIECE))
            .enumerate()
            .map_init(OutputScratch::default, |scratch, (piece, (out, cs))| {
                eval_piece(dp, &index, piece, cs, ns, out, scratch, true)
            })
            .reduce(|| true, |a, b| a && b);
    if !all_in_domain {
        // The error the two-pass check names (the first code, else the first n, outside).
        check_pairs(dp, &index, cs, ns)?;
    }
    Ok(())
}

/// The outputs of one run of codes with one n: short runs one by one, runs of consecutive
/// codes by [`Datapath::eval_outputs_range`], the others by [`Datapath::eval_outputs`].
fn run(
    dp: &Datapath,
    nc: &NConstants,
    cs: &[i64],
    out: &mut [i64],
    scratch: &mut OutputScratch,
    consecutive: bool,
) {
    if cs.len() < SHORT_RUN {
        for (o, &c) in out.iter_mut().zip(cs) {
            *o = dp.eval(c, nc).values[dp.stage_out()];
        }
    } else if consecutive && cs[cs.len() - 1] < i64::MAX {
        // One bisection finds the run's dead prefix; the live codes go through the kernels
        // (a run ending at i64::MAX, a u1.62 input's largest code, has no end to name).
        let first = cs[0];
        dp.eval_outputs_range(nc, first..first + cs.len() as i64, out, scratch);
    } else {
        for (out, cs) in out
            .chunks_mut(crate::engine::BATCH_CODES)
            .zip(cs.chunks(crate::engine::BATCH_CODES))
        {
            dp.eval_outputs(nc, cs, out, scratch);
        }
    }
}

/// Every stage's probe and event of every pair, by [`Datapath::eval`] in parallel, in pair
/// order. Nothing is evaluated unless every pair is in the datapath's domain.
pub fn eval_probes(dp: &Datapath, cs: &[i64], ns: Ns) -> Result<Vec<Probes>, Error> {
    let index = NIndex::new(dp);
    check_pairs(dp, &index, cs, ns)?;
    let constants = dp.constants();
    Ok(cs
        .par_iter()
        .enumerate()
        .with_min_len(1024)
        .map(|(i, &c)| {
            let n = match ns {
                Ns::One(n) => n,
                Ns::Each(ns) => ns[i],
            };
            dp.eval(c, &constants[index.of(n).expect("checked above")])
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
