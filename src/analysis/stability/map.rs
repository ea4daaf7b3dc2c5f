//! The map: every sample of every path flagged by its `Kind`, folded per n (in n order) into
//! failure regions and heat maps.

use rayon::prelude::*;
use serde::Serialize;

use crate::engine::{fold_n, Chunk, Codes};
use crate::error::Error;
use crate::fixed::Event;
use crate::nset::NSet;
use crate::pipeline::datapath::STAGE_B;
use crate::pipeline::{Config, Datapath, Variant};
use crate::reference::lobe::{cos_pow, m_of_k};
use crate::reference::method::Method;

use super::*;

/// Every sample of one path flagged with one kind.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Region {
    /// The kind.
    pub kind: Kind,
    /// Flagged samples.
    pub samples: u64,
    /// Of those, samples off by more than the tolerance.
    pub failing: u64,
    /// Whether the region is a failure: some sample in it is off by more than the tolerance,
    /// the lobe falls by more than the tolerance somewhere in it (non-monotonic), or its kind
    /// is a failure by itself (non-finite, unrepresentable).
    pub fails: bool,
    /// The smallest n with a flagged sample.
    pub n_min: u32,
    /// The largest.
    pub n_max: u32,
    /// The smallest flagged cosine (the largest angle).
    pub c_min: f64,
    /// The largest flagged cosine (the smallest angle).
    pub c_max: f64,
    /// The largest |lobe - cos^n| in the region (finite samples).
    pub worst_abs_err: f64,
    /// Its exponent.
    pub worst_n: u32,
    /// Its cosine.
    pub worst_c: f64,
    /// For `non_monotonic`: the largest fall of the lobe between neighbouring samples.
    pub max_drop: f64,
    /// The stages involved (overflow kinds of a datapath).
    pub stages: Vec<String>,
    /// A remark (for `unrepresentable`, the first n's validation error).
    pub note: Option<String>,
    /// The extent at the region's first and last n and at every power of two in between.
    pub at_n: Vec<NBounds>,
    /// The extent at each n with a flagged sample, ascending.
    #[serde(skip)]
    pub per_n: Vec<NBounds>,
}

impl Region {
    /// The extent at `n`, if the region has a sample there.
    pub fn at(&self, n: u32) -> Option<&NBounds> {
        self.per_n
            .binary_search_by_key(&n, |b| b.n)
            .ok()
            .map(|i| &self.per_n[i])
    }
}

/// One heat-map cell: the samples of a column of exponents and one degree of theta.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize)]
pub struct Cell {
    /// Samples in the cell.
    pub samples: u32,
    /// The largest |lobe - cos^n| of its finite samples.
    pub max_abs_err: f64,
    /// The union of its samples' kinds ([`Kind::bit`]).
    pub flags: u16,
}

/// A heat map: columns of exponents by rows of one degree of theta.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct HeatMap {
    /// Each column's first and last exponent.
    pub columns: Vec<(u32, u32)>,
    /// `cells[col * HEAT_ROWS + row]`; row r covers theta in [r, r + 1) degrees (90 in the
    /// last).
    pub cells: Vec<Cell>,
}

impl HeatMap {
    /// The cell of a column and a row.
    pub fn cell(&self, col: usize, row: usize) -> &Cell {
        &self.cells[col * HEAT_ROWS + row]
    }
}

/// The map of one path.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PathMap {
    /// The path's name.
    pub path: String,
    /// `f64`, `f32` or `fixed`.
    pub precision: String,
    /// The input resolution: fraction bits of the cosine samples.
    pub c_bits: u32,
    /// Samples evaluated.
    pub samples: u64,
    /// The largest |lobe - cos^n| over the map.
    pub max_abs_err: f64,
    /// Its exponent and cosine.
    pub worst_n: u32,
    /// Its cosine.
    pub worst_c: f64,
    /// Every region, in [`Kind::ALL`] order.
    pub regions: Vec<Region>,
    /// For a datapath, the exponents its configuration was designed for (its own `n`, which
    /// the map replaces by the grid's), smallest and largest; its inputs are every code from
    /// 0 to 1.0, theta 0..=90 degrees. `None` for a float path.
    pub design_n: Option<(u32, u32)>,
    /// The heat map.
    #[serde(skip)]
    pub heat: HeatMap,
}

impl PathMap {
    /// The region of a kind, if any sample has it.
    pub fn region(&self, kind: Kind) -> Option<&Region> {
        self.regions.iter().find(|r| r.kind == kind)
    }

    /// Whether the path stays within the tolerance everywhere and has no failing region.
    pub fn passes(&self) -> bool {
        !self.regions.iter().any(|r| r.fails)
    }
}

/// The heat-map row of a cosine.
pub(super) fn heat_row(c: f64) -> usize {
    let deg = c.clamp(0.0, 1.0).acos().to_degrees();
    (deg.floor() as usize).min(HEAT_ROWS - 1)
}

/// Groups sorted exponents into heat-map columns at least 1/16 octave wide (each n alone
/// while it is that wide by itself).
///
/// # Examples
/// ```
/// use specfx::analysis::stability::heat_columns;
/// let cols = heat_columns(&(1..=40).collect::<Vec<_>>());
/// assert_eq!(cols[0], (1, 1));
/// assert_eq!(cols[21], (22, 22)); // log2(23/22) >= 1/16
/// assert_eq!(cols[22], (23, 24)); // log2(24/23) < 1/16: two exponents
/// ```
pub fn heat_columns(ns: &[u32]) -> Vec<(u32, u32)> {
    let mut cols = Vec::new();
    let mut i = 0;
    while i < ns.len() {
        let first = ns[i];
        let mut j = i;
        while j + 1 < ns.len()
            && (f64::from(ns[j]) + 1.0).log2() - f64::from(first).log2() < 1.0 / 16.0
        {
            j += 1;
        }
        cols.push((first, ns[j]));
        i = j + 1;
    }
    cols
}

/// Per-kind accumulator of one path at one n.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct KindAcc {
    samples: u64,
    failing: u64,
    c_lo: f64,
    c_hi: f64,
    worst: f64,
    worst_c: f64,
    stage_mask: u32,
    max_drop: f64,
}

impl KindAcc {
    fn new() -> KindAcc {
        KindAcc {
            samples: 0,
            failing: 0,
            c_lo: f64::INFINITY,
            c_hi: f64::NEG_INFINITY,
            worst: -1.0,
            worst_c: 0.0,
            stage_mask: 0,
            max_drop: 0.0,
        }
    }
}

/// One path at one n: per-kind accumulators and its heat rows.
#[derive(Debug, Clone)]
pub(super) struct NAcc {
    kinds: [KindAcc; 10],
    rows: [Cell; HEAT_ROWS],
    samples: u64,
    max_abs_err: f64,
    worst_c: f64,
    unrepresentable: bool,
}

impl NAcc {
    fn new() -> NAcc {
        NAcc {
            kinds: [KindAcc::new(); 10],
            rows: [Cell::default(); HEAT_ROWS],
            samples: 0,
            max_abs_err: -1.0,
            worst_c: 0.0,
            unrepresentable: false,
        }
    }

    /// Records one sample: its cosine, heat row, error, flags, overflowing stages and how much
    /// the lobe fell from the sample before.
    #[inline]
    fn add(&mut self, c: f64, row: usize, err: f64, flags: u16, stage_mask: u32, drop: f64) {
        self.samples += 1;
        let abs = err.abs();
        let cell = &mut self.rows[row];
        cell.samples += 1;
        cell.flags |= flags;
        if abs > cell.max_abs_err {
            cell.max_abs_err = abs;
        }
        if abs > self.max_abs_err {
            self.max_abs_err = abs;
            self.worst_c = c;
        }
        if flags == 0 {
            return;
        }
        let failing = flags & FAIL_BITS != 0;
        let mut bits = flags;
        while bits != 0 {
            let i = bits.trailing_zeros() as usize;
            bits &= bits - 1;
            let k = &mut self.kinds[i];
            k.samples += 1;
            k.failing += u64::from(failing);
            k.c_lo = k.c_lo.min(c);
            k.c_hi = k.c_hi.max(c);
            if abs > k.worst {
                k.worst = abs;
                k.worst_c = c;
            }
            if i == Kind::Wrap as usize || i == Kind::Saturate as usize {
                k.stage_mask |= stage_mask;
            }
            if i == Kind::NonMonotonic as usize {
                k.max_drop = k.max_drop.max(drop);
            }
        }
    }
}

/// Flags of an error against the tolerance.
#[inline]
pub(super) fn error_flags(err: f64, tol: f64) -> u16 {
    if err > tol {
        Kind::Over.bit()
    } else if err < -tol {
        Kind::Under.bit()
    } else {
        0
    }
}

/// Evaluates one float path at one n over the grid of cosines.
pub(super) fn float_column(
    path: FloatPath,
    n: u32,
    cs: &[f64],
    rows: &[usize],
    reference: &[f64],
    tol: f64,
) -> NAcc {
    let p = path.prepare(n);
    let m = match path {
        FloatPath::Method(Method::CsM { k, .. }) => Some(m_of_k(k)),
        _ => None,
    };
    let n_below_m = m.is_some_and(|m| n < m);
    let min_normal = path.min_normal();
    let mut acc = NAcc::new();
    let mut prev = f64::NAN;
    let is_powf = matches!(p, Prepared::CosPow(_));
    for (j, &c) in cs.iter().enumerate() {
        // powf is the reference itself: the same call on the same input.
        let s = if is_powf {
            FloatSample {
                value: reference[j],
                base: None,
                exact_positive: c > 0.0,
            }
        } else {
            p.eval(c)
        };
        let v = s.value;
        let err = v - reference[j];
        let mut flags = if v.is_finite() {
            error_flags(err, tol)
        } else {
            Kind::NonFinite.bit()
        };
        if n_below_m && flags & FAIL_BITS != 0 {
            flags |= Kind::NBelowM.bit();
        }
        if s.base.is_some_and(|b| b < 0.0) && v != 0.0 {
            flags |= Kind::NegativeBase.bit();
        }
        if s.exact_positive && v.abs() < min_normal {
            flags |= Kind::Underflow.bit();
        }
        let drop = prev - v;
        if drop > 0.0 {
            flags |= Kind::NonMonotonic.bit();
        }
        prev = v;
        acc.add(
            c,
            rows[j],
            if err.is_finite() { err } else { 0.0 },
            flags,
            0,
            drop,
        );
    }
    acc
}

/// A fixed-point path prepared for the map: the datapath over the representable exponents.
pub(super) struct FixedPlan {
    dp: Option<Datapath>,
    /// Why the first exponent the datapath cannot hold is refused.
    reason: Option<String>,
    lobe_scale: f64,
    out_scale: f64,
    /// Every code from 0 up to 1.0.
    codes: Codes,
    cs: Vec<f64>,
    rows: Vec<usize>,
}

/// The datapath of `config` over the exponents of `ns` it can hold (`None` if it holds none),
/// with why the first one it cannot hold is refused. An error that names no exponent is the
/// configuration's own and is returned.
pub(super) fn representable(
    config: &Config,
    ns: &[u32],
) -> Result<(Option<Datapath>, Option<String>), Error> {
    let mut good = Vec::new();
    let mut reason = None;
    for &n in ns {
        let mut cfg = config.clone();
        cfg.n = NSet::range(n, n)?;
        match Datapath::new(cfg) {
            Ok(_) => good.push(n),
            Err(e) => {
                let text = e.to_string();
                if !text.contains(&format!("n = {n}")) {
                    return Err(e);
                }
                reason.get_or_insert(text);
            }
        }
    }
    if good.is_empty() {
        return Ok((None, reason));
    }
    let mut cfg = config.clone();
    cfg.n = NSet::from_values(&good)?;
    Ok((Some(Datapath::new(cfg)?), reason))
}

pub(super) fn fixed_plan(config: &Config, ns: &[u32]) -> Result<FixedPlan, Error> {
    let (dp, reason) = representable(config, ns)?;
    let (codes, lobe_scale, out_scale, c_scale) = match &dp {
        Some(dp) => {
            let scale =
                |stage_idx: usize| (-f64::from(dp.stages()[stage_idx].format.frac_bits())).exp2();
            (
                Codes::new(dp, (0..=dp.one_code()).collect()),
                scale(dp.stage_last_square()),
                scale(dp.stage_out()),
                (-f64::from(dp.config().c.format.frac_bits())).exp2(),
            )
        }
        None => (
            Codes {
                codes: Vec::new(),
                ln_c: Vec::new(),
            },
            1.0,
            1.0,
            1.0,
        ),
    };
    let cs: Vec<f64> = codes.codes.iter().map(|&c| c as f64 * c_scale).collect();
    let rows = cs.iter().map(|&c| heat_row(c)).collect();
    Ok(FixedPlan {
        dp,
        reason,
        lobe_scale,
        out_scale,
        codes,
        cs,
        rows,
    })
}

/// A fixed path's accumulator of one n: the map's figures and the previous element's lobe and
/// output (monotonicity runs across chunks).
pub(super) struct FixedAcc {
    acc: NAcc,
    prev_lobe: i64,
    prev_out: i64,
}

/// Folds one chunk of the engine's stream into a fixed path's accumulator.
pub(super) fn fixed_chunk(
    plan: &FixedPlan,
    dp: &Datapath,
    tol: f64,
    fa: &mut FixedAcc,
    chunk: &Chunk<'_>,
) {
    let nc = chunk.nc;
    let n = nc.n;
    let cfg = dp.config();
    let n_below_m = cfg.variant == Variant::Plain && n < m_of_k(nc.depth);
    let nf = f64::from(n);
    let cols = chunk.probes;
    let last = dp.stage_last_square();
    let out = dp.stage_out();
    // The stream visits plan.codes, which start at code 0: a code is its own index.
    for (i, &code) in chunk.codes.iter().enumerate() {
        let j = code as usize;
        let c = plan.cs[j];
        let lobe_raw = cols.values[last][i];
        let out_raw = cols.values[out][i];
        let b_raw = cols.values[STAGE_B][i];
        let lobe = lobe_raw as f64 * plan.lobe_scale;
        let err = lobe - cos_pow(c, nf);
        let mut flags = error_flags(err, tol);
        if n_below_m && flags & FAIL_BITS != 0 {
            flags |= Kind::NBelowM.bit();
        }
        if b_raw < 0 && lobe_raw != 0 {
            flags |= Kind::NegativeBase.bit();
        }
        if b_raw != 0 && lobe_raw == 0 {
            flags |= Kind::Underflow.bit();
        }
        // The fall in lobe units (an output fall is divided by the coefficient).
        let mut drop = 0.0;
        if lobe_raw < fa.prev_lobe || out_raw < fa.prev_out {
            flags |= Kind::NonMonotonic.bit();
            drop = ((fa.prev_lobe - lobe_raw) as f64 * plan.lobe_scale)
                .max((fa.prev_out - out_raw) as f64 * plan.out_scale / nc.coef);
        }
        fa.prev_lobe = lobe_raw;
        fa.prev_out = out_raw;
        let mut stage_mask = 0u32;
        if chunk.any_event() {
            for (stage_idx, e) in chunk.events(i).iter().enumerate() {
                match e {
                    Event::None => {}
                    Event::Wrapped => {
                        flags |= Kind::Wrap.bit();
                        stage_mask |= 1 << stage_idx;
                    }
                    Event::Saturated | Event::Zeroed => {
                        flags |= Kind::Saturate.bit();
                        stage_mask |= 1 << stage_idx;
                    }
                }
            }
        }
        fa.acc.add(c, plan.rows[j], err, flags, stage_mask, drop);
    }
}

/// The accumulators of a fixed path for every n of the grid, in grid order: the engine's
/// stream over the n its datapath holds, an unrepresentable accumulator for the others.
pub(super) fn fixed_columns(
    plan: &FixedPlan,
    ns: &[u32],
    tol: f64,
    done: &(dyn Fn() + Sync),
) -> Vec<NAcc> {
    let unrepresentable = || NAcc {
        unrepresentable: true,
        ..NAcc::new()
    };
    let Some(dp) = &plan.dp else {
        ns.iter().for_each(|_| done());
        return ns.iter().map(|_| unrepresentable()).collect();
    };
    let per_n = fold_n(
        dp,
        &plan.codes,
        |_| FixedAcc {
            acc: NAcc::new(),
            prev_lobe: i64::MIN,
            prev_out: i64::MIN,
        },
        |fa, chunk| fixed_chunk(plan, dp, tol, fa, chunk),
        done,
    );
    let mut held = dp.constants().iter().map(|nc| nc.n).zip(per_n).peekable();
    ns.iter()
        .map(|&n| match held.peek() {
            Some(&(m, _)) if m == n => held.next().expect("peeked").1.acc,
            _ => {
                done();
                unrepresentable()
            }
        })
        .collect()
}

/// What [`assemble`] needs to know of a path besides its accumulators.
pub(super) struct PathMeta {
    name: String,
    design_n: Option<(u32, u32)>,
    precision: &'static str,
    c_bits: u32,
    stage_names: Vec<String>,
    reason: Option<String>,
}

/// Folds the per-n accumulators of one path, in n order, into its map.
pub(super) fn assemble(meta: PathMeta, ns: &[u32], accs: Vec<NAcc>, tol: f64) -> PathMap {
    let PathMeta {
        name,
        design_n,
        precision,
        c_bits,
        stage_names,
        reason,
    } = meta;
    let stage_names = &stage_names[..];
    let columns = heat_columns(ns);
    let mut cells = vec![Cell::default(); columns.len() * HEAT_ROWS];
    let mut col = 0;
    let mut regions: Vec<Option<Region>> = vec![None; Kind::ALL.len()];
    let mut samples = 0;
    let (mut max_abs_err, mut worst_n, mut worst_c) = (0.0, ns[0], 1.0);
    for (&n, acc) in ns.iter().zip(accs) {
        while n > columns[col].1 {
            col += 1;
        }
        samples += acc.samples;
        if acc.max_abs_err > max_abs_err {
            max_abs_err = acc.max_abs_err;
            worst_n = n;
            worst_c = acc.worst_c;
        }
        for (row, r) in acc.rows.iter().enumerate() {
            let cell = &mut cells[col * HEAT_ROWS + row];
            cell.samples += r.samples;
            cell.flags |= r.flags;
            cell.max_abs_err = cell.max_abs_err.max(r.max_abs_err);
        }
        let mut kinds = acc.kinds;
        if acc.unrepresentable {
            let k = &mut kinds[Kind::Unrepresentable as usize];
            k.samples = 1;
            k.c_lo = 0.0;
            k.c_hi = 1.0;
            for row in 0..HEAT_ROWS {
                cells[col * HEAT_ROWS + row].flags |= Kind::Unrepresentable.bit();
            }
        }
        for (i, k) in kinds.iter().enumerate() {
            if k.samples == 0 {
                continue;
            }
            let kind = Kind::ALL[i];
            let reg = regions[i].get_or_insert_with(|| Region {
                kind,
                samples: 0,
                failing: 0,
                fails: false,
                n_min: n,
                n_max: n,
                c_min: k.c_lo,
                c_max: k.c_hi,
                worst_abs_err: -1.0,
                worst_n: n,
                worst_c: k.worst_c,
                max_drop: 0.0,
                stages: Vec::new(),
                note: None,
                at_n: Vec::new(),
                per_n: Vec::new(),
            });
            reg.samples += k.samples;
            reg.failing += k.failing;
            reg.n_max = n;
            reg.c_min = reg.c_min.min(k.c_lo);
            reg.c_max = reg.c_max.max(k.c_hi);
            reg.max_drop = reg.max_drop.max(k.max_drop);
            if k.worst > reg.worst_abs_err {
                reg.worst_abs_err = k.worst;
                reg.worst_n = n;
                reg.worst_c = k.worst_c;
            }
            for (stage_idx, stage) in stage_names.iter().enumerate() {
                if k.stage_mask & (1 << stage_idx) != 0 && !reg.stages.contains(stage) {
                    reg.stages.push(stage.clone());
                }
            }
            reg.per_n.push(NBounds {
                n,
                c_lo: k.c_lo,
                c_hi: k.c_hi,
                samples: k.samples,
            });
        }
    }
    let regions = regions
        .into_iter()
        .flatten()
        .map(|mut r| {
            r.worst_abs_err = r.worst_abs_err.max(0.0);
            r.fails = r.failing > 0
                || r.kind.is_structural()
                || (r.kind == Kind::NonMonotonic && r.max_drop > tol);
            if r.kind == Kind::Unrepresentable {
                r.note = reason.clone();
                r.samples = 0;
            }
            r.at_n = r
                .per_n
                .iter()
                .filter(|b| b.n.is_power_of_two() || b.n == r.n_min || b.n == r.n_max)
                .copied()
                .collect();
            // Keep the stages in pipeline order.
            r.stages.sort_by_key(|s| {
                stage_names
                    .iter()
                    .position(|x| x == s)
                    .unwrap_or(usize::MAX)
            });
            r
        })
        .collect();
    PathMap {
        path: name,
        design_n,
        precision: precision.to_string(),
        c_bits,
        samples,
        max_abs_err,
        worst_n,
        worst_c,
        regions,
        heat: HeatMap { columns, cells },
    }
}

/// The float grid: every `j / 2^c_bits` in [0, 1].
///
/// # Examples
/// ```
/// assert_eq!(specfx::analysis::stability::float_cosines(2), [0.0, 0.25, 0.5, 0.75, 1.0]);
/// ```
pub fn float_cosines(c_bits: u32) -> Vec<f64> {
    let steps = 1u64 << c_bits;
    (0..=steps)
        .map(|j| j as f64 / steps as f64)
        .collect::<Vec<f64>>()
}

/// How many exponents are evaluated in parallel between two progress reports.
pub(super) const CHUNK: usize = 64;

/// The most samples one map may take (2^34, a few minutes on two cores): see [`samples`].
pub const MAX_SAMPLES: u64 = 1 << 34;

/// How many samples [`map`] takes on `grid`: each float path at every exponent and each of its
/// `2^c_bits + 1` cosines, each datapath at every exponent and each of its input codes in
/// [0, 1] (`2^f + 1` for `f` fraction bits). Saturates at `u64::MAX`.
///
/// # Examples
/// ```
/// use specfx::analysis::stability::{samples, FloatPath, Grid, MapPath};
/// let grid = Grid { n: "1..=10".parse().unwrap(), c_bits: 4, ..Grid::default() };
/// let paths = [MapPath::Float(FloatPath::PowI), MapPath::Float(FloatPath::PowF32)];
/// assert_eq!(samples(&paths, &grid), 2 * 10 * 17);
/// ```
pub fn samples(paths: &[MapPath], grid: &Grid) -> u64 {
    let ns = grid.n.values().len() as u128;
    let codes = |bits: i64| (1u128 << bits.clamp(0, 100)) + 1;
    let total: u128 = paths
        .iter()
        .map(|p| match p {
            MapPath::Float(_) => codes(i64::from(grid.c_bits)),
            MapPath::Fixed(c) => codes(i64::from(c.c.format.frac_bits())),
        })
        .map(|per_n| per_n * ns)
        .sum();
    u64::try_from(total).unwrap_or(u64::MAX)
}

/// Maps every path over the grid. `progress(done, total)` is called after each chunk of
/// exponents (of the float paths together, then of each datapath).
///
/// Fails only on a datapath configuration that is invalid whatever n is.
///
/// # Examples
/// ```
/// use specfx::analysis::stability::{map, FloatPath, Grid, Kind, MapPath};
/// use specfx::reference::lobe::Cutoff;
/// use specfx::reference::method::Method;
/// let grid = Grid { n: "1..=20".parse().unwrap(), c_bits: 8, ..Grid::default() };
/// let paths = [MapPath::Float(FloatPath::Method(Method::CsM { k: 4, cutoff: Cutoff::Clamp }))];
/// let maps = map(&paths, &grid, &|_, _| {}).unwrap();
/// // cs16 with n = 1: (1 - (1 - c)/16)^16 at c = 0 is (15/16)^16 = 0.356, cos^1 is 0.
/// let r = maps[0].region(Kind::NBelowM).unwrap();
/// assert_eq!(r.n_min, 1);
/// assert!(r.n_max < 16);
/// ```
pub fn map(
    paths: &[MapPath],
    grid: &Grid,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Result<Vec<PathMap>, Error> {
    if !(1..=24).contains(&grid.c_bits) {
        return Err(Error::OutOfRange {
            what: "c_bits",
            expected: "in 1..=24".into(),
            got: grid.c_bits.to_string(),
        });
    }
    let work = samples(paths, grid);
    if work > MAX_SAMPLES {
        return Err(Error::OutOfRange {
            what: "samples (exponents x cosines, summed over the paths)",
            expected: format!("at most 2^34 = {MAX_SAMPLES}"),
            got: work.to_string(),
        });
    }
    let ns = grid.n.values();
    let tol = grid.tol.value;
    let floats: Vec<FloatPath> = paths
        .iter()
        .filter_map(|p| match p {
            MapPath::Float(f) => Some(*f),
            MapPath::Fixed(_) => None,
        })
        .collect();
    let plans: Vec<(&Config, FixedPlan)> = paths
        .iter()
        .filter_map(|p| match p {
            MapPath::Fixed(c) => Some(c.as_ref()),
            MapPath::Float(_) => None,
        })
        .map(|c| fixed_plan(c, ns).map(|p| (c, p)))
        .collect::<Result<_, _>>()?;
    let total = if floats.is_empty() { 0 } else { ns.len() } + plans.len() * ns.len();
    let mut done = 0;

    let mut float_accs: Vec<Vec<NAcc>> = vec![Vec::with_capacity(ns.len()); floats.len()];
    if !floats.is_empty() {
        let cs = float_cosines(grid.c_bits);
        let rows: Vec<usize> = cs.iter().map(|&c| heat_row(c)).collect();
        for chunk in ns.chunks(CHUNK) {
            let per_n: Vec<Vec<NAcc>> = chunk
                .par_iter()
                .map(|&n| {
                    let nf = f64::from(n);
                    let reference: Vec<f64> = cs.iter().map(|&c| cos_pow(c, nf)).collect();
                    floats
                        .iter()
                        .map(|&p| float_column(p, n, &cs, &rows, &reference, tol))
                        .collect()
                })
                .collect();
            for accs in per_n {
                for (i, a) in accs.into_iter().enumerate() {
                    float_accs[i].push(a);
                }
            }
            done += chunk.len();
            progress(done, total);
        }
    }
    let mut float_maps = floats
        .iter()
        .zip(float_accs)
        .map(|(p, accs)| {
            let meta = PathMeta {
                name: p.name(),
                design_n: None,
                precision: p.precision(),
                c_bits: grid.c_bits,
                stage_names: Vec::new(),
                reason: None,
            };
            assemble(meta, ns, accs, tol)
        })
        .collect::<Vec<_>>()
        .into_iter();

    let mut fixed_maps = Vec::new();
    for (config, plan) in &plans {
        let base = done;
        let finished = std::sync::atomic::AtomicUsize::new(0);
        let accs = fixed_columns(plan, ns, tol, &|| {
            let now = finished.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
            progress(base + now, total);
        });
        done += ns.len();
        let stage_names: Vec<String> = plan
            .dp
            .as_ref()
            .map(|dp| dp.stages().iter().map(|s| s.name.clone()).collect())
            .unwrap_or_default();
        let c_bits = config.c.format.frac_bits().max(0) as u32;
        let meta = PathMeta {
            name: config.name.clone(),
            design_n: Some((config.n.min(), config.n.max())),
            precision: "fixed",
            c_bits,
            stage_names,
            reason: plan.reason.clone(),
        };
        fixed_maps.push(assemble(meta, ns, accs, tol));
    }
    let mut fixed_maps = fixed_maps.into_iter();
    // Back in the order the paths were given.
    Ok(paths
        .iter()
        .map(|p| match p {
            MapPath::Float(_) => float_maps.next().expect("one map per float path"),
            MapPath::Fixed(_) => fixed_maps.next().expect("one map per datapath"),
        })
        .collect())
}
