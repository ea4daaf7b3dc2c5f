//! `specfx trace compare`: compares the model's VCD trace with a Verilog simulator's dump of the
//! co-simulation testbench, signal by signal and cycle by cycle.

use std::fs::File;
use std::io::{BufReader, Write};
use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use clap::{Args, Subcommand};

use super::output::print_with;
use super::Outcome;
use specfx::cycle::compare::{compare_with, Comparison, Missing, Options};
use specfx::error::Error;

/// Arguments of `specfx trace`.
#[derive(Debug, Args)]
pub struct TraceArgs {
    #[command(subcommand)]
    command: TraceCommand,
}

#[derive(Debug, Subcommand)]
enum TraceCommand {
    /// Compares two VCD traces of the testbench: the model's first (its `x` bits are
    /// don't-care), then the RTL's. A signal of the first file that the second lacks, or a
    /// register (`$var reg`) of the second file in a scope where the first file has signals
    /// (below tb_specfx) that the first lacks, is a difference unless --ignore-missing.
    /// Exit code 0 when they agree, 1 when they differ, 2 on bad input.
    Compare(CompareArgs),
}

#[derive(Debug, Args)]
struct CompareArgs {
    /// The model's trace (`specfx hdl stimulus --vcd`, `specfx sim --vcd`): where it has `x`
    /// or `z`, any value of the second file is accepted.
    first: PathBuf,
    /// The RTL's trace (the testbench's `rtl.vcd`, Icarus Verilog or Verilator).
    second: PathBuf,
    /// Accept signals in one file only: list them, but do not count them as a difference.
    /// Without it, a signal of the first file that the second lacks makes the traces differ
    /// (it was never compared), and so does a register of the second file in a scope the
    /// first file has signals in (below tb_specfx) that the first lacks.
    #[arg(long)]
    ignore_missing: bool,
    /// Leave a signal out altogether, neither compared nor missing: its full name as the
    /// comparison prints it (tb_specfx.dut.g_folded.u_core.x), or a prefix followed by `*`
    /// (tb_specfx.extra.*). Repeat for more; each must match a signal of either file.
    #[arg(long, value_name = "NAME")]
    ignore: Vec<String>,
}

/// How many names a list of signals shows before "and N more".
const SHOWN: usize = 10;

/// Runs `specfx trace ...`.
pub fn run(args: &TraceArgs) -> Result<Outcome> {
    match &args.command {
        TraceCommand::Compare(a) => run_compare(a),
    }
}

fn run_compare(args: &CompareArgs) -> Result<Outcome> {
    let options = Options {
        missing: if args.ignore_missing {
            Missing::Ignore
        } else {
            Missing::Differ
        },
        ignore: args.ignore.clone(),
    };
    let c = compare_files(&args.first, &args.second, &options)?;
    Ok(if c.agrees() {
        Outcome::Ok
    } else {
        Outcome::CheckFailed
    })
}

/// Compares two trace files (the model's first) and prints the comparison; an error naming
/// the file when one cannot be read.
pub fn compare_files(first: &Path, second: &Path, options: &Options) -> Result<Comparison> {
    let paths = [first, second];
    let open = |p: &Path| -> Result<BufReader<File>> {
        let what = format!("trace {}", p.display());
        specfx::input::check_regular_file(p, &what)?;
        Ok(BufReader::new(
            File::open(p).with_context(|| format!("{what}: cannot open it"))?,
        ))
    };
    let (a, b) = (open(first)?, open(second)?);
    let c = match compare_with(a, b, options) {
        Ok(c) => c,
        Err(Error::Trace { which, problem }) => {
            anyhow::bail!("{}: {problem}", paths[which].display())
        }
        Err(e) => return Err(e.into()),
    };
    let names = [first.display().to_string(), second.display().to_string()];
    print_with(|w| write_comparison(w, &c, &names))?;
    Ok(c)
}

fn list(names: &[String]) -> String {
    let mut s = names
        .iter()
        .take(SHOWN)
        .cloned()
        .collect::<Vec<_>>()
        .join(", ");
    if names.len() > SHOWN {
        s.push_str(&format!(" and {} more", names.len() - SHOWN));
    }
    s
}

fn write_comparison(
    w: &mut impl Write,
    c: &Comparison,
    files: &[String; 2],
) -> std::io::Result<()> {
    for m in &c.width_mismatches {
        writeln!(
            w,
            "width differs: {} is {} bits in {}, {} bits in {}",
            m.signal, m.first, files[0], m.second, files[1]
        )?;
    }
    if let Some(d) = &c.first_difference {
        writeln!(
            w,
            "first difference: cycle {}, {} = {} in {}, {} in {}",
            d.cycle, d.signal, d.first, files[0], d.second, files[1]
        )?;
        if !d.also.is_empty() {
            writeln!(
                w,
                "  also differing at cycle {}: {}",
                d.cycle,
                list(&d.also)
            )?;
        }
    }
    writeln!(
        w,
        "compared {} signals over {} cycles; {} signals only in {}, {} only in {}; {} width mismatches; {} signals differ",
        c.signals_compared,
        c.cycles_compared,
        c.only_first.len(),
        files[0],
        c.only_second.len(),
        files[1],
        c.width_mismatches.len(),
        c.signals_differing
    )?;
    if !c.only_first.is_empty() {
        writeln!(w, "  only in {}: {}", files[0], list(&c.only_first))?;
    }
    if !c.registers_only_second.is_empty() {
        writeln!(
            w,
            "  {} registers only in {}, in scopes {} has signals in: {}",
            c.registers_only_second.len(),
            files[1],
            files[0],
            list(&c.registers_only_second)
        )?;
    }
    let unchecked = c.only_second.len() - c.registers_only_second.len();
    if unchecked > 0 {
        let other = if c.registers_only_second.is_empty() {
            ""
        } else {
            "other "
        };
        writeln!(
            w,
            "  the {other}{unchecked} only in {} are wires, or registers in scopes {} has no signal in: internal to the RTL, not a difference",
            files[1], files[0]
        )?;
    }
    if !c.ignored.is_empty() {
        writeln!(
            w,
            "  {} signals ignored (--ignore): {}",
            c.ignored.len(),
            list(&c.ignored)
        )?;
    }
    if !c.never_known.is_empty() {
        writeln!(
            w,
            "  {} signals never known in {} (x at every cycle, so not checked): {}",
            c.never_known.len(),
            files[0],
            list(&c.never_known)
        )?;
    }
    if c.cycles_only_first + c.cycles_only_second > 0 {
        writeln!(
            w,
            "  cycles sampled only in {}: {}, only in {}: {}",
            files[0], c.cycles_only_first, files[1], c.cycles_only_second
        )?;
    }
    let missing = c.missing_signals();
    if missing > 0 && c.missing == Missing::Ignore {
        writeln!(
            w,
            "  {missing} signals missing from one file, accepted (--ignore-missing)"
        )?;
    }
    let verdict = if c.agrees() {
        "traces agree".to_string()
    } else if c.signals_compared == 0 || c.cycles_compared == 0 {
        "TRACES DIFFER: nothing to compare".to_string()
    } else if c.first_difference.is_none() && c.width_mismatches.is_empty() {
        format!(
            "TRACES DIFFER: {missing} signals missing from one file (--ignore-missing accepts them)"
        )
    } else {
        "TRACES DIFFER".to_string()
    };
    writeln!(w, "{verdict}")
}
