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
    let value: serde_json::Value =
        serde_json::from_str(&text).with_context(|| format!("{}: not JSON", file.display()))?;
    let config = value
        .get("config")
        .with_context(|| format!("{}: no key 'config'", file.display()))?;
    serde_json::from_value(config.clone()).with_context(|| {
        format!(
            "{}: key 'config' is not a specfx configuration",
            file.display()
        )
    })
}

/// The (n, c_raw) pairs of a vector directory, in file order, from its `vectors.csv` (read
/// with the csv crate): the columns of the ports `in_n` and `in_c`, found by name in the
/// header (cells `<port>:<format>`), wherever they are. A bad file gets one line naming the
/// file, the line and the column.
pub fn vector_inputs(dir: &Path) -> Result<Vec<(u32, i64)>> {
    let file = dir.join("vectors.csv");
    let text = std::fs::read(&file).with_context(|| format!("cannot read {}", file.display()))?;
    let mut reader = csv::ReaderBuilder::new()
        .has_headers(true)
        .from_reader(text.as_slice());
    let header: Vec<String> = reader
        .headers()
        .map_err(|e| csv_error(&file, &e))?
        .iter()
        .map(|cell| {
            cell.split_once(':')
                .map_or(cell, |(name, _)| name)
                .to_string()
        })
        .collect();
    let column = |port: &str| -> Result<usize> {
        header.iter().position(|h| h == port).with_context(|| {
            format!(
                "{}: no column '{port}' in the header (cells <port>:<format>; written by an older specfx? write the vectors again)",
                file.display()
            )
        })
    };
    let (i_n, i_c) = (column("in_n")?, column("in_c")?);
    let mut rows = Vec::new();
    for record in reader.records() {
        let record = record.map_err(|e| csv_error(&file, &e))?;
        let line = record.position().map_or(0, |p| p.line());
        let parse = |j: usize, port: &str| -> Result<i64> {
            let cell = record.get(j).unwrap_or("");
            cell.parse::<i64>().map_err(|_| {
                anyhow::anyhow!(
                    "{} line {line} column {}: expected an integer {port}, got '{cell}'",
                    file.display(),
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

/// A csv crate error while reading `file` as one line: the file, the line and what is wrong.
fn csv_error(file: &Path, e: &csv::Error) -> anyhow::Error {
    let line = e.position().map_or(0, |p| p.line());
    match e.kind() {
        csv::ErrorKind::UnequalLengths {
            expected_len, len, ..
        } => anyhow::anyhow!(
            "{} line {line}: expected {expected_len} fields as in the header, got {len}",
            file.display()
        ),
        csv::ErrorKind::Utf8 { err, .. } => anyhow::anyhow!(
            "{} line {line} column {}: not UTF-8",
            file.display(),
            err.field() + 1
        ),
        _ => anyhow::anyhow!("{} line {line}: {e}", file.display()),
    }
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
