//! External tools end with the command, through the real binary: Ctrl-C, SIGTERM or SIGKILL
//! during `specfx cost` leaves no yosys running, and no work directory behind (a killed run's
//! is removed by the next run).

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

fn start_cost(tmp: &Path) -> Child {
    Command::new(env!("CARGO_BIN_EXE_specfx"))
        .args(["cost", "--config", "baseline"])
        .env("TMPDIR", tmp)
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
            assert!(
                work_dirs(tmp.path()).is_empty(),
                "SIG{signal}: {:?}",
                work_dirs(tmp.path())
            );
        }
    }
}
