//! A deliberately broken case fails `cargo xtask validate`'s library call with a message
//! naming the check (issue #34): a misspelt preset in a check, a metric removed from a
//! run, a NaN injected late in a series.

use meniscus_harness::{Case, ValidateOptions, validate};
use std::path::{Path, PathBuf};

/// The tiny drop (dx = 0.1, 20 steps, the paper preset only) with one check of ours,
/// written to a fresh `dir/validation/tiny.json`.
fn tiny(name: &str, edit: impl FnOnce(&mut serde_json::Value)) -> (PathBuf, ValidateOptions) {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("broken_cases").join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(dir.join("validation")).expect("scratch directory");
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let case = Case::load(&root.join("validation/elliptical_drop.json")).expect("case");
    let mut v = serde_json::to_value(&case).expect("case JSON");
    v["case"] = "tiny".into();
    v["scene"]["time"]["end"] = serde_json::json!(4e-4);
    v["scene"]["output"]["probe_every"] = serde_json::json!(5);
    v["sweep"]["dx"] = serde_json::json!({"quick": [0.1]});
    v["sweep"]["presets"] = serde_json::json!([v["sweep"]["presets"][0].clone()]);
    v["checks"] = serde_json::json!([
        {"name": "the b check", "metric": "b_rel_err_max", "select": {"preset": "paper"}, "max": 0.5},
        {"name": "the pressure check", "metric": "pc_rel_err_late", "select": {"preset": "paper"}, "max": 10.0}
    ]);
    edit(&mut v);
    std::fs::write(dir.join("validation/tiny.json"), v.to_string()).expect("write case");
    let opts = ValidateOptions::quick_in(&dir);
    (dir, opts)
}

/// The failed checks of the one case, with their notes.
fn failed(opts: &ValidateOptions) -> Vec<(String, String)> {
    let out = validate(opts).expect("the validation runs");
    assert!(!out.pass(), "a broken case must fail the validation");
    out.results[0]
        .checks
        .iter()
        .filter(|c| !c.pass)
        .map(|c| (c.name.clone(), c.note.clone().unwrap_or_default()))
        .collect()
}

#[test]
fn the_intact_tiny_case_passes() {
    let (_, opts) = tiny("intact", |_| {});
    assert!(validate(&opts).expect("runs").pass());
}

#[test]
fn a_misspelt_preset_in_a_check_is_an_error_naming_it() {
    let (_, opts) = tiny("misspelt", |v| v["checks"][0]["select"]["preset"] = "papr".into());
    let e = validate(&opts).expect_err("the case file is rejected").to_string();
    assert!(e.contains("the b check") && e.contains("\"papr\""), "{e}");
}

#[test]
fn a_metric_removed_from_the_run_fails_its_check() {
    // Without the pressure probe the run has no centre-pressure metric.
    let (_, opts) = tiny("no_metric", |v| {
        let probes = v["scene"]["probes"].as_array_mut().expect("probes");
        probes.retain(|p| p.get("pressure_at").is_none());
    });
    let failed = failed(&opts);
    assert_eq!(failed.len(), 1, "{failed:?}");
    assert_eq!(failed[0].0, "the pressure check");
    assert!(failed[0].1.contains("pc_rel_err_late") && failed[0].1.contains("missing"), "{failed:?}");
}

#[test]
fn a_nan_late_in_a_series_fails_its_check() {
    let (dir, opts) = tiny("late_nan", |_| {});
    assert!(validate(&opts).expect("runs").pass());
    // One NaN in the b semi-axis, at the second-to-last sample of the cached run.
    let record = dir.join("reports/tiny/runs/isph-paper_dx0.1.json");
    let mut v: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&record).unwrap()).unwrap();
    let b = v["probes"]["ellipse_axes"]["b_moment"].as_array_mut().expect("b series");
    let k = b.len() - 2;
    b[k] = serde_json::Value::Null;
    std::fs::write(&record, v.to_string()).unwrap();
    let failed = failed(&opts);
    assert_eq!(failed.len(), 1, "{failed:?}");
    assert_eq!(failed[0].0, "the b check");
    assert!(failed[0].1.contains("b_rel_err_max") && failed[0].1.contains("not finite"), "{failed:?}");
}
