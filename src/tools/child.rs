//! External tools (yosys, nextpnr, gappa, the simulators) run as children that end with the
//! command: each in its own process group, killed by the interrupt handler on Ctrl-C or
//! SIGTERM and by the kernel when specfx itself dies (even by SIGKILL); their work
//! directories are removed then too, or by the next run when specfx was killed. Each child
//! gets a private temporary directory (`TMPDIR`, `TMP` and `TEMP`: a C++ compiler's `cc*.s`,
//! yosys's `yosys-abc-*`) inside the work directory it runs in, or a work directory of its
//! own, removed when the child ends and with the work directories otherwise.

use std::io;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::sync::Mutex;

/// Set by [`end_all`]: specfx is ending on an interrupt, and no caller may go on with a
/// killed child's result (an error of its own would race the interrupt's exit code 130).
static ENDING: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);

/// Once specfx is ending on an interrupt: waits for the interrupt handler's exit.
fn stop_if_ending() {
    while ENDING.load(std::sync::atomic::Ordering::SeqCst) {
        std::thread::park();
    }
}

/// Process groups of running children (each child leads its own group).
static GROUPS: Mutex<Vec<i32>> = Mutex::new(Vec::new());

/// Work directories of this process, removed on interrupt.
static WORK_DIRS: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

/// The private temporary directory of each running child, by its pid: removed when the child
/// is waited for.
static CHILD_TMP: Mutex<Vec<(i32, PathBuf)>> = Mutex::new(Vec::new());

/// The prefix of every work directory: `specfx-<tag>-<pid>-`, so a later run can tell the
/// ones of dead processes.
const PREFIX: &str = "specfx-";

/// Prepares `cmd` to run as a child that ends with specfx: its own process group (a terminal's
/// Ctrl-C reaches specfx, which ends the group), and on Linux a parent-death signal, so that a
/// SIGKILLed specfx takes the child with it.
fn prepare(cmd: &mut Command) {
    use std::os::unix::process::CommandExt as _;
    cmd.process_group(0);
    #[cfg(target_os = "linux")]
    // SAFETY: prctl is async-signal-safe; the closure touches no memory of the parent.
    unsafe {
        cmd.pre_exec(|| {
            if libc::prctl(libc::PR_SET_PDEATHSIG, libc::SIGKILL as libc::c_ulong) != 0 {
                return Err(io::Error::last_os_error());
            }
            // The parent may have died before prctl: then nobody would end this child.
            if libc::getppid() == 1 {
                return Err(io::Error::other("specfx ended before its child started"));
            }
            Ok(())
        });
    }
}

/// Runs `cmd` to completion like [`Command::output`], as a child that ends with specfx.
pub fn output(cmd: &mut Command) -> io::Result<Output> {
    cmd.stdin(std::process::Stdio::null());
    cmd.stdout(std::process::Stdio::piped());
    cmd.stderr(std::process::Stdio::piped());
    wait(spawn(cmd)?)
}

/// Spawns `cmd` (its stdio as set by the caller) as a child that ends with specfx, with a
/// private temporary directory; finish it with [`wait`].
pub fn spawn(cmd: &mut Command) -> io::Result<std::process::Child> {
    stop_if_ending();
    prepare(cmd);
    let tmp = private_tmp(cmd)?;
    for var in ["TMPDIR", "TMP", "TEMP"] {
        cmd.env(var, &tmp);
    }
    let child = match cmd.spawn() {
        Ok(c) => c,
        Err(e) => {
            remove_tmp(&tmp);
            return Err(e);
        }
    };
    let pid = child.id() as i32;
    if let Ok(mut g) = GROUPS.lock() {
        g.push(pid);
    }
    if let Ok(mut t) = CHILD_TMP.lock() {
        t.push((pid, tmp));
    }
    Ok(child)
}

/// A new temporary directory for a child of `cmd` (absolute, as every work directory, so that
/// the child's own working directory does not move it): inside the work directory the child
/// runs in when that is one of [`work_dir`]'s (removed with it), else a work directory of its
/// own (`specfx-tmp-<pid>-XXXXXX`), which the interrupt handler and the next run's clean-up
/// know as any other.
fn private_tmp(cmd: &Command) -> io::Result<PathBuf> {
    let work = cmd.get_current_dir().and_then(|cwd| {
        let cwd = std::path::absolute(cwd).ok()?;
        let dirs = WORK_DIRS.lock().ok()?;
        dirs.iter()
            .find(|w| std::path::absolute(w).is_ok_and(|w| cwd.starts_with(w)))
            .cloned()
    });
    match work {
        Some(work) => Ok(tempfile::Builder::new()
            .prefix("tmp-")
            .tempdir_in(work)?
            .keep()),
        None => Ok(work_dir("tmp")?.keep_registered()),
    }
}

/// Removes a child's private temporary directory (and forgets it as a work directory).
fn remove_tmp(dir: &Path) {
    let _ = std::fs::remove_dir_all(dir);
    forget(dir);
}

/// Waits for a child of [`spawn`] (or [`output`]) and collects its output.
pub fn wait(child: std::process::Child) -> io::Result<Output> {
    let pid = child.id() as i32;
    if let Ok(mut g) = GROUPS.lock() {
        if !g.contains(&pid) {
            g.push(pid);
        }
    }
    let out = child.wait_with_output();
    stop_if_ending();
    if let Ok(mut g) = GROUPS.lock() {
        g.retain(|&p| p != pid);
    }
    let tmp = CHILD_TMP.lock().ok().and_then(|mut t| {
        let i = t.iter().position(|(p, _)| *p == pid)?;
        Some(t.swap_remove(i).1)
    });
    if let Some(tmp) = tmp {
        remove_tmp(&tmp);
    }
    out
}

/// A work directory for a tool, `$TMPDIR/specfx-<tag>-<pid>-XXXXXX`, removed when dropped, on
/// interrupt, or (when specfx was killed) by the next call. The directories of processes that
/// no longer run are removed first.
pub fn work_dir(tag: &str) -> io::Result<WorkDir> {
    // Absolute: a child runs in it, and may be given paths inside it.
    let tmp = std::path::absolute(std::env::temp_dir())?;
    remove_stale(&tmp);
    let dir = tempfile::Builder::new()
        .prefix(&format!("{PREFIX}{tag}-{}-", std::process::id()))
        .tempdir_in(&tmp)?;
    if let Ok(mut w) = WORK_DIRS.lock() {
        w.push(dir.path().to_path_buf());
    }
    Ok(WorkDir(Some(dir)))
}

/// A work directory of [`work_dir`].
pub struct WorkDir(Option<tempfile::TempDir>);

impl WorkDir {
    /// The directory.
    pub fn path(&self) -> &Path {
        self.0.as_ref().expect("a live work directory").path()
    }

    /// Keeps the directory (`--keep`): returns its path; it is no longer removed, neither now
    /// nor by a later run's clean-up of dead processes' directories: it is renamed
    /// `specfx-<tag>-kept-<random>`, which names no process.
    pub fn keep(mut self) -> PathBuf {
        let dir = self.0.take().expect("a live work directory");
        forget(dir.path());
        let path = dir.keep();
        let pid = format!("-{}-", std::process::id());
        let kept = path.file_name().and_then(|n| n.to_str()).and_then(|n| {
            let renamed = n.replacen(&pid, "-kept-", 1);
            (renamed != n).then(|| path.with_file_name(renamed))
        });
        match kept {
            Some(k) if std::fs::rename(&path, &k).is_ok() => k,
            _ => path,
        }
    }

    /// Hands the directory's removal over: it stays registered, so the interrupt handler (and
    /// the next run, when specfx was killed) still removes it, but dropping the returned path
    /// does not.
    fn keep_registered(mut self) -> PathBuf {
        self.0.take().expect("a live work directory").keep()
    }
}

impl Drop for WorkDir {
    fn drop(&mut self) {
        if let Some(d) = self.0.take() {
            forget(d.path());
        }
    }
}

fn forget(path: &Path) {
    if let Ok(mut w) = WORK_DIRS.lock() {
        w.retain(|p| p != path);
    }
}

/// Removes `specfx-<tag>-<pid>-*` directories whose process no longer runs.
fn remove_stale(tmp: &Path) {
    let Ok(entries) = std::fs::read_dir(tmp) else {
        return;
    };
    for e in entries.flatten() {
        let name = e.file_name().to_string_lossy().into_owned();
        let Some(rest) = name.strip_prefix(PREFIX) else {
            continue;
        };
        // <tag>-<pid>-<random>: the pid is the second field from the end.
        let mut fields = rest.rsplitn(3, '-');
        let (Some(_random), Some(pid), Some(_tag)) = (fields.next(), fields.next(), fields.next())
        else {
            continue;
        };
        let Ok(pid) = pid.parse::<u32>() else {
            continue;
        };
        if pid != std::process::id()
            && !Path::new(&format!("/proc/{pid}")).exists()
            && e.path().is_dir()
        {
            let _ = std::fs::remove_dir_all(e.path());
        }
    }
}

/// Ends every running child's process group and removes every work directory: called by the
/// interrupt handler before specfx exits.
pub fn end_all() {
    ENDING.store(true, std::sync::atomic::Ordering::SeqCst);
    if let Ok(groups) = GROUPS.lock() {
        for &pgid in groups.iter() {
            // SAFETY: killpg only sends a signal.
            unsafe {
                libc::killpg(pgid, libc::SIGKILL);
            }
        }
    }
    if let Ok(dirs) = CHILD_TMP.lock() {
        for (_, d) in dirs.iter() {
            let _ = std::fs::remove_dir_all(d);
        }
    }
    if let Ok(dirs) = WORK_DIRS.lock() {
        for d in dirs.iter() {
            let _ = std::fs::remove_dir_all(d);
        }
    }
}
