//! End-to-end tests of the `specfx` binary: outputs, JSON shapes and error handling.

use crate::common::specfx;

use std::f64::consts::PI;
use std::process::Output;

fn stdout(o: &Output) -> String {
    String::from_utf8(o.stdout.clone()).expect("utf-8 stdout")
}

fn stderr(o: &Output) -> String {
    String::from_utf8(o.stderr.clone()).expect("utf-8 stderr")
}

#[test]
fn paper_json_has_every_documented_key() {
    let o = specfx(&["paper", "--json"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_str(&stdout(&o)).expect("valid JSON");
    let d = &v["delta"];
    for key in ["max", "min", "claim_max", "claim_min"] {
        assert!(d[key].is_number(), "delta.{key}");
    }
    for key in ["reproduced_max", "reproduced_min"] {
        assert!(d[key].is_boolean(), "delta.{key}");
    }
    let forms = v["forms"].as_array().expect("forms array");
    let names: Vec<&str> = forms.iter().map(|f| f["form"].as_str().unwrap()).collect();
    assert_eq!(
        names,
        [
            "phong",
            "phong_modified",
            "blinn_phong",
            "blinn_phong_modified",
            "blinn_phong_ndf",
            "blinn_phong_heightfield"
        ]
    );
    for f in forms {
        for key in [
            "claim_res_max",
            "paper_res_max",
            "refit_res_max",
            "exact_res_max",
        ] {
            assert!(f[key].is_number(), "{}.{key}", f["form"]);
        }
        assert!(f["reproduced"].is_boolean());
        assert!(f["refit"]["a"].is_number() && f["refit"]["b"].is_number());
    }
}

#[test]
fn paper_phong_residual_is_the_hand_computed_one() {
    // Hand derivation: for n >= 16 the clamped cs16 lobe integrates to 16/(17 n), so with the
    // paper's coef 1.063 n/(2 pi), res = 1.063 * 16/17 - 1 for every n (the 6/sqrt(n) reading
    // cuts only a part of the lobe < 1e-15 for n >= 26 and truncates a little below).
    let o = specfx(&["paper", "--json"]);
    let v: serde_json::Value = serde_json::from_str(&stdout(&o)).unwrap();
    let phong = &v["forms"][0];
    let want = 1.063 * 16.0 / 17.0 - 1.0;
    let got = phong["paper_res_max"].as_f64().unwrap();
    assert!((got - want).abs() < 1e-9, "{got} vs {want}");
    assert_eq!(phong["reproduced"], true);
    // Exact coefficients normalise to rounding.
    for f in v["forms"].as_array().unwrap() {
        assert!(f["exact_res_max"].as_f64().unwrap() < 1e-12);
    }
}

#[test]
fn paper_table_is_readable() {
    let o = specfx(&["paper"]);
    assert!(o.status.success());
    let out = stdout(&o);
    assert!(out.contains("Delta(theta, n)"));
    assert!(out.contains("blinn_phong_heightfield"));
    assert!(out.contains("printed claims reproduce"));
}

#[test]
fn coef_json_gives_the_closed_form() {
    let o = specfx(&[
        "coef", "--form", "phong", "--source", "exact", "--n", "64", "--json",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_str(&stdout(&o)).unwrap();
    let coef = v["coefficients"][0]["coef"].as_f64().unwrap();
    // (m + 1)/m * n/(2 pi) with m = 16, n = 64.
    let want = 17.0 * 64.0 / (32.0 * PI);
    assert!((coef / want - 1.0).abs() < 1e-14);
}

#[test]
fn bad_inputs_get_one_line_and_exit_code_2() {
    for args in [
        &["coef", "--form", "lambert"][..],
        &["coef", "--n", "0"],
        &["coef", "--k", "9"],
        &["minimax", "--n", "5000"],
        &["minimax", "--k", "8"],
        &["report", "--out", "/proc/forbidden/x"],
    ] {
        let o = specfx(args);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {}", stderr(&o));
        let err = stderr(&o);
        assert!(err.contains("error"), "{args:?}: {err}");
        assert!(stdout(&o).is_empty(), "{args:?} printed to stdout");
    }
    let o = specfx(&["minimax", "--n", "5000"]);
    assert_eq!(stderr(&o).lines().count(), 1, "{}", stderr(&o));
    assert!(stderr(&o).contains("n = 5000"));
}

#[test]
fn minimax_shows_cached_rows() {
    let o = specfx(&["minimax", "--n", "64,128", "--k", "4"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let out = stdout(&o);
    let lines: Vec<&str> = out.lines().collect();
    assert_eq!(lines[0], "k,n,a,b,max_abs_err,plain_max_abs_err");
    assert_eq!(lines.len(), 3);
    assert!(lines[1].starts_with("4,64,"));
    assert!(lines[2].starts_with("4,128,"));
}
