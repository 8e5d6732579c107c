//! The regression view on two fixture result sets (`tests/fixtures/baseline/{base,new}`):
//! the marks per metric, wall-time ratios, status and check changes, and their rendering
//! in `summary.md` and the HTML pages.

use meniscus_harness::baseline::{self, CaseComparison, Mark, NoiseBand, RunComparison, Speed};
use meniscus_harness::report::{self, Baseline, RenderOptions};
use std::path::{Path, PathBuf};

fn fixtures() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/baseline")
}

fn comparison() -> CaseComparison {
    let new = baseline::load(&fixtures().join("new"), None).unwrap();
    let old = baseline::load(&fixtures().join("base"), None).unwrap();
    let cmp = baseline::compare(&fixtures().join("base"), &new, &old, NoiseBand::default());
    assert_eq!(cmp.cases.len(), 1);
    cmp.cases.into_iter().next().unwrap()
}

fn run<'a>(c: &'a CaseComparison, slug: &str) -> &'a RunComparison {
    c.runs.iter().find(|r| r.slug == slug).unwrap_or_else(|| panic!("run {slug} not matched"))
}

fn mark(r: &RunComparison, metric: &str) -> Mark {
    r.metrics.iter().find(|m| m.name == metric).unwrap_or_else(|| panic!("{metric}")).mark
}

#[test]
fn runs_are_matched_by_scheme_preset_and_dx() {
    let c = comparison();
    assert!(c.in_baseline);
    let slugs: Vec<&str> = c.runs.iter().map(|r| r.slug.as_str()).collect();
    assert_eq!(slugs, ["isph-paper_dx0.04", "isph-paper_dx0.02", "isph-tuned_dx0.04"]);
    assert_eq!(c.added_runs, ["isph-tuned_dx0.02"]);
    assert_eq!(c.removed_runs, ["isph-paper_dx0.01"]);
}

#[test]
fn error_metrics_are_marked_better_worse_or_unchanged() {
    let c = comparison();
    let coarse = run(&c, "isph-paper_dx0.04");
    assert_eq!(mark(coarse, "b_rel_err_max"), Mark::Worse, "0.016 -> 0.020 (+25 %)");
    assert_eq!(mark(coarse, "pc_rel_err_final"), Mark::Better, "0.04 -> 0.03 (-25 %)");
    assert_eq!(mark(coarse, "a_rel_err_max"), Mark::Unchanged, "+0.8 % is inside the 5 % band");
    assert_eq!(mark(coarse, "particles"), Mark::Unchanged);
    let fine = run(&c, "isph-paper_dx0.02");
    assert_eq!(mark(fine, "ke_drift"), Mark::Unchanged, "+2 % drift is noise");
    assert_eq!(mark(fine, "b_rel_err_max"), Mark::Unchanged);
    // A diverged baseline run that now completes: its status and its null error get better;
    // the final time has no direction and is only marked changed.
    let tuned = run(&c, "isph-tuned_dx0.04");
    assert_eq!(tuned.status, Mark::Better);
    assert_eq!(mark(tuned, "b_rel_err_max"), Mark::Better);
    assert_eq!(mark(tuned, "t_final"), Mark::Changed);
    // Observed orders are shown without a direction.
    assert_eq!(c.orders.len(), 1);
    assert_eq!((c.orders[0].name.as_str(), c.orders[0].mark), ("b_rel_err_max", Mark::Changed));
}

#[test]
fn wall_time_ratio_is_flagged_beyond_25_percent_only() {
    let c = comparison();
    let coarse = run(&c, "isph-paper_dx0.04").wall;
    assert!((coarse.ratio - 1.10).abs() < 1e-9, "{}", coarse.ratio);
    assert_eq!(coarse.flag, None, "10 % slower is not flagged");
    let fine = run(&c, "isph-paper_dx0.02").wall;
    assert!((fine.ratio - 1.30).abs() < 1e-9, "{}", fine.ratio);
    assert_eq!(fine.flag, Some(Speed::Slower), "30 % slower is flagged");
    assert_eq!(run(&c, "isph-tuned_dx0.04").wall.flag, Some(Speed::Slower), "x2.75 (it now runs to the end)");
}

#[test]
fn flipped_checks_are_reported() {
    let c = comparison();
    let labels: Vec<(&str, String)> = c.checks.iter().map(|k| (k.name.as_str(), k.label())).collect();
    assert_eq!(
        labels,
        [
            ("b error at dx=0.04 <= 1.8% (paper)", "newly failing".to_string()),
            ("tuned b error <= 1%", "newly passing".to_string()),
        ]
    );
    let t = c.tally();
    assert_eq!((t.newly_failing, t.newly_passing), (1, 1));
    assert_eq!((t.slower, t.faster), (2, 0));
    assert_eq!(t.worse, 1);
    assert_eq!(t.better, 3, "pc error, tuned status, tuned b error");
    assert!(t.regressed());
}

#[test]
fn marks_appear_in_summary_md_and_html() {
    let out = std::env::temp_dir().join(format!("meniscus-baseline-render-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&out);
    let case_dir = out.join("elliptical_drop");
    std::fs::create_dir_all(&case_dir).unwrap();
    std::fs::copy(fixtures().join("new/elliptical_drop/results.json"), case_dir.join("results.json"))
        .unwrap();
    // A stale case left from an older run is not rendered when the case list is given.
    std::fs::create_dir_all(out.join("old_case")).unwrap();
    std::fs::write(out.join("old_case/results.json"), "not even JSON").unwrap();
    let cases = vec!["elliptical_drop".to_string()];
    let base = Baseline::load(&fixtures().join("base"), Some(&cases)).unwrap();
    let rendered = report::render(
        &out,
        &RenderOptions { cases: Some(cases), baseline: Some(base), extras: Vec::new(), elapsed_s: None },
    )
    .unwrap();
    assert_eq!(rendered.results.len(), 1);
    assert!(rendered.comparison.unwrap().tally().regressed());

    let md = std::fs::read_to_string(out.join("summary.md")).unwrap();
    for needle in [
        "| elliptical_drop | isph | quick | 0.04, 0.02 |",
        "## Failed checks",
        "- `elliptical_drop`: b error at dx=0.04 <= 1.8% (paper): FAIL, value 0.02000",
        "## Compared with baseline",
        "more than 5 % of its baseline value",
        "| isph-paper_dx0.04 | `b_rel_err_max` | 1.60 % | 2.00 % | +25.0 % | **worse** |",
        "| isph-paper_dx0.04 | `pc_rel_err_final` | 4.00 % | 3.00 % | -25.0 % | **better** |",
        "| isph-paper_dx0.04 | ok | 1.20 | 1.32 | ×1.10 |",
        "| isph-paper_dx0.02 | ok | 6.50 | 8.45 | **×1.30 (slower)** |",
        "check b error at dx=0.04 <= 1.8% (paper): **newly failing**",
        "Runs not in the baseline: isph-tuned_dx0.02.",
        "| observed order | `b_rel_err_max` | 2.00 | 1.50 | -25.0 % | changed |",
    ] {
        assert!(md.contains(needle), "summary.md lacks {needle:?}:\n{md}");
    }
    assert!(!md.contains("a_rel_err_max` |"), "unchanged metrics are only counted:\n{md}");
    assert!(!md.contains("old_case"));

    let page = std::fs::read_to_string(case_dir.join("index.html")).unwrap();
    for needle in
        ["Compared with baseline", "class=\"worse\"", "class=\"better\"", "×1.30 (slower)", "newly failing"]
    {
        assert!(page.contains(needle), "case page lacks {needle:?}");
    }
    let index = std::fs::read_to_string(out.join("index.html")).unwrap();
    assert!(index.contains("vs baseline") && index.contains("1 worse, 3 better"), "{index}");
    assert!(!index.contains("old_case"));
    let _ = std::fs::remove_dir_all(&out);
}

#[test]
fn a_directory_without_results_is_not_a_baseline() {
    assert!(baseline::load(&fixtures().join("nowhere"), None).is_err());
}
