//! The command line's manners, through the binary: `--quiet` leaves stderr empty and results
//! unchanged, progress off a terminal is one plain line per tenth, `NO_COLOR` removes every
//! ANSI escape (help and usage errors included), `--verbose` says more.

use crate::common;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn temp(name: &str) -> PathBuf {
    let p = std::env::temp_dir().join(format!("specfx-ux-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&p);
    let _ = std::fs::remove_file(&p);
    p
}

/// 2 x 2 x 2 x 2 = 16 points.
const SPACE: &str = "n = \"64,200\"\n[vary]\nk = [4, 5]\n\"square.frac\" = [10, 13]\n\"t.rounding\" = [\"TRN\", \"RND\"]\narch = [\"pipelined\", \"folded\"]\n";

fn space_file(name: &str) -> PathBuf {
    let p = temp(name);
    std::fs::write(&p, SPACE).unwrap();
    p
}

/// Runs the binary with `args`, `NO_COLOR` unset unless given in `env`.
fn run(args: &[&str], env: &[(&str, &str)]) -> Output {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_specfx"));
    cmd.args(args).env_remove("NO_COLOR");
    for (k, v) in env {
        cmd.env(k, v);
    }
    cmd.output().expect("the specfx binary runs")
}

fn text(bytes: &[u8]) -> String {
    String::from_utf8(bytes.to_vec()).expect("UTF-8 output")
}

fn sweep(space: &Path, out: &Path, extra: &[&str]) -> Output {
    let mut args = vec![
        "sweep",
        "--space",
        space.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ];
    args.extend_from_slice(extra);
    let o = run(&args, &[]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    o
}

/// The files of a result directory, by name, with their bytes.
fn files(dir: &Path) -> Vec<(String, Vec<u8>)> {
    let mut all: Vec<(String, Vec<u8>)> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.is_file())
        .map(|p| {
            (
                p.file_name().unwrap().to_string_lossy().into_owned(),
                std::fs::read(&p).unwrap(),
            )
        })
        .collect();
    all.sort();
    all
}

#[test]
fn quiet_prints_nothing_on_stderr_and_changes_no_result() {
    let space = space_file("quiet-space.toml");
    let (loud, quiet) = (temp("loud"), temp("quiet"));
    let l = sweep(&space, &loud, &[]);
    assert!(!l.stderr.is_empty(), "a normal sweep says what it does");
    // The flag is global: before or after the command.
    let q = sweep(&space, &quiet, &["--quiet"]);
    assert!(q.stderr.is_empty(), "{}", text(&q.stderr));
    let q2 = run(
        &[
            "-q",
            "sweep",
            "--space",
            space.to_str().unwrap(),
            "--out",
            temp("quiet2").to_str().unwrap(),
        ],
        &[],
    );
    assert!(q2.status.success() && q2.stderr.is_empty());
    // The result asked for still reaches stdout, and every file is the same.
    assert!(
        text(&q.stdout).starts_with("sweep: 16 points in "),
        "{}",
        text(&q.stdout)
    );
    let (a, b) = (files(&loud), files(&quiet));
    assert_eq!(
        a.iter().map(|f| &f.0).collect::<Vec<_>>(),
        b.iter().map(|f| &f.0).collect::<Vec<_>>()
    );
    assert!(a.iter().any(|(name, _)| name == "sweep.csv"));
    for ((name, x), (_, y)) in a.iter().zip(&b) {
        assert!(x == y, "{name} differs with --quiet");
    }

    // Golden vectors: the same files, nothing on stderr.
    let (v1, v2) = (temp("vec-loud"), temp("vec-quiet"));
    for (dir, quiet) in [(&v1, false), (&v2, true)] {
        let mut args = vec!["vectors", "--cases", "corner,random:500", "--out"];
        args.push(dir.to_str().unwrap());
        if quiet {
            args.push("-q");
        }
        let o = run(&args, &[]);
        assert!(o.status.success(), "{}", text(&o.stderr));
        if quiet {
            assert!(o.stderr.is_empty(), "{}", text(&o.stderr));
            assert!(text(&o.stdout).contains("wrote "), "{}", text(&o.stdout));
        }
    }
    assert_eq!(files(&v1), files(&v2));

    // Errors still print: one line, exit code 2.
    let e = run(&["-q", "sweep", "--space", "/nonexistent/space.toml"], &[]);
    assert_eq!(e.status.code(), Some(2));
    assert_eq!(text(&e.stderr).lines().count(), 1, "{}", text(&e.stderr));
    // --quiet and --verbose contradict each other.
    let e = run(&["-q", "-v", "paper"], &[]);
    assert_eq!(e.status.code(), Some(2));
    assert_eq!(text(&e.stderr).lines().count(), 1, "{}", text(&e.stderr));
    for p in [space, loud, quiet, v1, v2] {
        let _ = std::fs::remove_dir_all(&p);
        let _ = std::fs::remove_file(&p);
    }
}

#[test]
fn progress_off_a_terminal_is_a_plain_line_per_tenth() {
    let space = space_file("lines-space.toml");
    let out = temp("lines");
    let o = sweep(&space, &out, &[]);
    let err = text(&o.stderr);
    assert!(!err.contains('\r') && !err.contains('\x1b'), "{err:?}");
    // 16 points, one at a time: the tenth t is first reached at point ceil(16 t / 10).
    let want = [
        (10, 2),
        (20, 4),
        (30, 5),
        (40, 7),
        (50, 8),
        (60, 10),
        (70, 12),
        (80, 13),
        (90, 15),
        (100, 16),
    ];
    let lines: Vec<&str> = err
        .lines()
        .filter(|l| l.starts_with("sweep: ") && l.contains("% ("))
        .collect();
    assert_eq!(lines.len(), want.len(), "{err}");
    for (line, (pct, count)) in lines.iter().zip(want) {
        let head = format!("sweep: {pct}% ({count}/16 points)");
        assert!(line.starts_with(&head), "{line:?}, expected {head:?}");
        let tail = &line[head.len()..];
        if pct == 100 {
            assert!(tail.starts_with(", took "), "{line:?}");
        } else {
            assert!(tail.is_empty() || tail.starts_with(", eta "), "{line:?}");
        }
    }
    // A resumed sweep with nothing left to do shows no progress.
    let again = sweep(&space, &out, &[]);
    let err = text(&again.stderr);
    assert!(err.contains("16 already done"), "{err}");
    assert!(!err.contains("% ("), "{err}");
    let _ = std::fs::remove_dir_all(&out);
    let _ = std::fs::remove_file(&space);
}

#[test]
fn no_color_means_no_escape_anywhere() {
    let space = space_file("color-space.toml");
    let out = temp("color");
    let runs: Vec<Vec<&str>> = vec![
        vec!["--help"],
        vec!["sweep", "--help"],
        vec!["help", "vectors"],
        vec!["vectorz"],
        vec!["vectors", "--fo"],
        vec!["check", "--config", "/nonexistent.toml"],
        vec![
            "-v",
            "sweep",
            "--space",
            space.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ],
    ];
    for args in &runs {
        let o = run(args, &[("NO_COLOR", "1")]);
        for (stream, bytes) in [("stdout", &o.stdout), ("stderr", &o.stderr)] {
            assert!(
                !text(bytes).contains("\x1b["),
                "{args:?}: ANSI escape in {stream}: {:?}",
                text(bytes)
            );
        }
    }
    // The same runs captured without NO_COLOR have no colour either (not a terminal)...
    for args in &runs {
        let o = run(args, &[]);
        assert!(!text(&o.stdout).contains("\x1b[") && !text(&o.stderr).contains("\x1b["));
    }
    // ... and an explicit --color always is obeyed, also over NO_COLOR (no-color.org: a
    // flag given on the command line wins), so the checks above can fail.
    let help = run(&["--color", "always", "--help"], &[("NO_COLOR", "1")]);
    assert!(
        text(&help.stdout).contains("\x1b["),
        "{}",
        text(&help.stdout)
    );
    let verbose = run(&["--color=always", "-v", "paper"], &[]);
    assert!(text(&verbose.stderr).contains("\x1b[2m"));
    let never = run(&["--color", "never", "--help"], &[]);
    assert!(!text(&never.stdout).contains("\x1b["));
    let _ = std::fs::remove_dir_all(&out);
    let _ = std::fs::remove_file(&space);
}

/// The commands a help page lists in its "Commands:" block, `help` left out (a description
/// wrapped onto the next line is indented further than a command's line).
fn commands_of(help: &str) -> Vec<String> {
    help.lines()
        .skip_while(|l| !l.starts_with("Commands:"))
        .skip(1)
        .take_while(|l| l.starts_with("  "))
        .filter(|l| !l.starts_with("   "))
        .filter_map(|l| l.split_whitespace().next().map(str::to_string))
        .filter(|c| c != "help")
        .collect()
}

/// Help is wrapped: off a terminal, no line of any command's help (nested ones too) is wider
/// than 100 columns.
#[test]
fn help_fits_100_columns() {
    let help = text(&run(&["--help"], &[]).stdout);
    let commands = commands_of(&help);
    let mut pages = vec![(vec![], help)];
    for c in &commands {
        let page = text(&run(&[c.as_str(), "--help"], &[]).stdout);
        for sub in commands_of(&page) {
            let nested = text(&run(&[c.as_str(), sub.as_str(), "--help"], &[]).stdout);
            pages.push((vec![c.clone(), sub.to_string()], nested));
        }
        pages.push((vec![c.clone()], page));
    }
    assert!(pages.len() > 30, "{}", pages.len());
    for (args, page) in &pages {
        for line in page.lines() {
            assert!(
                line.chars().count() <= 100,
                "specfx {} --help: a line of {} columns: {line}",
                args.join(" "),
                line.chars().count()
            );
        }
    }
}

/// The line a failed run ends with is red on a terminal (here a real one, util-linux `script`'s
/// pseudo-terminal), and plain off one, with `NO_COLOR` or `--color never`; the same for an
/// error in the arguments, which comes before the logger.
#[test]
fn error_lines_are_red_on_a_terminal_only() {
    let red = "\x1b[31mspecfx: error: ";
    for args in [
        &["check", "--config", "/nonexistent.toml"][..],
        &["vectorz"][..],
    ] {
        let forced = run(&[&["--color", "always"][..], args].concat(), &[]);
        assert!(
            text(&forced.stderr).starts_with(red),
            "{args:?}: {:?}",
            text(&forced.stderr)
        );
        assert_eq!(forced.status.code(), Some(2));
        let plain = run(args, &[]);
        assert!(
            text(&plain.stderr).starts_with("specfx: error: "),
            "{:?}",
            text(&plain.stderr)
        );
        // On a terminal: red, unless NO_COLOR is set.
        let command = std::iter::once(env!("CARGO_BIN_EXE_specfx"))
            .chain(args.iter().copied())
            .collect::<Vec<_>>()
            .join(" ");
        for (no_color, want_red) in [("", true), ("1", false)] {
            let o = std::process::Command::new("script")
                .args(["-qec", &command, "/dev/null"])
                .env("NO_COLOR", no_color)
                .output()
                .expect("script (util-linux) runs");
            let out = text(&o.stdout);
            assert_eq!(
                out.contains(red),
                want_red,
                "NO_COLOR={no_color:?} {args:?}: {out:?}"
            );
            assert!(out.contains("specfx: error: "), "{out:?}");
        }
    }
}

#[test]
fn verbose_says_more_than_the_default() {
    let space = space_file("verbose-space.toml");
    let (plain, verbose) = (temp("plain"), temp("verbose"));
    let p = sweep(&space, &plain, &[]);
    let v = sweep(&space, &verbose, &["--verbose"]);
    let (p, v) = (text(&p.stderr), text(&v.stderr));
    assert!(v.lines().count() > p.lines().count(), "{p}\n---\n{v}");
    // Every default line is still there, in order; the details name files and timings.
    let mut rest = v.lines().filter(|l| !l.starts_with('['));
    for line in p.lines().filter(|l| !l.contains("% (")) {
        assert!(rest.any(|r| r == line), "{line:?} missing from {v}");
    }
    let details: Vec<&str> = v.lines().filter(|l| l.starts_with('[')).collect();
    let named = |what: &str| details.iter().any(|l| l.contains(what));
    assert!(
        named("read ") && named("verbose-space.toml"),
        "{details:#?}"
    );
    assert!(named("writing ") && named("sweep.csv"), "{details:#?}");
    assert!(named("sweep: 16 points in "), "{details:#?}");
    assert!(named("finished in "), "{details:#?}");
    // Each detail line starts with the seconds since the start: "[   0.123s] ".
    for l in &details {
        let secs = l[1..].split("s] ").next().unwrap().trim();
        assert!(secs.parse::<f64>().is_ok(), "{l:?}");
    }
    for p in [plain, verbose, space] {
        let _ = std::fs::remove_dir_all(&p);
        let _ = std::fs::remove_file(&p);
    }
}

#[test]
fn existing_single_line_errors_are_unchanged_by_the_flags() {
    // The one error line of a bad input is the same with -v: details come before it, and the
    // last line is still the error.
    let o = run(&["-v", "check", "--config", "/nonexistent/x.toml"], &[]);
    assert_eq!(o.status.code(), Some(2));
    let err = text(&o.stderr);
    let last = err.lines().last().unwrap_or("");
    assert!(
        last.starts_with("specfx: error: ") && last.contains("/nonexistent/x.toml"),
        "{err}"
    );
    let plain = common::specfx(&["check", "--config", "/nonexistent/x.toml"]);
    assert_eq!(text(&plain.stderr).lines().count(), 1);
    assert_eq!(text(&plain.stderr).lines().last(), Some(last));
}

#[test]
fn completions_and_manual_pages_cover_every_command() {
    // The commands, from the binary's own help (its "Commands:" block).
    let commands = commands_of(&text(&run(&["--help"], &[]).stdout));
    assert!(commands.len() > 20, "{commands:?}");
    let bash = run(&["completions", "bash"], &[]);
    assert!(bash.status.success());
    let script = text(&bash.stdout);
    assert!(script.contains("_specfx()"), "a bash completion function");
    for c in &commands {
        assert!(script.contains(c.as_str()), "completion of {c}");
    }
    // Enum flags complete their values, not file names.
    for values in [
        "pipelined folded",
        "slurm lsf sge k8s shell",
        "analytic yosys",
        "icarus verilator",
        "interleaved sorted",
        "define json iverilog verilator fusesoc instance",
    ] {
        assert!(
            script.contains(&format!("compgen -W \"{values}\"")),
            "the values {values} in the bash completions"
        );
    }
    let page = text(&run(&["man"], &[]).stdout);
    assert!(page.contains(".TH specfx 1"), "{page}");

    // --out: one page per command; a foreign file of the same name is kept, unless --force;
    // the command's own pages are replaced.
    let dir = temp("man");
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("specfx-report.1"), "my notes\n").unwrap();
    let o = run(&["man", "--out", dir.to_str().unwrap()], &[]);
    assert_eq!(o.status.code(), Some(2));
    let err = text(&o.stderr);
    assert!(
        err.contains("specfx-report.1: already exists") && err.lines().count() == 1,
        "{err}"
    );
    assert_eq!(
        std::fs::read_dir(&dir).unwrap().count(),
        1,
        "nothing written"
    );
    let forced = run(&["man", "--out", dir.to_str().unwrap(), "--force"], &[]);
    assert!(forced.status.success(), "{}", text(&forced.stderr));
    for c in &commands {
        let page = std::fs::read_to_string(dir.join(format!("specfx-{c}.1"))).unwrap();
        assert!(page.contains(&format!(".TH specfx-{c} 1")), "{c}");
    }
    // The nested subcommands too (`sweep plan`, `hdl params`, ...), from each command's help.
    let mut nested = Vec::new();
    for c in &commands {
        let help = text(&run(&[c.as_str(), "--help"], &[]).stdout);
        nested.extend(commands_of(&help).iter().map(|s| format!("{c}-{s}")));
    }
    for want in [
        "sweep-plan",
        "sweep-merge",
        "hdl-params",
        "hdl-rom",
        "hdl-stimulus",
        "trace-compare",
        "calibrate-merge",
    ] {
        assert!(nested.iter().any(|n| n == want), "{want} in {nested:?}");
    }
    for c in &nested {
        let page = std::fs::read_to_string(dir.join(format!("specfx-{c}.1")))
            .unwrap_or_else(|e| panic!("specfx-{c}.1: {e}"));
        assert!(page.contains(&format!(".TH specfx-{c} 1")), "{c}");
    }
    let again = run(&["man", "--out", dir.to_str().unwrap()], &[]);
    assert!(again.status.success(), "{}", text(&again.stderr));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn the_minimax_table_replaces_only_a_minimax_table() {
    let file = temp("minimax.csv");
    std::fs::write(&file, "precious\n").unwrap();
    let args = ["minimax", "--write", file.to_str().unwrap(), "--n-max", "2"];
    let o = run(&args, &[]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        text(&o.stderr).contains("already exists and is not an earlier result"),
        "{}",
        text(&o.stderr)
    );
    assert_eq!(std::fs::read_to_string(&file).unwrap(), "precious\n");
    let forced = run(&[&args[..], &["--force"]].concat(), &[]);
    assert!(forced.status.success(), "{}", text(&forced.stderr));
    // k = 1..=7 for n = 1, 2 under the header.
    let table = std::fs::read_to_string(&file).unwrap();
    assert_eq!(table.lines().count(), 1 + 14, "{table}");
    let again = run(&args, &[]);
    assert!(again.status.success(), "{}", text(&again.stderr));
    std::fs::remove_file(&file).unwrap();
}
