//! The independent BigInt oracle (`tests/common/oracle.rs`): checked against the hand-computed
//! examples of `docs/arithmetic.md`, then used to check `Datapath::eval` exhaustively, including
//! two reproductions from a bug report (a left-shifted wide output, a `t` format with negative
//! fraction bits).

use crate::common::oracle::{
    apply_overflow, constant, exact_f64, oracle_eval, pow2, quantize, round_shift, OracleProbes,
};
use num_bigint::BigInt;
use specfx::fixed::{Event, Format, Overflow, Rounding};
use specfx::pipeline::{Config, Datapath, NConstants};

const ROUNDINGS: [Rounding; 8] = [
    Rounding::Trn,
    Rounding::TrnZero,
    Rounding::Rnd,
    Rounding::RndZero,
    Rounding::RndInf,
    Rounding::RndMinInf,
    Rounding::RndConv,
    Rounding::RndConvOdd,
];

const OVERFLOWS: [Overflow; 4] = [
    Overflow::Wrap,
    Overflow::Sat,
    Overflow::SatZero,
    Overflow::SatSym,
];

fn fmt(s: &str) -> Format {
    s.parse().expect("valid format notation")
}

fn big(v: i64) -> BigInt {
    BigInt::from(v)
}

fn datapath(toml: &str) -> Datapath {
    Datapath::new(Config::from_toml(toml).expect("valid configuration"))
        .expect("configuration validates")
}

fn constants(dp: &Datapath, n: u32) -> NConstants {
    *dp.constants()
        .iter()
        .find(|nc| nc.n == n)
        .expect("n is in the configuration's set")
}

/// Bug report (a): the baseline with a 63-bit signed output, so the output product is shifted
/// left by 30 bits into `s1.62`.
const WIDE_OUT: &str = "n = \"100\"\n[out]\nformat = \"s1.62\"\n";
/// Bug report (b): the baseline with a 4-bit `t` whose LSB is 2^56 (75 bits dropped).
const COARSE_T: &str = "n = \"100\"\n[t]\nformat = \"s60.-56\"\n";

// ---------------------------------------------------------------------------------------------
// Section 2: single quantizations, from the document's tables.

/// docs/arithmetic.md section 2.1, the truth table (columns in `ROUNDINGS` order).
#[test]
fn rounding_truth_table() {
    let rows: [(i64, u64, [i64; 8]); 10] = [
        (5, 1, [2, 2, 3, 2, 3, 2, 2, 3]),
        (-5, 1, [-3, -2, -2, -2, -3, -3, -2, -3]),
        (7, 1, [3, 3, 4, 3, 4, 3, 4, 3]),
        (-7, 1, [-4, -3, -3, -3, -4, -4, -4, -3]),
        (9, 2, [2, 2, 2, 2, 2, 2, 2, 2]),
        (-9, 2, [-3, -2, -2, -2, -2, -2, -2, -2]),
        (11, 2, [2, 2, 3, 3, 3, 3, 3, 3]),
        (-11, 2, [-3, -2, -3, -3, -3, -3, -3, -3]),
        (-6, 2, [-2, -1, -1, -1, -2, -2, -2, -1]),
        (-3, 2, [-1, 0, -1, -1, -1, -1, -1, -1]),
    ];
    for (x, s, expected) in rows {
        for (mode, want) in ROUNDINGS.iter().zip(expected) {
            assert_eq!(
                round_shift(&big(x), s, *mode),
                big(want),
                "x = {x}, s = {s}, {mode:?}"
            );
        }
    }
    // r == 0 gives q in every mode.
    for mode in ROUNDINGS {
        assert_eq!(round_shift(&big(-12), 2, mode), big(-3), "{mode:?}");
        assert_eq!(round_shift(&big(12), 2, mode), big(3), "{mode:?}");
    }
}

/// docs/arithmetic.md section 2.2, the three truth tables (columns in `OVERFLOWS` order).
/// One row of an overflow truth table: `v` and the result of each mode in `OVERFLOWS` order.
type OverflowRow = (i64, [(i64, Event); 4]);

#[test]
fn overflow_truth_tables() {
    use Event::{None as N, Saturated as S, Wrapped as W, Zeroed as Z};
    let s4: [OverflowRow; 6] = [
        (7, [(7, N), (7, N), (7, N), (7, N)]),
        (8, [(-8, W), (7, S), (0, Z), (7, S)]),
        (-8, [(-8, N), (-8, N), (-8, N), (-7, S)]),
        (-9, [(7, W), (-8, S), (0, Z), (-7, S)]),
        (23, [(7, W), (7, S), (0, Z), (7, S)]),
        (-100, [(-4, W), (-8, S), (0, Z), (-7, S)]),
    ];
    let u4: [OverflowRow; 3] = [
        (16, [(0, W), (15, S), (0, Z), (15, S)]),
        (-1, [(15, W), (0, S), (0, Z), (0, S)]),
        (-100, [(12, W), (0, S), (0, Z), (0, S)]),
    ];
    let s1: [OverflowRow; 4] = [
        (0, [(0, N), (0, N), (0, N), (0, N)]),
        (-1, [(-1, N), (-1, N), (-1, N), (-1, S)]),
        (1, [(-1, W), (0, S), (0, Z), (0, S)]),
        (-2, [(0, W), (-1, S), (0, Z), (-1, S)]),
    ];
    let tables: [(&str, &[OverflowRow]); 3] = [("s4.0", &s4), ("u4.0", &u4), ("s1.0", &s1)];
    for (name, rows) in tables {
        let f = fmt(name);
        for (v, expected) in rows {
            for (mode, (raw, event)) in OVERFLOWS.iter().zip(expected) {
                let want = (big(*raw), *event);
                assert_eq!(
                    apply_overflow(&big(*v), f.is_signed(), f.width(), *mode),
                    want,
                    "v = {v} into {name}, {mode:?}"
                );
                // Through quantize with s = 0, and on formats that differ only in their
                // fraction bits ("only the raw integers and the fraction counts matter").
                let same: &[&str] = match name {
                    "s4.0" => &["s4.0", "s-1.5", "s6.-2"],
                    "u4.0" => &["u4.0", "u-3.7", "u9.-5"],
                    _ => &["s1.0", "s-4.5", "s8.-7"],
                };
                for other in same {
                    let g = fmt(other);
                    let got = quantize(&big(*v), i64::from(g.frac_bits()), g, Rounding::Rnd, *mode);
                    assert_eq!(got, (*raw, *event), "v = {v} into {other}, {mode:?}");
                }
            }
        }
    }
}

/// docs/arithmetic.md section 2.2, the combined example, and section 2: rounding up can
/// overflow (7.5 rounds to 8, which does not fit `s4.0`).
#[test]
fn quantize_examples() {
    assert_eq!(
        quantize(&big(-11), 2, fmt("s2.1"), Rounding::Rnd, Overflow::SatSym),
        (-3, Event::Saturated)
    );
    assert_eq!(
        quantize(&big(15), 1, fmt("s4.0"), Rounding::Rnd, Overflow::Sat),
        (7, Event::Saturated)
    );
    assert_eq!(
        quantize(&big(15), 1, fmt("s4.0"), Rounding::Trn, Overflow::Sat),
        (7, Event::None)
    );
    // The s1.0 rule spelled out: any v <= -1 gives -1, any v >= 1 gives 0, both saturated.
    for v in [-1_000_000_i64, -3, -2, -1] {
        assert_eq!(
            quantize(&big(v), 0, fmt("s1.0"), Rounding::Rnd, Overflow::SatSym),
            (-1, Event::Saturated)
        );
    }
    for v in [1_i64, 2, 1_000_000] {
        assert_eq!(
            quantize(&big(v), 0, fmt("s1.0"), Rounding::Rnd, Overflow::SatSym),
            (0, Event::Saturated)
        );
    }
}

/// docs/arithmetic.md section 2 step 1, `s < 0`: an exact left shift, whatever the rounding
/// mode, then the overflow step on the (possibly huge) result.
#[test]
fn left_shifts() {
    for mode in ROUNDINGS {
        // 1.0 with 0 fraction bits into u1.16 and u1.15.
        assert_eq!(
            quantize(&big(1), 0, fmt("u1.16"), mode, Overflow::Sat),
            (65536, Event::None)
        );
        assert_eq!(
            quantize(&big(1), 0, fmt("u1.15"), mode, Overflow::Sat),
            (32768, Event::None)
        );
        // -3 shifted by 2 is -12, which does not fit s2.2 (codes -8..=7).
        let s22 = fmt("s2.2");
        assert_eq!(
            quantize(&big(-3), 0, s22, mode, Overflow::Wrap),
            (4, Event::Wrapped)
        );
        assert_eq!(
            quantize(&big(-3), 0, s22, mode, Overflow::Sat),
            (-8, Event::Saturated)
        );
        assert_eq!(
            quantize(&big(-3), 0, s22, mode, Overflow::SatSym),
            (-7, Event::Saturated)
        );
        assert_eq!(
            quantize(&big(-3), 0, s22, mode, Overflow::SatZero),
            (0, Event::Zeroed)
        );
        // A 450-bit left shift into u-400.450 (W = 50): 2^450 keeps no low bits.
        let wide = fmt("u-400.450");
        assert_eq!(
            quantize(&big(1), 0, wide, mode, Overflow::Sat),
            ((1_i64 << 50) - 1, Event::Saturated)
        );
        assert_eq!(
            quantize(&big(1), 0, wide, mode, Overflow::Wrap),
            (0, Event::Wrapped)
        );
        // 3 * 2^-450 is exactly code 3 of that format (shift 0).
        assert_eq!(
            quantize(&big(3), 450, wide, mode, Overflow::Sat),
            (3, Event::None)
        );
    }
    // Negative fraction bits on both sides: 5 * 2^10 (f = -10) into s10.-2 (LSB 4) is
    // 5 * 2^8 = 1280 codes, beyond 127: saturated.
    assert_eq!(
        quantize(&big(5), -10, fmt("s10.-2"), Rounding::Rnd, Overflow::Sat),
        (127, Event::Saturated)
    );
    // 5 * 2^-1 (f = 1) into s10.-2 drops 3 bits: 5 / 8 = 0.625 rounds to 1 (RND), 0 (TRN).
    assert_eq!(
        quantize(&big(5), 1, fmt("s10.-2"), Rounding::Rnd, Overflow::Sat),
        (1, Event::None)
    );
    assert_eq!(
        quantize(&big(5), 1, fmt("s10.-2"), Rounding::Trn, Overflow::Sat),
        (0, Event::None)
    );
}

/// Shifts far wider than any machine integer: 75 bits (bug report (b)) and 300 bits.
#[test]
fn huge_right_shifts() {
    // -3276800 * 2^-19 into s60.-56: 75 bits dropped, the value is a tiny negative fraction of
    // an LSB. q = -1 and r = 2^75 - 3276800 > h = 2^74.
    let x = big(-3_276_800);
    let expected_75 = [-1, 0, 0, 0, 0, 0, 0, 0];
    for (mode, want) in ROUNDINGS.iter().zip(expected_75) {
        assert_eq!(round_shift(&x, 75, *mode), big(want), "{mode:?}");
        assert_eq!(
            quantize(&x, 19, fmt("s60.-56"), *mode, Overflow::Sat),
            (want, Event::None),
            "{mode:?}"
        );
    }
    // Exact ties at s = 300: +2^299 (q = 0, r = h) and -2^299 (q = -1, r = h).
    let half = pow2(299);
    let pos = [0, 0, 1, 0, 1, 0, 0, 1];
    let neg = [-1, 0, 0, 0, -1, -1, 0, -1];
    for ((mode, p), n) in ROUNDINGS.iter().zip(pos).zip(neg) {
        assert_eq!(round_shift(&half, 300, *mode), big(p), "+2^299, {mode:?}");
        assert_eq!(round_shift(&-&half, 300, *mode), big(n), "-2^299, {mode:?}");
        // Through a format: f = 200 into s104.-100 (W = 4) drops 300 bits.
        assert_eq!(
            quantize(&half, 200, fmt("s104.-100"), *mode, Overflow::Wrap),
            (p, Event::None)
        );
    }
    // Just above and below the tie.
    for mode in ROUNDINGS.iter().skip(2) {
        assert_eq!(round_shift(&(&half + 1), 300, *mode), big(1), "{mode:?}");
        assert_eq!(round_shift(&(&half - 1), 300, *mode), big(0), "{mode:?}");
    }
    // 5 * 2^300 + (2^300 - 1), dropping 300 bits: q = 5, r just below 2^300.
    let x = big(6) * pow2(300) - 1;
    assert_eq!(round_shift(&x, 300, Rounding::Trn), big(5));
    assert_eq!(round_shift(&x, 300, Rounding::Rnd), big(6));
}

/// docs/arithmetic.md section 2.3 and 3.1.3: constants converted exactly from f64 and rounded
/// once.
#[test]
fn worked_constants() {
    // coef(100) = 4759801726893809 * 2^-48 exactly; u8.16 with RND gives 1108228.
    let (x, f) = exact_f64(16.91021270351388);
    assert_eq!(
        x * pow2(48),
        big(4_759_801_726_893_809) * pow2(f.unsigned_abs())
    );
    let (x, f) = exact_f64(16.91021270351388);
    assert_eq!(f, 48);
    assert_eq!(
        constant(&x, f, fmt("u8.16"), Rounding::Rnd),
        Some(1_108_228)
    );
    assert_eq!(
        constant(&x, f, fmt("u8.16"), Rounding::Trn),
        Some(1_108_227)
    );
    // It does not fit u4.16 (max 15.99998...).
    assert_eq!(constant(&x, f, fmt("u4.16"), Rounding::Rnd), None);

    // Minimax, n = 100: A = 5.987449923395068 into u8.16 gives 392394.
    let (xa, fa) = exact_f64(5.987449923395068);
    assert_eq!(
        constant(&xa, fa, fmt("u8.16"), Rounding::Rnd),
        Some(392_394)
    );
    // A + B exactly = 1125493494458599 * 2^-50; into u1.16 it gives 65512.
    let (xb, fb) = exact_f64(-4.987810890104058);
    let f = fa.max(fb);
    let sum = xa * pow2((f - fa).unsigned_abs()) + xb * pow2((f - fb).unsigned_abs());
    assert_eq!(
        &sum * pow2(50),
        big(1_125_493_494_458_599) * pow2(f.unsigned_abs())
    );
    assert_eq!(constant(&sum, f, fmt("u1.16"), Rounding::Rnd), Some(65_512));
    // A signed format's most negative code is accepted as a constant.
    assert_eq!(constant(&big(-1), 0, fmt("s1.0"), Rounding::Rnd), Some(-1));
    // Subnormals and negative values convert exactly.
    let (x, f) = exact_f64(f64::from_bits(1));
    assert_eq!((x, f), (big(1), 1074));
    let (x, f) = exact_f64(-0.75);
    assert_eq!(x * pow2(2), big(-3) * pow2(f.unsigned_abs()));
}

// ---------------------------------------------------------------------------------------------
// Section 5.2: the worked example, stage by stage, then through oracle_eval.

/// docs/arithmetic.md section 5.2: each row's single quantization (baseline, c_raw = 32700,
/// n = 100).
#[test]
fn worked_example_single_quantizations() {
    let b = Config::baseline();
    let stage = |x: i64, f: i64, spec: &specfx::pipeline::StageSpec| {
        quantize(&big(x), f, spec.format, spec.rounding, spec.overflow)
    };
    // d: (32700 - 32768) << 0.
    assert_eq!(32700 - 32768, -68);
    // t: -68 * 100 = -6800 with 15 + 4 fraction bits; 3 bits dropped exactly.
    assert_eq!(-68 * 100, -6800);
    assert_eq!(stage(-6800, 19, &b.t), (-850, Event::None));
    // b: -850 + (1 << 16) = 64686 with 16 fraction bits; s = 0.
    assert_eq!(-850 + (1 << 16), 64686);
    assert_eq!(stage(64686, 16, &b.b), (64686, Event::None));
    // The squares, 32 fraction bits each, 16 dropped.
    let squares = [
        (64686_i64, 4_184_278_596_i64, 63847_i64),
        (63847, 4_076_439_409, 62202),
        (62202, 3_869_088_804, 59038),
        (59038, 3_485_485_444, 53184),
    ];
    for (i, (s, square, want)) in squares.into_iter().enumerate() {
        assert_eq!(s * s, square);
        assert_eq!(
            stage(square, 32, &b.square[i]),
            (want, Event::None),
            "sq{}",
            i + 1
        );
    }
    // out: 53184 * 1108228 with 32 fraction bits, 16 dropped, r = 65280 >= h.
    assert_eq!(53184 * 1_108_228, 58_939_997_952_i64);
    assert_eq!(stage(58_939_997_952, 32, &b.out), (899_353, Event::None));
    // The rows' q and r.
    let (q, r) = num_integer::Integer::div_mod_floor(&big(58_939_997_952), &pow2(16));
    assert_eq!((q, r), (big(899_352), big(65280)));
}

fn probes(values: &[i64], events: &[Event], cut: bool, input_clamped: bool) -> OracleProbes {
    OracleProbes {
        values: values.to_vec(),
        events: events.to_vec(),
        cut,
        input_clamped,
    }
}

/// docs/arithmetic.md sections 3.1.3 and 5.2: the baseline at n = 100, every probe of the
/// worked example and of the other input codes the section lists.
#[test]
fn worked_example_baseline_n100() {
    let cfg = Config::baseline();
    let dp = Datapath::new(cfg.clone()).expect("the baseline validates");
    let nc = constants(&dp, 100);
    // The constants of section 3.1.3 (inputs to the oracle; checked here against the document).
    assert_eq!(
        (
            nc.slope_raw,
            nc.slope_frac,
            nc.offset_raw,
            nc.offset_frac,
            nc.coef_raw
        ),
        (100, 4, 1, 0, 1_108_228)
    );
    let names: Vec<&str> = dp.stages().iter().map(|s| s.name.as_str()).collect();
    assert_eq!(
        names,
        ["d", "t", "b", "sq1", "sq2", "sq3", "sq4", "coef", "out"]
    );

    let none = [Event::None; 9];
    assert_eq!(
        oracle_eval(&cfg, &nc, 32700),
        probes(
            &[-68, -850, 64686, 63847, 62202, 59038, 53184, 1_108_228, 899_353],
            &none,
            false,
            false
        )
    );
    assert_eq!(
        oracle_eval(&cfg, &nc, 32767),
        probes(
            &[-1, -12, 65524, 65512, 65488, 65440, 65344, 1_108_228, 1_104_981],
            &none,
            false,
            false
        )
    );
    let mut t_saturated = none;
    t_saturated[1] = Event::Saturated;
    for (code, d) in [(0, -32768), (16384, -16384)] {
        assert_eq!(
            oracle_eval(&cfg, &nc, code),
            probes(
                &[d, -131_072, 0, 0, 0, 0, 0, 1_108_228, 0],
                &t_saturated,
                true,
                false
            ),
            "c_raw = {code}"
        );
    }
    for (code, clamped) in [(32768, false), (65535, true)] {
        assert_eq!(
            oracle_eval(&cfg, &nc, code),
            probes(
                &[0, 0, 65536, 65536, 65536, 65536, 65536, 1_108_228, 1_108_228],
                &none,
                false,
                clamped
            ),
            "c_raw = {code}"
        );
    }
}

/// docs/arithmetic.md sections 3.1.3 and 5.2: the minimax variant at n = 100, c_raw = 32700.
#[test]
fn worked_example_minimax_n100() {
    let dp = datapath("variant = \"minimax\"\nn = \"100\"\n");
    let nc = constants(&dp, 100);
    assert_eq!(
        (
            nc.slope_raw,
            nc.slope_frac,
            nc.offset_raw,
            nc.offset_frac,
            nc.coef_raw
        ),
        (392_394, 16, 65512, 16, 1_108_228)
    );
    let p = oracle_eval(dp.config(), &nc, 32700);
    assert_eq!(
        p.values,
        [-68, -814, 64698, 63871, 62248, 59125, 53341, 1_108_228, 902_008]
    );
    assert_eq!(p.events, [Event::None; 9]);
    assert!(!p.cut && !p.input_clamped);
}

/// docs/arithmetic.md section 3.1.4: the paper threshold at n = 100 is 27045.
#[test]
fn worked_example_paper_threshold() {
    let dp = datapath("cutoff = \"paper\"\nn = \"100\"\n");
    let nc = constants(&dp, 100);
    assert_eq!(nc.threshold, Some(27045));
    let cut = oracle_eval(dp.config(), &nc, 27044);
    assert!(cut.cut);
    assert_eq!(&cut.values[2..8], &[0, 0, 0, 0, 0, 1_108_228]);
    // Not cut, but the base 6.25 * (27045 / 32768 - 1) + 1 is still negative: with `paper` it
    // is quantized as it is, and the unsigned `b` saturates to 0 (section 3.2 step 4, notes).
    // t = -572300 * 2^-19 into s2.16: q = -71538, r = 4 = h, so RND gives -71537.
    let kept = oracle_eval(dp.config(), &nc, 27045);
    assert!(!kept.cut);
    assert_eq!(&kept.values[..3], &[-5723, -71537, 0]);
    assert_eq!(
        &kept.events[..3],
        &[Event::None, Event::None, Event::Saturated]
    );
}

// ---------------------------------------------------------------------------------------------
// The bug report's reproductions: values from the report, then the oracle against eval.

/// Bug report (a): at n = 100, c_raw = 32768 the `s1.62` output saturates to 2^62 - 1, and the
/// output never decreases as c_raw goes up over 0..=32768.
#[test]
fn bug_report_wide_out_oracle() {
    let dp = datapath(WIDE_OUT);
    let nc = constants(&dp, 100);
    let top = oracle_eval(dp.config(), &nc, 32768);
    assert_eq!(top.values[8], 4_611_686_018_427_387_903);
    assert_eq!(top.events[8], Event::Saturated);
    let mut before = i64::MIN;
    for code in 0..=32768 {
        let out = oracle_eval(dp.config(), &nc, code).values[8];
        assert!(
            out >= before,
            "out decreases at c_raw = {code}: {before} then {out}"
        );
        before = out;
    }
}

/// Bug report (b): with `t` in `s60.-56`, at n = 100 and c_raw = 0 the t probe is 0.
#[test]
fn bug_report_coarse_t_oracle() {
    let dp = datapath(COARSE_T);
    let nc = constants(&dp, 100);
    let p = oracle_eval(dp.config(), &nc, 0);
    assert_eq!(p.values[1], 0);
    assert_eq!(p.events[1], Event::None);
}

/// Compares `Datapath::eval` with the oracle on every code 0..=65535 for one n, and panics
/// with the first few disagreements (input, both probe sets) and their count.
fn assert_eval_agrees(label: &str, dp: &Datapath, n: u32) {
    let nc = constants(dp, n);
    let len = dp.stages().len();
    assert_eq!(len, dp.config().k as usize + 5);
    let mut mismatches = Vec::new();
    let mut count = 0_usize;
    for code in 0..=65535_i64 {
        let want = oracle_eval(dp.config(), &nc, code);
        let p = dp.eval(code, &nc);
        let got = probes(&p.values[..len], &p.events[..len], p.cut, p.input_clamped);
        if got != want {
            count += 1;
            if mismatches.len() < 5 {
                mismatches.push(format!(
                    "c_raw = {code}:\n  eval   {got:?}\n  oracle {want:?}"
                ));
            }
        }
    }
    assert!(
        count == 0,
        "{label}, n = {n}: Datapath::eval disagrees with the oracle on {count} codes; first:\n{}",
        mismatches.join("\n")
    );
}

#[test]
fn eval_agrees_baseline() {
    let dp = Datapath::new(Config::baseline()).expect("the baseline validates");
    for n in [16, 100, 1024] {
        assert_eval_agrees("baseline", &dp, n);
    }
}

#[test]
fn eval_agrees_bug_report_wide_out() {
    assert_eval_agrees("baseline + [out] s1.62", &datapath(WIDE_OUT), 100);
}

#[test]
fn eval_agrees_bug_report_coarse_t() {
    assert_eval_agrees("baseline + [t] s60.-56", &datapath(COARSE_T), 100);
}
