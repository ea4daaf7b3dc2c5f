//! `specfx budget`: the mixed models behind the attribution against hand oracles, parts that
//! add up to the total, headroom, gappa bounds that hold, and the command end to end.

use std::path::PathBuf;
use std::process::Command;

use crate::common::specfx;
use specfx::analysis::budget::analyse;
use specfx::analysis::check::reference_probes;
use specfx::analysis::gappa;
use specfx::pipeline::f64_walk::{mixed_eval, sources, Source, ALL_SOURCES};
use specfx::pipeline::{Config, Datapath};
use specfx::reference::lobe::Cutoff;

fn config_file(name: &str) -> Config {
    let path = format!("{}/tests/configs/{name}.toml", env!("CARGO_MANIFEST_DIR"));
    Config::from_toml(&std::fs::read_to_string(path).unwrap()).unwrap()
}

fn out_value(dp: &Datapath, raw: i64) -> f64 {
    dp.stages()[dp.stage_out()].format.to_f64(raw)
}

#[test]
fn every_source_quantized_is_the_datapath_itself() {
    // The products of these configurations have at most 53 bits, so f64 holds them exactly.
    for (cfg, ns) in [
        (Config::baseline(), vec![16, 100, 1024]),
        (config_file("narrow_trn_wrap"), vec![8, 13, 250]),
        (config_file("conv_sym_k5"), vec![32, 200, 1000]),
        (config_file("minimax_folded"), vec![16, 512]),
    ] {
        let dp = Datapath::new(cfg).unwrap();
        for n in ns {
            let nc = dp.constants_for(n).unwrap();
            for code in dp.input_codes() {
                let fixed = dp.eval(code, nc);
                let (lobe, out) = mixed_eval(&dp, nc, code, ALL_SOURCES);
                let lobe_fmt = dp.stages()[dp.stage_last_square()].format;
                assert_eq!(
                    (lobe, out),
                    (
                        lobe_fmt.to_f64(fixed.values[dp.stage_last_square()]),
                        out_value(&dp, fixed.values[dp.stage_out()])
                    ),
                    "{} n = {n} code {code}",
                    dp.config().name
                );
            }
        }
    }
}

#[test]
fn no_source_quantized_is_the_reference_of_check() {
    let dp = Datapath::new(config_file("conv_sym_k5")).unwrap();
    for n in [32, 1000] {
        let nc = dp.constants_for(n).unwrap();
        for code in dp.input_codes() {
            let c = code as f64 * dp.config().c.format.lsb();
            let r = reference_probes(&dp, nc, c);
            let (lobe, out) = mixed_eval(&dp, nc, code, 0);
            assert_eq!((lobe, out), (r[dp.stage_last_square()], r[dp.stage_out()]));
        }
    }
}

#[test]
fn t_alone_quantized_matches_a_hand_oracle() {
    // Baseline, n = 100: t * 2^16 = (100 / 16) * (code - 32768) * 2^16 / 2^15
    // = 12.5 * (code - 32768), rounded half up (RND) and saturated to s2.16, then
    // b = max(0, t + 1), the lobe b^16 and the output lobe * coef, all exact.
    let dp = Datapath::new(Config::baseline()).unwrap();
    let nc = dp.constants_for(100).unwrap();
    for code in (0..=32768i64).step_by(7) {
        let twice = 25 * (code - 32768); // 2 * t * 2^16, an integer
        let t_raw = (twice + 1).div_euclid(2).max(-(2 << 16)); // floor(x + 1/2)
        let b = (t_raw as f64 / 65536.0 + 1.0).max(0.0);
        let want = b.powi(16) * nc.coef;
        let got = mixed_eval(&dp, nc, code, Source::T.mask()).1;
        assert!(
            (got - want).abs() <= 1e-13 * want.max(1.0),
            "code {code}: {got} vs {want}"
        );
    }
}

fn wide_inside(out_rounding: &str) -> Config {
    // Every inner stage 40 fraction bits and the cut off: the output rounding is the only
    // error of note, and the base is c itself at n = m = 16.
    let text = format!(
        r#"
name = "wide_inside"
cutoff = "none"
n = "16"
[t]
format = "s7.40"
[b]
format = "u1.40"
[square]
format = "u1.40"
[coef]
format = "u8.40"
[out]
format = "u8.16"
rounding = "{out_rounding}"
"#
    );
    Config::from_toml(&text).unwrap()
}

#[test]
fn output_rounding_alone_is_attributed_to_the_output() {
    let dp = Datapath::new(wide_inside("RND")).unwrap();
    let r = analyse(&dp, None).unwrap();
    let a = &r.attribution;
    let by = |name: &str| a.sources.iter().find(|s| s.source == name).unwrap();
    // Round to nearest: at most half an LSB, in the datapath and in the out-only model.
    assert!(a.total.max_ulp <= 0.5 + 1e-6, "{}", a.total.max_ulp);
    assert!(by("out").max_ulp <= 0.5 && by("out").max_ulp > 0.49);
    for s in ["t", "b", "sq1", "sq4", "coef"] {
        assert!(by(s).max_ulp < 1e-3, "{s}: {}", by(s).max_ulp);
    }
}

#[test]
fn truncation_bias_matches_a_slow_oracle() {
    let dp = Datapath::new(wide_inside("TRN")).unwrap();
    let r = analyse(&dp, None).unwrap();
    let nc = dp.constants_for(16).unwrap();
    // floor(x * 2^16) / 2^16 - x over every code, with x = coef * c^16.
    let mut sum = 0.0;
    let codes = 32769;
    for code in 0..codes {
        let c = code as f64 / 32768.0;
        let x = nc.coef * c.powi(16);
        sum += (x * 65536.0).floor() / 65536.0 - x;
    }
    let want = sum / codes as f64;
    let out = r
        .attribution
        .sources
        .iter()
        .find(|s| s.source == "out")
        .unwrap();
    assert!(
        (out.mean - want).abs() < 1e-3 * want.abs(),
        "{} vs {want}",
        out.mean
    );
    assert!(want < -0.2 / 65536.0, "truncation biases downwards: {want}");
}

#[test]
fn the_parts_add_up_to_the_total() {
    for cfg in [Config::baseline(), config_file("conv_sym_k5")] {
        let mut cfg = cfg;
        cfg.n = "16..=96".parse().unwrap();
        let dp = Datapath::new(cfg).unwrap();
        let r = analyse(&dp, None).unwrap();
        let a = &r.attribution;
        assert_eq!(
            a.sources
                .iter()
                .map(|s| s.source.clone())
                .collect::<Vec<_>>(),
            sources(&dp).iter().map(|s| s.name()).collect::<Vec<_>>()
        );
        // Incremental parts telescope: their means add up to the total's mean.
        let inc_mean: f64 = a.incremental.iter().map(|s| s.mean).sum();
        assert!(
            (inc_mean - a.total.mean).abs() <= 1e-9 * a.total.max_abs,
            "{inc_mean} vs {}",
            a.total.mean
        );
        let inc_max: f64 = a.incremental.iter().map(|s| s.max_abs).sum();
        assert!(a.total.max_abs <= inc_max * (1.0 + 1e-12));
        assert!(a.total.max_abs <= (a.sum_of_max_abs + a.residual_max_abs) * (1.0 + 1e-12));
        // The measured total is the check's output error.
        let out = r.check.stages.last().unwrap();
        assert_eq!(a.total.max_abs, out.max_abs_err);
        // The histograms count every evaluation once.
        assert_eq!(r.histogram_out.total(), r.check.n_evaluations);
        assert_eq!(r.histogram_out.below + r.histogram_out.above, 0);
    }
}

#[test]
fn headroom_counts_integer_bits_by_hand() {
    let mut cfg = Config::baseline();
    cfg.n = "64".parse().unwrap();
    cfg.b.format = "u3.16".parse().unwrap();
    let dp = Datapath::new(cfg).unwrap();
    let r = analyse(&dp, None).unwrap();
    let b = r.headroom.iter().find(|h| h.stage == "b").unwrap();
    // b reaches 1.0 exactly (c = 1), which needs one integer bit: two are spare.
    assert_eq!(
        (b.seen_max, b.int_bits_needed, b.spare_int_bits),
        (1.0, 1, 2)
    );
    // t = 4 (c - 1) reaches -4 and saturates at s2.16's -2: no spare bit.
    let t = r.headroom.iter().find(|h| h.stage == "t").unwrap();
    assert_eq!((t.seen_min, t.spare_int_bits), (-2.0, 0));
    assert!(t.saturated > 0);
}

fn run_gappa(script: &str) -> String {
    use std::io::Write;
    let mut child = Command::new("gappa")
        .stdin(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .stdout(std::process::Stdio::piped())
        .spawn()
        .expect("gappa is installed (scripts/test installs it)");
    child
        .stdin
        .take()
        .unwrap()
        .write_all(script.as_bytes())
        .unwrap();
    let out = child.wait_with_output().unwrap();
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// The largest |fixed output - f64 output| of one n, by brute force.
fn exhaustive(dp: &Datapath, n: u32) -> f64 {
    let nc = dp.constants_for(n).unwrap();
    dp.input_codes()
        .map(|code| {
            let fixed = out_value(dp, dp.eval(code, nc).values[dp.stage_out()]);
            (fixed - mixed_eval(dp, nc, code, 0).1).abs()
        })
        .fold(0.0, f64::max)
}

#[test]
fn gappa_bounds_hold_and_are_tight_where_they_can_be() {
    for (cfg, ns) in [
        (Config::baseline(), vec![16, 29, 100, 1024]),
        (config_file("conv_sym_k5"), vec![32, 200, 1000]),
        (config_file("minimax_folded"), vec![16, 512]),
    ] {
        let dp = Datapath::new(cfg).unwrap();
        assert_ne!(dp.config().cutoff, Cutoff::None);
        for n in ns {
            let job = gappa::job(&dp, dp.constants_for(n).unwrap()).unwrap();
            let bound = gappa::bound(&job, &run_gappa(&job.script)).unwrap();
            let seen = exhaustive(&dp, n);
            assert!(
                bound >= seen,
                "{} n = {n}: proved {bound} below the exhaustive {seen}",
                dp.config().name
            );
        }
    }
    // Only the output rounds (to nearest): the proof must find half an LSB, plus the tiny
    // errors of the 40-bit inner stages.
    let dp = Datapath::new(wide_inside("RND")).unwrap();
    let job = gappa::job(&dp, dp.constants_for(16).unwrap()).unwrap();
    let bound = gappa::bound(&job, &run_gappa(&job.script)).unwrap() * 65536.0;
    assert!((0.5..0.501).contains(&bound), "{bound} LSB");
}

fn temp_dir(tag: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("specfx-budget-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

#[test]
fn budget_command_writes_a_deterministic_self_contained_report() {
    let files = [
        "budget.md",
        "budget.html",
        "budget.json",
        "histogram_out.svg",
        "histogram_out.png",
        "histogram_shape.svg",
        "error_vs_c.svg",
        "error_vs_n.png",
        "output_error_vs_c.svg",
        "output_error_vs_n.png",
    ];
    let mut runs = Vec::new();
    for tag in ["a", "b"] {
        let dir = temp_dir(tag);
        let o = specfx(&[
            "budget",
            "--n",
            "16..=64",
            "--budget",
            "shape_total <= 5 lsb8, out <= 4000 ulp",
            "--out",
            dir.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let bytes: Vec<Vec<u8>> = files
            .iter()
            .map(|f| std::fs::read(dir.join(f)).unwrap_or_else(|_| panic!("{f} written")))
            .collect();
        runs.push(bytes);
        let _ = std::fs::remove_dir_all(&dir);
    }
    assert!(runs[0] == runs[1], "two runs wrote different bytes");
    let html = String::from_utf8(runs[0][1].clone()).unwrap();
    assert_eq!(html.matches("<svg").count(), 6, "every chart inlined");
    assert!(!html.contains("src=") && !html.contains(".svg\""));
    let md = String::from_utf8(runs[0][0].clone()).unwrap();
    assert!(md.contains("| t | s2.16 | RND |") && md.contains("**PASS**"));
    let json: serde_json::Value = serde_json::from_slice(&runs[0][2]).unwrap();
    assert_eq!(json["pass"], true);
    assert!(!json["formal"].as_array().unwrap().is_empty(), "gappa ran");
}

#[test]
fn budget_fails_with_exit_1_and_bad_input_with_exit_2() {
    let dir = temp_dir("fail");
    let o = specfx(&[
        "budget",
        "--n",
        "64",
        "--budget",
        "out <= 1 ulp",
        "--no-gappa",
        "--json",
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(1));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["pass"], false);
    assert_eq!(v["bounds"][0]["pass"], false);
    let _ = std::fs::remove_dir_all(&dir);

    for args in [
        vec!["budget", "--budget", "out <= one ulp"],
        vec!["budget", "--n", "16..=32", "--gappa-n", "5"],
        vec!["budget", "--config", "/nonexistent.toml"],
    ] {
        let dir = temp_dir("bad");
        let mut args = args.clone();
        args.extend(["--out", dir.to_str().unwrap()]);
        let o = specfx(&args);
        assert_eq!(o.status.code(), Some(2), "{args:?}");
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(err.trim().lines().count(), 1, "{err}");
        assert!(!dir.exists(), "{args:?} wrote output");
    }
}
