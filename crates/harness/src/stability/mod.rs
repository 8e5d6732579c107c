//! The stability envelope (`cargo xtask validate --case stability`, issue #6): for the
//! elliptical drop and the periodic channel, per option set of the scheme,
//!
//! - `dt_max`: the largest stable multiple k of the adaptive step (Qiu 2013 eqs. 17–18 with
//!   α_c = α_d = 0.2, i.e. `cfl = viscous = 0.2 k`, cap `k ×` the template's), by
//!   geometric bisection ([`bisect`]);
//! - `re_max` (channel): the largest Reynolds number stable to the end time (1 D²/ν), by
//!   bisection on the body force `F = 12 ν² Re / D³` at fixed ν;
//! - `jitter`: the initial lattice displaced by 10, 20, 30 % of Δx (`bodies[0].jitter`,
//!   seeded);
//! - `long_run` (drop): to t = 0.02 s, the kinetic-energy drift (the exact flow conserves it).
//!
//! A run is *stable* when it reaches its end time with no guard tripped and its error is
//! within the stated bound ([`Settings::drop_bound`] on the larger of the a and b errors over
//! the history; [`Settings::channel_bound`] on the velocity profile's L2 error at the end).
//! Every result is a [`Row`] of `reports/stability/results.json` ([`StabilityResults`],
//! shaped like a case's results file) and of `reports/stability/index.html` ([`page`]).
//! Runs are cached like the cases' (`reports/stability/runs/<slug>.json`, keyed by the
//! scene and the solver build), and `results.json` is rewritten after every row.

pub mod bisect;
pub mod page;

use crate::cache::{self, CachedProbes, RunRecord, sha256_hex};
use crate::case::Case;
use crate::error::{HarnessError, Result};
use crate::io;
use crate::patch::merge_patch;
use crate::progress::Progress;
use crate::provenance::Provenance;
use crate::results::CheckResult;
use crate::tier::Tier;
use bisect::{Bracket, bisect};
use serde::{Deserialize, Serialize};
use serde_json::{Value, json};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// The name of the study on the command line (`--case stability`) and its directory.
pub const NAME: &str = "stability";

/// Spacings, ranges and bounds of a stability run (the budget).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Settings {
    /// Spacing of the drop \[m\].
    pub drop_dx: f64,
    /// End time of the drop's time-step and jitter runs \[s\] (the case's 0.008 s).
    pub drop_end: f64,
    /// End time of the drop's long run \[s\].
    pub long_end: f64,
    /// Spacing of the channel \[m\].
    pub channel_dx: f64,
    /// End time of the channel runs in viscous times D²/ν.
    pub channel_tau: f64,
    /// Search range of the time-step multiple k.
    pub dt_range: [f64; 2],
    /// Bisection steps of k.
    pub dt_iterations: usize,
    /// Search range of the Reynolds number.
    pub re_range: [f64; 2],
    /// Bisection steps of Re.
    pub re_iterations: usize,
    /// Jitter fractions of Δx.
    pub jitter: Vec<f64>,
    /// Seed of the jitter.
    pub seed: u64,
    /// Stability bound on the drop's error (largest of a and b over the history).
    pub drop_bound: f64,
    /// Stability bound on the channel's profile L2 error at the end time.
    pub channel_bound: f64,
    /// Option sets run (names of [`OPTION_SETS`]).
    pub option_sets: Vec<String>,
}

impl Settings {
    /// The envelope as published: drop Δx = 0.04, channel D/18, about 5 minutes on 2 cores.
    pub fn standard() -> Self {
        Settings {
            drop_dx: 0.04,
            drop_end: 0.008,
            long_end: 0.02,
            channel_dx: 0.2 / 18.0,
            channel_tau: 1.0,
            // The scene rule cfl ≤ 1 caps k at 5.
            dt_range: [0.25, 5.0],
            dt_iterations: 4,
            re_range: [4.0, 4000.0],
            re_iterations: 4,
            jitter: vec![0.1, 0.2, 0.3],
            seed: 2026,
            drop_bound: 0.02,
            channel_bound: 0.05,
            option_sets: OPTION_SETS.iter().map(|o| o.0.to_string()).collect(),
        }
    }

    /// A few seconds in all (tests): coarse drop and channel, short runs, one option set.
    pub fn tiny() -> Self {
        Settings {
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
            option_sets: vec!["xu".into()],
        }
    }
}

/// The option sets compared: name and description. The ISPH sets are merge patches on the
/// scheme options of the case's template (the drop's `paper` preset, the channel's `re40`);
/// `wcsph` replaces the scheme (see [`Base::scene`]).
pub const OPTION_SETS: [(&str, &str); 6] = [
    ("xu", "Xu shifting C = 0.02, symmetric pressure gradient, Qiu's divergence (Qiu 2013)"),
    ("none", "no shifting"),
    ("xu_difference", "Xu shifting C = 0.02 with the difference pressure gradient"),
    ("fickian", "Fickian shifting A = 2 with the kernel-corrected divergence"),
    (
        WCSPH,
        "WCSPH: the drop's wcsph_tuned preset (c0 = 10 u_max, α = 0.02, δ-SPH 0.1, corrected continuity); \
         in the channel c0 = 10 × the Poiseuille centre-line speed F D²/(8ν), no artificial viscosity, δ-SPH 0.1",
    ),
    (WCSPH_XU, "wcsph with Xu shifting C = 0.02 (scheme.wcsph.shifting)"),
];

/// The scheme an option set runs.
fn scheme_of(set: &str) -> &'static str {
    if set.starts_with(WCSPH) { "wcsph" } else { "isph" }
}

/// The WCSPH option set's name (and the prefix of its shifted variant).
const WCSPH: &str = "wcsph";

/// The WCSPH option set with Xu shifting.
const WCSPH_XU: &str = "wcsph_xu";

/// The merge patch of option set `name` (for `wcsph` only the removal of the ISPH scheme;
/// [`Base::scene`] adds the WCSPH options).
fn option_patch(name: &str) -> Option<Value> {
    Some(match name {
        "xu" => json!({}),
        WCSPH | WCSPH_XU => json!({"scheme": {"isph": null}}),
        "none" => json!({"scheme": {"isph": {"shifting": null}}}),
        "xu_difference" => json!({"scheme": {"isph": {"pressure_gradient": "difference"}}}),
        "fickian" => json!({"scheme": {"isph": {
            "shifting": {"xu": null, "fickian": {"coefficient": 2.0}},
            "divergence": "corrected"}}}),
        _ => return None,
    })
}

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
            Some(format!("error {:.3} % above the bound {:.3} %", 100.0 * self.error, 100.0 * bound))
        } else {
            None
        }
    }
}

fn nan_map<'de, D: serde::Deserializer<'de>>(d: D) -> std::result::Result<BTreeMap<String, f64>, D::Error> {
    let m: BTreeMap<String, Option<f64>> = Deserialize::deserialize(d)?;
    Ok(m.into_iter().map(|(k, v)| (k, v.unwrap_or(f64::NAN))).collect())
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

/// One result of the envelope: a row of `results.json` and of the page. The first fields
/// are those of a run in a case's results file (DESIGN.md); `status` is that of the run that
/// decided the row (for a bisection, the smallest unstable value's run, `ok` when none).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Row {
    /// Scheme.
    pub scheme: String,
    /// Option set.
    pub preset: String,
    /// Spacing \[m\].
    pub dx: f64,
    /// Particles.
    pub particles: usize,
    /// Steps over all trials.
    pub steps: usize,
    /// Wall time over all trials \[s\].
    pub wall_s: f64,
    /// `ok` or `diverged: <cause>` of the deciding run.
    pub status: String,
    /// Measured quantities (`dt_multiple_max`, `re_max`, `ke_drift`, ...; null when none).
    #[serde(deserialize_with = "nan_map")]
    pub metrics: BTreeMap<String, f64>,
    /// Series: the values tried and whether each was stable (1) or not (0).
    #[serde(default)]
    pub series: BTreeMap<String, Vec<f64>>,
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
    /// False while the study runs (the file is rewritten after every row).
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
        let passed = self.checks.iter().filter(|c| c.pass).count();
        (passed, self.checks.len() - passed)
    }

    /// Whether every check passed.
    pub fn pass(&self) -> bool {
        self.checks.iter().all(|c| c.pass)
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
    /// Spacings, ranges and bounds.
    pub settings: Settings,
    /// Rerun cached runs.
    pub force: bool,
    /// Use the progress display (otherwise one plain line per run on stderr).
    pub progress: bool,
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

/// A case as the study uses it: its template at the study's spacing.
struct Base {
    case: Case,
    /// `drop` or `channel` (slug prefix).
    short: &'static str,
    /// The template preset.
    preset: &'static str,
    dx: f64,
    bound: f64,
}

impl Base {
    /// The scene of option set `set` with `edit` applied. For `wcsph`, the drop takes its
    /// case's `wcsph_tuned` preset and the channel a WCSPH scheme whose sound speed is ten
    /// times the centre-line speed `F D²/(8ν)` of the (edited) body force, so that a
    /// Reynolds-number or time-step edit keeps the Mach number at 0.1.
    fn scene(&self, set: &str, edit: impl FnOnce(&mut Value)) -> Result<Value> {
        let mut v = crate::sweep::effective_scene(&self.case, self.preset, self.dx)?;
        let patch = option_patch(set)
            .ok_or_else(|| HarnessError::case(NAME, format!("unknown option set `{set}`")))?;
        merge_patch(&mut v, &patch);
        let wcsph = scheme_of(set) == "wcsph";
        if wcsph && self.short == "drop" {
            let preset =
                self.case.sweep.presets.iter().find(|p| p.name == "wcsph_tuned").ok_or_else(|| {
                    HarnessError::case(NAME, format!("{} has no wcsph_tuned preset", self.case.case))
                })?;
            merge_patch(&mut v, &preset.patch);
        }
        edit(&mut v);
        if wcsph && self.short == "channel" {
            let width = match self.case.reference {
                crate::case::ReferenceSpec::PoiseuilleStartup { width, .. } => width,
                _ => return Err(HarnessError::case(NAME, "the channel has no start-up reference")),
            };
            let force = v["body_force"][0].as_f64().unwrap_or(0.0).abs();
            let nu = v["fluid"]["viscosity"].as_f64().unwrap_or(1e-3)
                / v["fluid"]["density"].as_f64().unwrap_or(1e3);
            let u_max = force * width * width / (8.0 * nu);
            v["scheme"] = json!({"wcsph": {"sound_speed": 10.0 * u_max,
                "artificial_viscosity": {"alpha": 0.0, "beta": 0.0}, "density_diffusion": 0.1}});
        }
        if set == WCSPH_XU {
            v["scheme"]["wcsph"]["shifting"] = json!({"xu": {"coefficient": 0.02}});
        }
        Ok(v)
    }
}

/// A trial with what the rows need besides it.
struct Measured {
    trial: Trial,
    particles: usize,
    probes: CachedProbes,
}

/// Whether two parameter values are the same point of a bisection.
fn same(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-12 * a.abs().max(b.abs())
}

/// The runner: runs (or reuses) trials and measures them.
struct Runner<'a> {
    opts: &'a StabilityOptions,
    dir: PathBuf,
    progress: Progress,
    executed: usize,
    reused: usize,
    panics: usize,
}

impl Runner<'_> {
    /// Bisects `[lo, hi]` over `iterations` trials of `base`: `scene(value)` gives the run's
    /// slug and scene. Returns the bracket, the trials and the largest particle count; the
    /// first error stops the bisection and is returned.
    fn bisect_trials(
        &mut self,
        base: &Base,
        (lo, hi, iterations): (f64, f64, usize),
        mut scene: impl FnMut(f64) -> (String, Result<Value>),
    ) -> Result<(Bracket, Vec<Trial>, usize)> {
        let mut trials = Vec::new();
        let mut particles = 0;
        let mut failure = None;
        let bracket = bisect(lo, hi, iterations, |value| {
            if failure.is_some() {
                return false;
            }
            let (slug, sc) = scene(value);
            match sc.and_then(|sc| self.trial(base, slug, value, sc)) {
                Ok(m) => {
                    particles = particles.max(m.particles);
                    let stable = m.trial.stable;
                    trials.push(m.trial);
                    stable
                }
                Err(e) => {
                    failure = Some(e);
                    false
                }
            }
        });
        match failure {
            Some(e) => Err(e),
            None => Ok((bracket, trials, particles)),
        }
    }

    /// Runs `scene` (cached by scene hash) and measures it against `base`'s reference.
    fn trial(&mut self, base: &Base, slug: String, value: f64, scene: Value) -> Result<Measured> {
        let parsed = meniscus::Scene::from_json(&scene.to_string())
            .map_err(|source| HarnessError::Scene { case: NAME.into(), run: slug.clone(), source })?;
        let canonical = serde_json::to_value(&parsed)
            .map_err(|e| HarnessError::case(NAME, format!("run {slug}: scene does not serialise: {e}")))?;
        let hash = sha256_hex(&format!("{}\n{canonical}", crate::sweep::build_fingerprint()));
        let path = cache::record_path(&self.dir, &slug);
        let cached = if self.opts.force { None } else { cache::load(&path, &hash) };
        let record = match cached {
            Some(r) => {
                self.reused += 1;
                Some(r)
            }
            None => {
                self.executed += 1;
                let run = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                    meniscus::run(&parsed, &mut meniscus::Quiet)
                }));
                match run {
                    Ok(report) => {
                        let report = report.map_err(|source| HarnessError::Scene {
                            case: NAME.into(),
                            run: slug.clone(),
                            source,
                        })?;
                        let record = RunRecord {
                            completed: true,
                            slug: slug.clone(),
                            scheme: if scene["scheme"].get("wcsph").is_some() { "wcsph" } else { "isph" }
                                .into(),
                            preset: String::new(),
                            dx: base.dx,
                            scene_hash: hash,
                            scene: canonical.clone(),
                            summary: report.summary,
                            probes: CachedProbes::from(report.probes),
                            snapshots: Vec::new(),
                            cpu_s: None,
                        };
                        cache::store(&path, &record)?;
                        Some(record)
                    }
                    Err(panic) => {
                        self.panics += 1;
                        let msg = panic
                            .downcast_ref::<String>()
                            .cloned()
                            .or_else(|| panic.downcast_ref::<&str>().map(|s| s.to_string()))
                            .unwrap_or_else(|| "unknown panic".into());
                        let trial = Trial {
                            value,
                            slug,
                            status: format!("panic: {msg}"),
                            steps: 0,
                            t_final: 0.0,
                            wall_s: 0.0,
                            error: f64::NAN,
                            stable: false,
                        };
                        self.print(&trial);
                        return Ok(Measured { trial, particles: 0, probes: CachedProbes::default() });
                    }
                }
            }
        };
        let r = record.expect("a record unless the run panicked");
        let probes = meniscus::ProbeRecord::from(r.probes.clone());
        let measured =
            crate::metrics::compute(&base.case.reference, &canonical, &probes, r.summary.particles)
                .map_err(|source| HarnessError::Reference { case: NAME.into(), source })?;
        let error = match base.short {
            "drop" => {
                let a = measured.metrics.get("a_rel_err_max").copied().unwrap_or(f64::NAN);
                let b = measured.metrics.get("b_rel_err_max").copied().unwrap_or(f64::NAN);
                if a.is_nan() || b.is_nan() { f64::NAN } else { a.max(b) }
            }
            _ => measured.series.get("u_profile_l2_rel").and_then(|s| s.last().copied()).unwrap_or(f64::NAN),
        };
        let ok = r.summary.status == meniscus::Status::Ok && r.summary.error.is_none();
        let status = if ok {
            "ok".to_string()
        } else {
            format!("diverged: {}", r.summary.error.as_deref().unwrap_or("unknown cause"))
        };
        let trial = Trial {
            value,
            slug,
            status,
            steps: r.summary.steps,
            t_final: r.summary.t_end,
            wall_s: r.summary.wall_s,
            error,
            stable: ok && error <= base.bound,
        };
        self.print(&trial);
        Ok(Measured { trial, particles: r.summary.particles, probes: r.probes })
    }

    /// One line per run (plainly on stderr when the display is hidden, as the cases do).
    fn print(&self, t: &Trial) {
        self.progress.println(&format!(
            "  {} {} ({:.1} s, {} steps, error {})",
            t.slug,
            if t.stable { "stable" } else { "unstable" },
            t.wall_s,
            t.steps,
            pct(t.error)
        ));
    }
}

/// A parameter value in a slug: up to 4 decimals, trailing zeros dropped.
fn slug_value(v: f64) -> String {
    let s = format!("{v:.4}");
    s.trim_end_matches('0').trim_end_matches('.').to_string()
}

/// Assembles a bisection row from its trials.
#[allow(clippy::too_many_arguments)]
fn bisection_row(
    base: &Base,
    set: &str,
    study: &str,
    config: String,
    symbol: &str,
    bracket: Bracket,
    trials: Vec<Trial>,
    particles: usize,
) -> Row {
    let mut metrics = BTreeMap::new();
    let at_stable = bracket.stable().and_then(|s| trials.iter().find(|t| same(t.value, s)));
    let unstable_value = match bracket {
        Bracket::Found { unstable, .. } => Some(unstable),
        Bracket::Below(lo) => Some(lo),
        Bracket::AtLeast(_) => None,
    };
    let deciding = unstable_value.and_then(|u| trials.iter().find(|t| same(t.value, u)));
    let key = if study == "dt_max" { "dt_multiple" } else { "re" };
    metrics.insert(format!("{key}_max"), bracket.stable().unwrap_or(f64::NAN));
    metrics.insert(format!("{key}_unstable"), unstable_value.unwrap_or(f64::NAN));
    metrics.insert("err_at_max".into(), at_stable.map_or(f64::NAN, |t| t.error));
    if study == "dt_max" {
        let mean_dt = at_stable.map_or(f64::NAN, |t| t.t_final / t.steps.max(1) as f64);
        metrics.insert("dt_mean_s_at_max".into(), mean_dt);
    }
    let mut sorted: Vec<&Trial> = trials.iter().collect();
    sorted.sort_by(|a, b| a.value.total_cmp(&b.value));
    let series = BTreeMap::from([
        ("value".to_string(), sorted.iter().map(|t| t.value).collect()),
        ("stable".to_string(), sorted.iter().map(|t| if t.stable { 1.0 } else { 0.0 }).collect()),
    ]);
    Row {
        scheme: scheme_of(set).into(),
        preset: set.into(),
        dx: base.dx,
        particles,
        steps: trials.iter().map(|t| t.steps).sum(),
        wall_s: trials.iter().map(|t| t.wall_s).sum(),
        status: deciding.map_or("ok".into(), |t| t.status.clone()),
        metrics,
        series,
        study: study.into(),
        case: base.case.case.clone(),
        config,
        measured: format!("{symbol} {}", bracket.describe()),
        outcome: deciding
            .map(|t| {
                format!(
                    "at {symbol} = {}: {}",
                    bisect::sig3(t.value),
                    t.reason(base.bound).unwrap_or_default()
                )
            })
            .unwrap_or_else(|| "ok".into()),
        trials,
    }
}

/// A one-run row (jitter, long run).
fn single_row(base: &Base, set: &str, study: &str, config: String, trial: Trial, particles: usize) -> Row {
    Row {
        scheme: scheme_of(set).into(),
        preset: set.into(),
        dx: base.dx,
        particles,
        steps: trial.steps,
        wall_s: trial.wall_s,
        status: if trial.status.starts_with("panic") {
            format!("diverged: {}", trial.status)
        } else {
            trial.status.clone()
        },
        metrics: BTreeMap::from([("err".to_string(), trial.error), ("t_final".to_string(), trial.t_final)]),
        series: BTreeMap::new(),
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
    let s = &opts.settings;
    for set in &s.option_sets {
        if option_patch(set).is_none() {
            return Err(HarnessError::case(NAME, format!("unknown option set `{set}`")));
        }
    }
    let drop = Base {
        case: Case::load(&opts.validation_dir.join("elliptical_drop.json"))?,
        short: "drop",
        preset: "paper",
        dx: s.drop_dx,
        bound: s.drop_bound,
    };
    let channel = Base {
        case: Case::load(&opts.validation_dir.join("poiseuille_periodic.json"))?,
        short: "channel",
        preset: "re40",
        dx: s.channel_dx,
        bound: s.channel_bound,
    };
    let dir = opts.out.join(NAME);
    let mut runner = Runner {
        opts,
        dir: dir.clone(),
        progress: Progress::new(opts.progress),
        executed: 0,
        reused: 0,
        panics: 0,
    };
    let mut results = StabilityResults {
        case: NAME.into(),
        scheme: {
            let mut schemes: Vec<&str> = s.option_sets.iter().map(|o| scheme_of(o)).collect();
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
    let nu_of = |v: &Value| {
        v["fluid"]["viscosity"].as_f64().unwrap_or(1e-3) / v["fluid"]["density"].as_f64().unwrap_or(1e3)
    };
    // The channel's width and viscous time, from its reference and template.
    let width = match channel.case.reference {
        crate::case::ReferenceSpec::PoiseuilleStartup { width, .. } => width,
        _ => return Err(HarnessError::case(NAME, "poiseuille_periodic has no start-up reference")),
    };
    let nu = nu_of(&channel.case.scene);
    let channel_end = s.channel_tau * width * width / nu;
    // Channel runs end at channel_tau D²/ν, with the probe times up to there.
    let channel_time = |v: &mut Value| {
        v["time"]["end"] = json!(channel_end);
        if let Some(times) = v["output"]["probe_times"].as_array_mut() {
            times.retain(|t| t.as_f64().is_some_and(|t| t < channel_end * (1.0 - 1e-9)));
        }
    };
    let drop_end = s.drop_end;
    let drop_time = |v: &mut Value| v["time"]["end"] = json!(drop_end);
    let save = |results: &mut StabilityResults, runner: &Runner, start: &Instant| -> Result<()> {
        results.elapsed_s = start.elapsed().as_secs_f64();
        results.executed = runner.executed;
        results.reused = runner.reused;
        io::write_json(&dir.join("results.json"), results)
    };

    for set in &s.option_sets {
        // Largest stable multiple of the adaptive step.
        for (base, time) in [(&drop, &drop_time as &dyn Fn(&mut Value)), (&channel, &channel_time)] {
            let template_max =
                crate::sweep::effective_scene(&base.case, base.preset, base.dx)?["time"]["step"]["adaptive"]
                    ["max"]
                    .as_f64()
                    .unwrap_or(1e-3);
            let (bracket, trials, particles) =
                runner.bisect_trials(base, (s.dt_range[0], s.dt_range[1], s.dt_iterations), |k| {
                    let scene = base.scene(set, |v| {
                        time(v);
                        v["time"]["step"] = json!({"adaptive": {"cfl": 0.2 * k, "viscous": 0.2 * k, "max": template_max * k}});
                    });
                    (format!("{}-{set}-dt_k{}", base.short, slug_value(k)), scene)
                })?;
            let config = format!(
                "{}, dx = {}, to t = {} s; Δt = k × adaptive step (α_c = α_d = 0.2 k), k bisected in [{}, {}]",
                base.case.case,
                crate::report::html::format_dx(base.dx),
                bisect::sig3(if base.short == "drop" { drop_end } else { channel_end }),
                s.dt_range[0],
                s.dt_range[1]
            );
            results.runs.push(bisection_row(base, set, "dt_max", config, "k", bracket, trials, particles));
            save(&mut results, &runner, &start)?;
        }
        // Largest stable Reynolds number of the channel: ISPH only. WCSPH's acoustic step
        // (c0 ∝ Re) needs about 1e3 Re steps to 1 D²/ν (measured: 39 064 at Re = 40), four
        // million at the range's Re = 4000.
        if scheme_of(set) == "isph" {
            let (bracket, trials, particles) =
                runner.bisect_trials(&channel, (s.re_range[0], s.re_range[1], s.re_iterations), |re| {
                    let force = 12.0 * nu * nu * re / width.powi(3);
                    let scene = channel.scene(set, |v| {
                        channel_time(v);
                        v["body_force"] = json!([force, 0.0]);
                    });
                    (format!("channel-{set}-re{}", slug_value(re)), scene)
                })?;
            let config = format!(
                "poiseuille_periodic, dx = {}, to {} D²/ν; F = 12 ν² Re / D³ (ν = {nu:e} m²/s), adaptive step (α = 0.2), Re bisected in [{}, {}]",
                crate::report::html::format_dx(channel.dx),
                s.channel_tau,
                s.re_range[0],
                s.re_range[1]
            );
            results
                .runs
                .push(bisection_row(&channel, set, "re_max", config, "Re", bracket, trials, particles));
            save(&mut results, &runner, &start)?;
        }
        // Jittered initial lattices.
        for (base, time) in [(&drop, &drop_time as &dyn Fn(&mut Value)), (&channel, &channel_time)] {
            for &f in &s.jitter {
                let scene = base.scene(set, |v| {
                    time(v);
                    v["bodies"][0]["jitter"] = json!({"fraction": f, "seed": s.seed});
                })?;
                let slug = format!("{}-{set}-jitter{}", base.short, slug_value(f));
                let Measured { trial, particles, .. } = runner.trial(base, slug, f, scene)?;
                let config = format!(
                    "{}, dx = {}, lattice jittered by {} % of dx (seed {}), the case's time step",
                    base.case.case,
                    crate::report::html::format_dx(base.dx),
                    bisect::sig3(100.0 * f),
                    s.seed
                );
                let mut row = single_row(base, set, "jitter", config, trial, particles);
                row.metrics.insert("jitter_fraction".into(), f);
                row.measured = if row.status == "ok" {
                    format!("error {}", pct(row.metrics["err"]))
                } else {
                    format!("diverged at t = {} s", bisect::sig3(row.metrics["t_final"]))
                };
                results.runs.push(row);
            }
            save(&mut results, &runner, &start)?;
        }
        // The drop's long run: kinetic-energy drift.
        {
            let long_end = s.long_end;
            let scene = drop.scene(set, |v| v["time"]["end"] = json!(long_end))?;
            let slug = format!("drop-{set}-long{}", slug_value(long_end));
            let Measured { trial, particles, probes } = runner.trial(&drop, slug, long_end, scene)?;
            let e = probes.series.get("kinetic_energy").and_then(|q| q.get("e")).cloned().unwrap_or_default();
            let drift = crate::metrics::drift(&e);
            let (e_series, t_series) = (e, probes.t);
            let config = format!(
                "elliptical_drop, dx = {}, to t = {} s (the case ends at 0.008 s), the case's time step",
                crate::report::html::format_dx(drop.dx),
                bisect::sig3(long_end)
            );
            let mut row = single_row(&drop, set, "long_run", config, trial, particles);
            // The long run's verdict is the energy drift, not the axes' error.
            row.outcome = if row.status == "ok" { "ok".into() } else { row.status.clone() };
            row.metrics.insert("ke_drift".into(), drift);
            row.measured = if row.status == "ok" {
                format!("KE drift {}", pct(drift))
            } else {
                let t = row.trials.first().map_or(f64::NAN, |t| t.t_final);
                format!("diverged at t = {} s (KE drift {} up to there)", bisect::sig3(t), pct(drift))
            };
            row.series = BTreeMap::from([("t".to_string(), t_series), ("e".to_string(), e_series)]);
            results.runs.push(row);
            save(&mut results, &runner, &start)?;
        }
    }
    results.checks = checks(&results, runner.panics);
    results.complete = true;
    save(&mut results, &runner, &start)?;
    let page = page::render(&results);
    io::write_atomic(&dir.join("index.html"), page.as_bytes())?;
    // The index links the study.
    let cases = Some(crate::case::known_cases(&opts.validation_dir)?);
    let extras = vec![results.index_entry()];
    crate::report::render(&opts.out, &crate::report::RenderOptions { cases, baseline: None, extras })?;
    Ok(results)
}

/// A fraction in percent (`1.234 %`, `—`).
pub(crate) fn pct(v: f64) -> String {
    if v.is_finite() { format!("{:.3} %", 100.0 * v) } else { "—".into() }
}

/// The envelope's checks, stated before the numbers were known (issue #6): no panic and
/// every run explained; Qiu's α = 0.2 step stable for the drop and the channel; the channel
/// stable at Re = 400 to 1 D²/ν; the drop's energy drift to 0.02 s within 2 %; the paper's
/// option set within its error bound with a 10 % jitter. The time-step and energy checks
/// are repeated for WCSPH (added with its option set).
pub fn checks(results: &StabilityResults, panics: usize) -> Vec<CheckResult> {
    let row = |study: &str, case: &str, set: &str| {
        results.runs.iter().find(|r| r.study == study && r.case == case && r.preset == set)
    };
    let metric =
        |r: Option<&Row>, m: &str| r.and_then(|r| r.metrics.get(m).copied()).filter(|v| v.is_finite());
    let min = |name: &str, value: Option<f64>, threshold: f64, missing: &str| CheckResult {
        name: name.into(),
        value,
        threshold: Some(threshold),
        pass: value.is_some_and(|v| v >= threshold),
        note: value.is_none().then(|| missing.to_string()),
    };
    let max = |name: &str, value: Option<f64>, threshold: f64, missing: &str| CheckResult {
        name: name.into(),
        value,
        threshold: Some(threshold),
        pass: value.is_some_and(|v| v <= threshold),
        note: value.is_none().then(|| missing.to_string()),
    };
    let unexplained = results
        .runs
        .iter()
        .flat_map(|r| &r.trials)
        .filter(|t| !(t.status == "ok" || t.status.starts_with("diverged: ")))
        .count();
    let mut out = vec![max(
        "every stress run ends at its end time or with a typed, explained error (count of panics and others)",
        Some((panics + unexplained) as f64),
        0.0,
        "",
    )];
    let none = "not run (no result, or unstable over the whole range)";
    out.push(min(
        "drop (xu): largest stable multiple of the adaptive step ≥ 1 (Qiu's α = 0.2)",
        metric(row("dt_max", "elliptical_drop", "xu"), "dt_multiple_max"),
        1.0,
        none,
    ));
    out.push(min(
        "channel (xu): largest stable multiple of the adaptive step ≥ 1 (Qiu's α = 0.2)",
        metric(row("dt_max", "poiseuille_periodic", "xu"), "dt_multiple_max"),
        1.0,
        none,
    ));
    out.push(min(
        "channel (xu): stable at Re = 400 to the end time",
        metric(row("re_max", "poiseuille_periodic", "xu"), "re_max"),
        400.0,
        none,
    ));
    out.push(max(
        "drop (xu): kinetic-energy drift of the long run ≤ 2 %",
        metric(row("long_run", "elliptical_drop", "xu"), "ke_drift"),
        0.02,
        "not run or not measurable (diverged before the first sample)",
    ));
    // The same bounds for WCSPH, without and with shifting (no Reynolds-number study: see
    // `run`).
    for set in [WCSPH, WCSPH_XU] {
        out.push(min(
            &format!("drop ({set}): largest stable multiple of the adaptive step ≥ 1"),
            metric(row("dt_max", "elliptical_drop", set), "dt_multiple_max"),
            1.0,
            none,
        ));
        out.push(min(
            &format!("channel ({set}): largest stable multiple of the adaptive step ≥ 1"),
            metric(row("dt_max", "poiseuille_periodic", set), "dt_multiple_max"),
            1.0,
            none,
        ));
        out.push(max(
            &format!("drop ({set}): kinetic-energy drift of the long run ≤ 2 %"),
            metric(row("long_run", "elliptical_drop", set), "ke_drift"),
            0.02,
            "not run or not measurable (diverged before the first sample)",
        ));
    }
    let jittered: Vec<&Row> = results
        .runs
        .iter()
        .filter(|r| r.study == "jitter" && r.preset == "xu")
        .filter(|r| r.metrics.get("jitter_fraction").is_some_and(|f| (f - 0.1).abs() < 1e-12))
        .collect();
    let failing = jittered.iter().filter(|r| !r.trials.iter().all(|t| t.stable)).count();
    out.push(CheckResult {
        name: "xu: drop and channel stable with a 10 % jitter (runs outside the bound)".into(),
        value: Some(failing as f64),
        threshold: Some(0.0),
        pass: jittered.len() == 2 && failing == 0,
        note: (jittered.len() != 2).then(|| "not run for both cases".to_string()),
    });
    out
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
    }

    #[test]
    fn option_sets_patch_valid_scenes() {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../validation");
        let case = Case::load(&dir.join("elliptical_drop.json")).unwrap();
        let base = Base { case, short: "drop", preset: "paper", dx: 0.04, bound: 0.02 };
        for &(set, _) in OPTION_SETS.iter().filter(|(s, _)| scheme_of(s) == "isph") {
            let v = base.scene(set, |_| {}).unwrap();
            let scene = meniscus::Scene::from_json(&v.to_string()).unwrap_or_else(|e| panic!("{set}: {e}"));
            let meniscus::scene::Scheme::Isph(o) = &scene.scheme else { panic!("{set}: not an ISPH scene") };
            match set {
                "none" => assert_eq!(o.shifting, meniscus::scene::Shifting::None),
                "fickian" => assert!(matches!(o.shifting, meniscus::scene::Shifting::Fickian { .. })),
                _ => assert!(matches!(o.shifting, meniscus::scene::Shifting::Xu { .. })),
            }
        }
        assert!(base.scene("bogus", |_| {}).is_err());
        // WCSPH: the drop's tuned preset; the channel at Mach 0.1 of its (edited) force.
        let v = base.scene(WCSPH, |_| {}).unwrap();
        let scene = meniscus::Scene::from_json(&v.to_string()).unwrap();
        let meniscus::scene::Scheme::Wcsph(o) = &scene.scheme else { panic!("not a WCSPH scene") };
        assert!((o.sound_speed - 1000.0).abs() < 1e-12, "{}", o.sound_speed);
        let case = Case::load(&dir.join("poiseuille_periodic.json")).unwrap();
        let channel = Base { case, short: "channel", preset: "re40", dx: 0.2 / 18.0, bound: 0.05 };
        let v = channel.scene(WCSPH, |v| v["body_force"] = json!([6e-7, 0.0])).unwrap();
        let scene = meniscus::Scene::from_json(&v.to_string()).unwrap();
        let meniscus::scene::Scheme::Wcsph(o) = &scene.scheme else { panic!("not a WCSPH scene") };
        // u_max = F D² / (8 ν) = 6e-7 × 0.04 / 8e-6 = 3e-3 m/s (Re = 400).
        assert!((o.sound_speed - 0.03).abs() < 1e-12, "{}", o.sound_speed);
        assert_eq!(o.shifting, meniscus::scene::Shifting::None);
        let v = channel.scene(WCSPH_XU, |_| {}).unwrap();
        let scene = meniscus::Scene::from_json(&v.to_string()).unwrap();
        let meniscus::scene::Scheme::Wcsph(o) = &scene.scheme else { panic!("not a WCSPH scene") };
        assert!(matches!(o.shifting, meniscus::scene::Shifting::Xu { .. }));
    }

    /// The whole runner on tiny settings: every study gives its rows, the page and the
    /// results file are written, the index links the page, and a second run reuses the cache.
    #[test]
    fn tiny_envelope_produces_rows() {
        let dir = Scratch::new("stability");
        let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
        let opts = StabilityOptions {
            out: dir.path().join("reports"),
            validation_dir: root.join("validation"),
            workspace: dir.path().to_path_buf(),
            tier: Tier::Full,
            settings: Settings { option_sets: vec!["xu".into(), WCSPH.into()], ..Settings::tiny() },
            force: false,
            progress: false,
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
        assert!(res.runs[..6].iter().all(|r| r.scheme == "isph" && r.preset == "xu"));
        assert!(res.runs[6..].iter().all(|r| r.scheme == "wcsph" && r.preset == WCSPH));
        assert_eq!(res.scheme, "isph, wcsph");
        for r in &res.runs {
            assert!(!r.trials.is_empty() && !r.outcome.is_empty(), "{r:?}");
            assert!(r.status == "ok" || r.status.starts_with("diverged: "), "{}", r.status);
        }
        // One bisection step: both ends and one midpoint, unless an end decided.
        let dt = &res.runs[0];
        assert!(matches!(dt.trials.len(), 1..=3), "{:?}", dt.trials);
        assert!(dt.measured.starts_with("k "));
        let long = &res.runs[5];
        assert!(long.metrics["ke_drift"].is_finite() && !long.series["e"].is_empty());
        assert!(res.complete && res.checks.len() == 12);
        assert_eq!(res.checks[0].value, Some(0.0), "no panic");
        assert!(res.executed > 0 && res.reused == 0);
        let back: StabilityResults = io::read_json(&opts.out.join("stability/results.json")).unwrap();
        assert_eq!(back.runs.len(), res.runs.len());
        let page = std::fs::read_to_string(opts.out.join("stability/index.html")).unwrap();
        assert!(page.contains("dt_max") && page.contains("long_run") && page.contains("jitter"));
        let index = std::fs::read_to_string(opts.out.join("index.html")).unwrap();
        assert!(index.contains("stability/index.html"), "the index links the page");
        let again = run(&opts).unwrap();
        assert_eq!((again.executed, again.reused), (0, res.executed), "every run cached");
        assert_eq!(
            again.runs.iter().map(|r| &r.measured).collect::<Vec<_>>(),
            res.runs.iter().map(|r| &r.measured).collect::<Vec<_>>()
        );
    }
}
