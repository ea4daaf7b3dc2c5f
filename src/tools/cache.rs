//! The synthesis cache: what yosys and nextpnr answered for exactly these inputs, kept so
//! that the same synthesis is not run twice (a report, a sweep's front, the optimiser's
//! yosys objective and the test suite repeat many). An entry is found by the sha256 of
//! everything the tool reads (its version, its script, every source file's bytes), holds
//! the files specfx reads back from the tool (`stat.json`, nextpnr's `report.json`), and is
//! only ever written whole (a directory renamed into place); only a synthesis that succeeded
//! is kept. Tools are deterministic on the same inputs, so a result from the cache is the
//! result the tool would give: every figure and file is the same with and without it.
//!
//! Where: `$SPECFX_CACHE` (`off` or empty: no cache), else `$XDG_CACHE_HOME/specfx`, else
//! `$HOME/.cache/specfx`. A cache that cannot be read or written is as if there were none.
//!
//! Two processes (or threads) that need the same entry at once run the tool once: the first
//! claims the entry (a `<key>.claim` file naming its process) while it runs the tool, and the
//! others wait for the entry it keeps ([`get_or_claim`]). A claim whose process is gone is
//! taken over; a tool that fails keeps nothing, and the next in line runs it.
//!
//! Waiting is bounded: a claim that is not a regular file (a directory, say) or that cannot be
//! removed when stale, and a live claimant that has not kept its entry after [`WAIT_LIMIT`],
//! make the caller run the tool itself without the cache, with a warning naming the claim
//! file to remove. A figure is then the same, only not shared.

use std::path::{Path, PathBuf};

use sha2::{Digest, Sha256};

/// The cache directory, if any (see the module's documentation).
pub fn dir() -> Option<PathBuf> {
    match std::env::var_os("SPECFX_CACHE") {
        Some(v) if v.is_empty() || v == "off" => None,
        Some(v) => Some(PathBuf::from(v)),
        None => std::env::var_os("XDG_CACHE_HOME")
            .filter(|v| !v.is_empty())
            .map(PathBuf::from)
            .or_else(|| {
                std::env::var_os("HOME")
                    .filter(|v| !v.is_empty())
                    .map(|h| PathBuf::from(h).join(".cache"))
            })
            .map(|d| d.join("specfx")),
    }
}

/// The key of an entry: the sha256 of `parts`, each length-prefixed (so that no two lists
/// of parts give the same bytes), in hex.
pub fn key(parts: &[&[u8]]) -> String {
    let mut h = Sha256::new();
    for p in parts {
        h.update((p.len() as u64).to_le_bytes());
        h.update(p);
    }
    h.finalize().iter().map(|b| format!("{b:02x}")).collect()
}

/// The entry's directory: `<cache>/<kind>/<key>`.
fn entry(kind: &str, key: &str) -> Option<PathBuf> {
    Some(dir()?.join(kind).join(key))
}

/// The files `names` of the entry `kind`/`key`, when it is there and holds each of them
/// (`None` for a name it lacks only when every other is there: optional outputs).
pub fn get(kind: &str, key: &str, names: &[&str]) -> Option<Vec<Option<Vec<u8>>>> {
    get_at(&entry(kind, key)?, names)
}

/// [`get`] for the entry directory `dir`.
fn get_at(dir: &Path, names: &[&str]) -> Option<Vec<Option<Vec<u8>>>> {
    if !dir.is_dir() {
        return None;
    }
    let files: Vec<Option<Vec<u8>>> = names
        .iter()
        .map(|n| std::fs::read(dir.join(n)).ok())
        .collect();
    // An entry holds at least its first file.
    files.first()?.as_ref()?;
    Some(files)
}

/// The right to compute an entry, held while this process runs the tool: others asking for
/// the same entry wait ([`get_or_claim`]). Released when dropped, after [`put`].
#[derive(Debug)]
pub struct Claim {
    file: Option<PathBuf>,
}

impl Drop for Claim {
    fn drop(&mut self) {
        if let Some(f) = &self.file {
            let _ = std::fs::remove_file(f);
            if let Ok(mut held) = HELD.lock() {
                held.retain(|h| h != f);
            }
        }
    }
}

/// A process as a claim names it: its number and its start time (in clock ticks since boot,
/// from `/proc/<pid>/stat`), or None when there is no such process.
fn owner_of(pid: u32) -> Option<String> {
    let stat = std::fs::read_to_string(format!("/proc/{pid}/stat")).ok()?;
    // The command name (field 2) is in parentheses and may hold spaces: fields count from the
    // last ')'; the start time is field 22.
    let rest = &stat[stat.rfind(')')? + 1..];
    let start = rest.split_whitespace().nth(19)?;
    Some(format!("{pid} {start}"))
}

/// The claims this process holds, removed by [`release_all`] (an interrupt handler's work).
static HELD: std::sync::Mutex<Vec<PathBuf>> = std::sync::Mutex::new(Vec::new());

/// Removes every claim this process holds: for an interrupt handler, since the process then
/// exits without dropping them. (A claim left by a killed process is taken over anyway.)
pub fn release_all() {
    if let Ok(held) = HELD.lock() {
        for f in held.iter() {
            let _ = std::fs::remove_file(f);
        }
    }
}

/// How often a process waiting for another's entry looks again.
const WAIT_POLL: std::time::Duration = std::time::Duration::from_millis(50);

/// The longest a caller waits for another live process's entry (the slowest syntheses take
/// minutes) before it runs the tool itself, without the cache: 30 minutes.
pub const WAIT_LIMIT: std::time::Duration = std::time::Duration::from_secs(30 * 60);

/// The entry `kind`/`key` ([`get`]'s files) when it is there, or when another live process
/// that claimed it keeps it meanwhile (waiting for it); else a [`Claim`] for this caller to
/// run the tool and [`put`] the entry (without a cache, a claim that holds nothing).
pub fn get_or_claim(kind: &str, key: &str, names: &[&str]) -> Result<Vec<Option<Vec<u8>>>, Claim> {
    match entry(kind, key) {
        Some(dest) => get_or_claim_at(&dest, names, WAIT_LIMIT),
        None => Err(Claim { file: None }),
    }
}

/// A claim this caller cannot wait on or take over: the tool runs here without the cache (a
/// claim that holds nothing), and the warning says which file to remove.
fn without_cache(claim_file: &Path, why: &str) -> Claim {
    log::warn!(
        "synthesis cache: {why}; running the tool here without the cache (remove {} if no other specfx run is using it)",
        claim_file.display()
    );
    Claim { file: None }
}

/// [`get_or_claim`] for the entry directory `dest`, waiting at most `limit` for another live
/// process's entry.
fn get_or_claim_at(
    dest: &Path,
    names: &[&str],
    limit: std::time::Duration,
) -> Result<Vec<Option<Vec<u8>>>, Claim> {
    let claim_file = dest.with_extension("claim");
    let mut said = false;
    let started = std::time::Instant::now();
    loop {
        if let Some(files) = get_at(dest, names) {
            return Ok(files);
        }
        if dest
            .parent()
            .is_none_or(|p| std::fs::create_dir_all(p).is_err())
        {
            return Err(Claim { file: None });
        }
        let created = std::fs::OpenOptions::new()
            .write(true)
            .create_new(true)
            .open(&claim_file);
        match created {
            Ok(mut f) => {
                use std::io::Write as _;
                let _ = write!(f, "{}", owner_of(std::process::id()).unwrap_or_default());
                // The entry may have been kept between the look above and the claim.
                if let Some(files) = get_at(dest, names) {
                    let _ = std::fs::remove_file(&claim_file);
                    return Ok(files);
                }
                if let Ok(mut held) = HELD.lock() {
                    held.push(claim_file.clone());
                }
                return Err(Claim {
                    file: Some(claim_file),
                });
            }
            Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => {
                // Not a file specfx writes: nothing to read, wait on or take over.
                if let Ok(meta) = std::fs::symlink_metadata(&claim_file) {
                    if !meta.is_file() {
                        let kind = if meta.is_dir() {
                            "a directory"
                        } else {
                            "not a regular file"
                        };
                        return Err(without_cache(
                            &claim_file,
                            &format!("the claim {} is {kind}", claim_file.display()),
                        ));
                    }
                }
                let owner = std::fs::read_to_string(&claim_file).ok();
                // The claim names its process by number and start time, so a number the
                // system gave to another process since is not taken for the claimant.
                let alive = owner.as_deref().is_some_and(|t| {
                    t.trim()
                        .split_once(' ')
                        .and_then(|(pid, _)| pid.parse::<u32>().ok())
                        .is_some_and(|pid| owner_of(pid).as_deref() == Some(t.trim()))
                });
                // A claim being written has no number yet: it gets a few seconds.
                let unwritten = owner.as_deref().is_none_or(str::is_empty);
                let old = std::fs::metadata(&claim_file)
                    .and_then(|m| m.modified())
                    .is_ok_and(|t| t.elapsed().is_ok_and(|e| e.as_secs() > 10));
                if (!unwritten && !alive) || (unwritten && old) {
                    match std::fs::remove_file(&claim_file) {
                        Ok(()) => continue,
                        Err(e) if e.kind() == std::io::ErrorKind::NotFound => continue,
                        Err(e) => {
                            return Err(without_cache(
                                &claim_file,
                                &format!(
                                    "the stale claim {} cannot be removed: {e}",
                                    claim_file.display()
                                ),
                            ));
                        }
                    }
                }
                let who = owner
                    .as_deref()
                    .and_then(|t| t.split_whitespace().next())
                    .map_or("another process".to_string(), |pid| {
                        format!("process {pid}")
                    });
                if started.elapsed() >= limit {
                    return Err(without_cache(
                        &claim_file,
                        &format!(
                            "{who} claimed this synthesis ({}) and has not finished it after {} s",
                            claim_file.display(),
                            limit.as_secs()
                        ),
                    ));
                }
                if !said {
                    log::info!(
                        "waiting for {who}, another specfx run of the same synthesis (its claim {}), at most {} s",
                        claim_file.display(),
                        limit.as_secs()
                    );
                    said = true;
                }
                std::thread::sleep(WAIT_POLL);
            }
            // A cache that cannot be written is as if there were none.
            Err(_) => return Err(Claim { file: None }),
        }
    }
}

/// Keeps `files` (`(name, bytes)`) as the entry `kind`/`key`: written into a temporary
/// directory of the cache, then renamed into place whole. An entry already there (another
/// process's, for the same inputs) stays; any failure leaves the cache as it was.
pub fn put(kind: &str, key: &str, files: &[(&str, &[u8])]) {
    if let Some(dest) = entry(kind, key) {
        put_at(&dest, files);
    }
}

/// [`put`] for the entry directory `dest`.
fn put_at(dest: &Path, files: &[(&str, &[u8])]) {
    let Some(parent) = dest.parent() else {
        return;
    };
    if dest.exists() || std::fs::create_dir_all(parent).is_err() {
        return;
    }
    let Ok(tmp) = tempfile::Builder::new().prefix(".new-").tempdir_in(parent) else {
        return;
    };
    let written = files
        .iter()
        .all(|(name, bytes)| std::fs::write(tmp.path().join(name), bytes).is_ok());
    if written && std::fs::rename(tmp.path(), dest).is_ok() {
        // Renamed: nothing left for the temporary directory's drop to remove.
        let _ = tmp.keep();
    }
}

/// The bytes of a file the tool reads, for a key (empty when it cannot be read: the tool
/// would then fail, and a failure is never kept).
pub fn file_bytes(path: &Path) -> Vec<u8> {
    std::fs::read(path).unwrap_or_default()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_second_caller_waits_for_the_entry_the_first_keeps() {
        let tmp = tempfile::tempdir().unwrap();
        let dest = tmp.path().join("yosys").join("k");
        let claim = get_or_claim_at(&dest, &["a"], WAIT_LIMIT).expect_err("nothing there yet");
        assert!(dest.with_extension("claim").is_file());
        std::thread::scope(|s| {
            let waiter = s.spawn(|| get_or_claim_at(&dest, &["a"], WAIT_LIMIT));
            std::thread::sleep(5 * WAIT_POLL);
            assert!(!waiter.is_finished(), "it waits while the claim is held");
            put_at(&dest, &[("a", b"answer")]);
            drop(claim);
            let got = waiter.join().unwrap().expect("the kept entry");
            assert_eq!(got, [Some(b"answer".to_vec())]);
        });
        assert!(!dest.with_extension("claim").exists());
    }

    #[test]
    fn a_failed_run_lets_the_next_caller_run_the_tool() {
        let tmp = tempfile::tempdir().unwrap();
        let dest = tmp.path().join("k");
        let first = get_or_claim_at(&dest, &["a"], WAIT_LIMIT).expect_err("nothing there yet");
        std::thread::scope(|s| {
            let waiter = s.spawn(|| get_or_claim_at(&dest, &["a"], WAIT_LIMIT).is_err());
            std::thread::sleep(5 * WAIT_POLL);
            // The tool failed: no entry, the claim goes.
            drop(first);
            assert!(waiter.join().unwrap(), "the waiter claims it in turn");
        });
    }

    /// Runs `get_or_claim_at` on another thread and returns its answer, or panics when it has
    /// not returned within a minute: the old loop never returned on these claims.
    fn bounded(dest: &Path, limit: std::time::Duration) -> Result<Vec<Option<Vec<u8>>>, Claim> {
        let (tx, rx) = std::sync::mpsc::channel();
        let dest = dest.to_path_buf();
        std::thread::spawn(move || {
            let _ = tx.send(get_or_claim_at(&dest, &["a"], limit));
        });
        rx.recv_timeout(std::time::Duration::from_secs(60))
            .expect("get_or_claim returns: it must not spin or wait forever")
    }

    #[test]
    fn a_claim_that_is_a_directory_runs_the_tool_without_the_cache() {
        let tmp = tempfile::tempdir().unwrap();
        let dest = tmp.path().join("k");
        let claim_dir = dest.with_extension("claim");
        std::fs::create_dir(&claim_dir).unwrap();
        // Older than the grace of an unwritten claim, as the spinning loop found it.
        let old = std::time::SystemTime::now() - std::time::Duration::from_secs(3600);
        std::fs::File::open(&claim_dir)
            .unwrap()
            .set_modified(old)
            .unwrap();
        let claim = bounded(&dest, WAIT_LIMIT).expect_err("no entry");
        assert_eq!(claim.file, None, "it holds nothing");
        assert!(claim_dir.is_dir(), "the directory is left for the user");
    }

    #[test]
    fn a_live_claimant_is_waited_for_at_most_the_limit() {
        let tmp = tempfile::tempdir().unwrap();
        let dest = tmp.path().join("k");
        // This very process as the claimant: alive, and it never keeps the entry.
        let mine = owner_of(std::process::id()).unwrap();
        std::fs::write(dest.with_extension("claim"), &mine).unwrap();
        let claim = bounded(&dest, 3 * WAIT_POLL).expect_err("no entry");
        assert_eq!(claim.file, None, "it holds nothing");
        assert_eq!(
            std::fs::read_to_string(dest.with_extension("claim")).unwrap(),
            mine,
            "the other's claim is left alone"
        );
    }

    #[test]
    fn a_claim_whose_process_is_gone_is_taken_over() {
        let tmp = tempfile::tempdir().unwrap();
        let dest = tmp.path().join("k");
        // No process has this number (above the kernel's pid limit).
        std::fs::write(dest.with_extension("claim"), "4194305 1").unwrap();
        let claim = get_or_claim_at(&dest, &["a"], WAIT_LIMIT).expect_err("taken over");
        drop(claim);
        // This process's number with another start time: the number was given again.
        let mine = owner_of(std::process::id()).unwrap();
        let pid = mine.split(' ').next().unwrap();
        std::fs::write(dest.with_extension("claim"), format!("{pid} 1")).unwrap();
        let claim = get_or_claim_at(&dest, &["a"], WAIT_LIMIT).expect_err("taken over");
        assert_eq!(
            std::fs::read_to_string(dest.with_extension("claim")).unwrap(),
            owner_of(std::process::id()).unwrap()
        );
        drop(claim);
    }
}
