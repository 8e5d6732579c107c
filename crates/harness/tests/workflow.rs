//! Lints `.github/workflows/validate.yml` (issue #9): triggers, jobs, the commands, the
//! report upload and job summary on every outcome, and every action pinned.
//!
//! CI cannot fetch `actionlint`, so the structure the project relies on is asserted here.

use serde_json::Value;
use std::path::PathBuf;

fn repo_file(rel: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..").join(rel)
}

fn workflow_text() -> String {
    std::fs::read_to_string(repo_file(".github/workflows/validate.yml")).expect("validate.yml exists")
}

fn workflow() -> Value {
    serde_norway::from_str(&workflow_text()).expect("validate.yml is valid YAML")
}

/// Whether `uses:` names an action pinned to a full commit SHA or an exact `vX.Y.Z` tag.
fn is_pinned(uses: &str) -> bool {
    let Some((action, rev)) = uses.rsplit_once('@') else { return false };
    let sha = rev.len() == 40 && rev.bytes().all(|b| b.is_ascii_hexdigit());
    let exact = rev.strip_prefix('v').is_some_and(|v| {
        let parts: Vec<&str> = v.split('.').collect();
        parts.len() == 3 && parts.iter().all(|p| !p.is_empty() && p.bytes().all(|b| b.is_ascii_digit()))
    });
    action.contains('/') && (sha || exact)
}

/// Whether an `if:` condition is `always()` (with or without `${{ }}`).
fn is_always(cond: Option<&Value>) -> bool {
    let Some(c) = cond.and_then(Value::as_str) else { return false };
    let c = c.trim();
    let c = c.strip_prefix("${{").and_then(|c| c.strip_suffix("}}")).unwrap_or(c);
    c.trim() == "always()"
}

fn steps(job: &Value) -> &Vec<Value> {
    job["steps"].as_array().expect("a job has steps")
}

/// Index of the first step whose `run` contains `command` (as a whole line prefix).
fn step_running(job: &Value, command: &str) -> Option<usize> {
    steps(job).iter().position(|s| {
        s["run"].as_str().is_some_and(|r| {
            r.lines().any(|l| l.trim() == command || l.trim().starts_with(&format!("{command} ")))
        })
    })
}

fn uses(step: &Value) -> Option<&str> {
    step["uses"].as_str()
}

/// The job whose steps run `command`.
fn job_running<'a>(wf: &'a Value, command: &str) -> (&'a String, &'a Value) {
    wf["jobs"]
        .as_object()
        .expect("jobs")
        .iter()
        .find(|(_, j)| step_running(j, command).is_some())
        .unwrap_or_else(|| panic!("no job runs `{command}`"))
}

#[test]
fn pin_rule_accepts_shas_and_exact_versions_only() {
    assert!(is_pinned("actions/checkout@11bd71901bbe5b1630ceea73d27597364c9af683"));
    assert!(is_pinned("actions/checkout@v4.2.2"));
    assert!(!is_pinned("actions/checkout@v4"));
    assert!(!is_pinned("actions/checkout@main"));
    assert!(!is_pinned("dtolnay/rust-toolchain@stable"));
    assert!(!is_pinned("actions/checkout@11bd71901bbe5b1630ceea73d27597364c9af68"), "39 hex digits");
    assert!(!is_pinned("actions/checkout"));
    assert!(is_always(Some(&Value::from("always()"))));
    assert!(is_always(Some(&Value::from("${{ always() }}"))));
    assert!(!is_always(Some(&Value::from("success()"))));
    assert!(!is_always(None));
}

#[test]
fn triggers_are_push_pull_request_dispatch_and_weekly_schedule() {
    let wf = workflow();
    let on = wf["on"].as_object().expect("`on` is a mapping (YAML 1.2: not a boolean)");
    for t in ["push", "pull_request", "workflow_dispatch", "schedule"] {
        assert!(on.contains_key(t), "trigger {t} missing");
    }
    let crons = on["schedule"].as_array().expect("schedule is a list");
    assert_eq!(crons.len(), 1);
    let cron = crons[0]["cron"].as_str().expect("cron string");
    let fields: Vec<&str> = cron.split_whitespace().collect();
    assert_eq!(fields.len(), 5, "cron has five fields: {cron}");
    assert!(fields[2] == "*" && fields[3] == "*" && fields[4] != "*", "weekly: {cron}");
}

#[test]
fn quick_job_runs_the_readme_tests_then_the_quick_tier_and_always_publishes() {
    let wf = workflow();
    let readme = std::fs::read_to_string(repo_file("README.md")).unwrap();
    assert!(readme.contains("cargo test --workspace"), "README's test command");
    let (name, job) = job_running(&wf, "cargo xtask validate --quick");
    let cond = job["if"].as_str().unwrap_or_default();
    assert!(
        cond.contains("push") && cond.contains("pull_request"),
        "job {name} runs on push and PRs: {cond}"
    );
    assert!(!cond.contains("schedule"), "{cond}");
    let test = step_running(job, "cargo test --workspace").expect("the README's test command");
    let validate = step_running(job, "cargo xtask validate --quick").unwrap();
    assert!(test < validate);
    let s = steps(job);
    let names: Vec<Option<&str>> = s.iter().map(uses).collect();
    let pos = |prefix: &str| names.iter().position(|u| u.is_some_and(|u| u.starts_with(prefix)));
    let checkout = pos("actions/checkout@").expect("checkout");
    let toolchain = pos("dtolnay/rust-toolchain@").expect("toolchain");
    let cache = pos("Swatinem/rust-cache@").expect("cargo cache");
    assert!(checkout < toolchain && toolchain < cache && cache < test);
    let upload = pos("actions/upload-artifact@").expect("upload");
    assert!(upload > validate);
    assert!(is_always(s[upload].get("if")), "upload must run whatever the outcome");
    assert_eq!(s[upload]["with"]["name"], "reports-${{ github.sha }}");
    assert!(s[upload]["with"]["path"].as_str().unwrap().trim_end_matches('/') == "reports");
    // The job fails with the xtask's exit code: nothing may swallow it.
    for i in [test, validate] {
        assert!(s[i].get("continue-on-error").is_none_or(|v| v == false), "step {i} must fail the job");
        assert!(!s[i]["run"].as_str().unwrap().contains("|| true"));
    }
    let summary = s
        .iter()
        .position(|st| st["run"].as_str().is_some_and(|r| r.contains("$GITHUB_STEP_SUMMARY")))
        .expect("job summary step");
    assert!(s[summary]["run"].as_str().unwrap().contains("reports/summary.md"));
    assert!(is_always(s[summary].get("if")));
}

#[test]
fn scheduled_job_runs_the_default_tier_and_the_benchmark() {
    let wf = workflow();
    let (name, job) = job_running(&wf, "cargo xtask bench");
    let cond = job["if"].as_str().unwrap_or_default();
    assert!(cond.contains("workflow_dispatch") && cond.contains("schedule"), "job {name}: {cond}");
    assert!(!cond.contains("push"), "{cond}");
    let s = steps(job);
    let validate = s
        .iter()
        .position(|st| st["run"].as_str().is_some_and(|r| r.trim().starts_with("cargo xtask validate")))
        .expect("default validation");
    let cmd = s[validate]["run"].as_str().unwrap();
    assert!(!cmd.contains("--quick") && !cmd.contains("--full"), "default tier: {cmd}");
    let uploads: Vec<&Value> =
        s.iter().filter(|st| uses(st).is_some_and(|u| u.starts_with("actions/upload-artifact@"))).collect();
    assert!(!uploads.is_empty());
    for u in uploads {
        assert!(is_always(u.get("if")));
        assert!(u["with"]["name"].as_str().unwrap().contains("${{ github.sha }}"));
        // reports/ holds both the validation report and reports/work_precision/.
        assert_eq!(u["with"]["path"].as_str().unwrap().trim_end_matches('/'), "reports");
    }
}

#[test]
fn every_action_is_pinned_with_a_version_comment() {
    let wf = workflow();
    let mut count = 0;
    for (name, job) in wf["jobs"].as_object().unwrap() {
        for st in steps(job) {
            if let Some(u) = uses(st) {
                count += 1;
                assert!(is_pinned(u), "job {name}: `{u}` is not pinned to a SHA or an exact version");
            }
        }
    }
    assert!(count >= 8, "two jobs with checkout, toolchain, cache and upload each: {count}");
    // Comments are not in the parsed YAML: check the text for `@<sha> # v...`.
    for line in
        workflow_text().lines().filter(|l| l.trim_start().starts_with("uses:") || l.contains("- uses:"))
    {
        let rev = line.split('@').nth(1).unwrap_or_default();
        let sha = rev.split_whitespace().next().unwrap_or_default();
        if sha.len() == 40 {
            assert!(line.contains("# v"), "SHA without a version comment: {line}");
        }
    }
}
