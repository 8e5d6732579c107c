//! The Slurm executor: the runner's pending runs handed to a cluster as job arrays
//! (`cargo xtask validate --executor slurm`, issue #40).
//!
//! [`Cluster::connect`] checks, before anything is submitted, that Slurm's commands are on
//! `PATH`, that the partition exists, that the `meniscus` binary is of this solver build
//! (its `--version` carries [`meniscus::SOLVER_FINGERPRINT`]), that the spool directory
//! is one the partition's nodes can read, and that `--time-limit` is a Slurm time within the
//! partition's `MaxTime` (beyond it, Slurm would leave the tasks pending for ever).
//! [`Cluster::run`] then writes each run's scene to the [`spool`], submits one
//! `sbatch --array` per thread count (task k runs one scene through `meniscus run`; more
//! runs than the cluster's `MaxArraySize` take several arrays), follows the tasks with
//! `squeue` (and `scontrol` / `sacct` for an ended task's exit code), and collects each
//! finished run's outputs into the record the local executor would have written. A task
//! that fails, times out or is cancelled, or waits for a reason Slurm does not clear by
//! itself ([`commands::never_starts`]: it is cancelled), is reported with its Slurm state
//! and not collected; the next invocation submits it again, and only it. A run whose task
//! from an earlier invocation (its submitter killed) still pends or runs is followed, not
//! submitted again. Ctrl-C cancels the submitted arrays (`scancel`).

pub mod commands;
pub mod spool;

use crate::cache::RunRecord;
use crate::error::{HarnessError, Result};
use crate::sweep::RunSpec;
use commands::{TaskState, run};
use spool::Spool;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

/// Options of the Slurm executor (the `--executor slurm` flags).
#[derive(Debug, Clone)]
pub struct SlurmOptions {
    /// `sbatch --partition` (the cluster's default partition when `None`).
    pub partition: Option<String>,
    /// `sbatch --account`.
    pub account: Option<String>,
    /// `sbatch --time`, each task's time limit (`minutes`, `hh:mm:ss`, `days-hh`, …).
    pub time_limit: Option<String>,
    /// `sbatch --cpus-per-task`: the threads of each run (a job's own thread count, as the
    /// work-precision study's, takes precedence).
    pub cpus_per_task: usize,
    /// The most tasks of an array running at once (`--array=0-N%max`; per array, when the
    /// runs take several).
    pub max_tasks: Option<usize>,
    /// The spool directory, on a file system shared with the compute nodes.
    pub spool: PathBuf,
    /// The `meniscus` binary the tasks run (it must be reachable from the nodes).
    pub meniscus: PathBuf,
    /// How often the tasks' states are read.
    pub poll: Duration,
}

/// How long a task that Slurm reports completed may take to show its outputs (a shared
/// file system's attribute cache: NFS keeps a directory's for up to 60 s by default) before
/// it counts as failed.
const GRACE: Duration = Duration::from_secs(90);

/// File-system types that a cluster's nodes share (`/proc/self/mountinfo`'s type field).
const SHARED_FILE_SYSTEMS: &[&str] = &[
    "nfs",
    "nfs4",
    "lustre",
    "gpfs",
    "beegfs",
    "ceph",
    "fuse.ceph",
    "cephfs",
    "glusterfs",
    "fuse.glusterfs",
    "cifs",
    "smb3",
    "panfs",
    "wekafs",
    "pvfs2",
    "orangefs",
];

/// A checked connection to a Slurm cluster (see the module documentation).
#[derive(Debug)]
pub struct Cluster {
    opts: SlurmOptions,
    partition: String,
    spool: Spool,
    /// The most tasks of one array (the cluster's `MaxArraySize`: indices 0 to it − 1).
    max_array: usize,
}

/// How a run submitted to Slurm ended.
#[derive(Debug)]
pub enum Outcome {
    /// Its task finished (completed or diverged): the record, as the local executor writes it.
    Finished(Box<RunRecord>),
    /// Its task failed, timed out or was cancelled, or its outputs could not be read: why.
    Failed(String),
}

/// The tasks of the submitted arrays, by state (the progress display's).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Counts {
    /// Waiting for resources.
    pub pending: usize,
    /// Running.
    pub running: usize,
    /// Finished and collected.
    pub done: usize,
    /// Failed, timed out or cancelled.
    pub failed: usize,
}

impl Counts {
    /// `3 pending, 2 running, 5 done, 1 failed`.
    pub fn describe(&self) -> String {
        format!(
            "{} pending, {} running, {} done, {} failed",
            self.pending, self.running, self.done, self.failed
        )
    }
}

/// Set by Ctrl-C (or SIGTERM, SIGHUP) while arrays are being followed.
static INTERRUPTED: AtomicBool = AtomicBool::new(false);

/// Whether arrays are being followed: a signal at any other time ends the process.
static FOLLOWING: AtomicBool = AtomicBool::new(false);

fn slurm_error(message: impl Into<String>) -> HarnessError {
    HarnessError::Slurm { message: message.into() }
}

impl Cluster {
    /// Checks the cluster and the options (see the module documentation); nothing is
    /// submitted.
    pub fn connect(opts: SlurmOptions) -> Result<Cluster> {
        for program in ["sbatch", "squeue", "scontrol", "scancel", "sinfo"] {
            if !commands::on_path(program) {
                return Err(slurm_error(format!(
                    "--executor slurm: `{program}` is not on PATH: run on a node with Slurm's commands \
                     (a login node) or add their directory to PATH"
                )));
            }
        }
        if opts.cpus_per_task == 0 {
            return Err(slurm_error("--cpus-per-task: 0: must be at least 1"));
        }
        if opts.max_tasks == Some(0) {
            return Err(slurm_error("--max-tasks: 0: must be at least 1"));
        }
        let partitions = commands::parse_partitions(&run("sinfo", &["-h", "-o", "%P"]).map_err(slurm_error)?);
        let partition = match &opts.partition {
            Some(p) if partitions.contains(p) => p.clone(),
            Some(p) => {
                return Err(slurm_error(format!(
                    "--partition: `{p}` is not a partition of this cluster (sinfo lists: {})",
                    partitions.join(", ")
                )));
            }
            None => partitions.first().cloned().ok_or_else(|| slurm_error("sinfo lists no partition"))?,
        };
        let partition_line =
            run("scontrol", &["-o", "show", "partition", &partition]).map_err(slurm_error)?;
        if let Some(time) = &opts.time_limit {
            check_time_limit(time, &partition, &partition_line)?;
        }
        let config = run("scontrol", &["show", "config"]).map_err(slurm_error)?;
        // Slurm's default when the configuration does not say.
        let max_array =
            commands::config_value(&config, "MaxArraySize").and_then(|v| v.parse().ok()).unwrap_or(1001);
        check_binary(&opts.meniscus)?;
        crate::io::create_dir(&opts.spool)?;
        let spool_path = opts
            .spool
            .canonicalize()
            .map_err(|source| HarnessError::Io { path: opts.spool.clone(), source })?;
        check_shared(&spool_path, &partition, &partition_line)?;
        Ok(Cluster { spool: Spool::new(spool_path), opts, partition, max_array: usize::max(max_array, 1) })
    }

    /// Runs `runs` (`(key, spec, threads)`; `threads` `None`: `--cpus-per-task`): each
    /// finished in the spool already (unless `rerun`) is collected at once, the others are
    /// submitted; `report(key, outcome)` is called as each ends, `progress` after each look
    /// at the queue. Returns once every run ended; an interruption (Ctrl-C) cancels the
    /// arrays and is an error.
    pub fn run(
        &self,
        runs: &[(usize, &RunSpec, Option<usize>)],
        rerun: bool,
        progress: &dyn Fn(Counts),
        report: &mut dyn FnMut(usize, Outcome) -> Result<()>,
    ) -> Result<()> {
        let mut counts = Counts::default();
        // Tasks of earlier invocations still queued: followed again, or cancelled when the
        // runs are to be run again (two tasks must never share a run directory).
        let live = self.live_claims(runs)?;
        if rerun && !live.is_empty() {
            let ids: Vec<String> = live.iter().map(|(job, task)| format!("{job}_{task}")).collect();
            run("scancel", &ids.iter().map(String::as_str).collect::<Vec<_>>()).map_err(slurm_error)?;
        }
        let mut adopted: BTreeMap<u64, Array> = BTreeMap::new();
        // Arrays to submit: threads → runs.
        let mut groups: BTreeMap<usize, Vec<(usize, &RunSpec)>> = BTreeMap::new();
        for &(key, spec, threads) in runs {
            let threads = threads.unwrap_or(self.opts.cpus_per_task);
            // Finished after an earlier invocation stopped: collected, unless its outputs
            // cannot be read (then they are dropped and the run submitted again).
            let earlier = (!rerun && self.spool.finished(spec, threads))
                .then(|| self.spool.collect(spec, threads).ok())
                .flatten();
            if let Some(record) = earlier {
                report(key, Outcome::Finished(Box::new(record)))?;
                counts.done += 1;
                continue;
            }
            if let Some(claim) =
                self.spool.claimed(spec, threads).filter(|c| !rerun && live.contains(&(c.job, c.task)))
            {
                let array = adopted.entry(claim.job).or_insert_with(|| Array {
                    id: claim.job,
                    dir: claim.array.clone(),
                    threads,
                    tasks: Vec::new(),
                    adopted: true,
                });
                array.tasks.push(Task { index: claim.task, key, spec, ended: false, since: None });
                continue;
            }
            self.spool.prepare(spec, threads)?;
            groups.entry(threads).or_default().push((key, spec));
        }
        if groups.is_empty() && adopted.is_empty() {
            return Ok(());
        }
        install_interrupt_handler();
        INTERRUPTED.store(false, Ordering::SeqCst);
        // Cancels what is followed on any early return (an error, an interruption): the
        // arrays submitted here, the adopted tasks one by one (their arrays may hold runs of
        // other invocations).
        let mut submitted = Submitted::default();
        FOLLOWING.store(true, Ordering::SeqCst);
        let mut arrays: Vec<Array> = adopted.into_values().collect();
        for array in &arrays {
            submitted.0.extend(array.tasks.iter().map(|t| format!("{}_{}", array.id, t.index)));
        }
        for (threads, tasks) in groups {
            for (part, tasks) in tasks.chunks(self.max_array).enumerate() {
                arrays.push(self.submit(threads, part, tasks.to_vec(), &mut submitted)?);
            }
        }
        loop {
            if INTERRUPTED.swap(false, Ordering::SeqCst) {
                let ids = submitted.0.clone();
                let cancelled = submitted.cancel();
                return Err(slurm_error(format!(
                    "interrupted: Slurm job(s) {} {}; runs that finished are kept, run the command \
                     again to submit the others",
                    ids.join(", "),
                    match cancelled {
                        Ok(_) => "cancelled".to_string(),
                        Err(e) => format!("not cancelled: {e}"),
                    }
                )));
            }
            let (mut pending, mut running, mut seen) = (0, 0, true);
            for array in &mut arrays {
                match array.poll(self, &mut counts, report)? {
                    Some((p, r)) => (pending, running) = (pending + p, running + r),
                    None => seen = false,
                }
            }
            if seen {
                progress(Counts { pending, running, ..counts });
            }
            if arrays.iter().all(|a| a.tasks.iter().all(|t| t.ended)) {
                submitted.0.clear();
                return Ok(());
            }
            // An adopted task that ended is no longer anything to cancel.
            for array in arrays.iter().filter(|a| a.adopted) {
                for task in array.tasks.iter().filter(|t| t.ended) {
                    let id = format!("{}_{}", array.id, task.index);
                    submitted.0.retain(|s| *s != id);
                }
            }
            std::thread::sleep(self.opts.poll);
        }
    }

    /// The record of a finished run, or why it cannot be read.
    fn collect(&self, spec: &RunSpec, threads: usize) -> Outcome {
        match self.spool.collect(spec, threads) {
            Ok(record) => Outcome::Finished(Box::new(record)),
            Err(e) => Outcome::Failed(format!("its outputs could not be read: {e}")),
        }
    }

    /// Submits one array of `tasks`, each run on `threads` threads (`part`: its place among
    /// the arrays of this thread count), its id added to `submitted` as soon as it exists.
    fn submit<'a>(
        &self,
        threads: usize,
        part: usize,
        tasks: Vec<(usize, &'a RunSpec)>,
        submitted: &mut Submitted,
    ) -> Result<Array<'a>> {
        let stamp =
            std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).map_or(0, |d| d.as_millis());
        let name = format!("{stamp}-{}-t{threads}-{part}", std::process::id());
        let dirs: Vec<PathBuf> = tasks.iter().map(|(_, spec)| self.spool.run_dir(spec, threads)).collect();
        let dir = self.spool.write_array(&name, &dirs, &self.opts.meniscus, threads)?;
        let mut range = format!("0-{}", tasks.len() - 1);
        if let Some(max) = self.opts.max_tasks {
            range.push_str(&format!("%{max}"));
        }
        // `%` is sbatch's pattern character: the directory's own are doubled.
        let log = format!("{}/task_%a.log", dir.display().to_string().replace('%', "%%"));
        let mut args = vec![
            "--parsable".to_string(),
            format!("--array={range}"),
            "--job-name=meniscus".to_string(),
            format!("--partition={}", self.partition),
            format!("--cpus-per-task={threads}"),
            format!("--output={log}"),
        ];
        if let Some(account) = &self.opts.account {
            args.push(format!("--account={account}"));
        }
        if let Some(time) = &self.opts.time_limit {
            args.push(format!("--time={time}"));
        }
        args.push(dir.join("run.sh").display().to_string());
        let out = run("sbatch", &args.iter().map(String::as_str).collect::<Vec<_>>()).map_err(slurm_error)?;
        let id = commands::parse_job_id(&out)
            .ok_or_else(|| slurm_error(format!("sbatch printed no job id: `{}`", out.trim())))?;
        submitted.0.push(id.to_string());
        crate::io::write_atomic(&dir.join("job_id"), format!("{id}\n").as_bytes())?;
        for (k, run_dir) in dirs.iter().enumerate() {
            self.spool.claim(run_dir, id, k, &dir)?;
        }
        let tasks = tasks
            .into_iter()
            .enumerate()
            .map(|(index, (key, spec))| Task { index, key, spec, ended: false, since: None })
            .collect();
        Ok(Array { id, dir, threads, tasks, adopted: false })
    }

    /// The array tasks (job, task index) that took `runs` in earlier invocations and are
    /// still pending or running: one `squeue` for all their jobs (three tries, then an
    /// error: a run whose task cannot be seen must not get a second one). A task counts
    /// only if it is this user's and runs its claim's batch script (a job id that Slurm
    /// reused after losing its state is another job).
    fn live_claims(
        &self,
        runs: &[(usize, &RunSpec, Option<usize>)],
    ) -> Result<std::collections::BTreeSet<(u64, usize)>> {
        let claims: BTreeMap<(u64, usize), PathBuf> = runs
            .iter()
            .filter_map(|&(_, spec, threads)| {
                self.spool.claimed(spec, threads.unwrap_or(self.opts.cpus_per_task))
            })
            .map(|c| ((c.job, c.task), c.array.join("run.sh")))
            .collect();
        if claims.is_empty() {
            return Ok(Default::default());
        }
        let jobs: std::collections::BTreeSet<String> =
            claims.keys().map(|(job, _)| job.to_string()).collect();
        let list = jobs.into_iter().collect::<Vec<_>>().join(",");
        let args = ["-h", "-r", "--me", "--states=all", "-j", &list, "-o", "%F %K %T %o"];
        let mut out = run("squeue", &args);
        for _ in 0..2 {
            if out.is_ok() {
                break;
            }
            std::thread::sleep(Duration::from_secs(1));
            out = run("squeue", &args);
        }
        let out = out.map_err(|e| {
            slurm_error(format!(
                "{e}: the tasks of earlier invocations cannot be checked, so none is submitted"
            ))
        })?;
        Ok(commands::parse_squeue_jobs(&out)
            .into_iter()
            .filter(|(job, s, script)| {
                !s.ended() && claims.get(&(*job, s.task)).is_some_and(|c| Path::new(script) == c)
            })
            .map(|(job, s, _)| (job, s.task))
            .collect())
    }
}

/// One array and the tasks of it that are followed: all of an array submitted here, the
/// still-queued ones of an array adopted from an earlier invocation.
struct Array<'a> {
    id: u64,
    dir: PathBuf,
    threads: usize,
    tasks: Vec<Task<'a>>,
    /// Submitted by an earlier invocation: its tasks are cancelled one by one, and only
    /// while they run (see [`Submitted`]).
    adopted: bool,
}

/// The Slurm ids (`<job>` or `<job>_<task>`) followed by one [`Cluster::run`], cancelled
/// when dropped unless cleared.
#[derive(Default)]
struct Submitted(Vec<String>);

impl Submitted {
    /// `scancel` of every followed job or task; nothing is left to cancel after it.
    fn cancel(&mut self) -> std::result::Result<(), commands::CommandError> {
        if self.0.is_empty() {
            return Ok(());
        }
        let ids: Vec<String> = self.0.drain(..).collect();
        run("scancel", &ids.iter().map(String::as_str).collect::<Vec<_>>()).map(|_| ())
    }
}

impl Drop for Submitted {
    fn drop(&mut self) {
        FOLLOWING.store(false, Ordering::SeqCst);
        // An early return: the arrays would run on unfollowed (the error is the caller's).
        let _ = self.cancel();
    }
}

/// A task of an array.
struct Task<'a> {
    /// Its index in the array (`SLURM_ARRAY_TASK_ID`).
    index: usize,
    key: usize,
    spec: &'a RunSpec,
    /// Reported (finished or failed).
    ended: bool,
    /// Since when Slurm has reported it completed, or not listed it, without its outputs
    /// being visible (the grace period).
    since: Option<Instant>,
}

impl Array<'_> {
    /// Reads the array's task states and reports the tasks that ended (counted in
    /// `counts`); returns how many are pending and how many running, or `None` when the
    /// queue could not be read (a busy controller: the next poll tries again).
    fn poll(
        &mut self,
        cluster: &Cluster,
        counts: &mut Counts,
        report: &mut dyn FnMut(usize, Outcome) -> Result<()>,
    ) -> Result<Option<(usize, usize)>> {
        let (mut pending, mut running) = (0, 0);
        let id = self.id.to_string();
        let Ok(out) = run("squeue", &["-h", "-r", "--states=all", "-j", &id, "-o", "%K %T %r"]) else {
            return Ok(None);
        };
        let queue = commands::parse_squeue(&out);
        let threads = self.threads;
        let state: BTreeMap<usize, TaskState> = queue.into_iter().map(|s| (s.task, s)).collect();
        for i in 0..self.tasks.len() {
            let task = &mut self.tasks[i];
            let k = task.index;
            if task.ended {
                continue;
            }
            let outcome = if cluster.spool.finished(task.spec, threads) {
                Some(cluster.collect(task.spec, threads))
            } else {
                match state.get(&k) {
                    // Waiting for a limit to change: it would never start.
                    Some(s)
                        if s.state == "PENDING"
                            && s.reason.as_deref().is_some_and(commands::never_starts) =>
                    {
                        let reason = s.reason.as_deref().unwrap_or_default();
                        let cancelled = run("scancel", &[&format!("{}_{k}", self.id)])
                            .map_or_else(|e| format!("not cancelled: {e}"), |_| "cancelled".to_string());
                        Some(Outcome::Failed(format!(
                            "Slurm task {}_{k}: pending for a reason Slurm does not clear by itself \
                             ({reason}); {cancelled}",
                            self.id
                        )))
                    }
                    Some(s) if !s.ended() => {
                        task.since = None;
                        if s.state == "PENDING" {
                            pending += 1;
                        } else {
                            running += 1;
                        }
                        None
                    }
                    // Failed, cancelled, timed out: the script moves the outputs into place
                    // only when the run ended, so there are none to wait for.
                    Some(s) if s.state != "COMPLETED" => Some(Outcome::Failed(self.failure(k, Some(s)))),
                    // Completed without outputs yet, or gone from the queue: give the shared
                    // file system its grace, then report it.
                    _ => {
                        let since = *task.since.get_or_insert_with(Instant::now);
                        if since.elapsed() < GRACE {
                            running += 1;
                            None
                        } else if state.contains_key(&k) {
                            let out = cluster.spool.run_dir(task.spec, threads).join("out");
                            Some(Outcome::Failed(format!(
                                "Slurm task {}_{k} completed, but `{}` holds no summary.json after \
                                 {} s (log: {})",
                                self.id,
                                out.display(),
                                GRACE.as_secs(),
                                self.dir.join(format!("task_{k}.log")).display()
                            )))
                        } else {
                            Some(Outcome::Failed(self.failure(k, None)))
                        }
                    }
                }
            };
            if let Some(outcome) = outcome {
                let task = &mut self.tasks[i];
                task.ended = true;
                match &outcome {
                    Outcome::Finished(_) => counts.done += 1,
                    Outcome::Failed(_) => counts.failed += 1,
                }
                report(task.key, outcome)?;
            }
        }
        Ok(Some((pending, running)))
    }

    /// Why task `k` ended without outputs: its Slurm state and exit code (from `scontrol`,
    /// else `sacct`, else the queue's last word) and its log.
    fn failure(&self, k: usize, queued: Option<&TaskState>) -> String {
        let id = self.id.to_string();
        let detail = run("scontrol", &["-o", "show", "job", &id])
            .map(|out| commands::parse_scontrol(&out))
            .ok()
            .and_then(|v| v.into_iter().find(|s| s.task == k))
            .or_else(|| {
                run("sacct", &["-n", "-P", "-X", "-j", &id, "-o", "JobID,State,ExitCode"])
                    .map(|out| commands::parse_sacct(&out))
                    .ok()
                    .and_then(|v| v.into_iter().find(|s| s.task == k))
            })
            .or_else(|| queued.cloned());
        let log = self.dir.join(format!("task_{k}.log"));
        match detail {
            Some(s) => format!(
                "Slurm task {}_{k}: {}, exit code {} (log: {})",
                self.id,
                s.state,
                s.exit_code.as_deref().unwrap_or("unknown"),
                log.display()
            ),
            None => format!(
                "Slurm task {}_{k} left the queue without its outputs (log: {})",
                self.id,
                log.display()
            ),
        }
    }
}

/// Ctrl-C, SIGTERM and SIGHUP set [`INTERRUPTED`] while arrays are followed, and end the
/// process (exit code 130) otherwise (installed once per process).
fn install_interrupt_handler() {
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| {
        // A handler that cannot be installed leaves the signals to end the process, the
        // arrays running on (the next invocation collects what they finish).
        let _ = ctrlc::set_handler(|| {
            if FOLLOWING.load(Ordering::SeqCst) {
                INTERRUPTED.store(true, Ordering::SeqCst);
            } else {
                std::process::exit(130);
            }
        });
    });
}

/// The `meniscus` binary exists and is of this solver build.
fn check_binary(meniscus: &Path) -> Result<()> {
    if !meniscus.is_file() {
        return Err(slurm_error(format!(
            "--meniscus: `{}` does not exist: build it with `cargo build -p meniscus-cli` (`--release` \
             for `cargo xtask bench`, which runs in the release build), or name the binary with \
             --meniscus",
            meniscus.display()
        )));
    }
    let program = meniscus.display().to_string();
    let version = run(&program, &["--version"]).map_err(slurm_error)?;
    if !version.contains(meniscus::SOLVER_FINGERPRINT) {
        return Err(slurm_error(format!(
            "--meniscus: `{program}` is another build of the solver (`{}`; this harness's is {}): \
             rebuild it with `cargo build -p meniscus-cli`",
            version.lines().next().unwrap_or_default().trim(),
            meniscus::SOLVER_FINGERPRINT
        )));
    }
    Ok(())
}

/// `--time-limit` is a Slurm time within the partition's `MaxTime` (from `line`, its
/// `scontrol -o show partition`): a longer one would leave every task pending
/// (`PartitionTimeLimit`) unless the cluster refuses it outright.
fn check_time_limit(time: &str, partition: &str, line: &str) -> Result<()> {
    let asked = commands::parse_time(time).ok_or_else(|| {
        slurm_error(format!(
            "--time-limit: `{time}` is not a Slurm time (minutes, minutes:seconds, \
             hours:minutes:seconds, days-hours, days-hours:minutes or days-hours:minutes:seconds)"
        ))
    })?;
    // `--time=0` asks for no limit.
    let asked = asked.filter(|&s| s > 0);
    let max_time = commands::field(line, "MaxTime").unwrap_or("UNLIMITED");
    if let Some(Some(max)) = commands::parse_time(max_time)
        && asked.is_none_or(|asked| asked > max)
    {
        return Err(slurm_error(format!(
            "--time-limit: `{time}` exceeds partition `{partition}`'s MaxTime of {max_time}: Slurm \
             would leave the tasks pending (PartitionTimeLimit); ask for {max_time} or less"
        )));
    }
    Ok(())
}

/// The spool is readable from the partition's nodes (`line`: the partition's
/// `scontrol -o show partition`): they are all this host, or it lies on a shared file
/// system ([`SHARED_FILE_SYSTEMS`]).
fn check_shared(spool: &Path, partition: &str, line: &str) -> Result<()> {
    let list = commands::field(line, "Nodes").unwrap_or_default();
    let nodes: Vec<String> = run("scontrol", &["show", "hostnames", list])
        .map_err(slurm_error)?
        .lines()
        .map(|l| l.trim().to_string())
        .filter(|l| !l.is_empty())
        .collect();
    let here = hostname();
    let short = |h: &str| h.split('.').next().unwrap_or(h).to_string();
    if !nodes.is_empty() && here.as_deref().is_some_and(|h| nodes.iter().all(|n| short(n) == short(h))) {
        return Ok(());
    }
    let mounts = std::fs::read_to_string("/proc/self/mountinfo").unwrap_or_default();
    let fs = file_system(&mounts, spool).unwrap_or_else(|| "unknown".to_string());
    if SHARED_FILE_SYSTEMS.contains(&fs.as_str()) {
        return Ok(());
    }
    Err(slurm_error(format!(
        "--spool: `{}` is on a node-local file system (`{fs}`): the nodes of partition `{partition}` \
         ({}) cannot read it; put the spool on a shared file system ({})",
        spool.display(),
        nodes.join(", "),
        SHARED_FILE_SYSTEMS.join(", ")
    )))
}

/// This host's name (`/proc/sys/kernel/hostname`, else `$HOSTNAME`).
fn hostname() -> Option<String> {
    std::fs::read_to_string("/proc/sys/kernel/hostname")
        .ok()
        .or_else(|| std::env::var("HOSTNAME").ok())
        .map(|h| h.trim().to_string())
        .filter(|h| !h.is_empty())
}

/// The type of the file system holding `path`, from `/proc/self/mountinfo` text: the
/// mount with the longest mount point that is a prefix of `path`.
fn file_system(mountinfo: &str, path: &Path) -> Option<String> {
    mountinfo
        .lines()
        .filter_map(|l| {
            let (left, right) = l.split_once(" - ")?;
            let point = left.split_whitespace().nth(4)?.replace("\\040", " ");
            let fs = right.split_whitespace().next()?;
            path.starts_with(&point).then(|| (point.len(), fs.to_string()))
        })
        .max_by_key(|(len, _)| *len)
        .map(|(_, fs)| fs)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_spools_file_system_is_its_longest_mount() {
        let mounts = "22 1 254:0 / / rw,relatime - ext4 /dev/vda rw\n\
                      30 22 0:40 / /home rw - nfs4 server:/home rw\n\
                      31 22 0:41 / /home/x\\040y rw - tmpfs tmpfs rw\n";
        assert_eq!(file_system(mounts, Path::new("/home/me/spool")).as_deref(), Some("nfs4"));
        assert_eq!(file_system(mounts, Path::new("/home/x y/spool")).as_deref(), Some("tmpfs"));
        assert_eq!(file_system(mounts, Path::new("/tmp/spool")).as_deref(), Some("ext4"));
        assert_eq!(file_system("", Path::new("/tmp")), None);
    }

    #[test]
    fn counts_read_as_a_line() {
        let c = Counts { pending: 3, running: 2, done: 5, failed: 1 };
        assert_eq!(c.describe(), "3 pending, 2 running, 5 done, 1 failed");
    }
}
