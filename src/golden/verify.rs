//! Verifying a vector directory that `specfx vectors` wrote, before anything uses it: the
//! manifest's keys, its configuration, ports and columns ([`VerifiedManifest::parse`]), every
//! file's sha256 ([`VerifiedManifest::check_sha256`]), the number of vectors of every file and
//! every value's range ([`VerifiedManifest::read_csv`], [`VerifiedManifest::inputs`]), and the
//! hex files against the CSV ([`VerifiedManifest::check_hex`]).
//!
//! The functions take text and bytes, not paths: the caller reads the files (the command line
//! with its size limits, the fuzz target from memory) and names them; every error is one line
//! beginning with that name.

use std::collections::{BTreeMap, BTreeSet};

use serde::Deserialize;
use sha2::{Digest, Sha256};

use super::{csv_columns, hex_word, ports, CsvColumn, CsvInfo, Port};
use crate::error::{one_line, Error, OneLine};
use crate::fixed::Format;
use crate::pipeline::{Config, Datapath};

/// The name of a vector directory's CSV file.
pub const CSV_FILE: &str = "vectors.csv";

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

/// A manifest whose keys, configuration, ports, columns and list of files check out: what the
/// vector directory's files must hold.
#[derive(Debug, Clone)]
pub struct VerifiedManifest {
    config: Config,
    n_vectors: u64,
    ports: Vec<Port>,
    columns: Vec<CsvColumn>,
    formats: Vec<Format>,
    sha256: BTreeMap<String, String>,
}

fn fail(problem: String) -> Error {
    Error::Manifest { problem }
}

impl VerifiedManifest {
    /// Parses and checks the text of `manifest.json`; `name` (the file, as the user knows it)
    /// begins every error.
    ///
    /// # Examples
    /// ```
    /// use specfx::golden::verify::VerifiedManifest;
    /// let e = VerifiedManifest::parse("{\"config\": 1}", "v/manifest.json").unwrap_err();
    /// assert!(e.to_string().starts_with("v/manifest.json: key 'config': invalid type"), "{e}");
    /// ```
    pub fn parse(text: &str, name: &str) -> Result<VerifiedManifest, Error> {
        let de = &mut serde_json::Deserializer::from_str(text);
        let m: ManifestFile = serde_path_to_error::deserialize(de).map_err(|e| {
            let path = e.path().to_string();
            let inner = one_line(&e.into_inner().to_string());
            // "." is the whole document, "?" a place the parser never reached (truncated text).
            if path == "." || path == "?" {
                fail(format!("{name}: {inner}"))
            } else {
                fail(format!("{name}: key '{}': {inner}", OneLine(&path)))
            }
        })?;
        if m.specfx_version.is_empty() {
            return Err(fail(format!(
                "{name}: key 'specfx_version': expected a version, got ''"
            )));
        }
        let dp = Datapath::new(m.config.clone())
            .map_err(|e| fail(format!("{name}: key 'config': {e}")))?;
        if !matches!(m.order.as_str(), "interleaved" | "sorted") {
            return Err(fail(format!(
                "{name}: key 'order': expected interleaved or sorted, got '{}'",
                OneLine(&m.order)
            )));
        }
        if m.n_vectors == 0 {
            return Err(fail(format!(
                "{name}: key 'n_vectors': expected at least 1, got 0"
            )));
        }

        // The ports and columns the configuration implies, exactly.
        let ports = ports(&dp);
        let want_ports = serde_json::to_value(&ports).expect("ports serialise");
        if m.ports != want_ports {
            return Err(fail(format!(
                "{name}: key 'ports': expected the configuration's ports ({}), got something else",
                ports
                    .iter()
                    .map(|p| format!("{}:{}", p.name, p.format))
                    .collect::<Vec<_>>()
                    .join(", ")
            )));
        }
        let columns = csv_columns(&dp);
        let want_csv = serde_json::to_value(CsvInfo {
            file: CSV_FILE.to_string(),
            columns: columns.clone(),
        })
        .expect("csv info serialises");
        if m.csv != want_csv {
            return Err(fail(format!(
                "{name}: key 'csv': expected file {CSV_FILE} with one column per port, in the order of 'ports'"
            )));
        }

        // The hashes: exactly the CSV and one hex file per port, and the record of what
        // produced the vectors when it is listed.
        let mut files: BTreeSet<String> = ports.iter().map(Port::file_name).collect();
        files.insert(CSV_FILE.to_string());
        for record in [
            crate::provenance::INPUTS_FILE,
            crate::provenance::PROVENANCE_FILE,
        ] {
            if m.sha256.contains_key(record) {
                files.insert(record.to_string());
            }
        }
        let listed: BTreeSet<String> = m.sha256.keys().cloned().collect();
        if let Some(missing) = files.difference(&listed).next() {
            return Err(fail(format!("{name}: key 'sha256': no hash for {missing}")));
        }
        if let Some(extra) = listed.difference(&files).next() {
            return Err(fail(format!(
                "{name}: key 'sha256': '{}' is not a file of this vector directory",
                OneLine(extra)
            )));
        }
        let formats = columns
            .iter()
            .map(|c| {
                c.format
                    .parse()
                    .expect("a configuration's formats print and parse")
            })
            .collect();
        Ok(VerifiedManifest {
            config: m.config,
            n_vectors: m.n_vectors,
            ports,
            columns,
            formats,
            sha256: m.sha256,
        })
    }

    /// The configuration the vectors were written with (its `n` set unchanged).
    pub fn config(&self) -> &Config {
        &self.config
    }

    /// Consumes the manifest, returning its configuration.
    pub fn into_config(self) -> Config {
        self.config
    }

    /// The number of vectors every file holds.
    pub fn n_vectors(&self) -> u64 {
        self.n_vectors
    }

    /// The `$readmemh` files, one per port, in the order of the CSV's columns.
    pub fn ports(&self) -> &[Port] {
        &self.ports
    }

    /// Every file of the directory the manifest lists a hash for, sorted.
    pub fn files(&self) -> impl Iterator<Item = &str> {
        self.sha256.keys().map(String::as_str)
    }

    /// Checks `bytes`, the content of the directory's `file` (named `what` in the error),
    /// against the manifest's sha256.
    pub fn check_sha256(&self, file: &str, bytes: &[u8], what: &str) -> Result<(), Error> {
        let digest: String = Sha256::digest(bytes)
            .iter()
            .map(|b| format!("{b:02x}"))
            .collect();
        let want = self.sha256.get(file).ok_or_else(|| {
            fail(format!(
                "{what}: not a file of this vector directory (the manifest lists no hash for it)"
            ))
        })?;
        if &digest != want {
            return Err(fail(format!(
                "{what}: sha256 {digest} differs from the manifest's {} (the file was changed after specfx vectors wrote it; write the vectors again)",
                OneLine(want)
            )));
        }
        Ok(())
    }

    /// Every value of `vectors.csv` (named `what` in errors), row by row, checked against the
    /// header, the formats and the number of rows.
    pub fn read_csv(&self, bytes: &[u8], what: &str) -> Result<Vec<i64>, Error> {
        let n_vectors = self.n_vectors;
        let text = std::str::from_utf8(bytes).map_err(|e| {
            fail(format!(
                "{what}: expected UTF-8 text, got an invalid byte at offset {}",
                e.valid_up_to()
            ))
        })?;
        let mut lines = text.lines();
        let header = lines.next().unwrap_or("");
        let want: Vec<String> = self.columns.iter().map(CsvColumn::header).collect();
        let want = want.join(",");
        if header != want {
            return Err(fail(if header.contains(':') {
                format!("{what} line 1: expected the header {want}")
            } else {
                format!(
                    "{what} line 1: expected the header {want} (written by an older specfx? write the vectors again)"
                )
            }));
        }
        let mut values = Vec::new();
        let mut n_rows = 0u64;
        for (i, line) in lines.enumerate() {
            let line_no = i + 2;
            n_rows += 1;
            if n_rows > n_vectors {
                return Err(fail(format!(
                    "{what} line {line_no}: the manifest says {n_vectors} vectors, the file has more rows"
                )));
            }
            let mut fields = line.split(',');
            for (j, (col, format)) in self.columns.iter().zip(&self.formats).enumerate() {
                let cell = fields.next().ok_or_else(|| {
                    fail(format!(
                        "{what} line {line_no}: expected {} columns, got {j}",
                        self.columns.len()
                    ))
                })?;
                let v: i64 = cell.parse().map_err(|_| {
                    fail(format!(
                        "{what} line {line_no} column {} ({}): expected an integer raw code, got '{}'",
                        j + 1,
                        col.name,
                        OneLine(cell)
                    ))
                })?;
                if !format.contains_raw(i128::from(v)) {
                    return Err(fail(format!(
                        "{what} line {line_no} column {} ({}): raw code {v} is outside {} ({}..={})",
                        j + 1,
                        col.name,
                        col.format,
                        format.min_raw(),
                        format.max_raw()
                    )));
                }
                values.push(v);
            }
            if fields.next().is_some() {
                return Err(fail(format!(
                    "{what} line {line_no}: expected {} columns, got more",
                    self.columns.len()
                )));
            }
        }
        if n_rows != n_vectors {
            return Err(fail(format!(
                "{what}: the manifest says {n_vectors} vectors, the file has {n_rows} rows"
            )));
        }
        Ok(values)
    }

    /// The inputs of every vector, in file order: (n, raw code of c), from the values
    /// [`VerifiedManifest::read_csv`] returned; every n must be in the configuration's set.
    pub fn inputs(&self, rows: &[i64], what: &str) -> Result<Vec<(u32, i64)>, Error> {
        let column = |port: &str| {
            self.columns
                .iter()
                .position(|c| c.name == port)
                .expect("every configuration has in_n and in_c ports")
        };
        let (i_n, i_c) = (column("in_n"), column("in_c"));
        let ns = self.config.n.values();
        let mut inputs = Vec::with_capacity(rows.len() / self.columns.len());
        for (row, values) in rows.chunks(self.columns.len()).enumerate() {
            let n = values[i_n];
            if u32::try_from(n).map_or(true, |n| ns.binary_search(&n).is_err()) {
                return Err(fail(format!(
                    "{what} line {}: in_n = {n} is not in the configuration's n set {}",
                    row + 2,
                    self.config.n
                )));
            }
            inputs.push((n as u32, values[i_c]));
        }
        Ok(inputs)
    }

    /// Checks the `$readmemh` file of port `port` (an index into [`VerifiedManifest::ports`];
    /// its content `bytes`, named `what`): one word per vector, the CSV's value (from `rows`,
    /// as [`VerifiedManifest::read_csv`] returned them) masked to the port's width.
    pub fn check_hex(
        &self,
        port: usize,
        bytes: &[u8],
        what: &str,
        rows: &[i64],
    ) -> Result<(), Error> {
        let n_vectors = self.n_vectors;
        let width = self
            .ports
            .get(port)
            .ok_or_else(|| fail(format!("{what}: port {port} is not one of the manifest's")))?
            .width;
        if n_vectors.checked_mul(self.columns.len() as u64) != Some(rows.len() as u64) {
            return Err(fail(format!(
                "{what}: expected the {n_vectors} rows of {CSV_FILE}, got {} values",
                rows.len()
            )));
        }
        let text = std::str::from_utf8(bytes)
            .map_err(|_| fail(format!("{what}: expected hexadecimal text")))?;
        let mut n = 0u64;
        for (i, line) in text.lines().enumerate() {
            if i as u64 >= n_vectors {
                return Err(fail(format!(
                    "{what} line {}: the manifest says {n_vectors} vectors, the file has more lines",
                    i + 1
                )));
            }
            let want = hex_word(rows[i * self.columns.len() + port], width);
            if line != want {
                return Err(fail(format!(
                    "{what} line {}: expected the word {want} ({CSV_FILE} row {}), got '{}'",
                    i + 1,
                    i + 2,
                    OneLine(line)
                )));
            }
            n += 1;
        }
        if n != n_vectors {
            return Err(fail(format!(
                "{what}: the manifest says {n_vectors} vectors, the file has {n} lines"
            )));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn manifest_errors_are_one_line_and_name_the_key() {
        let e = VerifiedManifest::parse(
            "{\"specfx_version\": \"1\", \"config\": {\"name\": \"x\", \"variant\": \"a\\nb\"}}",
            "m.json",
        )
        .unwrap_err()
        .to_string();
        assert!(
            e.starts_with(
                "m.json: key 'config.variant': unknown variant `a b`, expected `plain` or `minimax`"
            ),
            "{e}"
        );
        let e = VerifiedManifest::parse("{\n", "m.json")
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("m.json: EOF while parsing an object"), "{e}");
        let e = VerifiedManifest::parse("{\"a\\nb\": 1}", "m.json")
            .unwrap_err()
            .to_string();
        assert!(!e.contains('\n'), "{e}");
    }
}
