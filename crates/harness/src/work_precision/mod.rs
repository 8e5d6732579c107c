//! `cargo xtask bench`: the work-precision study of the elliptical drop and the periodic
//! Poiseuille channel ([`channel`]).
//!
//! Every run of a pruned design over spacing × PPE solver and tolerance × gradient form ×
//! divergence form × shifting × time-step rule ([`design`]) goes through the solver
//! in-process, one run at a time, each on a rayon pool of the requested thread count. Per
//! run the study records wall time, steps, particles, seconds per stage, mean PPE
//! iterations, the b error at t = 0.008 s against the ellipse ODE (the harness's
//! elliptical-drop metrics) and the status; a diverged run is a row, never an abort.
//! From the rows alone it then derives the Pareto front, the cost-per-step fits and the
//! speed-ups and evaluates the performance issue's targets ([`targets`]), draws the figures
//! ([`plots`]) and writes `results.json`, one SVG per figure and `index.html` into the
//! output directory, atomically (`results.json` is also rewritten, marked incomplete,
//! after every run, so an interrupted study keeps what it measured). The channel's runs
//! follow the drop's and are recorded in the `channel` field of `results.json`, with their
//! own Pareto front and figure; the targets are the drop's.

pub mod channel;
pub mod design;
pub mod page;
pub mod pareto;
pub mod plots;
pub mod record;
pub mod targets;

use crate::case::Case;
use crate::error::{HarnessError, Result};
use crate::io;
use crate::metrics;
use crate::provenance::Provenance;
use crate::tier::Tier;
use channel::ChannelStudy;
use design::{Design, Planned, Ppe, Variant};
use record::{Machine, RunRow, Study};
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Options of a study.
#[derive(Debug, Clone)]
pub struct Options {
    /// Tier: `quick` (Δx 0.04, 0.02), `default` (to 0.01) or `full` (to 0.005).
    pub tier: Tier,
    /// Output directory (`reports/work_precision`).
    pub out: PathBuf,
    /// Directory of the case files (`validation/`).
    pub validation_dir: PathBuf,
    /// Workspace root (for git provenance).
    pub workspace: PathBuf,
    /// Threads of the main runs (the thread study compares 1 with this).
    pub threads: usize,
    /// Print one line per run on stderr.
    pub progress: bool,
}

/// The case the study runs.
pub const CASE: &str = "elliptical_drop";

fn study_error(message: impl Into<String>) -> HarnessError {
    HarnessError::case("work_precision", message)
}

/// CPU time of this process, user + system, all threads \[s\] (`/proc/self/stat` fields 14
/// and 15, in clock ticks of 1/100 s, the Linux value); `None` off Linux.
fn process_cpu_s() -> Option<f64> {
    let stat = std::fs::read_to_string("/proc/self/stat").ok()?;
    // Fields after the command name (which may hold spaces) start at field 3.
    let rest = &stat[stat.rfind(')')? + 1..];
    let f: Vec<&str> = rest.split_whitespace().collect();
    let ticks = f.get(11)?.parse::<f64>().ok()? + f.get(12)?.parse::<f64>().ok()?;
    Some(ticks / 100.0)
}

fn loadavg() -> Option<String> {
    std::fs::read_to_string("/proc/loadavg")
        .ok()
        .map(|s| s.split_whitespace().take(3).collect::<Vec<_>>().join(" "))
}

/// What running one scene gave: the solver's report, or the message of a panic inside it;
/// and the process CPU time over the run.
pub struct Outcome {
    /// The report (which may carry a divergence), or the panic message.
    pub report: std::result::Result<meniscus::RunReport, String>,
    /// CPU time of the process over the run \[s\] (`None` off Linux).
    pub cpu_s: Option<f64>,
}

/// Runs `scene` on `pool`; a panic inside the solver is caught and becomes the outcome.
fn run_scene(
    scene: &meniscus::Scene,
    pool: &rayon::ThreadPool,
) -> std::result::Result<Outcome, meniscus::SceneError> {
    let cpu0 = process_cpu_s();
    let outcome = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        pool.install(|| meniscus::run(scene, &mut meniscus::Quiet))
    }));
    let cpu_s = process_cpu_s().zip(cpu0).map(|(b, a)| b - a);
    let report = match outcome {
        Ok(Ok(report)) => Ok(report),
        Ok(Err(source)) => return Err(source),
        Err(panic) => Err(panic
            .downcast_ref::<String>()
            .cloned()
            .or_else(|| panic.downcast_ref::<&str>().map(|s| s.to_string()))
            .unwrap_or_else(|| "unknown".into())),
    };
    Ok(Outcome { report, cpu_s })
}

/// Runs the study and writes its directory; missed targets are results, not errors.
pub fn run(opts: &Options) -> Result<Study> {
    let case = Case::load(&opts.validation_dir.join(format!("{CASE}.json")))?;
    let channel_case = Case::load(&opts.validation_dir.join(format!("{}.json", channel::CASE)))?;
    let threads = opts.threads.max(1);
    let design = Design::for_tier(opts.tier, threads);
    let (channel_runs, channel_design) = channel::design(opts.tier, threads);
    let mut provenance = Provenance::collect(&opts.workspace);
    provenance.threads = threads;
    let mut study = Study {
        study: "work_precision".into(),
        case: CASE.into(),
        tier: opts.tier.name().into(),
        complete: false,
        error_metric: "b_rel_err_final: |b(t) / b_ODE(t) − 1| at t = 0.008 s, b from second moments".into(),
        threads,
        thread_counts: design.thread_counts.clone(),
        design: design.description.clone(),
        machine: Machine {
            provenance,
            loadavg_start: loadavg(),
            loadavg_end: None,
            build: Machine::current_build(),
        },
        elapsed_s: 0.0,
        runs: Vec::new(),
        pareto: Vec::new(),
        cost_fits: Vec::new(),
        speedups: Vec::new(),
        targets: Vec::new(),
        channel: Some(ChannelStudy::new(channel_design)),
    };
    let mut pools = Vec::new();
    for &k in &design.thread_counts {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(k)
            .build()
            .map_err(|e| study_error(format!("cannot build a rayon pool of {k} threads: {e}")))?;
        pools.push((k, pool));
    }
    let start = Instant::now();
    let total = design.runs.len() + channel_runs.len();
    let pool_of =
        |threads: usize| &pools.iter().find(|(k, _)| *k == threads).expect("a pool per thread count").1;
    let progress = |i: usize, id: &str, wall_s: f64, cpu_s: Option<f64>, error: String, status: &str| {
        if opts.progress {
            eprintln!(
                "[{:>3}/{total}] {:<52} {:>8.2} s (CPU/wall {:>4})  {error}  {status}  ({:.0} s elapsed)",
                i + 1,
                id,
                wall_s,
                cpu_s.map_or("—".into(), |c| format!("{:.2}", c / wall_s.max(1e-12))),
                start.elapsed().as_secs_f64()
            );
        }
    };
    let pct = |e: Option<f64>| e.map_or("—".into(), |e| format!("{:.3} %", 100.0 * e));
    for (i, planned) in design.runs.iter().enumerate() {
        let row = execute(&case, planned, pool_of(planned.threads))?;
        let status = if row.ok() { "ok" } else { &row.status };
        progress(i, &row.id, row.wall_s, row.cpu_s, format!("b err {:>9}", pct(row.b_err)), status);
        study.runs.push(row);
        study.elapsed_s = start.elapsed().as_secs_f64();
        io::write_json(&opts.out.join("results.json"), &study)?;
    }
    for (i, planned) in channel_runs.iter().enumerate() {
        let scene = channel::scene(&channel_case, &planned.variant, planned.dx)?;
        let outcome = run_scene(&scene, pool_of(planned.threads)).map_err(|source| HarnessError::Scene {
            case: channel_case.case.clone(),
            run: planned.id(),
            source,
        })?;
        let row = channel::row(&channel_case, planned, &scene, outcome)?;
        let status = if row.ok() { "ok" } else { &row.status };
        let error = format!("profile err {:>9}", pct(row.error));
        progress(design.runs.len() + i, &row.id, row.wall_s, row.cpu_s, error, status);
        if let Some(c) = &mut study.channel {
            c.runs.push(row);
        }
        study.elapsed_s = start.elapsed().as_secs_f64();
        io::write_json(&opts.out.join("results.json"), &study)?;
    }
    study.elapsed_s = start.elapsed().as_secs_f64();
    study.machine.loadavg_end = loadavg();
    study.complete = true;
    derive(&mut study, opts.tier);
    write(&opts.out, &study)?;
    Ok(study)
}

/// Fills the Pareto front, fits, speed-ups and targets of a study from its runs.
pub fn derive(study: &mut Study, tier: Tier) {
    let finest = match tier {
        Tier::Quick => 0.02,
        Tier::Default => 0.01,
        Tier::Full => 0.005,
    };
    study.pareto = targets::pareto_ids(&study.runs, study.threads);
    study.cost_fits = targets::cost_fits(&study.runs, study.threads);
    study.speedups = targets::speedups(&study.runs, study.threads);
    study.targets = targets::evaluate(&study.runs, study.threads, finest);
    if let Some(c) = &mut study.channel {
        c.derive();
    }
}

/// Runs one planned point on `pool`; a divergence (or a panic inside the solver) becomes
/// the row's status.
fn execute(case: &Case, planned: &Planned, pool: &rayon::ThreadPool) -> Result<RunRow> {
    let scene = design::scene(case, &planned.variant, planned.dx)?;
    let id = planned.id();
    let outcome = run_scene(&scene, pool).map_err(|source| HarnessError::Scene {
        case: case.case.clone(),
        run: id.clone(),
        source,
    })?;
    let cpu_s = outcome.cpu_s;
    let m = measure(case, &scene, outcome)?;
    let get = |k: &str| m.metrics.get(k).copied();
    Ok(RunRow {
        dx: planned.dx,
        variant: planned.variant,
        preset: planned.variant.preset().map(str::to_string),
        threads: planned.threads,
        groups: planned.groups.clone(),
        particles: m.particles,
        steps: m.steps,
        t_end: m.t_end,
        wall_s: m.wall_s,
        cpu_s,
        b_err: get("b_rel_err_final"),
        b_err_max: get("b_rel_err_max"),
        a_err: get("a_rel_err_final"),
        stages: m.stages,
        ppe_iterations_mean: m.ppe_iterations_mean,
        status: m.status,
        id,
    })
}

/// What a work-precision row takes from a run: its size and cost, its status, and the
/// case's finite metrics when it reached its end time (none after a divergence).
pub(crate) struct Measured {
    pub particles: usize,
    pub steps: usize,
    pub t_end: f64,
    pub wall_s: f64,
    pub stages: std::collections::BTreeMap<String, f64>,
    pub ppe_iterations_mean: f64,
    pub status: String,
    pub metrics: std::collections::BTreeMap<String, f64>,
}

/// Reads the `outcome` of a run of `scene`: a panic or a divergence becomes the status
/// (`diverged: …`), a finished run gets the metrics of `case`'s reference.
pub(crate) fn measure(case: &Case, scene: &meniscus::Scene, outcome: Outcome) -> Result<Measured> {
    let mut m = Measured {
        particles: 0,
        steps: 0,
        t_end: 0.0,
        wall_s: 0.0,
        stages: Default::default(),
        ppe_iterations_mean: 0.0,
        status: "ok".into(),
        metrics: Default::default(),
    };
    let report = match outcome.report {
        Ok(report) => report,
        Err(msg) => {
            m.status = format!("diverged: the solver panicked: {msg}");
            return Ok(m);
        }
    };
    let s = &report.summary;
    (m.particles, m.steps, m.t_end, m.wall_s) = (s.particles, s.steps, s.t_end, s.wall_s);
    m.stages = s.stages.clone();
    m.ppe_iterations_mean = s.ppe_iterations_mean;
    if let Some(e) = &report.error {
        m.status = format!("diverged: {e}");
        return Ok(m);
    }
    let scene_json = serde_json::to_value(scene).unwrap_or_default();
    let measured = metrics::compute(&case.reference, &scene_json, &report.probes, s.particles)
        .map_err(|source| HarnessError::Reference { case: case.case.clone(), source })?;
    m.metrics = measured.metrics.into_iter().filter(|(_, v)| v.is_finite()).collect();
    Ok(m)
}

/// The runs shown in the stage breakdown: the presets at every spacing, and the PPE
/// solver variants of both presets at Δx = 0.02.
fn breakdown_bars(study: &Study) -> Vec<(String, &RunRow)> {
    let mut bars = Vec::new();
    let main = |r: &&RunRow| r.threads == study.threads && r.steps > 0;
    let mut dxs: Vec<f64> = study.runs.iter().map(|r| r.dx).collect();
    dxs.sort_by(|a, b| b.total_cmp(a));
    dxs.dedup_by(|a, b| (*a - *b).abs() < 1e-12);
    for dx in dxs {
        for (name, v) in [("paper", Variant::PAPER), ("tuned", Variant::TUNED)] {
            for ppe in [Ppe::Bicgstab3, Ppe::Bicgstab5, Ppe::Cg3, Ppe::Direct] {
                if ppe != Ppe::Bicgstab3 && (dx - 0.02).abs() > 1e-12 {
                    continue;
                }
                let want = Variant { ppe, ..v };
                if let Some(r) =
                    study.runs.iter().filter(main).find(|r| r.variant == want && (r.dx - dx).abs() < 1e-12)
                {
                    let suffix = if ppe == Ppe::Bicgstab3 {
                        String::new()
                    } else {
                        format!(" {}", want.label().split(' ').next().unwrap_or(""))
                    };
                    bars.push((format!("{name} Δx={dx}{suffix}"), r));
                }
            }
        }
    }
    bars
}

/// Draws the figures of a study.
pub fn figures(study: &Study) -> Result<Vec<page::Figure>> {
    let main: Vec<&RunRow> = study.runs.iter().filter(|r| r.threads == study.threads).collect();
    let one: Vec<&RunRow> = study.runs.iter().filter(|r| r.threads == 1 && study.threads != 1).collect();
    let mut out = vec![
        page::Figure {
            file: "work_precision".into(),
            svg: plots::work_precision("work_precision", &main, &study.pareto)?,
            caption: format!(
                "Wall time against b error at t = 0.008 s, every finished run with {} threads; the black line joins the Pareto front.",
                study.threads
            ),
        },
        page::Figure {
            file: "stages".into(),
            svg: plots::stage_breakdown("stages", &breakdown_bars(study))?,
            caption: "Seconds per stage divided by particles × steps (µs per particle-step): the presets at every spacing and their PPE solver variants at Δx = 0.02.".into(),
        },
        page::Figure {
            file: "cost_scaling".into(),
            svg: plots::cost_scaling("cost_scaling", &study.cost_fits, &one)?,
            caption: "Wall time per step against particle count with the least-squares power law (log-log) of each preset; hollow markers: one thread.".into(),
        },
    ];
    if let Some(c) = study.channel.as_ref().filter(|c| !c.runs.is_empty()) {
        let rows: Vec<&channel::ChannelRow> = c.runs.iter().collect();
        out.push(page::Figure {
            file: "channel_work_precision".into(),
            svg: plots::channel_work_precision("channel_work_precision", &rows, &c.pareto)?,
            caption: format!(
                "Periodic channel (Re = 4, to τ = νt/D² = 1): wall time against the steady profile error, every finished run with {} threads; the black line joins the Pareto front.",
                study.threads
            ),
        });
    }
    if !study.speedups.is_empty() {
        out.push(page::Figure {
            file: "speedup".into(),
            svg: plots::speedup("speedup", &study.speedups, study.threads)?,
            caption: format!("Speed-up of {} threads over one at each spacing (the same run on pools of 1 and {} threads).", study.threads, study.threads),
        });
    }
    Ok(out)
}

/// Writes `results.json`, the SVGs and `index.html` into `out`, each atomically.
pub fn write(out: &Path, study: &Study) -> Result<()> {
    io::write_json(&out.join("results.json"), study)?;
    let figs = figures(study)?;
    for f in &figs {
        io::write_atomic(&out.join(format!("{}.svg", f.file)), f.svg.as_bytes())?;
    }
    io::write_atomic(&out.join("index.html"), page::render(study, &figs).as_bytes())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::testing::Scratch;

    #[test]
    fn a_tiny_study_writes_well_formed_files() {
        let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
        let case = Case::load(&root.join("validation/elliptical_drop.json")).unwrap();
        let pool = rayon::ThreadPoolBuilder::new().num_threads(1).build().unwrap();
        let mut study = Study {
            study: "work_precision".into(),
            case: CASE.into(),
            tier: "quick".into(),
            complete: true,
            error_metric: "b".into(),
            threads: 2,
            thread_counts: vec![1, 2],
            design: vec!["test".into()],
            machine: Machine {
                provenance: Provenance::default(),
                loadavg_start: None,
                loadavg_end: None,
                build: "release".into(),
            },
            elapsed_s: 1.0,
            runs: vec![],
            pareto: vec![],
            cost_fits: vec![],
            speedups: vec![],
            targets: vec![],
            channel: Some(ChannelStudy::new("test".into())),
        };
        // A short drop at a coarse spacing: end time cut to 10 steps.
        let mut short = case.clone();
        short.scene["time"]["end"] = serde_json::json!(2e-4);
        for (v, threads) in [(Variant::PAPER, 2), (Variant::TUNED, 2), (Variant::PAPER, 1)] {
            let planned = Planned { dx: 0.08, variant: v, threads, groups: vec!["test".into()] };
            let row = execute(&short, &planned, &pool).unwrap();
            assert!(row.ok(), "{}", row.status);
            assert_eq!(row.steps, 10);
            assert!(row.b_err.unwrap() < 0.05);
            assert!(row.stages.contains_key("ppe_solve"));
            assert!(row.cpu_s.is_some_and(|c| c >= 0.0));
            study.runs.push(row);
        }
        // The channel with implicit viscosity at D/36 to τ = 1 (about 670 steps).
        let ch_case = Case::load(&root.join("validation/poiseuille_periodic.json")).unwrap();
        let planned = channel::ChannelPlanned {
            dx: channel::D36,
            variant: channel::ChannelVariant::IMPLICIT,
            threads: 1,
        };
        let scene = channel::scene(&ch_case, &planned.variant, planned.dx).unwrap();
        let row = channel::row(&ch_case, &planned, &scene, run_scene(&scene, &pool).unwrap()).unwrap();
        assert!(row.ok(), "{}", row.status);
        assert_eq!((row.particles, row.preset.as_deref()), (648, Some("re4_implicit")));
        assert!(row.error.is_some_and(|e| e < 0.05), "{:?}", row.error);
        assert!(row.stages.contains_key("viscosity_implicit"));
        study.channel.as_mut().unwrap().runs.push(row);
        derive(&mut study, Tier::Quick);
        assert!(!study.pareto.is_empty());
        assert_eq!(study.channel.as_ref().unwrap().pareto.len(), 1);
        assert_eq!(study.targets.len(), 6);
        let dir = Scratch::new("work-precision");
        write(dir.path(), &study).unwrap();
        let html = std::fs::read_to_string(dir.path().join("index.html")).unwrap();
        assert!(html.contains("Targets") && html.contains("<svg"));
        assert!(html.contains("Periodic channel") && html.contains("re4_implicit"));
        for f in ["work_precision", "stages", "cost_scaling", "channel_work_precision"] {
            let svg = std::fs::read_to_string(dir.path().join(format!("{f}.svg"))).unwrap();
            assert!(svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"), "{f}");
        }
        let back: Study = io::read_json(&dir.path().join("results.json")).unwrap();
        assert_eq!(back.runs.len(), 3);
        assert_eq!(back.runs[0].variant, Variant::PAPER);
        assert_eq!(back.channel, study.channel);
        // A file written before the channel study existed still reads.
        let mut old = serde_json::to_value(&study).unwrap();
        old.as_object_mut().unwrap().remove("channel");
        assert_eq!(serde_json::from_value::<Study>(old).unwrap().channel, None);
    }
}
