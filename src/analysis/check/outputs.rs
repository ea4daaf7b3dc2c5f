//! The outputs-only judge: the output figures of an exhaustive check ([`check_outputs`])
//! without the per-stage statistics, the dead prefix of each n never evaluated, and the cache
//! of `cos^n` and of figures the optimiser's candidates share ([`CosCache`]).

use super::codes::{
    code_columns, cos_n_of, dead_prefix_end, f64_floor, f64_lobe_at, floor_over, reference_base,
    zero_run_end, CodeColumns, CHUNK,
};
use super::report::OutputFigures;
use crate::engine::map_n;
use crate::error::Error;
use crate::pipeline::{first_code_where, Datapath, NConstants, OutputScratch};
use crate::reference::normalisation::classic_coefficient;

/// What one exponent contributes to [`OutputFigures`].
struct OutputsOfN {
    quant: f64,
    approx: f64,
    total: f64,
    out_max_abs: f64,
    norm: f64,
    norm_rel: f64,
    norm_approx: f64,
    n_correct: u64,
    n_violations: u64,
}

impl OutputsOfN {
    /// Nothing seen yet: every maximum -1 (below any error), `n_correct` codes counted
    /// correctly rounded.
    fn empty(n_correct: u64) -> OutputsOfN {
        OutputsOfN {
            quant: -1.0,
            approx: -1.0,
            total: -1.0,
            out_max_abs: -1.0,
            norm: -1.0,
            norm_rel: -1.0,
            norm_approx: -1.0,
            n_correct,
            n_violations: 0,
        }
    }

    /// Takes in another exponent's figures.
    fn merge(&mut self, p: &OutputsOfN) {
        self.norm = self.norm.max(p.norm);
        self.norm_rel = self.norm_rel.max(p.norm_rel);
        self.norm_approx = self.norm_approx.max(p.norm_approx);
        self.quant = self.quant.max(p.quant);
        self.approx = self.approx.max(p.approx);
        self.total = self.total.max(p.total);
        self.out_max_abs = self.out_max_abs.max(p.out_max_abs);
        self.n_correct += p.n_correct;
        self.n_violations += p.n_violations;
    }
}

/// The output figures of one exponent: the dead prefix (cut in both models, see
/// [`dead_prefix_end`]) counts as exact, without evaluation; every later code is evaluated and
/// compared with the f64 walk, exactly as [`check_one_n`] compares them.
fn outputs_one_n(
    dp: &Datapath,
    nc: &NConstants,
    shared: &CodeColumns,
    cache: Option<&CosCache>,
    dead_end: i64,
    tabulate: bool,
) -> OutputsOfN {
    let cfg = dp.config();
    let codes = &shared.codes.codes[..];
    let (lo, last) = (codes[0], codes[codes.len() - 1]);
    let lobe_lsb = dp.stages()[dp.stage_last_square()].format.lsb();
    let out_lsb = cfg.out.format.lsb();
    let half = 0.5 * out_lsb * (1.0 + 1e-9);
    let c_lsb = cfg.c.format.lsb();
    let nf = f64::from(nc.n);
    let threshold = nc.threshold.unwrap_or(i64::MIN);
    let one = dp.one_code();
    let cos_direct = |i: usize| cos_n_of(codes[i], c_lsb, nf, shared.codes.ln_c[i]);
    let n_dead = (dead_end - lo) as usize;
    let row = cache.and_then(|c| {
        c.row(nc.n, n_dead, || {
            (n_dead..codes.len()).map(cos_direct).collect()
        })
    });
    let cos_n = |i: usize| match &row {
        Some(r) if i >= r.start => r.values[i - r.start],
        _ => cos_direct(i),
    };
    let mut r = OutputsOfN::empty(n_dead as u64);
    let norm_peak = classic_coefficient(cfg.coef.form, nf);
    if n_dead > 0 {
        // Every dead output and lobe is 0 in both models; cos^n grows with c, so the largest
        // dead code bounds the others' shape errors.
        let cn = cos_n(n_dead - 1);
        r.quant = 0.0;
        r.approx = cn;
        r.total = cn;
        r.out_max_abs = 0.0;
        r.norm = norm_peak * cn;
        r.norm_approx = norm_peak * cn;
    }
    let f64_lobe = |i: usize| f64_lobe_at(dp, nc, shared, i);
    let n_zero = zero_run_end(dp, nc, codes, n_dead, &f64_lobe);
    if n_zero > n_dead {
        // Every fixed-point lobe and output of the run is 0, and the f64 lobe s, its output
        // s coef and cos^n grow with c: each error against 0 is largest at the run's last
        // code, and the correctly rounded outputs (s coef <= half) are a prefix of the run.
        // Only the f64 lobe's own error against cos^n is looked at code by code.
        let last_zero = n_zero - 1;
        let (s, cn) = (f64_lobe(last_zero), cos_n(last_zero));
        r.quant = r.quant.max(s);
        r.total = r.total.max(cn);
        r.out_max_abs = r.out_max_abs.max((s * nc.coef).abs());
        r.norm = r.norm.max((norm_peak * cn).abs());
        let correct_end = first_code_where(n_dead as i64..n_zero as i64, |i| {
            (-(f64_lobe(i as usize) * nc.coef)).abs() > half
        });
        r.n_correct += (correct_end - n_dead as i64) as u64;
        // The f64 lobe's error over every code (0 in the dead prefix, which the f64 model
        // cuts too) is the datapath's floor: a cache holds it across datapaths.
        let (approx, norm_approx) = match cache {
            Some(c) => {
                let key = (
                    nc.n,
                    nc.depth,
                    nc.slope.to_bits(),
                    nc.offset.to_bits(),
                    nc.coef.to_bits(),
                    threshold,
                    cfg.cutoff as u8,
                    cfg.coef.form as u8,
                );
                c.floor(key, || {
                    f64_floor(dp, nc, codes, norm_peak, &f64_lobe, &cos_n)
                })
            }
            None => floor_over(n_dead..n_zero, nc, norm_peak, &f64_lobe, &cos_n),
        };
        r.approx = r.approx.max(approx);
        r.norm_approx = r.norm_approx.max(norm_approx);
    }
    let mut prev_out = (n_zero > 0).then_some(0);
    // The live codes, a chunk at a time: only the lobe and the output are looked at, so the
    // chunk runs the outputs' path (the squaring chain looked up from b), not every probe.
    let mut scratch = OutputScratch::default();
    let mut outs = vec![0i64; CHUNK.min(codes.len())];
    let mut start = n_zero;
    while start < codes.len() {
        let end = (start + CHUNK).min(codes.len());
        let chunk = &codes[start..end];
        let o_chunk = &mut outs[..chunk.len()];
        if tabulate {
            dp.eval_outputs(nc, chunk, o_chunk, &mut scratch);
        } else {
            dp.eval_outputs_untabulated(nc, chunk, o_chunk, &mut scratch);
        }
        let lobes = scratch.lobes();
        for (j, &k) in chunk.iter().enumerate() {
            let i = start + j;
            let t = nc.slope * shared.ref_d[i];
            let mut s = reference_base(cfg.cutoff, t, nc.offset, k.min(one) < threshold);
            for _ in 0..nc.depth {
                s *= s;
            }
            let fixed_lobe = lobes[j] as f64 * lobe_lsb;
            let o = o_chunk[j];
            let err = o as f64 * out_lsb - s * nc.coef;
            r.out_max_abs = r.out_max_abs.max(err.abs());
            r.n_correct += u64::from(err.abs() <= half);
            let cn = cos_n(i);
            r.quant = r.quant.max((fixed_lobe - s).abs());
            r.approx = r.approx.max((s - cn).abs());
            r.total = r.total.max((fixed_lobe - cn).abs());
            r.norm = r.norm.max((o as f64 * out_lsb - norm_peak * cn).abs());
            r.norm_approx = r.norm_approx.max((s * nc.coef - norm_peak * cn).abs());
            if prev_out.is_some_and(|p| o < p) {
                r.n_violations += 1;
            }
            prev_out = Some(o);
        }
        start = end;
    }
    debug_assert!(last >= lo);
    r.norm_rel = r.norm / norm_peak;
    r.norm_approx /= norm_peak;
    r
}

/// `cos^n` of one exponent's codes from `start` (an index into the input codes) to the last.
#[derive(Debug)]
struct CosRow {
    start: usize,
    values: Vec<f64>,
}

/// The `cos^n` of the live codes of each exponent, kept across the exhaustive checks of
/// datapaths with the same input format (the optimiser's candidates differ in their stages,
/// not in `c` or its codes): each row is computed once, by the first check that needs it,
/// from that check's first live code on (a later check with more live codes computes the
/// extra ones itself). At most `capacity` values are kept (8 bytes each); past that, rows are
/// computed and not kept. The figures of every configuration checked through the cache are
/// kept too (a few hundred bytes each, keyed by the whole configuration), so that a search
/// that meets a candidate again (the optimiser's frontier, one search per budget) does not
/// check it twice. Shared by threads.
#[derive(Debug)]
pub struct CosCache {
    format: std::sync::OnceLock<crate::fixed::Format>,
    rows: std::sync::Mutex<std::collections::BTreeMap<u32, std::sync::Arc<CosRow>>>,
    floors: std::sync::Mutex<std::collections::BTreeMap<FloorKey, (f64, f64)>>,
    figures: std::sync::Mutex<std::collections::HashMap<String, OutputFigures>>,
    capacity: usize,
    kept: std::sync::atomic::AtomicUsize,
}

impl CosCache {
    /// An empty cache keeping at most `capacity` values.
    pub fn new(capacity: usize) -> CosCache {
        CosCache {
            format: std::sync::OnceLock::new(),
            rows: std::sync::Mutex::new(std::collections::BTreeMap::new()),
            floors: std::sync::Mutex::new(std::collections::BTreeMap::new()),
            figures: std::sync::Mutex::new(std::collections::HashMap::new()),
            capacity,
            kept: std::sync::atomic::AtomicUsize::new(0),
        }
    }

    /// The values kept.
    pub fn entries(&self) -> usize {
        self.kept.load(std::sync::atomic::Ordering::Relaxed)
    }

    /// Whether the cache holds this datapath's codes: the input format of the first datapath
    /// it served.
    fn serves(&self, dp: &Datapath) -> bool {
        *self.format.get_or_init(|| dp.config().c.format) == dp.config().c.format
    }

    /// The row of exponent `n`, made by `make` (the values from index `start` on) when absent;
    /// None when it is absent and does not fit.
    fn row(
        &self,
        n: u32,
        start: usize,
        make: impl FnOnce() -> Vec<f64>,
    ) -> Option<std::sync::Arc<CosRow>> {
        use std::sync::atomic::Ordering;
        if let Some(r) = self.rows.lock().expect("not poisoned").get(&n) {
            return Some(r.clone());
        }
        let values = make();
        if self.kept.load(Ordering::Relaxed) + values.len() > self.capacity {
            return Some(std::sync::Arc::new(CosRow { start, values }));
        }
        let mut rows = self.rows.lock().expect("not poisoned");
        let r = rows.entry(n).or_insert_with(|| {
            self.kept.fetch_add(values.len(), Ordering::Relaxed);
            std::sync::Arc::new(CosRow { start, values })
        });
        Some(r.clone())
    }
}

/// What the f64 lobe of one exponent depends on besides the input codes: n, its depth, the
/// f64 slope, offset and coefficient (as bits), the threshold, the cutoff and the form.
type FloorKey = (u32, u32, u64, u64, u64, i64, u8, u8);

impl CosCache {
    /// The f64 floor of one exponent, `(max |s - cos^n|, max |s coef - peak cos^n|)` over
    /// every code, made by `make` when absent: the same for every datapath whose f64 lobe is
    /// the same (the optimiser's candidates of one algorithm differ only in their stages).
    fn floor(&self, key: FloorKey, make: impl FnOnce() -> (f64, f64)) -> (f64, f64) {
        if let Some(&f) = self.floors.lock().expect("not poisoned").get(&key) {
            return f;
        }
        let f = make();
        self.floors.lock().expect("not poisoned").insert(key, f);
        f
    }
}

/// The output figures of an exhaustive check ([`OutputFigures`]) without the per-stage
/// statistics: the dead prefix of each n is not evaluated at all.
///
/// # Errors
/// As [`check`]: [`Error::TooManyCodes`].
///
/// # Examples
/// ```
/// use specfx::analysis::check::{check, check_outputs};
/// use specfx::pipeline::{Config, Datapath};
/// let dp = Datapath::new(Config::baseline()).unwrap();
/// assert_eq!(check_outputs(&dp).unwrap(), check(&dp).unwrap().output_figures());
/// ```
pub fn check_outputs(dp: &Datapath) -> Result<OutputFigures, Error> {
    check_outputs_cached(dp, None)
}

/// [`check_outputs`] with the `cos^n` of the live codes taken from `cache` where it holds
/// them (the same values, computed once for every datapath with the same input format: the
/// optimiser's candidates). The figures are those of [`check_outputs`], bit for bit.
///
/// # Errors
/// As [`check`]: [`Error::TooManyCodes`].
///
/// # Examples
/// ```
/// use specfx::analysis::check::{check_outputs, check_outputs_cached, CosCache};
/// use specfx::pipeline::{Config, Datapath};
/// let dp = Datapath::new(Config::baseline()).unwrap();
/// let cache = CosCache::new(1 << 24);
/// let first = check_outputs_cached(&dp, Some(&cache)).unwrap();
/// assert!(cache.entries() > 0);
/// assert_eq!(check_outputs_cached(&dp, Some(&cache)).unwrap(), first);
/// assert_eq!(check_outputs(&dp).unwrap(), first);
/// ```
pub fn check_outputs_cached(
    dp: &Datapath,
    cache: Option<&CosCache>,
) -> Result<OutputFigures, Error> {
    let Some(cache) = cache.filter(|c| c.serves(dp)) else {
        return outputs_of(dp, &code_columns(dp)?, None);
    };
    let key = dp.config().to_toml();
    if let Some(&f) = cache.figures.lock().expect("not poisoned").get(&key) {
        return Ok(f);
    }
    let f = outputs_of(dp, &code_columns(dp)?, Some(cache))?;
    cache.figures.lock().expect("not poisoned").insert(key, f);
    Ok(f)
}

/// The output figures of [`check_outputs_cached`], computed.
fn outputs_of(
    dp: &Datapath,
    shared: &CodeColumns,
    cache: Option<&CosCache>,
) -> Result<OutputFigures, Error> {
    let codes = &shared.codes.codes;
    let dead = map_n(dp, |nc| dead_prefix_end(dp, nc, codes));
    // The squaring chain is looked up from b where its tables (one pass of its kernels over
    // every b code, for each depth) cost fewer evaluations than running it on the codes above
    // the dead prefixes (a bound on the live codes).
    let end = codes[codes.len() - 1] + 1;
    let above_dead: u128 = dead.iter().map(|&d| (end - d) as u128).sum();
    let b = dp.config().b.format;
    let b_codes = (i128::from(b.max_raw()) - i128::from(b.min_raw()) + 1) as u128;
    let depths = dp
        .constants()
        .iter()
        .map(|nc| nc.depth)
        .collect::<std::collections::BTreeSet<_>>()
        .len() as u128;
    let tabulate = b_codes * depths <= above_dead;
    let per_n = map_n(dp, |nc| {
        let i = dp
            .config()
            .n
            .values()
            .binary_search(&nc.n)
            .expect("an exponent of the set");
        outputs_one_n(dp, nc, shared, cache, dead[i], tabulate)
    });
    let mut f = OutputsOfN::empty(0);
    for p in &per_n {
        f.merge(p);
    }
    let n_eval = shared.codes.codes.len() as u64 * per_n.len() as u64;
    Ok(OutputFigures {
        n_evaluations: n_eval,
        shape_quant_max_abs: f.quant,
        shape_approx_max_abs: f.approx,
        shape_total_max_abs: f.total,
        out_max_ulp: f.out_max_abs / dp.config().out.format.lsb(),
        out_correctly_rounded: f.n_correct as f64 / n_eval as f64,
        norm_total_max_abs: f.norm,
        norm_total_rel: f.norm_rel,
        norm_approx_rel: f.norm_approx,
        monotonic: f.n_violations == 0,
    })
}
