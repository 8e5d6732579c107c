//! `cargo xtask bench`: the work-precision study of the elliptical drop and the periodic
//! Poiseuille channel ([`channel`]).
//!
//! Every run of a pruned design over spacing × PPE solver and tolerance × gradient form ×
//! divergence form × shifting × time-step rule ([`design`]), and the case's WCSPH and MPS
//! presets at every spacing, goes through the harness's runner ([`crate::runner`]), one run
//! at a time, each on a rayon pool of the requested thread count. Per run the study records wall time, steps, particles, seconds per stage,
//! mean PPE iterations, the process CPU time, the b error at t = 0.008 s against the
//! ellipse ODE (the harness's elliptical-drop metrics) and the status; a diverged run (or
//! one whose solver panicked) is a row, never an abort. From the rows alone it then derives
//! the Pareto front of each scheme, the cost-per-step fits and the speed-ups and evaluates
//! the performance issue's targets ([`targets`]), the cost per particle-step of each
//! scheme's presets against the floor of NUMERICS.md ([`costs`]), draws the figures
//! ([`plots`]) and writes `results.json`,
//! one SVG per figure and `index.html` into the output directory, atomically
//! (`results.json` is also rewritten, marked incomplete, after every run, so an interrupted
//! study keeps what it measured). The channel's runs follow the drop's and are recorded in
//! the `channel` field of `results.json`, with their own Pareto fronts and figure (an MPS
//! point beside the ISPH option sets); the targets are the drop's ISPH presets'. Last, the
//! 3D pipe's ISPH and WCSPH presets ([`pipe`], the `pipe` field) add particle-steps per
//! second and each run's peak memory, in bytes and per particle, with their own table and
//! figure.
//!
//! Reuse: every run's record is cached in `<out>/runs/<id>.json`, but a study measures
//! every run again by default, so that all its times come from one invocation under one
//! machine load (recorded in `machine`). `resume` (`cargo xtask bench --resume`) reuses the
//! records of the same build and scenes, to finish an interrupted study: a reused row is
//! marked `reused` in `results.json` and on the page, and its times are those measured when
//! it ran.

pub mod channel;
pub mod costs;
pub mod design;
pub mod page;
pub mod pareto;
pub mod pipe;
pub mod plots;
pub mod record;
pub mod targets;

use crate::case::Case;
use crate::error::Result;
use crate::io;
use crate::metrics;
use crate::progress::Progress;
use crate::provenance::Provenance;
use crate::runner::{Job, Ran, Runner};
use crate::sweep::RunSpec;
use crate::tier::Tier;
use channel::ChannelStudy;
use design::{Design, Planned, Ppe, Variant};
use record::{Cost, Machine, RunRow, Study};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::Mutex;
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
    /// Reuse the cached runs of an earlier invocation (see the module documentation).
    pub resume: bool,
    /// Run what is not cached on this Slurm cluster instead of this machine.
    pub slurm: Option<std::sync::Arc<crate::slurm::Cluster>>,
}

/// The case the study runs.
pub const CASE: &str = "elliptical_drop";

fn loadavg() -> Option<String> {
    std::fs::read_to_string("/proc/loadavg")
        .ok()
        .map(|s| s.split_whitespace().take(3).collect::<Vec<_>>().join(" "))
}

/// A job of the study: run `id` of `case` with `scene`, on `threads` threads.
fn job(case: &Case, id: String, dx: f64, scene: meniscus::Scene, threads: usize) -> Result<Job> {
    let preset = id.clone();
    Ok(Job { threads: Some(threads), ..Job::new(RunSpec::new(&case.case, id, &preset, dx, scene)?) })
}

/// Runs the study and writes its directory; missed targets are results, not errors.
pub fn run(opts: &Options) -> Result<Study> {
    let case = Case::load(&opts.validation_dir.join(format!("{CASE}.json")))?;
    let channel_case = Case::load(&opts.validation_dir.join(format!("{}.json", channel::CASE)))?;
    let pipe_case = Case::load(&opts.validation_dir.join(format!("{}.json", pipe::CASE)))?;
    let threads = opts.threads.max(1);
    let design = Design::for_tier(opts.tier, threads);
    let (channel_runs, channel_design) = channel::design(opts.tier, threads);
    let (pipe_runs, pipe_design) = pipe::design(&pipe_case, opts.tier, threads)?;
    let mut provenance = Provenance::collect(&opts.workspace);
    provenance.threads = threads;
    let study = Mutex::new(Study {
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
        pipe: Some(pipe::PipeStudy::new(pipe_design)),
        scheme_costs: Vec::new(),
    });
    let start = Instant::now();
    let total = design.runs.len() + channel_runs.len() + pipe_runs.len();
    let progress = if opts.progress { Progress::new(true) } else { Progress::silent() };
    let runner = Runner::new(progress, !opts.resume, 1).with_slurm(opts.slurm.clone());
    // One line per run, and results.json rewritten with the run's row.
    let record = |i: usize,
                  id: &str,
                  cost: &Cost,
                  error: String,
                  status: &str,
                  reused: bool,
                  add: &dyn Fn(&mut Study)| {
        let mut s = study.lock().unwrap_or_else(|e| e.into_inner());
        add(&mut s);
        s.elapsed_s = start.elapsed().as_secs_f64();
        io::write_json(&opts.out.join("results.json"), &*s)?;
        let cpu = cost.cpu_s.map_or("—".into(), |c| format!("{:.2}", c / cost.wall_s.max(1e-12)));
        Ok(format!(
            "[{:>3}/{total}] {:<52} {:>8.2} s (CPU/wall {:>4})  {error}  {status}  ({:.0} s elapsed){}",
            i + 1,
            id,
            cost.wall_s,
            cpu,
            start.elapsed().as_secs_f64(),
            if reused { " cached" } else { "" }
        ))
    };
    let pct = |e: Option<f64>| e.map_or("—".into(), crate::numbers::percent);
    let jobs = design
        .runs
        .iter()
        .map(|p| job(&case, p.id(), p.dx, design::scene(&case, &p.setup, p.dx)?, p.threads))
        .collect::<Result<Vec<_>>>()?;
    runner.run(&opts.out, None, &jobs, |i, ran| {
        let row = drop_row(&case, &design.runs[i], &ran)?;
        let status = if row.ok() { "ok" } else { &row.status };
        let error = format!("b err {:>9}", pct(row.b_err));
        let line = record(i, &row.id, &row.cost, error, status, row.reused, &|s| s.runs.push(row.clone()))?;
        Ok(((), line))
    })?;
    let jobs = channel_runs
        .iter()
        .map(|p| job(&channel_case, p.id(), p.dx, channel::scene(&channel_case, &p.setup, p.dx)?, p.threads))
        .collect::<Result<Vec<_>>>()?;
    runner.run(&opts.out, None, &jobs, |i, ran| {
        let row = channel::row(&channel_case, &channel_runs[i], &ran)?;
        let status = if row.ok() { "ok" } else { &row.status };
        let error = format!("profile err {:>9}", pct(row.error));
        let add = |s: &mut Study| s.channel.iter_mut().for_each(|c| c.runs.push(row.clone()));
        let line = record(design.runs.len() + i, &row.id, &row.cost, error, status, row.reused, &add)?;
        Ok(((), line))
    })?;
    // The pipe's runs one batch each, so that the process's peak memory during a batch is
    // its run's.
    for (i, planned) in pipe_runs.iter().enumerate() {
        pipe::run(&runner, &opts.out, &pipe_case, planned, |row| {
            let status = if row.ok() { "ok" } else { &row.status };
            let memory = row.bytes_per_particle.map_or("—".into(), |b| format!("{b:.0} B/particle"));
            let error = format!("profile err {:>9}  {memory}", pct(row.error));
            let add = |s: &mut Study| s.pipe.iter_mut().for_each(|p| p.runs.push(row.clone()));
            let i = design.runs.len() + channel_runs.len() + i;
            record(i, &row.id, &row.cost, error, status, row.reused, &add)
        })?;
    }
    let mut study = study.into_inner().unwrap_or_else(|e| e.into_inner());
    study.elapsed_s = start.elapsed().as_secs_f64();
    study.machine.loadavg_end = loadavg();
    study.complete = true;
    derive(&mut study, opts.tier);
    write(&opts.out, &study)?;
    Ok(study)
}

/// Fills the Pareto fronts, fits, speed-ups, targets and scheme costs of a study from its
/// runs.
pub fn derive(study: &mut Study, tier: Tier) {
    let finest = *design::spacings(tier).last().expect("every tier has spacings");
    study.pareto = targets::pareto_ids(&study.runs, study.threads);
    study.cost_fits = targets::cost_fits(&study.runs, study.threads);
    study.speedups = targets::speedups(&study.runs, study.threads);
    study.targets = targets::evaluate(&study.runs, study.threads, finest);
    if let Some(c) = &mut study.channel {
        c.derive();
    }
    study.scheme_costs = costs::scheme_costs(study);
}

/// The row of a planned drop run from how it ran; a divergence (or a panic inside the
/// solver) is the row's status, and one the case file expects of its preset at its spacing
/// says so.
fn drop_row(case: &Case, planned: &Planned, ran: &Ran) -> Result<RunRow> {
    let m = measure(case, ran)?;
    let get = |k: &str| m.metrics.get(k).copied();
    Ok(RunRow {
        id: planned.id(),
        dx: planned.dx,
        scheme: planned.setup.scheme().to_string(),
        variant: planned.setup.variant(),
        preset: planned.setup.preset().map(str::to_string),
        expected_divergence: expected_divergence(case, planned),
        threads: planned.threads,
        groups: planned.groups.clone(),
        b_err: get("b_rel_err_final"),
        b_err_max: get("b_rel_err_max"),
        a_err: get("a_rel_err_final"),
        cost: m.cost,
        status: m.status,
        reused: ran.reused(),
    })
}

/// The case file's reason when the preset a planned drop run is (its scene is the
/// preset's) is expected to diverge at the run's spacing.
fn expected_divergence(case: &Case, planned: &Planned) -> Option<String> {
    let preset = planned.setup.preset()?;
    let p = case.sweep.presets.iter().find(|p| p.name == preset)?;
    p.expected_divergence_at(planned.dx).map(str::to_string)
}

/// What a work-precision row takes from a run: its size and cost, its status, and the
/// case's finite metrics when it reached its end time (none after a divergence).
pub(crate) struct Measured {
    pub cost: Cost,
    pub status: String,
    pub metrics: BTreeMap<String, f64>,
}

/// Reads how a run of `case` went: a panic or a divergence becomes the status
/// (`diverged: …`), a finished run gets the metrics of `case`'s reference.
pub(crate) fn measure(case: &Case, ran: &Ran) -> Result<Measured> {
    let status = ran.status();
    let Some(record) = ran.record() else {
        return Ok(Measured { cost: Cost::default(), status, metrics: BTreeMap::new() });
    };
    let s = &record.summary;
    let cost = Cost {
        particles: s.particles,
        steps: s.steps,
        t_end: s.t_end,
        wall_s: s.wall_s,
        cpu_s: record.cpu_s,
        stages: s.stages.clone(),
        ppe_iterations_mean: s.ppe_iterations_mean,
    };
    if status != "ok" {
        return Ok(Measured { cost, status, metrics: BTreeMap::new() });
    }
    let probes = meniscus::ProbeRecord::from(record.probes.clone());
    let measured = metrics::compute(&case.reference, &record.scene, &probes, s.particles, s.steady_at)
        .map_err(|source| crate::error::HarnessError::Reference { case: case.case.clone(), source })?;
    let metrics = measured.metrics.into_iter().filter(|(_, v)| v.is_finite()).collect();
    Ok(Measured { cost, status, metrics })
}

/// The runs shown in the stage breakdown: at every spacing the `paper` and `tuned` presets
/// (with their own PPE solvers) and the other schemes' presets, and at Δx = 0.02 the
/// presets with each other PPE solver (labelled by it).
fn breakdown_bars(study: &Study) -> Vec<(String, &RunRow)> {
    let mut bars = Vec::new();
    let main = |r: &&RunRow| r.threads == study.threads && r.cost.steps > 0;
    let mut dxs: Vec<f64> = study.runs.iter().map(|r| r.dx).collect();
    dxs.sort_by(|a, b| b.total_cmp(a));
    dxs.dedup_by(|a, b| (*a - *b).abs() < 1e-12);
    let at = |dx: f64| move |r: &&RunRow| (r.dx - dx).abs() < 1e-12;
    for dx in dxs {
        for (name, v) in [("paper", Variant::PAPER), ("tuned", Variant::TUNED)] {
            let others =
                [Ppe::Bicgstab3, Ppe::Bicgstab5, Ppe::Cg3, Ppe::Direct].into_iter().filter(|&p| p != v.ppe);
            for ppe in std::iter::once(v.ppe).chain(others) {
                if ppe != v.ppe && (dx - 0.02).abs() > 1e-12 {
                    continue;
                }
                let want = Variant { ppe, ..v };
                if let Some(r) =
                    study.runs.iter().filter(main).filter(at(dx)).find(|r| r.variant == Some(want))
                {
                    let suffix = if ppe == v.ppe {
                        String::new()
                    } else {
                        format!(" {}", want.label().split(' ').next().unwrap_or(""))
                    };
                    bars.push((format!("{name} Δx={dx}{suffix}"), r));
                }
            }
        }
        for r in study.runs.iter().filter(main).filter(at(dx)).filter(|r| r.variant.is_none()) {
            let preset = r.preset.as_deref().unwrap_or("");
            bars.push((format!("{} {preset} Δx={dx}", r.scheme), r));
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
                "Wall time against b error at t = 0.008 s, every finished run with {} threads: colour the spacing, marker the scheme (disc ISPH, triangle WCSPH, cross MPS); the black lines join each scheme's Pareto front.",
                study.threads
            ),
        },
        page::Figure {
            file: "stages".into(),
            svg: plots::stage_breakdown("stages", &breakdown_bars(study))?,
            caption: "Seconds per stage divided by particles × steps (µs per particle-step): the ISPH presets (with their own PPE solvers) and the WCSPH and MPS presets at every spacing, and the ISPH presets with the other PPE solvers at Δx = 0.02.".into(),
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
                "Periodic channel (Re = 4, to τ = νt/D² = 1): wall time against the steady profile error, every finished run with {} threads: colour the spacing, marker the scheme (disc ISPH, cross MPS); the black lines join each scheme's Pareto front.",
                study.threads
            ),
        });
    }
    if let Some(p) = study.pipe.as_ref().filter(|p| !p.runs.is_empty()) {
        let rows: Vec<&pipe::PipeRow> = p.runs.iter().collect();
        out.push(page::Figure {
            file: "pipe_work_precision".into(),
            svg: plots::pipe_work_precision("pipe_work_precision", &rows)?,
            caption: "3D pipe (Hagen–Poiseuille, Re = 1, to ν t/R² = 1): wall time against the steady profile error, every finished run: colour the spacing (the tier's R/Δx of 8, 12, 16: Δx = 0.00125, 0.00083, 0.000625 m), marker the scheme (disc ISPH qiu, triangle WCSPH wcsph_xu).".into(),
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

/// The report index's link to the study's page, when `out` (the validation's output
/// directory) holds a finished study in `work_precision/`.
pub fn extra_page(out: &Path) -> Option<crate::report::ExtraPage> {
    let study: Study = io::read_json(&out.join("work_precision").join("results.json")).ok()?;
    let missed = study.targets.iter().filter(|t| t.pass == Some(false)).count();
    Some(crate::report::ExtraPage {
        href: "work_precision/index.html".into(),
        title: "Work-precision study".into(),
        summary: format!(
            "run time against error for every scheme and spacing: {} runs, tier {}, {:.0} s, \
             {} / {} targets met{}",
            study.runs.len(),
            study.tier,
            study.elapsed_s,
            study.targets.iter().filter(|t| t.pass == Some(true)).count(),
            study.targets.iter().filter(|t| t.pass.is_some()).count(),
            if study.complete { "" } else { " (incomplete)" }
        ),
        pass: missed == 0 && study.complete,
    })
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
    use design::Setup;

    /// A row of a preset says where the case file expects the preset to diverge (the drop's
    /// `mps` at its finest spacings), and an option set that is no preset expects nothing.
    #[test]
    fn rows_say_where_the_case_file_expects_a_divergence() {
        let case = crate::case::testing::committed("elliptical_drop");
        let mps = design::SCHEME_PRESETS[1];
        let preset = case.sweep.presets.iter().find(|p| p.name == mps.preset).unwrap();
        let at = |setup: Setup, dx: f64| {
            expected_divergence(&case, &Planned { dx, setup, threads: 2, groups: vec![] })
        };
        let spacings = design::spacings(Tier::Full);
        for &dx in spacings {
            assert_eq!(at(Setup::Preset(mps), dx).as_deref(), preset.expected_divergence_at(dx), "dx {dx}");
        }
        assert!(spacings.iter().any(|&dx| at(Setup::Preset(mps), dx).is_some()));
        let adaptive = Variant { dt: design::Dt::Adaptive, ..Variant::PAPER };
        assert!(spacings.iter().all(|&dx| at(Setup::Isph(adaptive), dx).is_none()));
    }

    #[test]
    fn a_tiny_study_writes_well_formed_files() {
        let case = crate::case::testing::committed("elliptical_drop");
        let mut study = Study::for_test(vec!["test".into()], vec![], Some(ChannelStudy::new("test".into())));
        let dir = Scratch::new("work-precision");
        // A short drop at a coarse spacing: end time cut to 10 steps.
        let mut short = case.clone();
        short.scene["time"]["end"] = serde_json::json!(2e-4);
        let planned: Vec<Planned> = [
            (Setup::Isph(Variant::PAPER), 2),
            (Setup::Isph(Variant::TUNED), 2),
            (Setup::Isph(Variant::PAPER), 1),
            (Setup::Preset(design::SCHEME_PRESETS[0]), 2),
            (Setup::Preset(design::SCHEME_PRESETS[1]), 2),
        ]
        .into_iter()
        .map(|(setup, threads)| Planned { dx: 0.08, setup, threads, groups: vec!["test".into()] })
        .collect();
        let jobs: Vec<Job> = planned
            .iter()
            .map(|p| {
                job(&short, p.id(), p.dx, design::scene(&short, &p.setup, p.dx).unwrap(), p.threads).unwrap()
            })
            .collect();
        let finish = |i: usize, ran: Ran| Ok((drop_row(&short, &planned[i], &ran)?, String::new()));
        let runner = Runner::new(Progress::silent(), true, 1);
        for row in runner.run(dir.path(), None, &jobs, finish).unwrap() {
            assert!(row.ok() && !row.reused, "{}", row.status);
            assert!(row.b_err.unwrap() < 0.05, "{}: {:?}", row.id, row.b_err);
            assert!(row.cost.cpu_s.is_some_and(|c| c >= 0.0));
            assert_eq!(row.expected_divergence, None);
            if row.scheme == "isph" {
                // The fixed step: 10 steps to 2e-4 s.
                assert_eq!(row.cost.steps, 10);
                assert!(row.cost.stages.contains_key("ppe_solve"));
            } else {
                assert_eq!(row.variant, None);
            }
            study.runs.push(row);
        }
        let schemes: Vec<(&str, Option<&str>)> =
            study.runs.iter().map(|r| (r.scheme.as_str(), r.preset.as_deref())).collect();
        assert_eq!(
            schemes[3..],
            [("wcsph", Some("wcsph_tuned")), ("mps", Some("mps"))],
            "the other schemes' rows record scheme and preset"
        );
        // Resumed: the rows come from the cache, with the times measured then.
        let resumed = Runner::new(Progress::silent(), false, 1).run(dir.path(), None, &jobs, finish).unwrap();
        assert!(resumed.iter().all(|r| r.reused));
        assert_eq!(
            resumed.iter().map(|r| &r.cost).collect::<Vec<_>>(),
            study.runs.iter().map(|r| &r.cost).collect::<Vec<_>>()
        );
        study.runs[2].reused = true;
        // The channel with implicit viscosity at D/36 to τ = 1 (about 670 steps).
        let ch_case = crate::case::testing::committed("poiseuille_periodic");
        let planned = channel::ChannelPlanned {
            dx: channel::D36,
            setup: channel::ChannelSetup::Isph(channel::ChannelVariant::IMPLICIT),
            threads: 1,
        };
        let scene = channel::scene(&ch_case, &planned.setup, planned.dx).unwrap();
        let jobs = [job(&ch_case, planned.id(), planned.dx, scene, 1).unwrap()];
        let finish = |_: usize, ran: Ran| Ok((channel::row(&ch_case, &planned, &ran)?, String::new()));
        let row = runner.run(dir.path(), None, &jobs, finish).unwrap().remove(0);
        assert!(row.ok(), "{}", row.status);
        assert_eq!((row.cost.particles, row.preset.as_deref()), (648, Some("re4_implicit")));
        assert!(row.error.is_some_and(|e| e < 0.05), "{:?}", row.error);
        assert!(row.cost.stages.contains_key("viscosity_implicit"));
        study.channel.as_mut().unwrap().runs.push(row);
        derive(&mut study, Tier::Quick);
        // The stage breakdown shows the presets with their own solvers and the other schemes.
        let labels: Vec<String> = breakdown_bars(&study).into_iter().map(|(label, _)| label).collect();
        assert_eq!(
            labels,
            ["paper Δx=0.08", "tuned Δx=0.08", "wcsph wcsph_tuned Δx=0.08", "mps mps Δx=0.08"]
        );
        assert!(!study.pareto.is_empty());
        // One front per scheme: the WCSPH and MPS runs are each alone on theirs.
        assert!(study.pareto.contains(&study.runs[3].id) && study.pareto.contains(&study.runs[4].id));
        assert_eq!(study.channel.as_ref().unwrap().pareto.len(), 1);
        assert_eq!(study.targets.len(), 6);
        // Main-thread presets of each scheme, then the channel's (its run has one thread).
        let costs: Vec<&str> = study.scheme_costs.iter().map(|c| c.series.as_str()).collect();
        assert_eq!(costs, ["paper", "tuned", "wcsph_tuned", "mps"]);
        assert!(study.scheme_costs.iter().all(|c| c.floor_ratio.is_some_and(|r| r >= 0.0)));
        write(dir.path(), &study).unwrap();
        let html = std::fs::read_to_string(dir.path().join("index.html")).unwrap();
        assert!(html.contains("Targets") && html.contains("<svg"));
        assert!(html.contains("1 runs (marked cached)") && html.contains(" (cached)"));
        assert!(html.contains("Periodic channel") && html.contains("re4_implicit"));
        assert!(html.contains("Cost per particle-step by scheme") && html.contains("wcsph_tuned"));
        for f in ["work_precision", "stages", "cost_scaling", "channel_work_precision"] {
            let svg = std::fs::read_to_string(dir.path().join(format!("{f}.svg"))).unwrap();
            assert!(svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"), "{f}");
        }
        let back: Study = io::read_json(&dir.path().join("results.json")).unwrap();
        assert_eq!(back, study);
        assert_eq!(back.runs[0].variant, Some(Variant::PAPER));
        // A file written before the channel study existed still reads.
        let mut old = serde_json::to_value(&study).unwrap();
        old.as_object_mut().unwrap().remove("channel");
        assert_eq!(serde_json::from_value::<Study>(old).unwrap().channel, None);
        // So does one written before the other schemes and their costs: its rows are ISPH.
        let mut old = serde_json::to_value(&study).unwrap();
        old.as_object_mut().unwrap().remove("scheme_costs");
        old["runs"].as_array_mut().unwrap().truncate(3);
        for rows in ["/runs", "/channel/runs"] {
            for r in old.pointer_mut(rows).and_then(|v| v.as_array_mut()).unwrap() {
                r.as_object_mut().unwrap().remove("scheme");
            }
        }
        let old: Study = serde_json::from_value(old).unwrap();
        assert!(old.scheme_costs.is_empty());
        assert_eq!(old.runs, study.runs[..3]);
        assert_eq!(old.channel, study.channel);
    }
}
