//! The reference Verilog directory a command gives its tools: `--hdl-ref`, else
//! `$SPECFX_HDL_REF`, else the source tree's `hdl_ref/`, checked before any work.

use std::path::{Path, PathBuf};

use anyhow::{bail, Result};

/// The reference Verilog directory: `arg` (`--hdl-ref`), else `$SPECFX_HDL_REF` (unless empty),
/// else the source tree's `hdl_ref/`.
pub fn hdl_ref_dir(arg: Option<&Path>) -> PathBuf {
    hdl_ref_source(arg).0
}

/// [`hdl_ref_dir`] and how it was chosen, as errors name it (`--hdl-ref DIR`,
/// `SPECFX_HDL_REF=DIR`, or the built-in directory).
fn hdl_ref_source(arg: Option<&Path>) -> (PathBuf, String) {
    let shown = |p: &Path| super::error_text(&p.display().to_string());
    if let Some(p) = arg {
        return (p.to_path_buf(), format!("--hdl-ref {}", shown(p)));
    }
    match std::env::var_os("SPECFX_HDL_REF").filter(|v| !v.is_empty()) {
        Some(v) => {
            let p = PathBuf::from(v);
            let name = format!("SPECFX_HDL_REF={}", shown(&p));
            (p, name)
        }
        None => {
            let p = Path::new(env!("CARGO_MANIFEST_DIR")).join("hdl_ref");
            let name = format!(
                "the reference Verilog {} (pass --hdl-ref or set SPECFX_HDL_REF)",
                shown(&p)
            );
            (p, name)
        }
    }
}

/// The reference Verilog directory of [`hdl_ref_dir`], checked before any work: a directory
/// holding `rtl/*.v` and `specfx_dut.v`, what yosys is given.
pub fn hdl_ref(arg: Option<&Path>) -> Result<PathBuf> {
    let (dir, name) = hdl_ref_source(arg);
    let expected = "expected the reference Verilog directory (rtl/*.v and specfx_dut.v)";
    match std::fs::metadata(&dir) {
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            bail!("{name}: {expected}, got no such directory")
        }
        Err(e) => bail!("{name}: {expected}, but it cannot be read: {}", e.kind()),
        Ok(m) if !m.is_dir() => bail!("{name}: {expected}, got a file"),
        Ok(_) => {}
    }
    let has_rtl = std::fs::read_dir(dir.join("rtl")).is_ok_and(|entries| {
        entries
            .flatten()
            .any(|e| e.path().extension().is_some_and(|x| x == "v") && e.path().is_file())
    });
    if !has_rtl {
        bail!("{name}: {expected}, but it has no rtl/*.v");
    }
    if !dir.join("specfx_dut.v").is_file() {
        bail!("{name}: {expected}, but it has no specfx_dut.v");
    }
    Ok(dir)
}
