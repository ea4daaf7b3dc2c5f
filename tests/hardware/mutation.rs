//! Mutation tests of the co-simulation: deliberately broken copies of the reference Verilog
//! that `specfx cosim` must catch (Icarus Verilog; `./scripts/test` installs it).
//!
//! Each mutant replaces one exact piece of an RTL file (the test fails if the piece is no
//! longer found exactly once, so the set follows the RTL as it changes), and is run on a
//! configuration whose vectors exercise the broken part: the per-n constants' routing (which a
//! stream sorted by n exercised only at n boundaries), timing, handshake, rounding, overflow
//! and clamping, a rounding constant one LSB off in one stage (caught by the vectors on
//! and next to every stage's rounding boundary), and the per-n depth's routing and bypass. The unmutated RTL passes on every
//! configuration used.

use crate::common;

use std::path::{Path, PathBuf};
use std::process::Output;

/// One broken RTL variant.
struct Mutant {
    name: &'static str,
    file: &'static str,
    from: &'static str,
    to: &'static str,
    config: &'static str,
    arch: &'static str,
    /// Extra `specfx cosim` flags.
    flags: &'static [&'static str],
}

const MUTANTS: &[Mutant] = &[
    Mutant {
        name: "output multiplier takes the previous stage's coefficient",
        file: "rtl/specfx_pipelined.v",
        from: ".coef(coefs[K*COEF_W +: COEF_W])",
        to: ".coef(coefs[(K-1)*COEF_W +: COEF_W])",
        config: "baseline",
        arch: "pipelined",
        flags: &[],
    },
    Mutant {
        name: "t multiplier reads the slope port instead of its register",
        file: "rtl/specfx_pipelined.v",
        from: ".d(d_1), .slope(slope_1), .t(t_1)",
        to: ".d(d_1), .slope(in_slope), .t(t_1)",
        config: "baseline",
        arch: "pipelined",
        flags: &[],
    },
    Mutant {
        name: "b adder reads the offset one stage early",
        file: "rtl/specfx_pipelined.v",
        from: ".t(t_2), .offset(offset_2)",
        to: ".t(t_2), .offset(offset_1)",
        config: "tests/configs/minimax_folded.toml",
        arch: "pipelined",
        flags: &[],
    },
    Mutant {
        name: "paper cutoff compares with the threshold one stage early",
        file: "rtl/specfx_pipelined.v",
        from: ".threshold(threshold_2)",
        to: ".threshold(threshold_1)",
        config: "tests/configs/conv_sym_k5.toml",
        arch: "pipelined",
        flags: &[],
    },
    Mutant {
        name: "valid bit one register short",
        file: "rtl/specfx_pipelined.v",
        from: "specfx_delay #(.W(1), .LAT(L), .RESET(1)) u_valid",
        to: "specfx_delay #(.W(1), .LAT(L - 1), .RESET(1)) u_valid",
        config: "baseline",
        arch: "pipelined",
        flags: &[],
    },
    Mutant {
        name: "pipeline ignores backpressure",
        file: "rtl/specfx_pipelined.v",
        from: "wire advance = !out_valid || out_ready;",
        to: "wire advance = 1'b1;",
        config: "baseline",
        arch: "pipelined",
        flags: &[],
    },
    Mutant {
        name: "RND ties round down",
        file: "rtl/specfx_quant.v",
        from: "wire tie_up = (RND == 2) ? 1'b1 :",
        to: "wire tie_up = (RND == 2) ? 1'b0 :",
        config: "baseline",
        arch: "pipelined",
        flags: &[],
    },
    // One LSB too much rounding constant in the output stage only: it rounds up the exact
    // values one LSB below the tie, 8 of the baseline's 33 million inputs (none of which the
    // corner cases or 1000 random draws held before the rounding-boundary cases).
    Mutant {
        name: "output stage adds its rounding constant one LSB too large",
        file: "rtl/specfx_mul_out.v",
        from: ".x(product), .y(out)",
        to: ".x(product + 1'b1), .y(out)",
        config: "baseline",
        arch: "pipelined",
        flags: &[],
    },
    Mutant {
        name: "SAT wraps above the maximum",
        file: "rtl/specfx_quant.v",
        from: "assign y = below_min ? min_out : above_max ? max_out : kept;",
        to: "assign y = below_min ? min_out : kept;",
        config: "tests/configs/sat_out.toml",
        arch: "pipelined",
        flags: &[],
    },
    Mutant {
        name: "inputs above 1.0 are not clamped",
        file: "rtl/specfx_sub.v",
        from: "wire [XW-1:0] c_cl_x = above_one ? one : c_x;",
        to: "wire [XW-1:0] c_cl_x = c_x;",
        config: "baseline",
        arch: "pipelined",
        flags: &[],
    },
    Mutant {
        name: "folded core reads in_coef instead of its register",
        file: "rtl/specfx_folded.v",
        from: "(.x(coef_r), .y(coef_y))",
        to: "(.x(in_coef), .y(coef_y))",
        config: "baseline",
        arch: "folded",
        flags: &[],
    },
    Mutant {
        name: "folded core reads in_slope instead of its register",
        file: "rtl/specfx_folded.v",
        from: "(.x(slope_r), .y(slope_y))",
        to: "(.x(in_slope), .y(slope_y))",
        config: "baseline",
        arch: "folded",
        flags: &[],
    },
    Mutant {
        name: "folded core accepts an input while its result is stalled",
        file: "rtl/specfx_folded.v",
        from: "assign in_ready = (!busy || last) && out_free;",
        to: "assign in_ready = (!busy || last);",
        config: "baseline",
        arch: "folded",
        flags: &[],
    },
    Mutant {
        name: "folded output stays valid after its transfer",
        file: "rtl/specfx_folded.v",
        from: "end else if (out_valid && out_ready) begin",
        to: "end else if (1'b0) begin",
        config: "baseline",
        arch: "folded",
        flags: &[],
    },
    // Caught only by a stall at least an initiation interval long from an output's first
    // cycle: the stall bursts and the directed episodes of the handshake pattern.
    Mutant {
        name: "folded FSM steps on while its result waits for a stalled output",
        file: "rtl/specfx_folded.v",
        from: "if (busy && !last) begin",
        to: "if (busy) begin",
        config: "baseline",
        arch: "folded",
        flags: &[],
    },
    Mutant {
        name: "folded multiplier takes the coefficient one step early",
        file: "rtl/specfx_folded.v",
        from: "at_step[K+1] ? coef_y : x_y;",
        to: "at_step[K] ? coef_y : x_y;",
        config: "tests/configs/minimax_folded.toml",
        arch: "folded",
        flags: &[],
    },
    Mutant {
        name: "pipelined add_b stage takes the depth of the next input, not its own",
        file: "rtl/specfx_pipelined.v",
        from: ".d({depth_2, coef_2, b_2}),",
        to: ".d({in_depth, coef_2, b_2}),",
        config: "tests/configs/depth_best_k6.toml",
        arch: "pipelined",
        flags: &[],
    },
    Mutant {
        name: "a bypassed stage squares anyway (the multiplexer stuck on the product)",
        file: "rtl/specfx_sq_quant.v",
        from: "wire [A_W-1:0] aligned = pass ? (x_e << X_SH) : (p_e << P_SH);",
        to: "wire [A_W-1:0] aligned = 1'b0 ? (x_e << X_SH) : (p_e << P_SH);",
        config: "tests/configs/depth_steps_signed.toml",
        arch: "folded",
        flags: &[],
    },
    Mutant {
        name: "the top does not pass RESET_DATA to the pipelined core",
        file: "rtl/specfx_top.v",
        from: ".LAT_ADD(LAT_ADD),\n                .RESET_DATA(RESET_DATA)",
        to: ".LAT_ADD(LAT_ADD),\n                .RESET_DATA(0)",
        config: "baseline",
        arch: "pipelined",
        flags: &["--reset-data"],
    },
];

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

fn config_arg(config: &str) -> String {
    if config.ends_with(".toml") {
        root().join(config).to_string_lossy().into_owned()
    } else {
        config.to_string()
    }
}

/// A copy of hdl_ref/ in a fresh temporary directory.
fn copy_hdl_ref(tag: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("specfx-mutant-{}-{tag}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    for sub in ["rtl", "tb", "dpi"] {
        std::fs::create_dir_all(dir.join(sub)).unwrap();
        for e in std::fs::read_dir(root().join("hdl_ref").join(sub)).unwrap() {
            let p = e.unwrap().path();
            std::fs::copy(&p, dir.join(sub).join(p.file_name().unwrap())).unwrap();
        }
    }
    dir
}

fn cosim(hdl_ref: &Path, config: &str, arch: &str, flags: &[&str]) -> Output {
    run_cosim(
        &["--sim", "icarus", "--cases", "corner,random:600"],
        hdl_ref,
        config,
        arch,
        flags,
    )
}

/// The DPI scoreboard (`specfx cosim --dpi`, Verilator) on random stimulus.
fn cosim_dpi(hdl_ref: &Path, config: &str, arch: &str, flags: &[&str]) -> Output {
    run_cosim(
        &["--dpi", "--cases", "random:3000"],
        hdl_ref,
        config,
        arch,
        flags,
    )
}

/// `specfx cosim` with `how` (simulator, cases) on a configuration, seeded stimulus with
/// bubbles and stalls, and a copy of the reference Verilog.
fn run_cosim(how: &[&str], hdl_ref: &Path, config: &str, arch: &str, flags: &[&str]) -> Output {
    let config = config_arg(config);
    let mut args = vec!["cosim"];
    args.extend_from_slice(how);
    args.extend([
        "--config", &config, "--arch", arch, "--seed", "7", "--bubble", "0.3", "--stall", "0.3",
    ]);
    args.extend([
        "--hdl-ref",
        hdl_ref.to_str().expect("a UTF-8 temporary path"),
    ]);
    args.extend_from_slice(flags);
    common::specfx(&args)
}

/// The cocotb live scoreboard (`hdl_ref/cocotb/run.py --live`, Icarus, `import specfx`) on
/// random stimulus; the exponents cut to a few where the set is large.
fn cocotb_live(hdl_ref: &Path, config: &str, arch: &str, flags: &[&str]) -> Output {
    let config = config_arg(config);
    let mut cmd = std::process::Command::new(common::venv_python());
    cmd.arg(root().join("hdl_ref/cocotb/run.py"))
        .args([
            "--live", &config, "--arch", arch, "--seed", "7", "--nvec", "600",
        ])
        .args([
            "--bubble",
            "0.3",
            "--stall",
            "0.3",
            "--specfx",
            env!("CARGO_BIN_EXE_specfx"),
        ])
        .arg("--hdl-ref")
        .arg(hdl_ref)
        .args(flags);
    if config == "baseline" || config.ends_with("sat_out.toml") {
        cmd.args(["--n", "16..=32,1016..=1024"]);
    }
    cmd.output().expect("the cocotb Python runs")
}

fn summary(o: &Output) -> Option<(u64, u64)> {
    let text = String::from_utf8_lossy(&o.stdout);
    text.lines().rev().find_map(|l| {
        let (p, f) = l.split_once(" passed, ")?;
        Some((p.parse().ok()?, f.strip_suffix(" failed")?.parse().ok()?))
    })
}

#[test]
fn the_unmutated_rtl_passes_on_every_mutation_configuration() {
    let dir = copy_hdl_ref("control");
    let mut seen = std::collections::BTreeSet::new();
    for m in MUTANTS {
        if !seen.insert((m.config, m.arch, m.flags)) {
            continue;
        }
        let o = cosim(&dir, m.config, m.arch, m.flags);
        let (passed, failed) = summary(&o).expect("a summary line");
        assert!(
            o.status.success() && failed == 0 && passed > 0,
            "{} {}: {}",
            m.config,
            m.arch,
            String::from_utf8_lossy(&o.stderr)
        );
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The mutants `run` does not catch (exit code 1 with failed vectors, or no summary at all:
/// a dead simulation), each with its verdict; two at a time.
fn escaped(tag: &str, run: fn(&Path, &str, &str, &[&str]) -> Output) -> Vec<String> {
    let next = std::sync::atomic::AtomicUsize::new(0);
    let escaped = std::sync::Mutex::new(Vec::new());
    std::thread::scope(|s| {
        for _ in 0..2 {
            s.spawn(|| loop {
                let i = next.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                let Some(m) = MUTANTS.get(i) else { break };
                let dir = copy_hdl_ref(&format!("{tag}{i}"));
                let path = dir.join(m.file);
                let text = std::fs::read_to_string(&path).unwrap();
                assert_eq!(
                    text.matches(m.from).count(),
                    1,
                    "mutant '{}': `{}` must occur exactly once in {}",
                    m.name,
                    m.from,
                    m.file
                );
                std::fs::write(&path, text.replace(m.from, m.to)).unwrap();
                let o = run(&dir, m.config, m.arch, m.flags);
                let verdict = summary(&o);
                eprintln!("{tag}: mutant '{}': {:?}", m.name, verdict);
                let caught =
                    o.status.code() == Some(1) && verdict.is_none_or(|(_, failed)| failed > 0);
                if !caught {
                    escaped.lock().unwrap().push(format!(
                        "{} (exit {:?}, {:?}): {}",
                        m.name,
                        o.status.code(),
                        verdict,
                        String::from_utf8_lossy(&o.stderr)
                    ));
                }
                std::fs::remove_dir_all(&dir).unwrap();
            });
        }
    });
    escaped.into_inner().unwrap()
}

#[test]
fn every_mutant_is_caught() {
    let escaped = escaped("m", cosim);
    assert!(
        escaped.is_empty(),
        "mutants not caught:\n{}",
        escaped.join("\n")
    );
}

/// The DPI scoreboard (random stimulus, expected values and cycles from the model through
/// DPI-C) catches every mutant too; the unmutated RTL passes it in
/// `tests/hardware/dpi.rs`.
#[test]
fn every_mutant_is_caught_by_the_dpi_scoreboard() {
    let escaped = escaped("dpi", cosim_dpi);
    assert!(
        escaped.is_empty(),
        "mutants the DPI scoreboard does not catch:\n{}",
        escaped.join("\n")
    );
}

/// The cocotb live scoreboard catches every mutant too.
#[test]
fn every_mutant_is_caught_by_the_cocotb_live_scoreboard() {
    let escaped = escaped("live", cocotb_live);
    assert!(
        escaped.is_empty(),
        "mutants the cocotb live scoreboard does not catch:\n{}",
        escaped.join("\n")
    );
}

/// Why the default order interleaves n: with vectors sorted by n, the t multiplier reading
/// the slope port instead of its register passes every vector (the last vector of each n has
/// c above 1.0, so d = 0 and the slope does not matter); interleaved, it fails thousands.
#[test]
fn sorted_vectors_miss_a_routing_bug_that_interleaved_ones_catch() {
    let m = MUTANTS
        .iter()
        .find(|m| m.name.starts_with("t multiplier reads the slope port"))
        .expect("the slope mutant");
    let dir = copy_hdl_ref("order");
    let path = dir.join(m.file);
    let text = std::fs::read_to_string(&path).unwrap();
    std::fs::write(&path, text.replace(m.from, m.to)).unwrap();
    let sorted = cosim(&dir, m.config, m.arch, &["--order", "sorted"]);
    let interleaved = cosim(&dir, m.config, m.arch, &["--order", "interleaved"]);
    let (_, failed_sorted) = summary(&sorted).expect("a summary");
    let (passed, failed) = summary(&interleaved).expect("a summary");
    assert_eq!(
        failed_sorted, 0,
        "sorted order now catches it: update the docs"
    );
    assert!(sorted.status.success());
    assert!(
        failed * 10 > passed + failed,
        "interleaved: {failed} of {} failed",
        passed + failed
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A copy of hdl_ref/ with the named mutant applied.
fn mutated(tag: &str, name: &str) -> PathBuf {
    let m = MUTANTS.iter().find(|m| m.name == name).expect("the mutant");
    let dir = copy_hdl_ref(tag);
    let path = dir.join(m.file);
    let text = std::fs::read_to_string(&path).unwrap();
    assert_eq!(text.matches(m.from).count(), 1, "{}", m.name);
    std::fs::write(&path, text.replace(m.from, m.to)).unwrap();
    dir
}

/// A folded FSM whose step counter runs on while its result waits for a stalled output
/// (issue 48) fails only when an output stalls for an initiation interval from its first
/// cycle while the next input is computed: independent stalls of probability 0.2 did that
/// about once in 15,000 vectors. The handshake pattern's directed episodes catch it on their
/// own (no random bubble or stall), in the vector testbench, the cocotb live scoreboard and
/// the DPI scoreboard's exhaustive run (which drives no random stall), and so does the
/// default `specfx cosim` (its stall bursts too); the DPI scoreboard's random runs in
/// `every_mutant_is_caught_by_the_dpi_scoreboard`.
#[test]
fn the_handshake_pattern_catches_a_folded_fsm_that_steps_while_stalled() {
    let dir = mutated(
        "fsm",
        "folded FSM steps on while its result waits for a stalled output",
    );
    let hdl = dir.to_str().unwrap();
    let base = [
        "cosim",
        "--sim",
        "icarus",
        "--arch",
        "folded",
        "--n",
        "16..=24",
        "--cases",
        "corner,random:300",
        "--hdl-ref",
        hdl,
    ];
    for extra in [&[][..], &["--bubble", "0", "--stall", "0"][..]] {
        let o = common::specfx(&[&base[..], extra].concat());
        let verdict = summary(&o);
        assert!(
            o.status.code() == Some(1) && verdict.is_some_and(|(_, failed)| failed > 0),
            "cosim {extra:?}: {verdict:?} {}",
            String::from_utf8_lossy(&o.stderr)
        );
    }
    let o = std::process::Command::new(common::venv_python())
        .arg(root().join("hdl_ref/cocotb/run.py"))
        .args(["--live", "baseline", "--n", "16..=24", "--arch", "folded"])
        .args(["--nvec", "300", "--bubble", "0", "--stall", "0"])
        .args(["--specfx", env!("CARGO_BIN_EXE_specfx"), "--hdl-ref", hdl])
        .output()
        .expect("the cocotb Python runs");
    assert_eq!(
        o.status.code(),
        Some(1),
        "cocotb live: {}",
        String::from_utf8_lossy(&o.stdout)
    );
    let _lib = common::capi_dir();
    let o = common::specfx(&[
        "cosim",
        "--dpi",
        "--arch",
        "folded",
        "--n",
        "16",
        "--cases",
        "exhaustive",
        "--hdl-ref",
        hdl,
    ]);
    let verdict = summary(&o);
    assert!(
        o.status.code() == Some(1) && verdict.is_some_and(|(_, failed)| failed > 0),
        "cosim --dpi --cases exhaustive: {verdict:?} {}",
        String::from_utf8_lossy(&o.stderr)
    );
    std::fs::remove_dir_all(&dir).unwrap();
}
