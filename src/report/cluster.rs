//! The job scripts of `specfx sweep plan`: for one scheduler, the array job whose tasks take
//! their shards with `--shard auto/N`, the merge step that runs after it, and `submit.sh`,
//! which submits both in order; with `plan.json`, what they were derived from.

use crate::analysis::cluster::{Emit, Plan};
use crate::error::Error;
use crate::report::File;

/// The shard directories' template in the plan's directory.
pub const SHARDS_TEMPLATE: &str = "shards/shard-{shard}";
/// The merged sweep's directory in the plan's directory.
pub const MERGED_DIR: &str = "merged";
/// The space file the tasks read, beside the scripts.
pub const SPACE_FILE: &str = "space.toml";

/// The scripts a plan for `emit` writes beside [`SPACE_FILE`] and `plan.json`, by name (a test
/// holds [`plan_files`] to it).
pub fn script_names(emit: Emit) -> &'static [&'static str] {
    match emit {
        Emit::Slurm => &["sweep.sbatch", "merge.sbatch", "submit.sh", "resubmit.sh"],
        Emit::Lsf => &["sweep.lsf", "merge.lsf", "submit.sh"],
        Emit::Sge => &["sweep.sge", "merge.sge", "submit.sh"],
        Emit::K8s => &["sweep-job.json", "merge-job.json", "submit.sh"],
        Emit::Shell => &["submit.sh"],
    }
}

/// Whether `name`, an entry of a plan's directory, is a file `sweep plan` writes (for any
/// scheduler: the space, the scripts, `plan.json`, the provenance and the result marker) and
/// not something the plan's tasks, its merge or its scheduler wrote there (`shards/`,
/// `merged/`, logs), which re-planning must keep.
pub fn is_plan_file(name: &str) -> bool {
    [
        SPACE_FILE,
        "plan.json",
        crate::provenance::INPUTS_FILE,
        crate::provenance::PROVENANCE_FILE,
        crate::output::MARKER,
    ]
    .contains(&name)
        || Emit::ALL
            .into_iter()
            .any(|e| script_names(e).contains(&name))
}

/// `s` quoted for a POSIX shell (as is when it needs no quoting).
///
/// # Examples
/// ```
/// use specfx::report::cluster::sh_quote;
/// assert_eq!(sh_quote("specfx"), "specfx");
/// assert_eq!(sh_quote("shards/shard-{shard}"), "'shards/shard-{shard}'");
/// assert_eq!(sh_quote("it's"), r"'it'\''s'");
/// ```
pub fn sh_quote(s: &str) -> String {
    let plain = !s.is_empty()
        && s.chars()
            .all(|c| c.is_ascii_alphanumeric() || "-_./=:,+@%".contains(c));
    if plain {
        s.to_string()
    } else {
        format!("'{}'", s.replace('\'', r"'\''"))
    }
}

/// The sweep command of every task: its shards from the scheduler's index.
fn sweep_command(plan: &Plan) -> String {
    let mut cmd = format!(
        "{} sweep --space {SPACE_FILE} --shard auto/{}",
        sh_quote(&plan.specfx),
        plan.shards
    );
    if plan.shards_per_task > 1 {
        cmd += &format!(" --shards-per-task {}", plan.shards_per_task);
    }
    cmd + &format!(" --out {}", sh_quote(SHARDS_TEMPLATE))
}

/// The merge command, run once every task has finished.
fn merge_command(plan: &Plan) -> String {
    format!(
        "{} sweep merge --out {MERGED_DIR} shards/shard-*",
        sh_quote(&plan.specfx)
    )
}

/// A comment block saying what the plan is, for the head of each script.
fn header(plan: &Plan, what: &str) -> String {
    let r = &plan.resources;
    let c = &plan.point_cost;
    let from = if c.measured {
        format!(
            "twice the measured {:.3} s and {} MiB of a point, plus 5 min",
            c.seconds, c.peak_mib
        )
    } else {
        format!("twice the given {:.3} s a point, plus 5 min", c.seconds)
    };
    let each = if plan.shards_per_task == 1 {
        "1 shard".to_string()
    } else {
        format!("{} shards", plan.shards_per_task)
    };
    format!(
        "# {what}, written by `specfx sweep plan` (specfx {}).\n\
         # Sweep {}: {} points in {} shards, {} array tasks of {each} (at most {} points each).\n\
         # Each task: {} threads, {} MiB, {} min ({from}).\n\
         # A task that is requeued, cancelled and resubmitted, or run again resumes its shards.\n",
        crate::provenance::VERSION,
        &plan.sweep_sha256[..12],
        plan.n_points,
        plan.shards,
        plan.tasks,
        plan.points_per_task,
        r.threads,
        r.memory_mib,
        r.time_s / 60,
    )
}

/// The scheduler's lines for the plan's [`SchedulerOptions`](crate::analysis::cluster::SchedulerOptions)
/// (partition or queue, account or project, quality of service, the user's directives), after
/// the resources of every job script.
fn scheduler_lines(plan: &Plan) -> String {
    let o = &plan.scheduler;
    let (prefix, partition, account, qos) = match plan.emit {
        Emit::Slurm => ("#SBATCH", "--partition=", "--account=", "--qos="),
        Emit::Lsf => ("#BSUB", "-q ", "-P ", ""),
        Emit::Sge => ("#$", "-q ", "-A ", ""),
        // SchedulerOptions::check refuses every option for these.
        Emit::K8s | Emit::Shell => return String::new(),
    };
    let mut lines = String::new();
    for (flag, value) in [
        (partition, &o.partition),
        (account, &o.account),
        (qos, &o.qos),
    ] {
        if let Some(v) = value {
            lines += &format!("{prefix} {flag}{v}\n");
        }
    }
    for d in &o.directives {
        lines += &format!("{prefix} {d}\n");
    }
    lines
}

fn script(text: String) -> Vec<u8> {
    text.into_bytes()
}

fn slurm(plan: &Plan) -> Vec<File> {
    let r = &plan.resources;
    let name = plan.job_name();
    let sweep = format!(
        "#!/bin/bash\n\
         #SBATCH --job-name={name}\n\
         #SBATCH --array=0-{last}\n\
         #SBATCH --cpus-per-task={threads}\n\
         #SBATCH --mem={mem}M\n\
         #SBATCH --time={minutes}\n\
         #SBATCH --requeue\n\
         #SBATCH --output=%x-%A_%a.out\n\
         {options}{header}set -euo pipefail\n\
         export RAYON_NUM_THREADS={threads}\n\
         {cmd}\n",
        options = scheduler_lines(plan),
        last = plan.tasks - 1,
        threads = r.threads,
        mem = r.memory_mib,
        minutes = r.time_s / 60,
        header = header(plan, "The sweep's Slurm job array"),
        cmd = sweep_command(plan),
    );
    let merge = format!(
        "#!/bin/bash\n\
         #SBATCH --job-name={name}-merge\n\
         #SBATCH --cpus-per-task=1\n\
         #SBATCH --mem=512M\n\
         #SBATCH --time=30\n\
         #SBATCH --output=%x-%j.out\n\
         {options}{header}set -euo pipefail\n\
         {cmd}\n",
        options = scheduler_lines(plan),
        header = header(plan, "The merge of the sweep's shards, after the array"),
        cmd = merge_command(plan),
    );
    let submit = format!(
        "#!/bin/sh\n\
         {header}set -eu\n\
         cd \"$(dirname \"$0\")\"\n\
         array=$(sbatch --parsable sweep.sbatch)\n\
         array=${{array%%;*}}\n\
         merge=$(sbatch --parsable --dependency=afterok:\"$array\" merge.sbatch)\n\
         echo \"submitted the array $array and its merge ${{merge%%;*}}\"\n",
        header = header(plan, "Submits the sweep's array and its merge (Slurm)"),
    );
    // A cancelled, failed or timed-out task leaves the merge's `afterok` unmet for ever
    // (DependencyNeverSatisfied): the resubmission cancels that merge and submits another
    // after the resubmitted tasks and whatever tasks of the first array still run.
    let resubmit = format!(
        "#!/bin/sh\n\
         {header}# Usage: ./resubmit.sh TASKS, the array tasks to run again as sbatch --array takes\n\
         # them (5, 3,7 or 0-2): each resumes its shards where they stopped.\n\
         set -eu\n\
         cd \"$(dirname \"$0\")\"\n\
         if [ \"$#\" -ne 1 ]; then\n  \
           echo \"usage: $0 TASKS (array task indexes as sbatch --array takes them: 5, 3,7 or 0-2)\" >&2\n  \
           exit 2\n\
         fi\n\
         # The merge submitted before waits on a task that will never succeed: cancel it.\n\
         scancel --name={name}-merge --state=PENDING\n\
         # Tasks of the earlier submissions that still run or wait: the new merge waits for them too.\n\
         earlier=$(squeue --noheader --name={name} --format=%F | sort -u | paste -sd: -)\n\
         array=$(sbatch --parsable --array=\"$1\" sweep.sbatch)\n\
         array=${{array%%;*}}\n\
         after=afterok:$array\n\
         [ -z \"$earlier\" ] || after=$after,afterany:$earlier\n\
         merge=$(sbatch --parsable --dependency=\"$after\" merge.sbatch)\n\
         echo \"resubmitted tasks $1 as $array and the merge ${{merge%%;*}} after them\"\n",
        header = header(plan, "Resubmits array tasks of the sweep, and its merge after them (Slurm)"),
    );
    vec![
        ("sweep.sbatch".into(), script(sweep)),
        ("merge.sbatch".into(), script(merge)),
        ("submit.sh".into(), script(submit)),
        ("resubmit.sh".into(), script(resubmit)),
    ]
}

fn lsf(plan: &Plan) -> Vec<File> {
    let r = &plan.resources;
    let name = plan.job_name();
    let sweep = format!(
        "#!/bin/bash\n\
         #BSUB -J \"{name}[1-{tasks}]\"\n\
         #BSUB -n {threads}\n\
         #BSUB -R \"span[hosts=1] rusage[mem={mem}MB]\"\n\
         #BSUB -W {minutes}\n\
         #BSUB -r\n\
         #BSUB -o {name}-%J_%I.out\n\
         {options}{header}set -euo pipefail\n\
         export RAYON_NUM_THREADS={threads}\n\
         {cmd}\n",
        options = scheduler_lines(plan),
        tasks = plan.tasks,
        threads = r.threads,
        mem = r.memory_mib,
        minutes = r.time_s / 60,
        header = header(plan, "The sweep's LSF job array"),
        cmd = sweep_command(plan),
    );
    let merge = format!(
        "#!/bin/bash\n\
         #BSUB -J {name}-merge\n\
         #BSUB -w \"done({name})\"\n\
         #BSUB -n 1\n\
         #BSUB -W 30\n\
         #BSUB -o {name}-merge-%J.out\n\
         {options}{header}set -euo pipefail\n\
         {cmd}\n",
        options = scheduler_lines(plan),
        header = header(plan, "The merge of the sweep's shards, after the array"),
        cmd = merge_command(plan),
    );
    let submit = format!(
        "#!/bin/sh\n\
         {header}set -eu\n\
         cd \"$(dirname \"$0\")\"\n\
         bsub < sweep.lsf\n\
         bsub < merge.lsf\n",
        header = header(plan, "Submits the sweep's array and its merge (LSF)"),
    );
    vec![
        ("sweep.lsf".into(), script(sweep)),
        ("merge.lsf".into(), script(merge)),
        ("submit.sh".into(), script(submit)),
    ]
}

fn sge(plan: &Plan) -> Vec<File> {
    let r = &plan.resources;
    let name = plan.job_name();
    let sweep = format!(
        "#!/bin/bash\n\
         #$ -N {name}\n\
         #$ -t 1-{tasks}\n\
         #$ -cwd\n\
         #$ -pe smp {threads}\n\
         #$ -l h_vmem={per_slot}M,h_rt={seconds}\n\
         #$ -r y\n\
         #$ -j y\n\
         {options}{header}# (h_vmem is per slot: {mem} MiB over {threads} slots.)\n\
         set -euo pipefail\n\
         export RAYON_NUM_THREADS={threads}\n\
         {cmd}\n",
        tasks = plan.tasks,
        threads = r.threads,
        per_slot = r.memory_mib.div_ceil(u64::from(r.threads)),
        mem = r.memory_mib,
        seconds = r.time_s,
        options = scheduler_lines(plan),
        header = header(plan, "The sweep's SGE array job"),
        cmd = sweep_command(plan),
    );
    let merge = format!(
        "#!/bin/bash\n\
         #$ -N {name}-merge\n\
         #$ -hold_jid {name}\n\
         #$ -cwd\n\
         #$ -l h_rt=1800\n\
         #$ -j y\n\
         {options}{header}set -euo pipefail\n\
         {cmd}\n",
        options = scheduler_lines(plan),
        header = header(plan, "The merge of the sweep's shards, after the array"),
        cmd = merge_command(plan),
    );
    let submit = format!(
        "#!/bin/sh\n\
         {header}set -eu\n\
         cd \"$(dirname \"$0\")\"\n\
         qsub sweep.sge\n\
         qsub merge.sge\n",
        header = header(plan, "Submits the sweep's array and its merge (SGE)"),
    );
    vec![
        ("sweep.sge".into(), script(sweep)),
        ("merge.sge".into(), script(merge)),
        ("submit.sh".into(), script(submit)),
    ]
}

/// A Kubernetes Job (JSON, which `kubectl apply -f` reads like YAML) running `args` in the
/// plan's directory on the volume `specfx-sweep` (a PersistentVolumeClaim mounted at `/work`),
/// with the image `specfx` (edit both to your cluster's).
fn k8s_job(name: &str, args: &[String], indexed: Option<&Plan>) -> serde_json::Value {
    let (cpu, memory) = match indexed {
        Some(p) => (
            p.resources.threads.to_string(),
            format!("{}Mi", p.resources.memory_mib),
        ),
        None => ("1".to_string(), "512Mi".to_string()),
    };
    // (An Indexed Job's pods get JOB_COMPLETION_INDEX from Kubernetes itself.)
    let env = vec![serde_json::json!({ "name": "RAYON_NUM_THREADS", "value": cpu })];
    let mut spec = serde_json::json!({
        "backoffLimit": 6,
        "template": { "spec": {
            "restartPolicy": "OnFailure",
            "containers": [{
                "name": "specfx",
                "image": "specfx",
                "workingDir": "/work",
                "command": ["sh", "-c", args.join(" ")],
                "env": env,
                "resources": {
                    "requests": { "cpu": cpu, "memory": memory },
                    "limits": { "memory": memory }
                },
                "volumeMounts": [{ "name": "work", "mountPath": "/work" }]
            }],
            "volumes": [{ "name": "work", "persistentVolumeClaim": { "claimName": "specfx-sweep" } }]
        } }
    });
    if let Some(p) = indexed {
        let extra = serde_json::json!({
            "completionMode": "Indexed",
            "completions": p.tasks,
            "parallelism": p.tasks,
            "backoffLimit": 6 * p.tasks,
            "activeDeadlineSeconds": p.resources.time_s * p.tasks
        });
        for (k, v) in extra.as_object().expect("an object") {
            spec[k] = v.clone();
        }
    }
    serde_json::json!({
        "apiVersion": "batch/v1",
        "kind": "Job",
        "metadata": { "name": name, "labels": { "app": "specfx-sweep" } },
        "spec": spec
    })
}

fn json(value: &serde_json::Value) -> Vec<u8> {
    let mut v = serde_json::to_vec_pretty(value).expect("a JSON value renders");
    v.push(b'\n');
    v
}

fn k8s(plan: &Plan) -> Vec<File> {
    let name = plan.job_name();
    let sweep = k8s_job(&name, &[sweep_command(plan)], Some(plan));
    let merge = k8s_job(&format!("{name}-merge"), &[merge_command(plan)], None);
    let submit = format!(
        "#!/bin/sh\n\
         {header}# The Jobs run in /work of the PersistentVolumeClaim specfx-sweep, which must hold this\n\
         # directory's files, with the image specfx (edit both in the two JSON manifests).\n\
         set -eu\n\
         cd \"$(dirname \"$0\")\"\n\
         kubectl apply -f sweep-job.json\n\
         kubectl wait --for=condition=complete --timeout={wait}s job/{name}\n\
         kubectl apply -f merge-job.json\n",
        header = header(plan, "Runs the sweep's Indexed Job, then its merge Job (Kubernetes)"),
        wait = plan.resources.time_s * plan.tasks,
    );
    vec![
        ("sweep-job.json".into(), json(&sweep)),
        ("merge-job.json".into(), json(&merge)),
        ("submit.sh".into(), script(submit)),
    ]
}

fn shell(plan: &Plan) -> Vec<File> {
    let threads = plan.resources.threads;
    let cmd = sweep_command(plan);
    // xargs -I replaces its token everywhere in the command: one that the command (the
    // --specfx path) does not hold.
    let mut token = "@".to_string();
    while cmd.contains(&token) {
        token.push('@');
    }
    let run = format!(
        "#!/bin/sh\n\
         {header}# Tasks run side by side, as many as the machine has cores for ({threads} threads each;\n\
         # SPECFX_JOBS overrides); each takes its shards from SPECFX_TASK_ID.\n\
         set -eu\n\
         cd \"$(dirname \"$0\")\"\n\
         jobs=${{SPECFX_JOBS:-$(( $(nproc) / {threads} ))}}\n\
         [ \"$jobs\" -ge 1 ] || jobs=1\n\
         seq 0 {last} | xargs -P \"$jobs\" -I {token} env SPECFX_TASK_ID={token} RAYON_NUM_THREADS={threads} \\\n  {cmd}\n\
         {merge}\n",
        header = header(plan, "Runs the sweep's tasks, then the merge, on this machine"),
        last = plan.tasks - 1,
        merge = merge_command(plan),
    );
    vec![("submit.sh".into(), script(run))]
}

/// The plan's files: the space, the scripts for its scheduler, and `plan.json`.
pub fn plan_files(plan: &Plan, space_toml: &str) -> Result<Vec<File>, Error> {
    let mut files = vec![(SPACE_FILE.to_string(), space_toml.as_bytes().to_vec())];
    files.extend(match plan.emit {
        Emit::Slurm => slurm(plan),
        Emit::Lsf => lsf(plan),
        Emit::Sge => sge(plan),
        Emit::K8s => k8s(plan),
        Emit::Shell => shell(plan),
    });
    files.push(crate::report::json_file("plan.json", plan)?);
    Ok(files)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analysis::cluster::PointCost;

    fn plan(emit: Emit, specfx: &str) -> Plan {
        let cost = PointCost {
            seconds: 1.0,
            peak_mib: 0,
            measured: false,
        };
        Plan::new(emit, &"ab".repeat(32), 12, (4, 1), cost, 2, specfx).unwrap()
    }

    #[test]
    fn the_script_names_are_those_each_plan_writes() {
        for emit in Emit::ALL {
            let names: Vec<String> = plan_files(&plan(emit, "specfx"), "")
                .unwrap()
                .into_iter()
                .map(|f| f.0)
                .collect();
            let mut want = vec![SPACE_FILE.to_string()];
            want.extend(script_names(emit).iter().map(|s| s.to_string()));
            want.push("plan.json".into());
            assert_eq!(names, want, "{emit:?}");
            assert!(names.iter().all(|n| is_plan_file(n)));
        }
        assert!(!is_plan_file("shards") && !is_plan_file("merged"));
        assert!(!is_plan_file("specfx-sweep-ababab-12_3.out"));
    }

    #[test]
    fn scheduler_options_reach_every_job_script_in_the_schedulers_words() {
        use crate::analysis::cluster::SchedulerOptions;
        let options = |qos: Option<&str>| SchedulerOptions {
            partition: Some("gpu".into()),
            account: Some("proj-7".into()),
            qos: qos.map(str::to_string),
            directives: vec!["--gres=gpu:1".into(), "--exclusive".into()],
        };
        let want: [(Emit, &[&str], usize); 3] = [
            (
                Emit::Slurm,
                &[
                    "#SBATCH --partition=gpu\n",
                    "#SBATCH --account=proj-7\n",
                    "#SBATCH --qos=high\n",
                    "#SBATCH --gres=gpu:1\n#SBATCH --exclusive\n",
                ],
                2,
            ),
            (
                Emit::Lsf,
                &[
                    "#BSUB -q gpu\n",
                    "#BSUB -P proj-7\n",
                    "#BSUB --gres=gpu:1\n",
                ],
                2,
            ),
            (
                Emit::Sge,
                &["#$ -q gpu\n", "#$ -A proj-7\n", "#$ --exclusive\n"],
                2,
            ),
        ];
        for (emit, lines, jobs) in want {
            let qos = (emit == Emit::Slurm).then_some("high");
            let p = plan(emit, "specfx").with_scheduler(options(qos)).unwrap();
            let files = plan_files(&p, "").unwrap();
            // The array's script and the merge's (the first two after the space).
            for (name, bytes) in &files[1..=jobs] {
                let text = String::from_utf8(bytes.clone()).unwrap();
                for line in lines {
                    assert!(text.contains(line), "{emit:?} {name}: {line:?} in {text}");
                }
            }
            // Without options the scripts are as they were: no such line.
            let plain = plan_files(&plan(emit, "specfx"), "").unwrap();
            let text = String::from_utf8(plain[1].1.clone()).unwrap();
            assert!(!text.contains("gpu"), "{text}");
        }
        // What a scheduler's scripts have no place for is refused, naming the option.
        for (emit, opts, option) in [
            (Emit::Lsf, options(Some("high")), "--qos"),
            (Emit::Sge, options(Some("high")), "--qos"),
            (Emit::K8s, options(None), "--partition"),
            (
                Emit::Shell,
                SchedulerOptions {
                    directives: vec!["-x".into()],
                    ..SchedulerOptions::default()
                },
                "--directive",
            ),
        ] {
            let e = plan(emit, "specfx")
                .with_scheduler(opts)
                .unwrap_err()
                .to_string();
            assert!(e.starts_with(option) && !e.contains('\n'), "{emit:?}: {e}");
        }
        for bad in [
            SchedulerOptions {
                partition: Some("two words".into()),
                ..SchedulerOptions::default()
            },
            SchedulerOptions {
                directives: vec!["--x\n#SBATCH --y".into()],
                ..SchedulerOptions::default()
            },
            SchedulerOptions {
                directives: vec!["#SBATCH --x".into()],
                ..SchedulerOptions::default()
            },
        ] {
            assert!(plan(Emit::Slurm, "specfx").with_scheduler(bad).is_err());
        }
    }

    #[test]
    fn the_shell_plans_xargs_token_is_not_in_its_command() {
        let files = plan_files(&plan(Emit::Shell, "/opt/a@b/specfx"), "").unwrap();
        let submit = String::from_utf8(files[1].1.clone()).unwrap();
        assert!(
            submit.contains("xargs -P \"$jobs\" -I @@ env SPECFX_TASK_ID=@@ "),
            "{submit}"
        );
        assert!(submit.contains("/opt/a@b/specfx sweep"), "{submit}");
    }
}
