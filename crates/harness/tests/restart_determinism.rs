//! An interrupted and restarted sweep gives the same `results.json` as an uninterrupted
//! one, bit for bit apart from how each run ran (its wall and CPU times, its threads): runs re-executed after a deleted or truncated
//! cache record reproduce the cached ones exactly.

use meniscus_harness::{Case, Tier, ValidateOptions, validate};
use std::path::{Path, PathBuf};

fn scratch() -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("restart_determinism");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(dir.join("validation")).expect("scratch directory");
    dir
}

/// `results.json` of the case with every run's `wall_s`, `cpu_s` and `threads` removed.
fn results_without_wall_times(out: &Path) -> String {
    let text = std::fs::read_to_string(out.join("restart_drop/results.json")).expect("results.json");
    let mut v: serde_json::Value = serde_json::from_str(&text).expect("results JSON");
    for run in v["runs"].as_array_mut().expect("runs") {
        let run = run.as_object_mut().expect("run object");
        for how in ["wall_s", "cpu_s", "threads"] {
            run.remove(how);
        }
    }
    serde_json::to_string_pretty(&v).expect("serialisable")
}

#[test]
fn restarted_sweep_reproduces_results_bit_for_bit() {
    let dir = scratch();
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let mut case = Case::load(&root.join("validation/elliptical_drop.json")).expect("case");
    // Two tiny runs (both presets at dx = 0.1, 20 steps).
    case.case = "restart_drop".into();
    case.scene["time"]["end"] = serde_json::json!(4e-4);
    case.scene["output"]["probe_every"] = serde_json::json!(5);
    case.sweep.dx = [(Tier::Quick, vec![0.1])].into();
    // The two ISPH presets (the file also has the WCSPH ones).
    case.sweep.presets.truncate(2);
    assert_eq!(case.sweep.presets.len(), 2);
    // The checks of what the tiny case still runs (a selector naming a preset or spacing it
    // no longer has is rejected when the case loads).
    let kept = ["paper", "tuned"];
    case.checks
        .retain(|c| c.select.preset.as_deref().is_none_or(|p| kept.contains(&p)) && c.select.dx.is_none());
    std::fs::write(
        dir.join("validation/restart_drop.json"),
        serde_json::to_string_pretty(&case).expect("case JSON"),
    )
    .expect("write case");
    let opts = ValidateOptions::quick_in(&dir);
    let first = validate(&opts).expect("first sweep");
    assert_eq!((first.executed, first.reused), (2, 0));
    assert!(first.results[0].runs.iter().all(|r| r.ok()), "both runs finish");
    let reference = results_without_wall_times(&opts.out);
    let runs = opts.out.join("restart_drop/runs");

    // Interrupted before the second run was stored: its record is missing.
    std::fs::remove_file(runs.join("isph-tuned_dx0.1.json")).expect("cached run");
    let second = validate(&opts).expect("restarted sweep");
    assert_eq!((second.executed, second.reused), (1, 1));
    assert_eq!(results_without_wall_times(&opts.out), reference, "deleted record: results differ");

    // Interrupted while writing a record (a torn file).
    std::fs::write(runs.join("isph-paper_dx0.1.json"), "{\"completed\": tr").expect("truncate");
    let third = validate(&opts).expect("restarted sweep");
    assert_eq!((third.executed, third.reused), (1, 1));
    assert_eq!(results_without_wall_times(&opts.out), reference, "torn record: results differ");

    // Everything rerun, two runs at a time.
    let forced = validate(&ValidateOptions { force: true, jobs: 2, ..opts.clone() }).expect("forced sweep");
    assert_eq!(forced.executed, 2);
    assert_eq!(results_without_wall_times(&opts.out), reference, "forced rerun: results differ");
}
