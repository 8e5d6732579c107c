//! The spool directory, on the file system the login node shares with the compute nodes:
//!
//! - `runs/<scene hash>-t<threads>/scene.json`: a run's effective scene (the thread count
//!   in the name: the work-precision study runs one scene on several); `out/` once its task has
//!   finished (the `meniscus run` outputs, `summary.json`, `probes.json`, `snapshots/`,
//!   and `cpu.txt`, the task's CPU time), `out.partial/` while it runs; `task`, the array
//!   task that last took it (`<job> <task index> <array directory>`). The directory is
//!   keyed by the run's hash, so a run that finished after its submitter was stopped is
//!   collected by the next invocation instead of run again, and one whose task still
//!   pends or runs is followed instead of submitted again;
//! - `arrays/<name>/`: one submitted job array: `run.sh` (the batch script), `tasks.txt`
//!   (task k runs the run directory on line k + 1), `task_<k>.log` (each task's output),
//!   `job_id`.

use crate::cache::{CachedProbes, RunRecord};
use crate::error::{HarnessError, Result};
use crate::io;
use crate::snapshots::Snapshot;
use crate::sweep::RunSpec;
use serde::Deserialize;
use std::path::{Path, PathBuf};

/// The spool directory (see the module documentation).
#[derive(Debug, Clone)]
pub struct Spool {
    root: PathBuf,
}

impl Spool {
    /// The spool at `root` (created when first written).
    pub fn new(root: PathBuf) -> Self {
        Spool { root }
    }

    /// The directory of a run on `threads` threads.
    pub fn run_dir(&self, spec: &RunSpec, threads: usize) -> PathBuf {
        self.root.join("runs").join(format!("{}-t{threads}", spec.hash))
    }

    /// Whether the run's task finished (its outputs are complete). Its directory is listed
    /// first: on NFS that revalidates the directory's cached entries.
    pub fn finished(&self, spec: &RunSpec, threads: usize) -> bool {
        let dir = self.run_dir(spec, threads);
        let _ = std::fs::read_dir(&dir).map(|entries| entries.count());
        dir.join("out").join("summary.json").is_file()
    }

    /// Records that array task `task` of job `job` (its directory `array`) took the run.
    pub fn claim(&self, run_dir: &Path, job: u64, task: usize, array: &Path) -> Result<()> {
        io::write_atomic(&run_dir.join("task"), format!("{job} {task} {}\n", array.display()).as_bytes())
    }

    /// The array task that last took the run (see [`Spool::claim`]), if any.
    pub fn claimed(&self, spec: &RunSpec, threads: usize) -> Option<Claim> {
        let text = std::fs::read_to_string(self.run_dir(spec, threads).join("task")).ok()?;
        let mut f = text.trim_end_matches('\n').splitn(3, ' ');
        Some(Claim { job: f.next()?.parse().ok()?, task: f.next()?.parse().ok()?, array: f.next()?.into() })
    }

    /// Writes the run's scene for a task, dropping the outputs of an earlier one.
    pub fn prepare(&self, spec: &RunSpec, threads: usize) -> Result<PathBuf> {
        let dir = self.run_dir(spec, threads);
        remove_dir(&dir.join("out"))?;
        io::create_dir(&dir)?;
        io::write_json(&dir.join("scene.json"), &spec.scene_json)?;
        Ok(dir)
    }

    /// The record of a finished run (see [`Spool::finished`]), as the local executor would
    /// have stored it: the scene, summary, probes and snapshots from the task's outputs, the
    /// CPU time the task measured.
    pub fn collect(&self, spec: &RunSpec, threads: usize) -> Result<RunRecord> {
        let out = self.run_dir(spec, threads).join("out");
        let summary: meniscus::Summary = io::read_json(&out.join("summary.json"))?;
        let probes: CachedProbes = io::read_json(&out.join("probes.json"))?;
        let mut snapshots = Vec::new();
        let frames = out.join("snapshots");
        if frames.is_dir() {
            let mut files: Vec<PathBuf> = std::fs::read_dir(&frames)
                .map_err(|source| HarnessError::Io { path: frames.clone(), source })?
                .filter_map(|e| e.ok().map(|e| e.path()))
                .filter(|p| p.extension().is_some_and(|x| x == "json"))
                .collect();
            files.sort();
            for file in files {
                let frame: FrameFile = io::read_json(&file)?;
                snapshots.push(frame.snapshot(spec.scene.dimension));
            }
        }
        let cpu_s = std::fs::read_to_string(out.join("cpu.txt")).ok().and_then(|t| parse_times(&t));
        let threads = summary.threads;
        Ok(spec.record(summary, probes, snapshots, cpu_s, threads))
    }

    /// Writes a job array's directory `arrays/<name>/`: the batch script running each of
    /// `runs` (run directories) through `meniscus` with `threads` threads, and the task
    /// list. Returns the directory.
    pub fn write_array(
        &self,
        name: &str,
        runs: &[PathBuf],
        meniscus: &Path,
        threads: usize,
    ) -> Result<PathBuf> {
        let dir = self.root.join("arrays").join(name);
        io::create_dir(&dir)?;
        let tasks: String = runs.iter().map(|r| format!("{}\n", r.display())).collect();
        io::write_atomic(&dir.join("tasks.txt"), tasks.as_bytes())?;
        let script = batch_script(&dir.join("tasks.txt"), meniscus, threads);
        io::write_atomic(&dir.join("run.sh"), script.as_bytes())?;
        Ok(dir)
    }
}

/// An array task that took a run (see [`Spool::claim`]).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Claim {
    /// The array's job id.
    pub job: u64,
    /// The task's index in the array.
    pub task: usize,
    /// The array's directory (`arrays/<name>/`).
    pub array: PathBuf,
}

/// The batch script of an array: task k runs the scene of the run directory on line k + 1
/// of `tasks` through `meniscus run` and, when the run ended (completed or diverged: exit
/// code 0 or 3, a result either way), records the task's CPU time (bash's `times`, the
/// children's user and system seconds) and renames `out.partial/` to `out/`, so that `out/`
/// only ever holds a finished run's outputs. Any other exit code is the task's.
pub fn batch_script(tasks: &Path, meniscus: &Path, threads: usize) -> String {
    let tasks = quote(&tasks.display().to_string());
    let meniscus = quote(&meniscus.display().to_string());
    format!(
        "#!/bin/bash
# One Meniscus run per array task, written by `cargo xtask validate --executor slurm`.
set -u
# bash's `times` below writes the C locale's decimal point.
export LC_ALL=C
run=$(sed -n \"$((SLURM_ARRAY_TASK_ID + 1))p\" {tasks})
if [ -z \"$run\" ]; then echo \"no run for task $SLURM_ARRAY_TASK_ID in \"{tasks} >&2; exit 2; fi
rm -rf \"$run/out.partial\"
{meniscus} run \"$run/scene.json\" --out \"$run/out.partial\" --threads {threads}
rc=$?
# 3: the run diverged; its summary says why, and it is a result like any other.
if [ \"$rc\" -ne 0 ] && [ \"$rc\" -ne 3 ]; then exit \"$rc\"; fi
times > \"$run/out.partial/cpu.txt\"
rm -rf \"$run/out\"
mv \"$run/out.partial\" \"$run/out\"
"
    )
}

/// `text` single-quoted for bash.
fn quote(text: &str) -> String {
    format!("'{}'", text.replace('\'', r"'\''"))
}

/// The children's user + system seconds of bash's `times` output: its last line,
/// `0m1.250s 0m0.030s` (`times` in a pipeline would run in a subshell, which has no
/// children yet).
fn parse_times(text: &str) -> Option<f64> {
    let line = text.lines().last()?;
    let seconds = |f: &str| -> Option<f64> {
        let (m, s) = f.trim_end_matches('s').split_once('m')?;
        Some(m.parse::<f64>().ok()? * 60.0 + s.parse::<f64>().ok()?)
    };
    let mut f = line.split_whitespace();
    Some(seconds(f.next()?)? + seconds(f.next()?)?)
}

/// A `meniscus run` snapshot file (a [`meniscus::Frame`]) with its non-finite values
/// written as `null`.
#[derive(Deserialize)]
struct FrameFile {
    step: usize,
    time: f64,
    x: Vec<[Option<f64>; 3]>,
    p: Vec<Option<f64>>,
}

impl FrameFile {
    fn snapshot(self, dimension: usize) -> Snapshot {
        let nan = |v: Option<f64>| v.unwrap_or(f64::NAN);
        let frame = meniscus::Frame {
            step: self.step,
            time: self.time,
            x: self.x.into_iter().map(|x| x.map(nan)).collect(),
            p: self.p.into_iter().map(nan).collect(),
            ..Default::default()
        };
        Snapshot::new(&frame, dimension)
    }
}

fn remove_dir(dir: &Path) -> Result<()> {
    match std::fs::remove_dir_all(dir) {
        Err(e) if e.kind() != std::io::ErrorKind::NotFound => {
            Err(HarnessError::Io { path: dir.into(), source: e })
        }
        _ => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_bash_times_and_quotes_paths() {
        assert_eq!(parse_times("0m0.010s 0m0.002s\n1m2.500s 0m0.250s\n"), Some(62.75));
        assert_eq!(parse_times("garbage"), None);
        assert_eq!(quote("/a b/it's"), r"'/a b/it'\''s'");
        let script = batch_script(Path::new("/s/arrays/x/tasks.txt"), Path::new("/bin/meniscus"), 2);
        assert!(
            script.contains("'/bin/meniscus' run \"$run/scene.json\" --out \"$run/out.partial\" --threads 2")
        );
        assert!(script.starts_with("#!/bin/bash\n"));
    }
}
