//! `cargo xtask validate`: run every case's sweep (reusing cached runs), compute metrics,
//! orders and checks, write the results files and render the report.

use crate::baseline::Comparison;
use crate::case::{self, Case, CaseRecord};
use crate::checks::evaluate_all;
use crate::error::{HarnessError, Result};
use crate::fit::fit_power_law;
use crate::io;
use crate::metrics;
use crate::progress::Progress;
use crate::provenance::Provenance;
use crate::report::{self, Baseline, RenderOptions};
use crate::results::{CaseResults, Convergence, RunResult};
use crate::runner::{Job, Ran, Runner};
use crate::sweep::{self, RunSpec};
use crate::tier::Tier;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// Options of a validation.
#[derive(Debug, Clone)]
pub struct ValidateOptions {
    /// Tier to run.
    pub tier: Tier,
    /// Cases to run (all in `validation_dir` when empty).
    pub cases: Vec<String>,
    /// Output directory (`reports/`).
    pub out: PathBuf,
    /// Directory of the case files (`validation/`).
    pub validation_dir: PathBuf,
    /// Workspace root (for git provenance).
    pub workspace: PathBuf,
    /// Rerun even when a cached run is valid.
    pub force: bool,
    /// Runs executed concurrently (1 = sequential).
    pub jobs: usize,
    /// Show progress bars.
    pub progress: bool,
    /// A previous `reports/` directory to compare the new results with.
    pub baseline: Option<PathBuf>,
    /// Run what is not cached on this Slurm cluster instead of this machine.
    pub slurm: Option<std::sync::Arc<crate::slurm::Cluster>>,
}

impl ValidateOptions {
    /// The quick tier of every case file in `<dir>/validation`, reports in `<dir>/reports`,
    /// one run at a time, no progress bars, no baseline (a scratch workspace: tests).
    pub fn quick_in(dir: &Path) -> Self {
        ValidateOptions {
            tier: Tier::Quick,
            cases: vec![],
            out: dir.join("reports"),
            validation_dir: dir.join("validation"),
            workspace: dir.to_path_buf(),
            force: false,
            jobs: 1,
            progress: false,
            baseline: None,
            slurm: None,
        }
    }
}

/// What a validation produced.
#[derive(Debug, Clone)]
pub struct Outcome {
    /// Results of the cases run by this invocation.
    pub results: Vec<CaseResults>,
    /// Runs executed (not taken from the cache).
    pub executed: usize,
    /// Runs taken from the cache.
    pub reused: usize,
    /// The comparison with the baseline, when one was given.
    pub comparison: Option<Comparison>,
}

impl Outcome {
    /// Whether every check of every case run passed (the exit code).
    pub fn pass(&self) -> bool {
        self.results.iter().all(CaseResults::pass)
    }
}

/// Runs the validation described by `opts`; failed checks are results, not errors.
pub fn validate(opts: &ValidateOptions) -> Result<Outcome> {
    let started = std::time::Instant::now();
    let paths = case::discover(&opts.validation_dir, &opts.cases)?;
    let cases: Vec<Case> = paths.iter().map(|p| Case::load(p)).collect::<Result<_>>()?;
    let known = case::known_cases(&opts.validation_dir)?;
    // Read the baseline before running anything: a wrong path fails at once, and a baseline
    // that is the output directory itself still holds the previous results.
    let baseline = opts.baseline.as_deref().map(|dir| Baseline::load(dir, Some(&known))).transpose()?;
    let runner =
        Runner::new(Progress::new(opts.progress), opts.force, opts.jobs).with_slurm(opts.slurm.clone());
    let provenance = Provenance::collect(&opts.workspace);
    let mut outcome = Outcome { results: Vec::new(), executed: 0, reused: 0, comparison: None };
    // Every case's runs in one batch, so that the costliest of the tier start first.
    let planned: Vec<(PathBuf, Vec<Job>)> = cases
        .iter()
        .map(|case| {
            let dir = opts.out.join(&case.case);
            let measured = measured_costs(&dir);
            let jobs = sweep::expand(case, opts.tier)?
                .into_iter()
                .map(|spec| {
                    // A perturbed start costs what its unperturbed run cost.
                    let unperturbed = crate::results::slug(&spec.scheme, &spec.preset, spec.dx);
                    let previous = measured.get(&spec.slug).or_else(|| measured.get(&unperturbed)).copied();
                    plan(spec, previous)
                })
                .collect();
            Ok((dir, jobs))
        })
        .collect::<Result<_>>()?;
    let placed: Vec<(&Path, &Job)> =
        planned.iter().flat_map(|(dir, jobs)| jobs.iter().map(move |j| (dir.as_path(), j))).collect();
    let ran = runner.run_placed(Some(opts.tier.name()), &placed, |i, ran| {
        let spec = &placed[i].1.spec;
        let line = match &ran {
            Ran::Finished { record, reused } => format!(
                "  {}/{} {} ({:.1} s{})",
                spec.case,
                spec.slug,
                record.status(),
                record.summary.wall_s,
                if *reused { ", cached" } else { "" }
            ),
            Ran::Panicked { .. } | Ran::Failed { .. } => {
                format!("  {}/{} {}", spec.case, spec.slug, ran.status())
            }
        };
        Ok((ran, line))
    })?;
    let mut ran = ran.into_iter();
    for (case, (case_dir, jobs)) in cases.iter().zip(&planned) {
        let ran: Vec<Ran> = ran.by_ref().take(jobs.len()).collect();
        for r in ran.iter().filter_map(Ran::record).filter(|r| !r.snapshots.is_empty()) {
            let file = crate::snapshots::SnapshotFile {
                slug: r.slug.clone(),
                preset: r.preset.clone(),
                dx: r.dx,
                status: r.status(),
                frames: r.snapshots.clone(),
            };
            crate::snapshots::store(case_dir, &file)?;
        }
        let runs = jobs
            .iter()
            .zip(&ran)
            .map(|(job, ran)| run_result(case, &job.spec, ran))
            .collect::<Result<_>>()?;
        let results = assemble(case, opts.tier, runs);
        let record = CaseRecord {
            case: case.clone(),
            provenance: provenance.clone(),
            scene_hashes: jobs.iter().map(|j| (j.spec.slug.clone(), j.spec.hash.clone())).collect(),
        };
        io::write_json(&case_dir.join("results.json"), &results)?;
        io::write_json(&case_dir.join("provenance.json"), &record)?;
        let (passed, failed) = results.counts();
        runner.progress().println(&format!(
            "{}: {passed} checks passed, {failed} failed -> {}",
            case.case,
            case_dir.join("index.html").display()
        ));
        outcome.results.push(results);
    }
    let tally = runner.tally();
    (outcome.executed, outcome.reused) = (tally.executed, tally.reused);
    let extras = extra_pages(&opts.out);
    // The wall time of the last invocation that ran something (a fully cached rerun keeps
    // the previous one).
    let elapsed_s = if tally.executed > 0 {
        Some(started.elapsed().as_secs_f64())
    } else {
        io::read_json::<crate::results::Summary>(&opts.out.join("summary.json"))
            .ok()
            .and_then(|s| s.elapsed_s)
    };
    let rendered =
        report::render(&opts.out, &RenderOptions { cases: Some(known), baseline, extras, elapsed_s })?;
    outcome.comparison = rendered.comparison;
    Ok(outcome)
}

/// The pages beside the cases that the index links, those present in `out`: the
/// stability envelope's and the work-precision study's.
pub fn extra_pages(out: &Path) -> Vec<report::ExtraPage> {
    crate::stability::extra_page(out).into_iter().chain(crate::work_precision::extra_page(out)).collect()
}

/// Runs with at least this many particles may get every thread of the machine (and run
/// alone, first) when they are the batch's critical path ([`crate::runner::Job::wide`]);
/// other runs get one worker's share. Measured on the 2-core machine
/// (docs/notes/main-job-time.md): a second thread speeds one run up 1.5–1.8 times (3200 to
/// 96 000 particles), two one-thread runs at once give 2.0–2.2 times the throughput; so
/// one thread per run wins, except for a run long enough to be the batch's critical path:
/// the open channel at Δx = 0.0025 (96 000 particles) when its case runs alone, not beside
/// the whole default tier.
pub const WIDE_PARTICLES: usize = 50_000;

/// Estimated cost of one particle-step \[core-s\] (the paper drop at Δx = 0.02: about
/// 1.5 core-µs): scales the estimate of [`plan`] to core-seconds when no run measured it.
const CORE_S_PER_PARTICLE_STEP: f64 = 1.5e-6;

/// The job of a run: whether it may run wide, from its particle count ([`WIDE_PARTICLES`]), and its
/// cost in core-seconds: `previous`, the same run's measured cost when the case's last
/// results have it; otherwise `particles × end / Δt₀ × 1.5 core-µs` with the first step's
/// Δt (built from the scene before anything runs; a scene that cannot start is costed as
/// zero, and its error is the run's). The estimate ranks a flow that starts from rest by
/// its first, viscous-limited step, ten times too cheap for the periodic channel at Re 400
/// (docs/notes/main-job-time.md); a measured cost ranks it right.
fn plan(spec: RunSpec, previous: Option<f64>) -> Job {
    let Ok(sim) = meniscus::AnySimulation::new(&spec.scene) else {
        return Job::new(spec);
    };
    let particles = sim.particles();
    let wide = particles >= WIDE_PARTICLES;
    let cost = previous.unwrap_or_else(|| {
        let steps = sim.first_step().map_or(0.0, |dt| (spec.scene.time.end / dt).ceil());
        particles as f64 * steps * CORE_S_PER_PARTICLE_STEP
    });
    Job { wide, cost, ..Job::new(spec) }
}

/// The core-seconds each run of a case took when it last ran, by slug, from the case's
/// `results.json` in `dir` (CPU time when measured, else wall time × threads); empty when
/// there is no readable results file.
fn measured_costs(dir: &Path) -> BTreeMap<String, f64> {
    let Ok(previous) = io::read_json::<CaseResults>(&dir.join("results.json")) else {
        return BTreeMap::new();
    };
    previous
        .runs
        .iter()
        .filter_map(|r| {
            let core_s = r.cpu_s.unwrap_or(r.wall_s * r.threads.unwrap_or(1) as f64);
            (core_s > 0.0 && core_s.is_finite()).then(|| (r.slug(), core_s))
        })
        .collect()
}

/// A run of `case` as its results file shows it: the metrics of its probes against the
/// case's reference; none when the solver panicked.
pub fn run_result(case: &Case, spec: &RunSpec, ran: &Ran) -> Result<RunResult> {
    let mut run = RunResult {
        scheme: spec.scheme.clone(),
        preset: spec.preset.clone(),
        dx: spec.dx,
        start: spec.start,
        particles: 0,
        steps: 0,
        wall_s: 0.0,
        cpu_s: None,
        threads: None,
        steady_at: None,
        status: ran.status(),
        metrics: BTreeMap::new(),
        series: BTreeMap::new(),
    };
    if let Some(r) = ran.record() {
        let probes = meniscus::ProbeRecord::from(r.probes.clone());
        let measured =
            metrics::compute(&case.reference, &r.scene, &probes, r.summary.particles, r.summary.steady_at)
                .map_err(|source| HarnessError::Reference { case: case.case.clone(), source })?;
        (run.particles, run.steps, run.wall_s) = (r.summary.particles, r.summary.steps, r.summary.wall_s);
        (run.cpu_s, run.threads, run.steady_at) = (r.cpu_s, r.threads, r.summary.steady_at);
        (run.metrics, run.series) = (measured.metrics, measured.series);
    }
    Ok(run)
}

/// Builds a case's results from its runs: orders and checks.
pub fn assemble(case: &Case, tier: Tier, runs: Vec<RunResult>) -> CaseResults {
    let convergence = convergence(case, &runs);
    // A run that diverged where its preset expects it to is judged once, by its completion
    // check below; the other checks read the runs that completed or were not expected to
    // stop (an expected divergence that completed is an unexpected pass, judged by all).
    let judged: Vec<RunResult> =
        runs.iter().filter(|r| r.ok() || expected_divergence(case, r).is_none()).cloned().collect();
    let mut checks = evaluate_all(&case.checks, &judged, tier);
    if checks.is_empty() {
        // A case that nothing judges cannot fail: it reads as a failure, not "0 / 0".
        checks.push(crate::results::CheckResult {
            name: format!("at least one check applies in tier {tier}"),
            value: None,
            threshold: None,
            pass: false,
            note: Some(format!("no check of {} selects a run of tier {tier}", case.case)),
            expected_failure: None,
            judges: None,
        });
    }
    checks.extend(completion_checks(case, &runs));
    CaseResults {
        case: case.case.clone(),
        scheme: case.scheme.clone(),
        tier: tier.name().to_string(),
        runs,
        convergence,
        checks,
    }
}

/// The reason a run's preset expects it to diverge at its spacing, if it does.
fn expected_divergence<'a>(case: &'a Case, r: &RunResult) -> Option<&'a str> {
    case.sweep.presets.iter().find(|p| p.name == r.preset).and_then(|p| p.expected_divergence_at(r.dx))
}

/// Every run reaches its end time: one check for the runs no preset expects to diverge
/// (failing with the slugs of those that did not), and one strict expected failure per run
/// that its preset expects to diverge (`expected_divergence`, with its reason): its
/// completion is an unexpected pass.
fn completion_checks(case: &Case, runs: &[RunResult]) -> Vec<crate::results::CheckResult> {
    let expected = |r: &RunResult| expected_divergence(case, r);
    let mut out = Vec::new();
    let unmarked: Vec<&RunResult> = runs.iter().filter(|r| expected(r).is_none()).collect();
    if !unmarked.is_empty() {
        let stopped: Vec<String> = unmarked.iter().filter(|r| !r.ok()).map(|r| r.slug()).collect();
        out.push(crate::results::CheckResult {
            name: "every run reaches its end time".into(),
            value: Some(stopped.len() as f64),
            threshold: Some(0.0),
            pass: stopped.is_empty(),
            note: (!stopped.is_empty()).then(|| format!("did not: {}", stopped.join(", "))),
            expected_failure: None,
            judges: None,
        });
    }
    for r in runs {
        if let Some(reason) = expected(r) {
            out.push(crate::results::CheckResult {
                name: format!("{} reaches its end time", r.slug()),
                value: None,
                threshold: None,
                pass: r.ok(),
                note: (!r.ok()).then(|| r.status.clone()),
                expected_failure: Some(reason.to_string()),
                judges: None,
            });
        }
    }
    out
}

/// Observed orders of the case's convergence metrics, from the runs that completed (a
/// perturbed-start ensemble by its mean, [`crate::checks::per_spacing`]). The
/// headline order is the primary preset's; when that preset has no fit (runs diverged or
/// the metric is undefined), the first preset (by name) that has one.
pub fn convergence(case: &Case, runs: &[RunResult]) -> BTreeMap<String, Convergence> {
    let primary = case.primary_preset();
    let mut out = BTreeMap::new();
    for metric in &case.convergence {
        let mut by_preset = BTreeMap::new();
        let mut primary_pts = None;
        let mut fallback = None;
        let mut presets: Vec<&str> = runs.iter().map(|r| r.preset.as_str()).collect();
        presets.sort_unstable();
        presets.dedup();
        for preset in presets {
            let mine: Vec<&RunResult> = runs.iter().filter(|r| r.preset == preset).collect();
            let pts = crate::checks::per_spacing(&mine, metric);
            let (dx, e): (Vec<f64>, Vec<f64>) = pts.iter().filter_map(|&(d, v)| Some((d, v?))).unzip();
            if let Some(fit) = fit_power_law(&dx, &e) {
                by_preset.insert(preset.to_string(), fit.order);
                if preset == primary {
                    primary_pts = Some((fit.order, preset, dx, e));
                } else if fallback.is_none() {
                    fallback = Some((fit.order, preset, dx, e));
                }
            }
        }
        if let Some((order, preset, dx, values)) = primary_pts.or(fallback) {
            out.insert(
                metric.clone(),
                Convergence { order, preset: preset.to_string(), dx, values, by_preset },
            );
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cache::{CachedProbes, RunRecord};
    use crate::io::testing::Scratch;

    fn drop_case() -> Case {
        crate::case::testing::committed("elliptical_drop")
    }

    /// The drop's results from `records` (as the runner would hand them over).
    fn results(records: Vec<RunRecord>) -> CaseResults {
        let case = drop_case();
        let runs = records
            .into_iter()
            .map(|r| {
                let spec = sweep::spec(&case, &r.preset, r.dx).unwrap();
                run_result(&case, &spec, &Ran::Finished { record: Box::new(r), reused: false }).unwrap()
            })
            .collect();
        assemble(&case, Tier::Quick, runs)
    }

    /// A synthetic record whose b error is `c dx^2` (a exact): no solver run.
    fn synthetic(preset: &str, dx: f64, c: f64, particles: usize) -> RunRecord {
        let t: Vec<f64> = (0..=4).map(|i| i as f64 * 2e-3).collect();
        let exact = meniscus_reference::elliptical_drop::EllipticalDrop::new(1.0, 100.0, 1000.0)
            .unwrap()
            .states_at(&t)
            .unwrap();
        let axes: BTreeMap<String, Vec<f64>> = [
            ("a_moment".to_string(), exact.iter().map(|s| s.a).collect()),
            ("b_moment".to_string(), exact.iter().map(|s| s.b * (1.0 + c * dx * dx)).collect()),
        ]
        .into();
        let e: BTreeMap<String, Vec<f64>> = [("e".to_string(), vec![1.0; t.len()])].into();
        let p: BTreeMap<String, Vec<f64>> = [("p".to_string(), exact.iter().map(|s| s.pc).collect())].into();
        let mut rec = crate::cache::tests::record("h");
        rec.slug = crate::results::slug("isph", preset, dx);
        rec.preset = preset.into();
        rec.dx = dx;
        rec.summary.particles = particles;
        rec.probes = CachedProbes {
            t,
            series: [
                ("ellipse_axes".to_string(), axes),
                ("kinetic_energy".to_string(), e),
                ("pressure_at".to_string(), p),
            ]
            .into(),
        };
        rec
    }

    /// A case that no check judges in a tier fails there instead of reading "0 / 0".
    #[test]
    fn a_case_with_no_applicable_check_fails() {
        let mut case = drop_case();
        case.checks.retain(|c| c.select.preset.as_deref() == Some("wcsph_paper"));
        assert!(!case.checks.is_empty());
        let runs = results(vec![synthetic("paper", 0.04, 5.0, 1976)]).runs;
        let res = assemble(&case, Tier::Quick, runs);
        assert_eq!(res.checks.len(), 2, "that one and the completion check: {:?}", res.checks);
        assert!(!res.checks[0].pass && res.checks[0].name.contains("at least one check"));
        assert!(!res.pass());
    }

    #[test]
    fn measured_costs_come_from_the_last_results() {
        let dir = Scratch::new("measured-costs");
        assert!(measured_costs(dir.path()).is_empty(), "no results file: no measured cost");
        let mut timed = synthetic("paper", 0.04, 5.0, 1976);
        (timed.summary.wall_s, timed.cpu_s) = (3.0, Some(5.5));
        let mut untimed = synthetic("paper", 0.02, 5.0, 7860);
        (untimed.summary.wall_s, untimed.threads) = (2.0, Some(2));
        let mut unknown = synthetic("tuned", 0.02, 1.0, 7860);
        unknown.summary.wall_s = 0.0;
        io::write_json(&dir.path().join("results.json"), &results(vec![timed, untimed, unknown])).unwrap();
        let costs = measured_costs(dir.path());
        assert_eq!(costs.len(), 2, "{costs:?}");
        assert!((costs["isph-paper_dx0.04"] - 5.5).abs() < 1e-12, "CPU time when measured");
        assert!((costs["isph-paper_dx0.02"] - 4.0).abs() < 1e-12, "else wall time x threads");
    }

    #[test]
    fn assemble_computes_orders_and_checks() {
        let recs = vec![
            synthetic("paper", 0.04, 5.0, 1976),
            synthetic("tuned", 0.04, 1.0, 1976),
            synthetic("paper", 0.02, 5.0, 7860),
            synthetic("tuned", 0.02, 1.0, 7860),
        ];
        let res = results(recs);
        assert_eq!(res.tier, "quick");
        assert_eq!(res.runs.len(), 4);
        let conv = &res.convergence["b_rel_err_max"];
        assert_eq!(conv.preset, "paper");
        assert!((conv.order - 2.0).abs() < 1e-9, "{}", conv.order);
        assert!((conv.by_preset["tuned"] - 2.0).abs() < 1e-9);
        // a is exact: no positive errors, no order.
        assert!(!res.convergence.contains_key("a_rel_err_max"));
        // Without a fit of the primary preset the headline order is another preset's.
        let partial = vec![
            synthetic("paper", 0.04, 5.0, 1976),
            synthetic("tuned", 0.04, 1.0, 1976),
            synthetic("tuned", 0.02, 1.0, 7860),
        ];
        let conv = results(partial).convergence;
        assert_eq!(conv["b_rel_err_max"].preset, "tuned");
        assert!((conv["b_rel_err_max"].order - 2.0).abs() < 1e-9);
        let names: Vec<&str> = res.checks.iter().map(|c| c.name.as_str()).collect();
        assert!(!names.iter().any(|n| n.contains("31428")), "dx=0.01 is not in the quick tier");
        let b = res.checks.iter().find(|c| c.name.starts_with("b error (moments")).unwrap();
        assert!(b.pass && (b.value.unwrap() - 5.0 * 0.02 * 0.02).abs() < 1e-12);
        // a errors are exactly 0 at both spacings: 0 does not decrease (ratio undefined).
        let a_dec = res.checks.iter().find(|c| c.name == "a error decreases with dx (paper)").unwrap();
        assert!(!a_dec.pass);
        assert!(res.checks.iter().find(|c| c.name == "b error decreases with dx (paper)").unwrap().pass);
        assert!(res.checks.iter().filter(|c| c.name.contains("particles")).all(|c| c.pass));
    }

    #[test]
    fn diverged_run_fails_its_checks() {
        let mut bad = synthetic("paper", 0.02, 5.0, 7860);
        bad.summary.status = meniscus::Status::Diverged;
        bad.summary.error = Some("diverged in stage `ppe` at step 7".into());
        let recs = vec![synthetic("paper", 0.04, 5.0, 1976), bad];
        let res = results(recs);
        assert!(res.runs[1].status.starts_with("diverged: "));
        let b = res.checks.iter().find(|c| c.name.starts_with("b error (moments")).unwrap();
        assert!(!b.pass && b.note.as_deref().unwrap_or("").contains("diverged"));
        assert!(!res.pass());
        assert!(!res.convergence.contains_key("b_rel_err_max"), "diverged runs are not fitted");
        // A run whose solver panicked is a diverged run without metrics.
        let spec = sweep::spec(&drop_case(), "tuned", 0.02).unwrap();
        let panicked = run_result(&drop_case(), &spec, &Ran::Panicked { message: "boom".into() }).unwrap();
        assert_eq!(panicked.status, "diverged: the solver panicked: boom");
        assert!(panicked.metrics.is_empty() && panicked.particles == 0 && !panicked.ok());
    }

    /// Every run reaches its end time unless its preset expects it to diverge there: then
    /// its divergence is an expected failure (and no other check reads the run) and its
    /// completion an unexpected pass.
    #[test]
    fn runs_must_complete_unless_expected_to_diverge() {
        use crate::case::ExpectedDivergence;
        use crate::results::Verdict;
        let diverged = |dx, particles| {
            let mut r = synthetic("paper", dx, 5.0, particles);
            r.summary.status = meniscus::Status::Diverged;
            r.summary.error = Some("diverged in stage `guard` at step 9".into());
            r
        };
        let completion = |case: &Case, recs: Vec<RunRecord>| {
            let runs = results(recs).runs;
            let out = assemble(case, Tier::Quick, runs).checks;
            out.into_iter().filter(|c| c.name.contains("reaches its end time")).collect::<Vec<_>>()
        };
        let mut case = drop_case();
        let c = completion(&case, vec![synthetic("paper", 0.04, 5.0, 1976), diverged(0.02, 7860)]);
        assert_eq!(c.len(), 1);
        assert!(!c[0].pass && c[0].note.as_deref().unwrap_or("").contains("isph-paper_dx0.02"), "{c:?}");
        case.sweep.presets[0].expected_divergence =
            Some(ExpectedDivergence { dx: vec![0.02], reason: "measured: flung off".into() });
        let c = completion(&case, vec![synthetic("paper", 0.04, 5.0, 1976), diverged(0.02, 7860)]);
        let verdicts: Vec<Verdict> = c.iter().map(|c| c.verdict()).collect();
        assert_eq!(verdicts, [Verdict::Pass, Verdict::ExpectedFail], "{c:?}");
        // Judged once: no other check reads the run that diverged as expected.
        let runs = results(vec![synthetic("paper", 0.04, 5.0, 1976), diverged(0.02, 7860)]).runs;
        let others = assemble(&case, Tier::Quick, runs).checks;
        let reads_it = |c: &crate::results::CheckResult| c.note.as_deref().unwrap_or("").contains("diverged");
        assert!(
            !others.iter().any(|c| !c.name.contains("reaches its end time") && reads_it(c)),
            "{others:?}"
        );
        let c =
            completion(&case, vec![synthetic("paper", 0.04, 5.0, 1976), synthetic("paper", 0.02, 5.0, 7860)]);
        assert_eq!(c[1].verdict(), Verdict::UnexpectedPass);
        // The marking names a spacing of the sweep and a reason.
        let mut v = serde_json::to_value(&case).unwrap();
        v["sweep"]["presets"][0]["expected_divergence"]["dx"] = serde_json::json!([0.03]);
        let e = Case::from_json(&v.to_string(), Path::new("x.json")).unwrap_err().to_string();
        assert!(e.contains("expected_divergence.dx") && e.contains("0.03"), "{e}");
        v["sweep"]["presets"][0]["expected_divergence"] = serde_json::json!({"dx": [0.02], "reason": " "});
        let e = Case::from_json(&v.to_string(), Path::new("x.json")).unwrap_err().to_string();
        assert!(e.contains("expected_divergence.reason"), "{e}");
    }

    /// A tiny real solver run (dx = 0.1, two steps) through the whole pipeline, twice:
    /// the second invocation reuses the cache, a changed scene reruns.
    #[test]
    fn end_to_end_tiny_case_uses_the_cache() {
        let dir = Scratch::new("validate");
        let vdir = dir.path().join("validation");
        let mut case = drop_case();
        case.case = "tiny_drop".into();
        case.scene["time"]["end"] = serde_json::json!(0.0004);
        case.scene["output"]["probe_every"] = serde_json::json!(5);
        case.sweep.dx = [(Tier::Quick, vec![0.1])].into();
        case.sweep.presets.truncate(1);
        // The checks of what the tiny case still runs (a selector naming a preset or a
        // spacing it no longer has is rejected when the case loads).
        case.checks
            .retain(|c| c.select.preset.as_deref().is_none_or(|p| p == "paper") && c.select.dx.is_none());
        assert!(!case.checks.is_empty());
        io::write_json(&vdir.join("tiny_drop.json"), &case).unwrap();
        let opts = ValidateOptions::quick_in(dir.path());
        let first = validate(&opts).unwrap();
        assert_eq!((first.executed, first.reused), (1, 0));
        let res = &first.results[0];
        assert_eq!(res.runs[0].status, "ok");
        assert!(res.runs[0].metrics["b_rel_err_max"].is_finite());
        assert!(opts.out.join("tiny_drop/runs/isph-paper_dx0.1.json").is_file());
        assert!(opts.out.join("tiny_drop/index.html").is_file());
        assert!(opts.out.join("summary.json").is_file());
        assert!(opts.out.join("index.html").is_file());
        let md = std::fs::read_to_string(opts.out.join("summary.md")).unwrap();
        assert!(md.contains("| tiny_drop | isph | quick | 0.1 |"), "{md}");
        // A stale case directory (no case file) is left out of the index and summaries.
        io::write_json(
            &opts.out.join("stale_case/results.json"),
            &CaseResults { case: "stale_case".into(), ..res.clone() },
        )
        .unwrap();
        let timed: crate::results::Summary = io::read_json(&opts.out.join("summary.json")).unwrap();
        let second = validate(&opts).unwrap();
        assert_eq!((second.executed, second.reused), (0, 1));
        let kept: crate::results::Summary = io::read_json(&opts.out.join("summary.json")).unwrap();
        assert!(
            timed.elapsed_s.is_some() && kept.elapsed_s == timed.elapsed_s,
            "a cached rerun keeps the time"
        );
        let index = std::fs::read_to_string(opts.out.join("index.html")).unwrap();
        assert!(index.contains("tiny_drop/index.html") && !index.contains("stale_case"));
        let summary: crate::results::Summary = io::read_json(&opts.out.join("summary.json")).unwrap();
        assert_eq!(summary.cases.len(), 1);
        assert_eq!(second.results[0].runs, first.results[0].runs);
        case.scene["time"]["end"] = serde_json::json!(0.0006);
        io::write_json(&vdir.join("tiny_drop.json"), &case).unwrap();
        let third = validate(&opts).unwrap();
        assert_eq!((third.executed, third.reused), (1, 0), "scene hash changed: rerun");
        // The output directory as its own baseline: read before the rerun.
        let forced =
            validate(&ValidateOptions { force: true, baseline: Some(opts.out.clone()), ..opts.clone() })
                .unwrap();
        assert_eq!(forced.executed, 1);
        let cmp = forced.comparison.expect("a baseline was given");
        assert!(cmp.cases[0].in_baseline && cmp.cases[0].runs.len() == 1);
        assert!(cmp.case("stale_case").is_none());
        let md = std::fs::read_to_string(opts.out.join("summary.md")).unwrap();
        assert!(md.contains("## Compared with baseline"), "{md}");
        let missing = ValidateOptions { baseline: Some(dir.path().join("nowhere")), ..opts.clone() };
        assert!(validate(&missing).is_err(), "a baseline without results is an error");
    }
}
