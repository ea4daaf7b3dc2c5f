//! The cocotb testbench (`hdl_ref/cocotb/run.py`, `test_specfx.py`) under Icarus Verilog: every
//! vector of several configurations passes, bit for bit and cycle for cycle, and a broken RTL
//! fails. Needs cocotb in `target/cocotb-venv` (`./scripts/test` makes it and sets
//! `SPECFX_COCOTB_PYTHON`) and Icarus Verilog.

use crate::common::{config_path, specfx, venv_python as cocotb_python};

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

fn temp_dir(name: &str) -> PathBuf {
    let p = std::env::temp_dir().join(format!("specfx-cocotb-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&p);
    p
}

/// Writes vectors into a fresh directory; returns it and the manifest's `n_vectors`.
fn vectors(name: &str, args: &[&str]) -> (PathBuf, u64) {
    let dir = temp_dir(name);
    let mut all = vec!["vectors", "--seed", "3", "--out", dir.to_str().unwrap()];
    all.extend_from_slice(args);
    let o = specfx(&all);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let manifest: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("manifest.json")).unwrap()).unwrap();
    (dir, manifest["n_vectors"].as_u64().unwrap())
}

/// Runs `hdl_ref/cocotb/run.py --vectors DIR` with more arguments.
fn run_py(vectors: &Path, args: &[&str]) -> Output {
    Command::new(cocotb_python())
        .arg(root().join("hdl_ref/cocotb/run.py"))
        .arg("--vectors")
        .arg(vectors)
        .arg("--specfx")
        .arg(env!("CARGO_BIN_EXE_specfx"))
        .args(args)
        .output()
        .expect("the cocotb Python runs")
}

fn text(o: &Output) -> String {
    format!(
        "{}\n{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    )
}

/// The N of run.py's `cocotb: N vectors passed (...)` line.
fn vectors_passed(o: &Output) -> Option<u64> {
    String::from_utf8_lossy(&o.stdout).lines().find_map(|l| {
        l.strip_prefix("cocotb: ")?
            .split_once(" vectors passed (")?
            .0
            .parse()
            .ok()
    })
}

/// Every vector of a configuration passes under the given architecture and stimulus.
fn check(name: &str, vector_args: &[&str], run_args: &[&str]) {
    let (dir, n) = vectors(name, vector_args);
    assert!(
        (100..=1000).contains(&n),
        "{name}: {n} vectors, want a few hundred"
    );
    let o = run_py(&dir, run_args);
    assert!(o.status.success(), "{name}: run.py failed:\n{}", text(&o));
    assert_eq!(vectors_passed(&o), Some(n), "{name}:\n{}", text(&o));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn baseline_pipelined_passes_every_vector() {
    check(
        "baseline",
        &["--n", "16,64,1000", "--cases", "corner,random:200"],
        &["--arch", "pipelined", "--seed", "11", "--bubble", "0.25"],
    );
}

#[test]
fn baseline_folded_passes_every_vector() {
    check(
        "baseline_folded",
        &["--n", "16,64,1000", "--cases", "corner,random:150"],
        &["--arch", "folded", "--seed", "12", "--stall", "0.4"],
    );
}

#[test]
fn minimax_folded_passes_every_vector() {
    check(
        "minimax_folded",
        &[
            "--config",
            &config_path("minimax_folded.toml"),
            "--cases",
            "corner,random:150",
        ],
        &[
            "--arch", "folded", "--seed", "13", "--bubble", "0.3", "--stall", "0.4",
        ],
    );
}

/// A per-n depth (stages 2 to 4 bypassed for n < 9): the vector test drives `in_depth.hex`.
#[test]
fn per_n_depth_passes_every_vector() {
    check(
        "depth_steps",
        &[
            "--config",
            &config_path("depth_steps_signed.toml"),
            "--cases",
            "corner,random:150",
        ],
        &["--seed", "5", "--bubble", "0.3", "--stall", "0.3"],
    );
}

/// Latencies of 2, the paper cutoff and a signed output.
#[test]
fn conv_sym_k5_pipelined_passes_every_vector() {
    check(
        "conv_sym_k5",
        &[
            "--config",
            &config_path("conv_sym_k5.toml"),
            "--cases",
            "corner,random:200",
        ],
        &[
            "--arch",
            "pipelined",
            "--seed",
            "14",
            "--bubble",
            "0.3",
            "--stall",
            "0.3",
        ],
    );
}

/// RESET_DATA = 1 (out_data checked to be 0 after reset), with 60-bit coefficients and 64-bit
/// signed output words, some negative, in both architectures.
#[test]
fn reset_data_and_64_bit_signed_words_pass_every_vector() {
    let config = config_path("wide_signed_out64.toml");
    let (dir, n) = vectors(
        "wide",
        &["--config", &config, "--cases", "corner,random:200"],
    );
    let manifest = std::fs::read_to_string(dir.join("manifest.json")).unwrap();
    assert!(manifest.contains("\"format\": \"s40.24\""), "{manifest}");
    let negative = std::fs::read_to_string(dir.join("expected_out.hex"))
        .unwrap()
        .lines()
        .filter(|l| l.len() == 16 && l.as_bytes()[0] >= b'8')
        .count();
    assert!(negative > 10, "only {negative} negative outputs");
    for (arch, seed) in [("pipelined", "15"), ("folded", "16")] {
        let o = run_py(
            &dir,
            &[
                "--arch",
                arch,
                "--seed",
                seed,
                "--stall",
                "0.3",
                "--reset-data",
            ],
        );
        assert!(o.status.success(), "{arch}: run.py failed:\n{}", text(&o));
        assert_eq!(vectors_passed(&o), Some(n), "{arch}:\n{}", text(&o));
        assert!(String::from_utf8_lossy(&o.stdout).contains("RESET_DATA = 1"));
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A copy of `hdl_ref/rtl` with one line of `specfx_pipelined.v` replaced.
fn broken_rtl(name: &str, from: &str, to: &str) -> PathBuf {
    let dir = temp_dir(name);
    std::fs::create_dir_all(dir.join("rtl")).unwrap();
    for entry in std::fs::read_dir(root().join("hdl_ref/rtl")).unwrap() {
        let path = entry.unwrap().path();
        let mut text = std::fs::read_to_string(&path).unwrap();
        if path.ends_with("specfx_pipelined.v") {
            assert_eq!(text.matches(from).count(), 1, "{from:?} is not one line");
            text = text.replace(from, to);
        }
        std::fs::write(dir.join("rtl").join(path.file_name().unwrap()), text).unwrap();
    }
    dir
}

fn check_broken(name: &str, from: &str, to: &str, problem: &str) {
    let (vec_dir, n) = vectors(name, &["--n", "16,64,1000", "--cases", "corner,random:100"]);
    let rtl = broken_rtl(&format!("{name}-rtl"), from, to);
    let args = ["--hdl-ref", rtl.to_str().unwrap(), "--seed", "17"];
    let o = run_py(&vec_dir, &args);
    let out = String::from_utf8_lossy(&o.stdout);
    assert_eq!(o.status.code(), Some(1), "{name} must fail:\n{}", text(&o));
    assert_eq!(vectors_passed(&o), None);
    assert!(
        out.lines().any(|l| l.starts_with(problem)),
        "{name}: no {problem:?} line:\n{out}"
    );
    let verdict = out.lines().last().unwrap();
    assert!(
        verdict.starts_with("cocotb: FAIL: ") && verdict.contains(&format!(" of {n} vectors")),
        "{verdict}"
    );
    std::fs::remove_dir_all(&vec_dir).unwrap();
    std::fs::remove_dir_all(&rtl).unwrap();
}

/// The output product reads the coefficient one stage back (the neighbouring vector's).
#[test]
fn a_neighbouring_coefficient_fails() {
    check_broken(
        "neighbour_coef",
        ".coef(coefs[K*COEF_W +: COEF_W])",
        ".coef(coefs[(K-1)*COEF_W +: COEF_W])",
        "mismatch i=",
    );
}

/// The output register moves while the output is stalled (rule 5 of docs/cycle.md).
#[test]
fn an_output_that_moves_while_stalled_fails() {
    check_broken(
        "moves_while_stalled",
        ".en(advance), .d(out_k), .q(out_data)",
        ".en(1'b1), .d(out_k), .q(out_data)",
        "protocol: out_valid/out_data changed while stalled",
    );
}

/// Runs `hdl_ref/cocotb/run.py --live CONFIG` (the live scoreboard, `import specfx`) under
/// Icarus Verilog.
fn run_live(config: &str, args: &[&str]) -> Output {
    Command::new(cocotb_python())
        .arg(root().join("hdl_ref/cocotb/run.py"))
        .args(["--live", config, "--specfx", env!("CARGO_BIN_EXE_specfx")])
        .args(args)
        .output()
        .expect("the cocotb Python runs")
}

/// The Python with cocotb 1.8.1, which runs Verilator 5.006 (cocotb 2.x needs 5.036):
/// `$SPECFX_COCOTB_VERILATOR_PYTHON`, else the virtual environment `./scripts/test` makes.
fn cocotb_verilator_python() -> PathBuf {
    let python = std::env::var_os("SPECFX_COCOTB_VERILATOR_PYTHON")
        .map(PathBuf::from)
        .unwrap_or_else(|| root().join("target/cocotb18-venv/bin/python"));
    assert!(
        python.is_file(),
        "{}: no Python with cocotb 1.8.1; ./scripts/test makes it (or: python3 -m venv \
         target/cocotb18-venv && target/cocotb18-venv/bin/pip install -r \
         hdl_ref/cocotb/requirements-verilator.txt and the specfx wheel)",
        python.display()
    );
    python
}

/// `hdl_ref/cocotb/run.py --sim verilator ARGS` with cocotb 1.8.1.
fn run_verilator(args: &[&str]) -> Output {
    Command::new(cocotb_verilator_python())
        .arg(root().join("hdl_ref/cocotb/run.py"))
        .args([
            "--sim",
            "verilator",
            "--specfx",
            env!("CARGO_BIN_EXE_specfx"),
        ])
        .args(args)
        .output()
        .expect("the cocotb Python runs")
}

/// The live scoreboard (random stimulus with backpressure, each expected value from the
/// Python package as the input is accepted, each cycle from the cycle model) passes on
/// configurations of both architectures, the directed cases and the random ones all checked.
#[test]
fn the_live_scoreboard_passes() {
    let every_mode = config_path("every_mode.toml");
    let conv = config_path("conv_sym_k5.toml");
    let depth = config_path("depth_best_k6.toml");
    for (config, args) in [
        (
            "baseline",
            vec!["--n", "16..=20,1000..=1024", "--arch", "folded"],
        ),
        (
            every_mode.as_str(),
            vec!["--n", "8..=12,40", "--stall", "0.4"],
        ),
        (conv.as_str(), vec!["--n", "32,33,1000", "--bubble", "0.4"]),
        // A per-n depth: in_depth from the Python package's constants(n)["depth"].
        (depth.as_str(), vec!["--n", "16,17,31,64,1024"]),
    ] {
        let o = run_live(
            config,
            &[&args[..], &["--nvec", "400", "--seed", "3"]].concat(),
        );
        assert!(o.status.success(), "{config}: run.py failed:\n{}", text(&o));
        let n = vectors_passed(&o).unwrap_or(0);
        assert!(
            n > 400,
            "{config}: {n} vectors, want the directed ones and 400:\n{}",
            text(&o)
        );
    }
}

/// A copy of `hdl_ref/rtl` whose b adder reads the offset one stage early.
fn offset_one_stage_early(name: &str) -> PathBuf {
    let dir = temp_dir(name);
    std::fs::create_dir_all(dir.join("rtl")).unwrap();
    for e in std::fs::read_dir(root().join("hdl_ref/rtl")).unwrap() {
        let p = e.unwrap().path();
        std::fs::copy(&p, dir.join("rtl").join(p.file_name().unwrap())).unwrap();
    }
    let file = dir.join("rtl/specfx_pipelined.v");
    let text_v = std::fs::read_to_string(&file).unwrap();
    let from = ".t(t_2), .offset(offset_2)";
    assert_eq!(text_v.matches(from).count(), 1);
    std::fs::write(&file, text_v.replace(from, ".t(t_2), .offset(offset_1)")).unwrap();
    dir
}

/// The `stage:` line of a failed live run: the first register that differs from the model.
fn stage_line(o: &Output) -> String {
    assert_eq!(o.status.code(), Some(1), "{}", text(o));
    String::from_utf8_lossy(&o.stdout)
        .lines()
        .find(|l| l.starts_with("stage: "))
        .map(str::to_string)
        .unwrap_or_else(|| panic!("no stage line:\n{}", text(o)))
}

/// A failing seed points at a stage: the b adder reading the offset one stage early fails,
/// and the first register that differs from the model is the b stage's.
#[test]
fn the_live_scoreboard_names_the_stage_that_went_wrong() {
    let dir = offset_one_stage_early("stage");
    let minimax = config_path("minimax_folded.toml");
    let o = run_live(
        &minimax,
        &["--nvec", "100", "--hdl-ref", dir.to_str().unwrap()],
    );
    let stage = stage_line(&o);
    assert!(
        stage.contains("the first register that differs from the model is b"),
        "{stage}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Under Verilator (cocotb 1.8.1): the live scoreboard passes in the folded architecture with
/// bubbles and stalls, the vector replay passes pipelined, and the same broken b adder is
/// named by its register.
#[test]
fn the_cocotb_testbenches_pass_and_fail_under_verilator() {
    let o = run_verilator(&[
        "--live",
        "baseline",
        "--n",
        "16..=20,1000..=1024",
        "--arch",
        "folded",
        "--nvec",
        "400",
        "--seed",
        "5",
        "--bubble",
        "0.3",
        "--stall",
        "0.3",
    ]);
    assert!(
        o.status.success(),
        "live, folded: run.py failed:\n{}",
        text(&o)
    );
    assert!(vectors_passed(&o).unwrap_or(0) > 400, "{}", text(&o));
    assert!(
        String::from_utf8_lossy(&o.stdout).contains("(verilator, folded, live scoreboard)"),
        "{}",
        text(&o)
    );

    let (dir, n) = vectors(
        "verilator",
        &[
            "--config",
            &config_path("conv_sym_k5.toml"),
            "--cases",
            "corner,random:200",
        ],
    );
    let o = run_verilator(&[
        "--vectors",
        dir.to_str().unwrap(),
        "--seed",
        "6",
        "--stall",
        "0.3",
    ]);
    assert!(o.status.success(), "vectors: run.py failed:\n{}", text(&o));
    assert_eq!(vectors_passed(&o), Some(n), "{}", text(&o));
    std::fs::remove_dir_all(&dir).unwrap();

    let broken = offset_one_stage_early("stage-verilator");
    let o = run_verilator(&[
        "--live",
        &config_path("minimax_folded.toml"),
        "--nvec",
        "100",
        "--hdl-ref",
        broken.to_str().unwrap(),
    ]);
    let stage = stage_line(&o);
    assert!(
        stage.contains("the first register that differs from the model is b"),
        "{stage}"
    );
    std::fs::remove_dir_all(&broken).unwrap();
}

/// A copy of `hdl_ref/rtl` (and the vector testbench) with one exact piece of `file` (under
/// `rtl/`) replaced.
fn rtl_with(name: &str, file: &str, from: &str, to: &str) -> PathBuf {
    let dir = temp_dir(name);
    std::fs::create_dir_all(dir.join("tb")).unwrap();
    std::fs::copy(
        root().join("hdl_ref/tb/tb_specfx.v"),
        dir.join("tb/tb_specfx.v"),
    )
    .unwrap();
    std::fs::create_dir_all(dir.join("rtl")).unwrap();
    for entry in std::fs::read_dir(root().join("hdl_ref/rtl")).unwrap() {
        let path = entry.unwrap().path();
        let mut text = std::fs::read_to_string(&path).unwrap();
        if path.ends_with(file) {
            assert_eq!(
                text.matches(from).count(),
                1,
                "{from:?} is not in {file} once"
            );
            text = text.replace(from, to);
        }
        std::fs::write(dir.join("rtl").join(path.file_name().unwrap()), text).unwrap();
    }
    dir
}

/// A folded core whose `out_valid` has no reset starts with `out_valid` X in Icarus Verilog:
/// the live scoreboard fails it (it used to read the X as 0 and pass every vector), and so
/// does the vector testbench (`specfx cosim`).
#[test]
fn an_x_on_out_valid_fails_the_live_scoreboard_and_the_vector_testbench() {
    let dir = rtl_with(
        "no-reset",
        "specfx_folded.v",
        "            count     <= {CNT_W{1'b0}};\n            out_valid <= 1'b0;\n",
        "            count     <= {CNT_W{1'b0}};\n",
    );
    let hdl = dir.to_str().unwrap();
    let o = run_live(
        "baseline",
        &[
            "--n",
            "16,17",
            "--arch",
            "folded",
            "--nvec",
            "100",
            "--hdl-ref",
            hdl,
        ],
    );
    assert_eq!(o.status.code(), Some(1), "{}", text(&o));
    assert!(
        String::from_utf8_lossy(&o.stdout)
            .lines()
            .any(|l| l.starts_with("protocol: cycle ")
                && l.contains(" out_valid=")
                && l.ends_with("an X or Z")),
        "{}",
        text(&o)
    );
    let (vec_dir, _) = vectors("no-reset-vectors", &["--n", "16,17", "--cases", "corner"]);
    let o = run_py(&vec_dir, &["--arch", "folded", "--hdl-ref", hdl]);
    assert_eq!(o.status.code(), Some(1), "{}", text(&o));
    assert!(
        String::from_utf8_lossy(&o.stdout)
            .lines()
            .any(|l| l.starts_with("protocol: cycle ") && l.ends_with("an X or Z")),
        "{}",
        text(&o)
    );
    std::fs::remove_dir_all(&vec_dir).unwrap();
    let o = specfx(&[
        "cosim",
        "--sim",
        "icarus",
        "--arch",
        "folded",
        "--n",
        "16,17",
        "--cases",
        "corner",
        "--hdl-ref",
        hdl,
    ]);
    assert_eq!(o.status.code(), Some(1), "{}", text(&o));
    assert!(
        String::from_utf8_lossy(&o.stdout)
            .lines()
            .any(|l| l.starts_with("protocol: cycle ") && l.ends_with("an X or Z")),
        "{}",
        text(&o)
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A register that differs from the model where no port shows it fails the live scoreboard:
/// a pipelined core whose first register keeps the input unclamped (`c_cl_1` above 1.0; only
/// the paper cutoff reads it) passes every vector at the ports (`specfx cosim` passes it) and
/// the live scoreboard's register comparison fails it, naming the register.
#[test]
fn a_register_only_difference_fails_the_live_scoreboard() {
    let dir = rtl_with(
        "register-only",
        "specfx_pipelined.v",
        ".d({in_depth, in_coef, in_threshold, in_offset, in_slope, c_cl_0, d_0}),",
        ".d({in_depth, in_coef, in_threshold, in_offset, in_slope, in_c, d_0}),",
    );
    let hdl = dir.to_str().unwrap();
    let o = specfx(&[
        "cosim",
        "--sim",
        "icarus",
        "--n",
        "16,17",
        "--cases",
        "corner",
        "--hdl-ref",
        hdl,
    ]);
    assert!(o.status.success(), "the ports show it now: {}", text(&o));
    let o = run_live(
        "baseline",
        &["--n", "16,17", "--nvec", "100", "--hdl-ref", hdl],
    );
    let stage = stage_line(&o);
    assert!(
        stage.contains("the first register that differs from the model is c_cl_1"),
        "{stage}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}
