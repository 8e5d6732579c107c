//! Regression view: the new results of each case compared with a previous `reports/`
//! directory (the *baseline*), per run, metric, wall time, observed order and check.
//!
//! Everything here but [`load`] is a pure function over [`CaseResults`].
//!
//! Rules (stated on every page that shows a comparison, see [`NoiseBand::describe`]):
//! - Runs are matched by (scheme, preset, dx, perturbed start); dx to 1e-9 relative.
//! - A metric *changed* when its change is beyond the noise band: relative change above
//!   5 % of the baseline value **and** absolute change above 1e-6.
//! - Direction: lower is better for error metrics (the name contains `err`) and drifts
//!   (the name contains `drift`, a conservation error); a changed one is marked *better* or
//!   *worse*. Every other metric (particle counts, final time, ...) and the observed orders
//!   are marked *changed* without a direction.
//! - A value that turns non-finite (diverged run) is worse; one that turns finite is better.
//! - Wall time is shown as the ratio new / baseline and flagged *slower* or *faster* only
//!   when it moved by more than 25 % (ratio above 1.25 or below 0.75).
//! - A run that was `ok` and now diverged is worse (and the reverse better); a check that
//!   passed and now fails is *newly failing*.

use crate::checks::same_spacing;
use crate::error::{HarnessError, Result};
use crate::io;
use crate::results::{CaseResults, RunResult, case_dirs};
use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// The thresholds below which a change is noise.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NoiseBand {
    /// Relative change of a metric that counts (0.05 = 5 % of the baseline value).
    pub rel: f64,
    /// Absolute change of a metric that counts (both must be exceeded).
    pub abs: f64,
    /// Relative change of the wall time that is flagged (0.25: ratio > 1.25 or < 0.75).
    pub wall: f64,
}

impl Default for NoiseBand {
    fn default() -> Self {
        NoiseBand { rel: 0.05, abs: 1e-6, wall: 0.25 }
    }
}

impl NoiseBand {
    /// One sentence stating the band and the directions, for the pages.
    pub fn describe(&self) -> String {
        format!(
            "A metric counts as changed when it moved by more than {rel} % of its baseline value \
             and by more than {abs:e} in absolute terms. Lower is better for error metrics \
             (name contains \"err\") and drifts (name contains \"drift\"); other metrics and observed \
             orders are only marked changed. Wall time is the ratio now / baseline, flagged when \
             it moved by more than {wall} %. Runs are matched by scheme, preset, dx and perturbed start.",
            rel = self.rel * 100.0,
            abs = self.abs,
            wall = self.wall * 100.0,
        )
    }
}

/// Which way a metric should move.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Direction {
    /// Error metrics and drifts.
    LowerIsBetter,
    /// Anything else: a change is reported without a judgement.
    Neutral,
}

/// The direction of a metric, from its name (see the module documentation).
pub fn direction(metric: &str) -> Direction {
    if metric.contains("err") || metric.contains("drift") {
        Direction::LowerIsBetter
    } else {
        Direction::Neutral
    }
}

/// The verdict on one value.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Mark {
    /// Moved the good way beyond the noise band.
    Better,
    /// Moved the bad way beyond the noise band.
    Worse,
    /// Within the noise band.
    Unchanged,
    /// Moved beyond the noise band, no direction defined.
    Changed,
    /// Present now, absent from the baseline.
    Added,
    /// In the baseline, absent now.
    Removed,
}

impl Mark {
    /// Lower-case label used on the pages (`better`, `worse`, ...).
    pub fn label(self) -> &'static str {
        match self {
            Mark::Better => "better",
            Mark::Worse => "worse",
            Mark::Unchanged => "unchanged",
            Mark::Changed => "changed",
            Mark::Added => "new",
            Mark::Removed => "removed",
        }
    }
}

/// Classifies the move of metric `name` from `old` to `new` (`None`: absent; NaN: not
/// finite, e.g. after a divergence), with the direction given by the name.
pub fn classify(name: &str, old: Option<f64>, new: Option<f64>, band: &NoiseBand) -> Mark {
    classify_as(direction(name), old, new, band)
}

/// Classifies the move from `old` to `new` for a value of direction `dir`.
pub fn classify_as(dir: Direction, old: Option<f64>, new: Option<f64>, band: &NoiseBand) -> Mark {
    let directed = |better: bool| match dir {
        Direction::LowerIsBetter if better => Mark::Better,
        Direction::LowerIsBetter => Mark::Worse,
        Direction::Neutral => Mark::Changed,
    };
    match (old, new) {
        (None, None) => Mark::Unchanged,
        (None, Some(_)) => Mark::Added,
        (Some(_), None) => Mark::Removed,
        (Some(o), Some(n)) => match (o.is_finite(), n.is_finite()) {
            (false, false) => Mark::Unchanged,
            (true, false) => directed(false),
            (false, true) => directed(true),
            (true, true) => {
                let d = n - o;
                if d.abs() <= band.abs || d.abs() <= band.rel * o.abs() {
                    Mark::Unchanged
                } else {
                    directed(d < 0.0)
                }
            }
        },
    }
}

/// One metric of one run (or one observed order), baseline against now.
#[derive(Debug, Clone, PartialEq)]
pub struct MetricChange {
    /// Metric name.
    pub name: String,
    /// Baseline value (`None`: absent; NaN: not finite).
    pub old: Option<f64>,
    /// New value.
    pub new: Option<f64>,
    /// The verdict.
    pub mark: Mark,
}

impl MetricChange {
    fn new(name: &str, dir: Direction, old: Option<f64>, new: Option<f64>, band: &NoiseBand) -> Self {
        MetricChange { name: name.to_string(), old, new, mark: classify_as(dir, old, new, band) }
    }

    /// Relative change `(new - old) / |old|` when both are finite and old is not zero.
    pub fn relative(&self) -> Option<f64> {
        match (self.old, self.new) {
            (Some(o), Some(n)) if o.is_finite() && n.is_finite() && o != 0.0 => Some((n - o) / o.abs()),
            _ => None,
        }
    }
}

/// A flagged wall-time move.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Speed {
    /// Ratio above 1 + band.
    Slower,
    /// Ratio below 1 - band.
    Faster,
}

/// Wall time of a run, baseline against now.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WallChange {
    /// Baseline wall time \[s\].
    pub old: f64,
    /// New wall time \[s\].
    pub new: f64,
    /// `new / old` (NaN when the baseline time is not positive).
    pub ratio: f64,
    /// Set when the ratio is outside the band.
    pub flag: Option<Speed>,
}

impl WallChange {
    /// Compares two wall times; flags a move beyond `band.wall`.
    pub fn new(old: f64, new: f64, band: &NoiseBand) -> Self {
        let ratio = if old > 0.0 && new.is_finite() { new / old } else { f64::NAN };
        let flag = if !ratio.is_finite() {
            None
        } else if ratio > 1.0 + band.wall {
            Some(Speed::Slower)
        } else if ratio < 1.0 - band.wall {
            Some(Speed::Faster)
        } else {
            None
        };
        WallChange { old, new, ratio, flag }
    }
}

/// One run present in both result sets.
#[derive(Debug, Clone, PartialEq)]
pub struct RunComparison {
    /// The run's slug (`isph-paper_dx0.02`).
    pub slug: String,
    /// Baseline status.
    pub old_status: String,
    /// New status.
    pub new_status: String,
    /// `Worse` when an ok run now diverges, `Better` for the reverse, else `Unchanged`.
    pub status: Mark,
    /// Every metric of either side, by name.
    pub metrics: Vec<MetricChange>,
    /// Wall time.
    pub wall: WallChange,
}

/// One check, baseline against now (only checks whose outcome differs are kept).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct CheckChange {
    /// Check name.
    pub name: String,
    /// Baseline outcome (`None`: the check was not in the baseline).
    pub old: Option<bool>,
    /// New outcome (`None`: the check is gone).
    pub new: Option<bool>,
}

impl CheckChange {
    /// Passed in the baseline, fails now.
    pub fn newly_failing(&self) -> bool {
        self.old == Some(true) && self.new == Some(false)
    }

    /// Failed in the baseline, passes now.
    pub fn newly_passing(&self) -> bool {
        self.old == Some(false) && self.new == Some(true)
    }

    /// A short label (`newly failing`, `newly passing`, `new check (fail)`, ...).
    pub fn label(&self) -> String {
        let word = |p: bool| if p { "pass" } else { "fail" };
        match (self.old, self.new) {
            (Some(true), Some(false)) => "newly failing".to_string(),
            (Some(false), Some(true)) => "newly passing".to_string(),
            (None, Some(p)) => format!("new check ({})", word(p)),
            (Some(p), None) => format!("check removed (was {})", word(p)),
            _ => "unchanged".to_string(),
        }
    }
}

/// One case, baseline against now.
#[derive(Debug, Clone, PartialEq)]
pub struct CaseComparison {
    /// Case name.
    pub case: String,
    /// Whether the baseline had this case at all.
    pub in_baseline: bool,
    /// Runs present in both, in the order of the new results.
    pub runs: Vec<RunComparison>,
    /// Slugs of runs only in the new results.
    pub added_runs: Vec<String>,
    /// Slugs of runs only in the baseline.
    pub removed_runs: Vec<String>,
    /// Observed orders (no direction: marked `changed` beyond the band).
    pub orders: Vec<MetricChange>,
    /// Checks whose outcome differs (flipped, new or removed).
    pub checks: Vec<CheckChange>,
}

/// Counts of a comparison, for one-line summaries.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Tally {
    /// Metrics (and run statuses) marked worse.
    pub worse: usize,
    /// Metrics (and run statuses) marked better.
    pub better: usize,
    /// Metrics and orders marked changed (no direction).
    pub changed: usize,
    /// Metrics within the band.
    pub unchanged: usize,
    /// Runs flagged slower.
    pub slower: usize,
    /// Runs flagged faster.
    pub faster: usize,
    /// Checks that passed in the baseline and fail now.
    pub newly_failing: usize,
    /// Checks that failed in the baseline and pass now.
    pub newly_passing: usize,
}

impl Tally {
    /// Adds another tally.
    pub fn add(&mut self, o: &Tally) {
        self.worse += o.worse;
        self.better += o.better;
        self.changed += o.changed;
        self.unchanged += o.unchanged;
        self.slower += o.slower;
        self.faster += o.faster;
        self.newly_failing += o.newly_failing;
        self.newly_passing += o.newly_passing;
    }

    /// Whether anything moved the bad way (worse, slower or newly failing).
    pub fn regressed(&self) -> bool {
        self.worse + self.slower + self.newly_failing > 0
    }

    /// `2 worse, 1 better, 3 changed, 40 unchanged; 1 slower; 1 newly failing check`.
    pub fn describe(&self) -> String {
        let mut s = format!(
            "{} worse, {} better, {} changed, {} unchanged",
            self.worse, self.better, self.changed, self.unchanged
        );
        if self.slower + self.faster > 0 {
            s.push_str(&format!("; wall time: {} slower, {} faster", self.slower, self.faster));
        }
        if self.newly_failing + self.newly_passing > 0 {
            s.push_str(&format!(
                "; checks: {} newly failing, {} newly passing",
                self.newly_failing, self.newly_passing
            ));
        }
        s
    }
}

impl CaseComparison {
    /// Counts of the marks of this case.
    pub fn tally(&self) -> Tally {
        let mut t = Tally::default();
        let mut count = |m: Mark| match m {
            Mark::Worse => t.worse += 1,
            Mark::Better => t.better += 1,
            Mark::Changed => t.changed += 1,
            Mark::Unchanged => t.unchanged += 1,
            Mark::Added | Mark::Removed => {}
        };
        for r in &self.runs {
            if r.status != Mark::Unchanged {
                count(r.status);
            }
            r.metrics.iter().for_each(|m| count(m.mark));
        }
        self.orders.iter().for_each(|m| count(m.mark));
        for r in &self.runs {
            match r.wall.flag {
                Some(Speed::Slower) => t.slower += 1,
                Some(Speed::Faster) => t.faster += 1,
                None => {}
            }
        }
        t.newly_failing = self.checks.iter().filter(|c| c.newly_failing()).count();
        t.newly_passing = self.checks.iter().filter(|c| c.newly_passing()).count();
        t
    }
}

/// A whole comparison: the baseline directory, the band and every current case.
#[derive(Debug, Clone, PartialEq)]
pub struct Comparison {
    /// The baseline directory as given.
    pub baseline: PathBuf,
    /// The noise band used.
    pub band: NoiseBand,
    /// One entry per current case, in the order of the new results.
    pub cases: Vec<CaseComparison>,
}

impl Comparison {
    /// The comparison of case `name`, if that case is current.
    pub fn case(&self, name: &str) -> Option<&CaseComparison> {
        self.cases.iter().find(|c| c.case == name)
    }

    /// The counts over every case.
    pub fn tally(&self) -> Tally {
        let mut t = Tally::default();
        self.cases.iter().for_each(|c| t.add(&c.tally()));
        t
    }
}

/// Whether two runs are the same point of the sweep: same scheme, preset, dx and start.
pub fn same_run(a: &RunResult, b: &RunResult) -> bool {
    a.scheme == b.scheme && a.preset == b.preset && a.start == b.start && same_spacing(a.dx, b.dx)
}

fn compare_run(old: &RunResult, new: &RunResult, band: &NoiseBand) -> RunComparison {
    let names: BTreeSet<&String> = old.metrics.keys().chain(new.metrics.keys()).collect();
    let metrics = names
        .into_iter()
        .map(|n| {
            MetricChange::new(n, direction(n), old.metrics.get(n).copied(), new.metrics.get(n).copied(), band)
        })
        .collect();
    let status = match (old.ok(), new.ok()) {
        (true, false) => Mark::Worse,
        (false, true) => Mark::Better,
        _ => Mark::Unchanged,
    };
    RunComparison {
        slug: new.slug(),
        old_status: old.status.clone(),
        new_status: new.status.clone(),
        status,
        metrics,
        wall: WallChange::new(old.wall_s, new.wall_s, band),
    }
}

/// Compares one case's new results with its baseline results (`None`: not in the
/// baseline, so everything is new).
pub fn compare_case(new: &CaseResults, old: Option<&CaseResults>, band: &NoiseBand) -> CaseComparison {
    let empty = CaseResults {
        case: new.case.clone(),
        scheme: new.scheme.clone(),
        tier: new.tier.clone(),
        runs: Vec::new(),
        convergence: BTreeMap::new(),
        checks: Vec::new(),
    };
    let base = old.unwrap_or(&empty);
    let mut runs = Vec::new();
    let mut added_runs = Vec::new();
    for r in &new.runs {
        match base.runs.iter().find(|b| same_run(b, r)) {
            Some(b) => runs.push(compare_run(b, r, band)),
            None => added_runs.push(r.slug()),
        }
    }
    let removed_runs =
        base.runs.iter().filter(|b| !new.runs.iter().any(|r| same_run(b, r))).map(RunResult::slug).collect();
    let order_names: BTreeSet<&String> = base.convergence.keys().chain(new.convergence.keys()).collect();
    let orders = order_names
        .into_iter()
        .map(|n| {
            let get = |c: &CaseResults| c.convergence.get(n).map(|c| c.order);
            MetricChange::new(n, Direction::Neutral, get(base), get(new), band)
        })
        .collect();
    let check_names: BTreeSet<&String> = base.checks.iter().chain(&new.checks).map(|c| &c.name).collect();
    let checks = check_names
        .into_iter()
        .map(|n| {
            let get = |c: &CaseResults| c.checks.iter().find(|k| &k.name == n).map(|k| k.pass);
            CheckChange { name: n.clone(), old: get(base), new: get(new) }
        })
        .filter(|c| c.old != c.new)
        .collect();
    CaseComparison {
        case: new.case.clone(),
        in_baseline: old.is_some(),
        runs,
        added_runs,
        removed_runs,
        orders,
        checks,
    }
}

/// Compares every current case with the baseline case of the same name.
pub fn compare(baseline_dir: &Path, new: &[CaseResults], old: &[CaseResults], band: NoiseBand) -> Comparison {
    let cases = new.iter().map(|n| compare_case(n, old.iter().find(|o| o.case == n.case), &band)).collect();
    Comparison { baseline: baseline_dir.to_path_buf(), band, cases }
}

/// Reads the baseline: every `<dir>/<case>/results.json` (restricted to `cases` when
/// given). A directory holding no results file is an error, so a mistyped path does not
/// silently compare against nothing.
pub fn load(dir: &Path, cases: Option<&[String]>) -> Result<Vec<CaseResults>> {
    let found: Vec<CaseResults> = case_dirs(dir, cases)
        .iter()
        .map(|d| io::read_json(&d.join("results.json")))
        .collect::<Result<_>>()?;
    if found.is_empty() {
        return Err(HarnessError::Io {
            path: dir.to_path_buf(),
            source: std::io::Error::new(
                std::io::ErrorKind::NotFound,
                "baseline: no <case>/results.json here (expected a previous reports/ directory)",
            ),
        });
    }
    Ok(found)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn band() -> NoiseBand {
        NoiseBand::default()
    }

    #[test]
    fn band_needs_both_relative_and_absolute_change() {
        let b = band();
        // 4 % relative: noise.
        assert_eq!(classify("b_rel_err_max", Some(0.01), Some(0.0104), &b), Mark::Unchanged);
        // 10 % relative, 1e-3 absolute: counts.
        assert_eq!(classify("b_rel_err_max", Some(0.01), Some(0.011), &b), Mark::Worse);
        assert_eq!(classify("b_rel_err_max", Some(0.01), Some(0.009), &b), Mark::Better);
        // 100 % relative but below the absolute floor: noise.
        assert_eq!(classify("a_rel_err_max", Some(1e-9), Some(2e-9), &b), Mark::Unchanged);
        // From zero: beyond the floor counts.
        assert_eq!(classify("a_rel_err_max", Some(0.0), Some(1e-3), &b), Mark::Worse);
    }

    #[test]
    fn a_perturbed_start_is_a_run_of_its_own() {
        let run = |start: Option<u64>| -> RunResult {
            serde_json::from_value(serde_json::json!({"scheme": "isph", "preset": "long", "dx": 0.02,
                "start": start, "particles": 1, "steps": 1, "wall_s": 1.0, "status": "ok",
                "metrics": {}, "series": {}}))
            .unwrap()
        };
        assert!(same_run(&run(None), &run(None)) && same_run(&run(Some(1)), &run(Some(1))));
        assert!(!same_run(&run(None), &run(Some(1))) && !same_run(&run(Some(1)), &run(Some(2))));
    }

    #[test]
    fn direction_comes_from_the_name() {
        let b = band();
        assert_eq!(direction("pc_rel_err_final"), Direction::LowerIsBetter);
        assert_eq!(direction("ke_drift"), Direction::LowerIsBetter);
        assert_eq!(direction("particles"), Direction::Neutral);
        assert_eq!(classify("particles", Some(1976.0), Some(2000.0), &b), Mark::Unchanged);
        assert_eq!(classify("particles", Some(1976.0), Some(7860.0), &b), Mark::Changed);
        assert_eq!(classify("ke_drift", Some(0.01), Some(0.02), &b), Mark::Worse);
    }

    #[test]
    fn non_finite_and_missing_values() {
        let b = band();
        assert_eq!(classify("b_rel_err_max", Some(0.01), Some(f64::NAN), &b), Mark::Worse);
        assert_eq!(classify("b_rel_err_max", Some(f64::NAN), Some(0.01), &b), Mark::Better);
        assert_eq!(classify("b_rel_err_max", Some(f64::NAN), Some(f64::NAN), &b), Mark::Unchanged);
        assert_eq!(classify("t_final", Some(0.008), Some(f64::NAN), &b), Mark::Changed);
        assert_eq!(classify("x", None, Some(1.0), &b), Mark::Added);
        assert_eq!(classify("x", Some(1.0), None, &b), Mark::Removed);
    }

    #[test]
    fn wall_time_is_flagged_beyond_a_quarter() {
        let b = band();
        assert_eq!(WallChange::new(2.0, 2.2, &b).flag, None);
        assert_eq!(WallChange::new(2.0, 1.8, &b).flag, None);
        assert_eq!(WallChange::new(2.0, 2.6, &b).flag, Some(Speed::Slower));
        assert_eq!(WallChange::new(2.0, 1.4, &b).flag, Some(Speed::Faster));
        let w = WallChange::new(0.0, 1.0, &b);
        assert!(w.ratio.is_nan() && w.flag.is_none());
    }

    #[test]
    fn check_change_labels() {
        let c = CheckChange { name: "x".into(), old: Some(true), new: Some(false) };
        assert!(c.newly_failing() && !c.newly_passing());
        assert_eq!(c.label(), "newly failing");
        let n = CheckChange { name: "y".into(), old: None, new: Some(false) };
        assert!(!n.newly_failing());
        assert_eq!(n.label(), "new check (fail)");
    }
}
