//! What the binary says on stderr besides results: the `log` backend (one line per record,
//! levels set by `--quiet` / `--verbose`) and the colour decision (`--color`, `NO_COLOR`).
//!
//! Levels: `--quiet` keeps errors and warnings; the default adds informational lines (what a
//! command is doing); `-v` adds details (files read and written, timings of steps), each
//! prefixed by the seconds since the start (`-vv` is the same: no dependency logs through `log`
//! today, and records of other crates are left out).
//! Lines are printed above any progress bar ([`super::progress::suspend`]).

use std::ffi::OsStr;
use std::io::{IsTerminal, Write};
use std::sync::OnceLock;
use std::time::Instant;

/// How much the binary says on stderr.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Verbosity {
    /// Errors and warnings only; no progress.
    Quiet,
    /// Informational lines and progress.
    Normal,
    /// Also details: files read and written, timings.
    Verbose,
}

impl Verbosity {
    /// The verbosity of `--quiet` and the number of `--verbose` flags.
    pub fn from_flags(quiet: bool, verbose: u8) -> Verbosity {
        match (quiet, verbose) {
            (true, _) => Verbosity::Quiet,
            (false, 0) => Verbosity::Normal,
            (false, _) => Verbosity::Verbose,
        }
    }

    fn level(self) -> log::LevelFilter {
        match self {
            Verbosity::Quiet => log::LevelFilter::Warn,
            Verbosity::Normal => log::LevelFilter::Info,
            Verbosity::Verbose => log::LevelFilter::Trace,
        }
    }
}

/// The resolved terminal settings of this run, fixed once the arguments are parsed.
#[derive(Clone, Copy, Debug)]
pub struct Settings {
    /// How much to say.
    pub verbosity: Verbosity,
    /// Whether stderr is a terminal (progress bars rather than lines).
    pub stderr_terminal: bool,
    /// Whether lines on stderr may carry ANSI colour.
    pub color: bool,
}

static SETTINGS: OnceLock<Settings> = OnceLock::new();
static START: OnceLock<Instant> = OnceLock::new();

/// This run's settings ([`init`]'s, or the defaults before it: normal verbosity, no colour).
pub fn settings() -> Settings {
    *SETTINGS.get_or_init(|| Settings {
        verbosity: Verbosity::Normal,
        stderr_terminal: std::io::stderr().is_terminal(),
        color: false,
    })
}

/// The time since the start of the run.
pub fn elapsed() -> std::time::Duration {
    START.get_or_init(Instant::now).elapsed()
}

/// The value of a `--color` flag, found before clap parses (it colours clap's own help):
/// the last `--color WHEN` or `--color=WHEN` before a `--`. A bad value is left to clap.
pub fn color_flag<I, S>(args: I) -> clap::ColorChoice
where
    I: IntoIterator<Item = S>,
    S: AsRef<OsStr>,
{
    let mut choice = clap::ColorChoice::Auto;
    let mut next_is_value = false;
    for arg in args {
        let arg = arg.as_ref().to_string_lossy();
        let value = if next_is_value {
            next_is_value = false;
            Some(arg.as_ref())
        } else if arg == "--" {
            break;
        } else if arg == "--color" {
            next_is_value = true;
            None
        } else {
            arg.strip_prefix("--color=")
        };
        match value {
            Some("always") => choice = clap::ColorChoice::Always,
            Some("never") => choice = clap::ColorChoice::Never,
            Some("auto") => choice = clap::ColorChoice::Auto,
            _ => {}
        }
    }
    choice
}

/// Whether `NO_COLOR` asks for no colour: set and not empty (no-color.org).
pub fn no_color(value: Option<&OsStr>) -> bool {
    value.is_some_and(|v| !v.is_empty())
}

/// Whether a stream gets colour: `always` and `never` are obeyed (an explicit flag wins over
/// the environment, as no-color.org asks); `auto` colours a terminal unless `NO_COLOR` is set.
pub fn color_enabled(choice: clap::ColorChoice, no_color: bool, terminal: bool) -> bool {
    match choice {
        clap::ColorChoice::Always => true,
        clap::ColorChoice::Never => false,
        clap::ColorChoice::Auto => terminal && !no_color,
    }
}

/// The colour setting handed to clap for its help and errors: `auto` becomes `never` when
/// `NO_COLOR` is set (clap then checks the terminal itself).
pub fn clap_color(choice: clap::ColorChoice, no_color: bool) -> clap::ColorChoice {
    match choice {
        clap::ColorChoice::Auto if no_color => clap::ColorChoice::Never,
        c => c,
    }
}

/// Fixes this run's settings and installs the logger. Called once, after parsing.
pub fn init(verbosity: Verbosity, color: clap::ColorChoice) {
    START.get_or_init(Instant::now);
    let stderr_terminal = std::io::stderr().is_terminal();
    let no_color = no_color(std::env::var_os("NO_COLOR").as_deref());
    let settings = Settings {
        verbosity,
        stderr_terminal,
        color: color_enabled(color, no_color, stderr_terminal),
    };
    let _ = SETTINGS.set(settings);
    if log::set_logger(&LOGGER).is_ok() {
        log::set_max_level(verbosity.level());
    }
}

/// The line a run ends with when it fails (`specfx: error: ...`): red where `color` (on a
/// terminal, unless `NO_COLOR` is set or `--color never`), as the log's error lines.
pub fn error_line(line: &str, color: bool) -> String {
    format_line(log::Level::Error, line, color)
}

/// Writes the line a failed run ends with ([`error_line`]) to stderr, coloured as this run's
/// lines are ([`stderr_color`]); a closed or full stderr is no reason to panic (the exit code
/// still tells).
pub fn print_error_line(line: &str) {
    let _ = writeln!(std::io::stderr(), "{}", error_line(line, stderr_color()));
}

/// Whether this run's lines on stderr are coloured: [`init`]'s settings, or before it (an
/// error in the arguments) the `--color` flag, `NO_COLOR` and whether stderr is a terminal.
pub fn stderr_color() -> bool {
    match SETTINGS.get() {
        Some(s) => s.color,
        None => color_enabled(
            color_flag(std::env::args_os()),
            no_color(std::env::var_os("NO_COLOR").as_deref()),
            std::io::stderr().is_terminal(),
        ),
    }
}

/// The `log` backend: one line per record on stderr.
struct StderrLogger;

static LOGGER: StderrLogger = StderrLogger;

impl log::Log for StderrLogger {
    fn enabled(&self, metadata: &log::Metadata<'_>) -> bool {
        metadata.level() <= settings().verbosity.level() && metadata.target().starts_with("specfx")
    }

    fn log(&self, record: &log::Record<'_>) {
        if !self.enabled(record.metadata()) {
            return;
        }
        let line = format_line(record.level(), &record.args().to_string(), settings().color);
        super::progress::suspend(|| {
            let mut err = std::io::stderr().lock();
            // Nothing sensible is left to do when stderr itself fails.
            let _ = writeln!(err, "{line}");
        });
    }

    fn flush(&self) {
        let _ = std::io::stderr().flush();
    }
}

/// A record's line: errors, warnings and information as written; details and traces after
/// the seconds since the start. With `color`, errors are red, warnings yellow, details dim.
fn format_line(level: log::Level, message: &str, color: bool) -> String {
    let text = match level {
        log::Level::Error | log::Level::Warn | log::Level::Info => message.to_string(),
        log::Level::Debug | log::Level::Trace => {
            format!("[{:>8.3}s] {message}", elapsed().as_secs_f64())
        }
    };
    let style = match level {
        log::Level::Error => "\x1b[31m",
        log::Level::Warn => "\x1b[33m",
        log::Level::Info => "",
        log::Level::Debug | log::Level::Trace => "\x1b[2m",
    };
    if color && !style.is_empty() {
        format!("{style}{text}\x1b[0m")
    } else {
        text
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::ColorChoice::{Always, Auto, Never};

    #[test]
    fn verbosity_follows_the_flags() {
        assert_eq!(Verbosity::from_flags(true, 0), Verbosity::Quiet);
        assert_eq!(Verbosity::from_flags(false, 0), Verbosity::Normal);
        assert_eq!(Verbosity::from_flags(false, 1), Verbosity::Verbose);
        assert_eq!(Verbosity::from_flags(false, 3), Verbosity::Verbose);
        assert_eq!(Verbosity::Quiet.level(), log::LevelFilter::Warn);
    }

    #[test]
    fn colour_only_on_a_terminal_without_no_color_unless_forced() {
        // (choice, NO_COLOR set, terminal) -> colour, every case of the rule written out.
        let cases = [
            (Auto, false, true, true),
            (Auto, true, true, false),
            (Auto, false, false, false),
            (Auto, true, false, false),
            (Never, false, true, false),
            (Always, true, false, true),
        ];
        for (choice, no, term, want) in cases {
            assert_eq!(
                color_enabled(choice, no, term),
                want,
                "{choice:?} {no} {term}"
            );
        }
        assert!(no_color(Some(OsStr::new("1"))));
        assert!(!no_color(Some(OsStr::new(""))));
        assert!(!no_color(None));
        assert_eq!(clap_color(Auto, true), Never);
        assert_eq!(clap_color(Auto, false), Auto);
        assert_eq!(clap_color(Always, true), Always);
    }

    #[test]
    fn the_color_flag_is_found_before_parsing() {
        let flag = |args: &[&str]| color_flag(args.iter().copied());
        assert_eq!(flag(&["specfx", "check"]), Auto);
        assert_eq!(flag(&["specfx", "--color", "never", "check"]), Never);
        assert_eq!(flag(&["specfx", "check", "--color=always"]), Always);
        assert_eq!(flag(&["specfx", "--color=never", "--color", "auto"]), Auto);
        assert_eq!(flag(&["specfx", "--", "--color=never"]), Auto);
        assert_eq!(flag(&["specfx", "--color", "purple"]), Auto);
    }

    #[test]
    fn lines_are_plain_without_colour() {
        assert_eq!(format_line(log::Level::Info, "sweep: x", true), "sweep: x");
        assert_eq!(format_line(log::Level::Warn, "w", false), "w");
        assert_eq!(
            format_line(log::Level::Error, "e", true),
            "\x1b[31me\x1b[0m"
        );
        let debug = format_line(log::Level::Debug, "wrote a", false);
        assert!(
            debug.starts_with('[') && debug.ends_with("s] wrote a"),
            "{debug}"
        );
    }
}
