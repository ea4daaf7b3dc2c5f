//! The synthesis cache: what yosys and nextpnr answered for exactly these inputs, kept so
//! that the same synthesis is not run twice (a report, a sweep's front, the optimiser's
//! yosys objective and the test suite repeat many). An entry is found by the sha256 of
//! everything the tool reads (its version, its script, every source file's bytes), holds
//! the files specfx reads back from the tool (`stat.json`, nextpnr's `report.json`), and is
//! only ever written whole (a directory renamed into place); only a synthesis that succeeded
//! is kept. Tools are deterministic on the same inputs, so a result from the cache is the
//! result the tool would give: every figure and file is the same with and without it.
//!
//! Where: `$SPECFX_CACHE` (`off` or empty: no cache), else `$XDG_CACHE_HOME/specfx`, else
//! `$HOME/.cache/specfx`. A cache that cannot be read or written is as if there were none.

use std::path::{Path, PathBuf};

use sha2::{Digest, Sha256};

/// The cache directory, if any (see the module's documentation).
pub fn dir() -> Option<PathBuf> {
    match std::env::var_os("SPECFX_CACHE") {
        Some(v) if v.is_empty() || v == "off" => None,
        Some(v) => Some(PathBuf::from(v)),
        None => std::env::var_os("XDG_CACHE_HOME")
            .filter(|v| !v.is_empty())
            .map(PathBuf::from)
            .or_else(|| {
                std::env::var_os("HOME")
                    .filter(|v| !v.is_empty())
                    .map(|h| PathBuf::from(h).join(".cache"))
            })
            .map(|d| d.join("specfx")),
    }
}

/// The key of an entry: the sha256 of `parts`, each length-prefixed (so that no two lists
/// of parts give the same bytes), in hex.
pub fn key(parts: &[&[u8]]) -> String {
    let mut h = Sha256::new();
    for p in parts {
        h.update((p.len() as u64).to_le_bytes());
        h.update(p);
    }
    h.finalize().iter().map(|b| format!("{b:02x}")).collect()
}

/// The entry's directory: `<cache>/<kind>/<key>`.
fn entry(kind: &str, key: &str) -> Option<PathBuf> {
    Some(dir()?.join(kind).join(key))
}

/// The files `names` of the entry `kind`/`key`, when it is there and holds each of them
/// (`None` for a name it lacks only when every other is there: optional outputs).
pub fn get(kind: &str, key: &str, names: &[&str]) -> Option<Vec<Option<Vec<u8>>>> {
    let dir = entry(kind, key)?;
    if !dir.is_dir() {
        return None;
    }
    let files: Vec<Option<Vec<u8>>> = names
        .iter()
        .map(|n| std::fs::read(dir.join(n)).ok())
        .collect();
    // An entry holds at least its first file.
    files.first()?.as_ref()?;
    Some(files)
}

/// Keeps `files` (`(name, bytes)`) as the entry `kind`/`key`: written into a temporary
/// directory of the cache, then renamed into place whole. An entry already there (another
/// process's, for the same inputs) stays; any failure leaves the cache as it was.
pub fn put(kind: &str, key: &str, files: &[(&str, &[u8])]) {
    let Some(dest) = entry(kind, key) else {
        return;
    };
    let Some(parent) = dest.parent() else {
        return;
    };
    if dest.exists() || std::fs::create_dir_all(parent).is_err() {
        return;
    }
    let Ok(tmp) = tempfile::Builder::new().prefix(".new-").tempdir_in(parent) else {
        return;
    };
    let written = files
        .iter()
        .all(|(name, bytes)| std::fs::write(tmp.path().join(name), bytes).is_ok());
    if written && std::fs::rename(tmp.path(), &dest).is_ok() {
        // Renamed: nothing left for the temporary directory's drop to remove.
        let _ = tmp.keep();
    }
}

/// The bytes of a file the tool reads, for a key (empty when it cannot be read: the tool
/// would then fail, and a failure is never kept).
pub fn file_bytes(path: &Path) -> Vec<u8> {
    std::fs::read(path).unwrap_or_default()
}
