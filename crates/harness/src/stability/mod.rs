//! The stability envelope (`cargo xtask validate --case stability`, issue #6): for the
//! elliptical drop and the periodic channel, per option set of the scheme,
//!
//! - `dt_max`: the largest stable multiple k of the adaptive step (Qiu 2013 eqs. 17–18 with
//!   α_c = α_d = 0.2, i.e. `cfl = viscous = 0.2 k`, cap `k ×` the template's), by
//!   geometric bisection ([`bisect`]);
//! - `re_max` (channel, ISPH option sets): the largest Reynolds number stable to the end
//!   time (1 D²/ν), by bisection on the body force `F = 12 ν² Re / D³` at fixed ν;
//! - `jitter`: the initial lattice displaced by 10, 20, 30 % of Δx (`bodies[0].jitter`,
//!   seeded);
//! - `long_run` (drop): to t = 0.02 s, the kinetic-energy drift (the exact flow conserves it).
//!
//! The spacings, ranges, bounds, option sets and checks are data,
//! `validation/studies/stability.json` ([`config`]); the bisections and the error measures
//! are here. A run is *stable* when it reaches its end time with no guard tripped and its
//! error is within the stated bound ([`Settings::drop_bound`] on the larger of the a and b
//! errors over the history; [`Settings::channel_bound`] on the velocity profile's L2 error
//! at the end). Every result is a [`Row`] of `reports/stability/results.json`
//! ([`StabilityResults`], shaped like a case's results file) and of
//! `reports/stability/index.html` ([`page`]). The runs go through the harness's runner
//! ([`crate::runner`]: cached in `reports/stability/runs/<slug>.json`, panics caught,
//! `--jobs` at a time): the three bisections of an option set advance together, one batch
//! per step, then its jittered and long runs go as one batch; `results.json` is rewritten
//! after every batch.

pub mod bisect;
pub mod config;
pub mod page;

use crate::case::{Case, ReferenceSpec};
use crate::checks::Checked;
use crate::error::{HarnessError, Result};
use crate::io;
use crate::numbers::{format_dx, percent};
use crate::patch::merge_patch;
use crate::progress::Progress;
use crate::provenance::Provenance;
use crate::results::{CheckResult, RunResult, check_counts};
use crate::runner::{Job, Ran, Runner};
use crate::sweep::{RunSpec, effective_scene};
use crate::tier::Tier;
use bisect::{Bisection, Bracket, sig3};
pub use config::{Check, Config, OptionSet, Settings};
use serde::{Deserialize, Serialize};
use serde_json::{Value, json};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// The name of the study on the command line (`--case stability`) and its directory.
pub const NAME: &str = "stability";

/// α_c = α_d of Qiu 2013 eqs. 17–18: the adaptive step the multiple k scales.
const ALPHA: f64 = 0.2;

/// One solver run of a study.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Trial {
    /// The parameter tried (k, Re or the jitter fraction).
    pub value: f64,
    /// Run slug (`drop-xu-dt_k1.1892`).
    pub slug: String,
    /// `ok`, `diverged: <the solver's typed error>` or `panic: <message>`.
    pub status: String,
    /// Steps taken.
    pub steps: usize,
    /// Final time reached \[s\].
    pub t_final: f64,
    /// Wall time \[s\].
    pub wall_s: f64,
    /// The measured error (see [`Settings`]); NaN when not measurable.
    #[serde(with = "nan_as_null")]
    pub error: f64,
    /// Reached the end time, no guard tripped, error within the bound.
    pub stable: bool,
}

impl Trial {
    /// Why the trial is not stable (`None` when it is).
    pub fn reason(&self, bound: f64) -> Option<String> {
        if self.status != "ok" {
            Some(self.status.clone())
        } else if !self.stable {
            Some(format!("error {} above the bound {}", percent(self.error), percent(bound)))
        } else {
            None
        }
    }

    /// The progress line of the trial.
    fn line(&self) -> String {
        format!(
            "  {} {} ({:.1} s, {} steps, error {})",
            self.slug,
            if self.stable { "stable" } else { "unstable" },
            self.wall_s,
            self.steps,
            pct(self.error)
        )
    }
}

mod nan_as_null {
    use serde::{Deserialize, Deserializer, Serializer};

    pub fn serialize<S: Serializer>(v: &f64, s: S) -> Result<S::Ok, S::Error> {
        if v.is_finite() { s.serialize_f64(*v) } else { s.serialize_none() }
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
        Ok(Option::<f64>::deserialize(d)?.unwrap_or(f64::NAN))
    }
}

/// One result of the envelope: a row of `results.json` and of the page. It starts with the
/// fields of a run in a case's results file (DESIGN.md), `run`; its `status` is that of the
/// run that decided the row (for a bisection, the smallest unstable value's run, `ok` when
/// none), its `metrics` the measured quantities (`dt_multiple_max`, `re_max`, `ke_drift`,
/// ...; null when none) and its `series` the values tried and whether each was stable.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Row {
    /// Scheme, option set (`preset`), spacing, particles, steps and wall time over all
    /// trials, status, metrics, series.
    #[serde(flatten)]
    pub run: RunResult,
    /// `dt_max`, `re_max`, `jitter` or `long_run`.
    pub study: String,
    /// `elliptical_drop` or `poiseuille_periodic`.
    pub case: String,
    /// The configuration in words.
    pub config: String,
    /// The measured quantity in words (`k ∈ [1.19, 1.41)`, `Re ≥ 4000`, ...).
    pub measured: String,
    /// `ok`, or what went wrong (the typed error of the guard, or the error above its bound).
    pub outcome: String,
    /// Every run of the row.
    pub trials: Vec<Trial>,
}

impl Checked for Row {
    fn run(&self) -> &RunResult {
        &self.run
    }

    fn study(&self) -> Option<&str> {
        Some(&self.study)
    }

    fn case(&self) -> Option<&str> {
        Some(&self.case)
    }

    /// None: a row's status names the unstable run that decided it, a result.
    fn failure(&self) -> Option<String> {
        None
    }
}

/// `reports/stability/results.json`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct StabilityResults {
    /// Always `stability`.
    pub case: String,
    /// The scheme.
    pub scheme: String,
    /// The tier requested.
    pub tier: String,
    /// The settings (spacings, ranges, bounds).
    pub settings: Settings,
    /// Every result.
    pub runs: Vec<Row>,
    /// Checks of the envelope.
    pub checks: Vec<CheckResult>,
    /// False while the study runs (the file is rewritten after every batch).
    pub complete: bool,
    /// Wall time of the whole study \[s\].
    pub elapsed_s: f64,
    /// Runs executed and taken from the cache.
    pub executed: usize,
    /// Runs taken from the cache.
    pub reused: usize,
    /// Commit, machine, threads, date.
    pub provenance: Provenance,
}

impl StabilityResults {
    /// Passed and failed checks.
    pub fn counts(&self) -> (usize, usize) {
        check_counts(&self.checks)
    }

    /// Whether every check passed.
    pub fn pass(&self) -> bool {
        check_counts(&self.checks).1 == 0
    }
}

/// Options of a stability run.
#[derive(Debug, Clone)]
pub struct StabilityOptions {
    /// Output directory (`reports/`): writes `stability/`.
    pub out: PathBuf,
    /// The case files (`validation/`): the drop's and the channel's templates.
    pub validation_dir: PathBuf,
    /// Workspace root (provenance).
    pub workspace: PathBuf,
    /// Tier requested (recorded).
    pub tier: Tier,
    /// The study's data (`validation/studies/stability.json`, [`Config::load`]).
    pub config: Config,
    /// Rerun cached runs.
    pub force: bool,
    /// Runs executed concurrently.
    pub jobs: usize,
    /// Use the progress display (otherwise one plain line per run on stderr).
    pub progress: bool,
    /// Run what is not cached on this Slurm cluster instead of this machine.
    pub slurm: Option<std::sync::Arc<crate::slurm::Cluster>>,
}

/// How the cases named on the command line split between validation cases and the
/// stability study: `(cases, run the cases, run the study)`. No name: every case, and the
/// study in the full tier only; `stability` among the names runs the study in any tier.
pub fn split_cases(names: &[String], tier: Tier) -> (Vec<String>, bool, bool) {
    let cases: Vec<String> = names.iter().filter(|n| n.as_str() != NAME).cloned().collect();
    let asked = cases.len() < names.len();
    if names.is_empty() {
        (cases, true, tier == Tier::Full)
    } else {
        (cases.clone(), !cases.is_empty(), asked)
    }
}

/// Which base scene, with what it needs for its error and end time.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Kind {
    /// The elliptical drop: error = larger of the a and b errors over the history.
    Drop,
    /// The periodic channel of width D and kinematic viscosity ν (the template's): error =
    /// the profile L2 error at the end.
    Channel { width: f64, nu: f64 },
}

/// A case as the study uses it: its template preset at the study's spacing.
struct Base {
    kind: Kind,
    case: Case,
    preset: String,
    dx: f64,
    bound: f64,
    /// End time of the time-step and jitter runs \[s\].
    end: f64,
}

impl Base {
    /// The drop of `config`.
    fn drop(config: &Config, validation_dir: &Path) -> Result<Base> {
        let s = &config.settings;
        let case = Case::load(&validation_dir.join(format!("{}.json", config.drop.case)))?;
        let preset = config.drop.preset.clone();
        Ok(Base { kind: Kind::Drop, case, preset, dx: s.drop_dx, bound: s.drop_bound, end: s.drop_end })
    }

    /// The channel of `config`, to `channel_tau` viscous times D²/ν of its template.
    fn channel(config: &Config, validation_dir: &Path) -> Result<Base> {
        let s = &config.settings;
        let case = Case::load(&validation_dir.join(format!("{}.json", config.channel.case)))?;
        let ReferenceSpec::PoiseuilleStartup { width, .. } = case.reference else {
            return Err(HarnessError::case(
                NAME,
                format!("{} has no Poiseuille start-up reference", case.case),
            ));
        };
        let nu = case.scene["fluid"]["viscosity"].as_f64().unwrap_or(1e-3)
            / case.scene["fluid"]["density"].as_f64().unwrap_or(1e3);
        let end = s.channel_tau * width * width / nu;
        let preset = config.channel.preset.clone();
        Ok(Base {
            kind: Kind::Channel { width, nu },
            case,
            preset,
            dx: s.channel_dx,
            bound: s.channel_bound,
            end,
        })
    }

    /// The slug prefix (`drop`, `channel`).
    fn short(&self) -> &'static str {
        match self.kind {
            Kind::Drop => "drop",
            Kind::Channel { .. } => "channel",
        }
    }

    /// Ends a scene at the study's end time (the channel's probe times up to there).
    fn set_end(&self, v: &mut Value) {
        v["time"]["end"] = json!(self.end);
        if let Kind::Channel { .. } = self.kind
            && let Some(times) = v["output"]["probe_times"].as_array_mut()
        {
            times.retain(|t| t.as_f64().is_some_and(|t| t < self.end * (1.0 - 1e-9)));
        }
    }

    /// The scene of option set `set` with `edit` applied: the template preset at the
    /// study's spacing, the set's patch, its case preset and patch for this case, `edit`,
    /// then the sound speed it asks for (from the edited body force).
    fn scene(&self, set: &OptionSet, edit: impl FnOnce(&mut Value)) -> Result<Value> {
        let mut v = effective_scene(&self.case, &self.preset, self.dx)?;
        merge_patch(&mut v, &set.patch);
        let own = set.cases.get(&self.case.case);
        if let Some(o) = own {
            if let Some(name) = &o.preset {
                let preset = self.case.sweep.presets.iter().find(|p| &p.name == name).ok_or_else(|| {
                    HarnessError::case(
                        NAME,
                        format!("option set `{}`: {} has no preset `{name}`", set.name, self.case.case),
                    )
                })?;
                merge_patch(&mut v, &preset.patch);
            }
            merge_patch(&mut v, &o.patch);
        }
        edit(&mut v);
        if let Some(multiple) = own.and_then(|o| o.sound_speed_over_u_max) {
            let Kind::Channel { width, .. } = self.kind else {
                return Err(HarnessError::case(
                    NAME,
                    format!("option set `{}`: a sound speed from u_max needs the channel", set.name),
                ));
            };
            let force = v["body_force"][0].as_f64().unwrap_or(0.0).abs();
            let nu = v["fluid"]["viscosity"].as_f64().unwrap_or(1e-3)
                / v["fluid"]["density"].as_f64().unwrap_or(1e3);
            let u_max = force * width * width / (8.0 * nu);
            v["scheme"]["wcsph"]["sound_speed"] = json!(multiple * u_max);
        }
        Ok(v)
    }

    /// The job of run `slug`: option set `set` with `edit`.
    fn job(&self, set: &OptionSet, slug: String, edit: impl FnOnce(&mut Value)) -> Result<Job> {
        let scene = self.scene(set, edit)?;
        Ok(Job::new(RunSpec::from_json(NAME, slug, &set.name, self.dx, &scene)?))
    }

    /// Measures the run `slug` that tried `value` against this case's reference.
    fn measure(&self, value: f64, slug: &str, ran: Ran) -> Result<Measured> {
        let record = match ran {
            Ran::Finished { record, .. } => record,
            // The executor could not run it: no verdict on stability (a bisection would read
            // it as unstable).
            Ran::Failed { message } => {
                return Err(HarnessError::Slurm { message: format!("stability run `{slug}`: {message}") });
            }
            Ran::Panicked { message } => {
                let trial = Trial {
                    value,
                    slug: slug.to_string(),
                    status: format!("panic: {message}"),
                    steps: 0,
                    t_final: 0.0,
                    wall_s: 0.0,
                    error: f64::NAN,
                    stable: false,
                };
                return Ok(Measured { trial, particles: 0, t: Vec::new(), energy: Vec::new() });
            }
        };
        let probes = meniscus::ProbeRecord::from(record.probes.clone());
        let measured = crate::metrics::compute(
            &self.case.reference,
            &record.scene,
            &probes,
            record.summary.particles,
            record.summary.steady_at,
        )
        .map_err(|source| HarnessError::Reference { case: NAME.into(), source })?;
        let error = match self.kind {
            Kind::Drop => {
                let a = measured.metrics.get("a_rel_err_max").copied().unwrap_or(f64::NAN);
                let b = measured.metrics.get("b_rel_err_max").copied().unwrap_or(f64::NAN);
                if a.is_nan() || b.is_nan() { f64::NAN } else { a.max(b) }
            }
            Kind::Channel { .. } => {
                measured.series.get("u_profile_l2_rel").and_then(|s| s.last().copied()).unwrap_or(f64::NAN)
            }
        };
        let status = record.status();
        let s = &record.summary;
        let trial = Trial {
            value,
            slug: slug.to_string(),
            stable: status == "ok" && error <= self.bound,
            status,
            steps: s.steps,
            t_final: s.t_end,
            wall_s: s.wall_s,
            error,
        };
        let energy =
            record.probes.series.get("kinetic_energy").and_then(|q| q.get("e")).cloned().unwrap_or_default();
        Ok(Measured { trial, particles: s.particles, t: record.probes.t, energy })
    }
}

/// A trial with what the rows need besides it: particles, and the kinetic energy history
/// (`t`, `e`) for the long run.
struct Measured {
    trial: Trial,
    particles: usize,
    t: Vec<f64>,
    energy: Vec<f64>,
}

/// One bisection of an option set on a base: its scene per value and the trials so far.
struct Search<'a> {
    base: &'a Base,
    /// `dt_max` or `re_max`.
    study: &'static str,
    /// `k` or `Re`.
    symbol: &'static str,
    config: String,
    bisection: Bisection,
    /// The job that tries a value.
    job: Box<dyn Fn(f64) -> Result<Job> + 'a>,
    trials: Vec<Trial>,
    particles: usize,
}

impl<'a> Search<'a> {
    /// The bisection of `study` (of the quantity `symbol`) over `range` in `iterations`
    /// steps on `base`, described by `config`; `job` tries a value.
    fn new(
        base: &'a Base,
        (study, symbol): (&'static str, &'static str),
        config: String,
        (range, iterations): ([f64; 2], usize),
        job: impl Fn(f64) -> Result<Job> + 'a,
    ) -> Self {
        let bisection = Bisection::new(range[0], range[1], iterations);
        Search {
            base,
            study,
            symbol,
            config,
            bisection,
            job: Box::new(job),
            trials: Vec::new(),
            particles: 0,
        }
    }

    /// The bisection's row.
    fn row(self, set: &OptionSet) -> Row {
        let bracket = self.bisection.bracket().expect("the bisection is done");
        bisection_row(
            self.base,
            set,
            self.study,
            self.config,
            self.symbol,
            bracket,
            self.trials,
            self.particles,
        )
    }
}

/// Runs `searches` together until every bisection is done: each step tries the next value
/// of every unfinished one, as one batch of the runner.
fn bisect_together(runner: &Runner, dir: &Path, searches: &mut [Search]) -> Result<()> {
    loop {
        let tried: Vec<(usize, f64)> = searches
            .iter()
            .enumerate()
            .filter_map(|(i, s)| s.bisection.next_value().map(|v| (i, v)))
            .collect();
        if tried.is_empty() {
            return Ok(());
        }
        let jobs = tried.iter().map(|&(i, value)| (searches[i].job)(value)).collect::<Result<Vec<_>>>()?;
        let bases: Vec<&Base> = tried.iter().map(|&(i, _)| searches[i].base).collect();
        let measured = runner.run(dir, None, &jobs, |k, ran| {
            let m = bases[k].measure(tried[k].1, &jobs[k].spec.slug, ran)?;
            let line = m.trial.line();
            Ok((m, line))
        })?;
        for (&(i, _), m) in tried.iter().zip(measured) {
            let s = &mut searches[i];
            s.bisection.record(m.trial.stable);
            s.particles = s.particles.max(m.particles);
            s.trials.push(m.trial);
        }
    }
}

/// Whether two parameter values are the same point of a bisection.
fn same(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-12 * a.abs().max(b.abs())
}

/// A parameter value in a slug: up to 4 decimals, trailing zeros dropped.
fn slug_value(v: f64) -> String {
    let s = format!("{v:.4}");
    s.trim_end_matches('0').trim_end_matches('.').to_string()
}

/// A row's run fields for option set `set` on `base`.
fn row_run(base: &Base, set: &OptionSet, trials: &[Trial], particles: usize) -> RunResult {
    RunResult {
        scheme: set.scheme.clone(),
        preset: set.name.clone(),
        dx: base.dx,
        start: None,
        particles,
        steps: trials.iter().map(|t| t.steps).sum(),
        wall_s: trials.iter().map(|t| t.wall_s).sum(),
        cpu_s: None,
        threads: None,
        steady_at: None,
        status: "ok".into(),
        metrics: BTreeMap::new(),
        series: BTreeMap::new(),
    }
}

/// Assembles a bisection row from its trials.
#[allow(clippy::too_many_arguments)]
fn bisection_row(
    base: &Base,
    set: &OptionSet,
    study: &str,
    config: String,
    symbol: &str,
    bracket: Bracket,
    trials: Vec<Trial>,
    particles: usize,
) -> Row {
    let mut run = row_run(base, set, &trials, particles);
    let at_stable = bracket.stable().and_then(|s| trials.iter().find(|t| same(t.value, s)));
    let unstable_value = match bracket {
        Bracket::Found { unstable, .. } => Some(unstable),
        Bracket::Below(lo) => Some(lo),
        Bracket::AtLeast(_) => None,
    };
    let deciding = unstable_value.and_then(|u| trials.iter().find(|t| same(t.value, u)));
    let key = if study == "dt_max" { "dt_multiple" } else { "re" };
    run.metrics.insert(format!("{key}_max"), bracket.stable().unwrap_or(f64::NAN));
    run.metrics.insert(format!("{key}_unstable"), unstable_value.unwrap_or(f64::NAN));
    run.metrics.insert("err_at_max".into(), at_stable.map_or(f64::NAN, |t| t.error));
    if study == "dt_max" {
        let mean_dt = at_stable.map_or(f64::NAN, |t| t.t_final / t.steps.max(1) as f64);
        run.metrics.insert("dt_mean_s_at_max".into(), mean_dt);
    }
    let mut sorted: Vec<&Trial> = trials.iter().collect();
    sorted.sort_by(|a, b| a.value.total_cmp(&b.value));
    run.series = BTreeMap::from([
        ("value".to_string(), sorted.iter().map(|t| t.value).collect()),
        ("stable".to_string(), sorted.iter().map(|t| if t.stable { 1.0 } else { 0.0 }).collect()),
    ]);
    if let Some(t) = deciding {
        run.status = t.status.clone();
    }
    Row {
        run,
        study: study.into(),
        case: base.case.case.clone(),
        config,
        measured: format!("{symbol} {}", bracket.describe()),
        outcome: deciding
            .map(|t| format!("at {symbol} = {}: {}", sig3(t.value), t.reason(base.bound).unwrap_or_default()))
            .unwrap_or_else(|| "ok".into()),
        trials,
    }
}

/// A one-run row (jitter, long run).
fn single_row(
    base: &Base,
    set: &OptionSet,
    study: &str,
    config: String,
    trial: Trial,
    particles: usize,
) -> Row {
    let mut run = row_run(base, set, std::slice::from_ref(&trial), particles);
    run.status = if trial.status.starts_with("panic") {
        format!("diverged: {}", trial.status)
    } else {
        trial.status.clone()
    };
    run.metrics = BTreeMap::from([("err".to_string(), trial.error), ("t_final".to_string(), trial.t_final)]);
    Row {
        run,
        study: study.into(),
        case: base.case.case.clone(),
        config,
        measured: String::new(),
        outcome: trial.reason(base.bound).unwrap_or_else(|| "ok".into()),
        trials: vec![trial],
    }
}

/// Runs the stability envelope into `<out>/stability/` and refreshes `<out>/index.html`.
pub fn run(opts: &StabilityOptions) -> Result<StabilityResults> {
    let start = Instant::now();
    let cfg = &opts.config;
    let s = &cfg.settings;
    let sets: Vec<&OptionSet> =
        s.option_sets.iter().map(|name| cfg.option_set(name)).collect::<Result<_>>()?;
    let drop = Base::drop(cfg, &opts.validation_dir)?;
    let channel = Base::channel(cfg, &opts.validation_dir)?;
    let Kind::Channel { width, nu } = channel.kind else { unreachable!("the channel's kind") };
    let dir = opts.out.join(NAME);
    let runner =
        Runner::new(Progress::new(opts.progress), opts.force, opts.jobs).with_slurm(opts.slurm.clone());
    let mut results = StabilityResults {
        case: NAME.into(),
        scheme: {
            let mut schemes: Vec<&str> = sets.iter().map(|o| o.scheme.as_str()).collect();
            schemes.dedup();
            schemes.join(", ")
        },
        tier: opts.tier.name().into(),
        settings: s.clone(),
        runs: Vec::new(),
        checks: Vec::new(),
        complete: false,
        elapsed_s: 0.0,
        executed: 0,
        reused: 0,
        provenance: Provenance::collect(&opts.workspace),
    };
    let save = |results: &mut StabilityResults| -> Result<()> {
        results.elapsed_s = start.elapsed().as_secs_f64();
        (results.executed, results.reused) = (runner.tally().executed, runner.tally().reused);
        io::write_json(&dir.join("results.json"), results)
    };

    for set in sets.iter().copied() {
        // Largest stable multiple of the adaptive step (drop and channel) and, for ISPH,
        // largest stable Reynolds number of the channel. WCSPH's acoustic step (c0 ∝ Re)
        // needs about 1e3 Re steps to 1 D²/ν (measured: 39 064 at Re = 40), four million at
        // the range's Re = 4000.
        let mut searches = Vec::new();
        for base in [&drop, &channel] {
            let template_max =
                effective_scene(&base.case, &base.preset, base.dx)?["time"]["step"]["adaptive"]["max"]
                    .as_f64()
                    .unwrap_or(1e-3);
            let config = format!(
                "{}, dx = {}, to t = {} s; Δt = k × adaptive step (α_c = α_d = 0.2 k), k bisected in [{}, {}]",
                base.case.case,
                format_dx(base.dx),
                sig3(base.end),
                s.dt_range[0],
                s.dt_range[1]
            );
            searches.push(Search::new(base, ("dt_max", "k"), config, (s.dt_range, s.dt_iterations), move |k| {
                let slug = format!("{}-{}-dt_k{}", base.short(), set.name, slug_value(k));
                base.job(set, slug, |v| {
                    base.set_end(v);
                    v["time"]["step"] =
                        json!({"adaptive": {"cfl": ALPHA * k, "viscous": ALPHA * k, "max": template_max * k}});
                })
            }));
        }
        // The Reynolds-number bisection for the incompressible schemes (WCSPH's sound speed
        // grows with Re: a run of 1 D²/ν would cost about 1e3 Re acoustic steps).
        if set.scheme != "wcsph" {
            let config = format!(
                "{}, dx = {}, to {} D²/ν; F = 12 ν² Re / D³ (ν = {nu:e} m²/s), adaptive step (α = 0.2), Re bisected in [{}, {}]",
                channel.case.case,
                format_dx(channel.dx),
                s.channel_tau,
                s.re_range[0],
                s.re_range[1]
            );
            let base = &channel;
            searches.push(Search::new(
                base,
                ("re_max", "Re"),
                config,
                (s.re_range, s.re_iterations),
                move |re| {
                    let force = 12.0 * nu * nu * re / width.powi(3);
                    base.job(set, format!("channel-{}-re{}", set.name, slug_value(re)), |v| {
                        base.set_end(v);
                        v["body_force"] = json!([force, 0.0]);
                    })
                },
            ));
        }
        bisect_together(&runner, &dir, &mut searches)?;
        results.runs.extend(searches.into_iter().map(|search| search.row(set)));
        save(&mut results)?;

        // Jittered initial lattices of both cases, and the drop's long run (kinetic-energy
        // drift), as one batch.
        let mut jobs = Vec::new();
        let mut tried = Vec::new();
        for base in [&drop, &channel] {
            for &f in &s.jitter {
                let slug = format!("{}-{}-jitter{}", base.short(), set.name, slug_value(f));
                jobs.push(base.job(set, slug, |v| {
                    base.set_end(v);
                    v["bodies"][0]["jitter"] = json!({"fraction": f, "seed": s.seed});
                })?);
                tried.push((base, f));
            }
        }
        let long_slug = format!("drop-{}-long{}", set.name, slug_value(s.long_end));
        jobs.push(drop.job(set, long_slug, |v| v["time"]["end"] = json!(s.long_end))?);
        tried.push((&drop, s.long_end));
        let mut measured = runner.run(&dir, None, &jobs, |k, ran| {
            let m = tried[k].0.measure(tried[k].1, &jobs[k].spec.slug, ran)?;
            let line = m.trial.line();
            Ok((m, line))
        })?;
        let long = measured.pop().expect("the long run was in the batch");
        for ((base, f), Measured { trial, particles, .. }) in tried.into_iter().zip(measured) {
            let config = format!(
                "{}, dx = {}, lattice jittered by {} % of dx (seed {}), the case's time step",
                base.case.case,
                format_dx(base.dx),
                sig3(100.0 * f),
                s.seed
            );
            let mut row = single_row(base, set, "jitter", config, trial, particles);
            row.run.metrics.insert("jitter_fraction".into(), f);
            row.measured = if row.run.status == "ok" {
                format!("error {}", pct(row.run.metrics["err"]))
            } else {
                format!("diverged at t = {} s", sig3(row.run.metrics["t_final"]))
            };
            results.runs.push(row);
        }
        let drift = crate::metrics::drift(&long.energy);
        let config = format!(
            "{}, dx = {}, to t = {} s (the case ends at {} s), the case's time step",
            drop.case.case,
            format_dx(drop.dx),
            sig3(s.long_end),
            sig3(drop.case.scene["time"]["end"].as_f64().unwrap_or(f64::NAN))
        );
        let mut row = single_row(&drop, set, "long_run", config, long.trial, long.particles);
        // The long run's verdict is the energy drift, not the axes' error.
        row.outcome = if row.run.status == "ok" { "ok".into() } else { row.run.status.clone() };
        row.run.metrics.insert("ke_drift".into(), drift);
        row.measured = if row.run.status == "ok" {
            format!("KE drift {}", pct(drift))
        } else {
            let t = row.trials.first().map_or(f64::NAN, |t| t.t_final);
            format!("diverged at t = {} s (KE drift {} up to there)", sig3(t), pct(drift))
        };
        row.run.series = BTreeMap::from([("t".to_string(), long.t), ("e".to_string(), long.energy)]);
        results.runs.push(row);
        save(&mut results)?;
    }
    results.checks = checks(&cfg.checks, &results.runs, runner.tally().panicked, opts.tier);
    results.complete = true;
    save(&mut results)?;
    io::write_atomic(&dir.join("index.html"), page::render(&results, cfg).as_bytes())?;
    // The index links the study.
    let cases = Some(crate::case::known_cases(&opts.validation_dir)?);
    let extras =
        std::iter::once(results.index_entry()).chain(crate::work_precision::extra_page(&opts.out)).collect();
    crate::report::render(
        &opts.out,
        &crate::report::RenderOptions { cases, baseline: None, extras, elapsed_s: None },
    )?;
    Ok(results)
}

/// A fraction in percent as the report writes it (`1.23 %`, `—`).
pub(crate) fn pct(v: f64) -> String {
    if v.is_finite() { percent(v) } else { "—".into() }
}

/// The envelope's checks (the study file's, in order) on its `rows`; `panics` counts the
/// runs whose solver panicked. A [`Check::Bound`] of another tier is left out.
pub fn checks(specs: &[Check], rows: &[Row], panics: usize, tier: Tier) -> Vec<CheckResult> {
    let result = |name: &str, value: Option<f64>, pass: bool, note: Option<&str>| CheckResult {
        name: name.into(),
        value,
        threshold: Some(0.0),
        pass,
        note: note.map(str::to_string),
        expected_failure: None,
        judges: None,
    };
    specs
        .iter()
        .filter_map(|c| match c {
            Check::Explained { name } => {
                let unexplained = rows
                    .iter()
                    .flat_map(|r| &r.trials)
                    .filter(|t| !(t.status == "ok" || t.status.starts_with("diverged: ")))
                    .count();
                let n = (panics + unexplained) as f64;
                Some(result(name, Some(n), n <= 0.0, None))
            }
            Check::Bound(spec) => spec.applies(tier).then(|| {
                spec.evaluate(rows, tier).unwrap_or_else(|| CheckResult {
                    name: spec.display_name(),
                    value: None,
                    threshold: spec.threshold(),
                    pass: false,
                    note: spec.missing.clone(),
                    expected_failure: spec.expected_failure.clone(),
                    judges: None,
                })
            }),
            Check::Jittered { name, preset, fraction, rows: expected, missing } => {
                let jittered: Vec<&Row> = rows
                    .iter()
                    .filter(|r| r.study == "jitter" && r.run.preset == *preset)
                    .filter(|r| {
                        r.run.metrics.get("jitter_fraction").is_some_and(|f| (f - fraction).abs() < 1e-12)
                    })
                    .collect();
                let failing = jittered.iter().filter(|r| !r.trials.iter().all(|t| t.stable)).count();
                let complete = jittered.len() == *expected;
                Some(result(
                    name,
                    Some(failing as f64),
                    complete && failing == 0,
                    (!complete).then_some(missing),
                ))
            }
        })
        .collect()
}

/// `results.json` of a previous study in `out`, if any.
pub fn load(out: &Path) -> Option<StabilityResults> {
    io::read_json(&out.join(NAME).join("results.json")).ok()
}

/// The report index's link to the study's page, when `out` holds a study.
pub fn extra_page(out: &Path) -> Option<crate::report::ExtraPage> {
    load(out).map(|s| s.index_entry())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::testing::Scratch;

    fn validation() -> PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../validation")
    }

    /// A few seconds in all: coarse drop and channel, short runs, one bisection step.
    fn tiny(option_sets: &[&str]) -> Config {
        let mut config = Config::load(&validation()).unwrap();
        config.settings = Settings {
            drop_dx: 0.1,
            drop_end: 4e-4,
            long_end: 6e-4,
            channel_dx: 0.2 / 12.0,
            channel_tau: 0.02,
            dt_range: [0.5, 4.0],
            dt_iterations: 1,
            re_range: [4.0, 400.0],
            re_iterations: 1,
            jitter: vec![0.2],
            seed: 1,
            drop_bound: 0.02,
            channel_bound: 0.05,
            option_sets: option_sets.iter().map(|s| s.to_string()).collect(),
        };
        config
    }

    #[test]
    fn stability_joins_the_cases_by_name_or_in_the_full_tier() {
        let names = |v: &[&str]| v.iter().map(|s| s.to_string()).collect::<Vec<_>>();
        assert_eq!(split_cases(&[], Tier::Quick), (vec![], true, false));
        assert_eq!(split_cases(&[], Tier::Default), (vec![], true, false));
        assert_eq!(split_cases(&[], Tier::Full), (vec![], true, true));
        assert_eq!(split_cases(&names(&["stability"]), Tier::Quick), (vec![], false, true));
        assert_eq!(
            split_cases(&names(&["elliptical_drop", "stability"]), Tier::Default),
            (names(&["elliptical_drop"]), true, true)
        );
        assert_eq!(
            split_cases(&names(&["elliptical_drop"]), Tier::Full),
            (names(&["elliptical_drop"]), true, false)
        );
        // The study's file is not a case: discovery does not see it.
        assert!(!crate::case::known_cases(&validation()).unwrap().iter().any(|c| c == NAME));
    }

    #[test]
    fn option_sets_patch_valid_scenes() {
        let config = Config::load(&validation()).unwrap();
        let drop = Base::drop(&config, &validation()).unwrap();
        let channel = Base::channel(&config, &validation()).unwrap();
        let parse = |v: Value| meniscus::Scene::from_json(&v.to_string()).unwrap();
        for set in &config.option_sets {
            for base in [&drop, &channel] {
                let scene = parse(base.scene(set, |_| {}).unwrap());
                assert_eq!(scene.scheme.key(), set.scheme, "{} on {}", set.name, base.case.case);
                match (&scene.scheme, set.name.as_str()) {
                    (meniscus::scene::Scheme::Isph(o), "none") => {
                        assert_eq!(o.shifting, meniscus::scene::Shifting::None)
                    }
                    (meniscus::scene::Scheme::Isph(o), "fickian") => {
                        assert!(matches!(o.shifting, meniscus::scene::Shifting::Fickian { .. }))
                    }
                    (meniscus::scene::Scheme::Isph(o), _) => {
                        assert!(matches!(o.shifting, meniscus::scene::Shifting::Xu { .. }))
                    }
                    (meniscus::scene::Scheme::Wcsph(o), name) => {
                        assert_eq!(
                            matches!(o.shifting, meniscus::scene::Shifting::Xu { .. }),
                            name == "wcsph_xu"
                        )
                    }
                    // MPS option sets differ in their own options, not in shifting.
                    (meniscus::scene::Scheme::Mps(_) | meniscus::scene::Scheme::Otm(_), _) => {}
                }
            }
        }
        // WCSPH: the drop's tuned preset; the channel at Mach 0.1 of its (edited) force.
        let wcsph = config.option_set("wcsph").unwrap();
        let meniscus::scene::Scheme::Wcsph(o) = parse(drop.scene(wcsph, |_| {}).unwrap()).scheme else {
            panic!("not a WCSPH scene")
        };
        assert!((o.sound_speed - 1000.0).abs() < 1e-12, "{}", o.sound_speed);
        let v = channel.scene(wcsph, |v| v["body_force"] = json!([6e-7, 0.0])).unwrap();
        let meniscus::scene::Scheme::Wcsph(o) = parse(v).scheme else { panic!("not a WCSPH scene") };
        // u_max = F D² / (8 ν) = 6e-7 × 0.04 / 8e-6 = 3e-3 m/s (Re = 400).
        assert!((o.sound_speed - 0.03).abs() < 1e-12, "{}", o.sound_speed);
        assert!(o.artificial_viscosity.is_some_and(|a| a.alpha.abs() < 1e-15 && a.beta.abs() < 1e-15));
        assert!(o.density_diffusion.is_some_and(|d| (d - 0.1).abs() < 1e-15));
    }

    /// The whole study on tiny settings: every study gives its rows, the page and the
    /// results file are written, the index links the page, and a second run reuses the
    /// cache, two runs at a time.
    #[test]
    fn tiny_envelope_produces_rows() {
        let dir = Scratch::new("stability");
        let opts = StabilityOptions {
            out: dir.path().join("reports"),
            validation_dir: validation(),
            workspace: dir.path().to_path_buf(),
            tier: Tier::Full,
            config: tiny(&["xu", "wcsph"]),
            force: false,
            jobs: 1,
            progress: false,
            slurm: None,
        };
        let res = run(&opts).unwrap();
        let studies: Vec<(&str, &str)> =
            res.runs.iter().map(|r| (r.study.as_str(), r.case.as_str())).collect();
        assert_eq!(
            studies,
            [
                ("dt_max", "elliptical_drop"),
                ("dt_max", "poiseuille_periodic"),
                ("re_max", "poiseuille_periodic"),
                ("jitter", "elliptical_drop"),
                ("jitter", "poiseuille_periodic"),
                ("long_run", "elliptical_drop"),
                // WCSPH: no Reynolds-number study.
                ("dt_max", "elliptical_drop"),
                ("dt_max", "poiseuille_periodic"),
                ("jitter", "elliptical_drop"),
                ("jitter", "poiseuille_periodic"),
                ("long_run", "elliptical_drop"),
            ]
        );
        assert!(res.runs[..6].iter().all(|r| r.run.scheme == "isph" && r.run.preset == "xu"));
        assert!(res.runs[6..].iter().all(|r| r.run.scheme == "wcsph" && r.run.preset == "wcsph"));
        assert_eq!(res.scheme, "isph, wcsph");
        for r in &res.runs {
            assert!(!r.trials.is_empty() && !r.outcome.is_empty(), "{r:?}");
            assert!(r.run.status == "ok" || r.run.status.starts_with("diverged: "), "{}", r.run.status);
        }
        // One bisection step: both ends and one midpoint, unless an end decided.
        let dt = &res.runs[0];
        assert!(matches!(dt.trials.len(), 1..=3), "{:?}", dt.trials);
        assert!(dt.measured.starts_with("k "));
        let long = &res.runs[5];
        assert!(long.run.metrics["ke_drift"].is_finite() && !long.run.series["e"].is_empty());
        assert!(res.complete && res.checks.len() == 15);
        assert_eq!(res.checks[0].value, Some(0.0), "no panic");
        assert!(res.executed > 0 && res.reused == 0);
        let back: StabilityResults = io::read_json(&opts.out.join("stability/results.json")).unwrap();
        let json = |r: &StabilityResults| serde_json::to_value(r).unwrap();
        assert_eq!(json(&back), json(&res), "results.json round-trips (NaN as null)");
        let page = std::fs::read_to_string(opts.out.join("stability/index.html")).unwrap();
        assert!(page.contains("dt_max") && page.contains("long_run") && page.contains("jitter"));
        let index = std::fs::read_to_string(opts.out.join("index.html")).unwrap();
        assert!(index.contains("stability/index.html"), "the index links the page");
        let again = run(&StabilityOptions { jobs: 2, ..opts.clone() }).unwrap();
        assert_eq!((again.executed, again.reused), (0, res.executed), "every run cached");
        assert_eq!(
            again.runs.iter().map(|r| &r.measured).collect::<Vec<_>>(),
            res.runs.iter().map(|r| &r.measured).collect::<Vec<_>>()
        );
    }

    /// The checks of the committed file on hand-made rows: a bound check reads the row's
    /// metric whatever its status, a missing row fails with the file's note, a panic
    /// counts, the jitter check wants both cases.
    #[test]
    fn checks_read_the_rows() {
        let specs = Config::load(&validation()).unwrap().checks;
        let row = |study: &str, case: &str, preset: &str, metrics: &[(&str, f64)]| Row {
            run: RunResult {
                scheme: "isph".into(),
                preset: preset.into(),
                dx: 0.04,
                start: None,
                particles: 1,
                steps: 1,
                wall_s: 1.0,
                cpu_s: None,
                threads: None,
                steady_at: None,
                status: "diverged: at step 3".into(),
                metrics: metrics.iter().map(|(k, v)| (k.to_string(), *v)).collect(),
                series: BTreeMap::new(),
            },
            study: study.into(),
            case: case.into(),
            config: String::new(),
            measured: String::new(),
            outcome: String::new(),
            trials: Vec::new(),
        };
        let rows = vec![
            row("dt_max", "elliptical_drop", "xu", &[("dt_multiple_max", 1.19)]),
            row("dt_max", "poiseuille_periodic", "xu", &[("dt_multiple_max", f64::NAN)]),
            row("jitter", "elliptical_drop", "xu", &[("jitter_fraction", 0.1)]),
        ];
        let out = checks(&specs, &rows, 1, Tier::Default);
        assert_eq!(out.len(), 15);
        assert_eq!((out[0].value, out[0].pass), (Some(1.0), false), "one panic");
        assert_eq!((out[1].value, out[1].threshold, out[1].pass), (Some(1.19), Some(1.0), true));
        assert_eq!(
            out[1].name,
            "drop (xu): largest stable multiple of the adaptive step ≥ 1 (Qiu's α = 0.2)"
        );
        let not_run = Some("not run (no result, or unstable over the whole range)".to_string());
        assert_eq!(
            (out[2].value, out[2].pass, &out[2].note),
            (None, false, &not_run),
            "NaN: unstable everywhere"
        );
        assert_eq!((out[3].value, out[3].pass, &out[3].note), (None, false, &not_run), "no row");
        assert_eq!((out[14].value, out[14].pass), (Some(0.0), false));
        assert_eq!(out[14].note.as_deref(), Some("not run for both cases"));
    }
}
