//! What `reports/work_precision/results.json` holds.

use super::channel::ChannelStudy;
use super::design::Variant;
use super::pipe::PipeStudy;
use crate::provenance::Provenance;
use crate::results::FLOOR_CORE_US_PER_PARTICLE_PASS;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// One run of the study. A diverged run is a row with its status and no error value.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RunRow {
    /// Stable id, e.g. `dx0.02_t2_bicgstab_1e-3-sym-std-xu-fixed` or `dx0.02_t2_mps-mps`.
    pub id: String,
    /// Spacing \[m\].
    pub dx: f64,
    /// The scheme of the run's scene: `isph`, `wcsph` or `mps` (`isph` in files written
    /// before the other schemes joined the study).
    #[serde(default = "isph")]
    pub scheme: String,
    /// The ISPH option set; absent for another scheme's preset.
    #[serde(flatten)]
    pub variant: Option<Variant>,
    /// The case preset the run is: `paper` or `tuned` when the ISPH option set is one of
    /// them, or the other scheme's preset (`wcsph_tuned`, `mps`).
    pub preset: Option<String>,
    /// The case file's reason when `preset` is expected to diverge at this spacing (its
    /// `expected_divergence`), so that such a row reads as expected; absent otherwise.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub expected_divergence: Option<String>,
    /// Rayon threads of the run.
    pub threads: usize,
    /// Parts of the design that asked for the run.
    pub groups: Vec<String>,
    /// Size and cost of the run.
    #[serde(flatten)]
    pub cost: Cost,
    /// Relative error of the semi-axis b (second moments) at the end time, t = 0.008 s,
    /// against the ellipse ODE (`b_rel_err_final`); `None` when the run diverged.
    pub b_err: Option<f64>,
    /// Largest relative b error over the history (`b_rel_err_max`).
    pub b_err_max: Option<f64>,
    /// Relative error of the semi-axis a at the end time (`a_rel_err_final`).
    pub a_err: Option<f64>,
    /// `ok` or `diverged: <cause at stage, step, time>`.
    pub status: String,
    /// Taken from the run cache of an earlier invocation (`cargo xtask bench --resume`):
    /// its times are those measured then. Absent when measured by this one.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub reused: bool,
}

/// The size and cost of a run, from the solver's summary (a row of either study).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Cost {
    /// Particles.
    pub particles: usize,
    /// Steps taken.
    pub steps: usize,
    /// Time reached \[s\].
    pub t_end: f64,
    /// Wall time of the stepping loop \[s\].
    pub wall_s: f64,
    /// CPU time of the threads that ran the run \[s\] (Linux): `cpu_s / wall_s` well below
    /// the thread count means the machine was busy.
    #[serde(default)]
    pub cpu_s: Option<f64>,
    /// Seconds per stage (the solver's `summary.json` `stages`, with `probes` and `guard`).
    pub stages: BTreeMap<String, f64>,
    /// Mean PPE iterations per step.
    pub ppe_iterations_mean: f64,
}

impl Cost {
    /// Wall time per step \[s\] (`None` before the first step).
    pub fn per_step(&self) -> Option<f64> {
        (self.steps > 0).then(|| self.wall_s / self.steps as f64)
    }

    /// CPU cost of one particle-step \[core-µs\] (none without a CPU time or a step).
    pub fn core_us_per_particle_step(&self) -> Option<f64> {
        crate::results::core_us_per_particle_step(self.cpu_s, (self.particles * self.steps) as f64)
    }

    /// [`Cost::core_us_per_particle_step`] over the floor of NUMERICS.md
    /// ([`FLOOR_CORE_US_PER_PARTICLE_PASS`]): how many fused pair passes a step is worth.
    pub fn floor_ratio(&self) -> Option<f64> {
        self.core_us_per_particle_step().map(|c| c / FLOOR_CORE_US_PER_PARTICLE_PASS)
    }
}

/// The scheme of a row in a file written before the study ran other schemes.
pub(crate) fn isph() -> String {
    "isph".into()
}

impl RunRow {
    /// Whether the run reached its end time.
    pub fn ok(&self) -> bool {
        self.status == "ok"
    }

    /// Whether the run is `preset` at `dx` with `threads` threads.
    pub fn is(&self, preset: &str, dx: f64, threads: usize) -> bool {
        self.preset.as_deref() == Some(preset) && (self.dx - dx).abs() < 1e-12 && self.threads == threads
    }
}

/// Cost per step against particle count, `cost = C N^p`, fitted by least squares in
/// log-log.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CostFit {
    /// Preset.
    pub preset: String,
    /// Threads of the runs fitted.
    pub threads: usize,
    /// Fitted exponent p.
    pub exponent: Option<f64>,
    /// Fitted constant C \[s\].
    pub constant: Option<f64>,
    /// Spacings of the fitted runs, coarse to fine \[m\].
    pub dx: Vec<f64>,
    /// Particles of the fitted runs.
    pub particles: Vec<usize>,
    /// Seconds per step of the fitted runs.
    pub cost_per_step_s: Vec<f64>,
}

/// The CPU cost per particle-step of one preset of a scheme on one case of the study,
/// from its finished runs with the study's main thread count, against the performance
/// floor of NUMERICS.md ([`FLOOR_CORE_US_PER_PARTICLE_PASS`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SchemeCost {
    /// `elliptical_drop` or `poiseuille_periodic`.
    pub case: String,
    /// `isph`, `wcsph` or `mps`.
    pub scheme: String,
    /// What ran: the case preset (`paper`, `tuned`, `wcsph_tuned`, `mps`; `re4`,
    /// `re4_implicit`), or for the channel's other schemes `<scheme> (options of the
    /// <preset> preset) · re4`.
    pub series: String,
    /// Threads of the runs.
    pub threads: usize,
    /// Each finished spacing, coarse to fine.
    pub spacings: Vec<SpacingCost>,
    /// Over all of them: summed CPU time over summed particles × steps \[core-µs\]; none
    /// when a run lacks its CPU time.
    pub core_us_per_particle_step: Option<f64>,
    /// `core_us_per_particle_step` over the floor: fused pair passes per step.
    pub floor_ratio: Option<f64>,
}

/// The cost of one run of a [`SchemeCost`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SpacingCost {
    /// Spacing \[m\].
    pub dx: f64,
    /// Particles.
    pub particles: usize,
    /// Steps.
    pub steps: usize,
    /// CPU time of the run \[core-s\].
    pub cpu_s: Option<f64>,
    /// `cpu_s / (particles × steps)` \[core-µs\].
    pub core_us_per_particle_step: Option<f64>,
    /// `core_us_per_particle_step` over the floor.
    pub floor_ratio: Option<f64>,
}

/// Wall time with one thread against the main thread count.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SpeedUp {
    /// Preset.
    pub preset: String,
    /// Spacing \[m\].
    pub dx: f64,
    /// Particles.
    pub particles: usize,
    /// Threads of the parallel run.
    pub threads: usize,
    /// Wall time with one thread \[s\].
    pub wall_1_s: f64,
    /// Wall time with `threads` threads \[s\].
    pub wall_n_s: f64,
    /// `wall_1_s / wall_n_s`.
    pub speedup: f64,
}

/// One target of the performance issue, evaluated.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Target {
    /// What is required.
    pub name: String,
    /// The measured value (`None` when not measured in this tier).
    pub value: Option<f64>,
    /// Unit of `value` and `threshold`.
    pub unit: String,
    /// `max` (value ≤ threshold) or `min` (value ≥ threshold).
    pub kind: String,
    /// The threshold.
    pub threshold: f64,
    /// Pass, fail, or `None` when not evaluated.
    pub pass: Option<bool>,
    /// How the value was obtained.
    pub note: String,
}

impl Target {
    /// `PASS`, `FAIL` or `n/a`.
    pub fn verdict(&self) -> &'static str {
        match self.pass {
            Some(true) => "PASS",
            Some(false) => "FAIL",
            None => "n/a",
        }
    }
}

/// The machine and build the study ran on.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Machine {
    /// Git commit, CPU model, logical CPUs, date (UTC).
    #[serde(flatten)]
    pub provenance: Provenance,
    /// `/proc/loadavg` when the study started (other work on the machine skews timings).
    pub loadavg_start: Option<String>,
    /// `/proc/loadavg` when it ended.
    pub loadavg_end: Option<String>,
    /// Cargo profile of the runs: `release`, or `dev` (opt-level 3 with debug assertions
    /// and overflow checks; about 8 % slower on the drop). Absent in older files.
    #[serde(default = "unknown_build")]
    pub build: String,
}

fn unknown_build() -> String {
    "unknown".into()
}

impl Machine {
    /// The profile this code was compiled in.
    pub fn current_build() -> String {
        if cfg!(debug_assertions) { "dev".into() } else { "release".into() }
    }
}

/// `reports/work_precision/results.json`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Study {
    /// `work_precision`.
    pub study: String,
    /// The case of the main study and of the targets (`elliptical_drop`; the channel's is
    /// in `channel.case`).
    pub case: String,
    /// `quick`, `default` or `full`.
    pub tier: String,
    /// False while the study is still running (the file is rewritten after every run).
    pub complete: bool,
    /// The error measure of the study.
    pub error_metric: String,
    /// Threads of the main runs.
    pub threads: usize,
    /// Thread counts of the thread study.
    pub thread_counts: Vec<usize>,
    /// The parts of the design.
    pub design: Vec<String>,
    /// Machine and build.
    pub machine: Machine,
    /// Wall time of the whole study \[s\].
    pub elapsed_s: f64,
    /// Every run, in the order run.
    pub runs: Vec<RunRow>,
    /// Ids of the runs on the Pareto front of (b error, wall time), main thread count,
    /// cheapest first.
    pub pareto: Vec<String>,
    /// Cost-per-step fits, per preset.
    pub cost_fits: Vec<CostFit>,
    /// One-thread against multi-thread wall times.
    pub speedups: Vec<SpeedUp>,
    /// The targets.
    pub targets: Vec<Target>,
    /// The periodic channel's study (absent in files written before it existed).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub channel: Option<ChannelStudy>,
    /// The 3D pipe's runs (absent in files written before it existed).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pipe: Option<PipeStudy>,
    /// Cost per particle-step of each scheme's presets on each case, against the floor
    /// (absent in files written before it existed).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub scheme_costs: Vec<SchemeCost>,
}

#[cfg(test)]
impl Study {
    /// A finished quick-tier study of the drop on two threads with `runs` and the channel
    /// study `channel`, nothing derived yet: the tests' starting point.
    pub(crate) fn for_test(design: Vec<String>, runs: Vec<RunRow>, channel: Option<ChannelStudy>) -> Study {
        Study {
            study: "work_precision".into(),
            case: super::CASE.into(),
            tier: "quick".into(),
            complete: true,
            error_metric: "b".into(),
            threads: 2,
            thread_counts: vec![1, 2],
            design,
            machine: Machine {
                provenance: Provenance::default(),
                loadavg_start: None,
                loadavg_end: None,
                build: "release".into(),
            },
            elapsed_s: 1.0,
            runs,
            pareto: vec![],
            cost_fits: vec![],
            speedups: vec![],
            targets: vec![],
            channel,
            pipe: None,
            scheme_costs: vec![],
        }
    }
}
