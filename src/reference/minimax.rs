//! Minimax constants A(n), B(n) for the lobe `max(0, A c + B)^m`, and their cached table.
//!
//! For each integer n and k (m = 2^k) the constants minimise the maximum of
//! `|max(0, A c + B)^m - c^n|` over c in [0, 1]. [`fit`] computes them; the table in
//! `data/minimax.csv` (n = 1..=4096, k = 1..=7) is its output, written by
//! `specfx minimax --write data/minimax.csv` and embedded in the library.
//!
//! How: write the lobe as `s ((c - c0)/(1 - c0))^m` (c0 = -B/A the zero of the base, s the
//! value at c = 1). For a fixed c0 the maximum error is a convex function of s, minimised
//! exactly by bisection on the balance of its upper and lower envelopes over a grid that is
//! dense near c = 1; the outer search over c0 scans `u0 = n (1 - c0) / m` log-uniformly over
//! [1/4, 8] and refines the best bracket by golden section. The reported error is then measured
//! on the continuous function (grid maxima refined by golden section), see [`max_abs_error`].

use std::sync::OnceLock;

use crate::error::Error;
use crate::reference::lobe::{affine_lobe, m_of_k, pow_2k};

/// The largest n in the cached table.
pub const TABLE_N_MAX: u32 = 4096;

/// The cached table, as text (`k,n,a,b,max_abs_err,plain_max_abs_err`).
const TABLE_CSV: &str = include_str!("../../data/minimax.csv");

/// The CSV header of the table.
pub const TABLE_HEADER: &str = "k,n,a,b,max_abs_err,plain_max_abs_err";

/// Minimax constants for one (n, k) and how good they are.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct MinimaxFit {
    /// The exponent approximated.
    pub n: u32,
    /// The number of squarings (m = 2^k).
    pub k: u32,
    /// The slope A (replaces n/m).
    pub a: f64,
    /// The offset B (replaces 1 - n/m).
    pub b: f64,
    /// max over c in [0, 1] of |max(0, A c + B)^m - c^n|.
    pub max_abs_err: f64,
    /// The same for the plain constants A = n/m, B = 1 - n/m (clamp cutoff), for comparison.
    pub plain_max_abs_err: f64,
}

impl MinimaxFit {
    /// The CSV fields of this fit, in [`TABLE_HEADER`] order, with shortest round-trip floats.
    pub fn csv_fields(&self) -> [String; 6] {
        [
            self.k.to_string(),
            self.n.to_string(),
            format!("{:e}", self.a),
            format!("{:e}", self.b),
            format!("{:e}", self.max_abs_err),
            format!("{:e}", self.plain_max_abs_err),
        ]
    }
}

/// The lower end of the search domain in c: every lobe considered is zero below it, and
/// c^n < e^-60 there.
fn domain_low(n: u32, k: u32) -> f64 {
    let width = (60.0 + 8.0 * f64::from(m_of_k(k))) / f64::from(n);
    (1.0 - width).max(0.0)
}

/// A grid on [lo, 1], quadratically dense towards c = 1 where the lobes live.
fn grid(lo: f64, n_points: usize) -> Vec<f64> {
    let span = 1.0 - lo;
    (0..=n_points)
        .map(|i| {
            let t = i as f64 / n_points as f64;
            1.0 - span * t * t
        })
        .collect()
}

/// max over c in [0, 1] of `|max(0, a c + b)^m - c^n|`, and the c where it is reached.
///
/// # Examples
/// ```
/// use specfx::reference::minimax::max_abs_error;
/// // With m = n = 16 the plain constants are exact: error 0.
/// let (err, _) = max_abs_error(16, 4, 1.0, 0.0);
/// assert_eq!(err, 0.0);
/// ```
pub fn max_abs_error(n: u32, k: u32, a: f64, b: f64) -> (f64, f64) {
    let mut lo = domain_low(n, k);
    if a > 0.0 {
        lo = lo.min((-b / a).max(0.0));
    } else {
        lo = 0.0;
    }
    sup_abs_error(n, lo, |c| affine_lobe(c, a, b, k))
}

/// max over c in [lo, 1] of `|g(c) - c^n|` and the c where it is reached, for a `g` that is
/// zero below `lo` (or whose error there does not matter).
///
/// Evaluated on 8193 points quadratically dense towards c = 1, then each of the four largest
/// local maxima is refined by golden section between its grid neighbours.
///
/// # Examples
/// ```
/// use specfx::reference::minimax::sup_abs_error;
/// // max over [0, 1] of c - c^2 is 1/4 at c = 1/2.
/// let (err, at) = sup_abs_error(2, 0.0, |c| c);
/// assert!((err - 0.25).abs() < 1e-15 && (at - 0.5).abs() < 1e-7);
/// ```
pub fn sup_abs_error(n: u32, lo: f64, g: impl Fn(f64) -> f64) -> (f64, f64) {
    let nf = n as i32;
    let err = |c: f64| (g(c) - c.powi(nf)).abs();
    let cs = grid(lo, 8192);
    let es: Vec<f64> = cs.iter().map(|&c| err(c)).collect();
    // Local maxima of the grid values (cs is decreasing in the index).
    let mut peaks: Vec<usize> = (0..es.len())
        .filter(|&i| {
            let left = if i > 0 { es[i - 1] } else { f64::NEG_INFINITY };
            let right = if i + 1 < es.len() {
                es[i + 1]
            } else {
                f64::NEG_INFINITY
            };
            es[i] >= left && es[i] >= right
        })
        .collect();
    peaks.sort_by(|&x, &y| es[y].total_cmp(&es[x]));
    peaks.truncate(4);
    let mut best = (0.0, 1.0);
    for i in peaks {
        let hi_c = if i > 0 { cs[i - 1] } else { cs[i] };
        let lo_c = if i + 1 < cs.len() { cs[i + 1] } else { cs[i] };
        let (c, e) = golden_max(&err, lo_c, hi_c);
        let (c, e) = if es[i] > e { (cs[i], es[i]) } else { (c, e) };
        if e > best.0 {
            best = (e, c);
        }
    }
    best
}

/// Maximises a unimodal `f` on [lo, hi] by golden section; returns (argmax, max).
fn golden_max(f: &impl Fn(f64) -> f64, mut lo: f64, mut hi: f64) -> (f64, f64) {
    const INV_PHI: f64 = 0.618_033_988_749_894_8;
    let mut x1 = hi - INV_PHI * (hi - lo);
    let mut x2 = lo + INV_PHI * (hi - lo);
    let mut f1 = f(x1);
    let mut f2 = f(x2);
    while hi - lo > 1e-15 {
        if f1 < f2 {
            lo = x1;
            x1 = x2;
            f1 = f2;
            x2 = lo + INV_PHI * (hi - lo);
            f2 = f(x2);
        } else {
            hi = x2;
            x2 = x1;
            f2 = f1;
            x1 = hi - INV_PHI * (hi - lo);
            f1 = f(x1);
        }
    }
    if f1 > f2 {
        (x1, f1)
    } else {
        (x2, f2)
    }
}

/// For a fixed zero c0, the value s at c = 1 minimising the grid maximum of
/// `|s p(c) - c^n|`, and that maximum.
fn best_scale(p: &[f64], f: &[f64]) -> (f64, f64) {
    let envelopes = |s: f64| {
        let mut up = f64::NEG_INFINITY;
        let mut down = f64::NEG_INFINITY;
        for (&pi, &fi) in p.iter().zip(f) {
            let e = s * pi - fi;
            up = up.max(e);
            down = down.max(-e);
        }
        (up, down)
    };
    // up(s) is non-decreasing and down(s) non-increasing: bisect on their balance.
    let (mut lo, mut hi) = (0.0f64, 4.0f64);
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        let (up, down) = envelopes(mid);
        if up < down {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let s = 0.5 * (lo + hi);
    let (up, down) = envelopes(s);
    (s, up.max(down))
}

/// Computes the minimax constants for one (n, k). Deterministic.
///
/// # Examples
/// ```
/// use specfx::reference::minimax::fit;
/// let f = fit(64, 4);
/// assert!(f.max_abs_err < f.plain_max_abs_err);
/// ```
pub fn fit(n: u32, k: u32) -> MinimaxFit {
    let m = f64::from(m_of_k(k));
    let nf = f64::from(n);
    let cs = grid(domain_low(n, k), 1536);
    let fs: Vec<f64> = cs.iter().map(|&c| c.powi(n as i32)).collect();
    let objective = |log_u0: f64| -> (f64, f64) {
        let c0 = 1.0 - log_u0.exp() * m / nf;
        let p: Vec<f64> = cs
            .iter()
            .map(|&c| pow_2k(((c - c0) / (1.0 - c0)).max(0.0), k))
            .collect();
        let (s, e) = best_scale(&p, &fs);
        (e, s)
    };
    const N_SCAN: usize = 32;
    let (lo_u, hi_u) = (0.25f64.ln(), 8f64.ln());
    let step = (hi_u - lo_u) / (N_SCAN - 1) as f64;
    let scan: Vec<f64> = (0..N_SCAN)
        .map(|i| objective(lo_u + step * i as f64).0)
        .collect();
    let best_i = (0..N_SCAN)
        .min_by(|&x, &y| scan[x].total_cmp(&scan[y]))
        .expect("non-empty scan");
    let mut lo = lo_u + step * best_i.saturating_sub(1) as f64;
    let mut hi = lo_u + step * (best_i + 1).min(N_SCAN - 1) as f64;
    // Golden-section minimisation of the grid error over log u0.
    const INV_PHI: f64 = 0.618_033_988_749_894_8;
    let mut x1 = hi - INV_PHI * (hi - lo);
    let mut x2 = lo + INV_PHI * (hi - lo);
    let mut f1 = objective(x1).0;
    let mut f2 = objective(x2).0;
    for _ in 0..48 {
        if f1 < f2 {
            hi = x2;
            x2 = x1;
            f2 = f1;
            x1 = hi - INV_PHI * (hi - lo);
            f1 = objective(x1).0;
        } else {
            lo = x1;
            x1 = x2;
            f1 = f2;
            x2 = lo + INV_PHI * (hi - lo);
            f2 = objective(x2).0;
        }
    }
    let log_u0 = 0.5 * (lo + hi);
    let (_, s) = objective(log_u0);
    let c0 = 1.0 - log_u0.exp() * m / nf;
    let a = s.powf(1.0 / m) / (1.0 - c0);
    let b = -a * c0;
    let (max_abs_err, _) = max_abs_error(n, k, a, b);
    let (plain_max_abs_err, _) = max_abs_error(n, k, nf / m, 1.0 - nf / m);
    MinimaxFit {
        n,
        k,
        a,
        b,
        max_abs_err,
        plain_max_abs_err,
    }
}

/// The cached table, parsed once.
pub fn table() -> &'static [MinimaxFit] {
    static TABLE: OnceLock<Vec<MinimaxFit>> = OnceLock::new();
    TABLE.get_or_init(|| parse_table(TABLE_CSV).expect("data/minimax.csv is well formed"))
}

/// Parses the CSV text of a table (header [`TABLE_HEADER`]); an error names the line and the
/// column.
///
/// # Examples
/// ```
/// use specfx::reference::minimax::parse_table;
/// let t = parse_table("k,n,a,b,max_abs_err,plain_max_abs_err\n4,16,1.5,-0.5,1e-3,2e-3\n").unwrap();
/// assert_eq!((t[0].k, t[0].n, t[0].a), (4, 16, 1.5));
/// let e = parse_table("k,n,a,b,max_abs_err,plain_max_abs_err\n4,16,x,-0.5,1e-3,2e-3\n");
/// assert!(e.unwrap_err().to_string().contains("line 2 column 3"));
/// ```
pub fn parse_table(text: &str) -> Result<Vec<MinimaxFit>, crate::error::Error> {
    let fail = |problem: String| crate::error::Error::Config {
        key: "minimax table".into(),
        problem,
    };
    let mut reader = csv::ReaderBuilder::new()
        .has_headers(true)
        .from_reader(text.as_bytes());
    let header = reader
        .headers()
        .map_err(|e| fail(format!("line 1: {e}")))?
        .iter()
        .collect::<Vec<_>>()
        .join(",");
    if header != TABLE_HEADER {
        return Err(fail(format!(
            "line 1: expected header '{TABLE_HEADER}', got '{header}'"
        )));
    }
    let mut fits = Vec::new();
    for record in reader.records() {
        let record = record.map_err(|e| {
            let line = e.position().map_or(0, |p| p.line());
            match e.kind() {
                csv::ErrorKind::UnequalLengths { len, .. } => fail(format!(
                    "line {line}: expected 6 comma-separated numbers, got {len} fields"
                )),
                _ => fail(format!("line {line}: {e}")),
            }
        })?;
        let line = record.position().map_or(0, |p| p.line());
        let field = |j: usize| -> Result<&str, crate::error::Error> {
            record
                .get(j)
                .ok_or_else(|| fail(format!("line {line}: expected 6 fields")))
        };
        let bad = |j: usize, what: &str| {
            fail(format!(
                "line {line} column {}: expected {what}, got '{}'",
                j + 1,
                record.get(j).unwrap_or("")
            ))
        };
        let int = |j: usize| field(j)?.parse::<u32>().map_err(|_| bad(j, "an integer"));
        let float = |j: usize| field(j)?.parse::<f64>().map_err(|_| bad(j, "a number"));
        fits.push(MinimaxFit {
            k: int(0)?,
            n: int(1)?,
            a: float(2)?,
            b: float(3)?,
            max_abs_err: float(4)?,
            plain_max_abs_err: float(5)?,
        });
    }
    Ok(fits)
}

/// The cached minimax constants for (n, k).
///
/// # Examples
/// ```
/// use specfx::reference::minimax::constants;
/// let fit = constants(128, 4).unwrap();
/// assert!(fit.max_abs_err < 0.5 * fit.plain_max_abs_err);
/// assert!(constants(5000, 4).is_err());
/// ```
pub fn constants(n: u32, k: u32) -> Result<MinimaxFit, Error> {
    let t = table();
    if !(1..=TABLE_N_MAX).contains(&n) || !crate::reference::lobe::K_RANGE.contains(&k) {
        return Err(Error::NoMinimaxEntry {
            n,
            k,
            n_max: TABLE_N_MAX,
            k_max: crate::reference::lobe::K_MAX,
        });
    }
    let idx = (k - 1) as usize * TABLE_N_MAX as usize + (n - 1) as usize;
    t.get(idx)
        .copied()
        .filter(|f| f.n == n && f.k == k)
        .ok_or(Error::NoMinimaxEntry {
            n,
            k,
            n_max: TABLE_N_MAX,
            k_max: crate::reference::lobe::K_MAX,
        })
}

/// The best squaring depth of `n` up to `k` (`depth = "best"`, `docs/arithmetic.md` 3.1.0):
/// the j in 1..=k whose table floor is smallest (`max_abs_err` for minimax, `plain_max_abs_err`
/// for the plain slope n / 2^j), ties going to the smaller j; None outside the table.
///
/// # Examples
/// ```
/// use specfx::reference::minimax::best_depth;
/// // Minimax: m = 16 up to n = 21, 32 up to 42, 64 up to 85, then 128.
/// assert_eq!([21, 22, 42, 43, 85, 86].map(|n| best_depth(n, 7, false)), [4, 5, 5, 6, 6, 7].map(Some));
/// assert_eq!(best_depth(1024, 5, false), Some(5));
/// assert_eq!(best_depth(5000, 5, false), None);
/// ```
pub fn best_depth(n: u32, k: u32, plain: bool) -> Option<u32> {
    // Computed once for every (variant, k, n) of the table: eval-time callers look it up.
    static BEST: std::sync::OnceLock<Vec<u8>> = std::sync::OnceLock::new();
    let kmax = *crate::reference::lobe::K_RANGE.end();
    if !(1..=TABLE_N_MAX).contains(&n) || !crate::reference::lobe::K_RANGE.contains(&k) {
        return None;
    }
    let best = BEST.get_or_init(|| {
        let mut v = Vec::with_capacity(2 * kmax as usize * TABLE_N_MAX as usize);
        for plain in [false, true] {
            for k in 1..=kmax {
                for n in 1..=TABLE_N_MAX {
                    v.push(best_depth_uncached(n, k, plain).map_or(0, |j| j as u8));
                }
            }
        }
        v
    });
    let idx = (usize::from(plain) * kmax as usize + (k - 1) as usize) * TABLE_N_MAX as usize
        + (n - 1) as usize;
    best.get(idx).copied().filter(|&j| j > 0).map(u32::from)
}

/// [`best_depth`] from the table's floors.
fn best_depth_uncached(n: u32, k: u32, plain: bool) -> Option<u32> {
    let mut best = (k, f64::INFINITY);
    for j in 1..=k {
        let f = constants(n, j).ok()?;
        let e = if plain {
            f.plain_max_abs_err
        } else {
            f.max_abs_err
        };
        if e < best.1 {
            best = (j, e);
        }
    }
    Some(best.0)
}

/// The minimax lobe `max(0, A(n) c + B(n))^m` with the cached constants.
pub fn minimax_lobe(c: f64, n: u32, k: u32) -> Result<f64, Error> {
    let f = constants(n, k)?;
    Ok(affine_lobe(c, f.a, f.b, k))
}
