//! The C ABI (capi/, `libspecfx_c.a` and `capi/include/specfx.h`) from a C program compiled
//! with gcc: every vector `specfx vectors` writes, exhaustively where the input format allows,
//! gives the same output, probes and constants through `specfx_eval`, `specfx_eval_probes`,
//! `specfx_constants_of` and `specfx_eval_batch`, also from four threads at once
//! (`tests/c/check_vectors.c`). The configurations reach the edges: one-bit stages, a 64-bit
//! signed output, a signed input, inputs of 63 bits, and every rounding and overflow mode.

use crate::common::{self, config_path, specfx};

use std::path::{Path, PathBuf};
use std::process::Command;

/// `tests/c/check_vectors.c` compiled against the static library, once per test binary.
fn checker() -> &'static Path {
    static BIN: std::sync::OnceLock<PathBuf> = std::sync::OnceLock::new();
    BIN.get_or_init(|| {
        let root = Path::new(env!("CARGO_MANIFEST_DIR"));
        let lib = common::capi_dir();
        let dir = tempfile::Builder::new()
            .prefix("specfx-capi-")
            .tempdir()
            .expect("a temporary directory")
            .keep();
        let bin = dir.join("check_vectors");
        let out = Command::new("gcc")
            .args([
                "-O1",
                "-Wall",
                "-Werror",
                "-std=c11",
                "-D_POSIX_C_SOURCE=200809L",
            ])
            .arg("-I")
            .arg(root.join("capi/include"))
            .arg(root.join("tests/c/check_vectors.c"))
            .arg(lib.join("libspecfx_c.a"))
            .args(common::CAPI_LINK_FLAGS)
            .arg("-o")
            .arg(&bin)
            .output()
            .expect("gcc runs");
        assert!(
            out.status.success(),
            "gcc: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        bin
    })
}

fn check(config: &str, extra: &[&str]) {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let vectors = dir.path().join("v");
    let mut args = vec![
        "vectors",
        "--config",
        config,
        "--out",
        vectors.to_str().unwrap(),
    ];
    args.extend_from_slice(extra);
    let o = specfx(&args);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let written = String::from_utf8_lossy(&o.stdout);
    let rows: u64 = written
        .split_whitespace()
        .nth(1)
        .and_then(|w| w.parse().ok())
        .expect("wrote N vectors");
    let o = Command::new(checker())
        .arg(&vectors)
        .output()
        .expect("the checker runs");
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(
        o.status.success(),
        "{config}: {stdout}{}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert_eq!(
        stdout.trim(),
        format!("{rows} passed, 0 failed"),
        "{config}"
    );
}

#[test]
fn the_c_abi_gives_the_clis_vectors_bit_for_bit() {
    let every_mode = config_path("every_mode.toml");
    let signed_in = tempfile::NamedTempFile::new().expect("a temporary file");
    std::fs::write(
        signed_in.path(),
        "name = \"signed_in\"\nn = \"16..=24\"\n[c]\nformat = \"s2.14\"\n[d]\nformat = \"s3.14\"\n",
    )
    .expect("write the configuration");
    let exhaustive = &["--cases", "exhaustive"];
    check(
        "baseline",
        &["--cases", "exhaustive", "--n", "16,17,1023,1024"],
    );
    check(&every_mode, exhaustive);
    check(signed_in.path().to_str().unwrap(), exhaustive);
    check(&config_path("lint_narrowest.toml"), exhaustive);
    check(
        &config_path("conv_sym_k5.toml"),
        &["--cases", "exhaustive", "--n", "32..=34,1000"],
    );
    check(
        &config_path("wide_signed_out64.toml"),
        &["--cases", "corner,random:20000"],
    );
    check(
        &config_path("lint_widest.toml"),
        &["--cases", "corner,random:20000"],
    );
    // A per-n depth: SPECFX_DEPTH and specfx_constants.depth against the in_depth column.
    check(
        &config_path("depth_steps_signed.toml"),
        &["--cases", "corner,random:20000"],
    );
}
