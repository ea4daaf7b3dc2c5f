//! `specfx stability`: every failure region's boundaries pinned against closed forms and
//! slow oracles written here, so a change that moves one is noticed; the command end to end.

use crate::common::specfx;

use std::f64::consts::PI;

use specfx::analysis::stability::{
    map, narrow_datapath, overshoot_threshold, special_outcomes, FloatPath, Grid, Kind, MapPath,
    PathMap, Region, SpecialVerdict, Tolerance,
};
use specfx::fixed::Overflow;
use specfx::pipeline::Config;
use specfx::reference::lobe::Cutoff;
use specfx::reference::method::Method;

const TOL: f64 = 1.0 / 256.0;

fn grid(n: &str, c_bits: u32) -> Grid {
    Grid {
        n: n.parse().unwrap(),
        c_bits,
        tol: Tolerance::default(),
    }
}

fn cs(k: u32, cutoff: Cutoff) -> MapPath {
    MapPath::Float(FloatPath::Method(Method::CsM { k, cutoff }))
}

fn run(paths: &[MapPath], g: &Grid) -> Vec<PathMap> {
    map(paths, g, &|_, _| {}).unwrap()
}

fn region(m: &PathMap, kind: Kind) -> &Region {
    m.region(kind)
        .unwrap_or_else(|| panic!("{} has no {kind} region", m.path))
}

/// An oracle's flagged codes at one n: (smallest, largest, count).
type Extent = Option<(u64, u64, u64)>;

fn extent(codes: impl Iterator<Item = u64>) -> Extent {
    codes.fold(None, |acc, j| match acc {
        None => Some((j, j, 1)),
        Some((lo, hi, count)) => Some((lo.min(j), hi.max(j), count + 1)),
    })
}

/// Checks a region against an oracle's extent at every n: the same exponents, and at each the
/// same smallest and largest code and the same number of samples.
fn assert_region_matches(
    r: Option<&Region>,
    ns: &[u32],
    scale: f64,
    oracle: impl Fn(u32) -> Extent,
) {
    let expected: Vec<(u32, (u64, u64, u64))> = ns
        .iter()
        .filter_map(|&n| oracle(n).map(|e| (n, e)))
        .collect();
    let got: Vec<(u32, (u64, u64, u64))> = r.map_or(Vec::new(), |r| {
        r.per_n
            .iter()
            .map(|b| {
                (
                    b.n,
                    ((b.c_lo * scale) as u64, (b.c_hi * scale) as u64, b.samples),
                )
            })
            .collect()
    });
    assert_eq!(got.len(), expected.len(), "exponents differ");
    for (g, e) in got.iter().zip(&expected) {
        assert_eq!(g, e, "extent at n = {}", e.0);
    }
}

#[test]
fn the_paper_cutoff_admits_negative_bases_exactly_between_its_cut_and_the_zero_of_the_base() {
    // Not cut: c >= cos(6/sqrt(n)); base (n/m)(c - 1) + 1 < 0: j n < 2^15 (n - m), exact in
    // integers for c = j / 2^15.
    let g = grid("1..=4096", 15);
    let ns = g.n.values().to_vec();
    let paths = [
        cs(2, Cutoff::Paper),
        cs(3, Cutoff::Paper),
        cs(4, Cutoff::Paper),
        cs(5, Cutoff::Paper),
    ];
    let maps = run(&paths, &g);
    let scale = f64::from(1u32 << 15);
    for (k, m) in [2u32, 3, 4, 5].into_iter().zip(&maps) {
        let mm = 1u64 << k;
        let oracle = |n: u32| {
            let thr = (6.0 / f64::from(n).sqrt()).min(PI).cos();
            let n64 = u64::from(n);
            extent((0..=1u64 << 15).filter(|&j| {
                (j as f64) / scale >= thr && n64 > mm && j * n64 < (1u64 << 15) * (n64 - mm)
            }))
        };
        assert_region_matches(m.region(Kind::NegativeBase), &ns, scale, oracle);
    }
    // m = 16: the spurious lobe is at most (1 - (n/16)(1 - cos(6/sqrt(n))))^16, about
    // (1/8)^16, and cos^n there at most (1 - 16/n)^n (at the zero of the base), about e^-16:
    // the region's error is below one or the other, far inside the tolerance. m = 4 and m = 8 (the paper's constant 6 kept
    // for every m) fail.
    let r16 = region(&maps[2], Kind::NegativeBase);
    let bound = (r16.n_min..=4096)
        .map(|n| {
            let nf = f64::from(n);
            let c = (6.0 / nf.sqrt()).cos();
            (1.0 - nf / 16.0 * (1.0 - c))
                .powi(16)
                .max((1.0 - 16.0 / nf).powf(nf))
        })
        .fold(0.0, f64::max);
    assert!(bound < 2e-7, "{bound}");
    assert!(!r16.fails, "{}", r16.worst_abs_err);
    assert!(
        r16.worst_abs_err <= bound * (1.0 + 1e-9),
        "{} > {bound}",
        r16.worst_abs_err
    );
    assert!(region(&maps[0], Kind::NegativeBase).fails);
    assert!(region(&maps[1], Kind::NegativeBase).fails);
    // m = 32: 6/sqrt(n) comes before the zero of the base (6 < sqrt(2 m) for large n).
    assert!(maps[3].region(Kind::NegativeBase).is_none());
    // The spurious lobe makes the paper cutoff non-monotonic wherever it admits a negative
    // base, and for m = 16 by less than the tolerance.
    assert!(!region(&maps[2], Kind::NonMonotonic).fails);
    assert_eq!(
        region(&maps[2], Kind::NonMonotonic).n_min,
        region(&maps[2], Kind::NegativeBase).n_min
    );
}

#[test]
fn below_m_the_lobe_does_not_close() {
    // Oracle: cs_m and cos^n written out here, on the grid c = j / 2^12.
    let g = grid("1..=200", 12);
    let maps = run(&[cs(4, Cutoff::Clamp), cs(7, Cutoff::Clamp)], &g);
    for (k, m) in [4u32, 7].into_iter().zip(&maps) {
        let mf = f64::from(1u32 << k);
        let fails_at = |n: u32| {
            let nf = f64::from(n);
            (0..=4096).any(|j| {
                let c = f64::from(j) / 4096.0;
                let lobe = (1.0 - nf / mf * (1.0 - c)).max(0.0).powi(1 << k);
                let target = if c > 0.0 { c.powf(nf) } else { 0.0 };
                (lobe - target).abs() > TOL
            })
        };
        let expected: Vec<u32> = (1..(1u32 << k)).filter(|&n| fails_at(n)).collect();
        let r = region(m, Kind::NBelowM);
        let got: Vec<u32> = r.per_n.iter().map(|b| b.n).collect();
        assert_eq!(got, expected, "k = {k}");
        // At the horizon alone the error is (1 - n/m)^m: above the tolerance for every n
        // below m (1 - tol^(1/m)).
        let horizon_bound = (mf * (1.0 - TOL.powf(1.0 / mf))).ceil() as u32 - 1;
        assert!(
            r.n_max >= horizon_bound,
            "k = {k}: {} < {horizon_bound}",
            r.n_max
        );
    }
    // m = 16: the horizon alone fails up to n = 4, since (1 - 4/16)^16 = 1.0e-2 > 2^-8 and
    // (1 - 5/16)^16 = 2.5e-3 < 2^-8.
    assert!((1.0f64 - 4.0 / 16.0).powi(16) > TOL && (1.0f64 - 5.0 / 16.0).powi(16) < TOL);
    assert_eq!(region(&maps[0], Kind::NBelowM).n_min, 1);
}

#[test]
fn schlicks_tail_lies_where_its_closed_form_says() {
    let g = grid("1..=1024", 14);
    let maps = run(&[MapPath::Float(FloatPath::Method(Method::Schlick))], &g);
    let scale = f64::from(1u32 << 14);
    let oracle = |n: u32| {
        let nf = f64::from(n);
        extent((0..=1u64 << 14).filter(|&j| {
            let c = j as f64 / scale;
            let s = c / (nf - nf * c + c);
            let target = if c > 0.0 { c.powf(nf) } else { 0.0 };
            s - target > TOL
        }))
    };
    assert_region_matches(maps[0].region(Kind::Over), g.n.values(), scale, oracle);
    let over = region(&maps[0], Kind::Over);
    assert!(over.fails);
    // n = 1 is exact (c / 1); the tail starts at n = 2.
    assert_eq!(over.n_min, 2);
    assert!(maps[0].region(Kind::Under).is_none());
}

#[test]
fn underflow_starts_where_the_float_types_run_out() {
    let g = grid("1..=4096", 15);
    let paths = [
        MapPath::Float(FloatPath::Method(Method::CosPow)),
        MapPath::Float(FloatPath::PowF32),
        MapPath::Float(FloatPath::Method(Method::ExpLimit)),
    ];
    let maps = run(&paths, &g);
    // powf in f64: (j / 2^15)^n < 2^-1022; first at the smallest code, 2^-15n < 2^-1022, so
    // n > 1022 / 15.
    let powf = region(&maps[0], Kind::Underflow);
    assert_eq!(powf.n_min, 69);
    assert!(!powf.fails);
    // The largest underflowing code at n: j < 2^(15 - 1022/n).
    for (m, min_exp, r) in [
        (&maps[0], 1022.0, powf),
        (&maps[1], 126.0, region(&maps[1], Kind::Underflow)),
    ] {
        for n in [100u32, 1024, 4096] {
            let nf = f64::from(n);
            let j_max = (2f64.powf(15.0 - min_exp / nf)).ceil() as u64 - 1;
            let b = r.at(n).unwrap_or_else(|| panic!("{} at n = {n}", m.path));
            assert_eq!((b.c_hi * 32768.0) as u64, j_max, "{} at n = {n}", m.path);
            assert_eq!(b.c_lo, 2f64.powi(-15), "{} at n = {n}", m.path);
        }
    }
    // f32: 2^-15n < 2^-126 from n = 9 on.
    assert_eq!(region(&maps[1], Kind::Underflow).n_min, 9);
    // exp(-n(1 - c)) < 2^-1022 needs n(1 - c) > 1022 ln 2 = 708.4: first at c = 0, n = 709.
    assert_eq!(region(&maps[2], Kind::Underflow).n_min, 709);
}

/// The narrow wrap-around datapath written out in integers: c = code / 2^9, d in s1.9, t in
/// s3.8, b in u1.8, four squares in u1.8, the output in u10.6 with the coefficient in u10.6,
/// truncation (floor) and wrap-around everywhere, the clamp cutoff. Returns (lobe raw, out
/// raw, whether any stage wrapped).
fn narrow_wrap_oracle(code: i64, n: i64, coef_raw: i64) -> (i64, i64, bool) {
    let wrap = |x: i64, bits: u32, signed: bool| {
        let m = x.rem_euclid(1 << bits);
        if signed && m >= 1 << (bits - 1) {
            m - (1 << bits)
        } else {
            m
        }
    };
    let d = code - 512; // frac 9
    let t_exact = d * n; // frac 13 (slope n / 16)
    let t_trn = t_exact.div_euclid(1 << 5); // frac 8
    let t = wrap(t_trn, 11, true); // s3.8: 11 bits
    let mut wrapped = t != t_trn;
    let sum = t + 256; // + 1.0, frac 8
    let b_exact = sum.max(0);
    let b = wrap(b_exact, 9, false); // u1.8: 9 bits
    wrapped |= b != b_exact;
    let mut s = b;
    for _ in 0..4 {
        let sq = (s * s).div_euclid(1 << 8);
        let w = wrap(sq, 9, false);
        wrapped |= w != sq;
        s = w;
    }
    let out_exact = (s * coef_raw).div_euclid(1 << 8); // frac 8 + 6 -> 6
    let out = wrap(out_exact, 16, false);
    wrapped |= out != out_exact;
    (s, out, wrapped)
}

#[test]
fn wrap_around_and_non_monotonic_regions_of_the_narrow_datapath() {
    let g = grid("1..=4096", 9);
    let cfg = narrow_datapath(Overflow::Wrap);
    let maps = run(&[MapPath::Fixed(Box::new(cfg))], &g);
    let m = &maps[0];
    let coef_raw = |n: u32| {
        let c = specfx::reference::normalisation::coefficient(
            specfx::reference::normalisation::Form::Phong,
            specfx::reference::normalisation::CoefSource::Exact,
            f64::from(n),
            4,
        );
        (c * 64.0).floor() as i64
    };
    let ns = g.n.values();
    assert_region_matches(m.region(Kind::Wrap), ns, 512.0, |n| {
        let cr = coef_raw(n);
        extent((0..=512u64).filter(|&code| narrow_wrap_oracle(code as i64, i64::from(n), cr).2))
    });
    assert_region_matches(m.region(Kind::NonMonotonic), ns, 512.0, |n| {
        let cr = coef_raw(n);
        extent((1..=512u64).filter(|&code| {
            let (l0, o0, _) = narrow_wrap_oracle(code as i64 - 1, i64::from(n), cr);
            let (l1, o1, _) = narrow_wrap_oracle(code as i64, i64::from(n), cr);
            l1 < l0 || o1 < o0
        }))
    });
    // t wraps first when 512 n / 32 > 1024 at c = 0: n > 64.
    let w = region(m, Kind::Wrap);
    assert_eq!(w.n_min, 65);
    assert!(w.fails);
    assert_eq!(w.stages.first().map(String::as_str), Some("t"));
    assert!(region(m, Kind::NonMonotonic).fails);
}

#[test]
fn rounding_alone_never_makes_a_datapath_non_monotonic() {
    // Every rounding mode with saturation and the clamp cutoff: each stage is a monotone map
    // of a monotone input, so no region may appear; wrap-around (above) is what breaks it.
    use specfx::fixed::Rounding;
    let g = grid("1..=300", 8);
    let mut paths = Vec::new();
    for (i, mode) in Rounding::ALL.into_iter().enumerate() {
        let mut cfg = narrow_datapath(Overflow::Sat);
        cfg.name = format!("sat_{i}");
        cfg.t.rounding = mode;
        cfg.b.rounding = mode;
        for s in &mut cfg.square {
            s.rounding = mode;
            s.format = format!("u1.{}", 5 + i).parse().unwrap();
        }
        cfg.out.rounding = mode;
        paths.push(MapPath::Fixed(Box::new(cfg)));
    }
    for m in run(&paths, &g) {
        assert!(m.region(Kind::NonMonotonic).is_none(), "{}", m.path);
        assert!(m.region(Kind::Wrap).is_none(), "{}", m.path);
    }
}

#[test]
fn baselines_coefficient_does_not_fit_from_n_1514() {
    // coef = 17 n / (32 pi) for n >= 16 (the exact Phong normalisation of cs16), rounded to
    // u8.16: it overflows once coef >= 256 - 2^-17.
    let n_star = ((256.0 - 2f64.powi(-17)) * 32.0 * PI / 17.0).ceil() as u32;
    assert_eq!(n_star, 1514);
    let g = grid("1400..=1600", 15);
    let maps = run(&[MapPath::Fixed(Box::new(Config::baseline()))], &g);
    let r = region(&maps[0], Kind::Unrepresentable);
    assert_eq!((r.n_min, r.n_max), (n_star, 1600));
    assert!(r.fails);
    assert!(r
        .note
        .as_deref()
        .unwrap_or("")
        .starts_with("coef.format: coef(n = 1514)"));
    for kind in [
        Kind::Wrap,
        Kind::NonMonotonic,
        Kind::NegativeBase,
        Kind::NonFinite,
    ] {
        assert!(maps[0].region(kind).is_none(), "{kind}");
    }
}

#[test]
fn baselines_lobe_underflows_where_its_rounded_squares_reach_zero() {
    // The baseline written out: d = code - 2^15 (frac 15), t = RND(n d / 16) in s2.16 with
    // saturation, b = max(0, t + 1), four squares RND to u1.16. Underflow: b > 0, lobe 0.
    let rnd = |x: i64, shift: u32| (x + (1 << (shift - 1))).div_euclid(1 << shift);
    let lobe = |code: i64, n: i64| {
        let t = rnd((code - 32768) * n, 3).clamp(-(1 << 17), (1 << 17) - 1);
        let b = (t + 65536).max(0);
        let mut s = b;
        for _ in 0..4 {
            s = rnd(s * s, 16).min((1 << 17) - 1);
        }
        (b, s)
    };
    let g = grid("64,1024", 15);
    let maps = run(&[MapPath::Fixed(Box::new(Config::baseline()))], &g);
    assert_region_matches(
        maps[0].region(Kind::Underflow),
        g.n.values(),
        32768.0,
        |n| {
            extent((0..=32768u64).filter(|&code| {
                let (b, s) = lobe(code as i64, i64::from(n));
                b > 0 && s == 0
            }))
        },
    );
    assert!(!region(&maps[0], Kind::Underflow).fails);
}

#[test]
fn overshoot_thresholds_follow_their_closed_forms() {
    let eps = 2f64.powi(-23);
    for n in [16u32, 256, 1000, 4096] {
        let nf = f64::from(n);
        // powf: (1 + j eps)^n - 1 > tol.
        let j_pow = (((1.0 + TOL).powf(1.0 / nf) - 1.0) / eps).floor() as u32 + 1;
        assert_eq!(
            overshoot_threshold(FloatPath::Method(Method::CosPow), n, TOL),
            Some(j_pow),
            "powf n = {n}"
        );
        // Schlick: n eps / (1 - (n - 1) eps) > tol, so eps > tol / (n + tol (n - 1)).
        let j_schlick = (TOL / (nf + TOL * (nf - 1.0)) / eps).floor() as u32 + 1;
        assert_eq!(
            overshoot_threshold(FloatPath::Method(Method::Schlick), n, TOL),
            Some(j_schlick),
            "schlick n = {n}"
        );
    }
    // The bisection agrees with a linear scan.
    for path in [
        FloatPath::Method(Method::ExpLimit),
        FloatPath::Method(Method::CsM {
            k: 4,
            cutoff: Cutoff::Clamp,
        }),
        FloatPath::Method(Method::Minimax { k: 4 }),
        FloatPath::PowF32,
    ] {
        for n in [17u32, 300, 4096] {
            let p = path.prepare(n);
            let one = p.eval(1.0).value;
            let scan = (1..=specfx::analysis::stability::OVERSHOOT_J_MAX).find(|&j| {
                let v = p.eval(1.0 + f64::from(j) * eps).value;
                !v.is_finite() || v < 0.0 || v - one > TOL
            });
            assert_eq!(
                overshoot_threshold(path, n, TOL),
                scan,
                "{} n = {n}",
                path.name()
            );
        }
    }
}

#[test]
fn special_inputs_follow_ieee_754() {
    let paths = [
        MapPath::Float(FloatPath::Method(Method::CosPow)),
        cs(4, Cutoff::Clamp),
        cs(4, Cutoff::None),
        MapPath::Float(FloatPath::Method(Method::Schlick)),
        MapPath::Float(FloatPath::Method(Method::ExpLimit)),
        MapPath::Float(FloatPath::Method(Method::Minimax { k: 4 })),
        MapPath::Fixed(Box::new(Config::baseline())),
    ];
    let all = special_outcomes(&paths, TOL).unwrap();
    let verdict = |path: &str, input: &str, n: u32| {
        all.iter()
            .find(|s| s.path == path && s.input == input && s.n == n)
            .map(|s| s.verdict)
    };
    // powf(NaN) is NaN; max(0, NaN) in Rust (IEEE maxNum) is 0, so the clamp absorbs NaN.
    assert_eq!(verdict("powf", "NaN", 16), Some(SpecialVerdict::Nan));
    assert_eq!(
        verdict("cs16_clamp", "NaN", 16),
        Some(SpecialVerdict::Absorbed)
    );
    assert_eq!(
        verdict("minimax16", "NaN", 16),
        Some(SpecialVerdict::Absorbed)
    );
    assert_eq!(verdict("cs16_none", "NaN", 16), Some(SpecialVerdict::Nan));
    // +inf: inf^n; Schlick inf / (n - inf + inf) = NaN; exp(+inf) = inf.
    assert_eq!(verdict("powf", "+inf", 16), Some(SpecialVerdict::Inf));
    assert_eq!(verdict("schlick", "+inf", 16), Some(SpecialVerdict::Nan));
    assert_eq!(verdict("exp_limit", "+inf", 16), Some(SpecialVerdict::Inf));
    // -inf: powf is 0 for c <= 0, the clamp cuts; an even power of -inf is +inf.
    assert_eq!(verdict("powf", "-inf", 16), Some(SpecialVerdict::Absorbed));
    assert_eq!(
        verdict("cs16_clamp", "-inf", 1024),
        Some(SpecialVerdict::Absorbed)
    );
    assert_eq!(
        verdict("cs16_none", "-inf", 1024),
        Some(SpecialVerdict::Inf)
    );
    // Just below 0, Schlick's c / (n - n c + c) is negative.
    assert_eq!(
        verdict("schlick", "-2^-24", 16),
        Some(SpecialVerdict::Negative)
    );
    assert_eq!(verdict("powf", "-2^-24", 16), Some(SpecialVerdict::Ok));
    // 1 + 2^-10 to the 4096th is e^4 = 54.6: far off.
    assert_eq!(verdict("powf", "1+2^-10", 4096), Some(SpecialVerdict::Off));
    // The datapath rounds the input into u1.15 and clamps codes above 1.0: nothing overshoots;
    // NaN has no code and is left out.
    assert_eq!(verdict("baseline", "1+2^-10", 16), Some(SpecialVerdict::Ok));
    assert_eq!(verdict("baseline", "-2^-10", 16), Some(SpecialVerdict::Ok));
    assert_eq!(verdict("baseline", "NaN", 16), None);
}

#[test]
fn the_command_writes_maps_tables_and_json_and_refuses_bad_input() {
    let dir = std::env::temp_dir().join(format!("specfx-stability-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let args = [
        "stability",
        "--out",
        dir.to_str().unwrap(),
        "--n",
        "1..=64",
        "--c-bits",
        "10",
        "--float",
        "powf,schlick,cs16_paper",
        "--config",
        "baseline",
    ];
    let o = specfx(&args);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(
        stdout.contains("schlick") && stdout.contains("over (n 2..=64)"),
        "{stdout}"
    );
    for f in [
        "stability.md",
        "stability.html",
        "stability.json",
        "regions.csv",
        "special_inputs.csv",
        "overshoot.csv",
        "overview.svg",
        "overview.png",
        "overshoot.png",
        "heatmap_powf.png",
        "heatmap_schlick.svg",
        "heatmap_cs16_paper.png",
        "heatmap_baseline.png",
    ] {
        assert!(dir.join(f).is_file(), "{f} missing");
    }
    let json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.join("stability.json")).unwrap()).unwrap();
    let maps = json["maps"].as_array().unwrap();
    assert_eq!(maps.len(), 4);
    assert_eq!(maps[1]["path"], "schlick");
    let csv = std::fs::read_to_string(dir.join("regions.csv")).unwrap();
    assert!(
        csv.lines().any(|l| l.starts_with("schlick,f64,over,true,")),
        "{csv}"
    );
    // The same command writes byte-identical files.
    let first = std::fs::read(dir.join("stability.json")).unwrap();
    let png = std::fs::read(dir.join("heatmap_schlick.png")).unwrap();
    assert!(specfx(&args).status.success());
    assert_eq!(std::fs::read(dir.join("stability.json")).unwrap(), first);
    assert_eq!(std::fs::read(dir.join("heatmap_schlick.png")).unwrap(), png);

    for (bad, what) in [
        (vec!["stability", "--tol=-1"], "tolerance"),
        (vec!["stability", "--float", "cs17_clamp"], "--float"),
        (vec!["stability", "--c-bits", "30"], "--c-bits"),
        (
            vec!["stability", "--config", "/nonexistent.toml"],
            "nonexistent",
        ),
        (vec!["stability", "--n", "0..=5"], "exponent"),
    ] {
        let o = specfx(&bad);
        assert_eq!(o.status.code(), Some(2), "{bad:?}");
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(err.contains(what), "{bad:?}: {err}");
        assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    }
}

#[test]
fn a_users_datapath_file_is_mapped() {
    let dir = std::env::temp_dir().join(format!("specfx-stability-user-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    // t in s3.8 with wrap-around: it wraps once n (1 - c) / 16 > 4, first at n = 65, c = 0.
    let file = dir.join("mine.toml");
    std::fs::write(
        &file,
        "[c]\nformat = \"u1.9\"\n[d]\nformat = \"s1.9\"\n[t]\nformat = \"s3.8\"\nrounding = \"TRN\"\noverflow = \"WRAP\"\n",
    )
    .unwrap();
    let out = dir.join("out");
    let o = specfx(&[
        "stability",
        "--out",
        out.to_str().unwrap(),
        "--n",
        "60..=70",
        "--float",
        "none",
        "--config",
        file.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let csv = std::fs::read_to_string(out.join("regions.csv")).unwrap();
    let wrap = csv
        .lines()
        .find(|l| l.starts_with("mine,fixed,wrap,"))
        .unwrap_or_else(|| panic!("{csv}"));
    let fields: Vec<&str> = wrap.split(',').collect();
    assert_eq!((fields[6], fields[7]), ("65", "70"), "{wrap}");
    assert!(out.join("heatmap_mine.png").is_file());
}
