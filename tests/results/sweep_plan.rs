//! `specfx sweep plan`: the job scripts of each scheduler, run as the scheduler would run them
//! (each array task's script with its index variable, then the merge step), merge into the
//! one-shot sweep byte for byte; their directives and resource requests are the ones derived
//! by hand; they are the same bytes on every run; a plan with more shards than points is
//! refused. Here bash stands in for each scheduler (to bash their directives are comments), and
//! the shell plan runs as it is.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// 12 points (as in `sweep_merge.rs`).
const SPACE: &str = "n = \"64,200\"\n[vary]\nk = [3, 4, 5]\n\"square.rounding\" = [\"TRN\", \"RND\"]\narch = [\"pipelined\", \"folded\"]\n";

/// Every variable a task could read its index from: removed from each child (the test may run
/// inside a job), then the one under test set.
const TASK_VARS: [&str; 6] = [
    "SLURM_ARRAY_TASK_ID",
    "LSB_JOBINDEX",
    "SGE_TASK_ID",
    "PBS_ARRAYID",
    "JOB_COMPLETION_INDEX",
    "SPECFX_TASK_ID",
];

fn temp(name: &str) -> PathBuf {
    let p = std::env::temp_dir().join(format!("specfx-plan-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&p);
    std::fs::create_dir_all(&p).unwrap();
    p
}

fn ok(o: Output) -> Output {
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    o
}

fn specfx() -> Command {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_specfx"));
    for v in TASK_VARS {
        cmd.env_remove(v);
    }
    cmd
}

/// `specfx sweep plan --space SPACE --emit EMIT --tasks 4 --shards-per-task 2
/// --seconds-per-point 0.5 --out DIR`.
fn plan(space: &Path, emit: &str, dir: &Path) -> Output {
    specfx()
        .args([
            "sweep",
            "plan",
            "--space",
            space.to_str().unwrap(),
            "--emit",
            emit,
        ])
        .args([
            "--tasks",
            "4",
            "--shards-per-task",
            "2",
            "--seconds-per-point",
            "0.5",
        ])
        .args([
            "--specfx",
            env!("CARGO_BIN_EXE_specfx"),
            "--out",
            dir.to_str().unwrap(),
        ])
        .output()
        .unwrap()
}

fn read(dir: &Path, name: &str) -> String {
    std::fs::read_to_string(dir.join(name)).unwrap_or_else(|e| panic!("{name}: {e}"))
}

/// Runs `script` (a file of the plan) with bash in the plan's directory, `var=value` set.
fn run_script(dir: &Path, script: &str, var: Option<(&str, String)>) {
    let mut cmd = Command::new("bash");
    cmd.arg(script).current_dir(dir);
    for v in TASK_VARS {
        cmd.env_remove(v);
    }
    if let Some((k, v)) = var {
        cmd.env(k, v);
    }
    ok(cmd.output().unwrap());
}

/// Every file under `dir`, but the result marker (a merge's differs from a sweep's).
fn files(dir: &Path) -> Vec<(String, Vec<u8>)> {
    let mut v: Vec<(String, Vec<u8>)> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.file_name().unwrap() != ".specfx-result")
        .map(|p| {
            (
                p.file_name().unwrap().to_string_lossy().into_owned(),
                std::fs::read(&p).unwrap(),
            )
        })
        .collect();
    v.sort();
    v
}

#[test]
fn every_schedulers_scripts_run_the_sweep_and_merge_to_the_one_shot_sweep() {
    let root = temp("run");
    let space = root.join("space.toml");
    std::fs::write(&space, SPACE).unwrap();
    let one = root.join("one");
    ok(specfx()
        .args([
            "sweep",
            "--space",
            space.to_str().unwrap(),
            "--out",
            one.to_str().unwrap(),
        ])
        .output()
        .unwrap());
    // 12 points, 4 tasks of 2 shards: 8 shards of at most 2 points, 4 points a task. The time
    // asked: twice 0.5 s for each of 4 points, plus 300 s, in whole minutes: 304 s -> 6 min.
    for (emit, sweep_script, task_var, first) in [
        ("slurm", "sweep.sbatch", "SLURM_ARRAY_TASK_ID", 0u64),
        ("lsf", "sweep.lsf", "LSB_JOBINDEX", 1),
        ("sge", "sweep.sge", "SGE_TASK_ID", 1),
        ("k8s", "", "JOB_COMPLETION_INDEX", 0),
        ("shell", "", "", 0),
    ] {
        let dir = root.join(emit);
        let o = ok(plan(&space, emit, &dir));
        let said = String::from_utf8_lossy(&o.stdout);
        assert!(
            said.contains("12 points in 8 shards over 4"),
            "{emit}: {said}"
        );
        assert!(
            said.contains("(2 threads, 512 MiB, 6 min each)"),
            "{emit}: {said}"
        );
        let p: serde_json::Value = serde_json::from_str(&read(&dir, "plan.json")).unwrap();
        assert_eq!(
            (
                &p["shards"],
                &p["tasks"],
                &p["points_per_task"],
                &p["resources"]["time_s"]
            ),
            (&8.into(), &4.into(), &4.into(), &360.into()),
            "{emit}"
        );
        assert_eq!(read(&dir, "space.toml"), SPACE);
        let names: Vec<String> = files(&dir).into_iter().map(|f| f.0).collect();
        for f in &names {
            if f.ends_with(".sh")
                || f.ends_with(".sbatch")
                || f.ends_with(".lsf")
                || f.ends_with(".sge")
            {
                let syntax = Command::new("bash")
                    .arg("-n")
                    .arg(dir.join(f))
                    .output()
                    .unwrap();
                assert!(
                    syntax.status.success(),
                    "{emit} {f}: {}",
                    String::from_utf8_lossy(&syntax.stderr)
                );
            }
        }
        // The scheduler's own directives.
        match emit {
            "slurm" => {
                let s = read(&dir, "sweep.sbatch");
                for d in [
                    "--array=0-3",
                    "--cpus-per-task=2",
                    "--mem=512M",
                    "--time=6",
                    "--requeue",
                ] {
                    assert!(s.contains(&format!("#SBATCH {d}\n")), "{d}: {s}");
                }
                assert!(read(&dir, "submit.sh").contains("--dependency=afterok:"));
            }
            "lsf" => {
                let s = read(&dir, "sweep.lsf");
                assert!(
                    s.contains("[1-4]\"\n")
                        && s.contains("#BSUB -W 6\n")
                        && s.contains("#BSUB -r\n"),
                    "{s}"
                );
                assert!(read(&dir, "merge.lsf").contains("#BSUB -w \"done(specfx-sweep-"));
            }
            "sge" => {
                let s = read(&dir, "sweep.sge");
                assert!(
                    s.contains("#$ -t 1-4\n") && s.contains("h_vmem=256M,h_rt=360\n"),
                    "{s}"
                );
                assert!(read(&dir, "merge.sge").contains("#$ -hold_jid specfx-sweep-"));
            }
            "k8s" => {
                let j: serde_json::Value =
                    serde_json::from_str(&read(&dir, "sweep-job.json")).unwrap();
                assert_eq!(j["spec"]["completionMode"], "Indexed");
                assert_eq!(j["spec"]["completions"], 4);
                let c = &j["spec"]["template"]["spec"]["containers"][0];
                assert_eq!(c["resources"]["requests"]["cpu"], "2");
                assert_eq!(c["resources"]["requests"]["memory"], "512Mi");
            }
            _ => {}
        }
        // Run as the scheduler would: each task's script with its index, then the merge.
        match emit {
            "shell" => run_script(&dir, "submit.sh", None),
            "k8s" => {
                for (job, var) in [("sweep-job.json", true), ("merge-job.json", false)] {
                    let j: serde_json::Value = serde_json::from_str(&read(&dir, job)).unwrap();
                    let cmd = j["spec"]["template"]["spec"]["containers"][0]["command"][2]
                        .as_str()
                        .unwrap()
                        .to_string();
                    std::fs::write(dir.join("job.sh"), &cmd).unwrap();
                    if var {
                        for t in 0..4 {
                            run_script(&dir, "job.sh", Some((task_var, t.to_string())));
                        }
                    } else {
                        run_script(&dir, "job.sh", None);
                    }
                }
            }
            _ => {
                for t in 0..4 {
                    run_script(
                        &dir,
                        sweep_script,
                        Some((task_var, (first + t).to_string())),
                    );
                }
                run_script(&dir, &sweep_script.replace("sweep", "merge"), None);
            }
        }
        assert!(
            files(&dir.join("merged")) == files(&one),
            "{emit}: the merge is not the one-shot sweep"
        );
    }
    std::fs::remove_dir_all(&root).unwrap();
}

#[test]
fn a_plan_is_the_same_bytes_on_every_run_and_refuses_more_shards_than_points() {
    let root = temp("bytes");
    let space = root.join("space.toml");
    std::fs::write(&space, SPACE).unwrap();
    let (a, b) = (root.join("a"), root.join("b"));
    ok(plan(&space, "slurm", &a));
    ok(plan(&space, "slurm", &b));
    assert!(files(&a) == files(&b));
    let o = specfx()
        .args([
            "sweep",
            "plan",
            "--space",
            space.to_str().unwrap(),
            "--tasks",
            "7",
        ])
        .args([
            "--shards-per-task",
            "2",
            "--out",
            root.join("c").to_str().unwrap(),
        ])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(
        err.contains("7 tasks of 2 shards make 14 shards, more than the space's 12 points"),
        "{err}"
    );
    assert!(!root.join("c").exists());
    std::fs::remove_dir_all(&root).unwrap();
}

/// `sweep plan` with a `--specfx` of our own and extra arguments, into `dir`.
fn plan_with(space: &Path, dir: &Path, specfx_path: &Path, extra: &[&str]) -> Output {
    specfx()
        .args(["sweep", "plan", "--space", space.to_str().unwrap()])
        .args([
            "--emit",
            "shell",
            "--tasks",
            "4",
            "--seconds-per-point",
            "0.5",
        ])
        .args(["--specfx", specfx_path.to_str().unwrap(), "--out"])
        .arg(dir)
        .args(extra)
        .output()
        .unwrap()
}

/// Every file under `dir`, recursively, with its bytes.
fn tree(dir: &Path) -> Vec<(PathBuf, Vec<u8>)> {
    let mut out = Vec::new();
    let mut todo = vec![dir.to_path_buf()];
    while let Some(d) = todo.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                todo.push(p);
            } else {
                out.push((
                    p.strip_prefix(dir).unwrap().to_path_buf(),
                    std::fs::read(&p).unwrap(),
                ));
            }
        }
    }
    out.sort();
    out
}

#[test]
fn a_replan_keeps_what_the_tasks_computed_and_never_offers_to_delete_it() {
    let root = temp("replan");
    let space = root.join("space.toml");
    std::fs::write(&space, SPACE).unwrap();
    // A --specfx path holding '@', which the shell plan's `xargs -I @` once replaced by the
    // task index (every task then ran a program that does not exist).
    let bin = root.join("tools@2");
    std::fs::create_dir_all(&bin).unwrap();
    std::os::unix::fs::symlink(env!("CARGO_BIN_EXE_specfx"), bin.join("specfx")).unwrap();
    let dir = root.join("plan");
    ok(plan_with(&space, &dir, &bin.join("specfx"), &[]));
    // An earlier plan nothing ran from is replaced without --force (its marker, `sweep plan`,
    // is this command's: a check of its first word once refused it).
    ok(plan_with(&space, &dir, &bin.join("specfx"), &[]));
    run_script(&dir, "submit.sh", None);
    assert!(dir.join("merged/sweep.csv").is_file());
    std::fs::write(dir.join("slurm-7_0.out"), "a scheduler's log\n").unwrap();
    let results = |t: Vec<(PathBuf, Vec<u8>)>| -> Vec<(PathBuf, Vec<u8>)> {
        t.into_iter()
            .filter(|(p, _)| {
                p.starts_with("shards") || p.starts_with("merged") || p.ends_with("slurm-7_0.out")
            })
            .collect()
    };
    let computed = results(tree(&dir));
    assert!(computed.len() > 10, "{computed:?}");
    // The same sweep planned again, for another scheduler: in place, every result kept, the
    // shell's scripts replaced by Slurm's.
    let o = specfx()
        .args(["sweep", "plan", "--space", space.to_str().unwrap()])
        .args([
            "--emit",
            "slurm",
            "--tasks",
            "4",
            "--seconds-per-point",
            "0.5",
        ])
        .args(["--specfx", bin.join("specfx").to_str().unwrap(), "--out"])
        .arg(&dir)
        .output()
        .unwrap();
    ok(o);
    assert!(results(tree(&dir)) == computed, "a result changed");
    assert!(dir.join("sweep.sbatch").is_file() && dir.join("resubmit.sh").is_file());
    assert!(
        !read(&dir, "submit.sh").contains("xargs"),
        "the shell's submit.sh is left"
    );
    // Another sweep (another space) there: refused, with or without --force, and the message
    // offers no flag that would delete the results.
    let other = root.join("other.toml");
    std::fs::write(&other, SPACE.replace("[3, 4, 5]", "[3, 4]")).unwrap();
    for extra in [&[][..], &["--force"][..]] {
        let o = plan_with(&other, &dir, &bin.join("specfx"), extra);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{err}");
        assert_eq!(err.lines().count(), 1, "{err}");
        assert!(
            err.contains(
                "holds what an earlier plan's tasks computed (merged, shards, slurm-7_0.out)"
            ) && err.contains("re-planning there would lose it"),
            "{err}"
        );
        assert!(!err.contains("pass --force"), "{err}");
        assert!(results(tree(&dir)) == computed, "a result changed");
    }
    std::fs::remove_dir_all(&root).unwrap();
}
