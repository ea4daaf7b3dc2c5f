//! External tools end with the command, through the real binary: Ctrl-C, SIGTERM or SIGKILL
//! during `specfx cost` leaves no yosys running, and no work directory behind (a killed run's
//! is removed by the next run); every tool writes its temporary files into a private
//! directory removed with it; a file-size limit is a write error, not a silent death.

use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

const TIMEOUT: Duration = Duration::from_secs(60);

/// The pids whose parent is `parent`, read from /proc.
fn children_of(parent: u32) -> Vec<u32> {
    let mut out = Vec::new();
    for e in std::fs::read_dir("/proc").unwrap().flatten() {
        let Ok(pid) = e.file_name().to_string_lossy().parse::<u32>() else {
            continue;
        };
        let Ok(stat) = std::fs::read_to_string(format!("/proc/{pid}/stat")) else {
            continue;
        };
        // pid (comm) state ppid ...: the comm may hold spaces, so split after its ')'.
        let after = &stat[stat.rfind(')').unwrap() + 2..];
        let ppid: u32 = after.split(' ').nth(1).unwrap().parse().unwrap();
        if ppid == parent {
            out.push(pid);
        }
    }
    out
}

/// Whether any process of the process group `pgid` is alive (not a zombie).
fn group_alive(pgid: u32) -> bool {
    std::fs::read_dir("/proc").unwrap().flatten().any(|e| {
        let Ok(stat) = std::fs::read_to_string(e.path().join("stat")) else {
            return false;
        };
        let after = &stat[stat.rfind(')').unwrap() + 2..];
        let fields: Vec<&str> = after.split(' ').collect();
        fields[0] != "Z" && fields[2] == pgid.to_string()
    })
}

fn work_dirs(tmp: &Path) -> Vec<PathBuf> {
    std::fs::read_dir(tmp)
        .unwrap()
        .flatten()
        .map(|e| e.path())
        .filter(|p| {
            p.file_name()
                .unwrap()
                .to_string_lossy()
                .starts_with("specfx-yosys-")
        })
        .collect()
}

/// Everything in `dir`.
fn entries(dir: &Path) -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap()
        .flatten()
        .map(|e| e.path())
        .collect();
    v.sort();
    v
}

fn start_cost(tmp: &Path) -> Child {
    Command::new(env!("CARGO_BIN_EXE_specfx"))
        .args(["cost", "--config", "baseline"])
        .env("TMPDIR", tmp)
        // yosys must run: not from the synthesis cache.
        .env("SPECFX_CACHE", "off")
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap()
}

/// Waits until `specfx` has yosys running its synthesis script; returns its pid.
fn wait_for_tool(specfx: &Child) -> u32 {
    let start = Instant::now();
    loop {
        let synthesis = children_of(specfx.id()).into_iter().find(|pid| {
            std::fs::read(format!("/proc/{pid}/cmdline"))
                .is_ok_and(|c| String::from_utf8_lossy(&c).contains("cost.ys"))
        });
        if let Some(pid) = synthesis {
            return pid;
        }
        assert!(start.elapsed() < TIMEOUT, "yosys never started");
        std::thread::sleep(Duration::from_millis(20));
    }
}

fn wait_until(what: &str, cond: impl Fn() -> bool) {
    let start = Instant::now();
    while !cond() {
        assert!(start.elapsed() < TIMEOUT, "{what}");
        std::thread::sleep(Duration::from_millis(20));
    }
}

#[test]
fn tools_end_with_the_command_and_leave_no_work_directory() {
    let which = Command::new("yosys").arg("-V").output();
    assert!(
        which.is_ok_and(|o| o.status.success()),
        "yosys is needed (./scripts/test installs it)"
    );
    let tmp = tempfile::tempdir().unwrap();
    for signal in ["INT", "TERM", "KILL"] {
        let mut specfx = start_cost(tmp.path());
        let tool = wait_for_tool(&specfx);
        // The tool leads its own process group.
        assert!(group_alive(tool), "SIG{signal}: the tool's group is {tool}");
        assert_eq!(
            work_dirs(tmp.path()).len(),
            1,
            "SIG{signal}: one work directory"
        );
        let ok = Command::new("kill")
            .args([format!("-{signal}"), specfx.id().to_string()])
            .status()
            .unwrap()
            .success();
        assert!(ok);
        let status = specfx.wait().unwrap();
        wait_until(&format!("SIG{signal}: yosys still runs"), || {
            !group_alive(tool)
        });
        if signal == "KILL" {
            // Nothing could run in the killed process: its work directory is left, and the
            // next run that makes one removes it.
            assert_eq!(
                work_dirs(tmp.path()).len(),
                1,
                "SIGKILL leaves its directory"
            );
            let mut next = start_cost(tmp.path());
            let next_tool = wait_for_tool(&next);
            assert_eq!(work_dirs(tmp.path()).len(), 1, "the stale one is removed");
            next.kill().unwrap();
            next.wait().unwrap();
            wait_until("the next run's yosys ends with it", || {
                !group_alive(next_tool)
            });
            // That run was SIGKILLed as well: clean up by hand.
            for d in work_dirs(tmp.path()) {
                std::fs::remove_dir_all(d).unwrap();
            }
        } else {
            assert_eq!(status.code(), Some(130), "SIG{signal}");
            // Nothing at all is left in $TMPDIR: no work directory, nothing of yosys's.
            assert!(
                entries(tmp.path()).is_empty(),
                "SIG{signal}: {:?}",
                entries(tmp.path())
            );
        }
    }
}

/// A stand-in `yosys` in `bin/` that logs its `TMPDIR`, `TMP`, `TEMP` and working directory to
/// `log`, leaves a compiler's and abc's temporaries in its `TMPDIR`, then fails (or, when
/// `ready` is given, says so there and waits to be killed).
fn stand_in_yosys(bin: &Path, log: &Path, ready: Option<&Path>) {
    std::fs::create_dir_all(bin).unwrap();
    let tail = match ready {
        Some(r) => format!(": > '{}'\nexec /bin/sleep 60\n", r.display()),
        None => "echo 'ERROR: the stand-in fails as planned' >&2\nexit 1\n".to_string(),
    };
    let script = format!(
        "#!/bin/sh\n\
         echo \"$TMPDIR|$TMP|$TEMP|$PWD|$1\" >> '{}'\n\
         if [ \"$1\" = -V ]; then echo 'Yosys 0.0 (stand-in)'; exit 0; fi\n\
         /bin/mkdir \"$TMPDIR/yosys-abc-stand-in\" || exit 3\n\
         : > \"$TMPDIR/yosys-abc-stand-in/input.blif\" && : > \"$TMPDIR/ccStandIn.s\" || exit 3\n\
         {tail}",
        log.display()
    );
    let path = bin.join("yosys");
    std::fs::write(&path, script).unwrap();
    std::fs::set_permissions(&path, std::os::unix::fs::PermissionsExt::from_mode(0o755)).unwrap();
}

/// The log of [`stand_in_yosys`]: (TMPDIR, working directory, first argument) per run, after
/// checking that TMP and TEMP are TMPDIR.
fn tool_runs(log: &Path) -> Vec<(PathBuf, PathBuf, String)> {
    std::fs::read_to_string(log)
        .unwrap()
        .lines()
        .map(|l| {
            let f: Vec<&str> = l.split('|').collect();
            assert_eq!(
                (f[0], f[0]),
                (f[1], f[2]),
                "TMPDIR, TMP and TEMP differ: {l}"
            );
            (PathBuf::from(f[0]), PathBuf::from(f[3]), f[4].to_string())
        })
        .collect()
}

fn cost_with_stand_in(tmp: &Path, bin: &Path, log: &Path) -> Command {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_specfx"));
    cmd.args(["cost", "--config", "baseline"])
        .env("TMPDIR", tmp)
        .env("PATH", bin)
        .env("LOG", log);
    cmd
}

#[test]
fn every_tool_gets_a_private_temporary_directory_removed_with_it() {
    let root = tempfile::tempdir().unwrap();
    let tmp = root.path().join("tmp");
    std::fs::create_dir(&tmp).unwrap();
    let bin = root.path().join("bin");
    let log = root.path().join("log");
    stand_in_yosys(&bin, &log, None);
    let o = cost_with_stand_in(&tmp, &bin, &log).output().unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        err.contains("yosys failed on the reference Verilog: ERROR: the stand-in fails as planned"),
        "{err}"
    );
    let runs = tool_runs(&log);
    assert!(runs.iter().any(|(_, _, a)| a == "-q"), "{runs:?}");
    for (private, cwd, arg) in &runs {
        // Never $TMPDIR itself: a directory of specfx's in it.
        let inside = private
            .strip_prefix(&tmp)
            .unwrap_or_else(|_| panic!("{runs:?}"));
        assert!(inside.to_string_lossy().starts_with("specfx-"), "{runs:?}");
        // The synthesis runs in its work directory, and its temporaries go in there.
        if arg == "-q" {
            assert!(private.starts_with(cwd) && private != cwd, "{runs:?}");
        }
    }
    // Every private directory went with its tool: nothing is left.
    assert!(entries(&tmp).is_empty(), "{:?}", entries(&tmp));

    // Ended by SIGTERM while the tool works: its temporaries go with the work directory.
    std::fs::remove_file(&log).unwrap();
    let ready = root.path().join("ready");
    stand_in_yosys(&bin, &log, Some(&ready));
    let mut specfx = cost_with_stand_in(&tmp, &bin, &log)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    wait_until("the stand-in yosys never started", || ready.exists());
    let private = tool_runs(&log).last().unwrap().0.clone();
    assert!(private.join("ccStandIn.s").exists());
    let ok = Command::new("kill")
        .args(["-TERM", &specfx.id().to_string()])
        .status()
        .unwrap()
        .success();
    assert!(ok);
    assert_eq!(specfx.wait().unwrap().code(), Some(130));
    assert!(entries(&tmp).is_empty(), "{:?}", entries(&tmp));
}

#[test]
fn a_file_size_limit_is_a_write_error_naming_the_file() {
    // Without `trap '' XFSZ`: specfx itself must not die of SIGXFSZ.
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("rom.v");
    let line = format!(
        "ulimit -f 0; exec '{}' hdl rom --config baseline --out '{}'",
        env!("CARGO_BIN_EXE_specfx"),
        out.display()
    );
    let o = Command::new("sh").args(["-c", &line]).output().unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{:?}: {err}", o.status);
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(
        err.starts_with(&format!(
            "specfx: error: cannot write {}: File too large",
            out.display()
        )),
        "{err}"
    );
    assert!(o.stdout.is_empty());
    // Nothing written: no file, no temporary one.
    assert!(entries(dir.path()).is_empty(), "{:?}", entries(dir.path()));
}
