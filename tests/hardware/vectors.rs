//! `specfx vectors` through the built binary: the row order, the codes with a non-zero output
//! every n gets, the coverage figures of the manifest, and the CSV columns against the
//! `$readmemh` files, each checked against figures the test derives itself.

use crate::common::{config_path, specfx};

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

use serde_json::Value;
use specfx::fixed::Event;
use specfx::pipeline::{Config, Datapath};

/// A fresh, empty temporary directory that is removed when dropped.
fn temp_dir() -> tempfile::TempDir {
    tempfile::tempdir().unwrap()
}

/// Few non-zero outputs: a coarse output (LSB 2) and, at n = 1500, only the last codes below
/// 1.0 give a non-zero output; at n = 1..=3 the coefficient rounds to 0, so every output is 0.
const SPARSE: &str = "name = \"sparse\"
n = \"1..=3,300..=302,1500\"
[c]
format = \"u1.10\"
[d]
format = \"s1.10\"
[coef]
format = \"u9.8\"
[out]
format = \"u4.-1\"
";

/// Runs `specfx vectors --out <dir>/<name>` with `args` and returns the directory, the
/// manifest and the printed output; panics if the command fails.
fn vectors(dir: &Path, name: &str, args: &[&str]) -> (PathBuf, Value, String) {
    let out = dir.join(name);
    let mut a = vec!["vectors", "--out", out.to_str().unwrap()];
    a.extend_from_slice(args);
    let o = specfx(&a);
    assert!(
        o.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    let manifest: Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("manifest.json")).unwrap()).unwrap();
    (out, manifest, String::from_utf8(o.stdout).unwrap())
}

/// The CSV: header cells, then rows of integers.
struct Csv {
    header: Vec<String>,
    rows: Vec<Vec<i64>>,
}

impl Csv {
    fn read(dir: &Path) -> Csv {
        let text = std::fs::read_to_string(dir.join("vectors.csv")).unwrap();
        let mut lines = text.lines();
        let header = lines
            .next()
            .unwrap()
            .split(',')
            .map(str::to_string)
            .collect();
        let rows = lines
            .map(|l| l.split(',').map(|x| x.parse().unwrap()).collect())
            .collect();
        Csv { header, rows }
    }

    /// The index of the column of a port (header cell `<port>:<format>`).
    fn col(&self, port: &str) -> usize {
        self.header
            .iter()
            .position(|h| h.split(':').next() == Some(port))
            .unwrap_or_else(|| panic!("no column {port} in {:?}", self.header))
    }

    /// The format written in a column's header cell.
    fn format(&self, port: &str) -> Fmt {
        Fmt::parse(self.header[self.col(port)].split(':').nth(1).unwrap())
    }

    /// (n, c) of every row, in file order.
    fn inputs(&self) -> Vec<(i64, i64)> {
        let (n, c) = (self.col("in_n"), self.col("in_c"));
        self.rows.iter().map(|r| (r[n], r[c])).collect()
    }
}

/// A format read from its notation by the test: signedness, width, raw range.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Fmt {
    signed: bool,
    width: u32,
    frac: i32,
}

impl Fmt {
    fn parse(s: &str) -> Fmt {
        let signed = match &s[..1] {
            "s" => true,
            "u" => false,
            other => panic!("format {s}: sign letter {other}"),
        };
        let (int, frac) = s[1..].split_once('.').unwrap();
        let (int, frac): (i32, i32) = (int.parse().unwrap(), frac.parse().unwrap());
        Fmt {
            signed,
            width: (int + frac) as u32,
            frac,
        }
    }

    fn min_raw(self) -> i128 {
        if self.signed {
            -(1i128 << (self.width - 1))
        } else {
            0
        }
    }

    fn max_raw(self) -> i128 {
        if self.signed {
            (1i128 << (self.width - 1)) - 1
        } else {
            (1i128 << self.width) - 1
        }
    }

    /// A `$readmemh` word read back: `ceil(width / 4)` hex digits, two's complement.
    fn decode(self, word: &str) -> i64 {
        assert_eq!(word.len() as u32, self.width.div_ceil(4), "word {word}");
        let v = i128::from_str_radix(word, 16).unwrap();
        assert!(v < 1i128 << self.width, "word {word} wider than {self:?}");
        let v = if self.signed && v >= 1i128 << (self.width - 1) {
            v - (1i128 << self.width)
        } else {
            v
        };
        i64::try_from(v).unwrap()
    }
}

fn datapath_of(toml: &str) -> Datapath {
    Datapath::new(Config::from_toml(toml).unwrap()).unwrap()
}

fn datapath_of_file(path: &str) -> Datapath {
    if path == "baseline" {
        return Datapath::new(Config::baseline()).unwrap();
    }
    datapath_of(&std::fs::read_to_string(path).unwrap())
}

/// The n that change between consecutive rows.
fn n_changes(inputs: &[(i64, i64)]) -> usize {
    inputs.windows(2).filter(|w| w[0].0 != w[1].0).count()
}

#[test]
fn interleaved_is_a_seeded_permutation_of_sorted() {
    let dir = temp_dir();
    let base = [
        "--n",
        "16,100,1024",
        "--cases",
        "corner,random:300",
        "--seed",
        "5",
    ];
    fn with<'a>(base: &[&'a str], extra: &[&'a str]) -> Vec<&'a str> {
        base.iter().chain(extra).copied().collect()
    }
    let (sorted_dir, sorted_m, _) =
        vectors(dir.path(), "sorted", &with(&base, &["--order", "sorted"]));
    let (inter_dir, inter_m, _) = vectors(dir.path(), "inter", &with(&base, &[]));
    let (again_dir, _, _) = vectors(
        dir.path(),
        "again",
        &with(&base, &["--order", "interleaved"]),
    );
    assert_eq!(sorted_m["order"], "sorted");
    assert_eq!(inter_m["order"], "interleaved");
    let sorted = Csv::read(&sorted_dir).inputs();
    let inter = Csv::read(&inter_dir).inputs();
    // Sorted: by n, then c, each n one run.
    assert!(sorted.windows(2).all(|w| w[0] < w[1]));
    assert_eq!(n_changes(&sorted), 2);
    // Interleaved: the same rows (the order does not change the random draws), another order.
    assert_ne!(inter, sorted);
    let mut back = inter.clone();
    back.sort();
    assert_eq!(back, sorted);
    let rows = |d: &Path| {
        let mut r = Csv::read(d).rows;
        r.sort();
        r
    };
    assert_eq!(rows(&inter_dir), rows(&sorted_dir));
    assert_eq!(inter_m["n_vectors"], sorted_m["n_vectors"]);
    // Deterministic: the same arguments give byte-identical files.
    for entry in std::fs::read_dir(&inter_dir).unwrap() {
        let name = entry.unwrap().file_name();
        assert_eq!(
            std::fs::read(inter_dir.join(&name)).unwrap(),
            std::fs::read(again_dir.join(&name)).unwrap(),
            "{name:?}"
        );
    }
    // Another seed, same cases (corner only: no random draws), another order.
    let corner = |seed: &str, name: &str| {
        let (d, _, _) = vectors(
            dir.path(),
            name,
            &["--n", "16,100,1024", "--cases", "corner", "--seed", seed],
        );
        Csv::read(&d).inputs()
    };
    let (a, b) = (corner("5", "c5"), corner("6", "c6"));
    assert_ne!(a, b);
    let (mut sa, mut sb) = (a.clone(), b.clone());
    sa.sort();
    sb.sort();
    assert_eq!(sa, sb);
}

/// For a uniformly random permutation of a multiset with `k_i` copies of value i among N, two
/// neighbours differ with probability 1 - sum k_i (k_i - 1) / (N (N - 1)).
fn expected_change_share(inputs: &[(i64, i64)]) -> f64 {
    let mut counts: BTreeMap<i64, f64> = BTreeMap::new();
    for &(n, _) in inputs {
        *counts.entry(n).or_default() += 1.0;
    }
    let total = inputs.len() as f64;
    1.0 - counts.values().map(|k| k * (k - 1.0)).sum::<f64>() / (total * (total - 1.0))
}

#[test]
fn interleaved_changes_n_on_most_rows() {
    let dir = temp_dir();
    for (n_set, cases) in [("16..=47", "corner,random:2000"), ("16,100,1024", "corner")] {
        let (d, _, _) = vectors(
            dir.path(),
            "v",
            &["--n", n_set, "--cases", cases, "--force"],
        );
        let inputs = Csv::read(&d).inputs();
        let share = n_changes(&inputs) as f64 / (inputs.len() - 1) as f64;
        let expected = expected_change_share(&inputs);
        // 32 exponents: about 97% of neighbours differ; 3: about 2/3 (the standard deviation
        // of the share is about 0.004 over 2000 rows, 0.07 over 50). Sorted would give
        // 31 / 2000 and 2 / 50.
        assert!(share > 0.5, "{n_set}: {share}");
        if inputs.len() > 1000 {
            assert!(
                (share - expected).abs() < 0.03,
                "{n_set}: {share} against {expected}"
            );
        }
    }
}

/// Every code of the input format whose output (through the public scalar `eval`) is not 0,
/// per n: the slow oracle of the live codes.
fn nonzero_codes(dp: &Datapath) -> BTreeMap<u32, BTreeSet<i64>> {
    let codes = dp.input_codes();
    dp.constants()
        .iter()
        .map(|nc| {
            let set = codes
                .clone()
                .filter(|&c| dp.eval(c, nc).values[dp.stage_out()] != 0)
                .collect();
            (nc.n, set)
        })
        .collect()
}

#[test]
fn every_n_with_a_nonzero_output_has_nonzero_vectors() {
    let dir = temp_dir();
    let sparse_path = dir.path().join("sparse.toml");
    std::fs::write(&sparse_path, SPARSE).unwrap();
    let configs = [
        sparse_path.to_string_lossy().into_owned(),
        config_path("narrow_trn_wrap.toml"),
        config_path("conv_sym_k5.toml"),
        config_path("pow2_shift.toml"),
    ];
    let mut bites = false;
    for config in &configs {
        let dp = datapath_of_file(config);
        let one = dp.one_code();
        let oracle = nonzero_codes(&dp);
        for cases in ["corner", "random:40"] {
            let (d, m, _) = vectors(
                dir.path(),
                "v",
                &["--config", config, "--cases", cases, "--force"],
            );
            let csv = Csv::read(&d);
            let (ic, inn, io) = (csv.col("in_c"), csv.col("in_n"), csv.col("expected_out"));
            let mut want_without = Vec::new();
            for (&n, all) in &oracle {
                // Codes up to 1.0 (above it, the input is clamped to 1.0's output).
                let below: BTreeSet<i64> = all.iter().copied().filter(|&c| c <= one).collect();
                let got: BTreeSet<i64> = csv
                    .rows
                    .iter()
                    .filter(|r| r[inn] == i64::from(n) && r[ic] <= one && r[io] != 0)
                    .map(|r| r[ic])
                    .collect();
                assert!(got.is_subset(&below), "{config} n = {n}");
                assert!(
                    got.len() >= below.len().min(4),
                    "{config} {cases} n = {n}: {} of the {} codes with a non-zero output",
                    got.len(),
                    below.len()
                );
                bites |= (1..20).contains(&below.len());
                if all.is_empty() {
                    want_without.push(n);
                }
            }
            let cov = &m["coverage"];
            let without: Vec<u32> = cov["n_without_nonzero"]
                .as_array()
                .unwrap()
                .iter()
                .map(|v| v.as_u64().unwrap() as u32)
                .collect();
            assert_eq!(without, want_without, "{config}");
            assert_eq!(
                cov["n_with_nonzero"].as_u64().unwrap() as usize,
                oracle.len() - want_without.len()
            );
        }
    }
    // The sparse configuration has an n with a handful of non-zero codes below 1.0 (so corner
    // cases alone would not give four) and n without any.
    assert!(bites);
    let sparse = nonzero_codes(&datapath_of(SPARSE));
    assert!(sparse[&1].is_empty() && sparse[&1500].iter().filter(|&&c| c <= 1024).count() == 4);
}

/// The coverage object recomputed from vectors.csv (and, for the overflow events, from the
/// public scalar `eval` of each row).
fn check_coverage(config: &str, dir: &Path, m: &Value, printed: &str) {
    let dp = datapath_of_file(config);
    let csv = Csv::read(dir);
    let cov = &m["coverage"];
    let (ic, inn, io) = (csv.col("in_c"), csv.col("in_n"), csv.col("expected_out"));
    let rows = &csv.rows;
    let nonzero = rows.iter().filter(|r| r[io] != 0).count() as u64;
    assert_eq!(cov["nonzero_outputs"], nonzero);
    assert_eq!(
        cov["nonzero_share"].as_f64().unwrap(),
        nonzero as f64 / rows.len() as f64
    );
    let mut per_n: BTreeMap<i64, bool> = BTreeMap::new();
    for r in rows {
        *per_n.entry(r[inn]).or_default() |= r[io] != 0;
    }
    assert_eq!(cov["n_exponents"], per_n.len() as u64);
    assert_eq!(
        cov["n_with_nonzero"],
        per_n.values().filter(|&&x| x).count() as u64
    );
    let without: Vec<i64> = per_n
        .iter()
        .filter(|&(_, &x)| !x)
        .map(|(&n, _)| n)
        .collect();
    assert_eq!(cov["n_without_nonzero"], serde_json::json!(without));
    let one = dp.one_code();
    assert_eq!(
        cov["input_clamped"],
        rows.iter().filter(|r| r[ic] > one).count() as u64
    );
    // Each stage's column: the probes, the coefficient input, the expected output.
    let k = dp.config().k as usize;
    let mut names: Vec<String> = ["d", "t", "b"].iter().map(|s| s.to_string()).collect();
    names.extend((1..=k).map(|i| format!("sq{i}")));
    names.extend(["coef".to_string(), "out".to_string()]);
    let stages = cov["stages"].as_array().unwrap();
    assert_eq!(stages.len(), names.len());
    // Events and cut flags from the scalar model, row by row.
    let mut events = vec![[0u64; 3]; names.len()];
    let mut cut = 0u64;
    let mut cut_flags = Vec::with_capacity(rows.len());
    for r in rows {
        let nc = dp.constants_for(r[inn] as u32).unwrap();
        let p = dp.eval(r[ic], nc);
        cut += u64::from(p.cut);
        cut_flags.push(p.cut);
        for (stage_idx, e) in events.iter_mut().enumerate() {
            match p.events[stage_idx] {
                Event::Wrapped => e[0] += 1,
                Event::Saturated => e[1] += 1,
                Event::Zeroed => e[2] += 1,
                Event::None => {}
            }
        }
    }
    assert_eq!(cov["cut"], cut);
    for (stage_idx, (s, name)) in stages.iter().zip(&names).enumerate() {
        let port = match name.as_str() {
            "coef" => "in_coef".to_string(),
            "out" => "expected_out".to_string(),
            other => format!("probe_{other}"),
        };
        let col = csv.col(&port);
        let fmt = csv.format(&port);
        assert_eq!(s["stage"], name.as_str());
        assert_eq!(Fmt::parse(s["format"].as_str().unwrap()), fmt, "{name}");
        let lo = rows.iter().map(|r| r[col]).min().unwrap();
        let hi = rows.iter().map(|r| r[col]).max().unwrap();
        assert_eq!(
            (s["min_raw"].as_i64(), s["max_raw"].as_i64()),
            (Some(lo), Some(hi))
        );
        assert_eq!(s["format_min_raw"].as_i64().unwrap() as i128, fmt.min_raw());
        assert_eq!(s["format_max_raw"].as_i64().unwrap() as i128, fmt.max_raw());
        let share =
            (hi as i128 - lo as i128 + 1) as f64 / (fmt.max_raw() - fmt.min_raw() + 1) as f64;
        assert_eq!(s["range_share"].as_f64().unwrap(), share, "{name}");
        let got = [&s["wrapped"], &s["saturated"], &s["zeroed"]].map(|v| v.as_u64().unwrap());
        assert_eq!(got, events[stage_idx], "{config} stage {name}");
        // A saturated value sits at an end of the format (or at -max for SAT_SYM).
        let at_end = rows
            .iter()
            .filter(|r| {
                let v = r[col] as i128;
                v == fmt.max_raw() || v == fmt.min_raw() || v == -fmt.max_raw()
            })
            .count() as u64;
        assert!(got[1] <= at_end, "{config} stage {name}");
    }
    check_rounding_boundaries(&dp, &csv, stages, &cut_flags);
    // The printed summary states the same counts.
    let line = printed
        .lines()
        .find(|l| l.starts_with("coverage: "))
        .unwrap_or_else(|| panic!("no coverage line in {printed}"));
    assert!(
        line.starts_with(&format!("coverage: {nonzero} non-zero outputs (")),
        "{line}"
    );
    let n_with = per_n.values().filter(|&&x| x).count();
    assert!(
        line.contains(&format!(
            ", {n_with} of {} n with a non-zero output",
            per_n.len()
        )),
        "{line}"
    );
    let bounds: Vec<String> = stages
        .iter()
        .filter(|s| s["dropped_bits"].as_u64().unwrap() > 0)
        .map(|s| {
            format!(
                "{} {}/{}",
                s["stage"].as_str().unwrap(),
                s["at_boundary"],
                s["next_to_boundary"]
            )
        })
        .collect();
    if !bounds.is_empty() {
        assert!(
            line.contains(&format!(
                ", rounding boundaries (on/next to): {}",
                bounds.join(", ")
            )),
            "{line}"
        );
    }
}

/// Where an exact value `x` with `s` dropped bits lies against the rounding boundary, from the
/// definition (docs/arithmetic.md 2.1): the residue `r = x mod 2^s` equal to the boundary
/// (`2^(s-1)` for the round-to-nearest modes, 0 for TRN and TRN_ZERO) is "on" (0), one beside
/// it modulo 2^s is "next to" (1).
fn boundary_class(x: i128, s: i64, rounding: &str) -> Option<usize> {
    if s < 1 {
        return None;
    }
    let nearest = !matches!(rounding, "TRN" | "TRN_ZERO");
    if s > 126 {
        // |x| < 2^126: only TRN's boundary 0 and its neighbours -1 and 1 are in reach.
        return match (nearest, x) {
            (false, 0) => Some(0),
            (false, -1 | 1) => Some(1),
            _ => None,
        };
    }
    let m = 1i128 << s;
    let b = if nearest { m / 2 } else { 0 };
    let r = x.rem_euclid(m);
    if r == b {
        Some(0)
    } else if r == (b - 1).rem_euclid(m) || r == (b + 1).rem_euclid(m) {
        Some(1)
    } else {
        None
    }
}

/// Each stage's rounding-boundary counts recomputed from the CSV: the exact value a stage
/// quantizes is rebuilt from the ports (`probe_d * in_slope`, `probe_t + in_offset` aligned or
/// 0 when cut, the square of the previous probe, `probe_sqk * in_coef`) with the fraction
/// bits of the header's formats.
fn check_rounding_boundaries(dp: &Datapath, csv: &Csv, stages: &[Value], cut: &[bool]) {
    let cfg = dp.config();
    let k = cfg.k as usize;
    let col = |p: &str| csv.col(p);
    let frac = |p: &str| csv.format(p).frac;
    let sq = |i: usize| format!("probe_sq{i}");
    // (stage name, rounding, frac of the exact value, frac of the result, exact of a row).
    type Exact<'a> = Box<dyn Fn(usize) -> i128 + 'a>;
    let mut quantized: Vec<(String, String, i32, i32, Exact)> = Vec::new();
    let (cd, cs, ct, co) = (
        col("probe_d"),
        col("in_slope"),
        col("probe_t"),
        col("in_offset"),
    );
    let rows = &csv.rows;
    quantized.push((
        "t".into(),
        cfg.t.rounding.to_string(),
        frac("probe_d") + frac("in_slope"),
        frac("probe_t"),
        Box::new(move |i| i128::from(rows[i][cd]) * i128::from(rows[i][cs])),
    ));
    let (ft, fo) = (frac("probe_t"), frac("in_offset"));
    let fs = ft.max(fo);
    quantized.push((
        "b".into(),
        cfg.b.rounding.to_string(),
        fs,
        frac("probe_b"),
        Box::new(move |i| {
            if cut[i] {
                0
            } else {
                (i128::from(rows[i][ct]) << (fs - ft)) + (i128::from(rows[i][co]) << (fs - fo))
            }
        }),
    ));
    for i in 1..=k {
        let prev = if i == 1 {
            "probe_b".to_string()
        } else {
            sq(i - 1)
        };
        let cp = col(&prev);
        quantized.push((
            format!("sq{i}"),
            cfg.square[i - 1].rounding.to_string(),
            2 * frac(&prev),
            frac(&sq(i)),
            Box::new(move |r| i128::from(rows[r][cp]).pow(2)),
        ));
    }
    let (clast, ccoef) = (col(&sq(k)), col("in_coef"));
    quantized.push((
        "out".into(),
        cfg.out.rounding.to_string(),
        frac(&sq(k)) + frac("in_coef"),
        frac("expected_out"),
        Box::new(move |r| i128::from(rows[r][clast]) * i128::from(rows[r][ccoef])),
    ));
    for s in stages {
        let name = s["stage"].as_str().unwrap();
        match quantized.iter().find(|q| q.0 == name) {
            None => {
                // d and coef do not round.
                assert!(s["rounding"].is_null(), "{name}");
                assert_eq!(s["dropped_bits"], 0, "{name}");
                assert_eq!(
                    (&s["at_boundary"], &s["next_to_boundary"]),
                    (&0.into(), &0.into())
                );
            }
            Some((_, rounding, f_in, f_out, exact)) => {
                let dropped = i64::from(*f_in) - i64::from(*f_out);
                let mut counts = [0u64; 2];
                for i in 0..rows.len() {
                    if let Some(c) = boundary_class(exact(i), dropped, rounding) {
                        counts[c] += 1;
                    }
                }
                assert_eq!(s["dropped_bits"], dropped.max(0), "{name}");
                if dropped > 0 {
                    assert_eq!(s["rounding"], rounding.as_str(), "{name}");
                } else {
                    assert!(s["rounding"].is_null(), "{name}");
                }
                let got = [&s["at_boundary"], &s["next_to_boundary"]].map(|v| v.as_u64().unwrap());
                assert_eq!(got, counts, "{} stage {name}", cfg.name);
            }
        }
    }
}

#[test]
fn coverage_figures_match_the_csv() {
    let dir = temp_dir();
    let sparse_path = dir.path().join("sparse.toml");
    std::fs::write(&sparse_path, SPARSE).unwrap();
    let runs: [(String, &[&str]); 5] = [
        (
            "baseline".to_string(),
            &["--n", "16,100,1024", "--cases", "corner,random:500"],
        ),
        (
            config_path("narrow_trn_wrap.toml"),
            &["--cases", "corner,random:300"],
        ),
        (
            config_path("conv_sym_k5.toml"),
            &["--cases", "random:200", "--order", "sorted"],
        ),
        (
            config_path("minimax_folded.toml"),
            &["--cases", "corner,random:200"],
        ),
        (
            sparse_path.to_string_lossy().into_owned(),
            &["--cases", "exhaustive"],
        ),
    ];
    let mut overflow_seen = [false; 3];
    let mut boundary_seen = [false; 2];
    for (config, args) in &runs {
        let mut a = vec!["--config", config.as_str(), "--force"];
        a.extend_from_slice(args);
        let (d, m, printed) = vectors(dir.path(), "v", &a);
        check_coverage(config, &d, &m, &printed);
        for s in m["coverage"]["stages"].as_array().unwrap() {
            boundary_seen[0] |= s["at_boundary"].as_u64().unwrap() > 0;
            boundary_seen[1] |= s["next_to_boundary"].as_u64().unwrap() > 0;
        }
        for s in m["coverage"]["stages"].as_array().unwrap() {
            for (i, key) in ["wrapped", "saturated", "zeroed"].iter().enumerate() {
                overflow_seen[i] |= s[key].as_u64().unwrap() > 0;
            }
        }
    }
    // The runs exercise wrapping and saturating stages (so the event counts are checked on
    // something other than zeros).
    assert!(overflow_seen[0] && overflow_seen[1], "{overflow_seen:?}");
    assert_eq!(boundary_seen, [true, true]);
}

#[test]
fn csv_columns_are_the_hex_ports_line_by_line() {
    let dir = temp_dir();
    for config in [
        "baseline".to_string(),
        config_path("conv_sym_k5.toml"),
        config_path("minimax_folded.toml"),
        config_path("narrow_trn_wrap.toml"),
    ] {
        let (d, m, _) = vectors(
            dir.path(),
            "v",
            &[
                "--config",
                &config,
                "--n",
                "16,24,40",
                "--cases",
                "corner,random:100",
                "--force",
            ],
        );
        let csv = Csv::read(&d);
        let n_vectors = m["n_vectors"].as_u64().unwrap() as usize;
        assert_eq!(csv.rows.len(), n_vectors);
        let ports = m["ports"].as_array().unwrap();
        // The header: one `<port>:<format>` cell per port, in the ports' order; the manifest's
        // columns say the same.
        let want: Vec<String> = ports
            .iter()
            .map(|p| {
                format!(
                    "{}:{}",
                    p["name"].as_str().unwrap(),
                    p["format"].as_str().unwrap()
                )
            })
            .collect();
        assert_eq!(csv.header, want);
        let columns = m["csv"]["columns"].as_array().unwrap();
        assert_eq!(columns.len(), ports.len());
        for (c, p) in columns.iter().zip(ports) {
            for key in ["name", "format", "signed", "width"] {
                assert_eq!(c[key], p[key], "{key}");
            }
            let f = Fmt::parse(p["format"].as_str().unwrap());
            assert_eq!(p["signed"], f.signed);
            assert_eq!(p["width"], f.width);
        }
        let names: Vec<&str> = ports.iter().map(|p| p["name"].as_str().unwrap()).collect();
        assert_eq!(
            names[..6],
            [
                "in_c",
                "in_n",
                "in_slope",
                "in_offset",
                "in_threshold",
                "in_coef"
            ]
        );
        assert_eq!(*names.last().unwrap(), "expected_out");
        // Every hex file, line by line, is its CSV column.
        for (j, p) in ports.iter().enumerate() {
            let name = p["name"].as_str().unwrap();
            let fmt = Fmt::parse(p["format"].as_str().unwrap());
            let text = std::fs::read_to_string(d.join(format!("{name}.hex"))).unwrap();
            assert!(text.ends_with('\n'));
            let words: Vec<&str> = text.lines().collect();
            assert_eq!(words.len(), n_vectors, "{name}");
            for (i, (w, r)) in words.iter().zip(&csv.rows).enumerate() {
                assert_eq!(fmt.decode(w), r[j], "{config} {name} line {}", i + 1);
                assert!((fmt.min_raw()..=fmt.max_raw()).contains(&(r[j] as i128)));
            }
        }
        // Signed formats carry negative codes in decimal (d = c - 1 is never positive).
        let d_col = csv.col("probe_d");
        assert!(csv.rows.iter().any(|r| r[d_col] < 0));
        // The constants agree with the model's, per row.
        let mut cfg = datapath_of_file(&config).config().clone();
        cfg.n = "16,24,40".parse().unwrap();
        let dp = Datapath::new(cfg).unwrap();
        for r in &csv.rows {
            let nc = dp.constants_for(r[csv.col("in_n")] as u32).unwrap();
            assert_eq!(r[csv.col("in_slope")], nc.slope_raw);
            assert_eq!(r[csv.col("in_offset")], nc.offset_raw);
            assert_eq!(r[csv.col("in_coef")], nc.coef_raw);
            assert_eq!(r[csv.col("in_threshold")], nc.threshold.unwrap_or(0));
        }
    }
}

/// `hdl stimulus` verifies vectors.csv against its manifest: columns moved around are a
/// changed file, refused with one line before any stimulus is written.
#[test]
fn stimulus_refuses_columns_moved_around() {
    let dir = temp_dir();
    let (d, _, _) = vectors(
        dir.path(),
        "v",
        &["--n", "16,100,1024", "--cases", "corner,random:60"],
    );
    let stim = |vectors: &Path, out: &str| -> std::process::Output {
        specfx(&[
            "hdl",
            "stimulus",
            "--vectors",
            vectors.to_str().unwrap(),
            "--out",
            dir.path().join(out).to_str().unwrap(),
        ])
    };
    let o = stim(&d, "s1");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    // Reverse the columns of a copy.
    let moved = dir.path().join("moved");
    std::fs::create_dir_all(&moved).unwrap();
    for entry in std::fs::read_dir(&d).unwrap() {
        let e = entry.unwrap();
        std::fs::copy(e.path(), moved.join(e.file_name())).unwrap();
    }
    let text = std::fs::read_to_string(d.join("vectors.csv")).unwrap();
    let reversed: String = text
        .lines()
        .map(|l| l.split(',').rev().collect::<Vec<_>>().join(",") + "\n")
        .collect();
    std::fs::write(moved.join("vectors.csv"), reversed).unwrap();
    // The manifest fixes the columns: a reordered CSV is a changed file, refused before use.
    let o = stim(&moved, "s2");
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("vectors.csv: sha256") && err.lines().count() == 1,
        "{err}"
    );
    assert!(!dir.path().join("s2").exists());
}

#[test]
fn a_bad_order_is_refused() {
    let dir = temp_dir();
    let out = dir.path().join("never");
    let o = specfx(&[
        "vectors",
        "--out",
        out.to_str().unwrap(),
        "--order",
        "shuffled",
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("shuffled"));
    assert!(!out.exists());
}

/// Issue 25, item 4: a wrapping t behind the clamp cutoff on a 2^30-code input was refused
/// ("corner-case scan"), even for `--cases random:10`. Its cutoff switches are now found
/// without a scan, every one of them.
#[test]
fn a_wrapping_t_on_a_wide_input_gets_every_cut_switch() {
    let dir = temp_dir();
    let cfg = dir.path().join("wide_wrap.toml");
    let toml = "n = \"17,1024\"\n[c]\nformat = \"u1.30\"\n[d]\nformat = \"s1.30\"\n[t]\noverflow = \"WRAP\"\n";
    std::fs::write(&cfg, toml).unwrap();
    let (d, m, _) = vectors(
        dir.path(),
        "v",
        &["--config", cfg.to_str().unwrap(), "--cases", "random:10"],
    );
    // By hand: t = (n/16)(c - 1) before wrapping, kept modulo 4 in [-2, 2) by s2.16; the
    // base t + 1 is cut when the kept t is below -1, i.e. the unwrapped t lies in
    // [-2 + 4j, -1 + 4j). n = 17: t >= -17/16 never wraps, one switch (t = -1). n = 1024:
    // t >= -64, the 16 intervals j = -15..=0 each entered and left: 32 switches.
    let switches = &m["coverage"]["directed"]["cut_switches"];
    assert_eq!(switches["found"], 33, "{switches}");
    assert_eq!(switches["complete"], true);
    assert_eq!(switches["n_sampled"], serde_json::json!([]));
    // Every switch is in the vectors with the code before it, as the scalar model says.
    let dp = datapath_of(toml);
    let inputs: BTreeSet<(i64, i64)> = Csv::read(&d).inputs().into_iter().collect();
    let mut seen: BTreeMap<i64, usize> = BTreeMap::new();
    for &(n, c) in &inputs {
        if c > 0 && c <= dp.one_code() && inputs.contains(&(n, c - 1)) {
            let nc = dp.constants_for(n as u32).unwrap();
            if dp.eval(c, nc).cut != dp.eval(c - 1, nc).cut {
                *seen.entry(n).or_default() += 1;
            }
        }
    }
    assert_eq!(seen, BTreeMap::from([(17, 1), (1024, 32)]));
    // The rounding-boundary search looked at the highest codes below 1.0 only.
    let ties = &m["coverage"]["directed"]["ties"];
    assert_eq!(ties["exhaustive"], false);
    assert_eq!(ties["codes_per_n"], (1u64 << 25) / 2);
}

/// Issue 25, item 5: inputs on and next to every rounding stage's boundary are vectors. The
/// oracle is a scan of every input with the public scalar `eval`, the exact values rebuilt
/// from docs/arithmetic.md section 3.2 (t: d * slope, 3 bits dropped; sq_i: the previous
/// square, 16 bits; out: sq4 * coef, 16 bits; b drops none), the boundary being half an
/// output LSB (RND).
#[test]
fn every_rounding_boundary_the_model_reaches_has_vectors() {
    let dir = temp_dir();
    let (d, m, _) = vectors(dir.path(), "v", &["--n", "16..=120", "--cases", "corner"]);
    let dp = datapath_of_file("baseline");
    let inputs: BTreeSet<(i64, i64)> = Csv::read(&d).inputs().into_iter().collect();
    // (stage, offset from the tie, negative) -> every (n, c) reaching it.
    type Class = (&'static str, i128, bool);
    let mut reached: BTreeMap<Class, Vec<(i64, i64)>> = BTreeMap::new();
    for n in 16..=120u32 {
        let nc = dp.constants_for(n).unwrap();
        for c in 0..=32768i64 {
            let p = dp.eval(c, nc);
            let v = |i: usize| i128::from(p.values[i]);
            let mut exact = vec![("t", v(0) * i128::from(n), 3)];
            for (i, name) in ["sq1", "sq2", "sq3", "sq4"].into_iter().enumerate() {
                exact.push((name, v(2 + i) * v(2 + i), 16));
            }
            exact.push(("out", v(6) * i128::from(nc.coef_raw), 16));
            for (stage, x, s) in exact {
                let offset = x.rem_euclid(1 << s) - (1 << (s - 1));
                if offset.abs() <= 1 {
                    reached
                        .entry((stage, offset, x < 0))
                        .or_default()
                        .push((i64::from(n), c));
                }
            }
        }
    }
    // The outside run of the issue found the out values one LSB below the tie at n = 25, 82,
    // 111, 183, ...: in 16..=120, those three.
    let below: BTreeSet<i64> = reached[&("out", -1, false)].iter().map(|p| p.0).collect();
    assert_eq!(below, BTreeSet::from([25, 82, 111]));
    for (class, all) in &reached {
        let ns: BTreeSet<i64> = all.iter().map(|p| p.0).collect();
        let held = all.iter().filter(|p| inputs.contains(p)).count();
        assert!(
            held >= ns.len().min(8),
            "{class:?}: {held} of {} inputs over {} n",
            all.len(),
            ns.len()
        );
    }
    assert!(reached.keys().any(|k| k.0 == "out" && k.1 == 0));
    let ties = &m["coverage"]["directed"]["ties"];
    assert_eq!(ties["exhaustive"], true);
    assert_eq!(ties["codes_searched"], 105 * 32769);
    // Per stage, the classes reached and at most 8 vectors each.
    for st in ties["stages"].as_array().unwrap() {
        let name = st["stage"].as_str().unwrap();
        let classes = reached.keys().filter(|k| k.0 == name).count() as u64;
        assert_eq!(st["classes"], classes, "{name}");
        assert!(st["vectors"].as_u64().unwrap() <= 8 * classes, "{name}");
    }
}
