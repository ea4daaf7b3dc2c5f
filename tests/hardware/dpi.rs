//! The DPI-C face in a real simulator: `hdl_ref/dpi/specfx_dpi.sv` declares exactly the C
//! functions of `capi/include/specfx.h` (checked against `verilator --dpi-hdr-only`'s header),
//! and `specfx cosim --dpi` (Verilator, the constrained-random scoreboard calling the model)
//! passes on generated configurations at the edges and on every input of the baseline. The
//! mutants it must catch are in `tests/hardware/mutation.rs`.

use crate::common::{self, config_path, specfx};

use std::path::Path;
use std::process::{Command, Output};

fn summary(o: &Output) -> (u64, u64) {
    let text = String::from_utf8_lossy(&o.stdout);
    text.lines()
        .rev()
        .find_map(|l| {
            let (p, f) = l.split_once(" passed, ")?;
            Some((p.parse().ok()?, f.strip_suffix(" failed")?.parse().ok()?))
        })
        .unwrap_or_else(|| {
            panic!(
                "no summary line:\n{text}\n{}",
                String::from_utf8_lossy(&o.stderr)
            )
        })
}

fn coverage(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout)
        .lines()
        .find(|l| l.starts_with("coverage: "))
        .unwrap_or_else(|| panic!("no coverage line: {}", String::from_utf8_lossy(&o.stdout)))
        .to_string()
}

#[test]
fn the_dpi_package_declares_the_c_librarys_functions() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let dir = tempfile::tempdir().expect("a temporary directory");
    let o = Command::new("verilator")
        .args(["--dpi-hdr-only", "--top-module", "specfx_dpi", "-Mdir"])
        .arg(dir.path())
        .arg(root.join("hdl_ref/dpi/specfx_dpi.sv"))
        .output()
        .expect("verilator runs");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let header = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().path())
        .find(|p| p.to_string_lossy().ends_with("__Dpi.h"))
        .expect("verilator wrote the DPI header");
    let text = std::fs::read_to_string(&header).unwrap();
    // Every import is there (a declaration Verilator writes, and ours must agree with).
    let declared = text
        .lines()
        .filter(|l| l.trim_start().starts_with("extern ") && l.contains("specfx_dpi_"))
        .count();
    assert_eq!(declared, 15, "{text}");
    // One translation unit with both declarations of each function: the compiler refuses any
    // difference in a type (int vs long long, void* vs a typed pointer).
    let tu = dir.path().join("both.cpp");
    std::fs::write(
        &tu,
        format!("#include \"specfx.h\"\n#include \"{}\"\n", header.display()),
    )
    .unwrap();
    let o = Command::new("g++")
        .args(["-fsyntax-only", "-Wall", "-Werror"])
        .arg("-I")
        .arg(root.join("capi/include"))
        .args([
            "-I/usr/share/verilator/include",
            "-I/usr/share/verilator/include/vltstd",
        ])
        .arg(&tu)
        .output()
        .expect("g++ runs");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

/// `specfx cosim --dpi` with these arguments: passes, with every vector checked (`vectors`,
/// or `None` for the random ones plus the directed ones).
fn passes(args: &[&str], vectors: Option<u64>) -> Output {
    let mut all = vec![
        "cosim", "--dpi", "--seed", "5", "--bubble", "0.3", "--stall", "0.3",
    ];
    all.extend_from_slice(args);
    let o = specfx(&all);
    let (passed, failed) = summary(&o);
    let cov = coverage(&o);
    let directed: u64 = cov
        .split(" directed)")
        .next()
        .and_then(|h| h.rsplit('(').next())
        .and_then(|d| d.parse().ok())
        .unwrap_or_else(|| panic!("{cov}"));
    assert_eq!(
        (passed, failed),
        (vectors.unwrap_or(5000 + directed), 0),
        "{args:?}: {}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(o.status.success());
    o
}

#[test]
fn the_dpi_scoreboard_passes_on_generated_configurations() {
    let _lib = common::capi_dir();
    let signed_in = tempfile::NamedTempFile::new().expect("a temporary file");
    std::fs::write(
        signed_in.path(),
        "name = \"signed_in\"\nn = \"16..=40\"\n[c]\nformat = \"s2.14\"\n[d]\nformat = \"s3.14\"\n",
    )
    .unwrap();
    let every_mode = config_path("every_mode.toml");
    let conv = config_path("conv_sym_k5.toml");
    let wide = config_path("wide_signed_out64.toml");
    let narrowest = config_path("lint_narrowest.toml");
    let sat = config_path("sat_out.toml");
    let minimax = config_path("minimax_folded.toml");
    let depth = config_path("depth_best_k6.toml");
    let runs: Vec<Vec<&str>> = vec![
        vec!["--config", "baseline", "--arch", "folded"],
        vec!["--config", "baseline", "--reset-data"],
        vec!["--config", &every_mode],
        vec!["--config", &conv],
        vec!["--config", &wide, "--arch", "folded"],
        vec!["--config", &narrowest],
        vec![
            "--config",
            signed_in.path().to_str().unwrap(),
            "--arch",
            "folded",
        ],
        vec!["--config", &sat],
        vec!["--config", &minimax, "--arch", "folded"],
        // A per-n depth: in_depth from specfx_dpi_constant's SPECFX_DEPTH.
        vec!["--config", &depth],
    ];
    let next = std::sync::atomic::AtomicUsize::new(0);
    std::thread::scope(|s| {
        for _ in 0..2 {
            s.spawn(|| loop {
                let i = next.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                let Some(run) = runs.get(i) else { break };
                let mut args = run.clone();
                args.extend(["--cases", "random:5000"]);
                let o = passes(&args, None);
                // Bubbles and stalls happened, and the inputs covered c above 1.0.
                let cov = coverage(&o);
                assert!(!cov.contains(" 0 stall cycles"), "{cov}");
                assert!(!cov.contains(" 0 bubbles"), "{cov}");
            });
        }
    });
}

/// Every input code up to 1.0 of every n of the baseline through the RTL, each output checked
/// through DPI as it comes: 1009 exponents x 32769 codes (the codes above 1.0 clamp to it).
#[test]
fn the_dpi_scoreboard_checks_every_input_of_the_baseline() {
    let _lib = common::capi_dir();
    let o = passes(&["--cases", "exhaustive"], Some(1009 * 32769));
    assert!(
        coverage(&o)
            .starts_with("coverage: 33063921 vectors checked (0 directed), 1009 of 1009 n, "),
        "{}",
        coverage(&o)
    );
}

#[test]
fn icarus_has_no_dpi_and_says_so() {
    let o = specfx(&["cosim", "--dpi", "--sim", "icarus"]);
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("Icarus Verilog has no DPI-C support") && err.lines().count() == 1,
        "{err}"
    );
    let o = specfx(&["cosim", "--dpi", "--dpi-lib", "/nonexistent/libspecfx_c.a"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        String::from_utf8_lossy(&o.stderr)
            .contains("--dpi-lib /nonexistent/libspecfx_c.a: no such file"),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
}

/// A `--dpi-lib` (or `$SPECFX_DPI_LIB`) that is not a library is refused before Verilator
/// builds anything, in one line naming it, exit code 2 (it used to fail after the build, with
/// a linker error that did not name it).
#[test]
fn a_text_file_as_the_dpi_library_is_refused_up_front() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let text = dir.path().join("notes.txt");
    std::fs::write(&text, "not a library\n").unwrap();
    let text = text.to_str().unwrap();
    let o = specfx(&["cosim", "--dpi", "--dpi-lib", text]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    assert!(
        err.contains(&format!(
            "--dpi-lib {text}: not a library, expected libspecfx_c.a"
        )),
        "{err}"
    );
    let o = Command::new(env!("CARGO_BIN_EXE_specfx"))
        .args(["cosim", "--dpi"])
        .env("SPECFX_DPI_LIB", text)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        err.contains(&format!("SPECFX_DPI_LIB={text}: not a library")),
        "{err}"
    );
    // Nothing was built: the run stopped before its work directory was made.
    assert!(!err.contains("verilator failed"), "{err}");
}
