//! Array jobs on a cluster: which shards of a sharded run (a sweep, a calibration) one array
//! task takes, from the index its scheduler hands it (Slurm, LSF, SGE, PBS, Kubernetes) or
//! from `--shard I/N` given by hand, and the `{shard}` placeholder that names each shard's
//! directory.

use crate::error::Error;

/// The most array tasks a run is spread over (`sweep plan --tasks`, and a scheduler's count).
pub const MAX_TASKS: u64 = 100_000;
/// The most shards one array task runs (`--shards-per-task`).
pub const MAX_SHARDS_PER_TASK: u64 = 1000;
/// The most shards a run has (`--shard I/N`, `auto/N`): [`MAX_TASKS`] tasks of
/// [`MAX_SHARDS_PER_TASK`] shards.
pub const MAX_SHARDS: u64 = MAX_TASKS * MAX_SHARDS_PER_TASK;

/// How a run is sharded, as `--shard` gives it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ShardSpec {
    /// `I/N`: shard `index` of `count`, given by hand.
    Given {
        /// `I`, in `0..count`.
        index: u64,
        /// `N`, at least 1.
        count: u64,
    },
    /// `auto/N` (`count` given) or `auto` (the scheduler's task count times the shards per
    /// task): the task index comes from the scheduler's environment.
    Auto {
        /// `N`, when given.
        count: Option<u64>,
    },
}

const SHARD_EXPECTED: &str = "expected I/N with 0 <= I < N, auto/N (the index from the scheduler's array task) or auto (the count too)";

/// Parses `--shard`: `I/N`, `auto/N` or `auto`.
///
/// # Examples
/// ```
/// use specfx::analysis::cluster::{parse_shard_spec, ShardSpec};
/// assert_eq!(parse_shard_spec("1/4").unwrap(), ShardSpec::Given { index: 1, count: 4 });
/// assert_eq!(parse_shard_spec("auto/8").unwrap(), ShardSpec::Auto { count: Some(8) });
/// assert_eq!(parse_shard_spec("auto").unwrap(), ShardSpec::Auto { count: None });
/// assert!(parse_shard_spec("4/4").is_err());
/// assert!(parse_shard_spec("auto/0").is_err());
/// ```
pub fn parse_shard_spec(s: &str) -> Result<ShardSpec, Error> {
    let bad = || Error::Cluster {
        option: "--shard".into(),
        problem: format!("{SHARD_EXPECTED}, got '{}'", crate::error::OneLine(s)),
    };
    let count = |n: &str| match n.trim().parse::<u64>() {
        Ok(n) if n >= 1 => Ok(n),
        _ => Err(bad()),
    };
    match s.trim().split_once('/') {
        None if s.trim() == "auto" => Ok(ShardSpec::Auto { count: None }),
        None => Err(bad()),
        Some((i, n)) if i.trim() == "auto" => Ok(ShardSpec::Auto {
            count: Some(count(n)?),
        }),
        Some((i, n)) => {
            let count = count(n)?;
            match i.trim().parse::<u64>() {
                Ok(index) if index < count => Ok(ShardSpec::Given { index, count }),
                _ => Err(bad()),
            }
        }
    }
}

/// One scheduler's array-task variables.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Scheduler {
    /// Its name in messages.
    pub name: &'static str,
    /// The variable holding the task's index.
    pub index_var: &'static str,
    /// The index of the first task (0 or 1).
    pub first: u64,
    /// The variable holding the number of tasks, or the last index when counting from 1,
    /// where the scheduler sets one.
    pub count_var: Option<&'static str>,
    /// A value of `index_var` that means "not an array task" (SGE's `undefined`, LSF's 0).
    pub not_an_array: Option<&'static str>,
}

/// The schedulers whose array index `--shard auto` reads, in the order they are looked up.
pub const SCHEDULERS: [Scheduler; 5] = [
    Scheduler {
        name: "Slurm",
        index_var: "SLURM_ARRAY_TASK_ID",
        first: 0,
        count_var: Some("SLURM_ARRAY_TASK_COUNT"),
        not_an_array: None,
    },
    Scheduler {
        name: "LSF",
        index_var: "LSB_JOBINDEX",
        first: 1,
        count_var: Some("LSB_JOBINDEX_END"),
        not_an_array: Some("0"),
    },
    Scheduler {
        name: "SGE",
        index_var: "SGE_TASK_ID",
        first: 1,
        count_var: Some("SGE_TASK_LAST"),
        not_an_array: Some("undefined"),
    },
    Scheduler {
        name: "PBS",
        index_var: "PBS_ARRAYID",
        first: 0,
        count_var: None,
        not_an_array: None,
    },
    Scheduler {
        name: "Kubernetes",
        index_var: "JOB_COMPLETION_INDEX",
        first: 0,
        count_var: None,
        not_an_array: None,
    },
];

/// specfx's own task variable (0-based): when set, it is the task index whatever scheduler's
/// variables are set too (a shell loop inside a Slurm allocation, a scheduler specfx does not
/// know).
pub const SPECFX_TASK_VAR: &str = "SPECFX_TASK_ID";

/// The array task a scheduler says this process is.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Task {
    /// The scheduler that set it.
    pub scheduler: &'static str,
    /// The variable read, and its value as given.
    pub variable: &'static str,
    /// The value of the variable.
    pub value: String,
    /// The task's index counted from 0.
    pub index: u64,
    /// The number of tasks, where the scheduler says it.
    pub count: Option<u64>,
}

fn env_error(problem: String) -> Error {
    Error::Cluster {
        option: "--shard auto".into(),
        problem,
    }
}

/// The array task of this process, from the environment `env` gives (a lookup, so tests pass
/// their own): [`SPECFX_TASK_VAR`] when set, else the schedulers' variables; `None` when none
/// is set; an error when a value is not a number, or two schedulers' variables name different
/// tasks.
pub fn task_from_env(env: &dyn Fn(&str) -> Option<String>) -> Result<Option<Task>, Error> {
    // specfx's own variable is explicit: it wins over whatever scheduler runs the process.
    if let Some(value) = env(SPECFX_TASK_VAR) {
        let value = value.trim().to_string();
        let index = value.parse::<u64>().map_err(|_| {
            env_error(format!(
                "{SPECFX_TASK_VAR}={}: expected a whole number (the task index, from 0)",
                crate::error::OneLine(&value)
            ))
        })?;
        return Ok(Some(Task {
            scheduler: "specfx",
            variable: SPECFX_TASK_VAR,
            value,
            index,
            count: None,
        }));
    }
    let mut found: Option<Task> = None;
    for s in &SCHEDULERS {
        let Some(value) = env(s.index_var) else {
            continue;
        };
        let value = value.trim().to_string();
        if s.not_an_array == Some(value.as_str()) {
            continue;
        }
        let number = |var: &str, v: &str, what: &str| {
            v.trim().parse::<u64>().map_err(|_| {
                env_error(format!(
                    "{var}={}: expected a whole number ({}'s {what})",
                    crate::error::OneLine(v),
                    s.name
                ))
            })
        };
        let given = number(s.index_var, &value, "array task index")?;
        if given < s.first {
            return Err(env_error(format!(
                "{}={value}: expected {} or more ({} counts array tasks from {})",
                s.index_var, s.first, s.name, s.first
            )));
        }
        let count = match s.count_var.and_then(|var| env(var).map(|v| (var, v))) {
            Some((var, v)) => match number(var, &v, "number of array tasks")? {
                0 => {
                    return Err(env_error(format!(
                        "{var}=0: expected 1 or more ({}'s number of array tasks)",
                        s.name
                    )))
                }
                n => Some(n),
            },
            None => None,
        };
        let task = Task {
            scheduler: s.name,
            variable: s.index_var,
            value,
            index: given - s.first,
            count,
        };
        match &found {
            Some(other) if other.index != task.index => {
                return Err(env_error(format!(
                    "{}={} ({}) and {}={} ({}) name different array tasks: expected one scheduler's index",
                    other.variable,
                    other.value,
                    other.scheduler,
                    task.variable,
                    task.value,
                    task.scheduler
                )))
            }
            Some(_) => {}
            None => found = Some(task),
        }
    }
    Ok(found)
}

/// The shards one process runs: `shards` of `count`, and the array task it is, if any.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Assignment {
    /// The number of shards of the whole run (`N`).
    pub count: u64,
    /// The shards this process runs, ascending: task `t` of `T` takes `t`, `t + T`, ...
    pub shards: Vec<u64>,
    /// The number of array tasks the run is spread over.
    pub tasks: u64,
    /// The array task this process is (none for a shard given by hand).
    pub task: Option<Task>,
}

impl Assignment {
    /// Whether the shards come from a scheduler's task or are several: each then needs a
    /// directory of its own (a `{shard}` placeholder), and the log says which this process
    /// took.
    pub fn several_or_scheduled(&self) -> bool {
        self.task.is_some() || self.shards.len() > 1
    }

    /// One line for the log: which task this is and which shards it takes.
    pub fn describe(&self) -> String {
        let shards = self
            .shards
            .iter()
            .map(u64::to_string)
            .collect::<Vec<_>>()
            .join(", ");
        let which = if self.shards.len() == 1 {
            format!("shard {shards} of {}", self.count)
        } else {
            format!("shards {shards} of {}", self.count)
        };
        match &self.task {
            Some(t) => format!(
                "{} array task {} of {} ({}={}): {which}",
                t.scheduler, t.index, self.tasks, t.variable, t.value
            ),
            None => which,
        }
    }
}

/// The shards this process runs under `spec`, with `per_task` shards per array task (task `t`
/// of `T = ceil(N / per_task)` takes shards `t, t + T, t + 2T, ...`), the task read from
/// `env` for `auto`. Refused in one line: `auto` with no scheduler's index set, `auto` without
/// a count where the scheduler gives none, a task index out of range, and several shards per
/// task with a shard given by hand.
///
/// # Examples
/// ```
/// use specfx::analysis::cluster::{assign, ShardSpec};
/// let env = |var: &str| (var == "SLURM_ARRAY_TASK_ID").then(|| "2".to_string());
/// let a = assign(ShardSpec::Auto { count: Some(10) }, 3, &env).unwrap();
/// assert_eq!((a.tasks, a.shards), (4, vec![2, 6]));
/// ```
pub fn assign(
    spec: ShardSpec,
    per_task: u64,
    env: &dyn Fn(&str) -> Option<String>,
) -> Result<Assignment, Error> {
    if !(1..=MAX_SHARDS_PER_TASK).contains(&per_task) {
        return Err(Error::Cluster {
            option: "--shards-per-task".into(),
            problem: format!("expected 1 to {MAX_SHARDS_PER_TASK}, got {per_task}"),
        });
    }
    let bounded = |count: u64| {
        if count > MAX_SHARDS {
            Err(Error::Cluster {
                option: "--shard".into(),
                problem: format!(
                    "expected at most {MAX_SHARDS} shards ({MAX_TASKS} tasks of {MAX_SHARDS_PER_TASK}), got {count}"
                ),
            })
        } else {
            Ok(count)
        }
    };
    match spec {
        ShardSpec::Given { index, count } => {
            if per_task != 1 {
                return Err(Error::Cluster {
                    option: "--shards-per-task".into(),
                    problem: format!(
                        "takes --shard auto/N (the task index from a scheduler), not a shard given by hand ({index}/{count})"
                    ),
                });
            }
            bounded(count)?;
            Ok(Assignment {
                count,
                shards: vec![index],
                tasks: count,
                task: None,
            })
        }
        ShardSpec::Auto { count } => {
            let names = SCHEDULERS.map(|s| s.index_var).join(", ") + " or " + SPECFX_TASK_VAR;
            let task = task_from_env(env)?.ok_or_else(|| {
                env_error(format!(
                    "no scheduler's array task index is set: expected one of {names} (or --shard I/N)"
                ))
            })?;
            let count = match (count, task.count) {
                (Some(n), _) => n,
                (None, Some(tasks)) => tasks.checked_mul(per_task).ok_or_else(|| {
                    env_error(format!("{tasks} tasks of {per_task} shards: too many shards"))
                })?,
                (None, None) => {
                    return Err(env_error(format!(
                        "{} does not say how many array tasks there are ({} only): expected --shard auto/N",
                        task.scheduler, task.variable
                    )))
                }
            };
            let count = bounded(count)?;
            let tasks = count.div_ceil(per_task);
            if task.index >= tasks {
                let spread = if per_task == 1 {
                    String::new()
                } else {
                    format!(" at {per_task} shards per task")
                };
                return Err(env_error(format!(
                    "{}={} is array task {} (counted from 0), but {count} shards{spread} make {tasks} tasks (0..={})",
                    task.variable,
                    task.value,
                    task.index,
                    tasks - 1
                )));
            }
            Ok(Assignment {
                count,
                shards: (task.index..count).step_by(tasks as usize).collect(),
                tasks,
                task: Some(task),
            })
        }
    }
}

/// The shards this process runs under `spec` (see [`assign`]) and the directory of each: the
/// path `template` of the option `flag` (`--out`, `--data`) with `{shard}` replaced by the
/// shard's index (see [`shard_path`]). Every directory is known before the first shard runs,
/// so a missing placeholder is refused before any work.
///
/// # Examples
/// ```
/// use specfx::analysis::cluster::{assign_dirs, ShardSpec};
/// use std::path::{Path, PathBuf};
/// let env = |var: &str| (var == "SLURM_ARRAY_TASK_ID").then(|| "1".to_string());
/// let spec = ShardSpec::Auto { count: Some(4) };
/// let (a, dirs) = assign_dirs(spec, 2, &env, Path::new("o/s{shard}"), "--out").unwrap();
/// assert_eq!(a.shards, vec![1, 3]);
/// assert_eq!(dirs, vec![PathBuf::from("o/s1"), PathBuf::from("o/s3")]);
/// let e = assign_dirs(spec, 2, &env, Path::new("cal"), "--data").unwrap_err();
/// assert!(e.to_string().starts_with("--data: expected a {shard} placeholder"));
/// ```
pub fn assign_dirs(
    spec: ShardSpec,
    per_task: u64,
    env: &dyn Fn(&str) -> Option<String>,
    template: &std::path::Path,
    flag: &str,
) -> Result<(Assignment, Vec<std::path::PathBuf>), Error> {
    let assignment = assign(spec, per_task, env)?;
    let required = assignment.several_or_scheduled();
    let dirs = assignment
        .shards
        .iter()
        .map(|&i| match template.to_str() {
            Some(t) => shard_path(t, i, assignment.count, required)
                .map(std::path::PathBuf::from)
                .map_err(|e| match e {
                    Error::Cluster { problem, .. } => Error::Cluster {
                        option: flag.to_string(),
                        problem,
                    },
                    e => e,
                }),
            None if required => Err(Error::Cluster {
                option: flag.to_string(),
                problem: format!(
                    "expected a UTF-8 path holding {SHARD_PLACEHOLDER}, got {}",
                    crate::error::OneLine(&template.display().to_string())
                ),
            }),
            None => Ok(template.to_path_buf()),
        })
        .collect::<Result<_, Error>>()?;
    Ok((assignment, dirs))
}

/// The placeholder of a shard's index in an output path.
pub const SHARD_PLACEHOLDER: &str = "{shard}";

/// The output directory of shard `index` of `count`: `{shard}` in `template` replaced by the
/// index, zero-padded to the width of the largest (so that the shards' directories sort in
/// order). Refused when the run takes its shard from a scheduler or takes several and the
/// template has no placeholder: every task would write one directory.
///
/// # Examples
/// ```
/// use specfx::analysis::cluster::shard_path;
/// assert_eq!(shard_path("out/shard-{shard}", 7, 100, true).unwrap(), "out/shard-07");
/// assert_eq!(shard_path("out", 7, 100, false).unwrap(), "out");
/// assert!(shard_path("out", 7, 100, true).is_err());
/// ```
pub fn shard_path(template: &str, index: u64, count: u64, required: bool) -> Result<String, Error> {
    if !template.contains(SHARD_PLACEHOLDER) {
        if required {
            return Err(Error::Cluster {
                option: "--out".into(),
                problem: format!(
                    "expected a {SHARD_PLACEHOLDER} placeholder in '{}' (each shard writes its own directory; for example --out sweep/shard-{SHARD_PLACEHOLDER})",
                    crate::error::OneLine(template)
                ),
            });
        }
        return Ok(template.to_string());
    }
    // `o/{shard}/../x` names `o/x` for every shard: the placeholder must survive the path's
    // `..` components.
    let mut kept: Vec<&str> = Vec::new();
    for part in template.split('/') {
        match part {
            "" | "." => {}
            ".." if kept.last().is_some_and(|p| *p != "..") => {
                kept.pop();
            }
            _ => kept.push(part),
        }
    }
    if !kept.iter().any(|p| p.contains(SHARD_PLACEHOLDER)) {
        return Err(Error::Cluster {
            option: "--out".into(),
            problem: format!(
                "'{}': a '..' after {SHARD_PLACEHOLDER} cancels it, so every shard would write one directory: expected {SHARD_PLACEHOLDER} in the directory's own path",
                crate::error::OneLine(template)
            ),
        });
    }
    let width = (count - 1).max(1).to_string().len();
    Ok(template.replace(SHARD_PLACEHOLDER, &format!("{index:0width$}")))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn env_of<'a>(vars: &'a [(&'a str, &'a str)]) -> impl Fn(&str) -> Option<String> + 'a {
        move |k| {
            vars.iter()
                .find(|(n, _)| *n == k)
                .map(|(_, v)| v.to_string())
        }
    }

    #[test]
    fn every_schedulers_index_is_read_from_its_first_task() {
        // Each scheduler's documented numbering: the first task of an array is shard 0.
        type Vars<'a> = &'a [(&'a str, &'a str)];
        let cases: [(Vars, u64, Option<u64>); 6] = [
            (
                &[
                    ("SLURM_ARRAY_TASK_ID", "0"),
                    ("SLURM_ARRAY_TASK_COUNT", "8"),
                ],
                0,
                Some(8),
            ),
            (
                &[("LSB_JOBINDEX", "1"), ("LSB_JOBINDEX_END", "8")],
                0,
                Some(8),
            ),
            (&[("SGE_TASK_ID", "1"), ("SGE_TASK_LAST", "8")], 0, Some(8)),
            (&[("PBS_ARRAYID", "0")], 0, None),
            (&[("JOB_COMPLETION_INDEX", "0")], 0, None),
            (&[("SGE_TASK_ID", "8")], 7, None),
        ];
        for (vars, index, count) in cases {
            let t = task_from_env(&env_of(vars)).unwrap().unwrap();
            assert_eq!((t.index, t.count), (index, count), "{vars:?}");
        }
    }

    #[test]
    fn specfx_own_variable_wins_over_a_schedulers() {
        let vars = [("SLURM_ARRAY_TASK_ID", "5"), ("SPECFX_TASK_ID", "2")];
        let t = task_from_env(&env_of(&vars)).unwrap().unwrap();
        assert_eq!((t.scheduler, t.index, t.count), ("specfx", 2, None));
        let e = task_from_env(&env_of(&[("SPECFX_TASK_ID", "two")])).unwrap_err();
        assert!(
            e.to_string()
                .contains("SPECFX_TASK_ID=two: expected a whole number"),
            "{e}"
        );
    }

    #[test]
    fn not_an_array_job_is_no_task() {
        assert_eq!(task_from_env(&env_of(&[])).unwrap(), None);
        assert_eq!(
            task_from_env(&env_of(&[("LSB_JOBINDEX", "0")])).unwrap(),
            None
        );
        assert_eq!(
            task_from_env(&env_of(&[("SGE_TASK_ID", "undefined")])).unwrap(),
            None
        );
    }

    #[test]
    fn bad_or_disagreeing_indexes_are_refused_in_one_line() {
        for (vars, needle) in [
            (
                &[("SLURM_ARRAY_TASK_ID", "x")][..],
                "SLURM_ARRAY_TASK_ID=x: expected a whole number",
            ),
            (&[("SGE_TASK_ID", "-1")][..], "SGE_TASK_ID=-1"),
            (
                &[("SLURM_ARRAY_TASK_ID", "2"), ("JOB_COMPLETION_INDEX", "3")][..],
                "name different array tasks",
            ),
            (
                &[
                    ("SLURM_ARRAY_TASK_ID", "1"),
                    ("SLURM_ARRAY_TASK_COUNT", "many"),
                ][..],
                "SLURM_ARRAY_TASK_COUNT=many",
            ),
        ] {
            let e = task_from_env(&env_of(vars)).unwrap_err().to_string();
            assert!(e.contains(needle), "{e}");
            assert!(!e.contains('\n'), "{e}");
        }
        // Two schedulers naming the same task (0-based Slurm 2, 1-based SGE 3) agree.
        let both = [("SLURM_ARRAY_TASK_ID", "2"), ("SGE_TASK_ID", "3")];
        assert_eq!(task_from_env(&env_of(&both)).unwrap().unwrap().index, 2);
    }

    #[test]
    fn tasks_take_strided_shards_and_cover_each_once() {
        for (count, per_task) in [(10u64, 1u64), (10, 3), (10, 10), (7, 4), (1, 5)] {
            let tasks = count.div_ceil(per_task);
            let mut seen = Vec::new();
            for t in 0..tasks {
                let v = t.to_string();
                let vars = [("JOB_COMPLETION_INDEX", v.as_str())];
                let env = env_of(&vars);
                let a = assign(ShardSpec::Auto { count: Some(count) }, per_task, &env).unwrap();
                assert_eq!(a.tasks, tasks);
                assert!(a.shards.len() as u64 <= per_task && !a.shards.is_empty());
                seen.extend(a.shards);
            }
            seen.sort_unstable();
            assert_eq!(seen, (0..count).collect::<Vec<_>>(), "{count} {per_task}");
        }
    }

    #[test]
    fn assignments_out_of_range_or_without_a_count_are_refused() {
        let slurm5 = env_of(&[("SLURM_ARRAY_TASK_ID", "5")]);
        let e = assign(ShardSpec::Auto { count: Some(10) }, 2, &slurm5).unwrap_err();
        assert!(e.to_string().contains("make 5 tasks (0..=4)"), "{e}");
        let k8s = env_of(&[("JOB_COMPLETION_INDEX", "1")]);
        let e = assign(ShardSpec::Auto { count: None }, 1, &k8s).unwrap_err();
        assert!(e.to_string().contains("expected --shard auto/N"), "{e}");
        let e = assign(ShardSpec::Auto { count: Some(4) }, 1, &env_of(&[])).unwrap_err();
        assert!(
            e.to_string().contains("SLURM_ARRAY_TASK_ID, LSB_JOBINDEX"),
            "{e}"
        );
        let e = assign(ShardSpec::Given { index: 0, count: 4 }, 2, &k8s).unwrap_err();
        assert!(e.to_string().contains("--shards-per-task"), "{e}");
        // `auto` takes the count from the scheduler: 4 tasks of 2 shards.
        let lsf = env_of(&[("LSB_JOBINDEX", "4"), ("LSB_JOBINDEX_END", "4")]);
        let a = assign(ShardSpec::Auto { count: None }, 2, &lsf).unwrap();
        assert_eq!((a.count, a.tasks, &a.shards), (8, 4, &vec![3, 7]));
        assert_eq!(
            a.describe(),
            "LSF array task 3 of 4 (LSB_JOBINDEX=4): shards 3, 7 of 8"
        );
    }

    #[test]
    fn shard_numbers_past_the_plans_bounds_are_refused_not_allocated() {
        let slurm0 = env_of(&[("SLURM_ARRAY_TASK_ID", "0")]);
        // u64::MAX shards of u64::MAX per task: one task of every shard (a capacity overflow).
        let e = assign(
            ShardSpec::Auto {
                count: Some(u64::MAX),
            },
            u64::MAX,
            &slurm0,
        )
        .unwrap_err();
        assert!(
            e.to_string()
                .contains("expected 1 to 1000, got 18446744073709551615"),
            "{e}"
        );
        // The largest run `sweep plan` writes: 100,000 tasks of 1,000 shards; one more refused.
        let a = assign(
            ShardSpec::Auto {
                count: Some(100_000_000),
            },
            1000,
            &slurm0,
        )
        .unwrap();
        assert_eq!((a.tasks, a.shards.len()), (100_000, 1000));
        let e = assign(
            ShardSpec::Auto {
                count: Some(100_000_001),
            },
            1000,
            &slurm0,
        )
        .unwrap_err();
        assert!(e.to_string().contains("at most 100000000 shards"), "{e}");
        let e = assign(
            ShardSpec::Given {
                index: 0,
                count: u64::MAX,
            },
            1,
            &slurm0,
        )
        .unwrap_err();
        assert!(e.to_string().contains("at most 100000000 shards"), "{e}");
        let e = assign(ShardSpec::Auto { count: Some(4) }, 0, &slurm0).unwrap_err();
        assert!(e.to_string().contains("expected 1 to 1000, got 0"), "{e}");
        // A scheduler that counts no tasks.
        let none = env_of(&[
            ("SLURM_ARRAY_TASK_ID", "0"),
            ("SLURM_ARRAY_TASK_COUNT", "0"),
        ]);
        let e = assign(ShardSpec::Auto { count: None }, 1, &none).unwrap_err();
        assert!(
            e.to_string()
                .contains("SLURM_ARRAY_TASK_COUNT=0: expected 1 or more"),
            "{e}"
        );
    }

    #[test]
    fn a_plan_refuses_a_specfx_command_a_script_cannot_run() {
        let cost = PointCost {
            seconds: 1.0,
            peak_mib: 0,
            measured: false,
        };
        let plan =
            |specfx: &str| Plan::new(Emit::K8s, &"0".repeat(64), 10, (2, 1), cost, 1, specfx);
        for bad in ["", "  ", "-x/specfx", "spec\nfx"] {
            let e = plan(bad).unwrap_err().to_string();
            assert!(
                e.starts_with("--specfx: expected the command that runs specfx"),
                "{e}"
            );
        }
        assert!(plan("-x").unwrap_err().to_string().contains("write ./-x"));
        assert!(plan("/opt/specfx@2/bin/specfx").is_ok());
    }

    #[test]
    fn a_placeholder_cancelled_by_dot_dot_is_refused() {
        assert!(shard_path("o/{shard}/../x", 1, 4, true)
            .unwrap_err()
            .to_string()
            .contains("a '..' after {shard} cancels it"));
        assert!(shard_path("o/x-{shard}/a/../..", 1, 4, false).is_err());
        // A '..' that cancels another component, or comes first, keeps the placeholder.
        assert_eq!(
            shard_path("../o/a/../s{shard}", 1, 4, true).unwrap(),
            "../o/a/../s1"
        );
        assert_eq!(
            shard_path("o/{shard}/x/..", 1, 4, true).unwrap(),
            "o/1/x/.."
        );
    }
}

/// The schedulers `sweep plan` writes job scripts for.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Emit {
    /// A Slurm job array (`sbatch --array`) and a merge job after it (`afterok`).
    Slurm,
    /// An LSF job array (`bsub -J "name[1-T]"`) and a merge job after it (`done(...)`).
    Lsf,
    /// An SGE array job (`qsub -t 1-T`) and a merge job after it (`-hold_jid`).
    Sge,
    /// A Kubernetes Indexed Job and a merge Job applied once it completes.
    K8s,
    /// A plain shell loop: the tasks through `xargs -P`, then the merge.
    Shell,
}

impl Emit {
    /// Every scheduler, in the order of the documentation.
    pub const ALL: [Emit; 5] = [Emit::Slurm, Emit::Lsf, Emit::Sge, Emit::K8s, Emit::Shell];

    /// Its name on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Emit::Slurm => "slurm",
            Emit::Lsf => "lsf",
            Emit::Sge => "sge",
            Emit::K8s => "k8s",
            Emit::Shell => "shell",
        }
    }
}

impl std::str::FromStr for Emit {
    type Err = Error;
    fn from_str(s: &str) -> Result<Emit, Error> {
        Emit::ALL
            .into_iter()
            .find(|e| e.name() == s)
            .ok_or_else(|| Error::UnknownName {
                what: "scheduler",
                expected: "slurm, lsf, sge, k8s or shell",
                got: s.to_string(),
            })
    }
}

/// What one array task needs: derived from the space's size and the measured cost of a point.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Resources {
    /// Threads (CPUs) per task.
    pub threads: u32,
    /// Memory per task, MiB.
    pub memory_mib: u64,
    /// Wall-clock limit per task, seconds.
    pub time_s: u64,
}

/// The measured cost of one point: the slowest of the points timed, and the peak memory.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct PointCost {
    /// Seconds per point (on the measuring machine, with its threads).
    pub seconds: f64,
    /// Peak resident memory of the process that evaluated it, MiB.
    pub peak_mib: u64,
    /// Whether the figures were measured here (else given: `--seconds-per-point`).
    pub measured: bool,
}

/// The resources a task of `points_per_task` points needs at `cost` per point: twice the
/// measured time (another machine, a busier node) plus five minutes for the start and the
/// results, rounded up to whole minutes; twice the measured peak memory, at least 512 MiB,
/// rounded up to 256 MiB.
///
/// # Examples
/// ```
/// use specfx::analysis::cluster::{resources, PointCost};
/// let r = resources(PointCost { seconds: 0.5, peak_mib: 100, measured: true }, 54, 2);
/// assert_eq!((r.time_s, r.memory_mib, r.threads), (360, 512, 2));
/// ```
pub fn resources(cost: PointCost, points_per_task: u64, threads: u32) -> Resources {
    let seconds = 2.0 * cost.seconds * points_per_task as f64 + 300.0;
    let time_s = (seconds / 60.0).ceil() as u64 * 60;
    let memory_mib = (2 * cost.peak_mib).max(512).div_ceil(256) * 256;
    Resources {
        threads,
        memory_mib,
        time_s,
    }
}

/// The cost of a point of `space`: the slowest of its first, middle and last points, and the
/// peak memory of this process after them (evaluated as a sweep's task evaluates its points,
/// through one [`Evaluator`](crate::analysis::sweep::Evaluator), whose shared values the peak
/// includes; the first point, which finds nothing shared yet, is the slowest).
pub fn measure_point_cost(space: &crate::analysis::sweep::Space) -> PointCost {
    let n = space.n_points();
    let mut picks = vec![0, n / 2, n - 1];
    picks.dedup();
    let evaluator = crate::analysis::sweep::Evaluator::new(space);
    let seconds = picks
        .iter()
        .map(|&i| {
            let start = std::time::Instant::now();
            let _ = evaluator.evaluate(i);
            start.elapsed().as_secs_f64()
        })
        .fold(0.0, f64::max);
    PointCost {
        seconds,
        peak_mib: peak_rss_mib(),
        measured: true,
    }
}

/// This process's peak resident memory, MiB (0 where the system does not say).
fn peak_rss_mib() -> u64 {
    // SAFETY: getrusage writes the struct it is given and nothing else.
    let mut usage: libc::rusage = unsafe { std::mem::zeroed() };
    if unsafe { libc::getrusage(libc::RUSAGE_SELF, &mut usage) } != 0 {
        return 0;
    }
    // Linux reports kilobytes.
    (usage.ru_maxrss.max(0) as u64).div_ceil(1024)
}

/// The number of shards of `tasks` tasks of `shards_per_task` shards over `n_points` points;
/// refused when either is 0 or there would be more shards than points.
pub fn split(n_points: u64, tasks: u64, shards_per_task: u64) -> Result<u64, Error> {
    if tasks == 0 || shards_per_task == 0 {
        return Err(Error::Cluster {
            option: if tasks == 0 {
                "--tasks"
            } else {
                "--shards-per-task"
            }
            .into(),
            problem: "expected 1 or more, got 0".into(),
        });
    }
    let shards = tasks
        .checked_mul(shards_per_task)
        .ok_or_else(|| Error::Cluster {
            option: "--tasks".into(),
            problem: format!("{tasks} tasks of {shards_per_task} shards: too many shards"),
        })?;
    if shards > n_points {
        return Err(Error::Cluster {
            option: "--tasks".into(),
            problem: format!(
                "{tasks} tasks of {shards_per_task} shards make {shards} shards, more than the space's {n_points} points: expected at most {n_points} shards"
            ),
        });
    }
    Ok(shards)
}

/// What every job of a plan asks its scheduler beyond the resources: the partition (Slurm) or
/// queue (LSF, SGE), the account (Slurm) or project (LSF, SGE), the quality of service
/// (Slurm), and directives of the user's own, one line each after the scheduler's prefix
/// (`#SBATCH`, `#BSUB`, `#$`).
#[derive(Debug, Clone, Default, PartialEq, Eq, serde::Serialize)]
pub struct SchedulerOptions {
    /// `--partition`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub partition: Option<String>,
    /// `--account`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub account: Option<String>,
    /// `--qos`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub qos: Option<String>,
    /// `--directive`, in the order given.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub directives: Vec<String>,
}

impl SchedulerOptions {
    /// Whether nothing is asked.
    pub fn is_empty(&self) -> bool {
        *self == SchedulerOptions::default()
    }

    /// Refuses what `emit`'s scripts have no place for (a quality of service outside Slurm;
    /// any option for Kubernetes, whose Job the user edits, and for a shell), a name that is
    /// empty or holds a space or a control character, and a directive that is empty, holds a
    /// control character (a line break would end it) or starts with `#` (the prefix is
    /// written).
    pub fn check(&self, emit: Emit) -> Result<(), Error> {
        let refuse = |option: &str, problem: String| {
            Err(Error::Cluster {
                option: option.into(),
                problem,
            })
        };
        let names = [
            ("--partition", &self.partition),
            ("--account", &self.account),
            ("--qos", &self.qos),
        ];
        for (option, value) in names {
            let Some(v) = value else { continue };
            if v.is_empty() || v.chars().any(|c| c.is_whitespace() || c.is_control()) {
                return refuse(
                    option,
                    format!(
                        "expected a name without spaces or control characters, got '{}'",
                        crate::error::OneLine(v)
                    ),
                );
            }
        }
        for d in &self.directives {
            if d.trim().is_empty() || d.chars().any(char::is_control) || d.starts_with('#') {
                return refuse(
                    "--directive",
                    format!(
                        "expected the text after the scheduler's prefix (e.g. --gres=gpu:1 for Slurm), one line, got '{}'",
                        crate::error::OneLine(d)
                    ),
                );
            }
        }
        let unsupported = match emit {
            Emit::Slurm => None,
            Emit::Lsf | Emit::Sge => self.qos.is_some().then_some("--qos"),
            Emit::K8s | Emit::Shell => names
                .iter()
                .find(|(_, v)| v.is_some())
                .map(|(o, _)| *o)
                .or((!self.directives.is_empty()).then_some("--directive")),
        };
        match unsupported {
            Some(option) => refuse(
                option,
                format!(
                    "the {} scripts have no place for it{}",
                    emit.name(),
                    match emit {
                        Emit::K8s => " (edit the Job's JSON)",
                        Emit::Shell => " (the shell plan runs here, without a scheduler)",
                        _ => " (a quality of service is Slurm's; give --directive)",
                    }
                ),
            ),
            None => Ok(()),
        }
    }
}

/// A sweep split for a cluster: what `sweep plan` writes scripts for.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Plan {
    /// The scheduler.
    pub emit: Emit,
    /// The sweep's identity ([`crate::analysis::sweep::sweep_sha256`]).
    pub sweep_sha256: String,
    /// Points of the space.
    pub n_points: u64,
    /// Shards of the sweep (`N`).
    pub shards: u64,
    /// Array tasks (`T`).
    pub tasks: u64,
    /// Shards per task (`S`, with `T = ceil(N / S)`).
    pub shards_per_task: u64,
    /// The most points one task evaluates.
    pub points_per_task: u64,
    /// The measured cost of a point the resources were derived from.
    pub point_cost: PointCost,
    /// What each task requests.
    pub resources: Resources,
    /// The command that runs specfx in the scripts.
    pub specfx: String,
    /// What every job asks its scheduler beyond the resources ([`Plan::with_scheduler`]).
    #[serde(skip_serializing_if = "SchedulerOptions::is_empty")]
    pub scheduler: SchedulerOptions,
}

impl Plan {
    /// The plan of a sweep of `n_points` points (identity `sweep_sha256`) over `tasks` array
    /// tasks of `shards_per_task` shards each, for `emit`; refused when there would be more
    /// shards than points.
    pub fn new(
        emit: Emit,
        sweep_sha256: &str,
        n_points: u64,
        (tasks, shards_per_task): (u64, u64),
        point_cost: PointCost,
        threads: u32,
        specfx: &str,
    ) -> Result<Plan, Error> {
        if specfx.trim().is_empty()
            || specfx.starts_with('-')
            || specfx.chars().any(char::is_control)
        {
            let why = if specfx.starts_with('-') {
                " (a command starting with '-' reads as an option: write ./".to_string()
                    + &crate::error::OneLine(specfx).to_string()
                    + ")"
            } else {
                String::new()
            };
            return Err(Error::Cluster {
                option: "--specfx".into(),
                problem: format!(
                    "expected the command that runs specfx on the nodes (a path, or a name on their PATH, without control characters), got '{}'{why}",
                    crate::error::OneLine(specfx)
                ),
            });
        }
        let shards = split(n_points, tasks, shards_per_task)?;
        let points_per_task = n_points.div_ceil(shards) * shards_per_task;
        Ok(Plan {
            emit,
            sweep_sha256: sweep_sha256.to_string(),
            n_points,
            shards,
            tasks,
            shards_per_task,
            points_per_task,
            point_cost,
            resources: resources(point_cost, points_per_task, threads),
            specfx: specfx.to_string(),
            scheduler: SchedulerOptions::default(),
        })
    }

    /// The plan with `options` on every job, checked for its scheduler
    /// ([`SchedulerOptions::check`]).
    pub fn with_scheduler(mut self, options: SchedulerOptions) -> Result<Plan, Error> {
        options.check(self.emit)?;
        self.scheduler = options;
        Ok(self)
    }

    /// The job's name: `specfx-sweep-` and the first 12 hex digits of the sweep's identity.
    pub fn job_name(&self) -> String {
        format!("specfx-sweep-{}", &self.sweep_sha256[..12])
    }
}
