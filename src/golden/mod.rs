//! Golden vectors: the cases and their order, their CSV and `$readmemh` renderings, what they
//! cover, and the manifest.
//!
//! Everything renders into writers; the command line decides where the files go. Files are
//! byte-for-byte deterministic for the same configuration, cases, order and seed.

pub mod cases;
pub mod switches;
pub mod ties;
pub mod verify;

use std::collections::BTreeMap;
use std::io::{self, Write};

use serde::Serialize;
use sha2::{Digest, Sha256};

use crate::csv_dialect::CsvWriter;
use crate::fixed::{Format, Rounding};
use crate::pipeline::fast::EventCounts;
use crate::pipeline::ports::PerN;
use crate::pipeline::{Config, Datapath, NConstants, ProbeColumns};

pub use cases::{CaseSelection, Directed, Order, Selection};

/// What a port carries for one vector.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Source {
    C,
    N,
    PerN(PerN),
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

/// The ports of a datapath's vector files, in the order they are written.
///
/// Inputs first: `in_c`, `in_n`, then the per-n constants a datapath reads from its ROM, one
/// port each ([`PerN`], in the order of `specfx_top`'s ports; every configuration has all of
/// them, so one testbench serves them all: the depth is k for a fixed depth), then one probe
/// per stage before the coefficient, then `expected_out`.
pub fn ports(dp: &Datapath) -> Vec<Port> {
    let cfg = dp.config();
    let mut v = vec![
        Port::new("in_c", cfg.c.format, Source::C, "input cosine c (raw code)"),
        Port::new("in_n", n_format(cfg), Source::N, "specular exponent n"),
    ];
    for p in PerN::ALL {
        v.push(Port::new(
            p.port(),
            p.format(dp),
            Source::PerN(p),
            p.description(),
        ));
    }
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

/// The vector files a testbench reads: the input ports and `expected_out`, not the probes.
pub fn testbench_ports(dp: &Datapath) -> Vec<Port> {
    ports(dp)
        .into_iter()
        .filter(|p| !matches!(p.source, Source::Stage(i) if i != dp.stage_out()))
        .collect()
}

/// One column of `vectors.csv`: a port of [`ports`], in the same order.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct CsvColumn {
    /// The port's name (`in_c`, `probe_t`, `expected_out`, ...).
    pub name: String,
    /// The value's format (`u1.15`, `s2.16`); the cells are its raw codes in decimal.
    pub format: String,
    /// Whether the raw codes are signed (two's complement, written with a minus sign).
    pub signed: bool,
    /// The format's width in bits.
    pub width: u32,
}

impl CsvColumn {
    /// The column's header cell: `<port>:<format>`, e.g. `in_c:u1.15`.
    pub fn header(&self) -> String {
        format!("{}:{}", self.name, self.format)
    }
}

/// The CSV columns: exactly the [`ports`], in the same order, so that column `j` of row `i`
/// is word `i` of the `j`-th `$readmemh` file, in decimal.
pub fn csv_columns(dp: &Datapath) -> Vec<CsvColumn> {
    ports(dp)
        .into_iter()
        .map(|p| CsvColumn {
            name: p.name,
            format: p.format,
            signed: p.signed,
            width: p.width,
        })
        .collect()
}

/// The CSV header line (without its newline): one `<port>:<format>` cell per column.
///
/// # Examples
/// ```
/// use specfx::golden::csv_header;
/// use specfx::pipeline::{Config, Datapath};
/// let dp = Datapath::new(Config::baseline()).unwrap();
/// assert!(csv_header(&dp).starts_with("in_c:u1.15,in_n:u11.0,in_slope:u7.4,"));
/// assert!(csv_header(&dp).ends_with(",probe_sq4:u1.16,expected_out:u8.16"));
/// ```
pub fn csv_header(dp: &Datapath) -> String {
    csv_columns(dp)
        .iter()
        .map(CsvColumn::header)
        .collect::<Vec<_>>()
        .join(",")
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
    let mut s = Vec::new();
    push_hex_word(&mut s, raw, width);
    String::from_utf8(s).expect("hex digits are ASCII")
}

/// Appends [`hex_word`]`(raw, width)` to `buf` (the writer's fast path: no formatter).
fn push_hex_word(buf: &mut Vec<u8>, raw: i64, width: u32) {
    const DIGITS: &[u8; 16] = b"0123456789abcdef";
    let mask = if width >= 64 {
        u64::MAX
    } else {
        (1u64 << width) - 1
    };
    let word = (raw as u64) & mask;
    let digits = width.div_ceil(4);
    for i in (0..digits).rev() {
        buf.push(DIGITS[((word >> (4 * i)) & 0xf) as usize]);
    }
}

/// Appends `v` in decimal to `buf`, as `{v}` would write it (the writer's fast path).
fn push_decimal(buf: &mut Vec<u8>, v: i64) {
    if v < 0 {
        buf.push(b'-');
    }
    let mut x = v.unsigned_abs();
    let mut tmp = [0u8; 20];
    let mut i = tmp.len();
    loop {
        i -= 1;
        tmp[i] = b'0' + (x % 10) as u8;
        x /= 10;
        if x == 0 {
            break;
        }
    }
    buf.extend_from_slice(&tmp[i..]);
}

/// Rows evaluated and written together by [`write_vectors`].
const WRITE_CHUNK: usize = 1 << 16;

/// Writes every vector, in the order of `cases`: the CSV to `csv` (through the csv crate: the
/// [`csv_header`] line, then one row of decimal raw codes per vector) and each port's words to
/// `hex[i]` (in [`ports`] order), and returns what the vectors cover. `progress` is called with the number
/// of vectors written so far.
///
/// The cases are taken in chunks of 65536; each chunk's cases are grouped by n and each group
/// is evaluated as one batch ([`Datapath::eval_batch`]), then the chunk is written in the
/// order of `cases`. So any order (sorted or interleaved) costs about the same.
///
/// # Examples
/// ```
/// use specfx::golden::{ports, write_vectors};
/// use specfx::pipeline::{Config, Datapath};
/// let dp = Datapath::new(Config::baseline()).unwrap();
/// let cases = [(100, 32768), (16, 0), (100, 0)];
/// let mut csv = Vec::new();
/// let mut hex: Vec<Vec<u8>> = vec![Vec::new(); ports(&dp).len()];
/// let mut writers: Vec<&mut dyn std::io::Write> =
///     hex.iter_mut().map(|w| w as &mut dyn std::io::Write).collect();
/// let coverage = write_vectors(&dp, &cases, &mut csv, &mut writers, &mut |_| {}).unwrap();
/// let text = String::from_utf8(csv).unwrap();
/// let rows: Vec<&str> = text.lines().skip(1).collect();
/// assert!(rows[0].starts_with("32768,100,"));
/// assert_eq!(String::from_utf8(hex[0].clone()).unwrap(), "8000\n0000\n0000\n");
/// // c = 1.0 gives the coefficient; c = 0 gives 0 for both n.
/// assert_eq!((coverage.nonzero_outputs, coverage.n_with_nonzero), (1, 1));
/// assert_eq!(coverage.n_without_nonzero, vec![16]);
/// ```
pub fn write_vectors(
    dp: &Datapath,
    cases: &[(u32, i64)],
    csv: &mut dyn Write,
    hex: &mut [&mut dyn Write],
    progress: &mut dyn FnMut(u64),
) -> io::Result<Coverage> {
    let ports = ports(dp);
    assert_eq!(ports.len(), hex.len(), "one writer per port");
    let mut csv = CsvWriter::new(csv);
    csv.record(csv_columns(dp).iter().map(CsvColumn::header))?;
    let mut coverage = CoverageCounter::new(dp);
    let n_stages = dp.stages().len();
    let mut cols = ProbeColumns::default();
    let mut written = 0u64;
    // A CSV cell's digits, and each port's words of the chunk.
    let mut cell: Vec<u8> = Vec::with_capacity(24);
    let mut hex_text: Vec<Vec<u8>> = vec![Vec::new(); ports.len()];
    // values[i * n_stages + stage_idx]: the chunk's probes, in the order of the chunk.
    let mut values: Vec<i64> = Vec::new();
    let mut cuts: Vec<bool> = Vec::new();
    let mut by_n: Vec<usize> = Vec::new();
    let mut codes: Vec<i64> = Vec::new();
    for chunk in cases.chunks(WRITE_CHUNK) {
        values.clear();
        values.resize(chunk.len() * n_stages, 0);
        cuts.clear();
        cuts.resize(chunk.len(), false);
        by_n.clear();
        by_n.extend(0..chunk.len());
        by_n.sort_by_key(|&i| chunk[i].0);
        for group in by_n.chunk_by(|&a, &b| chunk[a].0 == chunk[b].0) {
            let n = chunk[group[0]].0;
            let nc = dp
                .constants_for(n)
                .expect("cases are drawn from the configuration's n set");
            codes.clear();
            codes.extend(group.iter().map(|&i| chunk[i].1));
            dp.eval_batch(nc, &codes, &mut cols);
            coverage.add_batch(&cols);
            for (j, &i) in group.iter().enumerate() {
                for (stage_idx, col) in cols.values.iter().enumerate() {
                    values[i * n_stages + stage_idx] = col[j];
                }
                cuts[i] = cols.cut[j];
            }
        }
        for text in &mut hex_text {
            text.clear();
        }
        for (i, &(n, c)) in chunk.iter().enumerate() {
            let nc = dp
                .constants_for(n)
                .expect("cases are drawn from the configuration's n set");
            let row = &values[i * n_stages..(i + 1) * n_stages];
            coverage.add_row(nc, row, cuts[i]);
            for (port, text) in ports.iter().zip(&mut hex_text) {
                let raw = match port.source {
                    Source::C => c,
                    Source::N => i64::from(n),
                    Source::PerN(p) => p.raw(nc),
                    Source::Stage(stage_idx) => row[stage_idx],
                };
                cell.clear();
                push_decimal(&mut cell, raw);
                csv.field(&cell)?;
                push_hex_word(text, raw, port.width);
                text.push(b'\n');
            }
            csv.end_record()?;
        }
        for (text, w) in hex_text.iter().zip(hex.iter_mut()) {
            w.write_all(text)?;
        }
        written += chunk.len() as u64;
        progress(written);
    }
    csv.finish()?;
    Ok(coverage.finish())
}

/// The range of values one stage takes over a vector set, and its overflow events.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct StageCoverage {
    /// The stage's name (`d`, `t`, `b`, `sq1`..`sqk`, `coef`, `out`).
    pub stage: String,
    /// The stage's format.
    pub format: String,
    /// The smallest raw code the stage takes over the vectors (`None` without vectors).
    pub min_raw: Option<i64>,
    /// The largest raw code the stage takes over the vectors (`None` without vectors).
    pub max_raw: Option<i64>,
    /// The format's smallest raw code.
    pub format_min_raw: i64,
    /// The format's largest raw code.
    pub format_max_raw: i64,
    /// `(max_raw - min_raw + 1) / (format_max_raw - format_min_raw + 1)`: the share of the
    /// format's codes between the extremes the vectors reach (0 without vectors).
    pub range_share: f64,
    /// Vectors whose quantization at this stage wrapped (`WRAP`).
    pub wrapped: u64,
    /// Vectors whose quantization at this stage saturated (`SAT`, `SAT_SYM`).
    pub saturated: u64,
    /// Vectors whose quantization at this stage overflowed to zero (`SAT_ZERO`).
    pub zeroed: u64,
    /// The stage's rounding mode where its quantization drops fraction bits; `None` for d and
    /// coef, and for a stage whose exact value is already on its grid (or shifted left).
    pub rounding: Option<Rounding>,
    /// The fraction bits the stage's quantization drops (0 when it drops none).
    pub dropped_bits: u64,
    /// Vectors whose exact value before this stage's quantization lies on its rounding
    /// boundary: a tie (half an LSB dropped) for the round-to-nearest modes, a value on the
    /// grid for `TRN` and `TRN_ZERO` ([`ties::RoundingStage::boundary`]).
    pub at_boundary: u64,
    /// Vectors whose exact value lies one exact LSB below or above that boundary.
    pub next_to_boundary: u64,
}

/// What a vector set exercises: non-zero outputs overall and per n, each stage's range and
/// overflow events, cut and clamped inputs. Written into the manifest as `coverage`.
///
/// The overflow counts are the datapath model's own quantization events (each stage's
/// quantization reports whether it wrapped, saturated or overflowed to zero), counted per
/// vector: exact, not estimated.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Coverage {
    /// Vectors whose output (`expected_out`) is not 0.
    pub nonzero_outputs: u64,
    /// `nonzero_outputs` over the number of vectors (0 without vectors).
    pub nonzero_share: f64,
    /// The number of distinct n among the vectors.
    pub n_exponents: u64,
    /// The number of n with at least one non-zero output among the vectors.
    pub n_with_nonzero: u64,
    /// The n (ascending) whose vectors all have output 0. The case selection looks for
    /// non-zero outputs for every n ([`cases::live_codes`]; every code when exhaustive), so
    /// for these the search found none.
    pub n_without_nonzero: Vec<u32>,
    /// Vectors whose base the cutoff forced to zero.
    pub cut: u64,
    /// Vectors whose input code was above 1.0 (clamped to 1.0).
    pub input_clamped: u64,
    /// One entry per stage, in pipeline order.
    pub stages: Vec<StageCoverage>,
    /// What the selection's directed cases cover (cutoff switches, rounding-boundary
    /// inputs): [`Selection::directed`], set by whoever selected the cases ([`write_vectors`]
    /// sees only the cases and leaves it `None`); `None` for an exhaustive selection.
    pub directed: Option<Directed>,
}

impl Coverage {
    /// One line for a terminal: non-zero outputs, n with a non-zero output, overflow events.
    ///
    /// # Examples
    /// ```
    /// use specfx::golden::Coverage;
    /// let c = Coverage {
    ///     nonzero_outputs: 3,
    ///     nonzero_share: 0.75,
    ///     n_exponents: 2,
    ///     n_with_nonzero: 1,
    ///     n_without_nonzero: vec![1024],
    ///     cut: 1,
    ///     input_clamped: 0,
    ///     stages: Vec::new(),
    ///     directed: None,
    /// };
    /// assert_eq!(
    ///     c.summary(),
    ///     "coverage: 3 non-zero outputs (75.0%), 1 of 2 n with a non-zero output (none for n = 1024), 1 cut, no overflow events"
    /// );
    /// ```
    pub fn summary(&self) -> String {
        let mut s = format!(
            "coverage: {} non-zero outputs ({:.1}%), {} of {} n with a non-zero output",
            self.nonzero_outputs,
            100.0 * self.nonzero_share,
            self.n_with_nonzero,
            self.n_exponents
        );
        if !self.n_without_nonzero.is_empty() {
            let shown: Vec<String> = self
                .n_without_nonzero
                .iter()
                .take(8)
                .map(u32::to_string)
                .collect();
            let more = if self.n_without_nonzero.len() > 8 {
                format!(", ... {} in all", self.n_without_nonzero.len())
            } else {
                String::new()
            };
            s.push_str(&format!(" (none for n = {}{more})", shown.join(", ")));
        }
        s.push_str(&format!(", {} cut", self.cut));
        let boundaries: Vec<String> = self
            .stages
            .iter()
            .filter(|st| st.dropped_bits > 0)
            .map(|st| format!("{} {}/{}", st.stage, st.at_boundary, st.next_to_boundary))
            .collect();
        if !boundaries.is_empty() {
            s.push_str(&format!(
                ", rounding boundaries (on/next to): {}",
                boundaries.join(", ")
            ));
        }
        let events: Vec<String> = self
            .stages
            .iter()
            .flat_map(|st| {
                [
                    (st.wrapped, "wrapped"),
                    (st.saturated, "saturated"),
                    (st.zeroed, "zeroed"),
                ]
                .into_iter()
                .filter(|&(count, _)| count > 0)
                .map(move |(count, what)| format!("{} {count} {what}", st.stage))
            })
            .collect();
        if events.is_empty() {
            s.push_str(", no overflow events");
        } else {
            s.push_str(&format!(", overflow events: {}", events.join(", ")));
        }
        s
    }
}

/// Accumulates a [`Coverage`] over the batches and rows [`write_vectors`] writes.
struct CoverageCounter<'a> {
    dp: &'a Datapath,
    n_rows: u64,
    nonzero: u64,
    /// Per n of the set: 0 not seen, 1 seen with outputs 0 only, 2 seen with a non-zero output.
    n_state: Vec<u8>,
    cut: u64,
    input_clamped: u64,
    min: Vec<i64>,
    max: Vec<i64>,
    events: Vec<EventCounts>,
    /// The stages that drop bits, and per stage index: vectors on and next to its boundary.
    rounding: Vec<ties::RoundingStage>,
    boundary: Vec<[u64; 2]>,
}

impl<'a> CoverageCounter<'a> {
    fn new(dp: &'a Datapath) -> Self {
        let n_stages = dp.stages().len();
        CoverageCounter {
            dp,
            n_rows: 0,
            nonzero: 0,
            n_state: vec![0; dp.config().n.values().len()],
            cut: 0,
            input_clamped: 0,
            min: vec![i64::MAX; n_stages],
            max: vec![i64::MIN; n_stages],
            events: vec![[0; 3]; n_stages],
            rounding: ties::rounding_stages(dp),
            boundary: vec![[0; 2]; n_stages],
        }
    }

    /// Counts a batch's events and flags (each case is evaluated in exactly one batch).
    fn add_batch(&mut self, cols: &ProbeColumns) {
        for (total, batch) in self.events.iter_mut().zip(&cols.event_counts) {
            for (t, b) in total.iter_mut().zip(batch) {
                *t += b;
            }
        }
        self.cut += cols.cut.iter().filter(|&&c| c).count() as u64;
        self.input_clamped += cols.input_clamped.iter().filter(|&&c| c).count() as u64;
    }

    /// Counts one row's values (`cut`: the row's base was cut).
    fn add_row(&mut self, nc: &NConstants, row: &[i64], cut: bool) {
        let n = nc.n;
        for st in &self.rounding {
            let x = ties::exact_input(self.dp, nc, st.stage_idx, |s| row[s], cut);
            if let Some(b) = st.boundary(x) {
                self.boundary[st.stage_idx][usize::from(b.offset != 0)] += 1;
            }
        }
        self.n_rows += 1;
        for ((lo, hi), &v) in self.min.iter_mut().zip(self.max.iter_mut()).zip(row) {
            *lo = (*lo).min(v);
            *hi = (*hi).max(v);
        }
        let live = row[self.dp.stage_out()] != 0;
        self.nonzero += u64::from(live);
        let idx = self
            .dp
            .config()
            .n
            .values()
            .binary_search(&n)
            .expect("cases are drawn from the configuration's n set");
        self.n_state[idx] = self.n_state[idx].max(1 + u8::from(live));
    }

    fn finish(self) -> Coverage {
        let ns = self.dp.config().n.values();
        let seen = self.n_rows > 0;
        let stages = self
            .dp
            .stages()
            .iter()
            .enumerate()
            .map(|(stage_idx, s)| {
                let (lo, hi) = (self.min[stage_idx], self.max[stage_idx]);
                let (fmin, fmax) = (s.format.min_raw(), s.format.max_raw());
                let share = if seen {
                    (i128::from(hi) - i128::from(lo) + 1) as f64
                        / (i128::from(fmax) - i128::from(fmin) + 1) as f64
                } else {
                    0.0
                };
                let [wrapped, saturated, zeroed] = self.events[stage_idx];
                let [at_boundary, next_to_boundary] = self.boundary[stage_idx];
                let rounding = self.rounding.iter().find(|r| r.stage_idx == stage_idx);
                StageCoverage {
                    stage: s.name.clone(),
                    format: s.format.to_string(),
                    min_raw: seen.then_some(lo),
                    max_raw: seen.then_some(hi),
                    format_min_raw: fmin,
                    format_max_raw: fmax,
                    range_share: share,
                    wrapped,
                    saturated,
                    zeroed,
                    rounding: rounding.map(|r| r.rounding),
                    dropped_bits: rounding.map_or(0, |r| r.dropped_bits.unsigned_abs()),
                    at_boundary,
                    next_to_boundary,
                }
            })
            .collect();
        Coverage {
            nonzero_outputs: self.nonzero,
            nonzero_share: if seen {
                self.nonzero as f64 / self.n_rows as f64
            } else {
                0.0
            },
            n_exponents: self.n_state.iter().filter(|&&s| s > 0).count() as u64,
            n_with_nonzero: self.n_state.iter().filter(|&&s| s == 2).count() as u64,
            n_without_nonzero: ns
                .iter()
                .zip(&self.n_state)
                .filter(|&(_, &s)| s == 1)
                .map(|(&n, _)| n)
                .collect(),
            cut: self.cut,
            input_clamped: self.input_clamped,
            stages,
            directed: None,
        }
    }
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
    /// The columns, in order: the ports, each with its format; the header cell of a column
    /// is [`CsvColumn::header`].
    pub columns: Vec<CsvColumn>,
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
    /// The order of the vectors.
    pub order: Order,
    /// The random seed (of the random cases, and of the interleaving permutation).
    pub seed: u64,
    /// The number of vectors (rows of the CSV after its header, words of each hex file).
    pub n_vectors: u64,
    /// What the vectors exercise.
    pub coverage: Coverage,
    /// sha256 of every other file, by name.
    pub sha256: BTreeMap<String, String>,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn decimal_and_hex_words_match_the_formatter() {
        let values = [
            0,
            1,
            -1,
            9,
            10,
            -10,
            99_999,
            i64::MIN,
            i64::MAX,
            -(1 << 17),
            (1 << 17) - 1,
        ];
        for v in values {
            let mut buf = Vec::new();
            push_decimal(&mut buf, v);
            assert_eq!(String::from_utf8(buf).unwrap(), format!("{v}"));
            for width in [1u32, 4, 5, 16, 18, 63, 64] {
                let mask = if width == 64 {
                    u64::MAX
                } else {
                    (1u64 << width) - 1
                };
                let want = format!("{:0w$x}", (v as u64) & mask, w = width.div_ceil(4) as usize);
                assert_eq!(hex_word(v, width), want, "{v} in {width} bits");
            }
        }
    }

    #[test]
    fn hex_words_at_the_edges() {
        // Hand-written: the most negative s2.16 code, -1 in one bit, the widest code.
        assert_eq!(hex_word(-(1 << 17), 18), "20000");
        assert_eq!(hex_word(-1, 1), "1");
        assert_eq!(hex_word(i64::MIN, 64), "8000000000000000");
        assert_eq!(hex_word(0, 17), "00000");
    }
}
