//! Loading a datapath from `--config FILE|baseline` (or a vector directory) and `--n SET`.

use std::path::Path;

use anyhow::{bail, Context, Result};

use specfx::nset::NSet;
use specfx::pipeline::{Config, Datapath};
use specfx::reference::lobe::K_RANGE;

/// Reads a configuration: a built-in name (`baseline`; a file of that name is read as
/// `./baseline`), a TOML file, or a vector directory (or its `manifest.json`), whose manifest
/// holds the full configuration (the whole directory is verified first, see
/// [`super::vectordir::open`]); then applies `--n`.
///
/// A TOML file that sets no `name` is named after the file.
pub fn load(arg: &str, n: Option<&NSet>) -> Result<Datapath> {
    let path = Path::new(arg);
    let mut config = match Config::builtin(arg) {
        Some(c) => c,
        None if path.is_dir() || path.file_name().is_some_and(|f| f == "manifest.json") => {
            super::vectordir::open(path)?.config
        }
        None if path.extension().is_some_and(|e| e == "json") => {
            bail!(
                "config {arg}: a JSON file, expected a TOML configuration, a built-in name (baseline) or a vector directory (or its manifest.json)"
            )
        }
        None => {
            // A dangling symbolic link exists as a link: read_text names it.
            if !path.exists() && path.symlink_metadata().is_err() {
                bail!("config {arg}: no such file (and it is not a built-in name: baseline)");
            }
            let text = super::input::read_text(path, &format!("config {arg}"))?;
            let mut config = Config::from_toml(&text).with_context(|| format!("config {arg}"))?;
            let names_itself = text
                .parse::<toml::Table>()
                .is_ok_and(|t| t.contains_key("name"));
            if !names_itself {
                if let Some(stem) = path.file_stem() {
                    config.name = specfx::pipeline::config::name_from(&stem.to_string_lossy());
                }
            }
            config
        }
    };
    if let Some(n) = n {
        config.n = n.clone();
    }
    Datapath::new(config).with_context(|| format!("config {arg}"))
}

/// The datapath of a `--vectors` argument: a verified vector directory (or its
/// `manifest.json`), nothing else.
pub fn load_vectors(path: &Path) -> Result<Datapath> {
    let config = super::vectordir::open(path)?.config;
    Datapath::new(config).with_context(|| format!("--vectors {}", path.display()))
}

/// Parses a set of numbers of squarings (`--k`): the n-set notation (`4`, `3..=5`, `1,4,7`)
/// with every value in 1..=7.
pub fn parse_k_set(s: &str) -> std::result::Result<NSet, String> {
    let bad =
        || format!("expected numbers of squarings k in 1..=7 (e.g. 4, 3..=5 or 1,4,7), got '{s}'");
    let set: NSet = s.parse().map_err(|_| bad())?;
    if set.values().iter().all(|k| K_RANGE.contains(k)) {
        Ok(set)
    } else {
        Err(bad())
    }
}
