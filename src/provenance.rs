//! What determined a result: the specfx version, the command, and one canonical TOML text of
//! every input that changes its figures (datapath configurations, a design space or a scene,
//! the options), with the sha256 of that text. Every result directory holds both
//! (`inputs.toml`, `provenance.json`) and its documents end with [`Provenance::line`].
//!
//! Canonical means that the same inputs written differently (key order, whitespace, comments,
//! a key left at its default or spelled out, `16..1024` or `16..=1024`) give the same text,
//! byte for byte, hence the same hash: configurations are written from their parsed form,
//! every key present in a fixed order, exponent sets in their compact notation, budgets as
//! their bounds. The text holds no path, time or host, so it is the same on every machine.

use serde::Serialize;
use sha2::{Digest, Sha256};

use crate::nset::NSet;
use crate::pipeline::Config;

/// The specfx version that writes a result (the Cargo package's version).
pub const VERSION: &str = env!("CARGO_PKG_VERSION");

/// The file of a result directory that holds the canonical inputs.
pub const INPUTS_FILE: &str = "inputs.toml";

/// The file of a result directory that holds the version, the command and the inputs' hash.
pub const PROVENANCE_FILE: &str = "provenance.json";

/// The lowercase hex sha256 of `bytes`.
///
/// # Examples
/// ```
/// use specfx::provenance::sha256_hex;
/// assert_eq!(
///     sha256_hex(b"abc"),
///     "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad"
/// );
/// ```
pub fn sha256_hex(bytes: &[u8]) -> String {
    Sha256::digest(bytes)
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect()
}

/// An exponent set in its compact notation (`16..=1024`, `1..=3,5`), whatever way it was
/// written.
///
/// # Examples
/// ```
/// use specfx::provenance::canonical_nset;
/// let a = canonical_nset(&"16..1024".parse().unwrap());
/// let b = canonical_nset(&"16..=1024, 20".parse().unwrap());
/// assert_eq!((a.as_str(), b.as_str()), ("16..=1024", "16..=1024"));
/// ```
pub fn canonical_nset(n: &NSet) -> String {
    NSet::from_values(n.values())
        .expect("a valid set's values form a valid set")
        .to_string()
}

/// A configuration with its exponent set in the compact notation: equal configurations give
/// equal canonical configurations.
pub fn canonical_config(config: &Config) -> Config {
    let mut c = config.clone();
    c.n = NSet::from_values(config.n.values()).expect("a valid set's values form a valid set");
    c
}

/// The inputs of one result, gathered into one TOML document: `command`, `[options]`, one
/// `[[config]]` per datapath configuration (complete: every key), and the design space or
/// scene when there is one.
#[derive(Debug, Clone, PartialEq)]
pub struct Inputs {
    root: toml::Table,
}

fn to_value(what: &str, v: &impl Serialize) -> toml::Value {
    toml::Value::try_from(v).unwrap_or_else(|e| panic!("{what} serialises to TOML: {e}"))
}

impl Inputs {
    /// The inputs of `specfx <command>` (e.g. `budget`, `sweep`).
    pub fn new(command: &str) -> Inputs {
        let mut root = toml::Table::new();
        root.insert("command".into(), command.into());
        Inputs { root }
    }

    /// Records an option that changes the result (under `[options]`).
    pub fn option(mut self, key: &str, value: impl Into<toml::Value>) -> Inputs {
        self.root
            .entry("options")
            .or_insert_with(|| toml::Value::Table(toml::Table::new()))
            .as_table_mut()
            .expect("options is a table")
            .insert(key.into(), value.into());
        self
    }

    /// Records a datapath configuration (another `[[config]]`, in the order given).
    pub fn config(mut self, config: &Config) -> Inputs {
        let value = to_value("a configuration", &canonical_config(config));
        self.root
            .entry("config")
            .or_insert_with(|| toml::Value::Array(Vec::new()))
            .as_array_mut()
            .expect("config is an array")
            .push(value);
        self
    }

    /// Records a serialisable value under `key` (a design space's `[space]`, recorded by
    /// `analysis::sweep::Space::recorded`: this module knows no result's types).
    pub fn value(mut self, key: &str, value: &impl Serialize) -> Inputs {
        self.root.insert(key.into(), to_value(key, value));
        self
    }

    /// Records a table under `key` (a scene's canonical form).
    pub fn table(mut self, key: &str, table: toml::Table) -> Inputs {
        self.root.insert(key.into(), toml::Value::Table(table));
        self
    }

    /// The canonical text.
    ///
    /// # Examples
    /// ```
    /// use specfx::pipeline::Config;
    /// use specfx::provenance::Inputs;
    /// // The same configuration, written two ways (s2.16 is the baseline's t format).
    /// let a = Config::from_toml("k = 5 # five\nn = \"16..1024\"\n[t]\nrounding = \"TRN\"\n").unwrap();
    /// let b = Config::from_toml("n = '16..=1024'\nk = 5\n[t]\nrounding = 'TRN'\nformat = 's2.16'\n").unwrap();
    /// let text = |c: &Config| Inputs::new("check").config(c).canonical();
    /// assert_eq!(text(&a), text(&b));
    /// assert!(text(&a).starts_with("command = \"check\"\n"));
    /// ```
    pub fn canonical(&self) -> String {
        toml::to_string(&self.root).expect("a TOML table serialises")
    }
}

/// What `provenance.json` holds: the version that wrote a result, the command, and the sha256
/// of its canonical inputs (the bytes of `inputs.toml`).
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct Provenance {
    /// The specfx version that wrote the result.
    pub specfx_version: String,
    /// The command, e.g. `budget`.
    pub command: String,
    /// The file holding the canonical inputs ([`INPUTS_FILE`]).
    pub inputs: String,
    /// The lowercase hex sha256 of that file's bytes.
    pub inputs_sha256: String,
    /// The canonical inputs themselves (the file's text).
    #[serde(skip)]
    pub canonical: String,
}

impl Provenance {
    /// The provenance of a result of `inputs`, written by this version.
    ///
    /// # Examples
    /// ```
    /// use specfx::provenance::{sha256_hex, Inputs, Provenance};
    /// let p = Provenance::new(&Inputs::new("tradeoff").option("n", "16..=1024"));
    /// assert_eq!(p.canonical, "command = \"tradeoff\"\n\n[options]\nn = \"16..=1024\"\n");
    /// assert_eq!(p.inputs_sha256, sha256_hex(p.canonical.as_bytes()));
    /// assert!(p.line().starts_with(&format!("specfx {} · `specfx tradeoff`", p.specfx_version)));
    /// ```
    pub fn new(inputs: &Inputs) -> Provenance {
        let canonical = inputs.canonical();
        Provenance {
            specfx_version: VERSION.to_string(),
            command: inputs
                .root
                .get("command")
                .and_then(|c| c.as_str())
                .unwrap_or_default()
                .to_string(),
            inputs: INPUTS_FILE.to_string(),
            inputs_sha256: sha256_hex(canonical.as_bytes()),
            canonical,
        }
    }

    /// The line documents end with: version, command and the inputs' hash (Markdown; the
    /// HTML renderer keeps the code spans).
    pub fn line(&self) -> String {
        format!(
            "specfx {} · `specfx {}` · inputs sha256 `{}` (`{INPUTS_FILE}`, `{PROVENANCE_FILE}`)",
            self.specfx_version, self.command, self.inputs_sha256
        )
    }

    /// The two files of a result's provenance, `(name, bytes)`: `inputs.toml` (the
    /// canonical inputs) and `provenance.json`.
    pub fn files(&self) -> [(String, Vec<u8>); 2] {
        [
            (INPUTS_FILE.to_string(), self.canonical.clone().into_bytes()),
            (PROVENANCE_FILE.to_string(), self.json().into_bytes()),
        ]
    }

    /// The provenance of a single file as comment lines (TOML, shell): the line documents end
    /// with, then the canonical inputs, each line behind `#| ` (the hash is of those lines
    /// without the prefix, each ending in a newline: `grep '^#|' FILE | cut -c4- | sha256sum`).
    pub fn comment(&self) -> String {
        let mut s = format!(
            "# specfx {} · specfx {} · inputs sha256 {}: the canonical inputs, on the lines starting with '#|'\n",
            self.specfx_version, self.command, self.inputs_sha256
        );
        for line in self.canonical.lines() {
            s.push_str(if line.is_empty() { "#|" } else { "#| " });
            s.push_str(line);
            s.push('\n');
        }
        s
    }

    /// `provenance.json`'s text (pretty JSON and a newline).
    pub fn json(&self) -> String {
        let mut s = serde_json::to_string_pretty(self).expect("provenance serialises");
        s.push('\n');
        s
    }
}
