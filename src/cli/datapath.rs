//! Loading a datapath from `--config FILE|baseline` (or a vector directory) and `--n SET`.

use std::path::Path;

use anyhow::{bail, Context, Result};

use specfx::nset::NSet;
use specfx::pipeline::{Config, Datapath};

/// Reads a configuration: a built-in name (`baseline`; a file of that name is read as
/// `./baseline`), a TOML file, or a vector directory (or its `manifest.json`), whose manifest
/// holds the full configuration; then applies `--n`.
///
/// A TOML file that sets no `name` is named after the file.
pub fn load(arg: &str, n: Option<&NSet>) -> Result<Datapath> {
    let path = Path::new(arg);
    let mut config = match Config::builtin(arg) {
        Some(c) => c,
        None if path.is_dir() || path.extension().is_some_and(|e| e == "json") => {
            config_from_manifest(path)?
        }
        None => {
            if !path.exists() {
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

/// The configuration recorded in a vector directory's `manifest.json`.
pub fn config_from_manifest(path: &Path) -> Result<Config> {
    let file = if path.is_dir() {
        path.join("manifest.json")
    } else {
        path.to_path_buf()
    };
    let text = super::input::read_text(&file, &file.display().to_string())?;
    specfx::golden::manifest_config(&text).with_context(|| file.display().to_string())
}

/// The (n, c_raw) pairs of a vector directory, in file order, from its `vectors.csv`: the
/// columns of the ports `in_n` and `in_c`, found by name in the header (cells
/// `<port>:<format>`), wherever they are.
pub fn vector_inputs(dir: &Path) -> Result<Vec<(u32, i64)>> {
    let file = dir.join("vectors.csv");
    let text = std::fs::read_to_string(&file)
        .with_context(|| format!("cannot read {}", file.display()))?;
    let mut lines = text.lines();
    let header: Vec<&str> = lines
        .next()
        .unwrap_or("")
        .split(',')
        .map(|cell| cell.split_once(':').map_or(cell, |(name, _)| name))
        .collect();
    let column = |port: &str| -> Result<usize> {
        header.iter().position(|&h| h == port).with_context(|| {
            format!(
                "{}: no column '{port}' in the header (cells <port>:<format>; written by an older specfx? write the vectors again)",
                file.display()
            )
        })
    };
    let (i_n, i_c) = (column("in_n")?, column("in_c")?);
    let mut rows = Vec::new();
    for (i, line) in lines.enumerate() {
        let fields: Vec<&str> = line.split(',').collect();
        let parse = |j: usize, port: &str| -> Result<i64> {
            fields
                .get(j)
                .and_then(|x| x.parse::<i64>().ok())
                .with_context(|| {
                    format!(
                        "{} line {}: expected an integer {port} in column {}, got '{line}'",
                        file.display(),
                        i + 2,
                        j + 1
                    )
                })
        };
        let n = parse(i_n, "in_n")?;
        let c = parse(i_c, "in_c")?;
        rows.push((u32::try_from(n).unwrap_or(0), c));
    }
    Ok(rows)
}

/// Parses a set of numbers of squarings (`--k`): the n-set notation (`4`, `3..=5`, `1,4,7`)
/// with every value in 1..=7.
pub fn parse_k_set(s: &str) -> std::result::Result<NSet, String> {
    let bad =
        || format!("expected numbers of squarings k in 1..=7 (e.g. 4, 3..=5 or 1,4,7), got '{s}'");
    let set: NSet = s.parse().map_err(|_| bad())?;
    if set.values().iter().all(|k| (1..=7).contains(k)) {
        Ok(set)
    } else {
        Err(bad())
    }
}
