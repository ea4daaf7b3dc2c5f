//! Calibration of the analytic cost model against yosys: a seeded sample of configurations,
//! the records of what yosys counted for each, and the least-squares fit of the model's
//! coefficients (the records live in `data/calibration/`; `specfx calibrate` writes them).

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

use crate::cycle::Arch;
use crate::error::Error;
use crate::fixed::{Format, Overflow, Rounding};
use crate::hdl::cost::{features, Features, Target};
use crate::nset::NSet;
use crate::pipeline::{Config, Datapath, Depth, DepthStep, StageSpec, Variant};
use crate::reference::lobe::Cutoff;

/// One synthesised configuration: what was built and what yosys counted. A configuration
/// yosys failed on is not a record: it is never stored, and a later run tries it again.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Record {
    /// Index in the seeded sample.
    pub index: u64,
    /// The microarchitecture synthesised.
    pub arch: Arch,
    /// The complete configuration.
    pub config: Config,
    /// yosys LUTs (logic gates for the generic target).
    pub luts: u64,
    /// yosys carry cells.
    pub carries: u64,
    /// yosys DSP blocks.
    pub dsps: u64,
    /// yosys flip-flops.
    pub ffs: u64,
}

fn format(signed: bool, int: i32, frac: i32) -> Format {
    Format::new(signed, int, frac).expect("sampled formats are in range")
}

fn stage(rng: &mut ChaCha8Rng, f: Format) -> StageSpec {
    StageSpec {
        format: f,
        rounding: Rounding::ALL[rng.gen_range(0..Rounding::ALL.len())],
        overflow: Overflow::ALL[rng.gen_range(0..Overflow::ALL.len())],
    }
}

/// Configuration `index` of the calibration sample drawn with `seed`, and its architecture:
/// k = 1..7, plain or minimax, every cutoff, rounding and overflow mode, input widths
/// 8..16 bits, internal stages 6..24 fraction bits, coefficient and output 4..16 fraction
/// bits, multiplier latencies 1..3, and n sets that are ranges, lists or powers of two.
/// From index [`DEPTH_FROM_INDEX`] on, half the configurations also get a per-n depth (a step
/// list giving some exponents fewer than k squarings: the bypass multiplexers), drawn apart so
/// that the rest of the configuration is the one the index always had.
/// Draws that the datapath rejects are drawn again (deterministically).
pub fn sample(seed: u64, index: u64) -> (Config, Arch) {
    let (cfg, arch) = sample_fixed(seed, index);
    if index < DEPTH_FROM_INDEX {
        return (cfg, arch);
    }
    let mut rng = ChaCha8Rng::seed_from_u64(!seed ^ index.wrapping_mul(0xD1B5_4A32_D192_ED03));
    if cfg.k < 2 || rng.gen_bool(0.5) {
        return (cfg, arch);
    }
    let values = cfg.n.values();
    // (A configuration no drawn rule suits keeps its fixed depth.)
    for _ in 0..64 {
        // One to three steps over the set's exponents, the first from its smallest, with a
        // depth below k somewhere.
        let mut froms: Vec<u32> = (1..rng.gen_range(1..=3))
            .map(|_| values[rng.gen_range(0..values.len())])
            .chain([values[0]])
            .collect();
        froms.sort_unstable();
        froms.dedup();
        let steps: Vec<DepthStep> = froms
            .iter()
            .map(|&from| DepthStep {
                from,
                j: rng.gen_range(1..=cfg.k),
            })
            .collect();
        let mut with = cfg.clone();
        with.depth = Depth::Steps(steps);
        if with.has_bypass() && Datapath::new(with.clone()).is_ok() {
            return (with, arch);
        }
    }
    (cfg, arch)
}

/// The first index of the calibration sample that may carry a per-n depth (the records before
/// it were drawn before the depth existed, and keep their configurations).
pub const DEPTH_FROM_INDEX: u64 = 120;

fn sample_fixed(seed: u64, index: u64) -> (Config, Arch) {
    let mut rng = ChaCha8Rng::seed_from_u64(seed ^ index.wrapping_mul(0x9E37_79B9_7F4A_7C15));
    loop {
        let mut cfg = Config::baseline();
        cfg.name = format!("cal{index}");
        cfg.variant = if rng.gen_bool(0.5) {
            Variant::Plain
        } else {
            Variant::Minimax
        };
        cfg.k = rng.gen_range(crate::reference::lobe::K_RANGE);
        cfg.cutoff = Cutoff::ALL[rng.gen_range(0..Cutoff::ALL.len())];
        cfg.n = match rng.gen_range(0..3) {
            0 => {
                let lo = rng.gen_range(1..=64);
                NSet::range(lo, lo + rng.gen_range(0..=1000)).expect("valid range")
            }
            1 => {
                let mut v: Vec<u32> = (0..rng.gen_range(1..=8))
                    .map(|_| rng.gen_range(1..=2048))
                    .collect();
                v.sort_unstable();
                v.dedup();
                NSet::from_values(&v).expect("valid list")
            }
            _ => {
                let lo = rng.gen_range(0..=4);
                let hi = rng.gen_range(lo..=10);
                NSet::from_values(&(lo..=hi).map(|e| 1u32 << e).collect::<Vec<_>>())
                    .expect("valid list")
            }
        };
        let cf = rng.gen_range(8..=16);
        cfg.c.format = format(false, 1, cf);
        cfg.d.format = format(true, 1, cf);
        let t_int = rng.gen_range(1..=3);
        let t = format(true, t_int, rng.gen_range(6..=24));
        cfg.t = stage(&mut rng, t);
        let b = format(rng.gen_bool(0.2), 1, rng.gen_range(6..=24));
        cfg.b = stage(&mut rng, b);
        cfg.square = (0..cfg.k)
            .map(|_| {
                let f = format(false, 1, rng.gen_range(6..=24));
                stage(&mut rng, f)
            })
            .collect();
        cfg.coef.format = format(false, rng.gen_range(8..=11), rng.gen_range(4..=16));
        cfg.coef.rounding = Rounding::ALL[rng.gen_range(0..Rounding::ALL.len())];
        let out = format(false, rng.gen_range(8..=11), rng.gen_range(4..=16));
        cfg.out = stage(&mut rng, out);
        cfg.minimax.a_format = format(false, 11, rng.gen_range(8..=16));
        cfg.minimax.offset_format = format(false, 1, rng.gen_range(8..=16));
        cfg.latency.mul = rng.gen_range(1..=3);
        cfg.latency.sub = rng.gen_range(1..=2);
        cfg.latency.add = rng.gen_range(1..=2);
        let arch = if rng.gen_bool(0.3) {
            Arch::Folded
        } else {
            Arch::Pipelined
        };
        if Datapath::new(cfg.clone()).is_ok() {
            return (cfg, arch);
        }
    }
}

/// The records of several files of one target joined in index order (`calibrate merge`):
/// each set named by its file; refused when a record was not drawn with `seed`, or one index
/// has two different records (the same record twice is one).
pub fn merge_records(seed: u64, sets: Vec<(String, Vec<Record>)>) -> Result<Vec<Record>, Error> {
    let mut by_index: std::collections::BTreeMap<u64, (Record, String)> = Default::default();
    for (name, records) in sets {
        for r in records {
            if sample(seed, r.index).0 != r.config {
                return Err(Error::Merge {
                    problem: format!(
                        "{name}: record {} was drawn with another seed than --seed {seed} or another sampler",
                        r.index
                    ),
                });
            }
            match by_index.get(&r.index) {
                Some((other, from)) if *other != r => {
                    return Err(Error::Merge {
                        problem: format!(
                            "{name}: record {} differs from the one in {from}: expected one record per configuration",
                            r.index
                        ),
                    })
                }
                Some(_) => {}
                None => {
                    by_index.insert(r.index, (r, name.clone()));
                }
            }
        }
    }
    Ok(by_index.into_values().map(|(r, _)| r).collect())
}

/// The coefficients of one target's model: logic cells as a weighted sum of the features,
/// flip-flops as a multiple of the register bits.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Coefficients {
    /// Logic cells per feature, in the order of [`Features::logic`].
    pub logic: [f64; Features::LOGIC],
    /// Flip-flops per register bit.
    pub ff_per_register_bit: f64,
}

impl Coefficients {
    /// How many coefficients a fit determines: one per logic feature, and the flip-flops per
    /// register bit. A fit over fewer records is underdetermined: its error (0 then) says
    /// nothing about the model.
    pub const COUNT: usize = Features::LOGIC + 1;
}

/// How well a fitted model matches the records.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct FitError {
    /// Number of records.
    pub records: usize,
    /// Median of |model / yosys - 1| over the records (logic cells).
    pub median_rel: f64,
    /// 90th percentile of the same.
    pub p90_rel: f64,
    /// Largest of the same.
    pub max_rel: f64,
    /// Median of |model / yosys - 1| for flip-flops.
    pub ff_median_rel: f64,
    /// Share of records whose DSP count the model gives exactly.
    pub dsp_exact: f64,
}

/// Least squares on relative error (each row weighted by 1 / yosys), every coefficient kept
/// non-negative: a feature whose coefficient comes out negative is dropped and the rest refitted.
pub fn fit_logic(rows: &[(Features, f64)]) -> [f64; Features::LOGIC] {
    let mut active = [true; Features::LOGIC];
    loop {
        let idx: Vec<usize> = (0..Features::LOGIC).filter(|&i| active[i]).collect();
        let p = idx.len();
        let mut ata = vec![vec![0.0; p]; p];
        let mut atb = vec![0.0; p];
        for (f, y) in rows {
            let w = 1.0 / y.max(1.0);
            let x = f.logic();
            for (a, &i) in idx.iter().enumerate() {
                atb[a] += w * w * x[i] * y;
                for (b, &j) in idx.iter().enumerate() {
                    ata[a][b] += w * w * x[i] * x[j];
                }
            }
        }
        let sol = solve(ata, atb);
        let mut out = [0.0; Features::LOGIC];
        let mut negative = None;
        for (a, &i) in idx.iter().enumerate() {
            out[i] = sol[a];
            if sol[a] < 0.0 && negative.is_none_or(|(_, v)| sol[a] < v) {
                negative = Some((i, sol[a]));
            }
        }
        match negative {
            Some((i, _)) => active[i] = false,
            None => return out,
        }
    }
}

/// Solves a small symmetric system by Gaussian elimination with partial pivoting; a singular
/// direction (a feature that never varies) gets a zero coefficient.
fn solve(mut a: Vec<Vec<f64>>, mut b: Vec<f64>) -> Vec<f64> {
    let n = b.len();
    let scale = a
        .iter()
        .enumerate()
        .map(|(i, r)| r[i].abs())
        .fold(0.0, f64::max);
    let mut pivot_of = vec![None; n];
    let mut used = vec![false; n];
    for col in 0..n {
        let Some(row) = (0..n)
            .filter(|&r| !used[r])
            .max_by(|&x, &y| a[x][col].abs().total_cmp(&a[y][col].abs()))
        else {
            break;
        };
        if a[row][col].abs() <= 1e-12 * scale.max(1e-300) {
            continue;
        }
        used[row] = true;
        pivot_of[col] = Some(row);
        for r in 0..n {
            if r != row {
                let f = a[r][col] / a[row][col];
                if f != 0.0 {
                    let pivot_row = a[row].clone();
                    for (x, p) in a[r][col..].iter_mut().zip(&pivot_row[col..]) {
                        *x -= f * p;
                    }
                    b[r] -= f * b[row];
                }
            }
        }
    }
    (0..n)
        .map(|col| pivot_of[col].map_or(0.0, |row| b[row] / a[row][col]))
        .collect()
}

fn percentile(sorted: &[f64], q: f64) -> f64 {
    if sorted.is_empty() {
        return 0.0;
    }
    let i = ((sorted.len() - 1) as f64 * q).round() as usize;
    sorted[i]
}

/// Fits a target's coefficients to its records and measures the fit on the same records; a
/// fit over no record is an error.
pub fn fit(records: &[Record], target: Target) -> Result<(Coefficients, FitError), Error> {
    if records.is_empty() {
        return Err(Error::Config {
            key: format!("calibration of {}", target.name()),
            problem: "no records to fit: a fit needs at least one configuration yosys synthesised"
                .to_string(),
        });
    }
    let mut rows = Vec::with_capacity(records.len());
    let mut regs = (0.0, 0.0);
    for r in records {
        let dp = Datapath::new(r.config.clone()).map_err(|e| Error::Config {
            key: format!("calibration record {}", r.index),
            problem: e.to_string(),
        })?;
        let f = features(&dp, r.arch, target);
        regs.0 += f.register_bits as f64 * r.ffs as f64;
        regs.1 += (f.register_bits as f64).powi(2);
        rows.push((f, r));
    }
    let logic = fit_logic(
        &rows
            .iter()
            .map(|(f, r)| (f.clone(), r.luts as f64))
            .collect::<Vec<_>>(),
    );
    let coefficients = Coefficients {
        logic,
        ff_per_register_bit: if regs.1 > 0.0 { regs.0 / regs.1 } else { 0.0 },
    };
    Ok((coefficients, measure(&rows, &coefficients)))
}

/// The fit error of `coefficients` on `(features, record)` pairs.
fn measure(rows: &[(Features, &Record)], c: &Coefficients) -> FitError {
    let rel = |model: f64, real: u64| (model / (real as f64).max(1.0) - 1.0).abs();
    let mut logic: Vec<f64> = rows
        .iter()
        .map(|(f, r)| rel(f.logic_cells(&c.logic), r.luts))
        .collect();
    let mut ffs: Vec<f64> = rows
        .iter()
        .map(|(f, r)| rel(f.register_bits as f64 * c.ff_per_register_bit, r.ffs))
        .collect();
    logic.sort_by(f64::total_cmp);
    ffs.sort_by(f64::total_cmp);
    let exact = rows.iter().filter(|(f, r)| f.dsps == r.dsps).count();
    FitError {
        records: rows.len(),
        median_rel: percentile(&logic, 0.5),
        p90_rel: percentile(&logic, 0.9),
        max_rel: logic.last().copied().unwrap_or(0.0),
        ff_median_rel: percentile(&ffs, 0.5),
        dsp_exact: if rows.is_empty() {
            1.0
        } else {
            exact as f64 / rows.len() as f64
        },
    }
}

/// What an earlier specfx stored for a configuration yosys failed on: a line with a `failed`
/// key (not a record: left out, so that the configuration is synthesised again).
#[derive(Deserialize)]
struct StoredFailure {
    #[serde(default)]
    failed: Option<serde::de::IgnoredAny>,
}

/// Reads a JSON Lines file of records (`path` names it in errors). Left out: the failures an
/// earlier specfx stored (a line with a `failed` key), and a last line cut short without its
/// newline (a write that was interrupted); both are synthesised again by the next run.
pub fn read_records(text: &str, path: &str) -> Result<Vec<Record>, Error> {
    let lines: Vec<&str> = text.lines().collect();
    let mut records = Vec::with_capacity(lines.len());
    for (i, l) in lines.iter().enumerate() {
        let stored_failure =
            || serde_json::from_str::<StoredFailure>(l).is_ok_and(|f| f.failed.is_some());
        if l.trim().is_empty() || stored_failure() {
            continue;
        }
        match serde_json::from_str::<Record>(l) {
            Ok(r) => records.push(r),
            Err(e)
                if i + 1 == lines.len()
                    && !text.ends_with('\n')
                    && e.classify() == serde_json::error::Category::Eof => {}
            Err(e) => {
                return Err(Error::Config {
                    key: format!("{path}: line {}", i + 1),
                    problem: format!("not a calibration record: {e}"),
                });
            }
        }
    }
    Ok(records)
}

/// One target's refit beside the committed calibration.
#[derive(Debug, Serialize)]
pub struct TargetFit {
    /// The fit of the records now in the data directory.
    pub fitted: Calibration,
    /// The calibration the model uses (compiled in).
    pub committed: Calibration,
    /// Configurations yosys failed on in this run: not records (left out of the fit, not
    /// stored), tried again by the next run.
    pub failed: usize,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn samples_are_valid_and_reproducible() {
        for i in 0..40 {
            let (a, arch_a) = sample(7, i);
            let (b, arch_b) = sample(7, i);
            assert_eq!((a.clone(), arch_a), (b, arch_b));
            assert!(Datapath::new(a).is_ok());
        }
        assert_ne!(sample(7, 1).0, sample(7, 2).0);
    }

    #[test]
    fn the_per_n_depth_is_drawn_from_its_index_on_in_both_architectures() {
        // Before DEPTH_FROM_INDEX every depth is fixed; after it, some configurations of each
        // architecture bypass stages (the bypass features are then fitted, not guessed), and the
        // rest of a drawn configuration is the one its index had without the depth.
        let mut bypassing = std::collections::BTreeSet::new();
        for i in 0..DEPTH_FROM_INDEX + 80 {
            let (cfg, arch) = sample(1, i);
            let (fixed, fixed_arch) = sample_fixed(1, i);
            assert_eq!(arch, fixed_arch);
            assert_eq!(
                Config {
                    depth: Depth::Fixed,
                    ..cfg.clone()
                },
                fixed
            );
            if i < DEPTH_FROM_INDEX {
                assert!(cfg.depth.is_fixed(), "index {i}");
            } else if !cfg.depth.is_fixed() {
                assert!(cfg.has_bypass(), "index {i}");
                assert!(Datapath::new(cfg).is_ok(), "index {i}");
                bypassing.insert(format!("{arch:?}"));
            }
        }
        assert_eq!(bypassing.len(), 2, "{bypassing:?}");
    }

    #[test]
    fn stored_failures_and_a_torn_last_line_are_not_records() {
        let (config, arch) = sample(1, 0);
        let record = Record {
            index: 0,
            arch,
            config,
            luts: 10,
            carries: 2,
            dsps: 1,
            ffs: 5,
        };
        let line = serde_json::to_string(&record).unwrap();
        let failed = r#"{"index":1,"arch":"pipelined","config":{"name":"x"},"luts":0,"carries":0,"dsps":0,"ffs":0,"failed":"yosys not found"}"#;
        let torn = &line[..line.len() / 2];
        let text = format!("{line}\n{failed}\n{torn}");
        assert_eq!(
            read_records(&text, "f").unwrap(),
            std::slice::from_ref(&record)
        );
        // A torn line followed by a newline, or anywhere but last, is an error that names it.
        for bad in [format!("{torn}\n"), format!("{torn}\n{line}\n")] {
            let e = read_records(&bad, "f").unwrap_err().to_string();
            assert!(e.starts_with("f: line 1: not a calibration record"), "{e}");
        }
        assert!(fit(&[], Target::Ice40)
            .unwrap_err()
            .to_string()
            .contains("no records to fit"));
        assert_eq!(fit(&[record], Target::Ice40).unwrap().1.records, 1);
    }

    #[test]
    fn least_squares_recovers_known_coefficients() {
        // y = 2 x0 + 0.5 x2 exactly: the fit recovers them, and a feature whose best
        // coefficient is negative is held at zero.
        let mut rows = Vec::new();
        for i in 0..30u64 {
            let f = Features {
                adder_bits: i * 3 + 1,
                rounding_bits: (i * 7) % 11,
                overflow_bits: (i * i) % 13 + 2,
                ..Features::default()
            };
            let x = f.logic();
            rows.push((f, 2.0 * x[0] + 0.5 * x[2]));
        }
        let c = fit_logic(&rows);
        assert!((c[0] - 2.0).abs() < 1e-9, "{c:?}");
        assert!(c[1].abs() < 1e-9, "{c:?}");
        assert!((c[2] - 0.5).abs() < 1e-9, "{c:?}");
        assert!(c.iter().all(|&v| v >= 0.0));
    }
}

/// The fitted coefficients of one target, and the fit's error on its records.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Calibration {
    /// The target.
    pub target: Target,
    /// The coefficients.
    pub coefficients: Coefficients,
    /// The fit's error over the records it was fitted to.
    pub error: FitError,
}

/// The model's coefficients for a target (generic and generic-fast share one fit, made
/// against `generic-fast`, the mapping a sample of hundreds can afford).
pub fn coefficients(target: Target) -> Coefficients {
    calibration(target).coefficients
}

/// The committed calibration of a target: `specfx calibrate --fit-only` refits it from the
/// records in `data/calibration/`, and a test checks the two agree.
pub fn calibration(target: Target) -> Calibration {
    let (logic, ff_per_register_bit, error) = match target {
        Target::Ice40 => (
            [
                0.2995448649364531,
                0.6073044007967087,
                2.3080426815950554,
                1.6411978206759201,
                0.147325602269583,
                0.7202834381496331,
                0.817094271759525,
                0.3403512746473868,
                0.4961682983809033,
                11.410389959936621,
            ],
            0.8967415752626459,
            (
                318,
                0.09239949773401224,
                0.22512926324512716,
                0.6827452112178467,
                0.03831335243420997,
                0.8836477987421384,
            ),
        ),
        Target::Xilinx => (
            [
                0.6970532189372445,
                0.0,
                1.6239828524190278,
                0.0,
                0.2121872826302171,
                0.20610343482667892,
                0.28186359524953064,
                0.14127127155720623,
                0.36897815827845953,
                1.0023694323068644,
            ],
            0.25656874340187613,
            (
                240,
                0.1339747818575978,
                0.3120625341973009,
                0.8530837676405194,
                0.3569334700632464,
                0.8541666666666666,
            ),
        ),
        Target::Generic | Target::GenericFast => (
            [
                0.0,
                0.0,
                3.4194276275012654,
                10.705789792051277,
                0.0,
                0.0,
                19.55373360705849,
                0.4892121446356437,
                1.0924908351179003,
                1184.6463340113744,
            ],
            0.9557557280334504,
            (
                240,
                0.07663680682441298,
                0.15891797640703198,
                0.6545236579936824,
                0.03675197617187842,
                1.0,
            ),
        ),
    };
    let (records, median_rel, p90_rel, max_rel, ff_median_rel, dsp_exact) = error;
    Calibration {
        target,
        coefficients: Coefficients {
            logic,
            ff_per_register_bit,
        },
        error: FitError {
            records,
            median_rel,
            p90_rel,
            max_rel,
            ff_median_rel,
            dsp_exact,
        },
    }
}
