//! Which (n, c) inputs a vector set holds: corner cases, every code, or seeded random draws.

use std::collections::BTreeSet;
use std::fmt;
use std::str::FromStr;

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::Serialize;

use crate::error::Error;
use crate::pipeline::datapath::CutStructure;
use crate::pipeline::{Datapath, ProbeColumns};

/// A selection of cases, written `corner`, `exhaustive`, `random:N` or a comma list of them.
///
/// # Examples
/// ```
/// use specfx::golden::cases::CaseSelection;
/// let s: CaseSelection = "corner,random:100".parse().unwrap();
/// assert!(s.corner && !s.exhaustive);
/// assert_eq!(s.random, 100);
/// assert_eq!(s.to_string(), "corner,random:100");
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct CaseSelection {
    /// Corner cases: c = 0, 1.0, codes above 1.0, the ends of the code range and the cutoff
    /// boundary +-1 code, for every n. They are always included; naming them is optional.
    pub corner: bool,
    /// Every input code for every n.
    pub exhaustive: bool,
    /// This many distinct random (n, c) pairs, drawn with the seed.
    pub random: u64,
}

impl FromStr for CaseSelection {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self, Error> {
        let bad = |part: &str| Error::UnknownName {
            what: "case selection",
            expected: "corner, exhaustive or random:N, separated by commas",
            got: part.to_string(),
        };
        let mut sel = CaseSelection {
            corner: false,
            exhaustive: false,
            random: 0,
        };
        for part in s.split(',').map(str::trim) {
            match part {
                "corner" => sel.corner = true,
                "exhaustive" => sel.exhaustive = true,
                _ => {
                    let count = part
                        .strip_prefix("random:")
                        .and_then(|c| c.parse::<u64>().ok())
                        .filter(|&c| c > 0)
                        .ok_or_else(|| bad(part))?;
                    sel.random += count;
                }
            }
        }
        Ok(sel)
    }
}

impl fmt::Display for CaseSelection {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let mut parts = Vec::new();
        if self.corner {
            parts.push("corner".to_string());
        }
        if self.exhaustive {
            parts.push("exhaustive".to_string());
        }
        if self.random > 0 {
            parts.push(format!("random:{}", self.random));
        }
        f.write_str(&parts.join(","))
    }
}

/// The most cutoff evaluations a corner-case scan may take per exponent, where the cut codes
/// are not proven to be a prefix and every code up to 1.0 must be looked at.
pub const MAX_SCAN_CODES: u64 = 1 << 22;

/// The most (n, c) cases a selection may hold.
pub const MAX_CASES: u64 = 1 << 26;

/// The corner codes of one n: the ends of the code range, 0, 1.0 and its neighbours, and
/// every place where the cutoff switches between two consecutive codes, +-1 code.
///
/// The switching points cost what they are: none without a cutoff, one bisection where the
/// cut codes are proven to be a prefix ([`Datapath::first_live_code`]); only a clamp behind a
/// wrapping or zeroing t scans every code up to 1.0, at most [`MAX_SCAN_CODES`] of them.
///
/// # Errors
/// When a scan would take more than [`MAX_SCAN_CODES`] evaluations.
pub fn corner_codes(
    dp: &Datapath,
    n: u32,
    cols: &mut ProbeColumns,
) -> Result<BTreeSet<i64>, Error> {
    let codes = dp.input_codes();
    let (lo, hi) = (*codes.start(), *codes.end());
    let one = dp.one_code();
    let mut set = BTreeSet::new();
    let add = |set: &mut BTreeSet<i64>, c: i64| {
        if (lo..=hi).contains(&c) {
            set.insert(c);
        }
    };
    for c in [lo, lo + 1, 0, 1, one - 1, one, one + 1, hi - 1, hi] {
        add(&mut set, c);
    }
    let Some(nc) = dp.constants_for(n) else {
        return Ok(set);
    };
    let last = hi.min(one);
    match dp.cut_structure() {
        CutStructure::Never => {}
        CutStructure::Prefix => {
            let live = dp.first_live_code(nc, lo..last + 1);
            if live > lo && live <= last {
                for x in [live - 2, live - 1, live, live + 1] {
                    add(&mut set, x);
                }
            }
        }
        CutStructure::Scan => {
            let n_codes = (last - lo + 1).max(0) as u64;
            if n_codes > MAX_SCAN_CODES {
                return Err(Error::OutOfRange {
                    what: "the corner-case scan",
                    expected: format!(
                        "at most {MAX_SCAN_CODES} codes up to 1.0 per n when t wraps or zeroes under the clamp cutoff (every code must be looked at)"
                    ),
                    got: format!("{n_codes} codes of c.format {}", dp.config().c.format),
                });
            }
            const CHUNK: i64 = 4096;
            let mut prev: Option<bool> = None;
            let mut start = lo;
            while start <= last {
                let end = (start + CHUNK - 1).min(last);
                let chunk: Vec<i64> = (start..=end).collect();
                dp.eval_batch(nc, &chunk, cols);
                for (i, &cut) in cols.cut.iter().enumerate() {
                    if prev.is_some_and(|p| p != cut) {
                        let c = chunk[i];
                        for x in [c - 2, c - 1, c, c + 1] {
                            add(&mut set, x);
                        }
                    }
                    prev = Some(cut);
                }
                start = end + 1;
            }
        }
    }
    Ok(set)
}

/// The (n, c_raw) pairs of a selection, sorted by n then c, without duplicates. Corner cases
/// are always included (`corner` only says so explicitly).
///
/// Random pairs are drawn from ChaCha8 seeded with `seed`, uniformly over the n set and the
/// input codes, until `random` pairs not already selected have been added (or every pair is
/// selected). The same arguments give the same cases on every machine.
///
/// # Errors
/// When the selection would hold more than [`MAX_CASES`] cases, or a corner-case scan is too
/// long (see [`corner_codes`]).
pub fn select(dp: &Datapath, sel: &CaseSelection, seed: u64) -> Result<Vec<(u32, i64)>, Error> {
    let ns = dp.config().n.values();
    let codes = dp.input_codes();
    let (lo, hi) = (*codes.start(), *codes.end());
    let per_n = u64::try_from(i128::from(hi) - i128::from(lo) + 1).unwrap_or(u64::MAX);
    let exhaustive = if sel.exhaustive {
        per_n.saturating_mul(ns.len() as u64)
    } else {
        0
    };
    let asked = exhaustive.saturating_add(sel.random);
    if asked > MAX_CASES {
        return Err(Error::OutOfRange {
            what: "the number of vectors",
            expected: format!("at most {MAX_CASES}"),
            got: format!(
                "{asked} ({} exponents x {per_n} input codes exhaustive, {} random)",
                ns.len(),
                sel.random
            ),
        });
    }
    let mut set: BTreeSet<(u32, i64)> = BTreeSet::new();
    if sel.exhaustive {
        for &n in ns {
            set.extend((lo..=hi).map(|c| (n, c)));
        }
    } else {
        // Corner cases are always included, whatever else is selected.
        let mut cols = ProbeColumns::default();
        for &n in ns {
            set.extend(corner_codes(dp, n, &mut cols)?.into_iter().map(|c| (n, c)));
        }
    }
    if sel.random > 0 {
        let total = ns.len() as u128 * (hi - lo + 1) as u128;
        let wanted = (set.len() as u128 + u128::from(sel.random)).min(total);
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        while (set.len() as u128) < wanted {
            let n = ns[rng.gen_range(0..ns.len())];
            let c = rng.gen_range(lo..=hi);
            set.insert((n, c));
        }
    }
    Ok(set.into_iter().collect())
}
