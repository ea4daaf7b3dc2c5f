//! The batch engine at the edges of what validation accepts: every stage's exact fallback is
//! chosen where the `i64` kernel would overflow, and gives `eval`'s bits; the two reproductions
//! of issue 10 give the values an independent oracle derived, through the library and the CLI.

use crate::common;

use specfx::pipeline::{Config, Datapath, ProbeColumns};

fn datapath(toml: &str) -> Datapath {
    Datapath::new(Config::from_toml(toml).expect("valid TOML")).expect("accepted configuration")
}

/// `eval_batch` on every code of the input format, checked against `eval` code by code.
fn batch_rows(dp: &Datapath, n: u32) -> ProbeColumns {
    let nc = dp.constants_for(n).expect("n in the set");
    let codes: Vec<i64> = dp.input_codes().collect();
    let mut cols = ProbeColumns::default();
    dp.eval_batch(nc, &codes, &mut cols);
    let mut counts = vec![[0u64; 3]; dp.stages().len()];
    for (i, &code) in codes.iter().enumerate() {
        let p = dp.eval(code, nc);
        assert_eq!(cols.row(i).values, p.values, "n = {n}, c_raw = {code}");
        assert_eq!(cols.row(i).cut, p.cut, "n = {n}, c_raw = {code}");
        for (stage_idx, e) in p.events.iter().take(dp.stages().len()).enumerate() {
            match e {
                specfx::fixed::Event::None => {}
                specfx::fixed::Event::Wrapped => counts[stage_idx][0] += 1,
                specfx::fixed::Event::Saturated => counts[stage_idx][1] += 1,
                specfx::fixed::Event::Zeroed => counts[stage_idx][2] += 1,
            }
        }
    }
    assert_eq!(counts, cols.event_counts, "event counts, n = {n}");
    cols
}

#[test]
fn an_output_shifted_past_i64_saturates() {
    // sq4 (u1.15) x coef (u8.16) has 31 fraction bits; s1.62 needs a left shift by 31 of a
    // 40-bit product: beyond i64, so the output stage falls back to the exact kernel.
    let dp = datapath("n = \"100\"\n[out]\nformat = \"s1.62\"\n");
    let plan = dp.batch_plan_of();
    assert!(!plan.out.is_fast());
    assert!(plan.t.is_fast() && plan.b.is_fast());
    let cols = batch_rows(&dp, 100);
    let out = &cols.values[dp.stage_out()];
    // c = 1.0: out = coef(100) > 1 saturates to the largest s1.62 code, 2^62 - 1.
    assert_eq!(out[32768], (1i64 << 62) - 1);
    // The output never decreases with c, and never goes negative.
    assert!(out[..=32768].windows(2).all(|w| w[0] <= w[1]));
    assert!(out.iter().all(|&v| v >= 0));
}

#[test]
fn a_right_shift_of_75_bits_rounds_to_zero() {
    // t's exact product has 15 + 4 = 19 fraction bits; s60.-56 keeps multiples of 2^56: a right
    // shift by 75. At c = 0, t = -100/16 = -6.25, which RND rounds to 0 on a 2^56 grid.
    let dp = datapath("n = \"100\"\n[t]\nformat = \"s60.-56\"\n");
    assert!(!dp.batch_plan_of().t.is_fast());
    let cols = batch_rows(&dp, 100);
    assert!(cols.values[1].iter().all(|&t| t == 0));
    assert!(cols.cut.iter().all(|&cut| !cut));
}

#[test]
fn a_sum_wider_than_i64_uses_the_exact_b_stage() {
    // t in s2.60: the exact sum t + 1 needs 63 bits.
    let dp = datapath("n = \"16,100\"\n[t]\nformat = \"s2.60\"\n");
    assert!(!dp.batch_plan_of().b.is_fast());
    batch_rows(&dp, 16);
    batch_rows(&dp, 100);
}

#[test]
fn wide_squares_and_huge_right_shifts_fall_back() {
    // b in u1.40: the first square's exact input has 82 bits.
    let dp = datapath("n = \"100\"\n[b]\nformat = \"u1.40\"\n");
    let plan = dp.batch_plan_of();
    assert!(!plan.squares[0].is_fast());
    assert!(plan.squares[1..].iter().all(|k| k.is_fast()));
    batch_rows(&dp, 100);
    // A SAT_ZERO squaring that keeps multiples of 2^100 from a 32-fraction-bit square: a right
    // shift by 132. Every square (below 4) rounds to 0 and nothing overflows: no event.
    let dp = datapath(
        "n = \"100\"\n[[square]]\nformat = \"u110.-100\"\noverflow = \"SAT_ZERO\"\n\
         [[square]]\nformat = \"u1.15\"\n[[square]]\nformat = \"u1.15\"\n[[square]]\nformat = \"u1.15\"\n",
    );
    assert!(!dp.batch_plan_of().squares[0].is_fast());
    let cols = batch_rows(&dp, 100);
    assert_eq!(cols.event_counts[3], [0, 0, 0]);
    assert!(cols.values[3].iter().all(|&v| v == 0));
}

#[test]
fn the_reproductions_through_vectors_and_check() {
    let dir = tempfile::tempdir().unwrap();
    let cases = [
        ("s1.62", "[out]\nformat = \"s1.62\"\n"),
        ("t", "[t]\nformat = \"s60.-56\"\n"),
    ];
    for (name, body) in cases {
        let cfg = dir.path().join(format!("{name}.toml"));
        std::fs::write(&cfg, format!("n = \"100\"\n{body}")).unwrap();
        let out = dir.path().join(name);
        let run = common::specfx(&[
            "vectors",
            "--config",
            cfg.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
            "--cases",
            "exhaustive",
        ]);
        assert!(
            run.status.success(),
            "{}",
            String::from_utf8_lossy(&run.stderr)
        );
        let csv = std::fs::read_to_string(out.join("vectors.csv")).unwrap();
        let row = |c_raw: i64| -> Vec<i64> {
            csv.lines()
                .skip(1)
                .map(|l| {
                    l.split(',')
                        .map(|f| f.parse().unwrap())
                        .collect::<Vec<i64>>()
                })
                .find(|r| r[0] == c_raw) // in_c is the first column
                .unwrap()
        };
        let check = common::specfx(&["check", "--config", cfg.to_str().unwrap(), "--json"]);
        let json: serde_json::Value = serde_json::from_slice(&check.stdout).unwrap();
        assert_eq!(json["monotonic"], true, "{name}");
        if name == "t" {
            // t = 0 at c = 0, so no base is cut.
            assert_eq!(row(0)[8], 0); // probe_t
            assert_eq!(json["n_cut"], 0);
        } else {
            assert_eq!(*row(32768).last().unwrap(), 4_611_686_018_427_387_903);
            assert!(*row(32114).last().unwrap() >= 0);
        }
    }
}

#[test]
fn wide_inputs_get_their_corner_cases_by_bisection() {
    // u1.40: 2^40 + 1 codes up to 1.0 per n; the cut codes are a prefix (t saturates), so the
    // switching point is found by bisection and checked here against the scalar model.
    let dp = datapath("n = \"17,1024\"\n[c]\nformat = \"u1.40\"\n[d]\nformat = \"s1.40\"\n");
    for n in [17, 1024] {
        let nc = dp.constants_for(n).unwrap();
        let set = specfx::golden::cases::corner_codes(&dp, n).codes;
        let live = dp.first_live_code(nc, 0..dp.one_code() + 1);
        assert!(
            dp.eval(live - 1, nc).cut && !dp.eval(live, nc).cut,
            "n = {n}"
        );
        assert!(set.contains(&(live - 1)) && set.contains(&live), "n = {n}");
        // The base (n/16)(c - 1) + 1 is cut below c = 1 - 16/n, up to t's rounding (2^-16).
        let edge = 1.0 - 16.0 / f64::from(n);
        let live_c = live as f64 / 2f64.powi(40);
        assert!(
            (live_c - edge).abs() <= 2f64.powi(-16) * 16.0 / f64::from(n) + 1e-12,
            "n = {n}"
        );
    }
}
