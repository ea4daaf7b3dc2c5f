//! `specfx throughput`: how fast the batch engine computes a datapath's outputs over every
//! code and n, with a checksum other models (`scripts/bench-peers`) compare against.

use std::time::Instant;

use anyhow::{Context, Result};
use clap::Args;
use serde::Serialize;

use super::output::{print_json, print_with};
use super::Outcome;
use specfx::engine::output_sum;
use specfx::nset::NSet;

/// Arguments of `specfx throughput`.
#[derive(Debug, Args)]
pub struct ThroughputArgs {
    /// A TOML configuration file, or a built-in name: baseline.
    #[arg(long, default_value = "baseline")]
    config: String,
    /// Exponents, replacing the configuration's set (e.g. 16..=1024).
    #[arg(long)]
    n: Option<NSet>,
    /// Worker threads (default: one per core).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=1024))]
    threads: Option<u32>,
    /// Times the run is repeated; the fastest is reported.
    #[arg(long, default_value_t = 3, value_parser = clap::value_parser!(u32).range(1..=100))]
    repeat: u32,
    /// Print one JSON object instead of text.
    #[arg(long)]
    json: bool,
}

#[derive(Debug, Serialize)]
struct Measured {
    config: String,
    n_set: String,
    evaluations: u64,
    seconds: f64,
    evals_per_s: f64,
    checksum: String,
    threads: usize,
}

/// Runs `specfx throughput`.
pub fn run(args: &ThroughputArgs) -> Result<Outcome> {
    let dp = specfx::input::load_datapath(&args.config, args.n.as_ref())?;
    let mut pool = rayon::ThreadPoolBuilder::new();
    if let Some(t) = args.threads {
        pool = pool.num_threads(t as usize);
    }
    let pool = pool.build().context("cannot start the worker threads")?;
    let codes = 0..dp.one_code() + 1;
    let mut best = f64::INFINITY;
    let mut sum = None;
    for _ in 0..args.repeat {
        let start = Instant::now();
        let s = pool.install(|| output_sum(&dp, codes.clone()));
        best = best.min(start.elapsed().as_secs_f64());
        sum = Some(s);
    }
    let sum = sum.expect("at least one run");
    let m = Measured {
        config: dp.config().name.clone(),
        n_set: dp.config().n.to_string(),
        evaluations: sum.evaluations,
        seconds: best,
        evals_per_s: sum.evaluations as f64 / best,
        checksum: sum.checksum.to_string(),
        threads: pool.current_num_threads(),
    };
    if args.json {
        print_json(&m)?;
    } else {
        print_with(|buf| {
            use std::io::Write;
            writeln!(
                buf,
                "throughput {}: n = {} x codes 0..={} = {} evaluations of the output",
                m.config,
                m.n_set,
                dp.one_code(),
                m.evaluations
            )?;
            writeln!(
                buf,
                "  {:.4} s on {} threads (best of {}): {:.1} million evaluations/s",
                m.seconds,
                m.threads,
                args.repeat,
                m.evals_per_s / 1e6
            )?;
            writeln!(
                buf,
                "  checksum (wrapping sum of out_raw * (c_raw + 1) * n): {}",
                m.checksum
            )
        })?;
    }
    Ok(Outcome::Ok)
}
