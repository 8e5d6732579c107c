//! The results files (DESIGN.md "Results files"): `reports/<case>/results.json`,
//! `reports/summary.json`, and where they are found.

use serde::{Deserialize, Deserializer, Serialize};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// One run of the sweep, as it appears in `results.json`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RunResult {
    /// Scheme of the run (`isph`).
    pub scheme: String,
    /// Preset (option set) name.
    pub preset: String,
    /// Particle spacing \[m\].
    pub dx: f64,
    /// The jitter seed of a perturbed start (`sweep.presets[].perturbed_starts`); absent
    /// for the unperturbed run.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub start: Option<u64>,
    /// Number of particles.
    pub particles: usize,
    /// Steps taken.
    pub steps: usize,
    /// Wall time of the run \[s\].
    pub wall_s: f64,
    /// CPU time of the threads that ran it \[s\] (absent when not measured).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cpu_s: Option<f64>,
    /// Threads it ran on (absent when not recorded).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub threads: Option<usize>,
    /// When the steady-state stop (`time.steady`) ended the run before its end time: the
    /// time \[s\] (absent otherwise).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub steady_at: Option<f64>,
    /// `ok` or `diverged: <cause at step/time>`.
    pub status: String,
    /// Scalar metrics (non-finite values are written as `null`).
    #[serde(deserialize_with = "nan_map")]
    pub metrics: BTreeMap<String, f64>,
    /// Series for plots, each aligned with `series.t`.
    #[serde(deserialize_with = "nan_series")]
    pub series: BTreeMap<String, Vec<f64>>,
}

impl RunResult {
    /// Whether the run reached its end time.
    pub fn ok(&self) -> bool {
        self.status == "ok"
    }

    /// The stable run slug, e.g. `isph-paper_dx0.02` (`isph-long_dx0.02_start3` for a
    /// perturbed start).
    pub fn slug(&self) -> String {
        start_slug(&slug(&self.scheme, &self.preset, self.dx), self.start)
    }

    /// A metric, falling back to the run's own numeric fields (`particles`, `steps`,
    /// `wall_s`, `cpu_s`); `None` when absent.
    pub fn metric(&self, name: &str) -> Option<f64> {
        self.metrics.get(name).copied().or(match name {
            "particles" => Some(self.particles as f64),
            "steps" => Some(self.steps as f64),
            "wall_s" => Some(self.wall_s),
            "cpu_s" => self.cpu_s,
            _ => None,
        })
    }

    /// Particle-steps per wall second (none before a step was taken).
    pub fn particle_steps_per_s(&self) -> Option<f64> {
        (self.wall_s > 0.0 && self.steps > 0).then(|| (self.particles * self.steps) as f64 / self.wall_s)
    }

    /// CPU cost of one particle-step \[core-µs\]: `cpu_s / (particles × steps)` (none
    /// without a CPU time or a step).
    pub fn core_us_per_particle_step(&self) -> Option<f64> {
        core_us_per_particle_step(self.cpu_s, (self.particles * self.steps) as f64)
    }

    /// [`RunResult::core_us_per_particle_step`] over [`FLOOR_CORE_US_PER_PARTICLE_PASS`].
    pub fn floor_ratio(&self) -> Option<f64> {
        self.core_us_per_particle_step().map(|c| c / FLOOR_CORE_US_PER_PARTICLE_PASS)
    }
}

/// The performance floor of NUMERICS.md as a CPU cost: one fused pair pass over the drop
/// at Δx = 0.02 (7860 particles, 24 pairs each, ≈ 2.2 ns per pair) takes 0.42 ms on two
/// threads, 0.107 core-µs per particle. A run's cost per particle-step over it is the
/// number of such passes its step is worth.
pub const FLOOR_CORE_US_PER_PARTICLE_PASS: f64 = 420.0 * 2.0 / 7860.0;

/// CPU cost of one particle-step \[core-µs\]: `cpu_s / particle_steps` (none without a CPU
/// time or any particle-step).
pub fn core_us_per_particle_step(cpu_s: Option<f64>, particle_steps: f64) -> Option<f64> {
    cpu_s.filter(|_| particle_steps > 0.0).map(|cpu| cpu / particle_steps * 1e6)
}

/// Summed times of a set of runs.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Totals {
    /// Runs.
    pub runs: usize,
    /// Summed wall times \[s\].
    pub wall_s: f64,
    /// Summed CPU times of the runs that measured one \[s\].
    pub cpu_s: f64,
    /// Runs without a CPU time (run before it was measured, or off Linux).
    pub without_cpu: usize,
    /// Summed particles × steps.
    pub particle_steps: f64,
}

impl Totals {
    /// The totals of `runs`.
    pub fn of<'a>(runs: impl IntoIterator<Item = &'a RunResult>) -> Self {
        runs.into_iter().fold(Totals::default(), |mut t, r| {
            t.runs += 1;
            t.wall_s += r.wall_s;
            match r.cpu_s {
                Some(c) => t.cpu_s += c,
                None => t.without_cpu += 1,
            }
            t.particle_steps += (r.particles * r.steps) as f64;
            t
        })
    }

    /// Summed CPU time \[s\] when at least one run measured one (none otherwise).
    pub fn measured_cpu_s(&self) -> Option<f64> {
        (self.runs > self.without_cpu).then_some(self.cpu_s)
    }

    /// CPU cost of one particle-step \[core-µs\] (none without CPU times or steps).
    pub fn core_us_per_particle_step(&self) -> Option<f64> {
        if self.without_cpu > 0 {
            return None;
        }
        core_us_per_particle_step(Some(self.cpu_s), self.particle_steps)
    }
}

/// The stable slug of a run: `<scheme>-<preset>_dx<dx>` (dx in shortest decimal form).
pub fn slug(scheme: &str, preset: &str, dx: f64) -> String {
    format!("{scheme}-{preset}_dx{dx}")
}

/// The slug of a perturbed start of the run `slug`: `<slug>_start<seed>`.
pub fn start_slug(slug: &str, start: Option<u64>) -> String {
    match start {
        Some(seed) => format!("{slug}_start{seed}"),
        None => slug.to_string(),
    }
}

/// Observed order of one metric.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Convergence {
    /// Observed order of the primary preset (least squares in log-log).
    pub order: f64,
    /// The preset the order belongs to.
    pub preset: String,
    /// Spacings used \[m\].
    pub dx: Vec<f64>,
    /// The metric at those spacings (the mean over a preset's perturbed starts).
    pub values: Vec<f64>,
    /// Orders of every preset with at least two spacings.
    #[serde(default)]
    pub by_preset: BTreeMap<String, f64>,
}

/// `reports/<case>/results.json`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CaseResults {
    /// Case name.
    pub case: String,
    /// Default scheme of the case.
    pub scheme: String,
    /// Tier run.
    pub tier: String,
    /// Every run of the sweep (diverged ones included).
    pub runs: Vec<RunResult>,
    /// Observed orders, per metric.
    pub convergence: BTreeMap<String, Convergence>,
    /// Acceptance checks.
    pub checks: Vec<CheckResult>,
}

impl CaseResults {
    /// Number of passed and failed checks.
    pub fn counts(&self) -> (usize, usize) {
        check_counts(&self.checks)
    }

    /// Whether every check passed.
    pub fn pass(&self) -> bool {
        check_counts(&self.checks).1 == 0
    }
}

/// Passed checks and unexpected results (failures, and passes of expected failures) among
/// `checks`; expected failures count in neither ([`expected_failures`]).
pub fn check_counts(checks: &[CheckResult]) -> (usize, usize) {
    let count = |v: Verdict| checks.iter().filter(|c| c.verdict() == v).count();
    (count(Verdict::Pass), count(Verdict::Fail) + count(Verdict::UnexpectedPass))
}

/// Checks among `checks` that failed as expected.
pub fn expected_failures(checks: &[CheckResult]) -> usize {
    checks.iter().filter(|c| c.verdict() == Verdict::ExpectedFail).count()
}

/// A check's outcome against what its case file expects.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Verdict {
    /// Passed, as expected.
    Pass,
    /// Failed, unexpectedly: fails the validation.
    Fail,
    /// Failed, as its case file expects (`expected_failure`, with the reason).
    ExpectedFail,
    /// Passed although expected to fail: fails the validation (the case file is out of date
    /// or the scheme changed; strict, as pytest's `xfail(strict=True)`).
    UnexpectedPass,
}

impl Verdict {
    /// Whether the outcome is the expected one (the exit code counts the others).
    pub fn expected(self) -> bool {
        matches!(self, Verdict::Pass | Verdict::ExpectedFail)
    }

    /// The label the reports show.
    pub fn label(self) -> &'static str {
        match self {
            Verdict::Pass => "pass",
            Verdict::Fail => "FAIL",
            Verdict::ExpectedFail => "expected fail",
            Verdict::UnexpectedPass => "UNEXPECTED PASS",
        }
    }
}

/// One case in `reports/summary.json`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CaseSummary {
    /// Case name.
    pub case: String,
    /// Default scheme.
    pub scheme: String,
    /// Tier run.
    pub tier: String,
    /// Number of runs.
    pub runs: usize,
    /// Runs that diverged.
    pub diverged: usize,
    /// Checks passed.
    pub passed: usize,
    /// Unexpected check results (failures, passes of expected failures).
    pub failed: usize,
    /// Checks that failed as the case file expects.
    #[serde(default)]
    pub expected_failures: usize,
    /// Whether every check had its expected outcome.
    pub pass: bool,
    /// Sum of the runs' wall times \[s\].
    pub wall_s: f64,
    /// Sum of the runs' CPU times \[s\] (the runs that measured one).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cpu_s: Option<f64>,
    /// Sum over the runs of particles × steps.
    #[serde(default)]
    pub particle_steps: u64,
}

impl CaseSummary {
    /// Summarises one case's results.
    pub fn of(results: &CaseResults) -> Self {
        let (passed, failed) = results.counts();
        let t = Totals::of(&results.runs);
        CaseSummary {
            case: results.case.clone(),
            scheme: results.scheme.clone(),
            tier: results.tier.clone(),
            runs: results.runs.len(),
            diverged: results.runs.iter().filter(|r| !r.ok()).count(),
            passed,
            failed,
            expected_failures: expected_failures(&results.checks),
            pass: failed == 0,
            wall_s: t.wall_s,
            cpu_s: t.measured_cpu_s(),
            particle_steps: t.particle_steps as u64,
        }
    }
}

/// `reports/summary.json`: every case with its pass/fail counts.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Summary {
    /// Whether every check of every case passed.
    pub pass: bool,
    /// Checks passed over all cases.
    pub passed: usize,
    /// Unexpected check results over all cases.
    pub failed: usize,
    /// Expected failures over all cases.
    #[serde(default)]
    pub expected_failures: usize,
    /// One entry per case, sorted by name.
    pub cases: Vec<CaseSummary>,
    /// Wall time of the last invocation that ran runs \[s\], when known.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub elapsed_s: Option<f64>,
}

impl Summary {
    /// The summary of the cases' results (`reports/summary.json`).
    pub fn of(results: &[CaseResults]) -> Self {
        Summary::new(results.iter().map(CaseSummary::of).collect())
    }

    /// Builds the summary from per-case summaries (sorted by case name).
    pub fn new(mut cases: Vec<CaseSummary>) -> Self {
        cases.sort_by(|a, b| a.case.cmp(&b.case));
        cases.dedup_by(|a, b| a.case == b.case);
        let passed = cases.iter().map(|c| c.passed).sum();
        let failed = cases.iter().map(|c| c.failed).sum();
        let expected_failures = cases.iter().map(|c| c.expected_failures).sum();
        Summary {
            pass: cases.iter().all(|c| c.pass),
            passed,
            failed,
            expected_failures,
            cases,
            elapsed_s: None,
        }
    }
}

/// Kinds of check.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum CheckKind {
    /// Every selected run has `metric <= max`.
    Max,
    /// Every selected run has `metric >= min`.
    Min,
    /// Every selected run has `|metric - value| <= tolerance` (default 0: exact).
    Equals,
    /// The metric strictly decreases as dx decreases (per scheme and preset); the value is
    /// the largest ratio `e(finer)/e(coarser)`, which must be below 1.
    Decreasing,
    /// The observed order in dx (least squares in log-log) is at least `min`.
    Order,
    /// A quantity that has no reference value settles: its relative change between the two
    /// finest spacings (per scheme and preset), `|m(finest) − m(next)| / |m(next)|`, is at
    /// most `max`.
    FinestChange,
}

/// Which runs a check applies to (all fields optional; absent = any).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Selector {
    /// Spacing (matched to 1e-9 relative).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub dx: Option<f64>,
    /// Preset name.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub preset: Option<String>,
    /// Scheme name.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub scheme: Option<String>,
    /// Study of a study's row (`dt_max`, ...): a case's runs have none.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub study: Option<String>,
    /// Case of a study's row: a case's runs have none.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub case: Option<String>,
}

/// What a check judges, recorded in its result (`checks[].judges` of `results.json`) so a
/// report can tell which values a check judges and write them in the metric's units.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Judged {
    /// The metric.
    pub metric: String,
    /// The kind of check.
    pub kind: CheckKind,
    /// The runs it selects.
    #[serde(default)]
    pub select: Selector,
}

/// A check's outcome, as written to `results.json`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CheckResult {
    /// Check name.
    pub name: String,
    /// Measured value (worst over the selected runs); `null` when it could not be measured.
    pub value: Option<f64>,
    /// The bound it is compared with (`decreasing`: 1, the largest allowed ratio).
    pub threshold: Option<f64>,
    /// Whether it passed.
    pub pass: bool,
    /// Why it failed when not because of the value (diverged run, missing metric), and the
    /// spread of a bound over perturbed starts.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub note: Option<String>,
    /// Why the case file expects it to fail (the scheme's documented shortfall), if it does.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub expected_failure: Option<String>,
    /// What the check judges (its metric, kind and selector); absent for checks that judge
    /// no metric (a run's completion) and in results written before it was recorded.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub judges: Option<Judged>,
}

impl CheckResult {
    /// The outcome against the expectation.
    pub fn verdict(&self) -> Verdict {
        match (self.pass, self.expected_failure.is_some()) {
            (true, false) => Verdict::Pass,
            (false, false) => Verdict::Fail,
            (false, true) => Verdict::ExpectedFail,
            (true, true) => Verdict::UnexpectedPass,
        }
    }
}

/// The case directories `<out>/<case>` that hold a `results.json`, sorted by name; only
/// those named in `cases` when given (other directories, e.g. a stale case or
/// `work_precision/`, are left out).
pub fn case_dirs(out: &Path, cases: Option<&[String]>) -> Vec<PathBuf> {
    let Ok(rd) = std::fs::read_dir(out) else { return Vec::new() };
    let wanted = |p: &Path| {
        cases.is_none_or(|names| p.file_name().is_some_and(|n| names.iter().any(|c| n == c.as_str())))
    };
    let mut dirs: Vec<PathBuf> = rd
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| wanted(p) && p.join("results.json").is_file())
        .collect();
    dirs.sort();
    dirs
}

fn nan_map<'de, D: Deserializer<'de>>(d: D) -> Result<BTreeMap<String, f64>, D::Error> {
    let m: BTreeMap<String, Option<f64>> = Deserialize::deserialize(d)?;
    Ok(m.into_iter().map(|(k, v)| (k, v.unwrap_or(f64::NAN))).collect())
}

fn nan_series<'de, D: Deserializer<'de>>(d: D) -> Result<BTreeMap<String, Vec<f64>>, D::Error> {
    let m: BTreeMap<String, Vec<Option<f64>>> = Deserialize::deserialize(d)?;
    Ok(m.into_iter().map(|(k, v)| (k, v.into_iter().map(|x| x.unwrap_or(f64::NAN)).collect())).collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn slug_is_stable() {
        assert_eq!(slug("isph", "paper", 0.02), "isph-paper_dx0.02");
        assert_eq!(slug("isph", "tuned", 0.005), "isph-tuned_dx0.005");
    }

    #[test]
    fn non_finite_values_round_trip_as_null() {
        let run = RunResult {
            scheme: "isph".into(),
            preset: "paper".into(),
            dx: 0.04,
            start: None,
            particles: 10,
            steps: 3,
            wall_s: 0.1,
            cpu_s: None,
            threads: None,
            steady_at: None,
            status: "diverged: x".into(),
            metrics: [("a".to_string(), f64::NAN)].into(),
            series: [("t".to_string(), vec![0.0, f64::INFINITY])].into(),
        };
        let text = serde_json::to_string(&run).unwrap();
        assert!(text.contains("\"a\":null"), "{text}");
        let back: RunResult = serde_json::from_str(&text).unwrap();
        assert!(back.metrics["a"].is_nan() && back.series["t"][1].is_nan());
        assert!(!back.ok());
        assert_eq!(back.metric("particles"), Some(10.0));
        assert_eq!(back.metric("nope"), None);
    }
}
