//! The Python package (`python/`, `import specfx`) against the command line: its tests
//! (`python/tests/test_specfx.py`, unittest) run in the virtual environment `./scripts/test`
//! makes, where it installs the wheel it builds with maturin.

use std::path::{Path, PathBuf};
use std::process::Command;

/// The Python with the specfx wheel: `$SPECFX_COCOTB_PYTHON`, else `target/cocotb-venv`.
fn python() -> PathBuf {
    let python = crate::common::venv_python();
    let o = Command::new(&python).args(["-c", "import specfx"]).output();
    assert!(
        o.as_ref().is_ok_and(|o| o.status.success()),
        "{}: no Python with the specfx package; ./scripts/test builds and installs it (or: \
         target/cocotb-venv/bin/maturin develop -m python/Cargo.toml)",
        python.display()
    );
    python
}

#[test]
fn the_python_package_evaluates_what_the_cli_writes() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let o = Command::new(python())
        .arg(root.join("python/tests/test_specfx.py"))
        .env("SPECFX", env!("CARGO_BIN_EXE_specfx"))
        .env("SPECFX_CONFIGS", root.join("tests/configs"))
        .output()
        .expect("python runs");
    assert!(
        o.status.success(),
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    );
}
