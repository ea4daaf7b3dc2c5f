//! Co-simulation of the reference Verilog against the golden vectors and the Rust cycle model,
//! in Icarus Verilog and Verilator (both must be installed: `./scripts/test` installs them).

use crate::common::{config_path, specfx};

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn temp_dir(name: &str) -> PathBuf {
    let p = std::env::temp_dir().join(format!("specfx-cosim-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&p);
    p
}

fn cosim(vectors: &Path, sim: &str, arch: &str, seed: &str) -> Output {
    Command::new(Path::new(env!("CARGO_MANIFEST_DIR")).join("scripts/cosim"))
        .args([
            "--vectors",
            vectors.to_str().unwrap(),
            "--sim",
            sim,
            "--arch",
            arch,
        ])
        .args(["--seed", seed, "--bubble", "0.25", "--stall", "0.25"])
        .env("SPECFX", env!("CARGO_BIN_EXE_specfx"))
        .output()
        .expect("scripts/cosim runs")
}

/// The `N passed, N failed` line of a run.
fn summary(o: &Output) -> (u64, u64) {
    let text = String::from_utf8_lossy(&o.stdout);
    let line = text
        .lines()
        .rev()
        .find(|l| l.contains(" passed, ") && l.trim_end().ends_with(" failed"))
        .unwrap_or_else(|| {
            panic!(
                "no summary line in:\n{text}\n{}",
                String::from_utf8_lossy(&o.stderr)
            )
        });
    let nums: Vec<u64> = line
        .split(|c: char| !c.is_ascii_digit())
        .filter(|s| !s.is_empty())
        .map(|s| s.parse().unwrap())
        .collect();
    (nums[0], nums[1])
}

fn vectors(config: &str, name: &str, cases: &str) -> (PathBuf, u64) {
    let dir = temp_dir(name);
    let o = specfx(&[
        "vectors",
        "--config",
        config,
        "--cases",
        cases,
        "--seed",
        "3",
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let manifest: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("manifest.json")).unwrap()).unwrap();
    (dir, manifest["n_vectors"].as_u64().unwrap())
}

fn check_all(config: &str, name: &str, arch: &str, cases: &str) {
    let (dir, n) = vectors(config, name, cases);
    for sim in ["icarus", "verilator"] {
        let o = cosim(&dir, sim, arch, "11");
        let (passed, failed) = summary(&o);
        assert_eq!(
            (passed, failed),
            (n, 0),
            "{name} on {sim} ({arch}):\n{}\n{}",
            String::from_utf8_lossy(&o.stdout),
            String::from_utf8_lossy(&o.stderr)
        );
        assert!(o.status.success());
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn baseline_pipelined_matches_bit_and_cycle() {
    check_all("baseline", "baseline", "pipelined", "corner,random:400");
}

#[test]
fn narrow_trn_wrap_matches_bit_and_cycle() {
    check_all(
        &config_path("narrow_trn_wrap.toml"),
        "narrow",
        "pipelined",
        "corner,random:300",
    );
}

#[test]
fn conv_sym_k5_matches_bit_and_cycle() {
    check_all(
        &config_path("conv_sym_k5.toml"),
        "k5",
        "pipelined",
        "corner,random:300",
    );
}

/// Every n a power of two: the pipelined RTL's t product is a shifter (`SLOPE_POW2`), checked
/// on every exponent (corner cases hold each n) and in both simulators; folded keeps its
/// shared multiplier.
#[test]
fn power_of_two_slopes_shift_and_match_bit_and_cycle() {
    let config = config_path("pow2_shift.toml");
    let header = specfx(&["hdl", "params", "--config", &config]);
    assert!(String::from_utf8_lossy(&header.stdout).contains("`define SPECFX_SLOPE_POW2 1\n"));
    check_all(&config, "pow2", "pipelined", "corner,random:400");
    check_all(&config, "pow2_folded", "folded", "corner,random:100");
}

#[test]
fn folded_matches_bit_and_cycle() {
    check_all("baseline", "baseline_folded", "folded", "random:300");
    check_all(
        &config_path("minimax_folded.toml"),
        "minimax_folded",
        "folded",
        "corner,random:200",
    );
}

/// A per-n squaring depth: the bypass multiplexers and the depth riding the pipeline, bit and
/// cycle exact in both simulators and both architectures (minimax with `depth = "best"`,
/// stages 5 and 6 bypassed for small n; a plain step list on signed stages, stages 2 to 4
/// bypassed for n < 9), and lint-clean in both.
#[test]
fn per_n_depth_matches_bit_and_cycle_in_both_architectures() {
    let best = config_path("depth_best_k6.toml");
    let steps = config_path("depth_steps_signed.toml");
    for config in [&best, &steps] {
        let header = specfx(&["hdl", "params", "--config", config, "--format", "json"]);
        let params: serde_json::Value = serde_json::from_slice(&header.stdout).unwrap();
        assert!(
            params["DEPTH_MIN"].as_i64() < params["K"].as_i64(),
            "{config}"
        );
    }
    check_all(&best, "depth_best", "pipelined", "corner,random:400");
    check_all(&steps, "depth_steps_folded", "folded", "corner,random:200");
    // The other two pairings, and the lint, in Icarus only.
    for (config, arch) in [(&best, "folded"), (&steps, "pipelined")] {
        let (dir, n) = vectors(config, &format!("depth_{arch}"), "corner,random:200");
        let o = specfx(&[
            "cosim",
            "--vectors",
            dir.to_str().unwrap(),
            "--sim",
            "icarus",
            "--arch",
            arch,
            "--lint",
        ]);
        assert_eq!(
            summary(&o),
            (n, 0),
            "{config} {arch}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }
}

/// A corrupted expected value never reaches the simulator: the vector directory is verified
/// against its manifest first (the testbench's own sensitivity to a wrong output is
/// tests/hardware/mutation.rs's business).
#[test]
fn a_corrupted_expected_value_is_refused_before_simulation() {
    let (dir, _) = vectors("baseline", "corrupt", "random:50");
    let path = dir.join("expected_out.hex");
    let text = std::fs::read_to_string(&path).unwrap();
    let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
    let v = u64::from_str_radix(&lines[17], 16).unwrap() ^ 1;
    lines[17] = format!("{v:06x}");
    std::fs::write(&path, lines.join("\n") + "\n").unwrap();
    let o = cosim(&dir, "icarus", "pipelined", "5");
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains("expected_out.hex: sha256")
            && stderr.contains("differs from the manifest's"),
        "{stderr}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// `specfx cosim` with no argument co-simulates the baseline on vectors it writes itself.
#[test]
fn cosim_defaults_lead_to_an_answer() {
    let o = specfx(&["cosim"]);
    let (passed, failed) = summary(&o);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    // The default cases: every n of the baseline's 16..1024 has corner cases, plus 1000 random.
    assert!(passed > 1009 + 1000 && failed == 0, "{passed} passed");
}

/// RESET_DATA = 1 (data registers cleared on reset) matches in both simulators and both
/// architectures, with the top linted under its parameters first; the testbench then also
/// checks out_data = 0 right after reset.
#[test]
fn reset_data_variant_matches_and_is_lint_clean() {
    let (dir, n) = vectors(
        &config_path("minimax_folded.toml"),
        "reset",
        "corner,random:100",
    );
    for (sim, arch) in [("icarus", "pipelined"), ("verilator", "folded")] {
        let o = specfx(&[
            "cosim",
            "--vectors",
            dir.to_str().unwrap(),
            "--sim",
            sim,
            "--arch",
            arch,
            "--reset-data",
            "--lint",
        ]);
        assert_eq!(summary(&o), (n, 0), "{sim} {arch}");
        assert!(o.status.success());
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A simulator that is not installed is named with the package that has it: one line, exit 2.
#[test]
fn a_missing_simulator_is_named_with_its_package() {
    let o = Command::new(env!("CARGO_BIN_EXE_specfx"))
        .args(["cosim", "--sim", "icarus"])
        .env("PATH", "/nonexistent")
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(
        err.contains("iverilog and vvp not found on PATH")
            && err.contains("apt-get install -y iverilog"),
        "{err}"
    );
    let o = Command::new(env!("CARGO_BIN_EXE_specfx"))
        .arg("cosim")
        .env("PATH", "/nonexistent")
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("no Verilog simulator"));
}

/// `--keep` keeps the work directory, whose path the run prints, and a later run does not
/// take it for a dead run's leftover: it is still there, with the simulator's files.
#[test]
fn a_kept_work_directory_outlives_later_runs() {
    let tmp = tempfile::tempdir().unwrap();
    let run = |keep: bool| {
        let mut cmd = Command::new(env!("CARGO_BIN_EXE_specfx"));
        cmd.args(["cosim", "--sim", "icarus", "--n", "16", "--cases", "corner"])
            .env("TMPDIR", tmp.path());
        if keep {
            cmd.arg("--keep");
        }
        let o = cmd.output().unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        String::from_utf8(o.stderr).unwrap()
    };
    let err = run(true);
    let kept = err
        .lines()
        .find_map(|l| {
            l.split_once("cosim: work directory ")
                .map(|(_, p)| p.trim())
        })
        .unwrap_or_else(|| panic!("no kept directory in {err}"));
    let kept = PathBuf::from(kept);
    assert!(kept.join("tb.vvp").is_file(), "{}", kept.display());
    run(false);
    assert!(
        kept.join("tb.vvp").is_file(),
        "a later run removed {}",
        kept.display()
    );
}

/// `specfx cosim` reads the testbench's exit status as well as its count: a testbench that
/// counts every vector passed but ends with `$fatal` (a check the count does not show) fails
/// the run, and the reason names the status.
#[test]
fn a_testbench_that_fails_its_exit_status_fails_the_run() {
    let hdl = temp_dir("fatal-tb");
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("hdl_ref");
    for sub in ["rtl", "tb"] {
        std::fs::create_dir_all(hdl.join(sub)).unwrap();
        for e in std::fs::read_dir(root.join(sub)).unwrap() {
            let p = e.unwrap().path();
            std::fs::copy(&p, hdl.join(sub).join(p.file_name().unwrap())).unwrap();
        }
    }
    let tb = hdl.join("tb/tb_specfx.v");
    let text = std::fs::read_to_string(&tb).unwrap();
    let from = "            $finish;\n        end\n    endtask";
    assert_eq!(
        text.matches(from).count(),
        1,
        "the testbench's ending moved"
    );
    let to =
        "            $fatal(1, \"a check the count does not show\");\n        end\n    endtask";
    std::fs::write(&tb, text.replace(from, to)).unwrap();
    let o = specfx(&[
        "cosim",
        "--sim",
        "icarus",
        "--n",
        "16,17",
        "--cases",
        "corner",
        "--hdl-ref",
        hdl.to_str().unwrap(),
    ]);
    let (passed, failed) = summary(&o);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(passed > 0 && failed == 0, "{err}");
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(
        err.contains(&format!(
            "the testbench counted {passed} passed, 0 failed but ended with exit status: 1"
        )),
        "{err}"
    );
    std::fs::remove_dir_all(&hdl).unwrap();
}
