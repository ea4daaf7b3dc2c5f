//! Resuming a multi-step result (`specfx report`): each long step, once its files are written,
//! leaves a checkpoint in the staging directory; a later run that takes the staging directory
//! over (see [`specfx::output::OutDir::begin_resumable`]) reuses every step whose checkpoint is
//! still true and runs the others.
//!
//! A checkpoint (`.resume/<step>.json`) holds the step's summary (what the rest of the run needs
//! of it), the sha256 of every file the step wrote, and the run's key: the sha256 of the specfx
//! executable and the versions of the external tools the steps use. It is reused only when the
//! key is the same and every file is still there with its hash; everything else in a taken-over
//! staging directory (unfinished steps, temporary files) is removed first, so a resumed result
//! holds the same bytes as one written in a single run.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};

use specfx::output::{write_atomic, MARKER};

/// The directory of the checkpoints inside a staging directory; removed before the commit.
pub const CHECKPOINTS: &str = ".resume";

/// A finished step as it is kept.
#[derive(Serialize, Deserialize)]
struct Checkpoint<T> {
    /// The run's key ([`Resume::key`]).
    key: String,
    /// Every file the step wrote (path relative to the staging directory, `/`-separated) and
    /// its sha256.
    files: BTreeMap<String, String>,
    /// What the rest of the run needs of the step.
    summary: T,
}

/// The checkpoints of one staging directory.
pub struct Resume {
    dir: PathBuf,
    key: String,
    /// The steps found finished and true when the run began.
    reusable: BTreeMap<String, serde_json::Value>,
}

impl Resume {
    /// The checkpoints of `staging` under `key`. When `resumed` (the directory was taken over
    /// from an interrupted run), the still-true checkpoints are kept with their files and
    /// everything else is removed; otherwise the directory is new and holds none.
    pub fn open(staging: &Path, key: String, resumed: bool) -> Result<Resume> {
        let mut reusable = BTreeMap::new();
        let mut keep: Vec<String> = vec![MARKER.to_string(), CHECKPOINTS.to_string()];
        let checkpoints = staging.join(CHECKPOINTS);
        if resumed {
            for entry in std::fs::read_dir(&checkpoints)
                .into_iter()
                .flatten()
                .flatten()
            {
                let path = entry.path();
                let Some(step) = path
                    .file_name()
                    .and_then(|f| f.to_str())
                    .and_then(|f| f.strip_suffix(".json"))
                    .map(str::to_string)
                else {
                    let _ = std::fs::remove_file(&path);
                    continue;
                };
                match still_true(staging, &path, &key) {
                    Some(checkpoint) => {
                        keep.extend(
                            checkpoint
                                .files
                                .keys()
                                .filter_map(|f| f.split('/').next().map(str::to_string)),
                        );
                        reusable.insert(step, checkpoint.summary);
                    }
                    None => {
                        log::debug!("{}: out of date, the step runs again", path.display());
                        let _ = std::fs::remove_file(&path);
                    }
                }
            }
            // Whatever no true checkpoint accounts for was left by an unfinished step.
            for entry in std::fs::read_dir(staging)
                .with_context(|| format!("cannot read {}", staging.display()))?
                .flatten()
            {
                let name = entry.file_name().to_string_lossy().into_owned();
                if !keep.contains(&name) {
                    let path = entry.path();
                    let removed = if path.is_dir() && !path.is_symlink() {
                        std::fs::remove_dir_all(&path)
                    } else {
                        std::fs::remove_file(&path)
                    };
                    removed.with_context(|| format!("cannot remove {}", path.display()))?;
                }
            }
        }
        std::fs::create_dir_all(&checkpoints)
            .with_context(|| format!("cannot create {}", checkpoints.display()))?;
        Ok(Resume {
            dir: staging.to_path_buf(),
            key,
            reusable,
        })
    }

    /// How many finished steps this run reuses.
    pub fn n_reusable(&self) -> usize {
        self.reusable.len()
    }

    /// The summary of `step` when an interrupted run finished it, else `run()`'s, after which
    /// the step's `parts` (files and directories relative to the staging directory) are
    /// checkpointed. A step that runs again starts from no files of its own.
    pub fn step<T: Serialize + DeserializeOwned>(
        &mut self,
        step: &str,
        parts: &[&str],
        run: impl FnOnce() -> Result<T>,
    ) -> Result<T> {
        if let Some(value) = self.reusable.remove(step) {
            if let Ok(summary) = serde_json::from_value(value) {
                log::info!("specfx report: reusing '{step}' from the interrupted run");
                return Ok(summary);
            }
        }
        for part in parts {
            let path = self.dir.join(part);
            if path.is_dir() {
                std::fs::remove_dir_all(&path)
                    .with_context(|| format!("cannot remove {}", path.display()))?;
            }
        }
        let summary = run()?;
        let mut files = BTreeMap::new();
        for part in parts {
            hash_tree(&self.dir, &self.dir.join(part), &mut files)?;
        }
        let checkpoint = Checkpoint {
            key: self.key.clone(),
            files,
            summary,
        };
        let text = serde_json::to_vec(&checkpoint).context("a checkpoint serialises")?;
        write_atomic(
            &self.dir.join(CHECKPOINTS).join(format!("{step}.json")),
            &text,
        )?;
        Ok(checkpoint.summary)
    }

    /// Removes the checkpoints: done before the result is committed, which then holds only
    /// its files.
    pub fn finish(self) -> Result<()> {
        let dir = self.dir.join(CHECKPOINTS);
        std::fs::remove_dir_all(&dir).with_context(|| format!("cannot remove {}", dir.display()))
    }
}

/// The checkpoint at `path` when it reads, has `key`, and every file it lists is in `staging`
/// with its hash.
fn still_true(staging: &Path, path: &Path, key: &str) -> Option<Checkpoint<serde_json::Value>> {
    let text = std::fs::read(path).ok()?;
    let checkpoint: Checkpoint<serde_json::Value> = serde_json::from_slice(&text).ok()?;
    if checkpoint.key != key || checkpoint.files.is_empty() {
        return None;
    }
    for (file, want) in &checkpoint.files {
        if file
            .split('/')
            .any(|c| c.is_empty() || c == "." || c == "..")
        {
            return None;
        }
        let bytes = std::fs::read(staging.join(file)).ok()?;
        if &sha256_hex(&bytes) != want {
            return None;
        }
    }
    // No file the step did not write may hide among its parts (a temporary file of a step that
    // ran again and was interrupted): the listed files must be all of them.
    let mut found = BTreeMap::new();
    let parts: std::collections::BTreeSet<&str> = checkpoint
        .files
        .keys()
        .filter_map(|f| f.split('/').next())
        .collect();
    for part in parts {
        hash_tree(staging, &staging.join(part), &mut found).ok()?;
    }
    (found == checkpoint.files).then_some(checkpoint)
}

/// Adds every file under `path` (or `path` itself), relative to `root`, with its sha256. Only
/// real directories and regular files count: a symbolic link (which would make the result
/// point outside itself) or any other kind of file is an error, so a checkpoint holding one is
/// never reused.
fn hash_tree(root: &Path, path: &Path, out: &mut BTreeMap<String, String>) -> Result<()> {
    let kind = std::fs::symlink_metadata(path)
        .with_context(|| format!("cannot read {}", path.display()))?
        .file_type();
    if !kind.is_dir() && !kind.is_file() {
        anyhow::bail!("{}: is not a regular file or directory", path.display());
    }
    if kind.is_dir() {
        let mut entries: Vec<PathBuf> = std::fs::read_dir(path)
            .with_context(|| format!("cannot read {}", path.display()))?
            .map(|e| e.map(|e| e.path()))
            .collect::<std::io::Result<_>>()
            .with_context(|| format!("cannot read {}", path.display()))?;
        entries.sort();
        for e in entries {
            hash_tree(root, &e, out)?;
        }
    } else {
        let bytes =
            std::fs::read(path).with_context(|| format!("cannot read {}", path.display()))?;
        let rel = path
            .strip_prefix(root)
            .expect("under the staging directory")
            .components()
            .map(|c| c.as_os_str().to_string_lossy().into_owned())
            .collect::<Vec<_>>()
            .join("/");
        out.insert(rel, sha256_hex(&bytes));
    }
    Ok(())
}

/// The lower-case hex sha256 of `bytes`.
pub fn sha256_hex(bytes: &[u8]) -> String {
    Sha256::digest(bytes)
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect()
}

/// The key of this run's checkpoints: the sha256 of the running executable (another build
/// computes other figures) and `tools` (the versions of the external tools the steps use).
pub fn run_key(tools: &str) -> String {
    let exe = std::env::current_exe()
        .ok()
        .and_then(|p| std::fs::read(p).ok())
        .map_or_else(|| env!("CARGO_PKG_VERSION").to_string(), |b| sha256_hex(&b));
    sha256_hex(format!("{exe}\n{tools}").as_bytes())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Runs step `a` (writes `a/x.txt` holding `text`) and returns its summary and whether it
    /// ran (false: reused).
    fn step_a(r: &mut Resume, dir: &Path, text: &str) -> (u32, bool) {
        let mut ran = false;
        let v = r
            .step("a", &["a"], || {
                ran = true;
                std::fs::create_dir_all(dir.join("a")).unwrap();
                std::fs::write(dir.join("a/x.txt"), text).unwrap();
                Ok(7u32)
            })
            .unwrap();
        (v, ran)
    }

    #[test]
    fn a_true_checkpoint_is_reused_and_anything_else_runs_again() {
        let tmp = tempfile::tempdir().unwrap();
        let dir = tmp.path();
        std::fs::write(dir.join(MARKER), "report\n").unwrap();
        let mut r = Resume::open(dir, "k".into(), false).unwrap();
        assert_eq!(step_a(&mut r, dir, "one"), (7, true));
        // Left by an unfinished step, and a temporary file: removed when the run is taken over.
        std::fs::create_dir(dir.join("b")).unwrap();
        std::fs::write(dir.join("b/half.png"), "x").unwrap();
        std::fs::write(dir.join(".c.txt.abc.tmp"), "x").unwrap();

        let mut r = Resume::open(dir, "k".into(), true).unwrap();
        assert_eq!(r.n_reusable(), 1);
        assert!(!dir.join("b").exists() && !dir.join(".c.txt.abc.tmp").exists());
        assert!(dir.join(MARKER).exists());
        assert_eq!(step_a(&mut r, dir, "two"), (7, false), "reused");
        assert_eq!(std::fs::read_to_string(dir.join("a/x.txt")).unwrap(), "one");

        // A changed file: the step runs again (and starts from no files of its own).
        std::fs::write(dir.join("a/x.txt"), "changed").unwrap();
        let mut r = Resume::open(dir, "k".into(), true).unwrap();
        assert_eq!(r.n_reusable(), 0);
        assert!(!dir.join("a").exists(), "the step's files are removed");
        assert_eq!(step_a(&mut r, dir, "three"), (7, true));

        // A file the step did not write, among its files: runs again.
        std::fs::write(dir.join("a/extra.txt"), "x").unwrap();
        let r = Resume::open(dir, "k".into(), true).unwrap();
        assert_eq!(r.n_reusable(), 0);

        // Another build or other tools (another key): runs again.
        let mut r = Resume::open(dir, "k".into(), false).unwrap();
        step_a(&mut r, dir, "four");
        let mut r = Resume::open(dir, "other".into(), true).unwrap();
        assert_eq!(r.n_reusable(), 0);
        assert_eq!(step_a(&mut r, dir, "five"), (7, true));

        // A checkpoint that does not read, or whose summary is another type: runs again.
        std::fs::write(dir.join(CHECKPOINTS).join("a.json"), "{").unwrap();
        let r = Resume::open(dir, "other".into(), true).unwrap();
        assert_eq!(r.n_reusable(), 0);
        let mut r = Resume::open(dir, "k".into(), false).unwrap();
        r.step("a", &["a"], || {
            std::fs::create_dir_all(dir.join("a")).unwrap();
            std::fs::write(dir.join("a/x.txt"), "six").unwrap();
            Ok("a string".to_string())
        })
        .unwrap();
        let mut r = Resume::open(dir, "k".into(), true).unwrap();
        assert_eq!(r.n_reusable(), 1);
        assert_eq!(step_a(&mut r, dir, "seven"), (7, true));

        // Finished: the checkpoints go, the files stay.
        r.finish().unwrap();
        assert!(!dir.join(CHECKPOINTS).exists());
        assert!(dir.join("a/x.txt").exists());
    }

    #[test]
    fn a_checkpointed_file_replaced_by_a_symlink_is_not_reused() {
        let tmp = tempfile::tempdir().unwrap();
        let dir = &tmp.path().join("staging");
        std::fs::create_dir(dir).unwrap();
        std::fs::write(dir.join(MARKER), "report\n").unwrap();
        let mut r = Resume::open(dir, "k".into(), false).unwrap();
        assert_eq!(step_a(&mut r, dir, "one"), (7, true));
        // An outside copy with the very same bytes, linked in place of the step's file: its
        // hash holds, yet the result would point outside itself.
        let outside = tmp.path().join("outside.txt");
        std::fs::write(&outside, "one").unwrap();
        std::fs::remove_file(dir.join("a/x.txt")).unwrap();
        std::os::unix::fs::symlink(&outside, dir.join("a/x.txt")).unwrap();
        let mut r = Resume::open(dir, "k".into(), true).unwrap();
        assert_eq!(r.n_reusable(), 0);
        assert_eq!(step_a(&mut r, dir, "two"), (7, true), "runs again");
        let kind = std::fs::symlink_metadata(dir.join("a/x.txt")).unwrap();
        assert!(kind.is_file(), "a regular file again");
        assert_eq!(std::fs::read_to_string(&outside).unwrap(), "one");

        // The same with the step's whole directory linked to an outside copy.
        let copy = tmp.path().join("copy");
        std::fs::create_dir(&copy).unwrap();
        std::fs::write(copy.join("x.txt"), "two").unwrap();
        std::fs::remove_dir_all(dir.join("a")).unwrap();
        std::os::unix::fs::symlink(&copy, dir.join("a")).unwrap();
        let r = Resume::open(dir, "k".into(), true).unwrap();
        assert_eq!(r.n_reusable(), 0);
        assert!(
            std::fs::symlink_metadata(dir.join("a")).is_err(),
            "the link is removed"
        );
        assert!(copy.join("x.txt").exists(), "not what it points to");
    }
}
