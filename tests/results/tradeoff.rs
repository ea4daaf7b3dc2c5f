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
    let (v, dir) = tradeoff_json("all", &["--n", "64,256", "--ladder", "none"]);
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
    assert!(!dir.join("frontier.csv").exists());
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
    let (v, dir) = tradeoff_json(
        "yosys",
        &["--n", "64", "--yosys", "ice40", "--ladder", "none"],
    );
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
/// threads: measured speed is kept in files of its own. (The frontier at two budgets: the
/// parallel search per algorithm is what a thread count could change.)
#[test]
fn tradeoff_files_are_the_same_bytes_on_every_run() {
    let run = |tag: &str, threads: &str| {
        let dir =
            std::env::temp_dir().join(format!("specfx-tradeoff-det-{tag}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        let o = Command::new(env!("CARGO_BIN_EXE_specfx"))
            .args(["tradeoff", "--n", "64,256", "--ladder", "2,1"])
            .args(["--out", dir.to_str().unwrap()])
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

/// The frontier: every point is proved within its budget by the test oracle's own evaluation
/// (the cheapest point within 1 lsb8) and by `specfx check` (every point), is what
/// `specfx optimize` answers for its algorithm and budget (or a tighter budget's cheaper
/// answer), never costs more for a looser budget, and is missing exactly where the
/// algorithm's f64 floor is above the budget or no datapath was found.
#[test]
fn the_frontier_is_the_optimisers_answer_within_each_budget() {
    use specfx::pipeline::{Config, Datapath};
    let (_, dir) = tradeoff_json("frontier", &["--n", "64,256", "--ladder", "2,1"]);
    let f: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.join("frontier.json")).unwrap()).unwrap();
    let points = f["points"].as_array().unwrap();
    let csv = std::fs::read_to_string(dir.join("frontier.csv")).unwrap();
    assert_eq!(csv.lines().count(), points.len() + 1);
    for stem in [
        "error_vs_cost_ice40",
        "error_vs_dsps_ice40",
        "error_vs_luts_ice40",
    ] {
        assert!(dir.join(format!("{stem}.png")).is_file(), "{stem}");
    }
    let lsb8 = 1.0 / 256.0;
    let name = |a: &serde_json::Value| {
        format!(
            "{}{}{}",
            a["variant"].as_str().unwrap().to_lowercase(),
            a["k"],
            if a["per_n"].as_bool().unwrap() {
                "_per_n"
            } else {
                ""
            }
        )
    };
    // Present exactly where the floor allows (every algorithm with a floor within 2 lsb8
    // has some datapath within the budget at n = 64, 256: at least its start point).
    for floor in f["floors"].as_array().unwrap() {
        let Some(x) = floor["shape_total"].as_f64() else {
            continue;
        };
        for b in [2.0, 1.0] {
            let has = points.iter().any(|p| {
                name(&p["algorithm"]) == name(&floor["algorithm"]) && p["budget_lsb8"] == b
            });
            assert_eq!(
                has,
                x <= b * lsb8,
                "{} at {b}: floor {x}",
                name(&floor["algorithm"])
            );
        }
    }
    let mut cheapest: Option<(f64, &serde_json::Value)> = None;
    for p in points {
        let b = p["budget_lsb8"].as_f64().unwrap();
        let total = p["shape_total"].as_f64().unwrap();
        assert!(total <= b * lsb8, "{p}");
        let cfg = Config::from_toml(p["config_toml"].as_str().unwrap()).unwrap();
        let r = specfx::analysis::check::check(&Datapath::new(cfg).unwrap()).unwrap();
        assert_eq!(r.shape_total_max_abs, total, "{}", name(&p["algorithm"]));
        let cost = p["objective"].as_f64().unwrap();
        if b == 1.0 && cheapest.is_none_or(|(c, _)| cost < c) {
            cheapest = Some((cost, p));
        }
        // A looser budget never costs more.
        if b == 2.0 {
            if let Some(tighter) = points
                .iter()
                .find(|q| q["algorithm"] == p["algorithm"] && q["budget_lsb8"] == 1.0)
            {
                assert!(cost <= tighter["objective"].as_f64().unwrap(), "{p}");
            }
        }
    }
    // The cheapest point within 1 lsb8, evaluated by the oracle on every code of both n.
    let (cost, p) = cheapest.expect("a point within 1 lsb8");
    let cfg = Config::from_toml(p["config_toml"].as_str().unwrap()).unwrap();
    let dp = Datapath::new(cfg.clone()).unwrap();
    let k = cfg.k as usize;
    let lsb_c = cfg.c.format.lsb();
    let lsb_s = cfg.square[k - 1].format.lsb();
    let mut worst: f64 = 0.0;
    for n in [64u32, 256] {
        let nc = dp.constants_for(n).unwrap();
        for c in 0..=dp.one_code() {
            let lobe = crate::common::oracle::oracle_eval(&cfg, nc, c).values[2 + k] as f64 * lsb_s;
            let cos = (c as f64 * lsb_c).powi(n as i32);
            worst = worst.max((lobe - cos).abs());
        }
    }
    assert!(worst <= lsb8, "{worst}");
    assert!(
        (worst - p["shape_total"].as_f64().unwrap()).abs() < 1e-12,
        "{worst} vs {p}"
    );
    // `specfx optimize` for that algorithm and budget answers the same cost (or a dearer one
    // when the point is a tighter budget's answer).
    let a = &p["algorithm"];
    let out = dir.join("opt.toml");
    let o = crate::common::specfx(&[
        "optimize",
        "--n",
        "64,256",
        "--budget",
        "shape_total <= 1 lsb8",
        "--k",
        &a["k"].to_string(),
        "--variants",
        &a["variant"].as_str().unwrap().to_lowercase(),
        "--depth",
        if a["per_n"].as_bool().unwrap() {
            "best"
        } else {
            "fixed"
        },
        "--arch",
        "pipelined",
        "--device",
        "none",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let stdout = String::from_utf8_lossy(&o.stdout);
    let answered: f64 = stdout
        .split("pipelined, ")
        .nth(1)
        .and_then(|rest| rest.split(": ").nth(1))
        .and_then(|rest| rest.split(' ').next())
        .and_then(|v| v.parse().ok())
        .unwrap_or_else(|| panic!("no cost in {stdout}"));
    if p["found_at_lsb8"] == p["budget_lsb8"] {
        assert_eq!(answered, cost.round(), "{stdout}");
    } else {
        assert!(answered >= cost.round(), "{stdout}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
