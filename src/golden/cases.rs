//! Which (n, c) inputs a vector set holds (corner cases, codes with a non-zero output, every
//! code, or seeded random draws) and in which order they are written.

use std::collections::BTreeSet;
use std::fmt;
use std::str::FromStr;

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::Serialize;

use crate::error::Error;
use crate::golden::switches::cut_switches;
use crate::golden::ties::{self, TieSearch};
use crate::pipeline::datapath::CutStructure;
use crate::pipeline::{Datapath, ProbeColumns};

/// The order the selected cases are written in.
///
/// # Examples
/// ```
/// use specfx::golden::cases::Order;
/// let o: Order = "sorted".parse().unwrap();
/// assert_eq!(o, Order::Sorted);
/// assert_eq!(Order::default().to_string(), "interleaved");
/// assert!("shuffled".parse::<Order>().is_err());
/// ```
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Order {
    /// A seeded random permutation of the cases (see [`order`]), so that n changes on most
    /// rows and the per-n constants' routing is exercised on every vector, not only where n
    /// changes.
    #[default]
    Interleaved,
    /// Sorted by n, then by input code.
    Sorted,
}

impl Order {
    /// Both orders.
    pub const ALL: [Order; 2] = [Order::Interleaved, Order::Sorted];

    /// The name on the command line and in the manifest.
    pub fn name(self) -> &'static str {
        match self {
            Order::Interleaved => "interleaved",
            Order::Sorted => "sorted",
        }
    }
}

crate::names::named_enum!(Order, "vector order", "interleaved or sorted");

/// The ChaCha8 stream of the interleaving permutation: the random cases are drawn from stream
/// 0 of the same seed, so the permutation never changes which cases are drawn.
pub const ORDER_STREAM: u64 = 1;

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
    /// Corner cases: c = 0, 1.0, codes above 1.0, the ends of the code range and every
    /// cutoff switch +-1 code, for every n. They are always included, as are up to
    /// [`LIVE_CODES`] codes with a non-zero output per n ([`live_codes`]) and the inputs on
    /// and next to every stage's rounding boundary ([`ties::search`]); naming them is
    /// optional.
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
                    sel.random = sel
                        .random
                        .checked_add(count)
                        .filter(|&r| r <= MAX_CASES)
                        .ok_or_else(|| Error::OutOfRange {
                            what: "the number of random vectors",
                            expected: format!("at most {MAX_CASES} in all"),
                            got: s.to_string(),
                        })?;
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

/// The most (n, c) cases a selection may hold.
pub const MAX_CASES: u64 = 1 << 26;

/// The corner codes of one n, and whether they hold every cutoff switch.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Corners {
    /// The codes, ascending.
    pub codes: BTreeSet<i64>,
    /// The cutoff's switches found ([`crate::golden::switches::Switches::codes`]).
    pub switches: u64,
    /// Whether those are every switch of the n (see [`cut_switches`]).
    pub complete: bool,
}

/// The corner codes of one n: the ends of the code range, 0, 1.0 and its neighbours, and
/// every place where the cutoff switches between two consecutive codes, +-1 code.
///
/// The switching points cost what they are, and no scan of every code up to 1.0 is needed:
/// none without a cutoff, one bisection where the cut codes are proven to be a prefix
/// ([`Datapath::first_live_code`]), and behind a wrapping or zeroing t one bisection per
/// boundary of t (see [`crate::golden::switches`]); only when t has more than
/// [`crate::golden::switches::MAX_BISECTIONS`] boundaries in the n's range of products are the switches
/// scanned (up to [`crate::golden::switches::MAX_SCAN_CODES`] codes) or, beyond that, sampled
/// ([`Corners::complete`] is then false).
pub fn corner_codes(dp: &Datapath, n: u32) -> Corners {
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
        return Corners {
            codes: set,
            switches: 0,
            complete: true,
        };
    };
    let found = cut_switches(dp, nc, lo, hi.min(one));
    for &c in &found.codes {
        for x in [c - 2, c - 1, c, c + 1] {
            add(&mut set, x);
        }
    }
    Corners {
        codes: set,
        switches: found.codes.len() as u64,
        complete: found.complete,
    }
}

/// The most codes [`live_codes`] scans per exponent, down from 1.0, when its candidates hold
/// fewer than [`LIVE_CODES`] non-zero outputs.
pub const MAX_LIVE_SCAN: u64 = 1 << 16;

/// How many codes with a non-zero output [`live_codes`] keeps per exponent.
pub const LIVE_CODES: usize = 4;

/// The evenly spaced candidate codes [`live_codes`] evaluates first.
const LIVE_CANDIDATES: i64 = 64;

/// The codes just below 1.0 (1.0 included) [`live_codes`] always evaluates.
const LIVE_NEAR_ONE: i64 = 16;

/// Codes per batch of the scan of [`live_codes`].
const LIVE_CHUNK: i64 = 4096;

/// Up to [`LIVE_CODES`] input codes of one n whose datapath output is non-zero, spread over
/// the codes found: the smallest, the largest and two between (in the order of the codes
/// found). Empty when the search finds none.
///
/// The search looks at codes from `start` to `top = min(1.0, max code)` (codes above 1.0 are
/// clamped to 1.0 and give its output), where `start` is the first live code where the cut
/// codes are proven to be a prefix ([`Datapath::first_live_code`]: every code below it is cut
/// and gives 0) and the smallest input code otherwise:
///
/// 1. it evaluates 64 evenly spaced codes from `start` to `top` and the 16 codes up to and
///    including `top`;
/// 2. when fewer than [`LIVE_CODES`] of them give a non-zero output, it scans every code down
///    from `top` in batches of 4096 until it holds [`LIVE_CODES`] non-zero codes, reaches
///    `start`, or has scanned [`MAX_LIVE_SCAN`] codes.
///
/// So where `start..=top` holds at most [`MAX_LIVE_SCAN`] codes (every unsigned input format
/// with at most 15 fraction bits, such as baseline's `u1.15`, and wider ones where the cut
/// prefix leaves that few), the result holds `min(4, the number of codes with a non-zero
/// output)` codes: none only when every input code gives 0. Elsewhere it relies on the
/// candidates and the scan near 1.0. The result does not depend on any seed.
///
/// # Examples
/// ```
/// use specfx::golden::cases::live_codes;
/// use specfx::pipeline::{Config, Datapath, ProbeColumns};
/// let dp = Datapath::new(Config::baseline()).unwrap();
/// let nc = dp.constants_for(1024).unwrap();
/// let live = live_codes(&dp, 1024, &mut ProbeColumns::default());
/// assert_eq!(live.len(), 4);
/// assert!(live.iter().all(|&c| dp.eval(c, nc).values[dp.stage_out()] != 0));
/// assert_eq!(*live.last().unwrap(), dp.one_code());
/// ```
pub fn live_codes(dp: &Datapath, n: u32, cols: &mut ProbeColumns) -> Vec<i64> {
    let Some(nc) = dp.constants_for(n) else {
        return Vec::new();
    };
    let codes = dp.input_codes();
    let (lo, hi) = (*codes.start(), *codes.end());
    let top = hi.min(dp.one_code());
    let start = match dp.cut_structure() {
        CutStructure::Prefix => dp.first_live_code(nc, lo..top + 1),
        CutStructure::Never | CutStructure::Scan => lo,
    };
    if start > top {
        return Vec::new();
    }
    let out_idx = dp.stage_out();
    let mut found = BTreeSet::new();
    let mut look = |codes: &[i64], found: &mut BTreeSet<i64>| {
        dp.eval_batch(nc, codes, cols);
        let out = &cols.values[out_idx];
        found.extend(
            codes
                .iter()
                .zip(out)
                .filter(|&(_, &o)| o != 0)
                .map(|(&c, _)| c),
        );
    };
    let span = i128::from(top) - i128::from(start);
    let mut candidates = BTreeSet::new();
    for i in 0..LIVE_CANDIDATES {
        let c = i128::from(start) + span * i128::from(i) / i128::from(LIVE_CANDIDATES - 1);
        candidates.insert(i64::try_from(c).expect("between two codes"));
    }
    for j in 0..LIVE_NEAR_ONE {
        if i128::from(top) - i128::from(j) >= i128::from(start) {
            candidates.insert(top - j);
        }
    }
    let candidates: Vec<i64> = candidates.into_iter().collect();
    look(&candidates, &mut found);
    let mut scanned = 0u64;
    let mut end = top;
    while found.len() < LIVE_CODES && scanned < MAX_LIVE_SCAN {
        let room = i128::from((MAX_LIVE_SCAN - scanned).min(LIVE_CHUNK as u64));
        let begin = (i128::from(end) - room + 1).max(i128::from(start));
        let begin = i64::try_from(begin).expect("between two codes");
        let chunk: Vec<i64> = (begin..=end).collect();
        look(&chunk, &mut found);
        scanned += chunk.len() as u64;
        if begin == start {
            break;
        }
        end = begin - 1;
    }
    spread(&found.into_iter().collect::<Vec<_>>())
}

/// Up to [`LIVE_CODES`] of the sorted `codes`: the first, the last and two between.
fn spread(codes: &[i64]) -> Vec<i64> {
    if codes.len() <= LIVE_CODES {
        return codes.to_vec();
    }
    let last = codes.len() - 1;
    vec![codes[0], codes[last / 3], codes[2 * last / 3], codes[last]]
}

/// Puts cases in the given order. [`Order::Sorted`] sorts them by n, then code.
/// [`Order::Interleaved`] sorts them, then applies a Fisher-Yates shuffle driven by ChaCha8
/// seeded with `seed` on stream [`ORDER_STREAM`] (the random cases use stream 0): for `i` from
/// the last index down to 1, swap element `i` with element `j`, `j` drawn uniformly from
/// `0..=i` (as a `u64`). The result depends only on the set of cases and the seed, the same on
/// every machine.
///
/// # Examples
/// ```
/// use specfx::golden::cases::{order, Order};
/// let sorted: Vec<(u32, i64)> = (0..40).map(|i| (16 + (i % 4) as u32, i / 4)).collect();
/// let mut a = sorted.clone();
/// order(&mut a, Order::Interleaved, 7);
/// assert_ne!(a, sorted);
/// let mut b = a.clone();
/// b.sort();
/// order(&mut a, Order::Sorted, 7);
/// assert_eq!(a, b);
/// ```
pub fn order(cases: &mut [(u32, i64)], order: Order, seed: u64) {
    cases.sort_unstable();
    if order == Order::Sorted {
        return;
    }
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    rng.set_stream(ORDER_STREAM);
    for i in (1..cases.len()).rev() {
        let j = rng.gen_range(0..=i as u64) as usize;
        cases.swap(i, j);
    }
}

/// The directed cases `specfx vectors` always writes (every n's corner cases, codes with a
/// non-zero output, the inputs on and next to every stage's rounding boundary), interleaved
/// with `seed`: what the C, DPI and Python faces hand a testbench.
///
/// # Examples
/// ```
/// let dp = specfx::load_datapath("baseline", None).unwrap();
/// let cases = specfx::golden::cases::directed(&dp, 1).unwrap();
/// // Every exponent's 1.0 is a corner case.
/// assert!(cases.contains(&(16, dp.one_code())));
/// assert!(cases.contains(&(1024, dp.one_code())));
/// ```
///
/// # Errors
/// As [`select`].
pub fn directed(dp: &Datapath, seed: u64) -> Result<Vec<(u32, i64)>, Error> {
    let sel = CaseSelection {
        corner: true,
        exhaustive: false,
        random: 0,
    };
    let mut cases = select(dp, &sel, seed)?.cases;
    order(&mut cases, Order::Interleaved, seed);
    Ok(cases)
}

/// The directed cases of a selection: what the cutoff-switch analysis and the
/// rounding-boundary search found (the manifest's `coverage.directed`).
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct Directed {
    /// The cutoff's switches among the corner cases.
    pub cut_switches: CutSwitches,
    /// The inputs on and next to every rounding stage's boundary.
    pub ties: TieSearch,
}

/// The cutoff's switches over every n (see [`corner_codes`]).
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct CutSwitches {
    /// The switches found, over all n (each gives the corner cases c - 2..=c + 1).
    pub found: u64,
    /// Whether every switch of every n was found.
    pub complete: bool,
    /// The n whose switches were sampled rather than all found (empty when complete).
    pub n_sampled: Vec<u32>,
}

/// A selection's cases and, unless it is exhaustive, what its directed cases cover.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Selection {
    /// The (n, c_raw) pairs, sorted by n then c, without duplicates.
    pub cases: Vec<(u32, i64)>,
    /// The directed cases' report; `None` for an exhaustive selection (every input is a case).
    pub directed: Option<Directed>,
}

/// The (n, c_raw) pairs of a selection, sorted by n then c, without duplicates (put them in
/// the written order with [`order`]). Unless the selection is exhaustive, every n gets its
/// corner cases ([`corner_codes`]; `corner` only says so explicitly) and up to
/// [`LIVE_CODES`] codes with a non-zero output ([`live_codes`]), and the selection holds the
/// rounding-boundary inputs of every stage that rounds ([`ties::search`]). None of these
/// visits every code of a wide input: a random-only selection costs about the same on `u1.30`
/// as on `u1.15`.
///
/// Random pairs are drawn from ChaCha8 seeded with `seed`, uniformly over the n set and the
/// input codes, until `random` pairs not already selected have been added (or every pair is
/// selected). The same arguments give the same cases on every machine.
///
/// # Errors
/// When the selection would hold more than [`MAX_CASES`] cases.
pub fn select(dp: &Datapath, sel: &CaseSelection, seed: u64) -> Result<Selection, Error> {
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
    let too_many = |asked: u64| Error::OutOfRange {
        what: "the number of vectors",
        expected: format!("at most {MAX_CASES}"),
        got: format!(
            "{asked} ({} exponents x {per_n} input codes exhaustive, {} random)",
            ns.len(),
            sel.random
        ),
    };
    if asked > MAX_CASES {
        return Err(too_many(asked));
    }
    if sel.exhaustive {
        // Every pair: the random draws could add nothing.
        let mut all = Vec::with_capacity(usize::try_from(exhaustive).unwrap_or(0));
        for &n in ns {
            all.extend((lo..=hi).map(|c| (n, c)));
        }
        return Ok(Selection {
            cases: all,
            directed: None,
        });
    }
    let mut set: BTreeSet<(u32, i64)> = BTreeSet::new();
    // Corner cases, live codes and rounding ties are always included, whatever else is
    // selected.
    let mut cols = ProbeColumns::default();
    let mut cut = CutSwitches {
        found: 0,
        complete: true,
        n_sampled: Vec::new(),
    };
    for &n in ns {
        let corners = corner_codes(dp, n);
        cut.found += corners.switches;
        if !corners.complete {
            cut.complete = false;
            cut.n_sampled.push(n);
        }
        set.extend(corners.codes.into_iter().map(|c| (n, c)));
        set.extend(live_codes(dp, n, &mut cols).into_iter().map(|c| (n, c)));
    }
    let ties = ties::search(dp);
    set.extend(ties.cases);
    let directed = Directed {
        cut_switches: cut,
        ties: ties.report,
    };
    let wanted = set.len() as u64 + sel.random;
    if wanted > MAX_CASES {
        return Err(too_many(wanted));
    }
    if sel.random > 0 {
        let total = ns.len() as u128 * (i128::from(hi) - i128::from(lo) + 1) as u128;
        let wanted = (set.len() as u128 + u128::from(sel.random)).min(total);
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        while (set.len() as u128) < wanted {
            let n = ns[rng.gen_range(0..ns.len())];
            let c = rng.gen_range(lo..=hi);
            set.insert((n, c));
        }
    }
    Ok(Selection {
        cases: set.into_iter().collect(),
        directed: Some(directed),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pipeline::Config;

    fn datapath(toml: &str) -> Datapath {
        Datapath::new(Config::from_toml(toml).unwrap()).unwrap()
    }

    #[test]
    fn order_names_round_trip() {
        for o in Order::ALL {
            assert_eq!(o.to_string().parse::<Order>().unwrap(), o);
        }
        assert_eq!("SORTED".parse::<Order>().unwrap(), Order::Sorted);
        assert_eq!(
            "random".parse::<Order>().unwrap_err().to_string(),
            "unknown vector order 'random': expected interleaved or sorted"
        );
    }

    #[test]
    fn spread_keeps_the_ends_and_two_between() {
        // Ten codes: indexes 0, 9/3 = 3, 18/3 = 6 and 9.
        let codes: Vec<i64> = (100..110).collect();
        assert_eq!(spread(&codes), [100, 103, 106, 109]);
        assert_eq!(spread(&[5, 7, 9]), [5, 7, 9]);
        assert_eq!(spread(&[1, 2, 3, 4, 5]), [1, 2, 3, 5]);
        assert!(spread(&[]).is_empty());
    }

    #[test]
    fn order_is_a_seeded_permutation() {
        let sorted: Vec<(u32, i64)> = (0..500).map(|i| (1 + (i % 7) as u32, i / 7)).collect();
        let mut sorted_copy = sorted.clone();
        sorted_copy.sort_unstable();
        let mut by_order = sorted.clone();
        by_order.reverse();
        order(&mut by_order, Order::Sorted, 3);
        assert_eq!(by_order, sorted_copy);
        let shuffle = |seed: u64, start: &[(u32, i64)]| {
            let mut v = start.to_vec();
            order(&mut v, Order::Interleaved, seed);
            v
        };
        let a = shuffle(3, &sorted);
        // The input's order does not matter, only its set and the seed.
        assert_eq!(
            shuffle(3, &by_order.iter().rev().copied().collect::<Vec<_>>()),
            a
        );
        assert_ne!(a, sorted_copy);
        assert_ne!(shuffle(4, &sorted), a);
        let mut back = a.clone();
        back.sort_unstable();
        assert_eq!(back, sorted_copy);
    }

    #[test]
    fn the_permutation_is_not_the_random_draws_stream() {
        // Stream 0 of the seed draws the random cases; the permutation uses stream 1, so its
        // first draw differs from the first draw of stream 0.
        let mut s0 = ChaCha8Rng::seed_from_u64(9);
        let mut s1 = ChaCha8Rng::seed_from_u64(9);
        s1.set_stream(ORDER_STREAM);
        assert_ne!(s0.r#gen::<u64>(), s1.r#gen::<u64>());
    }

    #[test]
    fn live_codes_equal_a_brute_force_search_on_narrow_inputs() {
        // u1.10: every code up to 1.0 is within the scan limit, so the search is complete.
        for toml in [
            "n = \"1,2,300,1500\"\n[c]\nformat = \"u1.10\"\n[d]\nformat = \"s1.10\"\n[coef]\nformat = \"u9.8\"\n[out]\nformat = \"u4.-1\"\n",
            "n = \"8,100\"\n[c]\nformat = \"u1.9\"\n[d]\nformat = \"s1.9\"\n[t]\nformat = \"s3.8\"\noverflow = \"WRAP\"\n",
            "cutoff = \"paper\"\nn = \"40,1000\"\n",
        ] {
            let dp = datapath(toml);
            let mut cols = ProbeColumns::default();
            for nc in dp.constants() {
                let live: Vec<i64> = (*dp.input_codes().start()..=dp.one_code())
                    .filter(|&c| dp.eval(c, nc).values[dp.stage_out()] != 0)
                    .collect();
                let got = live_codes(&dp, nc.n, &mut cols);
                assert_eq!(got.len(), live.len().min(LIVE_CODES), "{toml} n = {}", nc.n);
                assert!(got.iter().all(|c| live.contains(c)), "{toml} n = {}", nc.n);
                assert!(got.windows(2).all(|w| w[0] < w[1]));
                if !live.is_empty() {
                    // 1.0 is always a candidate, and in these configurations its output is
                    // the largest non-zero code's.
                    assert_eq!(got.last(), live.last(), "{toml} n = {}", nc.n);
                }
            }
        }
    }

    #[test]
    fn exhaustive_selects_every_pair_in_order() {
        let dp = datapath("n = \"3,5\"\n[c]\nformat = \"u1.3\"\n[d]\nformat = \"s1.3\"\n");
        let sel: CaseSelection = "exhaustive,random:5".parse().unwrap();
        let got = select(&dp, &sel, 1).unwrap();
        assert!(got.directed.is_none());
        let got = got.cases;
        let want: Vec<(u32, i64)> = [3, 5]
            .into_iter()
            .flat_map(|n| (0..16).map(move |c| (n, c)))
            .collect();
        assert_eq!(got, want);
    }
}
