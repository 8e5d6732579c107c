//! The harness's one runner: the validation cases, the stability envelope and the
//! work-precision study all run the solver through it.
//!
//! A [`Job`] is a [`RunSpec`] (scene, slug, hash). The runner
//! - reuses the job's record at `<dir>/runs/<slug>.json` ([`cache`]) while the scene hash
//!   (which covers the solver build) matches, unless `force`;
//! - otherwise runs the scene in-process and stores the record atomically;
//! - catches a panic inside the solver: the job ends [`Ran::Panicked`] with the message
//!   (counted, never cached), and the other jobs go on;
//! - starts the costliest jobs first ([`Job::cost`], an estimate), so that no long run
//!   starts last while the other workers idle;
//! - runs a *wide* job (one asking for every thread of the machine, or allowed them and
//!   the batch's critical path: [`Job::wide`]) alone, before the others; the others `jobs` at a time, each worker with its own rayon pool of an equal
//!   share of the threads (a second thread speeds a run 1.5–1.8 times, a second run at once
//!   doubles the throughput: docs/notes/main-job-time.md); a job may ask for its own thread
//!   count instead (the work-precision study's thread counts);
//! - measures each run's CPU time as the CPU time of the threads that ran it (the worker
//!   and its pool), so it holds with several runs at once;
//! - shows a bar per running run (simulated time) and, optionally, one for the batch whose
//!   length is the jobs' summed cost, advanced as the runs advance, with its ETA; and prints
//!   the line the study makes of each finished job.
//!
//! A reused record's times (`summary.wall_s`, `cpu_s`) are those measured when it ran.
//!
//! With the Slurm executor ([`Runner::with_slurm`]) the runs not in the cache go to the
//! cluster instead ([`crate::slurm`]) and their records come back into the same cache; a
//! run whose task failed there ends [`Ran::Failed`] (counted, never cached).

use crate::cache::{self, CachedProbes, RunRecord};
use crate::error::{HarnessError, Result};
use crate::progress::Progress;
use crate::snapshots::Snapshot;
use crate::sweep::RunSpec;
use indicatif::ProgressBar;
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
    /// May take every thread of the machine (running alone, first) when that ends the batch
    /// sooner: for the costliest such job of cost `c` among the batch's uncached jobs of
    /// summed cost `T`, on `W` workers, when `c (1 − 1/s) > (T − c) / W` with `s` the
    /// speed-up of every thread (each past the first adds half a core: 1.5 measured on two,
    /// docs/notes/main-job-time.md); with two threads, when it is over 60 %
    /// of `T`. Otherwise it runs on a worker's share, like any job with `threads` `None`.
    pub wide: bool,
    /// Estimated cost (any unit shared by the batch, e.g. core-seconds): the costliest jobs
    /// start first and the batch's bar measures progress in it; 0 when unknown (such jobs
    /// keep their order, after the costed ones, and the bar counts each as one unit).
    pub cost: f64,
}

impl Job {
    /// A job on the worker's share of the threads, of unknown cost.
    pub fn new(spec: RunSpec) -> Self {
        Job { spec, threads: None, wide: false, cost: 0.0 }
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
    /// The executor could not run it: its Slurm task failed, timed out or was cancelled
    /// (not cached: the next invocation submits it again).
    Failed {
        /// The executor's account (the task's state, exit code and log).
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
            Ran::Failed { message } => format!("failed: {message}"),
        }
    }

    /// The record, unless the solver panicked.
    pub fn record(&self) -> Option<&RunRecord> {
        match self {
            Ran::Finished { record, .. } => Some(record),
            Ran::Panicked { .. } | Ran::Failed { .. } => None,
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
    /// Jobs the executor could not run (failed Slurm tasks).
    pub failed: usize,
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
    slurm: Option<std::sync::Arc<crate::slurm::Cluster>>,
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
            slurm: None,
        }
    }

    /// The same runner handing the runs it does not find in the cache to `cluster` (the
    /// local executor when `None`).
    pub fn with_slurm(self, cluster: Option<std::sync::Arc<crate::slurm::Cluster>>) -> Self {
        Runner { slurm: cluster, ..self }
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

    /// Runs (or reuses) `jobs`, their records under `<dir>/runs/`, with a bar for the batch
    /// when `bar` names it. `finish` turns job `i`'s outcome into the study's item and the
    /// line printed for it (on the worker, as soon as the job ends). Returns the items in
    /// job order. An invalid scene, a failed write or an error of `finish` is an error: no
    /// job starts after it, and the first in job order is returned once the running ones
    /// ended.
    pub fn run<T: Send>(
        &self,
        dir: &Path,
        bar: Option<&str>,
        jobs: &[Job],
        finish: impl Fn(usize, Ran) -> Result<(T, String)> + Sync,
    ) -> Result<Vec<T>> {
        let placed: Vec<(&Path, &Job)> = jobs.iter().map(|j| (dir, j)).collect();
        self.run_placed(bar, &placed, finish)
    }

    /// [`Runner::run`] with each job's own directory: the jobs of several cases in one batch
    /// (so that the costliest of all start first).
    pub fn run_placed<T: Send>(
        &self,
        bar: Option<&str>,
        jobs: &[(&Path, &Job)],
        finish: impl Fn(usize, Ran) -> Result<(T, String)> + Sync,
    ) -> Result<Vec<T>> {
        if let Some(cluster) = &self.slurm {
            return self.run_on_slurm(cluster, bar, jobs, finish);
        }
        let before = self.tally();
        let units: Vec<u64> = jobs.iter().map(|(_, j)| bar_units(j.cost)).collect();
        let batch = bar.map(|name| self.progress.batch_bar(name, units.iter().sum(), jobs.len()));
        let slots: Vec<Mutex<Option<Result<T>>>> = jobs.iter().map(|_| Mutex::new(None)).collect();
        let failed = AtomicBool::new(false);
        let done = AtomicUsize::new(0);
        let all = rayon::current_num_threads();
        // Costliest first (a stable sort: jobs of unknown cost keep their order, last).
        let mut order: Vec<usize> = (0..jobs.len()).collect();
        order.sort_by(|&a, &b| jobs[b].1.cost.total_cmp(&jobs[a].1.cost));
        // What the batch will run (a cached job costs nothing), and the one `wide` job that
        // ends it sooner alone on every thread than on a worker's share (see `Job::wide`).
        let uncached: Vec<usize> = (0..jobs.len())
            .filter(|&i| {
                let (dir, j) = jobs[i];
                self.force || !cache::is_cached(&cache::record_path(dir, &j.spec.slug), &j.spec.hash)
            })
            .collect();
        let to_run: f64 = uncached.iter().map(|&i| jobs[i].1.cost).sum();
        let workers = self.jobs.min(all).max(1) as f64;
        let critical = uncached
            .iter()
            .copied()
            .filter(|&i| jobs[i].1.wide)
            .max_by(|&a, &b| jobs[a].1.cost.total_cmp(&jobs[b].1.cost))
            .filter(|&i| {
                let c = jobs[i].1.cost;
                c * (1.0 - 1.0 / wide_speedup(all)) > (to_run - c) / workers
            });
        let (wide, narrow): (Vec<usize>, Vec<usize>) = order.into_iter().partition(|&i| {
            self.jobs > 1 && (jobs[i].1.threads.is_some_and(|k| k >= all) || critical == Some(i))
        });
        let phase = |queue: &[usize], workers: usize| {
            let next = AtomicUsize::new(0);
            let share = (workers > 1).then(|| (all / workers).max(1));
            let worker = || {
                let mut pools = BTreeMap::new();
                while !failed.load(Ordering::Relaxed) {
                    let Some(&i) = queue.get(next.fetch_add(1, Ordering::Relaxed)) else { break };
                    let (dir, job) = jobs[i];
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
                    let share = batch.as_ref().map(|b| (b.clone(), units[i]));
                    let item = pool
                        .and_then(|pool| self.one(dir, job, pool, share))
                        .and_then(|ran| finish(i, ran))
                        .map(|(item, line)| {
                            self.progress.println(&line);
                            item
                        });
                    if let Some(b) = &batch {
                        let n = done.fetch_add(1, Ordering::Relaxed) + 1;
                        b.set_message(format!("{n}/{} runs", jobs.len()));
                    }
                    if item.is_err() {
                        failed.store(true, Ordering::Relaxed);
                    }
                    *slots[i].lock().unwrap_or_else(|e| e.into_inner()) = Some(item);
                }
            };
            if workers <= 1 {
                worker();
            } else {
                std::thread::scope(|s| {
                    for _ in 0..workers {
                        s.spawn(worker);
                    }
                });
            }
        };
        phase(&wide, 1);
        phase(&narrow, self.jobs.min(narrow.len()).max(1));
        if let Some(b) = batch {
            let t = self.tally();
            b.finish_with_message(format!(
                "{} run, {} cached",
                t.executed - before.executed,
                t.reused - before.reused
            ));
        }
        let mut items = Vec::with_capacity(jobs.len());
        for slot in slots {
            match slot.into_inner().unwrap_or_else(|e| e.into_inner()) {
                Some(item) => items.push(item),
                // Not started: an error stopped the batch, and is returned below.
                None => assert!(failed.load(Ordering::Relaxed), "without an error every job ran"),
            }
        }
        items.into_iter().collect()
    }

    /// [`Runner::run_placed`] on a Slurm cluster: the cached records reused, the other jobs
    /// run as job arrays; items in job order.
    fn run_on_slurm<T>(
        &self,
        cluster: &crate::slurm::Cluster,
        bar: Option<&str>,
        jobs: &[(&Path, &Job)],
        finish: impl Fn(usize, Ran) -> Result<(T, String)>,
    ) -> Result<Vec<T>> {
        let before = self.tally();
        let units: Vec<u64> = jobs.iter().map(|(_, j)| bar_units(j.cost)).collect();
        let batch = bar.map(|name| self.progress.batch_bar(name, units.iter().sum(), jobs.len()));
        let mut items: Vec<Option<T>> = jobs.iter().map(|_| None).collect();
        let mut end = |i: usize, ran: Ran| -> Result<()> {
            let (item, line) = finish(i, ran)?;
            self.progress.println(&line);
            if let Some(b) = &batch {
                b.inc(units[i]);
            }
            items[i] = Some(item);
            Ok(())
        };
        let mut pending = Vec::new();
        for (i, (dir, job)) in jobs.iter().enumerate() {
            let cached =
                (!self.force).then(|| cache::load(&cache::record_path(dir, &job.spec.slug), &job.spec.hash));
            match cached.flatten() {
                Some(record) => {
                    self.count(|t| t.reused += 1);
                    end(i, Ran::Finished { record: Box::new(record), reused: true })?;
                }
                None => pending.push((i, &job.spec, job.threads)),
            }
        }
        // Costliest first, as on this machine: an array's tasks start in index order.
        pending.sort_by(|a, b| jobs[b.0].1.cost.total_cmp(&jobs[a.0].1.cost));
        let show = |c: crate::slurm::Counts| {
            if let Some(b) = &batch {
                b.set_message(format!("slurm: {}", c.describe()));
            }
        };
        cluster.run(&pending, self.force, &show, &mut |i, outcome| {
            let (dir, job) = jobs[i];
            let ran = match outcome {
                crate::slurm::Outcome::Finished(record) => {
                    cache::store(&cache::record_path(dir, &job.spec.slug), &record)?;
                    self.count(|t| t.executed += 1);
                    Ran::Finished { record, reused: false }
                }
                crate::slurm::Outcome::Failed(message) => {
                    self.count(|t| {
                        t.executed += 1;
                        t.failed += 1;
                    });
                    Ran::Failed { message }
                }
            };
            end(i, ran)
        })?;
        if let Some(b) = &batch {
            let t = self.tally();
            b.finish_with_message(format!(
                "{} run on slurm, {} cached, {} failed",
                t.executed - before.executed,
                t.reused - before.reused,
                t.failed - before.failed
            ));
        }
        Ok(items.into_iter().map(|i| i.expect("every job ended")).collect())
    }

    /// Reuses or runs one job (on `pool` when given).
    /// `batch`: the batch's bar and the job's share of it.
    fn one(
        &self,
        dir: &Path,
        job: &Job,
        pool: Option<&rayon::ThreadPool>,
        batch: Option<(ProgressBar, u64)>,
    ) -> Result<Ran> {
        let spec = &job.spec;
        let path = cache::record_path(dir, &spec.slug);
        if !self.force
            && let Some(record) = cache::load(&path, &spec.hash)
        {
            self.count(|t| t.reused += 1);
            if let Some((b, units)) = batch {
                b.inc(units);
            }
            return Ok(Ran::Finished { record: Box::new(record), reused: true });
        }
        self.count(|t| t.executed += 1);
        let mut bar = self.progress.run_bar(&spec.slug, batch);
        let threads = pool.map_or_else(rayon::current_num_threads, rayon::ThreadPool::current_num_threads);
        let cpu0 = run_cpu_s(pool);
        let run = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| match pool {
            Some(pool) => pool.install(|| (self.solve)(&spec.scene, &mut bar)),
            None => (self.solve)(&spec.scene, &mut bar),
        }));
        let cpu_s = cpu0.and_then(|a| run_cpu_s(pool).map(|b| b - a));
        bar.finish();
        match run {
            Ok(Ok(report)) => {
                let snapshots =
                    report.snapshots.iter().map(|f| Snapshot::new(f, spec.scene.dimension)).collect();
                let record =
                    spec.record(report.summary, CachedProbes::from(report.probes), snapshots, cpu_s, threads);
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

/// The assumed speed-up of one run on `threads` threads over one: each thread past the
/// first adds half a core, as measured for the open channel at Δx = 0.0025 (96 000
/// particles) on two (1.50; 1.5–1.8 for 3200–37 500 particles, docs/notes/main-job-time.md).
fn wide_speedup(threads: usize) -> f64 {
    1.0 + 0.5 * threads.saturating_sub(1) as f64
}

/// Units of a job of estimated `cost` on the batch's bar (milliseconds of the estimate; one
/// unit when unknown).
fn bar_units(cost: f64) -> u64 {
    if cost > 0.0 && cost.is_finite() { (cost * 1e3).ceil() as u64 } else { 1 }
}

/// CPU time so far of the threads that run a job \[s\]: the calling thread (which runs the
/// serial parts when `pool` is `None`) and every thread of `pool` or of the global pool.
/// `None` off Linux.
fn run_cpu_s(pool: Option<&rayon::ThreadPool>) -> Option<f64> {
    let workers: Vec<Option<f64>> = match pool {
        Some(pool) => pool.broadcast(|_| thread_cpu_s()),
        None => rayon::broadcast(|_| thread_cpu_s()),
    };
    workers.into_iter().chain([thread_cpu_s()]).sum()
}

/// CPU time of the calling thread, user + system \[s\] (`/proc/thread-self/stat` fields 14
/// and 15, in clock ticks of 1/100 s, the Linux value); `None` off Linux.
fn thread_cpu_s() -> Option<f64> {
    let stat = std::fs::read_to_string("/proc/thread-self/stat").ok()?;
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

    /// The costliest jobs start first and a wide job (every thread) runs alone before the
    /// others; the items come back in job order.
    #[test]
    fn costliest_first_and_wide_jobs_alone() {
        let mut case = crate::case::testing::committed("elliptical_drop");
        case.scene["time"]["end"] = serde_json::json!(2e-4);
        let all = rayon::current_num_threads();
        let job = |name: &str, cost: f64, threads: Option<usize>| {
            let mut spec = crate::sweep::spec(&case, "paper", 0.1).unwrap();
            spec.slug = name.into();
            Job { threads, cost, ..Job::new(spec) }
        };
        let jobs = [
            job("cheap", 1.0, None),
            job("dear", 3.0, None),
            job("wide", 0.5, Some(all)),
            job("mid", 2.0, None),
        ];
        let dir = Scratch::new("runner-order");
        for workers in [1, 2] {
            let finished = Mutex::new(Vec::new());
            let runner = Runner::new(Progress::silent(), true, workers);
            let out = runner
                .run(dir.path(), Some("order"), &jobs, |i, _| {
                    finished.lock().unwrap().push(jobs[i].spec.slug.clone());
                    Ok((i, String::new()))
                })
                .unwrap();
            assert_eq!(out, [0, 1, 2, 3], "job order");
            let finished = finished.into_inner().unwrap();
            if workers == 1 {
                // One at a time: costliest first, the wide job among them by its cost.
                assert_eq!(finished, ["dear", "mid", "cheap", "wide"]);
            } else {
                assert_eq!(finished[0], "wide", "the wide job runs alone, first: {finished:?}");
            }
        }
    }

    /// A `wide` job takes every thread only when that ends what the batch runs sooner.
    #[test]
    fn wide_jobs_take_every_thread_only_on_the_critical_path() {
        let mut case = crate::case::testing::committed("elliptical_drop");
        case.scene["time"]["end"] = serde_json::json!(2e-4);
        let job = |name: &str, cost: f64, wide: bool| {
            let mut spec = crate::sweep::spec(&case, "paper", 0.1).unwrap();
            spec.slug = name.into();
            Job { wide, cost, ..Job::new(spec) }
        };
        let dir = Scratch::new("runner-wide");
        let pool = rayon::ThreadPoolBuilder::new().num_threads(2).build().unwrap();
        pool.install(|| {
            let threads = |force: bool, jobs: &[Job]| -> Vec<usize> {
                Runner::new(Progress::silent(), force, 2)
                    .run(dir.path(), None, jobs, |_, ran| {
                        Ok((ran.record().unwrap().threads.unwrap(), String::new()))
                    })
                    .unwrap()
            };
            // 5 (1 − 1/1.5) > (1 + 1) / 2: alone on both threads, the big run ends sooner.
            assert_eq!(
                threads(true, &[job("big", 5.0, true), job("a", 1.0, false), job("b", 1.0, false)]),
                [2, 1, 1]
            );
            // 3 (1 − 1/1.5) < (2 + 2) / 2: it does not, and runs on a worker's share.
            assert_eq!(
                threads(true, &[job("big", 3.0, true), job("a", 2.0, false), job("b", 2.0, false)]),
                [1, 1, 1]
            );
            // 5.5 of 10 (over half, under 60 %): still not.
            let batch = [job("big3", 5.5, true), job("c", 2.25, false), job("d", 2.25, false)];
            assert_eq!(threads(true, &batch), [1, 1, 1]);
            // The same batch with `a` and `b` cached: the new big run is all that runs.
            assert_eq!(
                threads(false, &[job("big2", 3.0, true), job("a", 2.0, false), job("b", 2.0, false)]),
                [2, 1, 1]
            );
        });
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
            assert_eq!(runner.tally(), Tally { executed: 2, reused: 0, panicked: 1, failed: 0 });
        }
        assert!(cache::record_path(dir.path(), "isph-paper_dx0.1").is_file());
        assert!(!cache::record_path(dir.path(), "panics").exists(), "a panic is not cached");
        let runner = runner(false, 1);
        let out = runner.run(dir.path(), None, &jobs, finish).unwrap();
        assert_eq!(out[0], (0, "ok".to_string(), true), "reused");
        assert_eq!(runner.tally(), Tally { executed: 1, reused: 1, panicked: 1, failed: 0 });
        // An error (here the study's) starts no further job.
        let runner = Runner::new(Progress::silent(), true, 1);
        let failing = |i: usize, _: Ran| {
            if i == 0 { Err(HarnessError::case("tiny", "bad")) } else { Ok(((), String::new())) }
        };
        assert!(runner.run(dir.path(), None, &jobs, failing).is_err());
        assert_eq!(runner.tally().executed, 1);
    }
}
