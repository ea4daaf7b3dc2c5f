//! End-to-end tests of `specfx check` and `specfx vectors` through the built binary.

use crate::common::specfx;

use std::path::{Path, PathBuf};
use std::process::Output;

use sha2::{Digest, Sha256};

fn stdout(o: &Output) -> String {
    String::from_utf8(o.stdout.clone()).unwrap()
}

fn stderr(o: &Output) -> String {
    String::from_utf8(o.stderr.clone()).unwrap()
}

fn temp_path(name: &str) -> PathBuf {
    let p = std::env::temp_dir().join(format!("specfx-cli-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&p);
    let _ = std::fs::remove_file(&p);
    p
}

#[test]
fn check_json_has_the_documented_keys() {
    let o = specfx(&["check", "--config", "baseline", "--n", "64,1024", "--json"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_str(&stdout(&o)).unwrap();
    for key in [
        "shape_quant_max_abs",
        "shape_approx_max_abs",
        "shape_total_max_abs",
        "out_max_ulp",
    ] {
        assert!(v[key].is_number(), "{key}");
    }
    assert_eq!(v["monotonic"], true);
    // Every code from 0 to 1.0 (32769 of them) for each of the two exponents.
    assert_eq!(v["n_evaluations"], 2 * 32769);
    // The approximation error at n = 1024 is the paper's Delta max, 1.70e-2, which is within
    // one cosine code of the continuous maximum.
    let approx = v["shape_approx_max_abs"].as_f64().unwrap();
    assert!((approx - 0.017012).abs() < 1e-4, "{approx}");
    let stages: Vec<&str> = v["stages"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| s["stage"].as_str().unwrap())
        .collect();
    assert_eq!(
        stages,
        ["d", "t", "b", "sq1", "sq2", "sq3", "sq4", "coef", "out"]
    );
}

/// The figures that look alarming carry their explanation on the next line: t's saturation,
/// and the output's error in LSBs as noise bits and effective bits. The noise bits are
/// log2 of the JSON's max ulp; the relative error is max |err| over the largest output, the
/// coefficient of n = 1024 (17 * 1024 / (32 pi) = 173.16) at c = 1.
#[test]
fn check_table_explains_its_large_figures_beside_them() {
    let o = specfx(&["check", "--config", "baseline", "--n", "64,1024"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = stdout(&o);
    let lines: Vec<&str> = text.lines().collect();
    let t = lines
        .iter()
        .position(|l| l.trim_start().starts_with("t "))
        .unwrap();
    assert!(lines[t + 1].contains("^ t saturated"), "{text}");
    let out = lines
        .iter()
        .position(|l| l.trim_start().starts_with("out "))
        .unwrap();
    let j = specfx(&["check", "--config", "baseline", "--n", "64,1024", "--json"]);
    let v: serde_json::Value = serde_json::from_str(&stdout(&j)).unwrap();
    let s = &v["stages"][8];
    let ulp = s["max_ulp"].as_f64().unwrap();
    let rel = s["max_abs_err"].as_f64().unwrap() / (17.0 * 1024.0 / (32.0 * std::f64::consts::PI));
    let want = format!("about {:.1} of its 16 fraction bits are noise", ulp.log2());
    assert!(lines[out + 1].contains(&want), "{}\n{want}", lines[out + 1]);
    assert!(
        lines[out + 1].contains(&format!("{rel:.2e}")),
        "{}",
        lines[out + 1]
    );
    assert!(text.contains("lsb8 = 2^-8 = 3.906e-3"), "{text}");
    assert!(!text.contains("\nnote: t saturated"), "{text}");
}

#[test]
fn check_table_reads_a_user_config_on_top_of_baseline() {
    let cfg = temp_path("narrow.toml");
    std::fs::write(
        &cfg,
        "name = \"narrow\"\nn = \"32\"\n[square]\nformat = \"u1.8\"\nrounding = \"TRN\"\noverflow = \"WRAP\"\n",
    )
    .unwrap();
    let o = specfx(&["check", "--config", cfg.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let out = stdout(&o);
    assert!(
        out.starts_with("check narrow: n = 32 (1 exponents) x 32769"),
        "{out}"
    );
    assert!(out.contains("sq4   u1.8"));
}

#[test]
fn bad_configs_get_one_line_naming_file_and_key() {
    let cfg = temp_path("bad.toml");
    std::fs::write(&cfg, "[t]\nformat = \"s2.16\"\nrounding = \"NEAREST\"\n").unwrap();
    let o = specfx(&["check", "--config", cfg.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
    let err = stderr(&o);
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(err.contains("bad.toml") && err.contains("line 3"), "{err}");

    std::fs::write(&cfg, "[coef]\nformat = \"u4.16\"\n").unwrap();
    let o = specfx(&["check", "--config", cfg.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2));
    let err = stderr(&o);
    assert!(err.contains("coef.format: coef(n = "), "{err}");

    let o = specfx(&["check", "--config", "/nonexistent/x.toml"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("/nonexistent/x.toml"));
}

fn sha256_hex(path: &Path) -> String {
    let bytes = std::fs::read(path).unwrap();
    Sha256::digest(&bytes)
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect()
}

/// RND of x / 2^s with Euclidean division, and the baseline's output from its specification.
fn baseline_out(c_raw: i64, n: i64) -> i64 {
    let rnd = |x: i64, s: u32| (x + (1 << (s - 1))).div_euclid(1 << s);
    let d = c_raw.min(32768) - 32768;
    let t = rnd(d * n, 3).clamp(-(1 << 17), (1 << 17) - 1);
    let mut s = (t + (1 << 16)).clamp(0, (1 << 17) - 1);
    for _ in 0..4 {
        s = rnd(s * s, 16).min((1 << 17) - 1);
    }
    let coef = (17.0 * n as f64 / (32.0 * std::f64::consts::PI) * 65536.0 + 0.5).floor() as i64;
    rnd(s * coef, 16).min((1 << 24) - 1)
}

#[test]
fn vectors_are_complete_correct_deterministic_and_not_overwritten() {
    let dir = temp_path("vec");
    let args = [
        "vectors",
        "--config",
        "baseline",
        "--n",
        "16,100,1024",
        "--cases",
        "corner,random:300",
        "--seed",
        "7",
        "--out",
    ];
    let mut a: Vec<&str> = args.to_vec();
    a.push(dir.to_str().unwrap());
    let o = specfx(&a);
    assert!(o.status.success(), "{}", stderr(&o));

    let manifest: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("manifest.json")).unwrap()).unwrap();
    let n_vectors = manifest["n_vectors"].as_u64().unwrap();
    assert_eq!(manifest["seed"], 7);
    assert_eq!(manifest["cases"], "corner,random:300");
    assert_eq!(manifest["config"]["t"]["format"], "s2.16");
    // Every file listed, with its hash.
    let hashes = manifest["sha256"].as_object().unwrap();
    assert!(hashes.len() >= 12);
    for (name, hash) in hashes {
        assert_eq!(
            sha256_hex(&dir.join(name)),
            hash.as_str().unwrap(),
            "{name}"
        );
    }
    // CSV: header, then one row per vector, each agreeing with the specification.
    let csv = std::fs::read_to_string(dir.join("vectors.csv")).unwrap();
    let mut lines = csv.lines();
    // The ports of the hex files, in their order, with baseline's formats (docs/arithmetic.md):
    // in_n is u11.0 (1024 needs 11 bits), the slope n with k = 4 fraction bits.
    assert_eq!(
        lines.next().unwrap(),
        "in_c:u1.15,in_n:u11.0,in_slope:u7.4,in_offset:u1.0,in_threshold:u1.15,in_coef:u8.16,\
         in_depth:u3.0,probe_d:s1.15,probe_t:s2.16,probe_b:u1.16,probe_sq1:u1.16,probe_sq2:u1.16,\
         probe_sq3:u1.16,probe_sq4:u1.16,expected_out:u8.16"
    );
    assert_eq!(manifest["order"], "interleaved");
    let rows: Vec<Vec<i64>> = lines
        .map(|l| l.split(',').map(|x| x.parse().unwrap()).collect())
        .collect();
    assert_eq!(rows.len() as u64, n_vectors);
    let (c, n, out) = (0, 1, 14);
    for r in &rows {
        assert_eq!(r[out], baseline_out(r[c], r[n]), "row {r:?}");
        // The constants: slope n, offset 1, threshold 0 (clamp cutoff), depth k = 4.
        assert_eq!((r[2], r[3], r[4], r[6]), (r[n], 1, 0, 4), "row {r:?}");
    }
    // Corner cases are there: c = 0, 1.0, above 1.0 and the last code, for every n.
    for n in [16, 100, 1024] {
        for c in [0, 32767, 32768, 32769, 65535] {
            assert!(rows.iter().any(|r| r[1] == n && r[0] == c), "n={n} c={c}");
        }
        // The cutoff boundary: the first code with a non-zero base, and the one before.
        let first_live = (0..=32768).find(|&c| baseline_out_base(c, n) > 0).unwrap();
        for c in [first_live - 1, first_live] {
            assert!(
                rows.iter().any(|r| r[1] == n && r[0] == c),
                "n={n} boundary c={c}"
            );
        }
    }
    // $readmemh: one word per vector, fixed width, trailing newline.
    let out_hex = std::fs::read_to_string(dir.join("expected_out.hex")).unwrap();
    assert!(out_hex.ends_with('\n'));
    let words: Vec<&str> = out_hex.lines().collect();
    assert_eq!(words.len() as u64, n_vectors);
    assert!(words.iter().all(|w| w.len() == 6)); // u8.16: 24 bits
    for (w, r) in words.iter().zip(&rows) {
        assert_eq!(i64::from_str_radix(w, 16).unwrap(), r[out]);
    }
    let t_hex = std::fs::read_to_string(dir.join("probe_t.hex")).unwrap();
    for (w, r) in t_hex.lines().zip(&rows) {
        // s2.16 is 18 bits: two's complement in 5 hex digits.
        let v = i64::from_str_radix(w, 16).unwrap();
        let v = if v >= 1 << 17 { v - (1 << 18) } else { v };
        assert_eq!(v, r[8]);
    }

    // The same command again replaces its own earlier result with the same bytes; a
    // directory that is not a vector directory is refused without --force, and kept.
    let before = std::fs::read(dir.join("vectors.csv")).unwrap();
    let o = specfx(&a);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(std::fs::read(dir.join("vectors.csv")).unwrap(), before);
    let mine = temp_path("vec-mine");
    std::fs::create_dir_all(&mine).unwrap();
    std::fs::write(mine.join("notes.txt"), "mine").unwrap();
    let mut m: Vec<&str> = args.to_vec();
    m.push(mine.to_str().unwrap());
    let o = specfx(&m);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("--force"), "{}", stderr(&o));
    assert_eq!(
        std::fs::read_to_string(mine.join("notes.txt")).unwrap(),
        "mine"
    );
    // With --force into another directory, the files are byte-identical.
    let dir2 = temp_path("vec2");
    let mut b: Vec<&str> = args.to_vec();
    b.push(dir2.to_str().unwrap());
    b.push("--force");
    assert!(specfx(&b).status.success());
    for name in hashes
        .keys()
        .chain(std::iter::once(&"manifest.json".to_string()))
    {
        assert_eq!(
            std::fs::read(dir.join(name)).unwrap(),
            std::fs::read(dir2.join(name)).unwrap(),
            "{name}"
        );
    }
    assert!(!dir.with_extension("partial").exists());
    std::fs::remove_dir_all(&dir).unwrap();
    std::fs::remove_dir_all(&dir2).unwrap();
}

/// The base b of baseline, in u1.16 raw, from its specification.
fn baseline_out_base(c_raw: i64, n: i64) -> i64 {
    let d = c_raw.min(32768) - 32768;
    let t = ((d * n + 4).div_euclid(8)).clamp(-(1 << 17), (1 << 17) - 1);
    (t + (1 << 16)).max(0)
}

#[test]
fn bad_case_selection_is_refused() {
    let dir = temp_path("never");
    let o = specfx(&[
        "vectors",
        "--out",
        dir.to_str().unwrap(),
        "--cases",
        "corners",
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("corners"));
    assert!(!dir.exists());
}
