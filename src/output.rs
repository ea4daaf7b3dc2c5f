//! Result files on disk: files written all or none, result directories staged beside their
//! final path and committed by one rename, and outputs checked before any work.

use std::fs;
use std::io::Write as _;
use std::path::{Path, PathBuf};

use crate::error::Error;

/// The library's results on disk fail with [`Error::Output`]: `context` followed, as one
/// line, by the error and each of its sources.
fn failed(context: String, e: &dyn std::error::Error) -> Error {
    let mut message = format!("{context}: {e}");
    let mut source = e.source();
    while let Some(s) = source {
        message.push_str(&format!(": {s}"));
        source = s.source();
    }
    Error::Output { message }
}

/// A refusal with no underlying error.
fn refused(message: String) -> Error {
    Error::Output { message }
}

type Result<T> = std::result::Result<T, Error>;

/// Returns a refusal (`format!` arguments) from the function.
macro_rules! bail {
    ($($arg:tt)*) => {
        return Err(refused(format!($($arg)*)))
    };
}

/// Writes `bytes` to `path` through a temporary file in the same directory (a unique
/// `.<name>.<random>.tmp`, removed on failure) and a rename, so an interrupted run never
/// leaves a half-written file under the final name. A directory at `path` is refused.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    persist(path, path, stage(path, path, bytes)?)
}

/// Writes several files all or none: every file to its temporary name first, then each
/// renamed into place (a rename needs no space). The files' directories are created as
/// needed; when one file cannot be written, none is, and the directories created for them are
/// removed again.
pub fn write_all_atomic(files: &[(PathBuf, Vec<u8>)]) -> Result<()> {
    write_all(files, &|p: &Path| p.to_path_buf())
}

/// A result rendered in memory, `(name, bytes)` with names relative to `dir` (`a/b.png`),
/// written into `dir` by one call, all or none ([`write_all_atomic`]).
pub fn write_all_in(dir: &Path, files: &[(String, Vec<u8>)]) -> Result<()> {
    write_all_shown(dir, dir, files)
}

/// [`write_all_in`] into `dir`, its messages naming the files in `shown` (the final directory
/// of a staged one).
pub fn write_all_shown(dir: &Path, shown: &Path, files: &[(String, Vec<u8>)]) -> Result<()> {
    let files: Vec<(PathBuf, Vec<u8>)> = files
        .iter()
        .map(|(name, bytes)| (dir.join(name), bytes.clone()))
        .collect();
    let show = |p: &Path| {
        p.strip_prefix(dir)
            .map_or(p.to_path_buf(), |r| shown.join(r))
    };
    write_all(&files, &show)
}

/// [`write_all_atomic`], its messages naming each path as `show` gives it.
fn write_all(files: &[(PathBuf, Vec<u8>)], show: &dyn Fn(&Path) -> PathBuf) -> Result<()> {
    let mut missing: Vec<PathBuf> = Vec::new();
    for (path, _) in files {
        for d in parent_of(path).ancestors() {
            if d.as_os_str().is_empty() || d.exists() {
                break;
            }
            if !missing.iter().any(|m| m == d) {
                missing.push(d.to_path_buf());
            }
        }
    }
    let staged = files
        .iter()
        .try_for_each(|(path, _)| {
            let dir = parent_of(path);
            fs::create_dir_all(dir)
                .map_err(|e| failed(format!("cannot create {}", show(dir).display()), &e))
        })
        .and_then(|()| {
            files
                .iter()
                .map(|(path, bytes)| stage(path, &show(path), bytes).map(|tmp| (path, tmp)))
                .collect::<Result<Vec<_>>>()
        });
    let staged = match staged {
        Ok(s) => s,
        Err(e) => {
            // Deepest first; a directory something else wrote into meanwhile stays.
            missing.sort_by_key(|d| std::cmp::Reverse(d.components().count()));
            for d in &missing {
                let _ = fs::remove_dir(d);
            }
            return Err(e);
        }
    };
    for (path, tmp) in staged {
        persist(path, &show(path), tmp)?;
    }
    Ok(())
}

/// `bytes` in a temporary file beside `path` (see [`write_atomic`]), not yet renamed;
/// messages name it `shown`.
fn stage(path: &Path, shown: &Path, bytes: &[u8]) -> Result<tempfile::NamedTempFile> {
    log::debug!("writing {} ({} bytes)", shown.display(), bytes.len());
    let dir = parent_of(path);
    let file_name = path
        .file_name()
        .ok_or_else(|| refused(format!("{}: not a file path", shown.display())))?;
    if path.is_dir() {
        bail!("{}: is a directory, expected a file path", shown.display());
    }
    let prefix = format!(".{}.", file_name.to_string_lossy());
    let mut builder = tempfile::Builder::new();
    builder.prefix(&prefix).suffix(".tmp");
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt as _;
        builder.permissions(fs::Permissions::from_mode(0o644));
    }
    let mut tmp = builder.tempfile_in(dir).map_err(|e| {
        failed(
            format!("cannot write into {}", parent_of(shown).display()),
            &e,
        )
    })?;
    tmp.write_all(bytes)
        .and_then(|()| tmp.flush())
        .map_err(|e| failed(format!("cannot write {}", shown.display()), &e))?;
    Ok(tmp)
}

/// Renames a staged file into place; messages name it `shown`.
fn persist(path: &Path, shown: &Path, tmp: tempfile::NamedTempFile) -> Result<()> {
    tmp.persist(path)
        .map(|_| ())
        .map_err(|e| e.error)
        .map_err(|e| failed(format!("cannot write {}", shown.display()), &e))
}

/// The result directories this process committed, newest last: an error after a commit (a
/// summary that cannot reach a full stdout) says that the result is nevertheless complete.
static COMMITTED: std::sync::Mutex<Vec<PathBuf>> = std::sync::Mutex::new(Vec::new());

/// The result directory this process committed last, if any.
pub fn last_committed() -> Option<PathBuf> {
    COMMITTED.lock().ok().and_then(|c| c.last().cloned())
}

/// The name of the marker file every result directory holds: it says which specfx command
/// wrote the directory, so that the command may replace its own earlier result.
pub const MARKER: &str = ".specfx-result";

/// The specfx command whose result `dir` holds: its [`MARKER`]'s first line (`sweep plan`,
/// `report`), or `None` where there is no marker.
pub fn result_of(dir: &Path) -> Option<String> {
    let marker = std::fs::read_to_string(dir.join(MARKER)).ok()?;
    Some(marker.lines().next().unwrap_or("").trim().to_string())
}

/// Staging directories of this process not yet committed, removed on Ctrl-C or SIGTERM.
static STAGING: std::sync::Mutex<Vec<PathBuf>> = std::sync::Mutex::new(Vec::new());

/// Removes this process's staging directories not yet committed (an interrupt handler's work:
/// the previous results stay as they were).
pub fn remove_uncommitted() {
    if let Ok(dirs) = STAGING.lock() {
        for d in dirs.iter() {
            let _ = std::fs::remove_dir_all(d);
        }
    }
}

/// A result directory that is complete or absent: everything is written into a staging
/// directory beside it (`.<name>.partial-<pid>`), renamed onto the final path by
/// [`OutDir::commit`]. Dropped without a commit (an error), the staging directory is removed;
/// killed, it is left hidden beside the result and removed by the next run.
///
/// An existing directory is replaced only when it is empty, an earlier result of the same
/// command (it holds the [`MARKER`]) or with `force`; anything else there is refused.
pub struct OutDir {
    target: PathBuf,
    staging: PathBuf,
    done: bool,
    /// Kept when the run does not finish (a resumable result), instead of removed.
    keep: bool,
}

impl OutDir {
    /// Starts writing the result of `command` for `target`, after checking that it would
    /// replace none of the command's `inputs` (see [`refuse_over_inputs`]).
    pub fn begin(
        target: &Path,
        command: &str,
        force: bool,
        inputs: &[(&str, PathBuf)],
    ) -> Result<OutDir> {
        Ok(OutDir::start(target, command, force, inputs, None)?.0)
    }

    /// Like [`OutDir::begin`], for a result that can be resumed: unless `restart`, the staging
    /// directory an interrupted or killed run of `command` left for `target` is taken over
    /// (renamed to this process's; the newest when there are several), and this run's staging
    /// directory is kept, not removed, when the run ends without a commit (an error, Ctrl-C,
    /// SIGTERM). Returns whether a directory was taken over.
    pub fn begin_resumable(
        target: &Path,
        command: &str,
        force: bool,
        inputs: &[(&str, PathBuf)],
        restart: bool,
    ) -> Result<(OutDir, bool)> {
        OutDir::start(target, command, force, inputs, Some(restart))
    }

    /// [`OutDir::begin`] (`resume` None) and [`OutDir::begin_resumable`] (`Some(restart)`).
    fn start(
        target: &Path,
        command: &str,
        force: bool,
        inputs: &[(&str, PathBuf)],
        resume: Option<bool>,
    ) -> Result<(OutDir, bool)> {
        // `dir/` and `dir/.` name `dir` (components() drops a trailing `.`); `.`, `..` and
        // `dir/..` have no name of their own and are refused below.
        let target = &target.components().collect::<PathBuf>();
        refuse_over_inputs(target, "--out", inputs)?;
        refuse_looping_link(target, "--out")?;
        let name = target
            .file_name()
            .ok_or_else(|| refused(format!("{}: expected a directory name", target.display())))?
            .to_string_lossy()
            .into_owned();
        let parent = match target.parent() {
            Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
            _ => PathBuf::from("."),
        };
        // A run killed between moving the previous result aside and renaming its own into
        // place left the previous result as `.<name>.old-<pid>`: it is put back first.
        if !target.exists() && !target.is_symlink() {
            let moved_aside = stale(&parent, &name)
                .into_iter()
                .find(|(p, partial)| !partial && p.join(MARKER).is_file());
            if let Some((old, _)) = moved_aside {
                let _ = std::fs::rename(old, target);
            }
        }
        if target.exists() || target.is_symlink() {
            if !target.is_dir() {
                bail!(
                    "{}: exists and is not a directory (pass another --out)",
                    target.display()
                );
            }
            let empty = std::fs::read_dir(target).is_ok_and(|mut d| d.next().is_none());
            let holder = result_of(target);
            if !force && !empty && holder.as_deref() != Some(command) {
                // What a run computed is never replaced at a message's suggestion: only a
                // directory of the user's own is offered to --force.
                match holder {
                    Some(other) => bail!(
                        "{} holds a `specfx {other}` result, not an earlier `specfx {command}` one: choose another --out, or move it away first",
                        target.display()
                    ),
                    None => bail!(
                        "{} already exists and is not an earlier `specfx {command}` result: pass --force to replace it",
                        target.display()
                    ),
                }
            }
            probe_move_aside(target, &parent, &name)?;
        }
        std::fs::create_dir_all(&parent)
            .map_err(|e| failed(format!("cannot create {}", parent.display()), &e))?;
        let staging = parent.join(format!(".{name}.partial-{}", std::process::id()));
        if std::fs::symlink_metadata(&staging).is_ok() {
            if !ours(&staging) {
                bail!(
                    "{}: exists and is not a staging directory specfx made; remove it or pass another --out",
                    staging.display()
                );
            }
            std::fs::remove_dir_all(&staging)
                .map_err(|e| failed(format!("cannot remove {}", staging.display()), &e))?;
        }
        // The newest unfinished run of the same command, taken over by a rename (of two runs
        // racing for it, one gets it and the other starts afresh).
        let resumed = resume == Some(false)
            && stale(&parent, &name)
                .into_iter()
                .filter(|(p, partial)| {
                    *partial && p.is_dir() && result_of(p).as_deref() == Some(command)
                })
                .max_by_key(|(p, _)| {
                    std::fs::metadata(p)
                        .and_then(|m| m.modified())
                        .unwrap_or(std::time::SystemTime::UNIX_EPOCH)
                })
                .is_some_and(|(p, _)| std::fs::rename(&p, &staging).is_ok());
        remove_stale(&parent, &name);
        if !resumed {
            std::fs::create_dir(&staging)
                .map_err(|e| failed(format!("cannot create {}", staging.display()), &e))?;
        }
        let keep = resume.is_some();
        if !keep {
            STAGING.lock().expect("staging list").push(staging.clone());
        }
        let out = OutDir {
            target: target.to_path_buf(),
            staging,
            done: false,
            keep,
        };
        std::fs::write(out.staging.join(MARKER), format!("{command}\n"))
            .map_err(|e| failed(format!("cannot write into {}", out.staging.display()), &e))?;
        Ok((out, resumed))
    }

    /// Where to write the result's files.
    pub fn path(&self) -> &Path {
        &self.staging
    }

    /// Puts the finished result in place of the target (and of an earlier result there).
    pub fn commit(mut self) -> Result<()> {
        let old = self.staging.with_file_name(
            self.staging
                .file_name()
                .expect("a staging name")
                .to_string_lossy()
                .replace(".partial-", ".old-"),
        );
        let had_old = self.target.exists();
        if had_old {
            std::fs::rename(&self.target, &old)
                .map_err(|e| failed(format!("cannot move {} aside", self.target.display()), &e))?;
        }
        if let Err(e) = std::fs::rename(&self.staging, &self.target) {
            if had_old {
                let _ = std::fs::rename(&old, &self.target);
            }
            return Err(failed(
                format!(
                    "cannot rename {} to {}",
                    self.staging.display(),
                    self.target.display()
                ),
                &e,
            ));
        }
        log::debug!("{} complete", self.target.display());
        if let Ok(mut committed) = COMMITTED.lock() {
            committed.push(self.target.clone());
        }
        self.done = true;
        self.unregister();
        if had_old {
            let _ = std::fs::remove_dir_all(&old);
        }
        Ok(())
    }

    fn unregister(&self) {
        if let Ok(mut dirs) = STAGING.lock() {
            dirs.retain(|d| d != &self.staging);
        }
    }
}

impl Drop for OutDir {
    fn drop(&mut self) {
        if !self.done && !self.keep {
            let _ = std::fs::remove_dir_all(&self.staging);
            self.unregister();
        }
    }
}

/// Checks before any work that the existing result `target` can be moved aside when the new
/// one is committed: renamed to its `.<name>.old-<pid>` name and straight back. An immutable
/// directory, a mount point or a read-only mount is refused here, not after the run.
fn probe_move_aside(target: &Path, parent: &Path, name: &str) -> Result<()> {
    let aside = parent.join(format!(".{name}.old-{}", std::process::id()));
    if std::fs::symlink_metadata(&aside).is_ok() {
        // Not ours to touch; the commit would stop at it too.
        bail!(
            "{}: exists beside --out {}; remove it or pass another --out",
            aside.display(),
            target.display()
        );
    }
    std::fs::rename(target, &aside).map_err(|e| {
        failed(
            format!(
                "--out {}: cannot be replaced (moving it aside failed); pass another --out",
                target.display()
            ),
            &e,
        )
    })?;
    std::fs::rename(&aside, target).map_err(|e| {
        failed(
            format!(
                "--out {}: was moved to {} and cannot be moved back",
                target.display(),
                aside.display()
            ),
            &e,
        )
    })
}

/// The `.<name>.partial-<pid>` (true) and `.<name>.old-<pid>` (false) directories left by
/// processes that no longer run (killed mid-write, or resumable results).
fn stale(parent: &Path, name: &str) -> Vec<(PathBuf, bool)> {
    let Ok(entries) = std::fs::read_dir(parent) else {
        return Vec::new();
    };
    let mut found = Vec::new();
    for e in entries.flatten() {
        let file = e.file_name().to_string_lossy().into_owned();
        let tagged = [".partial-", ".old-"].iter().find_map(|tag| {
            file.strip_prefix(&format!(".{name}{tag}"))
                .and_then(|p| p.parse::<u32>().ok())
                .map(|pid| (pid, *tag == ".partial-"))
        });
        if let Some((pid, partial)) = tagged {
            let path = e.path();
            if ours(&path)
                && pid != std::process::id()
                && !Path::new(&format!("/proc/{pid}")).exists()
            {
                found.push((path, partial));
            }
        }
    }
    found.sort();
    found
}

/// Whether `path` is a directory specfx made: a real directory (not a symbolic link) owned by
/// this user, holding its marker as a regular file (or still empty: killed before writing the
/// marker). A user's directory of the same name, or a link to one, is left alone.
fn ours(path: &Path) -> bool {
    let Ok(meta) = std::fs::symlink_metadata(path) else {
        return false;
    };
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt as _;
        // SAFETY: geteuid has no preconditions and cannot fail.
        if meta.uid() != unsafe { libc::geteuid() } {
            return false;
        }
    }
    meta.is_dir()
        && (std::fs::symlink_metadata(path.join(MARKER)).is_ok_and(|m| m.is_file())
            || std::fs::read_dir(path).is_ok_and(|mut d| d.next().is_none()))
}

/// Removes the directories [`stale`] finds.
fn remove_stale(parent: &Path, name: &str) {
    for (path, _) in stale(parent, name) {
        let _ = std::fs::remove_dir_all(path);
    }
}

/// The absolute form of `path` with symbolic links resolved as far as it exists: the path
/// itself when it exists, else its nearest existing ancestor's with the rest appended.
fn resolve(path: &Path) -> PathBuf {
    use std::path::Component;
    let abs = std::path::absolute(path).unwrap_or_else(|_| path.to_path_buf());
    let components: Vec<Component> = abs.components().collect();
    for i in (0..=components.len()).rev() {
        let head: PathBuf = components[..i].iter().collect();
        if let Ok(mut resolved) = head.canonicalize() {
            // What does not exist is no link: the rest applies as written.
            for c in &components[i..] {
                match c {
                    Component::ParentDir => {
                        resolved.pop();
                    }
                    Component::CurDir => {}
                    other => resolved.push(other),
                }
            }
            return resolved;
        }
    }
    abs
}

/// Refuses an output that would replace one of the command's inputs: the same file, or a
/// directory that is or holds an input (a result directory is replaced as a whole). `flag`
/// names the output (`--out`), each input comes with its flag (`--config`). Holds with
/// `--force` too: no command ever writes over what it reads.
pub fn refuse_over_inputs(out: &Path, flag: &str, inputs: &[(&str, PathBuf)]) -> Result<()> {
    let target = resolve(out);
    for (input_flag, input) in inputs {
        if !input.exists() {
            continue;
        }
        let source = resolve(input);
        if source == target {
            bail!(
                "{flag} {}: is the input {input_flag} {}; pass another {flag}",
                out.display(),
                input.display()
            );
        }
        if source.starts_with(&target) {
            bail!(
                "{flag} {}: would replace the directory that holds the input {input_flag} {}; pass another {flag}",
                out.display(),
                input.display()
            );
        }
    }
    Ok(())
}

/// Refuses an output (a file, or a directory written into) that is inside the input directory
/// `input_dir` (a vector directory): no command adds files to what it reads, even with
/// `--force`. Symbolic links and `..` are resolved first.
pub fn refuse_inside_input_dir(
    out: &Path,
    flag: &str,
    input_dir: &Path,
    input_flag: &str,
) -> Result<()> {
    if !input_dir.is_dir() {
        return Ok(());
    }
    if resolve(out).starts_with(resolve(input_dir)) {
        bail!(
            "{flag} {}: is inside the input {input_flag} directory {}, which no command writes into; pass another {flag}",
            out.display(),
            input_dir.display()
        );
    }
    Ok(())
}

/// Checks a single-file output before any work: never one of the inputs (see
/// [`refuse_over_inputs`]), never a directory, and an existing file only when it is an
/// earlier result of the same command (it begins with `own_header`, the first bytes the
/// command writes) or with `force`.
pub fn check_file_output(
    out: &Path,
    flag: &str,
    inputs: &[(&str, PathBuf)],
    own_header: Option<&str>,
    force: bool,
) -> Result<()> {
    refuse_over_inputs(out, flag, inputs)?;
    refuse_looping_link(out, flag)?;
    if out.is_dir() {
        bail!(
            "{flag} {}: is a directory, expected a file path",
            out.display()
        );
    }
    // A device, FIFO or socket is never replaced by a file, even with --force.
    if out.exists() && !out.is_file() {
        bail!(
            "{flag} {}: is not a regular file, expected a file path",
            out.display()
        );
    }
    if !force && (out.exists() || out.is_symlink()) && !begins_with(out, own_header) {
        bail!(
            "{flag} {}: already exists and is not an earlier result of this command; pass --force to replace it",
            out.display()
        );
    }
    let dir = parent_of(out);
    if !dir.is_dir() {
        bail!(
            "{flag} {}: its directory {} does not exist",
            out.display(),
            dir.display()
        );
    }
    probe(dir, out, flag)
}

/// Checks before any work the files a command will write into the directory `dir`, which it
/// creates when missing: each as [`check_file_output`] when `dir` exists, else that `dir` can
/// be created.
pub fn check_files_in(
    dir: &Path,
    names: &[&str],
    flag: &str,
    inputs: &[(&str, PathBuf)],
    own_header: Option<&str>,
    force: bool,
) -> Result<()> {
    if !dir.is_dir() {
        return check_can_create(dir, flag);
    }
    for name in names {
        check_file_output(&dir.join(name), flag, inputs, own_header, force)?;
    }
    Ok(())
}

/// The directory a path is in (`.` for a bare name).
fn parent_of(path: &Path) -> &Path {
    match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    }
}

/// Checks before any work that the directory `dir` can be created (or, if it exists, written
/// into): its nearest existing ancestor is a directory that takes a new entry.
pub fn check_can_create(dir: &Path, flag: &str) -> Result<()> {
    refuse_looping_link(dir, flag)?;
    let existing = dir
        .ancestors()
        .find(|d| d.as_os_str().is_empty() || d.exists())
        .map(|d| {
            if d.as_os_str().is_empty() {
                Path::new(".")
            } else {
                d
            }
        })
        .unwrap_or(Path::new("."));
    if !existing.is_dir() {
        bail!(
            "{flag} {}: {} is not a directory",
            dir.display(),
            existing.display()
        );
    }
    probe(existing, dir, flag)
}

/// Refuses an output path that is, or lies under, a symbolic link that loops (`a -> b -> a`):
/// it can neither be written through nor replaced, and the system's own word for it ("File
/// exists", "Too many levels of symbolic links") names neither the link nor the flag.
fn refuse_looping_link(out: &Path, flag: &str) -> Result<()> {
    for link in out.ancestors().filter(|a| !a.as_os_str().is_empty()) {
        let is_link = std::fs::symlink_metadata(link).is_ok_and(|m| m.file_type().is_symlink());
        if is_link && std::fs::metadata(link).is_err_and(|e| e.raw_os_error() == Some(libc::ELOOP))
        {
            bail!(
                "{flag} {}: {} is a symbolic link that loops (too many levels of links): pass another {flag}",
                out.display(),
                link.display()
            );
        }
    }
    Ok(())
}

/// Creates and removes a probe file in `dir`: whether it takes a new entry (permissions, a
/// read-only file system).
fn probe(dir: &Path, out: &Path, flag: &str) -> Result<()> {
    match tempfile::Builder::new()
        .prefix(".specfx-probe.")
        .tempfile_in(dir)
    {
        Ok(_) => Ok(()),
        // The kind only: the error names the probe's random path.
        Err(e) => bail!(
            "{flag} {}: cannot write into {}: {}",
            out.display(),
            dir.display(),
            e.kind()
        ),
    }
}

/// The files a `--config` (or `--vectors`) argument reads: none for a built-in name; the
/// Whether the regular file `path` begins with `header`.
fn begins_with(path: &Path, header: Option<&str>) -> bool {
    use std::io::Read as _;
    let Some(header) = header else {
        return false;
    };
    if !path.is_file() {
        return false;
    }
    let mut head = Vec::with_capacity(header.len());
    fs::File::open(path)
        .and_then(|f| f.take(header.len() as u64).read_to_end(&mut head))
        .is_ok_and(|_| head == header.as_bytes())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_symbolic_link_that_loops_is_refused_by_name() {
        let tmp = tempfile::tempdir().unwrap();
        let (a, b) = (tmp.path().join("a"), tmp.path().join("b"));
        std::os::unix::fs::symlink(&b, &a).unwrap();
        std::os::unix::fs::symlink(&a, &b).unwrap();
        let want = format!(
            "{} is a symbolic link that loops (too many levels of links): pass another --out",
            a.display()
        );
        let errors = [
            OutDir::begin(&a, "report", false, &[]).err().unwrap(),
            OutDir::begin(&a.join("x"), "report", false, &[])
                .err()
                .unwrap(),
            check_file_output(&a, "--out", &[], None, true).unwrap_err(),
            check_can_create(&a.join("x"), "--out").unwrap_err(),
        ];
        for e in errors {
            assert!(e.to_string().contains(&want), "{e}");
        }
        // A link to a directory is an ordinary path.
        let real = tmp.path().join("real");
        std::fs::create_dir(&real).unwrap();
        std::os::unix::fs::symlink(&real, tmp.path().join("link")).unwrap();
        check_can_create(&tmp.path().join("link/x"), "--out").unwrap();
    }

    /// A staging directory a dead process left for `target`, with `command`'s marker.
    fn left(target: &Path, tag: &str, command: &str) -> PathBuf {
        let name = target.file_name().unwrap().to_string_lossy();
        let dir = target.with_file_name(format!(".{name}{tag}999999999"));
        std::fs::create_dir(&dir).unwrap();
        std::fs::write(dir.join(MARKER), format!("{command}\n")).unwrap();
        std::fs::write(dir.join("done.txt"), "kept").unwrap();
        dir
    }

    #[test]
    fn a_link_named_like_a_staging_directory_is_never_taken_over() {
        let tmp = tempfile::tempdir().unwrap();
        let target = tmp.path().join("o");
        // A user's directory that even holds a marker, linked under a dead process's staging
        // name and under a moved-aside name.
        let users = tmp.path().join("users");
        std::fs::create_dir(&users).unwrap();
        std::fs::write(users.join(MARKER), "report\n").unwrap();
        std::fs::write(users.join("notes.txt"), "mine").unwrap();
        for tag in [".partial-", ".old-"] {
            std::os::unix::fs::symlink(&users, tmp.path().join(format!(".o{tag}999999999")))
                .unwrap();
        }
        let (out, resumed) = OutDir::begin_resumable(&target, "report", false, &[], false).unwrap();
        assert!(!resumed);
        assert!(!std::fs::symlink_metadata(out.path()).unwrap().is_symlink());
        std::fs::write(out.path().join("page.html"), "x").unwrap();
        out.commit().unwrap();
        assert!(!std::fs::symlink_metadata(&target).unwrap().is_symlink());
        assert_eq!(
            std::fs::read_to_string(users.join("notes.txt")).unwrap(),
            "mine"
        );
        assert!(!users.join("page.html").exists());
        for tag in [".partial-", ".old-"] {
            let link = tmp.path().join(format!(".o{tag}999999999"));
            assert!(
                std::fs::symlink_metadata(link).unwrap().is_symlink(),
                "left alone"
            );
        }

        // A link at this process's own staging name is refused, not followed or removed.
        let own = tmp
            .path()
            .join(format!(".p.partial-{}", std::process::id()));
        std::os::unix::fs::symlink(&users, &own).unwrap();
        let err = OutDir::begin(&tmp.path().join("p"), "report", false, &[])
            .err()
            .unwrap()
            .to_string();
        assert!(
            err.contains("is not a staging directory specfx made"),
            "{err}"
        );
        assert!(std::fs::symlink_metadata(&own).unwrap().is_symlink());
        assert!(users.join("notes.txt").exists());
    }

    #[test]
    fn a_resumable_result_takes_over_what_an_interrupted_run_left() {
        let tmp = tempfile::tempdir().unwrap();
        let target = tmp.path().join("r");
        let stale = left(&target, ".partial-", "report");
        let (out, resumed) = OutDir::begin_resumable(&target, "report", false, &[], false).unwrap();
        assert!(resumed);
        assert!(!stale.exists());
        assert_eq!(
            std::fs::read_to_string(out.path().join("done.txt")).unwrap(),
            "kept"
        );
        // Not committed: kept for the next run, not removed.
        let kept = out.path().to_path_buf();
        drop(out);
        assert!(kept.exists());
        std::fs::rename(&kept, &stale).unwrap();

        // --restart: the interrupted run's files are removed, not used.
        let (out, resumed) = OutDir::begin_resumable(&target, "report", false, &[], true).unwrap();
        assert!(!resumed && !stale.exists());
        assert!(!out.path().join("done.txt").exists());
        out.commit().unwrap();
        assert!(target.join(MARKER).exists());

        // Another command's staging directory is never taken over.
        let other = left(&target, ".partial-", "stability");
        let (out, resumed) = OutDir::begin_resumable(&target, "report", false, &[], false).unwrap();
        assert!(!resumed && !other.exists());
        assert!(!out.path().join("done.txt").exists());
        drop(out);

        // A plain result is removed when it does not finish.
        let out = OutDir::begin(&target, "report", false, &[]).unwrap();
        let staging = out.path().to_path_buf();
        drop(out);
        assert!(!staging.exists());
    }

    #[test]
    fn a_previous_result_moved_aside_by_a_killed_commit_is_put_back() {
        let tmp = tempfile::tempdir().unwrap();
        let target = tmp.path().join("r");
        let old = left(&target, ".old-", "report");
        let out = OutDir::begin(&target, "report", false, &[]).unwrap();
        assert!(!old.exists());
        assert_eq!(
            std::fs::read_to_string(target.join("done.txt")).unwrap(),
            "kept"
        );
        drop(out);
        assert!(
            target.join("done.txt").exists(),
            "untouched without a commit"
        );

        // A user's directory of that shape, without the marker, is not a result: left alone.
        let other = tmp.path().join("s");
        let theirs = other.with_file_name(".s.old-999999999");
        std::fs::create_dir(&theirs).unwrap();
        std::fs::write(theirs.join("notes.txt"), "mine").unwrap();
        let out = OutDir::begin(&other, "report", false, &[]).unwrap();
        assert!(!other.exists());
        drop(out);
        assert!(theirs.exists());
    }
}
