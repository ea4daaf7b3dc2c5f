//! Reading a vector directory written by `specfx vectors`, verified before anything uses it:
//! the manifest's keys, its configuration, ports and columns, every file's sha256, the
//! number of vectors of every file, every value's range, and the hex files against the CSV.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use serde::Deserialize;
use sha2::{Digest, Sha256};

use specfx::fixed::Format;
use specfx::golden::{self, CsvColumn, CsvInfo};
use specfx::pipeline::{Config, Datapath};

/// The largest data file of a vector directory (`vectors.csv` or a hex file): 4 GiB.
pub const MAX_DATA_BYTES: u64 = 4 << 30;

/// `manifest.json` as it is read: every key required, no other key allowed; the parts the
/// reader does not use (coverage) are kept as plain JSON.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
#[allow(dead_code)] // seed, cases and coverage are required but describe, not drive, the vectors
struct ManifestFile {
    specfx_version: String,
    config: Config,
    ports: serde_json::Value,
    csv: serde_json::Value,
    cases: String,
    order: String,
    seed: u64,
    n_vectors: u64,
    coverage: serde_json::Value,
    sha256: BTreeMap<String, String>,
}

/// A verified vector directory.
pub struct VectorDir {
    /// The configuration of its manifest (unchanged: the `n` set it was written with).
    pub config: Config,
    /// The inputs of every vector, in file order: (n, raw code of c).
    pub inputs: Vec<(u32, i64)>,
}

/// The directory a `--config`/`--vectors` argument names: the directory itself, or the
/// directory of a `manifest.json` path.
pub fn dir_of(path: &Path) -> PathBuf {
    if path.is_dir() {
        path.to_path_buf()
    } else {
        match path.parent() {
            Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
            _ => PathBuf::from("."),
        }
    }
}

/// Opens and verifies the vector directory `path` names (the directory or its
/// `manifest.json`). Nothing of the directory is used unless all of it checks out.
pub fn open(path: &Path) -> Result<VectorDir> {
    let dir = dir_of(path);
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
    let de = &mut serde_json::Deserializer::from_str(&text);
    let m: ManifestFile = serde_path_to_error::deserialize(de).map_err(|e| {
        let path = e.path().to_string();
        let inner = one_line(&e.into_inner().to_string());
        if path == "." {
            anyhow::anyhow!("{name}: {inner}")
        } else {
            anyhow::anyhow!("{name}: key '{path}': {inner}")
        }
    })?;
    if m.specfx_version.is_empty() {
        bail!("{name}: key 'specfx_version': expected a version, got ''");
    }
    let dp = Datapath::new(m.config.clone())
        .map_err(|e| anyhow::anyhow!("{name}: key 'config': {e}"))?;
    if !matches!(m.order.as_str(), "interleaved" | "sorted") {
        bail!(
            "{name}: key 'order': expected interleaved or sorted, got '{}'",
            m.order
        );
    }
    if m.n_vectors == 0 {
        bail!("{name}: key 'n_vectors': expected at least 1, got 0");
    }

    // The ports and columns the configuration implies, exactly.
    let ports = golden::ports(&dp);
    let want_ports = serde_json::to_value(&ports).expect("ports serialise");
    if m.ports != want_ports {
        bail!(
            "{name}: key 'ports': expected the configuration's ports ({}), got something else",
            ports
                .iter()
                .map(|p| format!("{}:{}", p.name, p.format))
                .collect::<Vec<_>>()
                .join(", ")
        );
    }
    let columns = golden::csv_columns(&dp);
    let want_csv = serde_json::to_value(CsvInfo {
        file: "vectors.csv".to_string(),
        columns: columns.clone(),
    })
    .expect("csv info serialises");
    if m.csv != want_csv {
        bail!("{name}: key 'csv': expected file vectors.csv with one column per port, in the order of 'ports'");
    }

    // The hashes: exactly the CSV and one hex file per port, each matching its file.
    let mut files: BTreeSet<String> = ports.iter().map(|p| p.file_name()).collect();
    files.insert("vectors.csv".to_string());
    let listed: BTreeSet<String> = m.sha256.keys().cloned().collect();
    // The record of what produced the vectors, verified like the rest when listed.
    for record in [
        specfx::provenance::INPUTS_FILE,
        specfx::provenance::PROVENANCE_FILE,
    ] {
        if listed.contains(record) {
            files.insert(record.to_string());
        }
    }
    if let Some(missing) = files.difference(&listed).next() {
        bail!("{name}: key 'sha256': no hash for {missing}");
    }
    if let Some(extra) = listed.difference(&files).next() {
        bail!("{name}: key 'sha256': '{extra}' is not a file of this vector directory");
    }
    let mut data = BTreeMap::new();
    for f in &files {
        let path = dir.join(f);
        let what = path.display().to_string();
        let bytes = super::input::read_bytes(&path, &what, MAX_DATA_BYTES)?;
        let digest = hex(&Sha256::digest(&bytes));
        let want = &m.sha256[f];
        if &digest != want {
            bail!("{what}: sha256 {digest} differs from the manifest's {want} (the file was changed after specfx vectors wrote it; write the vectors again)");
        }
        data.insert(f.clone(), bytes);
    }

    // The CSV: its header, its number of rows, every value in its column's format.
    let csv_name = dir.join("vectors.csv").display().to_string();
    let formats: Vec<Format> = columns
        .iter()
        .map(|c| {
            c.format
                .parse()
                .expect("a configuration's formats print and parse")
        })
        .collect();
    let rows = read_csv(
        &data["vectors.csv"],
        &csv_name,
        &columns,
        &formats,
        m.n_vectors,
    )?;

    // The inputs, in the configuration's n set.
    let (i_n, i_c) = (column(&columns, "in_n"), column(&columns, "in_c"));
    let ns = m.config.n.values();
    let mut inputs = Vec::with_capacity(rows.len() / columns.len());
    for (row, values) in rows.chunks(columns.len()).enumerate() {
        let n = values[i_n];
        if u32::try_from(n).map_or(true, |n| ns.binary_search(&n).is_err()) {
            bail!(
                "{csv_name} line {}: in_n = {n} is not in the configuration's n set {}",
                row + 2,
                m.config.n
            );
        }
        inputs.push((n as u32, values[i_c]));
    }

    // Every hex file: one word per vector, the CSV's value masked to the port's width.
    for (j, port) in ports.iter().enumerate() {
        let f = port.file_name();
        let what = dir.join(&f).display().to_string();
        check_hex(&data[&f], &what, port.width, m.n_vectors, |i| {
            rows[i * columns.len() + j]
        })?;
    }
    Ok(VectorDir {
        config: m.config,
        inputs,
    })
}

fn column(columns: &[CsvColumn], port: &str) -> usize {
    columns
        .iter()
        .position(|c| c.name == port)
        .expect("every configuration has in_n and in_c ports")
}

/// Every value of `vectors.csv`, row by row, checked against the header, the formats and the
/// number of rows.
fn read_csv(
    bytes: &[u8],
    what: &str,
    columns: &[CsvColumn],
    formats: &[Format],
    n_vectors: u64,
) -> Result<Vec<i64>> {
    let text = std::str::from_utf8(bytes).map_err(|e| {
        anyhow::anyhow!(
            "{what}: expected UTF-8 text, got an invalid byte at offset {}",
            e.valid_up_to()
        )
    })?;
    let mut lines = text.lines();
    let header = lines.next().unwrap_or("");
    let want: Vec<String> = columns.iter().map(CsvColumn::header).collect();
    if header != want.join(",") {
        if !header.contains(':') {
            bail!("{what} line 1: expected the header {} (written by an older specfx? write the vectors again)", want.join(","));
        }
        bail!("{what} line 1: expected the header {}", want.join(","));
    }
    let mut values = Vec::new();
    let mut n_rows = 0u64;
    for (i, line) in lines.enumerate() {
        let line_no = i + 2;
        n_rows += 1;
        if n_rows > n_vectors {
            bail!("{what} line {line_no}: the manifest says {n_vectors} vectors, the file has more rows");
        }
        let mut fields = line.split(',');
        for (j, (col, format)) in columns.iter().zip(formats).enumerate() {
            let cell = fields.next().with_context(|| {
                format!(
                    "{what} line {line_no}: expected {} columns, got {}",
                    columns.len(),
                    j
                )
            })?;
            let v: i64 = cell.parse().map_err(|_| {
                anyhow::anyhow!(
                    "{what} line {line_no} column {} ({}): expected an integer raw code, got '{cell}'",
                    j + 1,
                    col.name
                )
            })?;
            if !format.contains_raw(i128::from(v)) {
                bail!(
                    "{what} line {line_no} column {} ({}): raw code {v} is outside {} ({}..={})",
                    j + 1,
                    col.name,
                    col.format,
                    format.min_raw(),
                    format.max_raw()
                );
            }
            values.push(v);
        }
        if fields.next().is_some() {
            bail!(
                "{what} line {line_no}: expected {} columns, got more",
                columns.len()
            );
        }
    }
    if n_rows != n_vectors {
        bail!("{what}: the manifest says {n_vectors} vectors, the file has {n_rows} rows");
    }
    Ok(values)
}

/// Checks a `$readmemh` file: `n_vectors` lines, each the word of `value(i)` in `width` bits.
fn check_hex(
    bytes: &[u8],
    what: &str,
    width: u32,
    n_vectors: u64,
    value: impl Fn(usize) -> i64,
) -> Result<()> {
    let text = std::str::from_utf8(bytes)
        .map_err(|_| anyhow::anyhow!("{what}: expected hexadecimal text"))?;
    let mut n = 0usize;
    for (i, line) in text.lines().enumerate() {
        if i as u64 >= n_vectors {
            bail!(
                "{what} line {}: the manifest says {n_vectors} vectors, the file has more lines",
                i + 1
            );
        }
        let want = golden::hex_word(value(i), width);
        if line != want {
            bail!(
                "{what} line {}: expected the word {want} (vectors.csv row {}), got '{line}'",
                i + 1,
                i + 2
            );
        }
        n += 1;
    }
    if n as u64 != n_vectors {
        bail!("{what}: the manifest says {n_vectors} vectors, the file has {n} lines");
    }
    Ok(())
}

fn hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}

fn one_line(s: &str) -> String {
    s.split_whitespace().collect::<Vec<_>>().join(" ")
}
