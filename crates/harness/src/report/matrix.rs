//! The scheme-by-case matrix of the index and `summary.md`: for each case and scheme, the
//! best preset's headline error at the finest spacing, its observed order, its wall time
//! and the verdicts of the checks that judge them; which scheme wins each case.
//!
//! - **Headline metric** of a case: its first key metric (`key_metrics`) that is a relative
//!   error ([`is_relative`]), else its first key metric.
//! - **Best preset** of a scheme: at the finest spacing any of the scheme's presets ran,
//!   the preset with the smallest headline error there (the mean over perturbed starts, as
//!   the checks take it, [`per_spacing`]); when none completed there, the next spacing. A
//!   headline that is not an error (a spread factor) has no best: the scheme's first
//!   preset stands for it.
//! - A value is shown with a verdict only where a check bounds that metric of that run
//!   ([`crate::checks::Judged::bounds`]); the order likewise where an `order` check selects
//!   the preset. Anything else is information.
//! - **Best scheme** of a case: the smallest headline error, when two or more schemes have
//!   one. A check over more runs than the value's (no `dx` in its selector) judges its
//!   worst: the cell then gives that value too.

use crate::case::CaseRecord;
use crate::checks::{CheckKind, per_spacing, same_spacing};
use crate::numbers::{check_bound, check_number, is_relative};
use crate::results::{CaseResults, CheckResult, RunResult, Verdict};

/// Schemes in the order the matrix lists them; others follow alphabetically.
const SCHEME_ORDER: [&str; 4] = ["isph", "wcsph", "mps", "otm"];

/// A value and the verdict of the checks that judge it.
#[derive(Debug, Clone, PartialEq)]
pub struct Judgement {
    /// The worst verdict of the checks that judge the value (none: information only).
    pub verdict: Option<Verdict>,
    /// The bound of that check (`≤ 1.00 %`), empty without one.
    pub bound: String,
    /// That check's own value, when it is not the value shown (its worst over more runs).
    pub checked: Option<String>,
}

/// Checks of a scheme in a case, by verdict.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Tally {
    /// Passed.
    pub passed: usize,
    /// Unexpected results (failures and passes of expected failures).
    pub failed: usize,
    /// Failed as expected.
    pub expected: usize,
}

impl Tally {
    /// The tally as text: `5 / 6 checks pass, 1 expected fail`.
    pub fn describe(&self) -> String {
        let mut s = format!("{} / {} checks pass", self.passed, self.passed + self.failed);
        if self.expected > 0 {
            s.push_str(&format!(", {} expected fail", self.expected));
        }
        s
    }
}

/// One cell: a scheme's best preset on a case.
#[derive(Debug, Clone, PartialEq)]
pub struct Cell {
    /// The scheme.
    pub scheme: String,
    /// Its best preset ([module docs](self)).
    pub preset: String,
    /// The spacing of the value \[m\].
    pub dx: f64,
    /// The headline value there (mean over perturbed starts); none when no run has it.
    pub value: Option<f64>,
    /// Why there is no value (empty when there is one).
    pub missing: &'static str,
    /// Runs at that spacing (more than one with perturbed starts).
    pub starts: usize,
    /// The checks bounding the value.
    pub value_check: Judgement,
    /// The preset's observed order of the headline metric.
    pub order: Option<f64>,
    /// The `order` checks of the preset.
    pub order_check: Judgement,
    /// Wall time of the runs at that spacing (their mean over perturbed starts) \[s\].
    pub wall_s: f64,
    /// Every check of the case that selects a run of the scheme.
    pub tally: Tally,
    /// Whether the scheme has the case's smallest headline value.
    pub best: bool,
}

/// One row: a case.
#[derive(Debug, Clone, PartialEq)]
pub struct Row {
    /// Case name.
    pub case: String,
    /// Case title (empty without a record).
    pub title: String,
    /// The headline metric (none when the case names no metric).
    pub metric: Option<String>,
    /// One entry per column of [`Matrix::schemes`]; none where the scheme does not run.
    pub cells: Vec<Option<Cell>>,
    /// Whether every check of the case had its expected outcome.
    pub pass: bool,
}

/// The whole matrix.
#[derive(Debug, Clone, PartialEq)]
pub struct Matrix {
    /// Column schemes.
    pub schemes: Vec<String>,
    /// One row per case.
    pub rows: Vec<Row>,
}

/// The worse of two verdicts (unexpected results, then expected failures, then passes).
fn worse(a: Verdict, b: Verdict) -> Verdict {
    let rank = |v: Verdict| match v {
        Verdict::Pass => 0,
        Verdict::ExpectedFail => 1,
        Verdict::Fail | Verdict::UnexpectedPass => 2,
    };
    if rank(b) > rank(a) { b } else { a }
}

/// The judgement of `checks` (those that judge the value `shown`): the worst verdict, the
/// bound of that check, and its own value when it is not `shown` (a check over several
/// spacings or presets judges its worst).
fn judgement<'a>(checks: impl Iterator<Item = &'a CheckResult>, shown: Option<f64>) -> Judgement {
    let mut out = Judgement { verdict: None, bound: String::new(), checked: None };
    for c in checks {
        let v = c.verdict();
        if out.verdict.is_none_or(|w| worse(w, v) != w) {
            out.bound = check_bound(c);
            let same = match (c.value, shown) {
                (Some(a), Some(b)) => (a - b).abs() <= 1e-12 * a.abs().max(b.abs()),
                (None, None) => true,
                _ => false,
            };
            out.checked =
                if same { None } else { Some(c.value.map_or("—".to_string(), |x| check_number(c, x))) };
        }
        out.verdict = Some(out.verdict.map_or(v, |w| worse(w, v)));
    }
    out
}

/// The headline metric of a case ([module docs](self)).
pub fn headline(results: &CaseResults, record: Option<&CaseRecord>) -> Option<String> {
    let keys: Vec<String> = record.map(|r| r.case.key_metrics.clone()).unwrap_or_default();
    let keys = if keys.is_empty() { results.convergence.keys().cloned().collect() } else { keys };
    keys.iter().find(|k| is_relative(k)).or(keys.first()).cloned()
}

/// Whether check `c` concerns `scheme`, whose runs are `mine` (and not only runs of other
/// schemes): a recorded selector matching one of them, or matching no run of `all` (a
/// check that selects nothing fails; it counts for every scheme its selector allows); an
/// unrecorded check (a run's completion) naming one of them, or naming no run of `all`.
fn concerns(c: &CheckResult, scheme: &str, mine: &[&RunResult], all: &[RunResult]) -> bool {
    match &c.judges {
        Some(j) => {
            mine.iter().any(|r| j.select.matches(*r))
                || (!all.iter().any(|r| j.select.matches(r))
                    && j.select.scheme.as_deref().is_none_or(|s| s == scheme))
        }
        None => {
            let text = format!("{} {}", c.name, c.note.as_deref().unwrap_or(""));
            let names = |r: &RunResult| text.contains(&r.slug());
            mine.iter().any(|r| names(r)) || !all.iter().any(names)
        }
    }
}

/// The cell of `scheme` in `results` for `metric`.
fn cell(results: &CaseResults, scheme: &str, metric: Option<&str>) -> Option<Cell> {
    let mine: Vec<&RunResult> = results.runs.iter().filter(|r| r.scheme == scheme).collect();
    let finest_run = *mine.iter().min_by(|a, b| a.dx.total_cmp(&b.dx))?;
    let mut spacings: Vec<f64> = mine.iter().map(|r| r.dx).collect();
    spacings.sort_by(f64::total_cmp);
    spacings.dedup_by(|a, b| same_spacing(*a, *b));
    // Presets in the order the runs name them: the first is the scheme's primary one.
    let mut presets: Vec<&str> = Vec::new();
    for r in &mine {
        if !presets.contains(&r.preset.as_str()) {
            presets.push(&r.preset);
        }
    }
    let at = |preset: &str, dx: f64| -> Vec<&RunResult> {
        mine.iter().copied().filter(|r| r.preset == preset && same_spacing(r.dx, dx)).collect()
    };
    // Errors compare, so the best preset is the smallest; another headline has no "best":
    // the primary preset stands for the scheme.
    let comparable = metric.is_some_and(is_relative);
    let candidates: &[&str] = if comparable { &presets } else { &presets[..1] };
    // (preset, dx, value): the best value at the finest spacing that has one.
    let best = metric.and_then(|m| {
        spacings.iter().find_map(|&dx| {
            candidates
                .iter()
                .filter_map(|p| {
                    let members = at(p, dx);
                    let v = per_spacing(&members, m).first().and_then(|(_, v)| *v)?;
                    Some((*p, dx, v))
                })
                .min_by(|a, b| a.2.total_cmp(&b.2))
        })
    });
    let (preset, dx, value) = match best {
        Some((p, dx, v)) => (p, dx, Some(v)),
        None => (finest_run.preset.as_str(), finest_run.dx, None),
    };
    let members = at(preset, dx);
    let of_preset: Vec<&RunResult> = mine.iter().copied().filter(|r| r.preset == preset).collect();
    let value_check = judgement(
        results.checks.iter().filter(|c| {
            metric.is_some_and(|m| c.judges.as_ref().is_some_and(|j| members.iter().any(|r| j.bounds(m, r))))
        }),
        value,
    );
    let order = metric.and_then(|m| results.convergence.get(m)?.by_preset.get(preset).copied());
    let order_check = judgement(
        results.checks.iter().filter(|c| {
            c.judges.as_ref().is_some_and(|j| {
                j.kind == CheckKind::Order
                    && Some(j.metric.as_str()) == metric
                    && of_preset.iter().any(|r| j.select.matches(*r))
            })
        }),
        order,
    );
    let mut tally = Tally::default();
    for c in results.checks.iter().filter(|c| concerns(c, scheme, &mine, &results.runs)) {
        match c.verdict() {
            Verdict::Pass => tally.passed += 1,
            Verdict::ExpectedFail => tally.expected += 1,
            Verdict::Fail | Verdict::UnexpectedPass => tally.failed += 1,
        }
    }
    let missing = match (metric, value) {
        (_, Some(_)) => "",
        (None, None) => "the case names no headline metric",
        (Some(_), None) if members.iter().any(|r| r.ok()) => "not computed",
        (Some(_), None) => "diverged",
    };
    Some(Cell {
        scheme: scheme.to_string(),
        preset: preset.to_string(),
        dx,
        value,
        missing,
        starts: members.len(),
        value_check,
        order,
        order_check,
        wall_s: members.iter().map(|r| r.wall_s).sum::<f64>() / members.len() as f64,
        tally,
        best: false,
    })
}

/// One line of the overview figure: a case's headline error against wall time for a
/// scheme's best preset, one point per spacing (coarse to fine, the mean over perturbed
/// starts).
#[derive(Debug, Clone, PartialEq)]
pub struct Curve {
    /// Case name.
    pub case: String,
    /// The scheme.
    pub scheme: String,
    /// `(wall time [s], headline error [fraction])` per completed spacing.
    pub points: Vec<(f64, f64)>,
}

impl Matrix {
    /// The overview figure's lines: per row whose headline metric is a relative error, per
    /// scheme, the best preset's completed spacings.
    pub fn curves(&self, results: &[CaseResults]) -> Vec<Curve> {
        let mut out = Vec::new();
        for (row, res) in self.rows.iter().zip(results) {
            let Some(metric) = row.metric.as_deref().filter(|m| is_relative(m)) else { continue };
            for c in row.cells.iter().flatten() {
                let mine: Vec<&RunResult> =
                    res.runs.iter().filter(|r| r.scheme == c.scheme && r.preset == c.preset).collect();
                let points: Vec<(f64, f64)> = per_spacing(&mine, metric)
                    .into_iter()
                    .filter_map(|(dx, v)| {
                        let at: Vec<&&RunResult> = mine.iter().filter(|r| same_spacing(r.dx, dx)).collect();
                        let wall = at.iter().map(|r| r.wall_s).sum::<f64>() / at.len() as f64;
                        Some((wall, v?))
                    })
                    .collect();
                if !points.is_empty() {
                    out.push(Curve { case: row.case.clone(), scheme: c.scheme.clone(), points });
                }
            }
        }
        out
    }

    /// The matrix of `results` (`records[i]` belongs to `results[i]`).
    pub fn of(results: &[CaseResults], records: &[Option<&CaseRecord>]) -> Self {
        let mut schemes: Vec<String> =
            results.iter().flat_map(|c| c.runs.iter().map(|r| r.scheme.clone())).collect();
        let rank = |s: &String| SCHEME_ORDER.iter().position(|k| k == s).unwrap_or(SCHEME_ORDER.len());
        schemes.sort_by(|a, b| rank(a).cmp(&rank(b)).then(a.cmp(b)));
        schemes.dedup();
        let rows = results
            .iter()
            .enumerate()
            .map(|(i, r)| {
                let record = records.get(i).copied().flatten();
                let metric = headline(r, record);
                let mut cells: Vec<Option<Cell>> =
                    schemes.iter().map(|s| cell(r, s, metric.as_deref())).collect();
                let with_value: Vec<(usize, f64)> =
                    cells.iter().enumerate().filter_map(|(k, c)| Some((k, c.as_ref()?.value?))).collect();
                let comparable = metric.as_deref().is_some_and(is_relative);
                if comparable
                    && with_value.len() > 1
                    && let Some(&(k, _)) = with_value.iter().min_by(|a, b| a.1.total_cmp(&b.1))
                    && let Some(c) = cells[k].as_mut()
                {
                    c.best = true;
                }
                Row {
                    case: r.case.clone(),
                    title: record.map(|rec| rec.case.title.clone()).unwrap_or_default(),
                    metric,
                    cells,
                    pass: r.pass(),
                }
            })
            .collect();
        Matrix { schemes, rows }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::checks::{Judged, Selector};
    use crate::results::Convergence;

    fn run(scheme: &str, preset: &str, dx: f64, err: f64, status: &str) -> RunResult {
        RunResult {
            scheme: scheme.into(),
            preset: preset.into(),
            dx,
            start: None,
            particles: 100,
            steps: 10,
            wall_s: 1.0 / dx,
            cpu_s: None,
            threads: None,
            steady_at: None,
            status: status.into(),
            metrics: [("b_rel_err_max".to_string(), err)].into(),
            series: Default::default(),
        }
    }

    fn check(
        kind: CheckKind,
        preset: Option<&str>,
        dx: Option<f64>,
        threshold: f64,
        pass: bool,
    ) -> CheckResult {
        CheckResult {
            name: format!("{kind:?}"),
            value: Some(0.0),
            threshold: Some(threshold),
            pass,
            note: None,
            expected_failure: None,
            judges: Some(Judged {
                metric: "b_rel_err_max".into(),
                kind,
                select: Selector { dx, preset: preset.map(str::to_string), ..Default::default() },
            }),
        }
    }

    fn results() -> CaseResults {
        CaseResults {
            case: "drop".into(),
            scheme: "isph".into(),
            tier: "quick".into(),
            runs: vec![
                run("isph", "paper", 0.04, 0.02, "ok"),
                run("isph", "paper", 0.02, 0.005, "ok"),
                run("isph", "tuned", 0.04, 0.01, "ok"),
                run("isph", "tuned", 0.02, 0.003, "diverged: at step 9"),
                run("wcsph", "w", 0.04, 0.008, "ok"),
                run("wcsph", "w", 0.02, 0.004, "ok"),
            ],
            convergence: [(
                "b_rel_err_max".to_string(),
                Convergence {
                    order: 2.0,
                    preset: "paper".into(),
                    dx: vec![0.04, 0.02],
                    values: vec![0.02, 0.005],
                    by_preset: [("paper".to_string(), 2.0), ("w".to_string(), 1.0)].into(),
                },
            )]
            .into(),
            checks: vec![
                CheckResult {
                    value: Some(0.005),
                    ..check(CheckKind::Max, Some("paper"), Some(0.02), 0.01, true)
                },
                check(CheckKind::Max, Some("tuned"), Some(0.02), 0.01, false),
                CheckResult { value: Some(2.0), ..check(CheckKind::Order, Some("paper"), None, 1.5, true) },
                CheckResult {
                    expected_failure: Some("documented".into()),
                    ..check(CheckKind::Max, Some("w"), Some(0.04), 0.001, false)
                },
            ],
        }
    }

    /// The best preset completes at the finest spacing (a diverged one with a smaller
    /// value there does not count); only checks that bound that run judge the value; the
    /// scheme with the smallest value wins; the tallies split by scheme.
    #[test]
    fn cells_take_the_best_completed_preset_at_the_finest_spacing() {
        let m = Matrix::of(&[results()], &[None]);
        assert_eq!(m.schemes, ["isph", "wcsph"]);
        let row = &m.rows[0];
        assert_eq!(row.metric.as_deref(), Some("b_rel_err_max"));
        let isph = row.cells[0].as_ref().unwrap();
        assert_eq!((isph.preset.as_str(), isph.dx, isph.value), ("paper", 0.02, Some(0.005)));
        assert_eq!(
            isph.value_check,
            Judgement { verdict: Some(Verdict::Pass), bound: "≤ 1.00 %".into(), checked: None }
        );
        assert_eq!(isph.order, Some(2.0));
        assert_eq!(
            (isph.order_check.verdict, isph.order_check.checked.as_deref()),
            (Some(Verdict::Pass), None)
        );
        assert_eq!(isph.tally, Tally { passed: 2, failed: 1, expected: 0 });
        assert!(!isph.best);
        let wcsph = row.cells[1].as_ref().unwrap();
        assert_eq!((wcsph.preset.as_str(), wcsph.value), ("w", Some(0.004)));
        // Its only check bounds the coarse run: the finest value is information.
        assert_eq!(wcsph.value_check.verdict, None);
        assert_eq!(wcsph.order_check.verdict, None);
        assert_eq!(wcsph.tally, Tally { passed: 0, failed: 0, expected: 1 });
        assert!(wcsph.best);
        assert!(!row.pass);
        // The overview's lines: the best presets' completed spacings, coarse to fine.
        let curves = m.curves(&[results()]);
        assert_eq!(curves.len(), 2);
        assert_eq!(
            (curves[0].scheme.as_str(), curves[0].points.clone()),
            ("isph", vec![(25.0, 0.02), (50.0, 0.005)])
        );
        assert_eq!(curves[1].points, vec![(25.0, 0.008), (50.0, 0.004)]);
    }

    /// A check without a spacing judges the worst run: the cell gives that value beside
    /// the verdict. A check that selects no run fails and counts for the schemes its
    /// selector allows.
    #[test]
    fn checks_over_more_runs_and_checks_of_no_run_show() {
        let mut r = results();
        r.checks[0] = CheckResult {
            value: Some(0.02),
            pass: false,
            ..check(CheckKind::Max, Some("paper"), None, 0.01, false)
        };
        r.checks.push(CheckResult {
            value: None,
            judges: Some(Judged {
                metric: "b_rel_err_max".into(),
                kind: CheckKind::Max,
                select: Selector {
                    preset: Some("gone".into()),
                    scheme: Some("wcsph".into()),
                    ..Default::default()
                },
            }),
            ..check(CheckKind::Max, None, None, 0.01, false)
        });
        let m = Matrix::of(&[r], &[None]);
        let isph = m.rows[0].cells[0].as_ref().unwrap();
        assert_eq!(isph.value, Some(0.005));
        assert_eq!(isph.value_check.verdict, Some(Verdict::Fail));
        assert_eq!(isph.value_check.checked.as_deref(), Some("2.00 %"));
        assert_eq!(isph.tally, Tally { passed: 1, failed: 2, expected: 0 });
        let wcsph = m.rows[0].cells[1].as_ref().unwrap();
        assert_eq!(wcsph.tally, Tally { passed: 0, failed: 1, expected: 1 });
    }

    /// A headline that is not an error: the scheme's first preset, no star; a scheme whose
    /// runs all diverged (presets at different spacings): its finest run, no value.
    #[test]
    fn absolute_headlines_and_diverged_schemes() {
        let mut r = results();
        for run in &mut r.runs {
            let v = run.metrics.remove("b_rel_err_max").unwrap();
            run.metrics.insert("beta_max".into(), v);
        }
        r.runs.push(run("wcsph", "fine", 0.01, 0.0, "diverged: x"));
        r.runs[4].status = "diverged: x".into();
        r.runs[5].status = "diverged: x".into();
        r.convergence.clear();
        let record = |keys: Vec<String>| {
            let mut case = crate::case::testing::committed("elliptical_drop");
            case.key_metrics = keys;
            CaseRecord { case, provenance: Default::default(), scene_hashes: Default::default() }
        };
        let rec = record(vec!["beta_max".into()]);
        let m = Matrix::of(std::slice::from_ref(&r), &[Some(&rec)]);
        let isph = m.rows[0].cells[0].as_ref().unwrap();
        assert_eq!((isph.preset.as_str(), isph.value, isph.best), ("paper", Some(0.005), false));
        let wcsph = m.rows[0].cells[1].as_ref().unwrap();
        assert_eq!((wcsph.preset.as_str(), wcsph.dx, wcsph.value), ("fine", 0.01, None));
        assert_eq!(wcsph.missing, "diverged");
    }

    /// Every run of a scheme at its finest spacing diverged: the next spacing's value.
    #[test]
    fn a_diverged_finest_spacing_falls_back_to_the_next() {
        let mut r = results();
        r.runs[1].status = "diverged: x".into();
        let m = Matrix::of(&[r], &[None]);
        let isph = m.rows[0].cells[0].as_ref().unwrap();
        assert_eq!((isph.preset.as_str(), isph.dx, isph.value), ("tuned", 0.04, Some(0.01)));
        assert_eq!(isph.missing, "");
    }
}
