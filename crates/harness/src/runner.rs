//! The harness's one runner: the validation cases, the stability envelope and the
//! work-precision study all run the solver through it.
//!
//! A [`Job`] is a [`RunSpec`] (scene, slug, hash). The runner
//! - reuses the job's record at `<dir>/runs/<slug>.json` ([`cache`]) while the scene hash
//!   (which covers the solver build) matches, unless `force`;
//! - otherwise runs the scene in-process and stores the record atomically;
//! - catches a panic inside the solver: the job ends [`Ran::Panicked`] with the message
//!   (counted, never cached), and the other jobs go on;
//! - runs `jobs` jobs at a time, each worker with its own rayon pool of an equal share of
//!   the threads (small runs, like the channels' few thousand particles, gain nothing from a
//!   second thread: their steps are bound by synchronisation); a job may ask for its own
//!   thread count instead (the work-precision study's thread counts);
//! - shows a bar per running run (simulated time) and, optionally, one counting the jobs
//!   of a batch, and prints the line the study makes of each finished job.
//!
//! A reused record's times (`summary.wall_s`, `cpu_s`) are those measured when it ran.

use crate::cache::{self, CachedProbes, RunRecord};
use crate::error::{HarnessError, Result};
use crate::progress::Progress;
use crate::snapshots::Snapshot;
use crate::sweep::RunSpec;
use std::collections::BTreeMap;
use std::path::Path;
use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

/// One run for the runner.
#[derive(Debug, Clone)]
pub struct Job {
    /// What to run.
    pub spec: RunSpec,
    /// Threads of the run's own rayon pool; `None`: the worker's share of the machine (all
    /// of the global pool when one job runs at a time).
    pub threads: Option<usize>,
}

impl Job {
    /// A job on the worker's share of the threads.
    pub fn new(spec: RunSpec) -> Self {
        Job { spec, threads: None }
    }
}

/// How a job ended.
#[derive(Debug, Clone)]
pub enum Ran {
    /// The solver returned: the run reached its end time or diverged (see its summary).
    Finished {
        /// The run's record.
        record: Box<RunRecord>,
        /// Taken from the cache (its times are those measured when it ran).
        reused: bool,
    },
    /// The solver panicked (not cached: the next invocation runs it again).
    Panicked {
        /// The panic's message.
        message: String,
    },
}

impl Ran {
    /// The run's status: the record's ([`RunRecord::status`]), or
    /// `diverged: the solver panicked: <message>`.
    pub fn status(&self) -> String {
        match self {
            Ran::Finished { record, .. } => record.status(),
            Ran::Panicked { message } => format!("diverged: the solver panicked: {message}"),
        }
    }

    /// The record, unless the solver panicked.
    pub fn record(&self) -> Option<&RunRecord> {
        match self {
            Ran::Finished { record, .. } => Some(record),
            Ran::Panicked { .. } => None,
        }
    }

    /// Whether the record came from the cache.
    pub fn reused(&self) -> bool {
        matches!(self, Ran::Finished { reused: true, .. })
    }
}

/// What a runner did so far.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Tally {
    /// Jobs run (panicked ones included).
    pub executed: usize,
    /// Jobs whose record was reused.
    pub reused: usize,
    /// Jobs whose run panicked.
    pub panicked: usize,
}

/// How the runner runs a scene: [`meniscus::run`] (tests put a panicking one in its place).
type Solve = fn(
    &meniscus::Scene,
    &mut dyn meniscus::Observer,
) -> std::result::Result<meniscus::RunReport, meniscus::SceneError>;

/// The runner (see the module documentation).
#[derive(Debug)]
pub struct Runner {
    progress: Progress,
    force: bool,
    jobs: usize,
    tally: Mutex<Tally>,
    solve: Solve,
}

impl Runner {
    /// A runner that shows `progress`, reruns cached runs when `force`, and runs `jobs`
    /// jobs at a time (at least one).
    pub fn new(progress: Progress, force: bool, jobs: usize) -> Self {
        Runner {
            progress,
            force,
            jobs: jobs.max(1),
            tally: Mutex::new(Tally::default()),
            solve: meniscus::run,
        }
    }

    /// The progress display (for the studies' own lines).
    pub fn progress(&self) -> &Progress {
        &self.progress
    }

    /// The counts so far.
    pub fn tally(&self) -> Tally {
        *self.tally.lock().unwrap_or_else(|e| e.into_inner())
    }

    fn count(&self, f: impl FnOnce(&mut Tally)) {
        f(&mut self.tally.lock().unwrap_or_else(|e| e.into_inner()));
    }

    /// Runs (or reuses) `jobs`, their records under `<dir>/runs/`, with a bar counting them
    /// when `bar` names the batch. `finish` turns job `i`'s outcome into the study's item
    /// and the line printed for it (on the worker, as soon as the job ends). Returns the
    /// items in job order. An invalid scene, a failed write or an error of `finish` is an
    /// error: no job starts after it, and the first in job order is returned once the
    /// running ones ended.
    pub fn run<T: Send>(
        &self,
        dir: &Path,
        bar: Option<&str>,
        jobs: &[Job],
        finish: impl Fn(usize, Ran) -> Result<(T, String)> + Sync,
    ) -> Result<Vec<T>> {
        let before = self.tally();
        let batch = bar.map(|name| self.progress.case_bar(name, jobs.len()));
        let slots: Vec<Mutex<Option<Result<T>>>> = jobs.iter().map(|_| Mutex::new(None)).collect();
        let next = AtomicUsize::new(0);
        let failed = AtomicBool::new(false);
        let workers = self.jobs.min(jobs.len()).max(1);
        let share = (workers > 1).then(|| (rayon::current_num_threads() / workers).max(1));
        let worker = || {
            let mut pools = BTreeMap::new();
            while !failed.load(Ordering::Relaxed) {
                let i = next.fetch_add(1, Ordering::Relaxed);
                let Some(job) = jobs.get(i) else { break };
                // A share that cannot be had runs on the global pool; asked-for threads must be.
                let pool = match job.threads.or(share).map(|k| {
                    (
                        k,
                        pools
                            .entry(k)
                            .or_insert_with(|| rayon::ThreadPoolBuilder::new().num_threads(k).build()),
                    )
                }) {
                    Some((_, Ok(pool))) => Ok(Some(&*pool)),
                    Some((k, Err(e))) if job.threads.is_some() => Err(HarnessError::case(
                        &job.spec.case,
                        format!("run {}: no rayon pool of {k} threads: {e}", job.spec.slug),
                    )),
                    _ => Ok(None),
                };
                let item = pool.and_then(|pool| self.one(dir, job, pool)).and_then(|ran| finish(i, ran)).map(
                    |(item, line)| {
                        self.progress.println(&line);
                        item
                    },
                );
                if let Some(b) = &batch {
                    b.inc(1);
                }
                if item.is_err() {
                    failed.store(true, Ordering::Relaxed);
                }
                *slots[i].lock().unwrap_or_else(|e| e.into_inner()) = Some(item);
            }
        };
        if workers == 1 {
            worker();
        } else {
            std::thread::scope(|s| {
                for _ in 0..workers {
                    s.spawn(worker);
                }
            });
        }
        if let Some(b) = batch {
            let t = self.tally();
            b.finish_with_message(format!(
                "{} run, {} cached",
                t.executed - before.executed,
                t.reused - before.reused
            ));
        }
        // Jobs are taken in order, so every job before the first failed one ran.
        let items = slots
            .into_iter()
            .map_while(|m| m.into_inner().unwrap_or_else(|e| e.into_inner()))
            .collect::<Result<Vec<T>>>()?;
        assert_eq!(items.len(), jobs.len(), "without an error every job ran");
        Ok(items)
    }

    /// Reuses or runs one job (on `pool` when given).
    fn one(&self, dir: &Path, job: &Job, pool: Option<&rayon::ThreadPool>) -> Result<Ran> {
        let spec = &job.spec;
        let path = cache::record_path(dir, &spec.slug);
        if !self.force
            && let Some(record) = cache::load(&path, &spec.hash)
        {
            self.count(|t| t.reused += 1);
            return Ok(Ran::Finished { record: Box::new(record), reused: true });
        }
        self.count(|t| t.executed += 1);
        let mut bar = self.progress.run_bar(&spec.slug);
        // CPU time is the whole process's: meaningful only with one run at a time.
        let cpu0 = (self.jobs == 1).then(process_cpu_s).flatten();
        let run = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| match pool {
            Some(pool) => pool.install(|| (self.solve)(&spec.scene, &mut bar)),
            None => (self.solve)(&spec.scene, &mut bar),
        }));
        let cpu_s = cpu0.and_then(|a| process_cpu_s().map(|b| b - a));
        bar.finish();
        match run {
            Ok(Ok(report)) => {
                let record = RunRecord {
                    completed: true,
                    slug: spec.slug.clone(),
                    scheme: spec.scheme.clone(),
                    preset: spec.preset.clone(),
                    dx: spec.dx,
                    scene_hash: spec.hash.clone(),
                    scene: spec.scene_json.clone(),
                    summary: report.summary,
                    probes: CachedProbes::from(report.probes),
                    snapshots: report.snapshots.iter().map(Snapshot::from).collect(),
                    cpu_s,
                };
                cache::store(&path, &record)?;
                Ok(Ran::Finished { record: Box::new(record), reused: false })
            }
            Ok(Err(source)) => {
                Err(HarnessError::Scene { case: spec.case.clone(), run: spec.slug.clone(), source })
            }
            Err(panic) => {
                self.count(|t| t.panicked += 1);
                let message = panic
                    .downcast_ref::<String>()
                    .cloned()
                    .or_else(|| panic.downcast_ref::<&str>().map(|s| s.to_string()))
                    .unwrap_or_else(|| "unknown panic".into());
                Ok(Ran::Panicked { message })
            }
        }
    }
}

/// CPU time of this process, user + system, all threads \[s\] (`/proc/self/stat` fields 14
/// and 15, in clock ticks of 1/100 s, the Linux value); `None` off Linux.
fn process_cpu_s() -> Option<f64> {
    let stat = std::fs::read_to_string("/proc/self/stat").ok()?;
    // Fields after the command name (which may hold spaces) start at field 3.
    let rest = &stat[stat.rfind(')')? + 1..];
    let f: Vec<&str> = rest.split_whitespace().collect();
    let ticks = f.get(11)?.parse::<f64>().ok()? + f.get(12)?.parse::<f64>().ok()?;
    Some(ticks / 100.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::testing::Scratch;

    /// The solver, but a scene named `panics` makes it panic.
    fn solve_or_panic(
        scene: &meniscus::Scene,
        observer: &mut dyn meniscus::Observer,
    ) -> std::result::Result<meniscus::RunReport, meniscus::SceneError> {
        assert!(scene.name != "panics", "the solver panicked on purpose");
        meniscus::run(scene, observer)
    }

    /// Two tiny drops (dx = 0.1, 10 steps), one of which panics: the panic is that job's
    /// outcome, counted and not cached, and the other job is run, cached and then reused,
    /// one job at a time and two at once.
    #[test]
    fn catches_panics_caches_and_reuses() {
        let mut case = crate::case::testing::committed("elliptical_drop");
        case.scene["time"]["end"] = serde_json::json!(2e-4);
        let spec = crate::sweep::spec(&case, "paper", 0.1).unwrap();
        let mut panicking = spec.clone();
        (panicking.slug, panicking.scene.name) = ("panics".into(), "panics".into());
        let jobs = [Job::new(spec), Job { threads: Some(1), ..Job::new(panicking) }];
        let dir = Scratch::new("runner");
        let finish = |i: usize, ran: Ran| Ok(((i, ran.status(), ran.reused()), String::new()));
        let runner = |force: bool, jobs: usize| Runner {
            solve: solve_or_panic,
            ..Runner::new(Progress::silent(), force, jobs)
        };
        for jobs_at_once in [1, 2] {
            let runner = runner(jobs_at_once == 2, jobs_at_once);
            let out = runner.run(dir.path(), Some("tiny"), &jobs, finish).unwrap();
            assert_eq!(out[0], (0, "ok".to_string(), false), "run (again when forced)");
            assert_eq!(
                out[1],
                (1, "diverged: the solver panicked: the solver panicked on purpose".into(), false)
            );
            assert_eq!(runner.tally(), Tally { executed: 2, reused: 0, panicked: 1 });
        }
        assert!(cache::record_path(dir.path(), "isph-paper_dx0.1").is_file());
        assert!(!cache::record_path(dir.path(), "panics").exists(), "a panic is not cached");
        let runner = runner(false, 1);
        let out = runner.run(dir.path(), None, &jobs, finish).unwrap();
        assert_eq!(out[0], (0, "ok".to_string(), true), "reused");
        assert_eq!(runner.tally(), Tally { executed: 1, reused: 1, panicked: 1 });
        // An error (here the study's) starts no further job.
        let runner = Runner::new(Progress::silent(), true, 1);
        let failing = |i: usize, _: Ran| {
            if i == 0 { Err(HarnessError::case("tiny", "bad")) } else { Ok(((), String::new())) }
        };
        assert!(runner.run(dir.path(), None, &jobs, failing).is_err());
        assert_eq!(runner.tally().executed, 1);
    }
}
