//! Formal bounds with gappa: the script that states a datapath's quantization error for one
//! exponent, and the reading of gappa's answer. Running gappa is the caller's business.
//!
//! For one n, the error |fixed output - f64 model output| is bounded over two regions of the
//! input code:
//! - the **upper region** `K..=1.0`, where neither model cuts the base: gappa proves the bound
//!   of the straight-line program (subtraction, product, sum, k squarings, output product),
//!   each rounding as the datapath rounds, together with the range of every stage (which must
//!   fit its format: gappa's rounding operators do not overflow);
//! - the **lower region** `0..K`, where one of the models cuts the base to zero (the clamp or the
//!   paper's threshold): both outputs there are non-negative and non-decreasing in c (every
//!   rounding mode is monotone, squares of non-negative values are monotone, and no stage
//!   wraps), so the error is at most the larger of the two outputs at code `K - 1`. With the
//!   paper cutoff both models are exactly 0 below the threshold.

use std::collections::BTreeMap;
use std::fmt::Write as _;

use crate::error::Error;
use crate::fixed::{Event, Exact, Rounding};
use crate::pipeline::f64_walk::mixed_eval;
use crate::pipeline::walk::{walk, Arithmetic};
use crate::pipeline::{first_code_where, Datapath, NConstants, StageSpec};
use crate::reference::lobe::Cutoff;

/// Gappa's name for a rounding mode's direction.
///
/// # Examples
/// ```
/// use specfx::analysis::gappa::direction;
/// use specfx::fixed::Rounding;
/// assert_eq!(direction(Rounding::RndConv), "ne");
/// assert_eq!(direction(Rounding::Trn), "dn");
/// ```
pub fn direction(r: Rounding) -> &'static str {
    match r {
        Rounding::Trn => "dn",
        Rounding::TrnZero => "zr",
        Rounding::Rnd => "nu",
        Rounding::RndZero => "nz",
        Rounding::RndMinInf => "nd",
        Rounding::RndInf => "na",
        Rounding::RndConv => "ne",
        Rounding::RndConvOdd => "no",
    }
}

/// A finite f64 written exactly in gappa's dyadic notation (`mbe` = m * 2^e).
fn dyadic(x: f64) -> String {
    let e = Exact::from_f64(x).expect("finite constant");
    if e.raw == 0 {
        "0".into()
    } else {
        format!("{}b{}", e.raw, -e.frac_bits)
    }
}

fn raw_value(raw: i64, frac: i32) -> String {
    format!("{raw}b{}", -frac)
}

/// One gappa problem: the script for an exponent's upper region, and what is known of the
/// lower region.
#[derive(Debug, Clone, PartialEq)]
pub struct Job {
    /// The exponent.
    pub n: u32,
    /// The first input code of the upper region (`None`: the region is empty).
    pub upper_from: Option<i64>,
    /// The gappa script of the upper region (empty when it is empty).
    pub script: String,
    /// The bound of the lower region (0 when it is empty).
    pub lower_bound: f64,
    /// Stage names and formats' ranges to check gappa's ranges against, in script order.
    pub ranges: Vec<(String, f64, f64)>,
}

/// The smallest code from which a monotone predicate holds, over `0..=one`.
fn first_code(one: i64, holds: impl Fn(i64) -> bool) -> i64 {
    first_code_where(0..one + 1, holds)
}

/// The walk's interpreter that writes gappa's definitions: each step appends its line and
/// returns the name (or, for the exact sum `t + offset`, the expression) it defined. The
/// quantized chain rounds with `r_<stage>` and the quantized constants (`SQ`, `OQ`, `CQ`); the
/// exact chain (`exact`) names its values `M<stage>` and uses the exact constants (`SE`, `OE`,
/// `CE`). The script covers only the upper region, where neither model cuts, so no step cuts.
struct Script<'a> {
    text: &'a mut String,
    exact: bool,
}

impl<'a> Script<'a> {
    fn new(text: &'a mut String, exact: bool) -> Self {
        Script { text, exact }
    }

    /// Defines `name` (with the exact chain's `M` prefix) as `value`, rounded by the stage's
    /// operator in the quantized chain.
    fn define(&mut self, name: &str, value: &str) -> String {
        if self.exact {
            let _ = writeln!(self.text, "M{name} = {value};");
            format!("M{name}")
        } else {
            let _ = writeln!(self.text, "{name} = r_{name}({value});");
            name.to_string()
        }
    }

    fn constant(&self, name: &str) -> String {
        format!("{name}{}", if self.exact { 'E' } else { 'Q' })
    }
}

impl Arithmetic for Script<'_> {
    type Value = String;

    fn sub(&mut self) -> String {
        // d = c - 1 is exact and shared by both chains: the quantized chain defines it.
        if !self.exact {
            self.text.push_str("d = c - 1;\n");
        }
        "d".into()
    }

    fn below_threshold(&self) -> bool {
        false
    }

    fn mul_t(&mut self, d: String) -> String {
        let value = format!("{} * {d}", self.constant("S"));
        self.define("t", &value)
    }

    fn add_offset(&mut self, t: String) -> String {
        format!("{t} + {}", self.constant("O"))
    }

    fn is_negative(&self, _sum: String) -> bool {
        false
    }

    fn zero(&self) -> String {
        "0".into()
    }

    fn quant_b(&mut self, base: String) -> String {
        self.define("b", &base)
    }

    fn square(&mut self, i: usize, x: String) -> String {
        self.define(&format!("s{}", i + 1), &format!("{x} * {x}"))
    }

    fn pass(&mut self, i: usize, x: String) -> String {
        self.define(&format!("s{}", i + 1), &x)
    }

    fn mul_out(&mut self, s: String) -> String {
        let value = format!("{s} * {}", self.constant("C"));
        self.define("out", &value)
    }
}

/// Builds the gappa job of one exponent, or says why its bound cannot be proved this way.
///
/// # Examples
/// ```
/// use specfx::analysis::gappa::job;
/// use specfx::pipeline::{Config, Datapath};
/// let dp = Datapath::new(Config::baseline()).unwrap();
/// let j = job(&dp, dp.constants_for(16).unwrap()).unwrap();
/// assert_eq!(j.upper_from, Some(0)); // n = m: the base is c, never cut
/// assert!(j.script.contains("@r_t = fixed<-16,nu>;")); // RND: to nearest, ties up
/// ```
pub fn job(dp: &Datapath, nc: &NConstants) -> Result<Job, Error> {
    let unprovable = |reason: String| Error::Unprovable { n: nc.n, reason };
    let cfg = dp.config();
    let one = dp.one_code();
    let c_lo = *dp.input_codes().start();
    if c_lo < 0 {
        return Err(unprovable("signed input formats are not covered".into()));
    }
    let upper_from = match cfg.cutoff {
        Cutoff::None => 0,
        Cutoff::Paper => nc.threshold.unwrap_or(0).max(0),
        Cutoff::Clamp => {
            let fixed = first_code(one, |code| !dp.eval(code, nc).cut);
            let exact = first_code(one, |code| {
                let c = code as f64 * cfg.c.format.lsb();
                nc.slope * (c - 1.0) + nc.offset >= 0.0
            });
            fixed.max(exact)
        }
    };
    let lower_bound = if upper_from == 0 || cfg.cutoff == Cutoff::Paper {
        0.0
    } else {
        if (0..upper_from).any(|code| dp.eval(code, nc).events.contains(&Event::Wrapped)) {
            return Err(unprovable(format!(
                "a stage wraps below code {upper_from}, so the lower region is not monotone"
            )));
        }
        let below = upper_from - 1;
        let fixed = dp
            .config()
            .out
            .format
            .to_f64(dp.eval(below, nc).values[dp.stage_out()]);
        let reference = mixed_eval(dp, nc, below, 0).1;
        fixed.max(reference)
    };
    if upper_from > one {
        return Ok(Job {
            n: nc.n,
            upper_from: None,
            script: String::new(),
            lower_bound,
            ranges: Vec::new(),
        });
    }
    let mut s = String::new();
    let mut ranges = Vec::new();
    let mut round = |name: &str, spec: &StageSpec, s: &mut String| {
        let _ = writeln!(
            s,
            "@r_{name} = fixed<{},{}>;",
            -spec.format.frac_bits(),
            direction(spec.rounding)
        );
        ranges.push((
            name.to_string(),
            spec.format.min_value(),
            spec.format.max_value(),
        ));
    };
    round("t", &cfg.t, &mut s);
    round("b", &cfg.b, &mut s);
    for (i, sq) in cfg.square.iter().enumerate() {
        round(&format!("s{}", i + 1), sq, &mut s);
    }
    round("out", &cfg.out, &mut s);
    let k = cfg.square.len();
    let _ = writeln!(s, "SQ = {};", raw_value(nc.slope_raw, nc.slope_frac));
    let _ = writeln!(s, "SE = {};", dyadic(nc.slope));
    let _ = writeln!(s, "OQ = {};", raw_value(nc.offset_raw, nc.offset_frac));
    let _ = writeln!(s, "OE = {};", dyadic(nc.offset));
    let _ = writeln!(
        s,
        "CQ = {};",
        raw_value(nc.coef_raw, cfg.coef.format.frac_bits())
    );
    let _ = writeln!(s, "CE = {};", dyadic(nc.coef));
    let depth = nc.depth as usize;
    let quantized = walk(&mut Script::new(&mut s, false), cfg.cutoff, k, depth);
    let exact = walk(&mut Script::new(&mut s, true), cfg.cutoff, k, depth);
    let fc = cfg.c.format.frac_bits();
    let mut goal = format!(
        "{{ @FIX(c, {}) /\\ c in [{}, {}] -> out - Mout in ?",
        -fc,
        raw_value(upper_from, fc),
        raw_value(one, fc)
    );
    for (name, _, _) in &ranges {
        let _ = write!(goal, " /\\ {name} in ?");
    }
    goal.push_str(" }\n");
    s.push_str(&goal);
    // Hints: each error splits into the rounding of this stage plus the propagated error of
    // the stage before, which keeps gappa from losing the correlation between the two models.
    s.push_str("t - Mt -> (t - SQ * d) + (SQ - SE) * d;\n");
    s.push_str("b - Mb -> (b - (t + OQ)) + (t - Mt) + (OQ - OE);\n");
    let mut prev = ("b".to_string(), "Mb".to_string());
    debug_assert_eq!(
        (quantized.out.as_str(), exact.out.as_str()),
        ("out", "Mout")
    );
    for i in 1..=k {
        let (p, mp) = &prev;
        if i <= depth {
            let _ = writeln!(
                s,
                "s{i} - Ms{i} -> (s{i} - {p} * {p}) + ({p} - {mp}) * ({p} + {mp});"
            );
        } else {
            // A bypassed stage: its rounding plus the error it passes on.
            let _ = writeln!(s, "s{i} - Ms{i} -> (s{i} - {p}) + ({p} - {mp});");
        }
        prev = (format!("s{i}"), format!("Ms{i}"));
    }
    debug_assert_eq!((&prev.0, &prev.1), (&quantized.lobe, &exact.lobe));
    let (p, mp) = &prev;
    let _ = writeln!(
        s,
        "out - Mout -> (out - {p} * CQ) + ({p} - {mp}) * CQ + {mp} * (CQ - CE);"
    );
    Ok(Job {
        n: nc.n,
        upper_from: Some(upper_from),
        script: s,
        lower_bound,
        ranges,
    })
}

/// Parses a number as gappa prints it: an integer, optionally followed by `b` and a binary
/// exponent (`-483405125002887169b-65`). Returns the nearest f64 widened by one part in 2^50 away
/// from zero, so a bound never shrinks in the conversion.
///
/// # Examples
/// ```
/// use specfx::analysis::gappa::parse_number;
/// assert_eq!(parse_number("83b-4"), Some(5.1875));
/// assert_eq!(parse_number("0"), Some(0.0));
/// assert!(parse_number("-3b-1").unwrap() <= -1.5);
/// ```
pub fn parse_number(text: &str) -> Option<f64> {
    let (m, e) = match text.split_once('b') {
        Some((m, e)) => (m, e.parse::<i32>().ok()?),
        None => (text, 0),
    };
    let m: f64 = m.parse().ok()?;
    let x = m * f64::from(e).exp2();
    Some(if m.abs() < 9.007_199_254_740_992e15 && e.abs() < 1000 {
        x
    } else {
        x * (1.0 + 2f64.powi(-50))
    })
}

/// Reads the intervals gappa proved (`name in [lo, hi]` lines of its `Results:`), by name.
///
/// # Examples
/// ```
/// use specfx::analysis::gappa::parse_results;
/// let text = "Results:\n  t in [-1, 0]\n  out - Mout in [-3b-20 {-2.86e-06, -2^(-18.4)}, 1b-19 {1.9e-06, 2^(-19)}]\n";
/// let r = parse_results(text).unwrap();
/// assert_eq!(r["t"], (-1.0, 0.0));
/// assert_eq!(r["out - Mout"], (-3.0 / 1048576.0, 1.0 / 524288.0));
/// ```
pub fn parse_results(text: &str) -> Result<BTreeMap<String, (f64, f64)>, Error> {
    let unreadable = |message: String| Error::Tool {
        tool: "gappa",
        message,
    };
    let mut map = BTreeMap::new();
    let body = text
        .split_once("Results:")
        .map(|(_, b)| b)
        .ok_or_else(|| unreadable(format!("gappa printed no results: {}", first_line(text))))?;
    for line in body.lines() {
        let Some((name, interval)) = line.trim().split_once(" in [") else {
            continue;
        };
        let interval = interval.trim_end_matches(']');
        let mut bounds = interval
            .split(',')
            .map(|part| part.split('{').next().unwrap_or("").trim())
            .filter(|p| !p.is_empty() && !p.contains(')'));
        let lo = bounds.next().and_then(parse_number);
        let hi = bounds.next().and_then(parse_number);
        match (lo, hi) {
            (Some(lo), Some(hi)) => {
                map.insert(name.trim().to_string(), (lo, hi));
            }
            _ => {
                return Err(unreadable(format!(
                    "cannot read gappa's interval '{}'",
                    line.trim()
                )));
            }
        }
    }
    Ok(map)
}

fn first_line(text: &str) -> &str {
    text.lines()
        .find(|l| !l.trim().is_empty())
        .unwrap_or("")
        .trim()
}

/// The bound of one job from gappa's output: max(|proved error| over the upper region, the
/// lower region's bound), after checking that every stage's proved range fits its format.
pub fn bound(job: &Job, gappa_output: &str) -> Result<f64, Error> {
    let unproved = |reason: String| Error::Unprovable { n: job.n, reason };
    if job.upper_from.is_none() {
        return Ok(job.lower_bound);
    }
    let results = parse_results(gappa_output)?;
    let (lo, hi) = *results.get("out - Mout").ok_or_else(|| {
        unproved(format!(
            "gappa did not bound the error: {}",
            first_line(gappa_output)
        ))
    })?;
    for (name, fmin, fmax) in &job.ranges {
        let (rlo, rhi) = results
            .get(name.as_str())
            .ok_or_else(|| unproved(format!("gappa did not bound stage {name}")))?;
        if *rlo < *fmin || *rhi > *fmax {
            return Err(unproved(format!(
                "stage {name} may leave its format: gappa proves only [{rlo}, {rhi}] against {fmin}..={fmax}"
            )));
        }
    }
    Ok(lo.abs().max(hi.abs()).max(job.lower_bound))
}

/// Up to 8 exponents of a set, spread evenly on a log scale, always with its ends: those
/// `budget` proves bounds for by default.
pub fn spread(ns: &[u32]) -> Vec<u32> {
    if ns.len() <= 8 {
        return ns.to_vec();
    }
    let (lo, hi) = (f64::from(ns[0]), f64::from(ns[ns.len() - 1]));
    let mut picked: Vec<u32> = (0..8)
        .map(|j| {
            let target = lo * (hi / lo).powf(f64::from(j) / 7.0);
            *ns.iter()
                .min_by(|a, b| {
                    (f64::from(**a) - target)
                        .abs()
                        .total_cmp(&(f64::from(**b) - target).abs())
                })
                .expect("a non-empty set")
        })
        .collect();
    picked.dedup();
    picked
}

/// Runs gappa on a script: what it printed, or `None` when gappa is not installed.
pub type RunGappa<'a> = &'a (dyn Fn(&str) -> Result<Option<String>, Error> + Sync);

/// Proves bounds with gappa (`run`) for the exponents `ns` of the datapath, in parallel
/// (`tick` after each), and adds them to the report beside its exhaustive figures: a bound
/// per exponent and how it was proved, or a note saying why there is none (gappa missing, or
/// the exponents no bound could be proved for and why).
pub fn add_formal_bounds(
    dp: &Datapath,
    report: &mut crate::analysis::budget::BudgetReport,
    ns: &[u32],
    run: RunGappa<'_>,
    tick: &(dyn Fn() + Sync),
) -> Result<(), Error> {
    use rayon::prelude::*;
    let jobs: Vec<(u32, Result<Job, Error>)> = ns
        .iter()
        .filter_map(|&n| dp.constants_for(n).map(|nc| (n, job(dp, nc))))
        .collect();
    // Per exponent: its bound (NaN when none was proved) and how, or why not; `None` when
    // gappa is not installed.
    type Proved = Option<(u32, f64, String)>;
    let results: Vec<Result<Proved, Error>> = jobs
        .par_iter()
        .map(|(n, job)| {
            let job = match job {
                Ok(j) => j,
                Err(why) => return Ok(Some((*n, f64::NAN, why.to_string()))),
            };
            let output = if job.upper_from.is_some() {
                match run(&job.script)? {
                    Some(text) => text,
                    None => return Ok(None),
                }
            } else {
                String::new()
            };
            Ok(Some(match bound(job, &output) {
                Ok(b) => {
                    let how = match job.upper_from {
                        Some(0) => "gappa on every code".to_string(),
                        Some(k) => format!(
                            "gappa from code {k}; below it, where a model cuts the base, monotonicity bounds the error by {:.3e}",
                            job.lower_bound
                        ),
                        None => "every code is cut: monotonicity alone".to_string(),
                    };
                    (*n, b, how)
                }
                Err(why) => (*n, f64::NAN, why.to_string()),
            }))
        })
        .inspect(|_| tick())
        .collect();
    let out_lsb = report.out_lsb;
    let mut failures = Vec::new();
    for r in results {
        let Some((n, bound, how)) = r? else {
            report.formal_note = Some(
                "gappa is not installed (Debian package `gappa`): no formal bound, only the exhaustive figures."
                    .into(),
            );
            report.formal.clear();
            return Ok(());
        };
        if bound.is_nan() {
            failures.push(format!("n = {n}: {how}"));
            continue;
        }
        let exhaustive = report
            .per_n
            .iter()
            .find(|p| p.n == n)
            .map_or(f64::NAN, |p| p.out_quant_max_ulp);
        report.formal.push(crate::analysis::budget::FormalBound {
            n,
            bound,
            bound_ulp: bound / out_lsb,
            exhaustive_ulp: exhaustive,
            how,
        });
    }
    if !failures.is_empty() {
        report.formal_note = Some(format!("No bound proved for {}", failures.join("; ")));
    }
    Ok(())
}
