//! A real Slurm: the test starts a single-host cluster of its own (munge, slurmctld and slurmd
//! from Debian's packages, every file under a temporary directory, listening on 127.0.0.1
//! only, stopped at the end, also when the test fails), submits the array job and the merge
//! that `specfx sweep plan --emit slurm` writes, and checks that the merged sweep is the
//! one-shot sweep byte for byte; then cancels a task mid-run (`scancel`), resubmits it, and
//! checks that its shard resumes and the merge is still the one-shot sweep; and runs a
//! calibration (yosys) as an array of shards and a merge, whose records are those of one
//! machine's run byte for byte.

use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};
use std::time::{Duration, Instant};

/// 12 points, a few milliseconds each.
const SPACE: &str = "n = \"16..=1024\"\n[vary]\nk = [3, 4, 5]\n\"square.rounding\" = [\"TRN\", \"RND\"]\narch = [\"pipelined\", \"folded\"]\n";

/// The same 12 points on a 20-bit cosine: about half a second each on the 2-core AMD machine
/// (more on slower ones), so the five points a task has left after its first one give it
/// seconds to be cancelled mid-shard. `SPACE`'s points now take milliseconds (sweep points
/// share their `cos^n`), a race the cancellation lost.
const WIDE_SPACE: &str = "n = \"16..=1024\"\n[base.c]\nformat = \"u1.20\"\n[base.d]\nformat = \"s1.20\"\n[vary]\nk = [3, 4, 5]\n\"square.rounding\" = [\"TRN\", \"RND\"]\narch = [\"pipelined\", \"folded\"]\n";

/// The daemons of a cluster, killed (and waited for) when dropped.
struct Cluster {
    dir: tempfile::TempDir,
    conf: PathBuf,
    daemons: Vec<Child>,
}

impl Drop for Cluster {
    fn drop(&mut self) {
        for d in self.daemons.iter_mut().rev() {
            let _ = d.kill();
            let _ = d.wait();
        }
    }
}

/// A free TCP port on 127.0.0.1 (free when asked; the daemons bind it a moment later).
fn free_port() -> u16 {
    std::net::TcpListener::bind("127.0.0.1:0")
        .and_then(|l| l.local_addr())
        .expect("a free port")
        .port()
}

fn short_host_name() -> String {
    let o = Command::new("hostname")
        .arg("-s")
        .output()
        .expect("hostname runs");
    String::from_utf8_lossy(&o.stdout).trim().to_string()
}

/// Whether `host` resolves to a loopback address (the daemons bind there).
fn resolves_to_loopback(host: &str) -> bool {
    use std::net::ToSocketAddrs;
    (host, 0)
        .to_socket_addrs()
        .is_ok_and(|mut a| a.any(|a| a.ip().is_loopback()))
}

fn spawn(dir: &Path, name: &str, cmd: &mut Command) -> Child {
    let log = std::fs::File::create(dir.join(format!("{name}.out"))).unwrap();
    cmd.stdout(Stdio::from(log.try_clone().unwrap()))
        .stderr(Stdio::from(log))
        .spawn()
        .unwrap_or_else(|e| panic!("{name} does not start: {e}"))
}

impl Cluster {
    /// Starts munge, slurmctld and slurmd, and waits until the node is idle.
    fn start() -> Cluster {
        let host = short_host_name();
        assert!(
            resolves_to_loopback(&host),
            "the host name {host:?} does not resolve to a loopback address, where the test's Slurm daemons listen: add it to /etc/hosts (127.0.0.1 {host})"
        );
        let dir = tempfile::tempdir().expect("a temporary directory");
        let d = dir.path();
        for sub in ["state", "spool"] {
            std::fs::create_dir(d.join(sub)).unwrap();
        }
        let key: Vec<u8> = (0..1024u32)
            .map(|i| (i.wrapping_mul(2_654_435_761) >> 13) as u8)
            .collect();
        std::fs::write(d.join("munge.key"), key).unwrap();
        use std::os::unix::fs::PermissionsExt;
        std::fs::set_permissions(d.join("munge.key"), std::fs::Permissions::from_mode(0o400))
            .unwrap();
        let socket = d.join("munge.socket");
        let conf = d.join("slurm.conf");
        let cpus = std::thread::available_parallelism().map_or(1, |n| n.get());
        let p = |name: &str| d.join(name).display().to_string();
        std::fs::write(
            &conf,
            format!(
                "ClusterName=specfx\n\
                 SlurmctldHost={host}(127.0.0.1)\n\
                 SlurmctldPort={ctld}\n\
                 SlurmdPort={slurmd}\n\
                 AuthType=auth/munge\n\
                 CredType=cred/munge\n\
                 AuthInfo=socket={socket}\n\
                 ProctrackType=proctrack/linuxproc\n\
                 TaskPlugin=task/none\n\
                 JobAcctGatherType=jobacct_gather/none\n\
                 CommunicationParameters=NoCtldInAddrAny,NoInAddrAny\n\
                 StateSaveLocation={state}\n\
                 SlurmdSpoolDir={spool}\n\
                 SlurmctldPidFile={ctld_pid}\n\
                 SlurmdPidFile={slurmd_pid}\n\
                 SlurmctldLogFile={ctld_log}\n\
                 SlurmdLogFile={slurmd_log}\n\
                 SlurmUser=root\n\
                 SlurmdUser=root\n\
                 SelectType=select/cons_tres\n\
                 SelectTypeParameters=CR_CPU_Memory\n\
                 SchedulerParameters=batch_sched_delay=0\n\
                 ReturnToService=2\n\
                 MpiDefault=none\n\
                 NodeName={host} NodeAddr=127.0.0.1 CPUs={cpus} RealMemory=4000 State=UNKNOWN\n\
                 PartitionName=test Nodes={host} Default=YES MaxTime=INFINITE State=UP\n",
                ctld = free_port(),
                slurmd = free_port(),
                socket = socket.display(),
                state = p("state"),
                spool = p("spool"),
                ctld_pid = p("slurmctld.pid"),
                slurmd_pid = p("slurmd.pid"),
                ctld_log = p("slurmctld.log"),
                slurmd_log = p("slurmd.log"),
            ),
        )
        .unwrap();
        let mut cluster = Cluster {
            conf: conf.clone(),
            daemons: Vec::new(),
            dir,
        };
        let d = cluster.dir.path().to_path_buf();
        cluster.daemons.push(spawn(
            &d,
            "munged",
            Command::new("munged")
                .arg("--foreground")
                .arg("--force")
                .arg(format!("--key-file={}", d.join("munge.key").display()))
                .arg(format!("--socket={}", socket.display()))
                .arg(format!("--pid-file={}", d.join("munged.pid").display()))
                .arg(format!("--log-file={}", d.join("munged.log").display()))
                .arg(format!("--seed-file={}", d.join("munged.seed").display())),
        ));
        wait_for("munge's socket", Duration::from_secs(10), || {
            socket.exists()
        });
        for daemon in ["slurmctld", "slurmd"] {
            let child = spawn(
                &d,
                daemon,
                Command::new(daemon)
                    .arg("-D")
                    .arg("-f")
                    .arg(&conf)
                    .env("SLURM_CONF", &conf),
            );
            cluster.daemons.push(child);
        }
        wait_for("the node to be idle", Duration::from_secs(30), || {
            cluster
                .run("sinfo", &["-h", "-o", "%t"])
                .is_ok_and(|o| String::from_utf8_lossy(&o.stdout).trim() == "idle")
        });
        cluster
    }

    /// Runs a Slurm client command against this cluster.
    fn run(&self, cmd: &str, args: &[&str]) -> std::io::Result<Output> {
        Command::new(cmd)
            .args(args)
            .env("SLURM_CONF", &self.conf)
            .output()
    }

    /// Like [`Cluster::run`], and it must succeed; returns stdout.
    fn ok(&self, cmd: &str, args: &[&str], dir: &Path) -> String {
        let o = Command::new(cmd)
            .args(args)
            .current_dir(dir)
            .env("SLURM_CONF", &self.conf)
            .output()
            .unwrap();
        assert!(
            o.status.success(),
            "{cmd} {args:?}: {}{}",
            String::from_utf8_lossy(&o.stderr),
            self.logs()
        );
        String::from_utf8_lossy(&o.stdout).into_owned()
    }

    /// Waits until no job of the cluster is pending or running.
    fn wait_idle(&self, timeout: Duration) {
        wait_for("the jobs to finish", timeout, || {
            self.run("squeue", &["-h"])
                .is_ok_and(|o| o.stdout.is_empty())
        });
    }

    /// The end of the daemons' logs, for a failure's message.
    fn logs(&self) -> String {
        ["slurmctld.log", "slurmd.log", "munged.log"]
            .iter()
            .map(|f| {
                let t = std::fs::read_to_string(self.dir.path().join(f)).unwrap_or_default();
                let tail: Vec<&str> = t.lines().rev().take(15).collect();
                format!(
                    "\n--- {f}\n{}",
                    tail.into_iter().rev().collect::<Vec<_>>().join("\n")
                )
            })
            .collect()
    }
}

fn wait_for(what: &str, timeout: Duration, ready: impl FnMut() -> bool) {
    poll(what, timeout, Duration::from_millis(100), ready);
}

/// `wait_for`, looking every `every`.
fn poll(what: &str, timeout: Duration, every: Duration, mut ready: impl FnMut() -> bool) {
    let start = Instant::now();
    while !ready() {
        assert!(start.elapsed() < timeout, "timed out waiting for {what}");
        std::thread::sleep(every);
    }
}

fn specfx(args: &[&str]) -> Output {
    let o = Command::new(env!("CARGO_BIN_EXE_specfx"))
        .args(args)
        .env_remove("SLURM_ARRAY_TASK_ID")
        .env_remove("SPECFX_TASK_ID")
        .output()
        .unwrap();
    assert!(
        o.status.success(),
        "specfx {args:?}: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    o
}

/// Every file of a sweep directory but the result marker (a merge's differs from a sweep's).
fn files(dir: &Path) -> Vec<(String, Vec<u8>)> {
    let mut v: Vec<(String, Vec<u8>)> = std::fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
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

/// `specfx sweep plan --emit slurm` of `space` into `out` with `tasks` tasks of 2 shards, on
/// the test cluster's partition and with a directive of the user's own, which sbatch takes.
fn plan(space: &Path, out: &Path, tasks: &str) {
    specfx(&[
        "sweep",
        "plan",
        "--partition",
        "test",
        "--directive",
        "--comment=specfx-test",
        "--space",
        space.to_str().unwrap(),
        "--emit",
        "slurm",
        "--tasks",
        tasks,
        "--shards-per-task",
        "2",
        "--threads",
        "1",
        "--seconds-per-point",
        "1",
        "--specfx",
        env!("CARGO_BIN_EXE_specfx"),
        "--out",
        out.to_str().unwrap(),
    ]);
}

#[test]
fn a_slurm_array_sweeps_and_calibrates_like_one_machine_through_a_cancelled_task() {
    let cluster = Cluster::start();
    let root = cluster.dir.path().join("work");
    std::fs::create_dir(&root).unwrap();
    let space = root.join("space.toml");
    std::fs::write(&space, SPACE).unwrap();
    let one = root.join("one");
    specfx(&[
        "sweep",
        "--space",
        space.to_str().unwrap(),
        "--out",
        one.to_str().unwrap(),
    ]);
    let one = files(&one);

    // The plan's submit.sh: the array (3 tasks of 2 shards) and the merge after it.
    let whole = root.join("whole");
    plan(&space, &whole, "3");
    let said = cluster.ok("sh", &["submit.sh"], &whole);
    assert!(said.starts_with("submitted the array "), "{said}");
    cluster.wait_idle(Duration::from_secs(300));
    assert!(
        files(&whole.join("merged")) == one,
        "the merge is not the one-shot sweep{}",
        cluster.logs()
    );
    let logs: Vec<_> = std::fs::read_dir(&whole)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".out"))
        .collect();
    assert_eq!(logs.len(), 4, "three tasks' and the merge's logs: {logs:?}");

    // One task of 2 shards (12 points of the wide space): cancelled once its first point is
    // written, the merge that waited for it is never run; resubmitted, it resumes its shards.
    let wide = root.join("wide.toml");
    std::fs::write(&wide, WIDE_SPACE).unwrap();
    let wide_one = root.join("wide-one");
    specfx(&[
        "sweep",
        "--space",
        wide.to_str().unwrap(),
        "--out",
        wide_one.to_str().unwrap(),
    ]);
    let wide_one = files(&wide_one);
    let cancelled = root.join("cancelled");
    plan(&wide, &cancelled, "1");
    // Submitted by its submit.sh: the array, and the merge after it (`afterok`).
    let said = cluster.ok("sh", &["submit.sh"], &cancelled);
    let array = said
        .strip_prefix("submitted the array ")
        .and_then(|r| r.split_whitespace().next())
        .unwrap_or_else(|| panic!("{said}"))
        .to_string();
    let log = cancelled.join("shards/shard-0/points.jsonl");
    let every = Duration::from_millis(10);
    poll(
        "the task's first point",
        Duration::from_secs(120),
        every,
        || std::fs::read_to_string(&log).is_ok_and(|t| t.lines().count() >= 1),
    );
    cluster.ok("scancel", &[&format!("{array}_0")], &cancelled);
    wait_for("the task to end", Duration::from_secs(60), || {
        cluster
            .run("squeue", &["-h", "-j", &array])
            .is_ok_and(|o| o.stdout.is_empty())
    });
    let done_before = std::fs::read_to_string(&log).unwrap().lines().count();
    assert!(
        done_before < 6,
        "the task finished its shard before it was cancelled"
    );
    assert!(!cancelled.join("merged").exists());
    // The merge's dependency can never be met now: it waits, for ever.
    let pending = cluster.ok("squeue", &["-h", "-o", "%j %T"], &cancelled);
    assert!(
        pending.trim().ends_with("-merge PENDING"),
        "the merge is not waiting: {pending}"
    );
    // resubmit.sh, as docs/cluster.md says: the task again (its array has one task, it takes
    // the same shards and resumes them), and the merge after it, the stale one cancelled.
    let said = cluster.ok("sh", &["resubmit.sh", "0"], &cancelled);
    assert!(said.starts_with("resubmitted tasks 0 as "), "{said}");
    cluster.wait_idle(Duration::from_secs(60));
    assert!(
        files(&cancelled.join("merged")) == wide_one,
        "the merge after the resubmission is not the one-shot sweep"
    );
    let resumed = std::fs::read_dir(&cancelled)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "out"))
        .map(|p| std::fs::read_to_string(p).unwrap())
        .any(|t| {
            t.lines()
                .any(|l| l.contains(" in this shard, ") && !l.ends_with(", 0 already done"))
        });
    assert!(resumed, "no task log says it resumed a shard");

    // A calibration of two configurations as an array of two shards, then the merge.
    let cal = root.join("calibration");
    std::fs::create_dir(&cal).unwrap();
    let bin = env!("CARGO_BIN_EXE_specfx");
    std::fs::write(
        cal.join("calibrate.sbatch"),
        format!(
            "#!/bin/bash\n#SBATCH --array=0-1\n#SBATCH --cpus-per-task=1\n#SBATCH --mem=512M\n\
             #SBATCH --output=%x-%A_%a.out\nset -euo pipefail\n\
             {bin} calibrate --targets ice40 --count 2 --shard auto/2 --data 'shards/shard-{{shard}}'\n"
        ),
    )
    .unwrap();
    std::fs::write(
        cal.join("merge.sbatch"),
        format!(
            "#!/bin/bash\n#SBATCH --output=%x-%j.out\nset -euo pipefail\n\
             {bin} calibrate merge --data merged shards/shard-*\n"
        ),
    )
    .unwrap();
    let array = cluster.ok("sbatch", &["--parsable", "calibrate.sbatch"], &cal);
    let array = array.trim().split(';').next().unwrap().to_string();
    cluster.ok(
        "sbatch",
        &[
            "--wait",
            &format!("--dependency=afterok:{array}"),
            "merge.sbatch",
        ],
        &cal,
    );
    specfx(&[
        "calibrate",
        "--targets",
        "ice40",
        "--count",
        "2",
        "--data",
        cal.join("one").to_str().unwrap(),
    ]);
    let read = |p: PathBuf| {
        std::fs::read(&p).unwrap_or_else(|e| panic!("{}: {e}{}", p.display(), cluster.logs()))
    };
    let merged = read(cal.join("merged/ice40.jsonl"));
    assert_eq!(String::from_utf8_lossy(&merged).lines().count(), 2);
    assert!(
        merged == read(cal.join("one/ice40.jsonl")),
        "the merged calibration is not one machine's"
    );
}
