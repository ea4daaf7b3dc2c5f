//! Golden vectors: the cases, their CSV and `$readmemh` renderings, and the manifest.
//!
//! Everything renders into writers; the command line decides where the files go. Files are
//! byte-for-byte deterministic for the same configuration, cases and seed.

pub mod cases;

use std::collections::BTreeMap;
use std::io::{self, Write};

use serde::Serialize;
use sha2::{Digest, Sha256};

use crate::fixed::Format;
use crate::pipeline::{Config, Datapath, ProbeColumns, Variant};

pub use cases::CaseSelection;

/// What a port carries for one vector.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Source {
    C,
    N,
    Coef,
    Slope,
    Offset,
    Threshold,
    Stage(usize),
}

/// One `$readmemh` file: a datapath port or a stage probe, with its format.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct Port {
    /// The port's name; its file is `<name>.hex`.
    pub name: String,
    /// The value's format (the word is its raw code in two's complement, `width` bits).
    pub format: String,
    /// The word width in bits.
    pub width: u32,
    /// Whether the raw code is signed.
    pub signed: bool,
    /// What it holds, in words.
    pub description: String,
    #[serde(skip)]
    source: Source,
}

impl Port {
    fn new(name: &str, format: Format, source: Source, description: &str) -> Port {
        Port {
            name: name.to_string(),
            format: format.to_string(),
            width: format.width(),
            signed: format.is_signed(),
            description: description.to_string(),
            source,
        }
    }

    /// The file the port is written to.
    pub fn file_name(&self) -> String {
        format!("{}.hex", self.name)
    }
}

/// The format of the `in_n` port: unsigned, wide enough for the largest n.
pub fn n_format(config: &Config) -> Format {
    let bits = (32 - config.n.max().leading_zeros()) as i32;
    Format::unsigned(bits, 0).expect("1..=17 bits")
}

/// The formats of the per-n constant ports: (slope, offset). Plain datapaths take n with k
/// fraction bits (the value n/m) and the constant 1; minimax ones take A(n) and A(n) + B(n)
/// in their configured formats.
pub fn constant_formats(config: &Config) -> (Format, Format) {
    match config.variant {
        Variant::Plain => {
            let bits = (32 - config.n.max().leading_zeros()) as i32;
            let k = config.k as i32;
            (
                Format::unsigned(bits - k, k).expect("1..=17 bits"),
                Format::unsigned(1, 0).expect("one bit"),
            )
        }
        Variant::Minimax => (config.minimax.a_format, config.minimax.offset_format),
    }
}

/// The ports of a datapath's vector files, in the order they are written.
///
/// Inputs first: `in_c`, `in_n`, then the per-n constants a datapath reads from its ROM
/// (`in_slope`, `in_offset`, `in_threshold`, `in_coef`; every configuration has all four,
/// so one testbench serves them all), then one probe per stage before the coefficient, then
/// `expected_out`.
pub fn ports(dp: &Datapath) -> Vec<Port> {
    let cfg = dp.config();
    let (slope_format, offset_format) = constant_formats(cfg);
    let mut v = vec![
        Port::new("in_c", cfg.c.format, Source::C, "input cosine c (raw code)"),
        Port::new("in_n", n_format(cfg), Source::N, "specular exponent n"),
        Port::new(
            "in_slope",
            slope_format,
            Source::Slope,
            "slope: n with k fraction bits (plain) or A(n) (minimax)",
        ),
        Port::new(
            "in_offset",
            offset_format,
            Source::Offset,
            "offset: 1 (plain) or A(n) + B(n) (minimax)",
        ),
        Port::new(
            "in_threshold",
            cfg.c.format,
            Source::Threshold,
            "paper cutoff: inputs below this code give 0 (0 for the other cutoffs)",
        ),
        Port::new(
            "in_coef",
            cfg.coef.format,
            Source::Coef,
            "coef(n), the per-n coefficient constant",
        ),
    ];
    let coef_idx = dp.stage_coef();
    for (stage_idx, s) in dp.stages().iter().enumerate() {
        if stage_idx == coef_idx || stage_idx == dp.stage_out() {
            continue;
        }
        v.push(Port::new(
            &format!("probe_{}", s.name),
            s.format,
            Source::Stage(stage_idx),
            &format!("stage {} output", s.name),
        ));
    }
    v.push(Port::new(
        "expected_out",
        cfg.out.format,
        Source::Stage(dp.stage_out()),
        "datapath output",
    ));
    v
}

/// The CSV header: `n`, `c_raw`, one column per stage probe in pipeline order, `out_raw` last.
pub fn csv_columns(dp: &Datapath) -> Vec<String> {
    let mut cols = vec!["n".to_string(), "c_raw".to_string()];
    cols.extend(dp.stages().iter().map(|s| format!("{}_raw", s.name)));
    cols
}

/// One hexadecimal word: the raw code masked to `width` bits, `ceil(width / 4)` digits.
///
/// # Examples
/// ```
/// use specfx::golden::hex_word;
/// assert_eq!(hex_word(-1, 18), "3ffff");
/// assert_eq!(hex_word(5, 16), "0005");
/// ```
pub fn hex_word(raw: i64, width: u32) -> String {
    let mask = if width >= 64 {
        u64::MAX
    } else {
        (1u64 << width) - 1
    };
    let digits = width.div_ceil(4) as usize;
    format!("{:0digits$x}", (raw as u64) & mask)
}

/// Writes every vector: the CSV to `csv` and each port's words to `hex[i]` (in [`ports`]
/// order). `progress` is called with the number of vectors written so far.
pub fn write_vectors(
    dp: &Datapath,
    cases: &[(u32, i64)],
    csv: &mut dyn Write,
    hex: &mut [&mut dyn Write],
    progress: &mut dyn FnMut(u64),
) -> io::Result<()> {
    let ports = ports(dp);
    assert_eq!(ports.len(), hex.len(), "one writer per port");
    writeln!(csv, "{}", csv_columns(dp).join(","))?;
    let n_stages = dp.stages().len();
    let mut cols = ProbeColumns::default();
    let mut written = 0u64;
    let mut line = String::new();
    // Consecutive cases with the same n are evaluated as one batch.
    let mut start = 0;
    while start < cases.len() {
        let n = cases[start].0;
        let mut end = start;
        while end < cases.len() && cases[end].0 == n && end - start < 8192 {
            end += 1;
        }
        let nc = dp
            .constants_for(n)
            .expect("cases are drawn from the configuration's n set");
        let codes: Vec<i64> = cases[start..end].iter().map(|&(_, c)| c).collect();
        dp.eval_batch(nc, &codes, &mut cols);
        for (i, &c) in codes.iter().enumerate() {
            line.clear();
            line.push_str(&format!("{n},{c}"));
            for stage_idx in 0..n_stages {
                line.push_str(&format!(",{}", cols.values[stage_idx][i]));
            }
            writeln!(csv, "{line}")?;
            for (port, w) in ports.iter().zip(hex.iter_mut()) {
                let raw = match port.source {
                    Source::C => c,
                    Source::N => i64::from(n),
                    Source::Coef => nc.coef_raw,
                    Source::Slope => nc.slope_raw,
                    Source::Offset => nc.offset_raw,
                    Source::Threshold => nc.threshold.unwrap_or(0),
                    Source::Stage(stage_idx) => cols.values[stage_idx][i],
                };
                writeln!(w, "{}", hex_word(raw, port.width))?;
            }
        }
        written += codes.len() as u64;
        progress(written);
        start = end;
    }
    Ok(())
}

/// A writer that counts and hashes what passes through it.
pub struct HashingWriter<W: Write> {
    inner: W,
    hasher: Sha256,
}

impl<W: Write> HashingWriter<W> {
    /// Wraps a writer.
    pub fn new(inner: W) -> Self {
        HashingWriter {
            inner,
            hasher: Sha256::new(),
        }
    }

    /// The lowercase hex sha256 of everything written, and the inner writer.
    pub fn finish(self) -> (String, W) {
        let digest = self.hasher.finalize();
        let hex: String = digest.iter().map(|b| format!("{b:02x}")).collect();
        (hex, self.inner)
    }
}

impl<W: Write> Write for HashingWriter<W> {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        let n = self.inner.write(buf)?;
        self.hasher.update(&buf[..n]);
        Ok(n)
    }
    fn flush(&mut self) -> io::Result<()> {
        self.inner.flush()
    }
}

/// The CSV file's description in the manifest.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct CsvInfo {
    /// File name.
    pub file: String,
    /// Column names, in order.
    pub columns: Vec<String>,
}

/// `manifest.json`: everything needed to know what a vector directory holds.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Manifest {
    /// The specfx version that wrote it.
    pub specfx_version: String,
    /// The full configuration.
    pub config: Config,
    /// Every `$readmemh` file's port and format.
    pub ports: Vec<Port>,
    /// The CSV file.
    pub csv: CsvInfo,
    /// The case selection, as written.
    pub cases: String,
    /// The random seed.
    pub seed: u64,
    /// The number of vectors (rows of the CSV, words of each hex file).
    pub n_vectors: u64,
    /// sha256 of every other file, by name.
    pub sha256: BTreeMap<String, String>,
}
