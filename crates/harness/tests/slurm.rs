//! The Slurm executor against a real cluster (issue #40). Ignored by `cargo test`: it needs
//! Slurm's commands and a running cluster, which `tools/slurm-test/run.sh` starts (one node,
//! this machine) before running these tests with `--ignored`; that script is how CI runs
//! them, and it fails when the cluster cannot start. Environment: `SLURM_CONF` (the test
//! cluster's configuration) and `MENISCUS_BIN` (a `meniscus` binary of this solver build).
//!
//! - the quick drop sweep through Slurm writes the `results.json` of the local executor
//!   (runs, metrics, orders and checks; not the wall and CPU times or the threads), its
//!   runs split into arrays of the cluster's `MaxArraySize` (8 in the test cluster);
//! - a task killed mid-run is reported with its Slurm state, left uncached, and submitted
//!   alone by the next invocation;
//! - when the submitter is killed (SIGKILL: nothing cancels its arrays), the next invocation
//!   follows the tasks still queued instead of submitting their runs again;
//! - tasks that wait for a reason Slurm does not clear by itself (here the partition's
//!   `MaxTime` lowered below their time limit after the check) are cancelled and reported;
//! - an unknown partition, a spool on a node-local file system for a partition of other
//!   hosts, and a time limit that is not a Slurm time or exceeds the partition's `MaxTime`
//!   are errors before anything is submitted.

use meniscus_harness::slurm::{Cluster, SlurmOptions};
use meniscus_harness::{Case, Tier, ValidateOptions, validate};
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// A scratch workspace with the elliptical drop's case file, plus (`long`) a preset
/// running five times longer at Δx = 0.02, to be killed mid-run.
fn workspace(tag: &str, long: bool) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("slurm_{tag}"));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(dir.join("validation")).expect("scratch directory");
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let mut case = Case::load(&root.join("validation/elliptical_drop.json")).expect("case");
    if long {
        let mut preset = case.sweep.presets[0].clone();
        preset.name = "long".into();
        preset.patch["time"] = serde_json::json!({"end": 0.04});
        preset.dx = Some([(Tier::Quick, vec![0.02])].into());
        case.sweep.presets.push(preset);
    }
    std::fs::write(
        dir.join("validation/elliptical_drop.json"),
        serde_json::to_string_pretty(&case).expect("case JSON"),
    )
    .expect("write case");
    dir
}

fn options(partition: Option<&str>, spool: PathBuf) -> SlurmOptions {
    SlurmOptions {
        partition: partition.map(str::to_string),
        account: None,
        time_limit: Some("10".into()),
        cpus_per_task: 1,
        max_tasks: None,
        spool,
        meniscus: std::env::var_os("MENISCUS_BIN")
            .map(PathBuf::from)
            .expect("MENISCUS_BIN names the meniscus binary (tools/slurm-test/run.sh sets it)"),
        poll: Duration::from_millis(300),
    }
}

fn on_slurm(dir: &Path) -> ValidateOptions {
    let cluster = Cluster::connect(options(None, dir.join("spool"))).expect("the test cluster answers");
    ValidateOptions { slurm: Some(Arc::new(cluster)), ..ValidateOptions::quick_in(dir) }
}

/// `results.json` of the drop without how each run ran (wall and CPU times, threads).
fn results(out: &Path) -> serde_json::Value {
    let text = std::fs::read_to_string(out.join("elliptical_drop/results.json")).expect("results.json");
    let mut v: serde_json::Value = serde_json::from_str(&text).expect("results JSON");
    for run in v["runs"].as_array_mut().expect("runs") {
        let run = run.as_object_mut().expect("run object");
        for how in ["wall_s", "cpu_s", "threads"] {
            run.remove(how);
        }
    }
    v
}

#[test]
#[ignore = "needs a Slurm cluster: tools/slurm-test/run.sh"]
fn the_quick_drop_sweep_on_slurm_matches_the_local_one() {
    let local = workspace("local", false);
    let here =
        validate(&ValidateOptions { jobs: 2, ..ValidateOptions::quick_in(&local) }).expect("local sweep");
    let cluster = workspace("cluster", false);
    let there = validate(&on_slurm(&cluster)).expect("sweep on slurm");
    assert_eq!((there.executed, there.reused), (here.executed, 0));
    assert!(here.executed >= 10, "the quick drop sweep has its runs: {}", here.executed);
    assert_eq!(results(&cluster.join("reports")), results(&local.join("reports")));
    let arrays = std::fs::read_dir(cluster.join("spool/arrays")).expect("the spool's arrays").count();
    assert_eq!(arrays, here.executed.div_ceil(8), "arrays of at most MaxArraySize = 8 tasks");
    let runs = &there.results[0].runs;
    assert!(runs.iter().all(|r| r.cpu_s.is_some_and(|c| c > 0.0)), "each task's CPU time is recorded");
}

#[test]
#[ignore = "needs a Slurm cluster: tools/slurm-test/run.sh"]
fn a_killed_task_is_reported_and_resubmitted_alone() {
    let dir = workspace("killed", true);
    let opts = on_slurm(&dir);
    let spool = dir.join("spool");
    let sweep = {
        let opts = opts.clone();
        std::thread::spawn(move || validate(&opts).expect("sweep on slurm"))
    };
    // The long run's directory is the one whose scene ends at 0.04 s; kill its task once it runs.
    let job = long_task_once_running(&spool);
    let status = std::process::Command::new("scancel").arg(&job).status().expect("scancel runs");
    assert!(status.success(), "scancel {job}");
    let first = sweep.join().expect("the sweep thread");
    let runs = &first.results[0].runs;
    let failed: Vec<_> = runs.iter().filter(|r| r.status.starts_with("failed")).collect();
    assert_eq!(failed.len(), 1, "{:?}", runs.iter().map(|r| &r.status).collect::<Vec<_>>());
    assert_eq!(failed[0].preset, "long");
    assert!(failed[0].status.contains("CANCELLED"), "{}", failed[0].status);
    let record = dir.join("reports/elliptical_drop/runs/isph-long_dx0.02.json");
    assert!(!record.exists(), "a failed task is not cached");
    assert!(!first.pass(), "a failed run fails its checks");

    let second = validate(&opts).expect("resumed sweep");
    assert_eq!(
        (second.executed, second.reused),
        (1, runs.len() - 1),
        "only the killed run is submitted again"
    );
    assert!(second.results[0].runs.iter().all(|r| !r.status.starts_with("failed")));
    assert!(record.exists());
}

/// `<job>_<task>` of the long run's task, waiting (two minutes at most) until it runs.
fn long_task_once_running(spool: &Path) -> String {
    let start = Instant::now();
    loop {
        assert!(start.elapsed() < Duration::from_secs(120), "the long run never started");
        if let Some(task) = running_long_task(spool) {
            return task;
        }
        std::thread::sleep(Duration::from_millis(100));
    }
}

/// `<job>_<task>` of the long run's task once its run started (its `out.partial/` exists).
fn running_long_task(spool: &Path) -> Option<String> {
    let arrays = std::fs::read_dir(spool.join("arrays")).ok()?;
    for array in arrays.flatten().map(|e| e.path()) {
        let Ok(job) = std::fs::read_to_string(array.join("job_id")) else { continue };
        let tasks = std::fs::read_to_string(array.join("tasks.txt")).ok()?;
        for (k, run) in tasks.lines().enumerate() {
            let scene = std::fs::read_to_string(Path::new(run).join("scene.json")).ok()?;
            let scene: serde_json::Value = serde_json::from_str(&scene).ok()?;
            if scene["time"]["end"] == serde_json::json!(0.04) && Path::new(run).join("out.partial").is_dir()
            {
                return Some(format!("{}_{k}", job.trim()));
            }
        }
    }
    None
}

#[test]
#[ignore = "needs a Slurm cluster: tools/slurm-test/run.sh"]
fn bad_partitions_and_spools_are_refused_before_submitting() {
    let dir = workspace("refused", false);
    let error = |partition: &str, spool: PathBuf| {
        Cluster::connect(options(Some(partition), spool)).expect_err("refused").to_string()
    };
    let e = error("nosuch", dir.join("spool"));
    assert!(e.contains("--partition") && e.contains("nosuch"), "{e}");
    // `remote` holds a node that is not this host (tools/slurm-test/slurm.conf).
    let local = std::env::temp_dir().join("meniscus-slurm-spool");
    let e = error("remote", local.clone());
    assert!(e.contains("--spool") && e.contains("node-local"), "{e}");
    // `short` allows one minute; the tests' tasks ask for ten.
    let e = error("short", dir.join("spool"));
    assert!(e.contains("--time-limit") && e.contains("`10`") && e.contains("MaxTime of 00:01:00"), "{e}");
    let ten = SlurmOptions { time_limit: Some("ten".into()), ..options(None, dir.join("spool")) };
    let e = Cluster::connect(ten).expect_err("refused").to_string();
    assert!(e.contains("--time-limit") && e.contains("`ten` is not a Slurm time"), "{e}");
    assert!(!dir.join("spool/arrays").exists() && !local.join("arrays").exists(), "nothing was submitted");
}

/// Restores partition `short`'s one-minute `MaxTime` when dropped (also on a failed assertion).
struct RestoreShort;

impl Drop for RestoreShort {
    fn drop(&mut self) {
        let _ = std::process::Command::new("scontrol")
            .args(["update", "PartitionName=short", "MaxTime=1"])
            .status();
    }
}

#[test]
#[ignore = "needs a Slurm cluster: tools/slurm-test/run.sh"]
fn tasks_that_would_never_start_are_cancelled_and_reported() {
    let dir = workspace("never", false);
    let opts = SlurmOptions { time_limit: Some("1".into()), ..options(Some("short"), dir.join("spool")) };
    let cluster = Cluster::connect(opts).expect("a one-minute limit fits partition `short`");
    // After the check, the partition's limit drops below the tasks' (an administrator's change).
    let _restore = RestoreShort;
    let status = std::process::Command::new("scontrol")
        .args(["update", "PartitionName=short", "MaxTime=0"])
        .status()
        .expect("scontrol runs");
    assert!(status.success(), "scontrol update PartitionName=short MaxTime=0");
    let start = Instant::now();
    let outcome =
        validate(&ValidateOptions { slurm: Some(Arc::new(cluster)), ..ValidateOptions::quick_in(&dir) })
            .expect("the sweep ends");
    assert!(start.elapsed() < Duration::from_secs(60), "the sweep did not wait on its tasks");
    let runs = &outcome.results[0].runs;
    assert!(!runs.is_empty());
    for run in runs {
        assert!(
            run.status.contains("does not clear by itself") && run.status.contains("PartitionTimeLimit"),
            "{}",
            run.status
        );
    }
    assert!(!outcome.pass(), "runs that never ran fail their checks");
    let queued = std::process::Command::new("squeue").args(["-h", "-p", "short"]).output().expect("squeue");
    assert!(
        queued.stdout.is_empty(),
        "the tasks were cancelled: {}",
        String::from_utf8_lossy(&queued.stdout)
    );
}

#[test]
#[ignore = "needs a Slurm cluster: tools/slurm-test/run.sh"]
fn a_killed_submitters_tasks_are_followed_not_submitted_again() {
    // The submitter to be killed: this test's binary again, running only the sweep.
    if let Some(dir) = std::env::var_os("MENISCUS_SLURM_SUBMITTER") {
        let _ = validate(&on_slurm(Path::new(&dir)));
        return;
    }
    let dir = workspace("adopted", true);
    let spool = dir.join("spool");
    let mut submitter = std::process::Command::new(std::env::current_exe().expect("the test binary"))
        .args(["--exact", "a_killed_submitters_tasks_are_followed_not_submitted_again", "--ignored"])
        .env("MENISCUS_SLURM_SUBMITTER", &dir)
        .stdout(std::process::Stdio::null())
        .spawn()
        .expect("the submitter starts");
    let long = long_task_once_running(&spool);
    submitter.kill().expect("SIGKILL the submitter");
    let _ = submitter.wait();
    let arrays = || std::fs::read_dir(spool.join("arrays")).expect("the spool's arrays").count();
    let submitted = arrays();
    let queued = |task: &str| {
        let out = std::process::Command::new("squeue").args(["-h", "-j", task]).output().expect("squeue");
        !out.stdout.is_empty()
    };
    assert!(queued(&long), "the long run's task {long} outlives its submitter");

    let outcome = validate(&on_slurm(&dir)).expect("the next sweep");
    assert_eq!(arrays(), submitted, "nothing was submitted again");
    let runs = &outcome.results[0].runs;
    assert!(
        runs.iter().all(|r| !r.status.starts_with("failed")),
        "{:?}",
        runs.iter().map(|r| &r.status).collect::<Vec<_>>()
    );
    assert!(
        dir.join("reports/elliptical_drop/runs/isph-long_dx0.02.json").exists(),
        "the long run was collected"
    );
}
