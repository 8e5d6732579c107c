//! Slurm's own commands (`sbatch`, `squeue`, `scontrol`, `sacct`, `sinfo`, `scancel`), run
//! as child processes, and the parsers of their output.
//!
//! Hand-written on purpose: the one Rust crate for Slurm (`slurry` 0.1) drives the commands
//! over SSH and parses only `squeue`; the commands themselves are Slurm's stable interface
//! (`--parsable`, `-h -o`/`-O` formats, `scontrol -o`), and the few fields read here are
//! parsed by the pure functions below, each tested on the commands' real output.

use std::path::Path;
use std::process::Command;

/// A Slurm command's failure: the command line and what it printed.
pub type CommandError = String;

/// Runs `program args…`, returning its standard output; an error (start failure or
/// non-zero exit) names the command and quotes its standard error.
pub fn run(program: &str, args: &[&str]) -> Result<String, CommandError> {
    let line = format!("{program} {}", args.join(" "));
    let out =
        Command::new(program).args(args).output().map_err(|e| format!("`{line}` could not start: {e}"))?;
    if !out.status.success() {
        let stderr = String::from_utf8_lossy(&out.stderr);
        return Err(format!("`{line}` failed ({}): {}", out.status, stderr.trim()));
    }
    Ok(String::from_utf8_lossy(&out.stdout).into_owned())
}

/// Whether `program` is an executable file in a directory of `PATH`.
pub fn on_path(program: &str) -> bool {
    std::env::var_os("PATH").is_some_and(|path| {
        std::env::split_paths(&path).any(|dir| {
            let file = dir.join(program);
            file.is_file() && is_executable(&file)
        })
    })
}

#[cfg(unix)]
fn is_executable(file: &Path) -> bool {
    use std::os::unix::fs::PermissionsExt;
    file.metadata().is_ok_and(|m| m.permissions().mode() & 0o111 != 0)
}

#[cfg(not(unix))]
fn is_executable(file: &Path) -> bool {
    file.is_file()
}

/// The partitions `sinfo -h -o %P` lists, the default one (marked `*`) first.
pub fn parse_partitions(sinfo: &str) -> Vec<String> {
    let mut names: Vec<(bool, String)> = sinfo
        .lines()
        .map(str::trim)
        .filter(|l| !l.is_empty())
        .map(|l| (l.ends_with('*'), l.trim_end_matches('*').to_string()))
        .collect();
    names.sort_by_key(|(default, _)| !*default);
    names.dedup_by(|a, b| a.1 == b.1);
    names.into_iter().map(|(_, n)| n).collect()
}

/// The job id that `sbatch --parsable` printed (`<id>` or `<id>;<cluster>`).
pub fn parse_job_id(sbatch: &str) -> Option<u64> {
    sbatch.trim().split(';').next()?.trim().parse().ok()
}

/// A task's state as Slurm names it (`PENDING`, `RUNNING`, `COMPLETED`, `FAILED`,
/// `CANCELLED`, `TIMEOUT`, …).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct TaskState {
    /// The array task index.
    pub task: usize,
    /// Slurm's state name (`CANCELLED by 0` read as `CANCELLED`).
    pub state: String,
    /// `<exit code>:<signal>`, when the source gives it (`scontrol`, `sacct`).
    pub exit_code: Option<String>,
    /// Why a pending task waits (`Priority`, `Resources`, `PartitionTimeLimit`, …), when
    /// the source gives it (`squeue`).
    pub reason: Option<String>,
}

impl TaskState {
    /// Whether the task has ended: one of Slurm's terminal states (any other, such as
    /// `STOPPED`, `REQUEUE_HOLD` or `STAGE_OUT`, is still followed).
    pub fn ended(&self) -> bool {
        matches!(
            self.state.as_str(),
            "COMPLETED"
                | "FAILED"
                | "CANCELLED"
                | "TIMEOUT"
                | "NODE_FAIL"
                | "OUT_OF_MEMORY"
                | "BOOT_FAIL"
                | "DEADLINE"
                | "PREEMPTED"
                | "REVOKED"
        )
    }
}

/// Whether a pending task's `reason` is one that Slurm does not clear by itself: the request
/// exceeds a limit of the partition, the QOS or the association *per job* (or is below the
/// QOS's minimum), or names an
/// account, QOS or constraint that is not allowed (Slurm's job reason codes). Such a task
/// would wait until an administrator changes the limits; waits on other jobs (`Priority`,
/// `Resources`, `QOSGrp*`, `AssocGrp*`, `Max*PerUser`, …) or on nodes coming back are not
/// among them.
pub fn never_starts(reason: &str) -> bool {
    let per_job_limit =
        (reason.starts_with("QOSMax") || reason.starts_with("AssocMax")) && reason.contains("PerJob");
    // The request is below the QOS's per-job minimum (`QOSMinCpuNotSatisfied`, …).
    let below_minimum = reason.starts_with("QOSMin");
    per_job_limit
        || below_minimum
        || matches!(
            reason,
            "PartitionTimeLimit"
                | "AccountNotAllowed"
                | "QOSNotAllowed"
                | "InvalidAccount"
                | "InvalidQOS"
                | "BadConstraints"
                | "DependencyNeverSatisfied"
        )
}

/// The tasks of `squeue -h -r --states=all -j <job> -o "%K %T %r"` (array task index,
/// state, reason); lines without a single task index (a pending range such as `3-9%2` is
/// expanded by `-r`) are skipped.
pub fn parse_squeue(squeue: &str) -> Vec<TaskState> {
    squeue
        .lines()
        .filter_map(|l| {
            let mut f = l.split_whitespace();
            let task = f.next()?.parse().ok()?;
            let state = f.next()?.to_string();
            let reason = f.collect::<Vec<_>>().join(" ");
            Some(TaskState { task, state, exit_code: None, reason: (!reason.is_empty()).then_some(reason) })
        })
        .collect()
}

/// The tasks of `squeue -h -r --states=all -j <job>,<job>… -o "%F %K %T %o"`: array job
/// id, task (index and state) and the batch script it runs (the rest of the line: a path
/// may hold spaces).
pub fn parse_squeue_jobs(squeue: &str) -> Vec<(u64, TaskState, String)> {
    squeue
        .lines()
        .filter_map(|l| {
            let mut f = l.splitn(4, ' ');
            let job = f.next()?.parse().ok()?;
            let task = f.next()?.parse().ok()?;
            let state = f.next()?.to_string();
            let script = f.next()?.trim().to_string();
            Some((job, TaskState { task, state, exit_code: None, reason: None }, script))
        })
        .collect()
}

/// A Slurm time (`sbatch --time`, a partition's `MaxTime`) in seconds, `Some(None)` when
/// unlimited (`UNLIMITED`, `INFINITE` in any case, or `-1`); `None` when `time` is none of
/// Slurm's formats: `minutes`, `minutes:seconds`, `hours:minutes:seconds`, `days-hours`,
/// `days-hours:minutes`, `days-hours:minutes:seconds`. Zero is zero here: `sbatch --time=0`
/// asks for no limit, a partition's `MaxTime` of 0 allows none.
pub fn parse_time(time: &str) -> Option<Option<u64>> {
    let time = time.trim();
    if time.eq_ignore_ascii_case("unlimited") || time.eq_ignore_ascii_case("infinite") || time == "-1" {
        return Some(None);
    }
    let number = |s: &str| -> Option<u64> {
        (!s.is_empty() && s.bytes().all(|b| b.is_ascii_digit())).then(|| s.parse().ok()).flatten()
    };
    let seconds = match time.split_once('-') {
        Some((days, rest)) => {
            let f: Vec<&str> = rest.split(':').collect();
            let (h, m, s) = match f[..] {
                [h] => (number(h)?, 0, 0),
                [h, m] => (number(h)?, number(m)?, 0),
                [h, m, s] => (number(h)?, number(m)?, number(s)?),
                _ => return None,
            };
            ((number(days)? * 24 + h) * 60 + m) * 60 + s
        }
        None => {
            let f: Vec<&str> = time.split(':').collect();
            match f[..] {
                [m] => number(m)? * 60,
                [m, s] => number(m)? * 60 + number(s)?,
                [h, m, s] => (number(h)? * 60 + number(m)?) * 60 + number(s)?,
                _ => return None,
            }
        }
    };
    Some(Some(seconds))
}

/// The value of `key` in `scontrol show config` (`Key = value` lines).
pub fn config_value<'a>(config: &'a str, key: &str) -> Option<&'a str> {
    config.lines().find_map(|l| {
        let (k, v) = l.split_once('=')?;
        (k.trim() == key).then(|| v.trim())
    })
}

/// The value of `key` in a line of `scontrol -o` (`Key=value` pairs split by spaces).
pub fn field<'a>(line: &'a str, key: &str) -> Option<&'a str> {
    line.split_whitespace().find_map(|kv| kv.strip_prefix(key).and_then(|v| v.strip_prefix('=')))
}

/// The tasks of `scontrol -o show job <job>` (one line per array task: `ArrayTaskId=`,
/// `JobState=`, `ExitCode=`).
pub fn parse_scontrol(scontrol: &str) -> Vec<TaskState> {
    scontrol
        .lines()
        .filter_map(|l| {
            let field = |key: &str| field(l, key);
            Some(TaskState {
                task: field("ArrayTaskId")?.parse().ok()?,
                state: field("JobState")?.to_string(),
                exit_code: field("ExitCode").map(str::to_string),
                reason: None,
            })
        })
        .collect()
}

/// The tasks of `sacct -n -P -X -j <job> -o JobID,State,ExitCode` (`<job>_<task>|STATE|0:0`).
pub fn parse_sacct(sacct: &str) -> Vec<TaskState> {
    sacct
        .lines()
        .filter_map(|l| {
            let mut f = l.split('|');
            let id = f.next()?;
            let task = id.split_once('_')?.1.parse().ok()?;
            let state = f.next()?.split_whitespace().next()?.to_string();
            Some(TaskState { task, state, exit_code: f.next().map(str::to_string), reason: None })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Outputs copied from Slurm 22.05 (Debian 12) on a one-node cluster.
    #[test]
    fn parses_the_commands_output() {
        assert_eq!(parse_partitions("debug*\nlong\n"), ["debug", "long"]);
        assert_eq!(parse_partitions("long\ndebug*\nlong\n"), ["debug", "long"]);
        assert_eq!(parse_job_id("12\n"), Some(12));
        assert_eq!(parse_job_id("12;meniscus\n"), Some(12));
        assert_eq!(parse_job_id("sbatch: error"), None);
        let partition = "PartitionName=remote AllowGroups=ALL Nodes=ghost[1-2] TotalCPUs=2 TotalNodes=2";
        assert_eq!(field(partition, "Nodes"), Some("ghost[1-2]"));
        assert_eq!(field(partition, "TotalNodes"), Some("2"));
        assert_eq!(field(partition, "Missing"), None);
        let q = parse_squeue(
            "2 PENDING Resources\n1 RUNNING None\n3 COMPLETED None\nN/A PENDING Priority\n\
             4 PENDING ReqNodeNotAvail, UnavailableNodes:ghost\n5 PENDING\n",
        );
        assert_eq!(q.len(), 5);
        assert_eq!((q[0].task, q[0].state.as_str(), q[0].ended()), (2, "PENDING", false));
        assert_eq!(q[0].reason.as_deref(), Some("Resources"));
        assert!(q[2].ended());
        assert_eq!(q[3].reason.as_deref(), Some("ReqNodeNotAvail, UnavailableNodes:ghost"));
        assert_eq!(q[4].reason, None);
        let jobs = parse_squeue_jobs(
            "7 0 RUNNING /s/arrays/a/run.sh\n9 3 PENDING /s p/arrays/b/run.sh\nN/A 1 PENDING x\n",
        );
        assert_eq!(jobs.len(), 2);
        assert_eq!((jobs[1].0, jobs[1].1.task, jobs[1].1.state.as_str()), (9, 3, "PENDING"));
        assert_eq!(jobs[1].2, "/s p/arrays/b/run.sh");
        let config = "Configuration data as of 2026-12-07T23:01:02\nMaxArraySize            = 8\n\
                      MaxJobCount             = 10000\n";
        assert_eq!(config_value(config, "MaxArraySize"), Some("8"));
        assert_eq!(config_value(config, "MaxArray"), None);
        let s = parse_scontrol(
            "JobId=4 ArrayJobId=1 ArrayTaskId=2 ArrayTaskThrottle=2 JobName=t.sh UserId=root(0) \
             JobState=FAILED Reason=NonZeroExitCode Dependency=(null) ExitCode=7:0\n\
             JobId=3 ArrayJobId=1 ArrayTaskId=1 JobState=CANCELLED Reason=None ExitCode=0:15\n",
        );
        assert_eq!(s.len(), 2);
        assert_eq!((s[0].task, s[0].state.as_str(), s[0].exit_code.as_deref()), (2, "FAILED", Some("7:0")));
        assert_eq!((s[1].state.as_str(), s[1].exit_code.as_deref()), ("CANCELLED", Some("0:15")));
        let a = parse_sacct("7_0|COMPLETED|0:0\n7_1|CANCELLED by 0|0:15\n7_[2-3]|PENDING|0:0\n");
        assert_eq!(a.len(), 2);
        assert_eq!(
            (a[1].task, a[1].state.as_str(), a[1].exit_code.as_deref()),
            (1, "CANCELLED", Some("0:15"))
        );
    }

    #[test]
    fn slurm_times_in_seconds() {
        for (time, seconds) in [
            ("10", Some(600)),
            ("10:30", Some(630)),
            ("1:02:03", Some(3723)),
            ("2-3", Some((2 * 24 + 3) * 3600)),
            ("2-03:04", Some(((2 * 24 + 3) * 60 + 4) * 60)),
            ("1-00:00:01", Some(86_401)),
            ("00:01:00", Some(60)),
        ] {
            assert_eq!(parse_time(time), Some(seconds), "{time}");
        }
        for unlimited in ["UNLIMITED", "INFINITE", "Unlimited", "-1"] {
            assert_eq!(parse_time(unlimited), Some(None), "{unlimited}");
        }
        assert_eq!(parse_time("0"), Some(Some(0)));
        assert_eq!(parse_time("00:00:00"), Some(Some(0)));
        for bad in ["", "abc", "1h", "-5", "1:2:3:4", "1-2:3:4:5", "1--2", "1.5"] {
            assert_eq!(parse_time(bad), None, "{bad:?}");
        }
    }

    #[test]
    fn reasons_that_never_clear() {
        for reason in [
            "PartitionTimeLimit",
            "QOSMaxWallDurationPerJobLimit",
            "AssocMaxCpuPerJobLimit",
            "QOSMinCpuNotSatisfied",
            "InvalidAccount",
            "BadConstraints",
        ] {
            assert!(never_starts(reason), "{reason}");
        }
        for reason in [
            "Priority",
            "Resources",
            "None",
            "QOSGrpCpuLimit",
            "AssocGrpNodeLimit",
            "QOSMaxJobsPerUserLimit",
            "PartitionNodeLimit",
            "ReqNodeNotAvail, UnavailableNodes:ghost",
        ] {
            assert!(!never_starts(reason), "{reason}");
        }
    }
}
