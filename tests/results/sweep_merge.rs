//! `specfx sweep merge` and resuming, through the binary: shards carry their sweep's identity
//! and merge refuses anything that is not one complete sweep (another space, another
//! sharding, a shard twice or missing, a point of another shard or outside the space); merge
//! never writes over its inputs or an existing result; a full disk (a file size limit, a
//! device) fails with one line and exit code 2 and leaves nothing half-written; an
//! interrupted sweep resumes to the same bytes; each scheduler's array tasks (`--shard auto/N`,
//! several shards per task) write shards that merge into the one-shot sweep.

use crate::common::{limited, run_guarded, specfx};

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// A fresh directory for one test.
fn temp(name: &str) -> PathBuf {
    let p = std::env::temp_dir().join(format!("specfx-merge-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&p);
    std::fs::create_dir_all(&p).unwrap();
    p
}

/// 12 points: 3 values of k times 2 of the squarings' rounding times 2 architectures.
const SPACE: &str = "n = \"64,200\"\n[vary]\nk = [3, 4, 5]\n\"square.rounding\" = [\"TRN\", \"RND\"]\narch = [\"pipelined\", \"folded\"]\n";

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn ok(o: Output) -> Output {
    assert!(o.status.success(), "{}", stderr(&o));
    o
}

/// Runs `specfx sweep --space SPACE --out OUT [--shard S]`.
fn sweep(space: &Path, out: &Path, shard: Option<&str>) -> Output {
    let mut args = vec!["sweep", "--space", s(space), "--out", s(out)];
    if let Some(sh) = shard {
        args.extend(["--shard", sh]);
    }
    specfx(&args)
}

/// Runs `specfx sweep merge --out OUT SHARDS... [extra]`.
fn merge(out: &Path, shards: &[&Path], extra: &[&str]) -> Output {
    let mut args = vec!["sweep", "merge", "--out", s(out)];
    args.extend(extra);
    args.extend(shards.iter().map(|p| s(p)));
    specfx(&args)
}

/// Exit code 2 and one line on stderr containing `want`.
fn refused(o: &Output, want: &str) {
    let err = stderr(o);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert_eq!(err.lines().count(), 1, "one line: {err}");
    assert!(err.contains(want), "expected '{want}' in: {err}");
    assert!(!err.contains("panicked"), "{err}");
}

/// Exit code 2 and one error line, the last on stderr (after a sweep's progress lines),
/// containing `want`.
fn failed(o: &Output, want: &str) {
    let err = stderr(o);
    assert_eq!(o.status.code(), Some(2), "{err}");
    let errors = err
        .lines()
        .filter(|l| l.starts_with("specfx: error"))
        .count();
    assert_eq!(errors, 1, "one error: {err}");
    assert!(
        err.lines().last().unwrap_or("").contains(want),
        "expected '{want}' in the last line of: {err}"
    );
    assert!(!err.contains("panicked"), "{err}");
}

/// Every file under `dir` (relative path, bytes), sorted.
fn snapshot(dir: &Path) -> Vec<(PathBuf, Vec<u8>)> {
    fn walk(root: &Path, dir: &Path, out: &mut Vec<(PathBuf, Vec<u8>)>) {
        for e in std::fs::read_dir(dir).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                walk(root, &p, out);
            } else {
                let bytes = std::fs::read(&p).unwrap();
                out.push((p.strip_prefix(root).unwrap().to_path_buf(), bytes));
            }
        }
    }
    let mut v = Vec::new();
    walk(dir, dir, &mut v);
    v.sort();
    v
}

/// The names in `dir`, sorted.
fn names(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

/// A space file, a one-shot sweep and three shards of it, in `root`.
struct Sweeps {
    space: PathBuf,
    one: PathBuf,
    shards: Vec<PathBuf>,
}

fn sweeps(root: &Path) -> Sweeps {
    let space = root.join("space.toml");
    std::fs::write(&space, SPACE).unwrap();
    let one = root.join("one");
    ok(sweep(&space, &one, None));
    let shards: Vec<PathBuf> = (0..3)
        .map(|i| {
            let d = root.join(format!("shard{i}"));
            ok(sweep(&space, &d, Some(&format!("{i}/3"))));
            d
        })
        .collect();
    Sweeps { space, one, shards }
}

/// Rewrites line `i` (0-based) of `dir/points.jsonl` with `edit`.
fn edit_point(dir: &Path, i: usize, edit: impl FnOnce(&mut serde_json::Value)) {
    let path = dir.join("points.jsonl");
    let text = std::fs::read_to_string(&path).unwrap();
    let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
    let mut v: serde_json::Value = serde_json::from_str(&lines[i]).unwrap();
    edit(&mut v);
    lines[i] = v.to_string();
    std::fs::write(&path, lines.join("\n") + "\n").unwrap();
}

fn copy_dir(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap();
    for e in std::fs::read_dir(from).unwrap() {
        let e = e.unwrap();
        std::fs::copy(e.path(), to.join(e.file_name())).unwrap();
    }
}

#[test]
fn merge_refuses_anything_but_one_complete_sweep() {
    let root = temp("refuse");
    let w = sweeps(&root);
    let [a, b, c] = [&w.shards[0], &w.shards[1], &w.shards[2]].map(|p| p.as_path());
    let out = root.join("merged");
    // The three shards merge into the one-shot sweep, file for file (but the marker).
    ok(merge(&out, &[a, b, c], &[]));
    let without_marker = |d: &Path| {
        let mut v = snapshot(d);
        v.retain(|(p, _)| p != Path::new(".specfx-result"));
        v
    };
    assert_eq!(without_marker(&out), without_marker(&w.one));
    std::fs::remove_dir_all(&out).unwrap();

    // Each shard records the identity of its sweep: the space and the number of shards.
    let info = |d: &Path| -> serde_json::Value {
        serde_json::from_slice(&std::fs::read(d.join("space.json")).unwrap()).unwrap()
    };
    assert_eq!(info(a)["sweep_sha256"], info(c)["sweep_sha256"]);
    assert_ne!(info(a)["sweep_sha256"], info(&w.one)["sweep_sha256"]);

    // A shard of another space (k = 6 instead of 5: the same number of points).
    let other_space = root.join("other.toml");
    std::fs::write(&other_space, SPACE.replace("[3, 4, 5]", "[3, 4, 6]")).unwrap();
    let foreign = root.join("foreign1");
    ok(sweep(&other_space, &foreign, Some("1/3")));
    refused(
        &merge(&out, &[a, &foreign, c], &[]),
        "a shard of another sweep",
    );
    // A shard of another sharding of the same space (its indices would fit, wrongly).
    let half = root.join("half1");
    ok(sweep(&w.space, &half, Some("1/2")));
    refused(
        &merge(&out, &[a, &half, c], &[]),
        "shards of one sweep share their count",
    );
    // A shard twice: the same directory, another spelling of it, or a copy.
    refused(&merge(&out, &[a, b, b, c], &[]), "the same directory");
    let b_again = root.join(".").join("shard1");
    refused(
        &merge(&out, &[a, b, &b_again, c], &[]),
        "the same directory",
    );
    let b_copy = root.join("copy1");
    copy_dir(b, &b_copy);
    refused(&merge(&out, &[a, b, &b_copy, c], &[]), "both shard 1/3");
    // A missing shard.
    refused(&merge(&out, &[a, c], &[]), "shard 1/3 missing");
    // A point outside the space, or of another shard, or with the axis values of another.
    let bad = root.join("bad1");
    copy_dir(b, &bad);
    edit_point(&bad, 0, |v| v["index"] = 12.into());
    refused(
        &merge(&out, &[a, &bad, c], &[]),
        "points.jsonl line 1: point 12 is outside the space (12 points)",
    );
    copy_dir(b, &bad);
    edit_point(&bad, 1, |v| v["index"] = 3.into());
    refused(
        &merge(&out, &[a, &bad, c], &[]),
        "line 2: point 3 belongs to shard 0/3, not to this directory's shard 1/3",
    );
    copy_dir(b, &bad);
    edit_point(&bad, 0, |v| v["values"] = "k=9".into());
    refused(
        &merge(&out, &[a, &bad, c], &[]),
        "not a point of this sweep",
    );
    // An unfinished shard (a torn last line: killed while writing).
    copy_dir(b, &bad);
    let log = std::fs::read_to_string(b.join("points.jsonl")).unwrap();
    std::fs::write(bad.join("points.jsonl"), &log[..log.len() - 40]).unwrap();
    refused(
        &merge(&out, &[a, &bad, c], &[]),
        "holds 3 of its 4 points, 1 missing: resume it",
    );
    // An edited identity.
    copy_dir(b, &bad);
    let edited = std::fs::read_to_string(b.join("space.json"))
        .unwrap()
        .replace("\"shard_count\": 3", "\"shard_count\": 4");
    std::fs::write(bad.join("space.json"), edited).unwrap();
    refused(&merge(&out, &[a, &bad, c], &[]), "does not match itself");
    // None of these wrote anything.
    assert!(!out.exists());
    assert!(!names(&root).iter().any(|n| n.contains(".partial-")));
}

#[test]
fn merge_never_writes_over_its_inputs_nor_an_existing_result() {
    let root = temp("inputs");
    let w = sweeps(&root);
    let [a, b, c] = [&w.shards[0], &w.shards[1], &w.shards[2]].map(|p| p.as_path());
    let before: Vec<_> = w.shards.iter().map(|d| snapshot(d)).collect();
    let one_before = snapshot(&w.one);
    for force in [&[][..], &["--force"][..]] {
        // Onto a shard, into one, or onto a directory holding them: never, even with --force.
        refused(&merge(b, &[a, b, c], force), "is the shard");
        refused(
            &merge(&b.join("sub"), &[a, b, c], force),
            "is inside the shard",
        );
        refused(&merge(&root, &[a, b, c], force), "contains the shard");
        // Through a symbolic link to a shard.
        let link = root.join("link-to-shard2");
        let _ = std::fs::remove_file(&link);
        std::os::unix::fs::symlink(c, &link).unwrap();
        refused(&merge(&link, &[a, b, c], force), "is the shard");
    }
    // Onto another command's result: only with --force, which the message never offers
    // (it would delete what that run computed).
    let o = merge(&w.one, &[a, b, c], &[]);
    refused(
        &o,
        "holds a `specfx sweep` result, not an earlier merge of this sweep: choose another --out",
    );
    assert!(!String::from_utf8_lossy(&o.stderr).contains("--force"));
    let after: Vec<_> = w.shards.iter().map(|d| snapshot(d)).collect();
    assert!(before == after, "a shard changed");
    assert!(snapshot(&w.one) == one_before, "the one-shot sweep changed");
    // An earlier merge of the same sweep is replaced; of another sweep, only with --force.
    let out = root.join("merged");
    ok(merge(&out, &[a, b, c], &[]));
    let first = snapshot(&out);
    ok(merge(&out, &[c, a, b], &[]));
    assert!(snapshot(&out) == first);
    let other_space = root.join("other.toml");
    std::fs::write(&other_space, SPACE.replace("[3, 4, 5]", "[3, 4]")).unwrap();
    let others: Vec<PathBuf> = (0..2)
        .map(|i| {
            let d = root.join(format!("other{i}"));
            ok(sweep(&other_space, &d, Some(&format!("{i}/2"))));
            d
        })
        .collect();
    let o: Vec<&Path> = others.iter().map(|p| p.as_path()).collect();
    refused(&merge(&out, &o, &[]), "not an earlier merge of this sweep");
    assert!(snapshot(&out) == first);
    ok(merge(&out, &o, &["--force"]));
    let csv = std::fs::read_to_string(out.join("sweep.csv")).unwrap();
    assert_eq!(csv.lines().count(), 1 + 8);
    // With --force onto the one-shot sweep: replaced by the merge, the shards untouched.
    ok(merge(&w.one, &[a, b, c], &["--force"]));
    assert_eq!(
        std::fs::read_to_string(w.one.join(".specfx-result")).unwrap(),
        "sweep-merge\n"
    );
    let after: Vec<_> = w.shards.iter().map(|d| snapshot(d)).collect();
    assert!(before == after, "a shard changed");
}

#[test]
fn a_full_disk_fails_with_one_line_and_leaves_no_partial_output() {
    let root = temp("full");
    let w = sweeps(&root);
    let shards: Vec<&str> = w.shards.iter().map(|p| s(p)).collect();
    // Merge: the results do not fit (sweep.json is larger than 8 KiB): nothing is left.
    let out = root.join("merged");
    let mut args = vec!["sweep", "merge", "--out", s(&out)];
    args.extend(&shards);
    let (o, finished) = limited(16, &args);
    assert!(finished, "merge hung on a full disk");
    refused(&o, "cannot write");
    assert!(
        stderr(&o).contains("merged/"),
        "names the result: {}",
        stderr(&o)
    );
    assert!(stderr(&o).contains("File too large"), "{}", stderr(&o));
    assert!(!out.exists(), "a partial merge was left");
    assert!(
        !names(&root).iter().any(|n| n.contains("merged")),
        "{:?}",
        names(&root)
    );
    // An earlier merge stays as it was when a new one fails.
    ok(merge(
        &out,
        &[&w.shards[0], &w.shards[1], &w.shards[2]],
        &[],
    ));
    let earlier = snapshot(&out);
    let (o, _) = limited(16, &args);
    refused(&o, "cannot write");
    assert!(snapshot(&out) == earlier);
    assert!(!names(&root).iter().any(|n| n.contains(".merged.")));

    // Sweep: the points log fills the disk mid-run (4 KiB: about 9 of the 12 points).
    let full = root.join("sweep");
    let (o, finished) = limited(8, &["sweep", "--space", s(&w.space), "--out", s(&full)]);
    assert!(finished, "sweep hung on a full disk");
    failed(&o, "points.jsonl: File too large");
    let left = names(&full);
    assert_eq!(
        left,
        [".specfx-result", "points.jsonl", "space.json"],
        "{left:?}"
    );
    // The results do not fit: the log is complete, the results absent, nothing temporary.
    let (o, _) = limited(40, &["sweep", "--space", s(&w.space), "--out", s(&full)]);
    failed(&o, "cannot write");
    assert_eq!(
        names(&full),
        [".specfx-result", "points.jsonl", "space.json"],
        "{}",
        stderr(&o)
    );
    // Resumed with room, the sweep is the one-shot sweep, byte for byte.
    let o = ok(sweep(&w.space, &full, None));
    assert!(stderr(&o).contains("12 already done"), "{}", stderr(&o));
    assert!(snapshot(&full) == snapshot(&w.one));
}

#[test]
fn a_sweep_whose_files_are_devices_fails_instead_of_hanging() {
    let root = temp("device");
    let space = root.join("space.toml");
    std::fs::write(&space, SPACE).unwrap();
    let dir = root.join("s");
    ok(sweep(&space, &dir, None));
    // The points log is /dev/full (writes fail; reads never end): one line, exit code 2.
    std::fs::remove_file(dir.join("points.jsonl")).unwrap();
    std::os::unix::fs::symlink("/dev/full", dir.join("points.jsonl")).unwrap();
    let (o, finished) = run_guarded(Command::new(env!("CARGO_BIN_EXE_specfx")).args([
        "sweep",
        "--space",
        s(&space),
        "--out",
        s(&dir),
    ]));
    assert!(finished, "sweep hung on /dev/full");
    refused(&o, "points.jsonl: expected a regular file, got a device");
    // The same for a shard's space.json or log given to merge.
    let (o, finished) = run_guarded(Command::new(env!("CARGO_BIN_EXE_specfx")).args([
        "sweep",
        "merge",
        "--out",
        s(&root.join("m")),
        s(&dir),
    ]));
    assert!(finished, "merge hung on /dev/full");
    refused(&o, "got a device");
    std::fs::remove_file(dir.join("space.json")).unwrap();
    std::os::unix::fs::symlink("/dev/zero", dir.join("space.json")).unwrap();
    let (o, finished) = run_guarded(Command::new(env!("CARGO_BIN_EXE_specfx")).args([
        "sweep",
        "--space",
        s(&space),
        "--out",
        s(&dir),
    ]));
    assert!(finished, "sweep hung on /dev/zero");
    refused(&o, "space.json: expected a regular file, got a device");
}

#[test]
fn a_resumed_sweep_keeps_only_points_of_its_own_shard() {
    let root = temp("resume");
    let space = root.join("space.toml");
    std::fs::write(&space, SPACE).unwrap();
    let dir = root.join("s");
    ok(sweep(&space, &dir, Some("1/3")));
    let done = snapshot(&dir);
    // Killed while writing a point: the torn line is computed again, to the same bytes.
    let log = std::fs::read_to_string(dir.join("points.jsonl")).unwrap();
    std::fs::write(dir.join("points.jsonl"), &log[..log.len() - 25]).unwrap();
    let o = ok(sweep(&space, &dir, Some("1/3")));
    assert!(
        stderr(&o).contains("4 in this shard, 3 already done"),
        "{}",
        stderr(&o)
    );
    assert!(snapshot(&dir) == done);
    // A point of another shard in the log is refused, not silently merged in.
    edit_point(&dir, 0, |v| {
        v["index"] = 0.into();
    });
    refused(
        &sweep(&space, &dir, Some("1/3")),
        "point 0 belongs to shard 0/3, not to this directory's shard 1/3",
    );
    // The same space written differently is the same sweep, and resumes.
    std::fs::write(dir.join("points.jsonl"), &log).unwrap();
    let respelled = root.join("respelled.toml");
    std::fs::write(
        &respelled,
        "# the same space\n[vary]\narch = ['pipelined', 'folded']\n\"square.rounding\" = ['TRN', 'RND']\nk = \"3..=5\"\n\n[base]\nn = \"64, 200\"\n",
    )
    .unwrap();
    let o = ok(sweep(&respelled, &dir, Some("1/3")));
    assert!(stderr(&o).contains("4 already done"), "{}", stderr(&o));
    // A directory holding something else is not swept into.
    let other = root.join("other");
    std::fs::create_dir_all(&other).unwrap();
    std::fs::write(other.join("notes.txt"), "mine").unwrap();
    refused(
        &sweep(&space, &other, None),
        "exists and is not a sweep directory (no space.json)",
    );
    assert_eq!(names(&other), ["notes.txt"]);
}

/// The schedulers' array-task variables, and the value of each for the first task (Slurm,
/// PBS and Kubernetes count from 0, LSF and SGE from 1).
const SCHEDULER_VARS: [(&str, u64); 5] = [
    ("SLURM_ARRAY_TASK_ID", 0),
    ("LSB_JOBINDEX", 1),
    ("SGE_TASK_ID", 1),
    ("PBS_ARRAYID", 0),
    ("JOB_COMPLETION_INDEX", 0),
];

/// `specfx sweep ARGS` as array task `task` (0-based) of the scheduler whose index variable is
/// `var`: every other scheduler's variable removed (the test may itself run in a job).
fn as_task(var: &str, first: u64, task: u64, args: &[&str]) -> Output {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_specfx"));
    cmd.arg("sweep").args(args);
    for (v, _) in SCHEDULER_VARS {
        cmd.env_remove(v);
    }
    cmd.env_remove("SPECFX_TASK_ID");
    cmd.env(var, (first + task).to_string());
    cmd.output().expect("specfx runs")
}

#[test]
fn each_schedulers_array_tasks_take_their_shards_and_merge_to_the_one_shot_sweep() {
    let root = temp("auto");
    let space = root.join("space.toml");
    std::fs::write(&space, SPACE).unwrap();
    let one = root.join("one");
    ok(sweep(&space, &one, None));
    let without_marker = |d: &Path| {
        let mut v = snapshot(d);
        v.retain(|(p, _)| p != Path::new(".specfx-result"));
        v
    };
    for (var, first) in SCHEDULER_VARS {
        // Four shards, two per task: tasks 0 and 1 take shards {0, 2} and {1, 3}.
        let template = root.join(var).join("shard-{shard}");
        for task in 0..2 {
            let o = ok(as_task(
                var,
                first,
                task,
                &[
                    "--space",
                    s(&space),
                    "--shard",
                    "auto/4",
                    "--shards-per-task",
                    "2",
                ]
                .into_iter()
                .chain(["--out", s(&template)])
                .collect::<Vec<_>>(),
            ));
            let log = stderr(&o);
            let said = format!(
                "array task {task} of 2 ({var}={}): shards {task}, {} of 4",
                first + task,
                task + 2
            );
            assert!(log.contains(&said), "{var}: {log}");
        }
        let dirs: Vec<PathBuf> = (0..4)
            .map(|i| root.join(var).join(format!("shard-{i}")))
            .collect();
        let out = root.join(format!("{var}-merged"));
        ok(merge(
            &out,
            &dirs.iter().map(PathBuf::as_path).collect::<Vec<_>>(),
            &[],
        ));
        assert!(
            without_marker(&out) == without_marker(&one),
            "{var}: not the one-shot sweep"
        );
    }
    // Refused in one line before anything is written: no task index, a task beyond the array, a
    // directory without its placeholder.
    let out = root.join("refused-{shard}");
    let plain = ["--space", s(&space), "--shard", "auto/4", "--out", s(&out)];
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_specfx"));
    cmd.arg("sweep").args(plain);
    for (v, _) in SCHEDULER_VARS {
        cmd.env_remove(v);
    }
    cmd.env_remove("SPECFX_TASK_ID");
    refused(
        &cmd.output().unwrap(),
        "no scheduler's array task index is set",
    );
    refused(
        &as_task("SGE_TASK_ID", 1, 4, &plain),
        "SGE_TASK_ID=5 is array task 4 (counted from 0), but 4 shards make 4 tasks (0..=3)",
    );
    let no_placeholder = ["--space", s(&space), "--shard", "auto/4", "--out", s(&root)];
    refused(
        &as_task("SLURM_ARRAY_TASK_ID", 0, 0, &no_placeholder),
        "--out: expected a {shard} placeholder",
    );
    assert!(!root.join("refused-0").exists() && !root.join("refused-4").exists());
    // Shard numbers past the bounds of `sweep plan` (100,000 tasks of 1,000 shards): refused,
    // where u64::MAX once overflowed a capacity (a panic) and a million shards per task made a
    // directory each.
    let huge = root.join("huge").join("s{shard}");
    for (shard, per_task, want) in [
        (
            "auto/18446744073709551615",
            "18446744073709551615",
            "--shards-per-task: expected 1 to 1000, got 18446744073709551615",
        ),
        (
            "auto/1000000",
            "1000000",
            "--shards-per-task: expected 1 to 1000, got 1000000",
        ),
        (
            "auto/100000001",
            "1",
            "--shard: expected at most 100000000 shards (100000 tasks of 1000), got 100000001",
        ),
    ] {
        let args = [
            "--space",
            s(&space),
            "--shard",
            shard,
            "--shards-per-task",
            per_task,
        ];
        refused(
            &as_task(
                "SLURM_ARRAY_TASK_ID",
                0,
                0,
                &args
                    .into_iter()
                    .chain(["--out", s(&huge)])
                    .collect::<Vec<_>>(),
            ),
            want,
        );
    }
    assert!(!root.join("huge").exists());
    // A '..' after the placeholder cancels it: every task would write `o/x`.
    let cancelled = format!("{}/o/{{shard}}/../x", s(&root));
    refused(
        &as_task(
            "SLURM_ARRAY_TASK_ID",
            0,
            0,
            &[
                "--space",
                s(&space),
                "--shard",
                "auto/4",
                "--out",
                &cancelled,
            ],
        ),
        "a '..' after {shard} cancels it",
    );
    assert!(!root.join("o").exists());
    // A scheduler that says there are no tasks.
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_specfx"));
    cmd.arg("sweep")
        .args(["--space", s(&space), "--shard", "auto", "--out", s(&out)]);
    for (v, _) in SCHEDULER_VARS {
        cmd.env_remove(v);
    }
    cmd.env_remove("SPECFX_TASK_ID");
    cmd.env("SLURM_ARRAY_TASK_ID", "0")
        .env("SLURM_ARRAY_TASK_COUNT", "0");
    refused(
        &cmd.output().unwrap(),
        "SLURM_ARRAY_TASK_COUNT=0: expected 1 or more (Slurm's number of array tasks)",
    );
    std::fs::remove_dir_all(&root).unwrap();
}
