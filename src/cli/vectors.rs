//! `specfx vectors`: golden vectors for a testbench (CSV, `$readmemh` files, manifest).

use std::collections::BTreeMap;
use std::fs::{self, File};
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use clap::Args;

use super::Outcome;
use specfx::golden::{
    cases, csv_columns, ports, write_vectors, CaseSelection, Coverage, CsvInfo, HashingWriter,
    Manifest, Order,
};
use specfx::nset::NSet;
use specfx::pipeline::Datapath;
use specfx::provenance::{sha256_hex, Inputs, Provenance, INPUTS_FILE, PROVENANCE_FILE};

/// Arguments of `specfx vectors`.
#[derive(Debug, Args)]
pub struct VectorsArgs {
    /// A TOML configuration file, or a built-in name: baseline.
    #[arg(long, default_value = "baseline")]
    config: String,
    /// The directory to write. It is written completely or not at all, and replaces only an
    /// earlier vector directory (or an empty one) unless --force; never the configuration.
    #[arg(long)]
    out: PathBuf,
    /// Exponents, replacing the configuration's set.
    #[arg(long)]
    n: Option<NSet>,
    /// Which cases: corner, exhaustive, random:N, comma-separated. Unless exhaustive, the
    /// directed cases are always included: corner cases (ends of the code range, 0, 1.0 and
    /// above, every cutoff switch +-1 code), up to 4 codes with a non-zero output per n, and
    /// inputs on and next to every stage's rounding boundary (ties; at most 8 per stage and
    /// class, searched over every code up to 1.0 where at most 2^25 codes lie there over all
    /// n, the highest codes below 1.0 otherwise). The manifest's coverage.directed says what
    /// they cover.
    #[arg(long, default_value = "corner,random:1000")]
    cases: CaseSelection,
    /// Seed of the random cases and of the interleaved order.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Row order: interleaved (a seeded random permutation, so n changes on most rows) or
    /// sorted (by n, then c).
    #[arg(long, default_value = "interleaved", value_parser = super::named_values(&Order::ALL, Order::name, super::no_help))]
    order: Order,
    /// Replace an existing directory that is not an earlier vector directory.
    #[arg(long)]
    force: bool,
}

/// Runs `specfx vectors`.
pub fn run(args: &VectorsArgs) -> Result<Outcome> {
    let dp = specfx::input::load_datapath(&args.config, args.n.as_ref())?;
    let (cases, coverage) = write_dir(
        &dp,
        &args.out,
        &args.cases,
        args.order,
        args.seed,
        args.force,
        &super::output::config_inputs_as("--config", &args.config),
    )?;
    let n = cases.len();
    super::output::outln!(
        "wrote {n} vectors ({}, {} order, seed {}) to {}",
        args.cases,
        args.order,
        args.seed,
        args.out.display()
    )?;
    super::output::outln!("{}", coverage.summary())?;
    Ok(Outcome::Ok)
}

/// Writes a vector directory, staged ([`specfx::output::OutDir`]): complete or absent, an
/// existing directory replaced only when it is an earlier vector directory (or empty, or with
/// `force`), never one of `inputs`. Returns the vectors' inputs, (n, raw code of c) in file
/// order, and their coverage.
pub fn write_dir(
    dp: &Datapath,
    out: &Path,
    selection: &CaseSelection,
    order: Order,
    seed: u64,
    force: bool,
    inputs: &[(&str, PathBuf)],
) -> Result<(Vec<(u32, i64)>, Coverage)> {
    let chosen = cases::select(dp, selection, seed)
        .with_context(|| format!("config {}", dp.config().name))?;
    let mut cases = chosen.cases;
    cases::order(&mut cases, order, seed);
    let staged = specfx::output::OutDir::begin(out, "vectors", force, inputs)?;
    let partial = staged.path().to_path_buf();

    let ports = ports(dp);
    let open = |name: &str| -> Result<HashingWriter<BufWriter<File>>> {
        let path = partial.join(name);
        let f = File::create(&path).with_context(|| format!("cannot create {}", path.display()))?;
        Ok(HashingWriter::new(BufWriter::new(f)))
    };
    let mut csv = open("vectors.csv")?;
    let mut hex: Vec<HashingWriter<BufWriter<File>>> = ports
        .iter()
        .map(|p| open(&p.file_name()))
        .collect::<Result<_>>()?;
    // A few hundred thousand vectors take a moment; fewer are not worth a line.
    let bar = if cases.len() > 200_000 {
        super::progress::Progress::new("vectors", "vectors", cases.len() as u64)
    } else {
        super::progress::Progress::off("vectors", "vectors", cases.len() as u64)
    };
    let mut coverage = {
        let mut writers: Vec<&mut dyn Write> =
            hex.iter_mut().map(|w| w as &mut dyn Write).collect();
        let mut progress = |done: u64| bar.set_position(done);
        write_vectors(dp, &cases, &mut csv, &mut writers, &mut progress)
            .with_context(|| format!("cannot write vectors to {}", partial.display()))?
    };
    coverage.directed = chosen.directed;
    bar.finish();
    let mut sha256 = BTreeMap::new();
    let (digest, mut w) = csv.finish();
    w.flush()?;
    sha256.insert("vectors.csv".to_string(), digest);
    for (port, writer) in ports.iter().zip(hex) {
        let (digest, mut w) = writer.finish();
        w.flush()?;
        sha256.insert(port.file_name(), digest);
    }
    // What determined the vectors (corner cases are always included, named or not).
    let canonical_cases = CaseSelection {
        corner: true,
        ..*selection
    };
    let provenance = Provenance::new(
        &Inputs::new("vectors")
            .config(dp.config())
            .option("cases", canonical_cases.to_string())
            .option("order", order.to_string())
            .option("seed", seed.to_string()),
    );
    super::output::write_provenance(&partial, &provenance)?;
    for (name, text) in [
        (INPUTS_FILE, provenance.canonical.clone()),
        (PROVENANCE_FILE, provenance.json()),
    ] {
        sha256.insert(name.to_string(), sha256_hex(text.as_bytes()));
    }
    let manifest = Manifest {
        specfx_version: env!("CARGO_PKG_VERSION").to_string(),
        config: dp.config().clone(),
        ports,
        csv: CsvInfo {
            file: "vectors.csv".to_string(),
            columns: csv_columns(dp),
        },
        cases: selection.to_string(),
        order,
        seed,
        n_vectors: cases.len() as u64,
        coverage: coverage.clone(),
        sha256,
    };
    let mut json = serde_json::to_vec_pretty(&manifest)?;
    json.push(b'\n');
    fs::write(partial.join("manifest.json"), json)
        .with_context(|| format!("cannot write {}", partial.join("manifest.json").display()))?;
    staged.commit()?;
    log::debug!(
        "vectors: wrote {} (vectors.csv, {} $readmemh files, manifest.json)",
        out.display(),
        manifest.ports.len()
    );
    Ok((cases, coverage))
}
