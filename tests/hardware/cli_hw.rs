//! End-to-end tests of `specfx sim`, `specfx hdl` and `specfx cost` through the built binary.

use crate::common::specfx;

use std::process::Output;

fn json(o: &Output) -> serde_json::Value {
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    serde_json::from_slice(&o.stdout).expect("JSON on stdout")
}

#[test]
fn sim_json_reports_latency_throughput_and_no_mismatch() {
    for (arch, latency) in [("pipelined", 8), ("folded", 7)] {
        let v = json(&specfx(&[
            "sim", "--arch", arch, "--cycles", "3000", "--seed", "9", "--json",
        ]));
        assert_eq!(v["mismatches"], 0, "{arch}");
        assert_eq!(v["latency_min"], latency, "{arch}");
        assert!(v["latency_max"].as_u64().unwrap() >= latency);
        assert!(v["n_outputs"].as_u64().unwrap() > 0);
        assert!(v["throughput"].as_f64().unwrap() > 0.0);
    }
    // Without bubbles or stalls a pipeline delivers one result per cycle after it fills:
    // 1000 cycles - 8 of latency = 992 results.
    let v = json(&specfx(&[
        "sim", "--cycles", "1000", "--bubble", "0", "--stall", "0", "--json",
    ]));
    assert_eq!(v["n_outputs"], 992);
    assert_eq!(v["latency_max"], 8);
    // The sweep stream: n = 16 and 20, every code 0..=32768 of each (65,538 inputs) and on
    // into the second pass; every output checked against the functional model.
    let v = json(&specfx(&[
        "sim", "--n", "16,20", "--stream", "sweep", "--cycles", "70000", "--bubble", "0",
        "--stall", "0", "--json",
    ]));
    assert_eq!(v["n_inputs"], 70000);
    assert_eq!(v["n_outputs"], 70000 - 8);
    assert_eq!(v["mismatches"], 0);
    assert_eq!(v["order_errors"], 0);
}

#[test]
fn sim_writes_a_vcd() {
    let path = std::env::temp_dir().join(format!("specfx-{}-trace.vcd", std::process::id()));
    let o = specfx(&[
        "sim",
        "--cycles",
        "200",
        "--vcd",
        path.to_str().unwrap(),
        "--vcd-cycles",
        "100",
    ]);
    assert!(o.status.success());
    let text = std::fs::read_to_string(&path).unwrap();
    assert!(text.contains("$enddefinitions"));
    assert!(text.contains(" out_valid $end"));
    assert!(text.contains("$scope module u_core $end"));
    // Reset for four edges (the first at 5 ns), then 100 cycles of 10 ns: cycle 99 ends at
    // the edge at 1035 ns.
    assert!(
        text.contains("#1035\n1!"),
        "100 cycles of 10 ns after reset"
    );
    std::fs::remove_file(&path).unwrap();
}

#[test]
fn bad_sim_arguments_are_refused() {
    for args in [
        &["sim", "--arch", "systolic"][..],
        &["sim", "--bubble", "1.5"],
        &["sim", "--cycles", "0"],
        &["sim", "--stream", "sorted"],
        &["cost", "--target", "asic"],
    ] {
        let o = specfx(args);
        assert_eq!(o.status.code(), Some(2), "{args:?}");
        assert!(o.stdout.is_empty());
    }
}

#[test]
fn hdl_params_describe_the_configuration() {
    let o = specfx(&["hdl", "params", "--arch", "folded"]);
    assert!(o.status.success());
    let text = String::from_utf8(o.stdout).unwrap();
    for line in [
        "`define SPECFX_ARCH 1",
        "`define SPECFX_K 4",
        "`define SPECFX_T_W 18",
        "`define SPECFX_T_F 16",
        "`define SPECFX_T_S 1",
        "`define SPECFX_T_RND 2",
        "`define SPECFX_T_OVF 1",
        "`define SPECFX_OUT_W 24",
        "`define SPECFX_SLOPE_W 11",
        "`define SPECFX_SLOPE_F 4",
    ] {
        assert!(text.lines().any(|l| l == line), "missing {line}");
    }
}

#[test]
fn cost_runs_yosys_and_the_analytic_model() {
    let v = json(&specfx(&["cost", "--target", "ice40", "--json"]));
    for key in ["luts", "dsps", "ffs"] {
        assert!(v[key].as_u64().unwrap() > 0, "{key}");
    }
    assert!(v["yosys_version"].as_str().unwrap().starts_with("Yosys"));
    assert!(v["yosys_script"].as_str().unwrap().contains("synth_ice40"));
    // Six multipliers: d x n, four squares, the output product.
    assert_eq!(
        v["analytic"]["features"]["multipliers"]
            .as_array()
            .unwrap()
            .len(),
        6
    );
    // The pipeline keeps at least every stage's value in registers: 8 stages, >= 8 * 16 bits.
    assert!(v["ffs"].as_u64().unwrap() >= 128);
    let v = json(&specfx(&[
        "cost",
        "--analytic-only",
        "--arch",
        "folded",
        "--json",
    ]));
    assert!(v["yosys"].is_null());
    assert_eq!(
        v["analytic"]["features"]["multipliers"]
            .as_array()
            .unwrap()
            .len(),
        1
    );
    // Figures named with target and unit, and checked against the device.
    assert_eq!(v["analytic"]["target"], "ice40");
    assert_eq!(v["analytic"]["logic_unit"], "LUTs");
    assert_eq!(v["device"], "up5k");
    assert_eq!(v["over_limit"].as_array().unwrap().len(), 0);
    // The fast generic mapping: gates and a transistor estimate, through abc -fast.
    let v = json(&specfx(&["cost", "--target", "generic-fast", "--json"]));
    assert!(v["yosys_script"]
        .as_str()
        .unwrap()
        .contains("abc -fast -g cmos2"));
    assert!(v["yosys"]["transistors"].as_u64().unwrap() > 1000);
}

/// Seven squarings of 24 x 24 bits need four SB_MAC16 each on iCE40 (16 x 16 blocks: two
/// slices per operand): far more than the UP5K's eight DSP blocks, which `cost` flags.
#[test]
fn cost_flags_what_exceeds_the_device() {
    let dir = std::env::temp_dir().join(format!("specfx-hw-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let cfg = dir.join("wide.toml");
    std::fs::write(
        &cfg,
        "k = 7\n[b]\nformat = \"u1.23\"\n[square]\nformat = \"u1.23\"\n",
    )
    .unwrap();
    let v = json(&specfx(&[
        "cost",
        "--config",
        cfg.to_str().unwrap(),
        "--analytic-only",
        "--json",
    ]));
    let dsps = v["analytic"]["dsps"].as_u64().unwrap();
    assert!(dsps >= 7 * 4, "{dsps}");
    let flags = v["over_limit"].as_array().unwrap();
    assert!(
        flags.iter().any(|f| f.as_str().unwrap().contains("DSP")),
        "{flags:?}"
    );
}

/// The synthesis cache keeps what yosys and nextpnr answered for exactly these inputs. Shown
/// from outside: once its entries are edited, a repeated `cost --timing` reports the edited
/// figures (they came from the cache, not from the tools), while another configuration and
/// `SPECFX_CACHE=off` give the tools' own figures again.
#[test]
fn a_repeated_synthesis_comes_from_the_cache_and_only_for_the_same_inputs() {
    let root = tempfile::tempdir().unwrap();
    let cache = root.path().join("cache");
    // A small datapath (8-bit stages, four exponents): the cache does not depend on size,
    // and each synthesis and place and route of it takes seconds.
    let small = "n = \"16..=19\"\n[c]\nformat = \"u1.7\"\n[d]\nformat = \"s1.7\"\n[t]\nformat = \"s1.7\"\n[b]\nformat = \"u1.7\"\n[square]\nformat = \"u1.7\"\n[coef]\nformat = \"u4.4\"\n";
    let (tiny, narrow) = (
        root.path().join("tiny.toml"),
        root.path().join("narrow.toml"),
    );
    std::fs::write(&tiny, format!("{small}[out]\nformat = \"u1.7\"\n")).unwrap();
    std::fs::write(&narrow, format!("{small}[out]\nformat = \"u1.6\"\n")).unwrap();
    let tiny = tiny.to_str().unwrap();
    let cost = |config: &str, cache: &str| {
        let o = std::process::Command::new(env!("CARGO_BIN_EXE_specfx"))
            .args(["cost", "--timing", "--json", "--config", config])
            .env("SPECFX_CACHE", cache)
            .output()
            .unwrap();
        json(&o)
    };
    let figures = |v: &serde_json::Value| {
        (
            v["luts"].as_u64().unwrap(),
            v["rom_yosys"]["luts"].as_u64().unwrap(),
            v["timing"]["synthesis"]["luts"].as_u64().unwrap(),
        )
    };
    let first = figures(&cost(tiny, cache.to_str().unwrap()));
    // One entry per synthesis: the datapath and its ROM (yosys), the place and route.
    let entries = |tool: &str| -> Vec<std::path::PathBuf> {
        let mut v: Vec<_> = std::fs::read_dir(cache.join(tool))
            .unwrap()
            .map(|e| e.unwrap().path())
            .collect();
        v.sort();
        v
    };
    assert_eq!(entries("yosys").len(), 2, "{:?}", entries("yosys"));
    assert_eq!(entries("nextpnr").len(), 1, "{:?}", entries("nextpnr"));
    // Every cached LUT count becomes 7777: what a run takes from the cache shows.
    for e in entries("yosys").into_iter().chain(entries("nextpnr")) {
        let stat = e.join("stat.json");
        let v: serde_json::Value = serde_json::from_slice(&std::fs::read(&stat).unwrap()).unwrap();
        let mut v = v;
        v["design"]["num_cells_by_type"]["SB_LUT4"] = 7777.into();
        std::fs::write(&stat, serde_json::to_vec(&v).unwrap()).unwrap();
    }
    assert_eq!(
        figures(&cost(tiny, cache.to_str().unwrap())),
        (7777, 7777, 7777)
    );
    // Without the cache: the tools' own figures, the same as the first run's.
    assert_eq!(figures(&cost(tiny, "off")), first);
    // Another configuration is other inputs: synthesised, and its figures are not 7777.
    let other = figures(&cost(narrow.to_str().unwrap(), cache.to_str().unwrap()));
    assert!(other.0 != 7777 && other.2 != 7777, "{other:?}");
    assert!(entries("yosys").len() >= 3, "{:?}", entries("yosys"));
    assert_eq!(entries("nextpnr").len(), 2);
}

/// `cost` runs yosys twice (the datapath, its constant ROM), for seconds to minutes: off a
/// terminal it says what it starts and how far it is, as every long command does (a line
/// per step, a line per tenth); `--quiet` and `--analytic-only` print nothing on stderr.
#[test]
fn cost_reports_its_progress_off_a_terminal() {
    let dir = std::env::temp_dir().join(format!("specfx-hw-progress-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let cfg = dir.join("small.toml");
    std::fs::write(&cfg, "k = 1\nn = \"16..=20\"\n").unwrap();
    let run = |extra: &[&str]| {
        let o = std::process::Command::new(env!("CARGO_BIN_EXE_specfx"))
            .args(["cost", "--config", cfg.to_str().unwrap()])
            .args(extra)
            .env("SPECFX_CACHE", dir.join("cache"))
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        String::from_utf8(o.stderr).unwrap()
    };
    let stderr = run(&[]);
    let lines: Vec<&str> = stderr.lines().collect();
    assert_eq!(lines.len(), 4, "{stderr}");
    assert_eq!(
        lines[0],
        "specfx cost: synthesising small (pipelined) with yosys on ice40"
    );
    assert!(lines[1].starts_with("cost: 50% (1/2 steps)"), "{stderr}");
    assert_eq!(
        lines[2],
        "specfx cost: synthesising the constant ROM of small with yosys on ice40"
    );
    assert!(
        lines[3].starts_with("cost: 100% (2/2 steps), took "),
        "{stderr}"
    );
    assert_eq!(run(&["--quiet"]), "");
    assert_eq!(run(&["--analytic-only"]), "");
    let _ = std::fs::remove_dir_all(&dir);
}

/// `optimize` with yosys in the loop (here a yosys ceiling, measured on each algorithm's
/// answer) says when it starts synthesising and, for a long search, every tenth synthesis;
/// before, a yosys objective ran ten minutes without a line off a terminal.
#[test]
fn optimize_says_when_it_synthesises() {
    let dir = std::env::temp_dir().join(format!("specfx-hw-optprog-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let run = |extra: &[&str]| {
        let o = std::process::Command::new(env!("CARGO_BIN_EXE_specfx"))
            .args([
                "optimize",
                "--n",
                "64",
                "--k",
                "2",
                "--variants",
                "plain",
                "--budget",
                "shape_total <= 64 lsb8, yosys_luts <= 100000 on ice40",
                "--force",
                "--out",
            ])
            .arg(dir.join("answer.toml"))
            .args(extra)
            .env("SPECFX_CACHE", dir.join("cache"))
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        String::from_utf8(o.stderr).unwrap()
    };
    let stderr = run(&[]);
    assert!(
        stderr.lines().any(|l| l
            == "optimize: synthesising with yosys on ice40 (seconds to minutes each, cached ones at once; a line every 10)"),
        "{stderr}"
    );
    assert_eq!(run(&["--quiet"]), "");
    let _ = std::fs::remove_dir_all(&dir);
}

/// `timing` (yosys and nextpnr) places and routes the architecture the configuration records,
/// and `--arch` overrides it, as every command that reads a configuration does.
#[test]
fn timing_takes_the_configurations_arch() {
    let dir = std::env::temp_dir().join(format!("specfx-hw-timing-arch-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let cfg = dir.join("folded.toml");
    std::fs::write(&cfg, "arch = \"folded\"\nk = 3\nn = \"16..=64\"\n").unwrap();
    let arch = |extra: &[&str]| {
        let o = std::process::Command::new(env!("CARGO_BIN_EXE_specfx"))
            .args(["timing", "--json", "--config", cfg.to_str().unwrap()])
            .args(extra)
            .env("SPECFX_CACHE", dir.join("cache"))
            .output()
            .unwrap();
        json(&o)["arch"].clone()
    };
    assert_eq!(arch(&[]), "folded");
    assert_eq!(arch(&["--arch", "pipelined"]), "pipelined");
    let _ = std::fs::remove_dir_all(&dir);
}
