//! Command-line front end: clap definitions, dispatch, exit codes and file output.
//!
//! Exit codes: 0 success, 1 the command ran but a check it performs failed, 2 bad input or an
//! I/O error (one line on stderr). A closed stdout (broken pipe) is not an error.

pub mod budget;
mod calibrate;
mod check;
mod cosim;
mod cosim_dpi;
pub mod cost;
mod datapath;
pub mod fit;
pub mod furnace;
mod hdl;
mod hdl_ref;
mod logging;
mod optimize;
mod output;
mod paper;
mod pnr;
mod progress;
mod reference;
pub mod render;
mod report;
mod resume;
mod sim;
pub mod stability;
mod sweep;
mod terminal;
mod throughput;
mod trace;
pub mod tradeoff;
pub mod vectors;

use std::process::ExitCode;

use clap::{Parser, Subcommand};

/// Models a division-free fixed-point specular datapath bit for bit against an f64 reference.
#[derive(Debug, Parser)]
#[command(name = "specfx", version, about, long_about = None)]
struct Cli {
    #[command(subcommand)]
    command: Command,
    /// Print only results, warnings and errors: no progress, no informational lines.
    #[arg(short, long, global = true, conflicts_with = "verbose")]
    quiet: bool,
    /// Print details on stderr: files read and written, how long each step took.
    #[arg(short, long, global = true, action = clap::ArgAction::Count)]
    verbose: u8,
    /// Colour in help and messages: auto (on a terminal, unless NO_COLOR is set), always or
    /// never.
    #[arg(long, global = true, value_name = "WHEN", default_value = "auto")]
    color: clap::ColorChoice,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Runs the main job on built-in defaults and writes everything under ./specfx-out/.
    Report(report::ReportArgs),
    /// Reproduces every number the paper prints and says which ones hold.
    Paper(paper::PaperArgs),
    /// Checks a datapath exhaustively against f64: every input code, every n.
    Check(check::CheckArgs),
    /// Prints the normalisation coefficient coef(n) of a form.
    Coef(reference::CoefArgs),
    /// Simulates the cycle-level model under random bubbles and stalls.
    Sim(sim::SimArgs),
    /// Reference Verilog helpers: parameter headers and co-simulation stimulus.
    Hdl(hdl::HdlArgs),
    /// Co-simulates the reference Verilog against golden vectors and the cycle model's output
    /// cycles, in Icarus Verilog or Verilator (bit and cycle exact, under bubbles and stalls).
    Cosim(cosim::CosimArgs),
    /// VCD traces: compares the model's trace with the RTL's, signal by signal.
    Trace(trace::TraceArgs),
    /// Synthesis cost of a configuration: yosys on the reference Verilog, and the analytic model.
    Cost(cost::CostArgs),
    /// Calibrates the analytic cost model against yosys: a seeded sample synthesised, the
    /// model's coefficients fitted, the fit error printed.
    Calibrate(calibrate::CalibrateArgs),
    /// Place and route on iCE40 (yosys, nextpnr): Fmax, critical path, utilisation, latency
    /// and throughput at Fmax; a design too big for the device is flagged (exit code 1).
    Timing(pnr::TimingArgs),
    /// Evaluates a design space: every point checked exhaustively and costed; Pareto front.
    Sweep(sweep::SweepArgs),
    /// Error-budget report: per-stage attribution, headroom, histograms, gappa bounds.
    Budget(budget::BudgetArgs),
    /// Finds the cheapest configuration that meets an error budget, proved by a check.
    Optimize(optimize::OptimizeArgs),
    /// Maps where every method and datapath fails over n and theta: heat maps and regions.
    Stability(stability::StabilityArgs),
    /// Charts speed against accuracy for every method (f64 models and fixed-point datapaths).
    Tradeoff(tradeoff::TradeoffArgs),
    /// Renders a scene through the datapath beside f64 references: images, error maps, table.
    Render(render::RenderArgs),
    /// Fits the cheapest datapath to a scene: only its exponents, input range and output
    /// depth, within an image-space budget proved on every input the scene produces.
    Fit(fit::FitArgs),
    /// White-furnace check of every normalised form: reflectance against incident angle.
    Furnace(furnace::FurnaceArgs),
    /// Writes golden vectors: CSV, $readmemh files and a manifest.
    Vectors(vectors::VectorsArgs),
    /// Shows the cached minimax constants A(n), B(n), or recomputes the table.
    Minimax(reference::MinimaxArgs),
    /// Measures how fast the engine computes a datapath's outputs, with a checksum.
    Throughput(throughput::ThroughputArgs),
    /// Prints a shell completion script (bash, zsh, fish, elvish, powershell).
    Completions(CompletionsArgs),
    /// Prints the man page (roff) generated from the command-line definition, or writes one
    /// page per command into a directory.
    Man(ManArgs),
}

/// An example per command, shown at the end of its `--help` (and in the man pages).
const EXAMPLES: &[(&str, &str)] = &[
    ("report", "specfx report --out specfx-out"),
    ("paper", "specfx paper --json > paper.json"),
    ("check", "specfx check --config my.toml --n 16..1024"),
    (
        "coef",
        "specfx coef --form blinn_phong --source exact --n 16,64,256",
    ),
    (
        "sim",
        "specfx sim --config baseline --arch folded --cycles 5000 --vcd sim.vcd",
    ),
    ("hdl", "specfx hdl params --config my.toml --format json"),
    (
        "hdl params",
        "specfx hdl params --config my.toml --format define --out specfx_params.vh",
    ),
    (
        "hdl rom",
        "specfx hdl rom --config fit-out/fitted.toml --out specfx_rom.v",
    ),
    (
        "hdl stimulus",
        "specfx hdl stimulus --vectors vec --arch folded --bubble 0.3 --stall 0.1 --out stim",
    ),
    (
        "cosim",
        "specfx cosim --config my.toml --sim verilator --arch folded --lint",
    ),
    (
        "trace",
        "specfx trace compare traces/model.vcd traces/rtl.vcd",
    ),
    (
        "trace compare",
        "specfx trace compare model.vcd build/tb_specfx.vcd",
    ),
    (
        "cost",
        "specfx cost --config my.toml --target ice40 --timing",
    ),
    ("calibrate", "specfx calibrate --targets ice40 --fit-only"),
    (
        "calibrate merge",
        "specfx calibrate merge --data cal-all cal/shard-0 cal/shard-1",
    ),
    ("timing", "specfx timing --config my.toml --device up5k"),
    (
        "sweep",
        "specfx sweep --space space.toml --out sweep-out --shard 1/4",
    ),
    (
        "sweep merge",
        "specfx sweep merge --out sweep-all sweep-1 sweep-2 sweep-3 sweep-4",
    ),
    (
        "sweep plan",
        "specfx sweep plan --space space.toml --tasks 32 --emit slurm --out plan",
    ),
    (
        "budget",
        "specfx budget --config my.toml --budget 'shape_total <= 1 lsb8' --out budget-out",
    ),
    (
        "optimize",
        "specfx optimize --budget 'out_rel <= 1%, dsps <= 8 on ice40' --out best.toml",
    ),
    (
        "stability",
        "specfx stability --config my.toml --out stability-out",
    ),
    (
        "tradeoff",
        "specfx tradeoff --n 16..=1024 --out tradeoff-out --yosys ice40",
    ),
    (
        "render",
        "specfx render --scene examples/scenes/vessel_bifurcation.toml --config my.toml --out render-out",
    ),
    (
        "fit",
        "specfx fit --scene examples/scenes/vessel_bifurcation.toml --budget 'max_lsb <= 4' --out fit-out",
    ),
    ("furnace", "specfx furnace --out furnace-out"),
    (
        "vectors",
        "specfx vectors --config my.toml --cases corner,random:10000 --out vec",
    ),
    ("minimax", "specfx minimax --n 16,64,256 --k 4"),
    (
        "throughput",
        "specfx throughput --config baseline --threads 2",
    ),
    (
        "completions",
        "specfx completions bash > ~/.local/share/bash-completion/completions/specfx",
    ),
    ("man", "specfx man --out man/ && man -l man/specfx-cosim.1"),
];

/// The widest help line: the terminal's width up to this, and this off a terminal.
const HELP_WIDTH: usize = 100;

/// The command-line definition, with each command's example and the exit codes.
fn command() -> clap::Command {
    use clap::CommandFactory;
    let mut cmd = Cli::command()
        .after_help(
            "Exit codes: 0 success; 1 the command ran but a check it performs failed; 2 bad input \
             or an I/O error (one line on stderr, nothing written).",
        )
        // Help wrapped to the terminal's width, at most 100 columns (100 off a terminal).
        .max_term_width(HELP_WIDTH);
    cmd = negative_values(cmd);
    for (name, example) in EXAMPLES {
        let help = format!("Example:\n  {example}");
        cmd = match name.split_once(' ') {
            Some((parent, sub)) => {
                cmd.mut_subcommand(parent, |c| c.mut_subcommand(sub, |c| c.after_help(help)))
            }
            None => cmd.mut_subcommand(*name, |c| c.after_help(help)),
        };
    }
    cmd
}

/// Lets every option of `cmd` and its commands take a negative number (`--tol -1`), so that
/// the option's own check says what is wrong with it instead of clap's "unexpected argument".
fn negative_values(mut cmd: clap::Command) -> clap::Command {
    let ids: Vec<clap::Id> = cmd
        .get_arguments()
        .filter(|a| a.get_action().takes_values())
        .map(|a| a.get_id().clone())
        .collect();
    for id in ids {
        cmd = cmd.mut_arg(id, |a| a.allow_negative_numbers(true));
    }
    let subs: Vec<String> = cmd
        .get_subcommands()
        .map(|c| c.get_name().to_string())
        .collect();
    for sub in subs {
        cmd = cmd.mut_subcommand(sub, negative_values);
    }
    cmd
}

/// Arguments of `specfx completions`.
#[derive(Debug, clap::Args)]
pub struct CompletionsArgs {
    /// The shell.
    shell: clap_complete::Shell,
}

/// Arguments of `specfx man`.
#[derive(Debug, clap::Args)]
pub struct ManArgs {
    /// Write specfx.1 and specfx-<command>.1 for every command into this directory instead of
    /// printing specfx.1.
    #[arg(long)]
    out: Option<std::path::PathBuf>,
    /// Replace files of the same names that are not specfx manual pages.
    #[arg(long)]
    force: bool,
}

/// The first bytes of every manual page of specfx (clap_mangen's preamble, then the title).
const MAN_HEADER: &str = ".ie \\n(.g .ds Aq \\(aq\n.el .ds Aq '\n.TH specfx";

fn completions(args: &CompletionsArgs) -> anyhow::Result<Outcome> {
    let mut cmd = command();
    let mut buf = Vec::new();
    clap_complete::generate(args.shell, &mut cmd, "specfx", &mut buf);
    output::print_with(|w| {
        use std::io::Write;
        w.write_all(&buf)
    })?;
    Ok(Outcome::Ok)
}

/// No help for a value of [`named_values`]: `--help` lists the names alone.
fn no_help<T>(_: T) -> &'static str {
    ""
}

/// Every subcommand of `cmd` at any depth, named for its page: `specfx-sweep`, then
/// `specfx-sweep-plan` and `specfx-sweep-merge` after it.
fn subcommand_pages(cmd: &clap::Command, prefix: &str) -> Vec<(String, clap::Command)> {
    let mut pages = Vec::new();
    for sub in cmd.get_subcommands() {
        let name = format!("{prefix}-{}", sub.get_name());
        pages.push((name.clone(), sub.clone().name(name.clone())));
        pages.extend(subcommand_pages(sub, &name));
    }
    pages
}

fn man(args: &ManArgs) -> anyhow::Result<Outcome> {
    let cmd = command();
    let render = |c: clap::Command| -> anyhow::Result<Vec<u8>> {
        let mut buf = Vec::new();
        clap_mangen::Man::new(c).render(&mut buf)?;
        Ok(buf)
    };
    match &args.out {
        None => {
            let page = render(cmd)?;
            output::print_with(|w| {
                use std::io::Write;
                w.write_all(&page)
            })?;
        }
        Some(dir) => {
            // Every page is rendered and every file checked before the first is written: a
            // file of the same name that is not a specfx manual page is kept (unless --force).
            let mut pages = vec![(dir.join("specfx.1"), render(cmd.clone())?)];
            for (name, sub) in subcommand_pages(&cmd, "specfx") {
                pages.push((dir.join(format!("{name}.1")), render(sub)?));
            }
            let names: Vec<String> = pages
                .iter()
                .map(|(path, page)| {
                    debug_assert!(page.starts_with(MAN_HEADER.as_bytes()));
                    path.file_name()
                        .expect("a page name")
                        .to_string_lossy()
                        .into_owned()
                })
                .collect();
            let names: Vec<&str> = names.iter().map(String::as_str).collect();
            specfx::output::check_files_in(
                dir,
                &names,
                "--out",
                &[],
                Some(MAN_HEADER),
                args.force,
            )?;
            specfx::output::write_all_atomic(&pages)?;
        }
    }
    Ok(Outcome::Ok)
}

/// clap's whole error message on one line: the error, the missing arguments' names, the
/// "did you mean" tips and possible values, without the usage block and the `--help` footer.
///
/// # Examples
/// (in the unit tests below)
fn one_line(text: &str) -> String {
    let mut parts: Vec<String> = Vec::new();
    for line in text.lines() {
        let line = line.trim();
        if line.starts_with("Usage:") || line.starts_with("For more information") {
            break;
        }
        if !line.is_empty() {
            // A value clap echoes may hold control characters (a lone `\r` moves the cursor).
            parts.push(error_text(line));
        }
    }
    let mut out = String::new();
    for (i, p) in parts.iter().enumerate() {
        if i > 0 {
            // A list under a line ending in ':' continues it; anything else is a new clause.
            out.push_str(if parts[i - 1].ends_with(':') {
                " "
            } else {
                "; "
            });
        }
        out.push_str(p);
    }
    if out.is_empty() {
        "bad arguments".to_string()
    } else {
        out
    }
}

/// What a command reports back besides errors.
pub enum Outcome {
    /// Everything ran and every check passed.
    Ok,
    /// The command ran, but a check it performs failed (exit code 1).
    CheckFailed,
}

/// The most worker threads `RAYON_NUM_THREADS` may ask for (as `throughput --threads`).
const MAX_THREADS: usize = 1024;

/// Checks `RAYON_NUM_THREADS` (which rayon reads itself) before any work: unset, empty or 0
/// means one thread per core; more than [`MAX_THREADS`] would only spend memory on stacks.
fn check_thread_count(value: Option<&std::ffi::OsStr>) -> Result<(), String> {
    let Some(value) = value else { return Ok(()) };
    let text = value.to_string_lossy();
    // Exactly as rayon parses it (it takes anything else for "one per core").
    match text.parse::<usize>() {
        _ if text.is_empty() => Ok(()),
        Ok(n) if n <= MAX_THREADS => Ok(()),
        _ => Err(format!(
            "RAYON_NUM_THREADS: expected a number of worker threads in 0..={MAX_THREADS} (0: one per core), got '{}'",
            error_text(&text)
        )),
    }
}

/// User text on one line (control characters escaped).
fn error_text(text: &str) -> String {
    text.chars()
        .map(|c| {
            if c.is_control() {
                c.escape_debug().to_string()
            } else {
                c.to_string()
            }
        })
        .collect()
}

/// The error line of a command given without its subcommand: the command the arguments name
/// (walking down its subcommands by name) and the subcommands it takes.
fn missing_subcommand(
    root: &clap::Command,
    args: impl Iterator<Item = std::ffi::OsString>,
) -> String {
    let mut path = vec![root.get_name().to_string()];
    let mut cmd = root;
    for arg in args {
        let arg = arg.to_string_lossy();
        if let Some(sub) = cmd.find_subcommand(arg.as_ref()) {
            path.push(sub.get_name().to_string());
            cmd = sub;
        }
    }
    let subs: Vec<&str> = cmd
        .get_subcommands()
        .filter(|c| !c.is_hide_set())
        .map(|c| c.get_name())
        .collect();
    let path = path.join(" ");
    format!(
        "'{path}' needs a subcommand, expected one of: {} (see '{path} --help')",
        subs.join(", ")
    )
}

/// A value parser over a library enum's values (`values`, each with its name and its help, or
/// [`no_help`]): clap lists them (with their help) in `--help`, man pages and the shell
/// completions, which complete the values rather than file names. A name is taken in any case,
/// as the library's own parsers take it; any other value is refused with clap's error, which
/// lists the names.
fn named_values<T>(
    values: &'static [T],
    name: fn(T) -> &'static str,
    help: fn(T) -> &'static str,
) -> NamedValues<T>
where
    T: Copy + Send + Sync + 'static,
{
    NamedValues { values, name, help }
}

/// The parser [`named_values`] makes.
#[derive(Clone)]
struct NamedValues<T: 'static> {
    values: &'static [T],
    name: fn(T) -> &'static str,
    help: fn(T) -> &'static str,
}

impl<T: Copy + Send + Sync + 'static> NamedValues<T> {
    fn possible(&self) -> impl Iterator<Item = clap::builder::PossibleValue> + '_ {
        self.values.iter().map(|&v| match (self.help)(v) {
            "" => clap::builder::PossibleValue::new((self.name)(v)),
            help => clap::builder::PossibleValue::new((self.name)(v)).help(help),
        })
    }
}

impl<T: Copy + Send + Sync + 'static> clap::builder::TypedValueParser for NamedValues<T> {
    type Value = T;

    fn parse_ref(
        &self,
        cmd: &clap::Command,
        arg: Option<&clap::Arg>,
        value: &std::ffi::OsStr,
    ) -> Result<T, clap::Error> {
        if let Some(&v) = value.to_str().and_then(|s| {
            self.values
                .iter()
                .find(|&&v| (self.name)(v).eq_ignore_ascii_case(s))
        }) {
            return Ok(v);
        }
        // Not a name: clap's own error, with the names.
        match clap::builder::PossibleValuesParser::new(self.possible()).parse_ref(cmd, arg, value) {
            Err(e) => Err(e),
            Ok(_) => unreachable!("the value is none of the names"),
        }
    }

    fn possible_values(
        &self,
    ) -> Option<Box<dyn Iterator<Item = clap::builder::PossibleValue> + '_>> {
        Some(Box::new(self.possible()))
    }
}

/// Parses the arguments, runs the command and maps the result to an exit code.
pub fn main() -> ExitCode {
    output::install_interrupt_handler();
    // Colour is decided before parsing: clap's own help and errors honour it too.
    let color = logging::color_flag(std::env::args_os());
    let no_color = logging::no_color(std::env::var_os("NO_COLOR").as_deref());
    let cli = match command()
        .color(logging::clap_color(color, no_color))
        .try_get_matches()
        .and_then(|m| <Cli as clap::FromArgMatches>::from_arg_matches(&m))
    {
        Ok(cli) => cli,
        // Help and version go to stdout with exit code 0, as clap prints them.
        Err(e) if !e.use_stderr() => e.exit(),
        // A command without its subcommand is an error like any other: one line naming what
        // it takes, not a page of help.
        Err(e) if e.kind() == clap::error::ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand => {
            let message = missing_subcommand(&command(), std::env::args_os().skip(1));
            logging::print_error_line(&format!("specfx: error: {message}"));
            return ExitCode::from(2);
        }
        Err(e) => {
            // A closed or full stderr is no reason to panic: the exit code still tells.
            logging::print_error_line(&format!("specfx: {}", one_line(&e.render().to_string())));
            return ExitCode::from(2);
        }
    };
    if let Err(e) = check_thread_count(std::env::var_os("RAYON_NUM_THREADS").as_deref()) {
        logging::print_error_line(&format!("specfx: error: {e}"));
        return ExitCode::from(2);
    }
    logging::init(
        logging::Verbosity::from_flags(cli.quiet, cli.verbose),
        cli.color,
    );
    log::debug!(
        "specfx {}: {} threads",
        env!("CARGO_PKG_VERSION"),
        rayon::current_num_threads()
    );
    let result = match cli.command {
        Command::Report(args) => report::run(&args),
        Command::Paper(args) => paper::run(&args),
        Command::Check(args) => check::run(&args),
        Command::Coef(args) => reference::run_coef(&args),
        Command::Minimax(args) => reference::run_minimax(&args),
        Command::Vectors(args) => vectors::run(&args),
        Command::Sim(args) => sim::run(&args),
        Command::Cosim(args) => cosim::run(&args),
        Command::Cost(args) => cost::run(&args),
        Command::Calibrate(args) => calibrate::run(&args),
        Command::Timing(args) => pnr::run(&args),
        Command::Sweep(args) => sweep::run(&args),
        Command::Budget(args) => budget::run(&args),
        Command::Optimize(args) => optimize::run(&args),
        Command::Tradeoff(args) => tradeoff::run(&args),
        Command::Render(args) => render::run(&args),
        Command::Fit(args) => fit::run(&args),
        Command::Furnace(args) => furnace::run(&args),
        Command::Stability(args) => stability::run(&args),
        Command::Hdl(args) => hdl::run(&args),
        Command::Trace(args) => trace::run(&args),
        Command::Throughput(args) => throughput::run(&args),
        Command::Completions(args) => completions(&args),
        Command::Man(args) => man(&args),
    };
    log::debug!("finished in {:.3}s", logging::elapsed().as_secs_f64());
    match result {
        Ok(Outcome::Ok) => ExitCode::SUCCESS,
        Ok(Outcome::CheckFailed) => ExitCode::from(1),
        Err(err) if output::is_broken_pipe(&err) => ExitCode::SUCCESS,
        Err(err) => {
            // A summary that cannot reach stdout after the result directory was committed:
            // the files are all there, and the one line says so.
            let complete = specfx::output::last_committed()
                .filter(|_| output::is_stdout_error(&err))
                .map_or(String::new(), |dir| {
                    format!(" (the result in {} is complete)", dir.display())
                });
            logging::print_error_line(&format!("specfx: error: {err:#}{complete}"));
            ExitCode::from(2)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn clap_errors_keep_names_and_tips_on_one_line() {
        let err = |args: &[&str]| {
            let e = command()
                .try_get_matches_from(std::iter::once("specfx").chain(args.iter().copied()))
                .expect_err("bad arguments");
            one_line(&e.render().to_string())
        };
        let missing = err(&["vectors"]);
        assert!(
            missing.contains("were not provided: --out <OUT>"),
            "{missing}"
        );
        let typo = err(&["vectors", "--fo"]);
        assert!(
            typo.contains("unexpected argument '--fo'") && typo.contains("'--force'"),
            "{typo}"
        );
        let sub = err(&["vectorz"]);
        assert!(
            sub.contains("'vectorz'") && sub.contains("'vectors'"),
            "{sub}"
        );
        let value = err(&["cosim", "--sim", "foo"]);
        assert!(
            value.contains("[possible values: icarus, verilator]"),
            "{value}"
        );
        let control = err(&["check", "--n", "16..x\r"]);
        assert!(
            control.starts_with(r"error: invalid value '16..x\r' for '--n <N>'"),
            "{control}"
        );
        // A negative number reaches the option's own check, which says what it must be.
        let negative = err(&["stability", "--tol", "-1"]);
        assert!(
            negative.contains(
                "invalid value '-1' for '--tol <TOL>': the tolerance must be a positive number"
            ),
            "{negative}"
        );
        let negative = err(&[
            "hdl",
            "stimulus",
            "--vectors",
            "v",
            "--out",
            "o",
            "--bubble",
            "-0.5",
        ]);
        assert!(
            negative.contains("invalid value '-0.5' for '--bubble"),
            "{negative}"
        );
        for e in [missing, typo, sub, value, control] {
            assert!(!e.contains('\n') && !e.contains("Usage"), "{e}");
        }
    }

    #[test]
    fn the_thread_count_is_checked() {
        use std::ffi::OsStr;
        for ok in [None, Some(""), Some("0"), Some("1"), Some("1024")] {
            assert_eq!(check_thread_count(ok.map(OsStr::new)), Ok(()), "{ok:?}");
        }
        for bad in ["1025", "100000", "-1", "two", "1\n", " 2"] {
            let e = check_thread_count(Some(OsStr::new(bad))).unwrap_err();
            assert!(
                e.starts_with("RAYON_NUM_THREADS: expected a number of worker threads in 0..=1024"),
                "{e}"
            );
            assert!(!e.contains('\n'), "{e}");
        }
    }

    /// The long help of `specfx NAME` (NAME may be `hdl params`).
    fn cmd_help(name: &str) -> String {
        let mut cmd = command();
        let mut words = name.split(' ');
        let first = words.next().expect("a name");
        let mut sub = cmd.find_subcommand_mut(first).expect("a command").clone();
        for w in words {
            sub = sub.find_subcommand_mut(w).expect("a command").clone();
        }
        sub.render_long_help().to_string()
    }

    #[test]
    fn every_command_has_an_example_that_parses() {
        let cmd = command();
        // Every command, and every command of a command (`hdl params`, `sweep merge`).
        let mut names: Vec<String> = Vec::new();
        for sub in cmd.get_subcommands() {
            names.push(sub.get_name().to_string());
            for inner in sub.get_subcommands() {
                names.push(format!("{} {}", sub.get_name(), inner.get_name()));
            }
        }
        assert!(names.iter().any(|n| n == "hdl stimulus"), "{names:?}");
        for name in &names {
            let (_, example) = EXAMPLES
                .iter()
                .find(|(n, _)| n == name)
                .unwrap_or_else(|| panic!("no example for `specfx {name}`"));
            assert!(
                example.starts_with(&format!("specfx {name} ")),
                "the example of {name} runs another command: {example}"
            );
            let shown = cmd_help(name);
            assert!(
                shown.contains(example),
                "specfx {name} --help does not show its example"
            );
            // The example's arguments parse (single quotes group words; up to a shell
            // redirection or `&&`).
            let mut words: Vec<String> = Vec::new();
            let mut quoted = false;
            let mut word = String::new();
            for ch in example.chars() {
                match ch {
                    '\'' => quoted = !quoted,
                    ' ' if !quoted => {
                        if !word.is_empty() {
                            words.push(std::mem::take(&mut word));
                        }
                    }
                    _ => word.push(ch),
                }
            }
            words.push(word);
            let end = words
                .iter()
                .position(|w| w == ">" || w == "&&")
                .unwrap_or(words.len());
            command()
                .try_get_matches_from(&words[..end])
                .unwrap_or_else(|e| panic!("example of {name}: {e}"));
        }
    }
}
