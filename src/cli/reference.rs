//! `specfx coef` and `specfx minimax`: the reference models on the command line.

use std::path::PathBuf;

use anyhow::{bail, Context, Result};
use clap::Args;
use rayon::prelude::*;

use super::output::{print_json, print_with};
use super::Outcome;
use specfx::nset::NSet;
use specfx::output::write_atomic;
use specfx::reference::lobe::{m_of_k, K_RANGE, K_RANGE_TEXT};
use specfx::reference::minimax::{self, MinimaxFit, TABLE_N_MAX};
use specfx::reference::normalisation::{coefficient, CoefSource, Form};
use specfx::report::csv::write_minimax_table;

fn parse_k(s: &str) -> Result<u32, String> {
    match s.parse::<u32>() {
        Ok(k) if K_RANGE.contains(&k) => Ok(k),
        _ => Err(format!(
            "expected a number of squarings k in {K_RANGE_TEXT}, got '{s}'"
        )),
    }
}

/// Arguments of `specfx coef`.
#[derive(Debug, Args)]
pub struct CoefArgs {
    /// Normalisation form: phong, phong_modified, blinn_phong, blinn_phong_modified,
    /// blinn_phong_ndf, blinn_phong_heightfield.
    #[arg(long, default_value = "phong", value_parser = super::named_values(&Form::ALL, Form::name, super::no_help))]
    form: Form,
    /// Coefficient source: classic (cos^n), paper (Table 1 as printed), exact (cs_m).
    #[arg(long, default_value = "exact", value_parser = super::named_values(&CoefSource::ALL, CoefSource::name, super::no_help))]
    source: CoefSource,
    /// Exponents, e.g. 64 or 16..=1024 or 1,2,16..32.
    #[arg(long, default_value = "16,64,256,1024")]
    n: NSet,
    /// Number of squarings k (m = 2^k); used by the exact source.
    #[arg(long, default_value = "4", value_parser = parse_k)]
    k: u32,
    /// Print JSON instead of a table.
    #[arg(long)]
    json: bool,
}

#[derive(serde::Serialize)]
struct CoefRow {
    n: u32,
    coef: f64,
}

/// Runs `specfx coef`.
pub fn run_coef(args: &CoefArgs) -> Result<Outcome> {
    let rows: Vec<CoefRow> = args
        .n
        .values()
        .iter()
        .map(|&n| CoefRow {
            n,
            coef: coefficient(args.form, args.source, f64::from(n), args.k),
        })
        .collect();
    if args.json {
        #[derive(serde::Serialize)]
        struct Out<'a> {
            form: Form,
            source: CoefSource,
            k: u32,
            m: u32,
            coefficients: &'a [CoefRow],
        }
        print_json(&Out {
            form: args.form,
            source: args.source,
            k: args.k,
            m: m_of_k(args.k),
            coefficients: &rows,
        })?;
    } else {
        print_with(|buf| {
            use std::io::Write;
            writeln!(
                buf,
                "# coef(n), form {}, source {}, m = {}",
                args.form,
                args.source,
                m_of_k(args.k)
            )?;
            for r in &rows {
                writeln!(buf, "{:>6} {:.17e}", r.n, r.coef)?;
            }
            Ok(())
        })?;
    }
    Ok(Outcome::Ok)
}

/// Arguments of `specfx minimax`.
#[derive(Debug, Args)]
pub struct MinimaxArgs {
    /// Exponents to show (from the cached table, n <= 4096).
    #[arg(long, default_value = "16,64,256,1024")]
    n: NSet,
    /// Numbers of squarings to show, e.g. 4 or 1..=7.
    #[arg(long, default_value = "4", value_parser = super::datapath::parse_k_set)]
    k: NSet,
    /// Recompute the whole table (n = 1..=N_MAX, k = 1..=7) and write it to this CSV file
    /// (the library embeds data/minimax.csv).
    #[arg(long, value_name = "FILE")]
    write: Option<PathBuf>,
    /// Replace an existing --write file that is not a minimax table.
    #[arg(long)]
    force: bool,
    /// Largest n of a recomputed table.
    #[arg(long, default_value_t = TABLE_N_MAX)]
    n_max: u32,
    /// Print JSON instead of CSV.
    #[arg(long)]
    json: bool,
}

/// Runs `specfx minimax`.
pub fn run_minimax(args: &MinimaxArgs) -> Result<Outcome> {
    if let Some(path) = &args.write {
        return write_table(path, args.n_max, args.force);
    }
    if let Some(&k) = args.k.values().iter().find(|&&k| !K_RANGE.contains(&k)) {
        bail!("--k: expected numbers of squarings in {K_RANGE_TEXT}, got {k}");
    }
    let mut fits: Vec<MinimaxFit> = Vec::new();
    for &k in args.k.values() {
        for &n in args.n.values() {
            fits.push(minimax::constants(n, k).with_context(|| "--n".to_string())?);
        }
    }
    if args.json {
        print_json(&fits)?;
    } else {
        print_with(|buf| write_minimax_table(buf, &fits))?;
    }
    Ok(Outcome::Ok)
}

fn write_table(path: &std::path::Path, n_max: u32, force: bool) -> Result<Outcome> {
    if !(1..=specfx::nset::N_MAX).contains(&n_max) {
        bail!("--n-max: expected 1..={}, got {n_max}", specfx::nset::N_MAX);
    }
    // An earlier table (its first line the table's header) is replaced without --force.
    let header = format!("{}\n", specfx::reference::minimax::TABLE_HEADER);
    specfx::output::check_file_output(path, "--write", &[], Some(&header), force)?;
    let jobs: Vec<(u32, u32)> = K_RANGE
        .flat_map(|k| (1..=n_max).map(move |n| (k, n)))
        .collect();
    let bar = super::progress::Progress::new("minimax", "fits", jobs.len() as u64);
    let fits: Vec<MinimaxFit> = jobs
        .par_iter()
        .map(|&(k, n)| {
            let f = minimax::fit(n, k);
            bar.inc(1);
            f
        })
        .collect();
    bar.finish();
    let mut text = Vec::new();
    write_minimax_table(&mut text, &fits)?;
    write_atomic(path, &text)?;
    log::info!("minimax: wrote {} fits to {}", fits.len(), path.display());
    Ok(Outcome::Ok)
}
