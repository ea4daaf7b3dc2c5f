//! Reading a vector directory written by `specfx vectors`, verified before anything uses it
//! (`specfx::golden::verify`: the manifest's keys, its configuration, ports and columns, every
//! file's sha256, the number of vectors of every file, every value's range, and the hex files
//! against the CSV); this module reads the files, within their size limits.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use anyhow::{bail, Result};

use specfx::golden::verify::{VerifiedManifest, CSV_FILE};
use specfx::pipeline::Config;

/// The largest data file of a vector directory (`vectors.csv` or a hex file): 4 GiB.
pub const MAX_DATA_BYTES: u64 = 4 << 30;

/// A verified vector directory.
pub struct VectorDir {
    /// The configuration of its manifest (unchanged: the `n` set it was written with).
    pub config: Config,
    /// The inputs of every vector, in file order: (n, raw code of c).
    pub inputs: Vec<(u32, i64)>,
}

/// The directory a `--config`/`--vectors` argument names: the directory itself, or the
/// directory of a `manifest.json` path; anything else is its own path, which [`open`] refuses
/// by name.
pub fn dir_of(path: &Path) -> PathBuf {
    if !path.is_dir() && path.file_name().is_some_and(|f| f == "manifest.json") {
        match path.parent() {
            Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
            _ => PathBuf::from("."),
        }
    } else {
        path.to_path_buf()
    }
}

/// Opens and verifies the vector directory `path` names (the directory or its
/// `manifest.json`) with [`VerifiedManifest`]. Nothing of the directory is used unless all of
/// it checks out.
pub fn open(path: &Path) -> Result<VectorDir> {
    if let Err(e) = std::fs::metadata(path) {
        let what = if std::fs::symlink_metadata(path).is_ok()
            && e.kind() == std::io::ErrorKind::NotFound
        {
            "a dangling symbolic link".to_string()
        } else if e.kind() == std::io::ErrorKind::NotFound {
            "no such file or directory".to_string()
        } else {
            e.to_string()
        };
        bail!(
            "{}: {what}, expected a vector directory (written by specfx vectors) or its manifest.json",
            path.display()
        );
    }
    let dir = dir_of(path);
    if !dir.is_dir() {
        bail!(
            "{}: not a directory, expected a vector directory (written by specfx vectors) or its manifest.json",
            path.display()
        );
    }
    let file = dir.join("manifest.json");
    let name = file.display().to_string();
    if !file.exists() {
        bail!(
            "{}: no manifest.json (write a vector directory with specfx vectors --out {})",
            dir.display(),
            dir.display()
        );
    }
    let text = super::input::read_text(&file, &name)?;
    let manifest = VerifiedManifest::parse(&text, &name)?;
    let label = |f: &str| dir.join(f).display().to_string();
    let mut data = BTreeMap::new();
    for f in manifest.files() {
        let what = label(f);
        let bytes = super::input::read_bytes(&dir.join(f), &what, MAX_DATA_BYTES)?;
        manifest.check_sha256(f, &bytes, &what)?;
        data.insert(f.to_string(), bytes);
    }
    let csv_name = label(CSV_FILE);
    let rows = manifest.read_csv(&data[CSV_FILE], &csv_name)?;
    let inputs = manifest.inputs(&rows, &csv_name)?;
    for (j, port) in manifest.ports().iter().enumerate() {
        let f = port.file_name();
        manifest.check_hex(j, &data[&f], &label(&f), &rows)?;
    }
    Ok(VectorDir {
        config: manifest.into_config(),
        inputs,
    })
}
