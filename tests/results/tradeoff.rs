//! `specfx tradeoff`: every method listed with its figures, charts written, and errors that
//! agree with a brute-force oracle.

use std::process::Command;

/// Runs `specfx tradeoff --json --out <temp dir named after tag>` with `args`; returns the
/// parsed JSON and the directory.
fn tradeoff_json(tag: &str, args: &[&str]) -> (serde_json::Value, std::path::PathBuf) {
    let dir = std::env::temp_dir().join(format!("specfx-tradeoff-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let o = Command::new(env!("CARGO_BIN_EXE_specfx"))
        .arg("tradeoff")
        .args(args)
        .args(["--json", "--out", dir.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    (serde_json::from_slice(&o.stdout).unwrap(), dir)
}

#[test]
fn tradeoff_lists_every_method_with_figures_that_hold() {
    let (v, dir) = tradeoff_json("all", &["--n", "64,256"]);
    let list = v.as_array().unwrap();
    let names: Vec<&str> = list.iter().map(|m| m["method"].as_str().unwrap()).collect();
    for want in [
        "powf",
        "powi",
        "schlick",
        "exp_limit",
        "cs4_clamp",
        "cs16_paper",
        "cs128_none",
        "minimax4",
        "minimax128",
        "minimax64_per_n",
        "fixed_sq8",
        "fixed_sq16",
    ] {
        assert!(names.contains(&want), "{want} missing from {names:?}");
    }
    for m in list {
        for key in ["max_abs_err", "mean_abs_err"] {
            assert!(m[key].is_number(), "{}: {key}", m["method"]);
        }
        // Measured speed is a property of this run, kept out of the JSON.
        assert!(m.get("evals_per_s").is_none());
    }
    // The per-n depth up to m = 64 takes, at each n, the least error of minimax m <= 64 (m = 2
    // is never the best at these n).
    let per_n = |name: &str| -> Vec<f64> {
        let m = list.iter().find(|m| m["method"] == name).unwrap();
        m["per_n_max_abs_err"]
            .as_array()
            .unwrap()
            .iter()
            .map(|e| e.as_f64().unwrap())
            .collect()
    };
    let best = per_n("minimax64_per_n");
    for (i, &e) in best.iter().enumerate() {
        let least = [
            "minimax4",
            "minimax8",
            "minimax16",
            "minimax32",
            "minimax64",
        ]
        .iter()
        .map(|m| per_n(m)[i])
        .fold(f64::INFINITY, f64::min);
        assert!((e - least).abs() <= 1e-12, "n #{i}: {e} vs {least}");
    }
    // Brute force: exp(-n(1-c)) against c^n on a fine uniform grid, n = 64 and 256.
    let mut brute: f64 = 0.0;
    for n in [64.0f64, 256.0] {
        for i in 0..=200_000 {
            let c = f64::from(i) / 200_000.0;
            brute = brute.max(((-n * (1.0 - c)).exp() - c.powf(n)).abs());
        }
    }
    let exp = list.iter().find(|m| m["method"] == "exp_limit").unwrap();
    let got = exp["max_abs_err"].as_f64().unwrap();
    assert!(
        got >= brute - 1e-12 && got - brute < 1e-6,
        "{got} vs {brute}"
    );
    for file in [
        "tradeoff.csv",
        "tradeoff.json",
        "measured_speed.csv",
        "measured_speed_accuracy.svg",
        "measured_speed_accuracy.png",
        "error_vs_n.svg",
        "error_vs_n.png",
    ] {
        assert!(dir.join(file).is_file(), "{file}");
    }
    let speed = std::fs::read_to_string(dir.join("measured_speed.csv")).unwrap();
    assert_eq!(speed.lines().count(), list.len() + 1);
    for line in speed.lines().skip(1) {
        let evals: f64 = line.split(',').nth(2).unwrap().parse().unwrap();
        assert!(evals > 0.0, "{line}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn tradeoff_synthesises_the_datapaths_with_yosys_on_request() {
    // `./scripts/test` installs yosys. Wider squares cost more logic: the 16-bit squares'
    // datapath needs more iCE40 LUTs than the 8-bit one, and only datapaths are synthesised.
    let (v, dir) = tradeoff_json("yosys", &["--n", "64", "--yosys", "ice40"]);
    let list = v.as_array().unwrap();
    let luts = |name: &str| {
        let m = list.iter().find(|m| m["method"] == name).unwrap();
        m["yosys"]["luts"].as_u64()
    };
    assert_eq!(luts("schlick"), None);
    let (l8, l16) = (luts("fixed_sq8").unwrap(), luts("fixed_sq16").unwrap());
    assert!(l8 > 0 && l16 > l8, "{l8} {l16}");
    let csv = std::fs::read_to_string(dir.join("tradeoff.csv")).unwrap();
    assert!(csv
        .lines()
        .next()
        .unwrap()
        .ends_with("yosys_target,yosys_luts,yosys_dsps,yosys_ffs"));
    assert!(csv
        .lines()
        .any(|l| l.starts_with("fixed_sq8,") && l.contains(",ice40,")));
}

/// Everything but the `measured_*` files is byte-identical from run to run and with 1 or 2
/// threads: measured speed is kept in files of its own.
#[test]
fn tradeoff_files_are_the_same_bytes_on_every_run() {
    let run = |tag: &str, threads: &str| {
        let dir =
            std::env::temp_dir().join(format!("specfx-tradeoff-det-{tag}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        let o = Command::new(env!("CARGO_BIN_EXE_specfx"))
            .args(["tradeoff", "--n", "64,256", "--out", dir.to_str().unwrap()])
            .env("RAYON_NUM_THREADS", threads)
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let mut files: Vec<(String, Vec<u8>)> = std::fs::read_dir(&dir)
            .unwrap()
            .map(|e| {
                let p = e.unwrap().path();
                let name = p.file_name().unwrap().to_string_lossy().into_owned();
                (name, std::fs::read(&p).unwrap())
            })
            .filter(|(name, _)| !name.starts_with("measured_"))
            .collect();
        files.sort();
        std::fs::remove_dir_all(&dir).unwrap();
        files
    };
    let a = run("a", "1");
    let b = run("b", "2");
    assert!(a.len() >= 14, "{} files", a.len());
    assert_eq!(
        a.iter().map(|f| &f.0).collect::<Vec<_>>(),
        b.iter().map(|f| &f.0).collect::<Vec<_>>()
    );
    for (x, y) in a.iter().zip(&b) {
        assert!(x.1 == y.1, "{} differs between runs", x.0);
    }
}
