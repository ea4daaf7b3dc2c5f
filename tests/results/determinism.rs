//! The same command gives the same bytes: each main command is run twice, with one and with two
//! threads, and every file it writes is compared (measured speed lives in `measured_*` files,
//! the only ones allowed to differ). The whole `report` (which also covers `fit`, `tradeoff`
//! and `cost`) is compared the same way in `tests/results/report.rs`, where its runs are shared.

use crate::common;
use crate::common::snapshot;

use std::path::PathBuf;
use std::process::Command;

/// Runs `specfx <args> <out-flag> <dir>` with `threads` threads in a fresh directory and
/// returns what it wrote (and its stdout as a file named `stdout`).
fn run(tag: &str, threads: &str, args: &[&str], out_flag: Option<&str>) -> Vec<(PathBuf, Vec<u8>)> {
    let base =
        std::env::temp_dir().join(format!("specfx-det-{}-{tag}-{threads}", std::process::id()));
    let _ = std::fs::remove_dir_all(&base);
    std::fs::create_dir_all(&base).unwrap();
    let out = base.join("out");
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_specfx"));
    cmd.args(args);
    if let Some(flag) = out_flag {
        cmd.arg(flag).arg(&out);
    }
    let o = cmd
        .env("RAYON_NUM_THREADS", threads)
        .current_dir(&base)
        .output()
        .unwrap();
    assert!(
        o.status.success(),
        "{tag}: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    let mut files = if out.is_dir() {
        snapshot(&out)
    } else if out.exists() {
        vec![(PathBuf::from("out"), std::fs::read(&out).unwrap())]
    } else {
        Vec::new()
    };
    // Paths printed on stdout name the run's own directory: compare the rest.
    let stdout = String::from_utf8_lossy(&o.stdout).replace(base.to_str().unwrap(), "<dir>");
    files.push((PathBuf::from("<stdout>"), stdout.into_bytes()));
    std::fs::remove_dir_all(&base).unwrap();
    files
}

fn same_bytes(tag: &str, args: &[&str], out_flag: Option<&str>) {
    let a = run(&format!("{tag}-a"), "1", args, out_flag);
    let b = run(&format!("{tag}-b"), "2", args, out_flag);
    let names = |v: &[(PathBuf, Vec<u8>)]| v.iter().map(|f| f.0.clone()).collect::<Vec<_>>();
    assert_eq!(names(&a), names(&b), "{tag}: different file sets");
    assert!(
        a.len() >= if out_flag.is_some() { 2 } else { 1 },
        "{tag}: nothing written"
    );
    for (x, y) in a.iter().zip(&b) {
        assert!(x.1 == y.1, "{tag}: {} differs between runs", x.0.display());
    }
}

#[test]
fn vectors_are_the_same_bytes() {
    same_bytes(
        "vectors",
        &["vectors", "--cases", "corner,random:3000"],
        Some("--out"),
    );
}

#[test]
fn check_json_is_the_same_bytes() {
    same_bytes("check", &["check", "--n", "16..=128", "--json"], None);
}

#[test]
fn budget_is_the_same_bytes() {
    same_bytes("budget", &["budget", "--n", "16..=64"], Some("--out"));
}

#[test]
fn stability_is_the_same_bytes() {
    same_bytes(
        "stability",
        &["stability", "--n", "1..=256", "--c-bits", "10"],
        Some("--out"),
    );
}

#[test]
fn sweep_is_the_same_bytes() {
    same_bytes("sweep", &["sweep"], Some("--out"));
}

#[test]
fn render_is_the_same_bytes() {
    same_bytes("render", &["render"], Some("--out"));
}

#[test]
fn furnace_is_the_same_bytes() {
    same_bytes("furnace", &["furnace", "--n", "16,256"], Some("--out"));
}

#[test]
fn optimize_is_the_same_bytes() {
    same_bytes(
        "optimize",
        &[
            "optimize",
            "--k",
            "5",
            "--variants",
            "minimax",
            // Three exponents: the search's order and its parallel checks are the same on
            // any n set.
            "--n",
            "16..=18",
        ],
        Some("--out"),
    );
}

#[test]
fn the_cycle_models_trace_is_the_same_bytes() {
    same_bytes(
        "sim",
        &[
            "sim",
            "--arch",
            "folded",
            "--cycles",
            "2000",
            "--vcd-cycles",
            "300",
        ],
        Some("--vcd"),
    );
}

#[test]
fn the_verilog_rom_and_parameters_are_the_same_bytes() {
    same_bytes(
        "rom",
        &[
            "hdl",
            "rom",
            "--config",
            &common::config_path("minimax_folded.toml"),
        ],
        Some("--out"),
    );
    same_bytes(
        "params",
        &[
            "hdl", "params", "--config", "baseline", "--format", "define",
        ],
        Some("--out"),
    );
}

#[test]
fn the_papers_claims_are_the_same_bytes() {
    same_bytes("paper", &["paper", "--json"], None);
}
