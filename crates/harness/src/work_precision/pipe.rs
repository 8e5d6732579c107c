//! The third part of `cargo xtask bench`: the 3D Hagen–Poiseuille pipe
//! (`validation/hagen_poiseuille.json`: periodic pipe of radius R = 0.01 m, dummy-particle
//! wall shell, Re = 1, from rest to ν t/R² = 1), its ISPH preset `qiu` and WCSPH preset
//! `wcsph_xu` exactly as the validation runs them ([`crate::sweep::spec`]: template, the
//! preset's merge patch, Δx), at R/Δx = 8 (quick), 8 and 12 (default), 8, 12 and 16 (full).
//!
//! Per run it records the cost (wall and CPU time, steps, particles), the throughput in
//! particle-steps per second, the steady profile error `u_profile_l2_rel_steady` of the
//! harness's pipe metrics (`metrics::poiseuille`, the start-up series of REFERENCES.md
//! 3(d)), and the run's peak memory, in bytes and per particle ([`memory`]).
//!
//! Particle counts: the solver's summary reports the fluid particles only; the wall's dummy
//! particles are counted from the scene as the solver seeds them ([`wall_particles`]), and
//! the memory per particle is over both (every dummy particle holds the per-particle arrays
//! and a neighbour row). The throughput counts fluid particles, as the other parts' costs do.

use super::measure;
use super::record::Cost;
use crate::case::{Case, ReferenceSpec};
use crate::error::{HarnessError, Result};
use crate::runner::{Job, Ran, Runner};
use crate::tier::Tier;
use meniscus::Scene;
use meniscus::scene::{Scheme, WallModel, seeding};
use serde::{Deserialize, Serialize};
use std::path::Path;

/// The case file of the pipe (`validation/<CASE>.json`).
pub const CASE: &str = "hagen_poiseuille";

/// The case presets the pipe runs, ISPH then WCSPH.
pub const PRESETS: [&str; 2] = ["qiu", "wcsph_xu"];

/// The error metric of the pipe.
pub const METRIC: &str = "u_profile_l2_rel_steady";

/// R/Δx of each tier, coarse first.
pub fn resolutions(tier: Tier) -> &'static [u32] {
    match tier {
        Tier::Quick => &[8],
        Tier::Default => &[8, 12],
        Tier::Full => &[8, 12, 16],
    }
}

/// The pipe's radius R \[m\] (the case's reference).
pub fn radius(case: &Case) -> Result<f64> {
    match case.reference {
        ReferenceSpec::HagenPoiseuille { radius, .. } => Ok(radius),
        _ => Err(HarnessError::case(&case.case, "the pipe study needs a hagen_poiseuille reference")),
    }
}

/// One planned pipe run.
#[derive(Debug, Clone, PartialEq)]
pub struct PipePlanned {
    /// Spacing \[m\] (one of the case's `sweep.dx`).
    pub dx: f64,
    /// R/Δx (8, 12, 16).
    pub r_over_dx: u32,
    /// The case preset (`qiu`, `wcsph_xu`).
    pub preset: &'static str,
    /// The scheme of the preset's scene (`isph`, `wcsph`).
    pub scheme: String,
    /// Rayon threads.
    pub threads: usize,
}

impl PipePlanned {
    /// A stable id, e.g. `pipe_dx0.00125_t2_qiu`.
    pub fn id(&self) -> String {
        format!("pipe_dx{:.5}_t{}_{}", self.dx, self.threads, self.preset)
    }

    /// The run's job: the preset at `dx` exactly as the validation builds it, under the
    /// study's id, on the study's thread count.
    pub fn job(&self, case: &Case) -> Result<Job> {
        let mut spec = crate::sweep::spec(case, self.preset, self.dx)?;
        spec.slug = self.id();
        Ok(Job { threads: Some(self.threads), ..Job::new(spec) })
    }
}

/// The pipe runs of a tier, coarse spacings first, each spacing's presets in [`PRESETS`]
/// order, and the design's description. Each spacing is the case's (its full tier's
/// `sweep.dx`) whose R/Δx is the tier's; one the case lacks is an error.
pub fn design(case: &Case, tier: Tier, threads: usize) -> Result<(Vec<PipePlanned>, String)> {
    let r = radius(case)?;
    for preset in PRESETS {
        if !case.sweep.presets.iter().any(|p| p.name == preset) {
            return Err(HarnessError::case(
                &case.case,
                format!("the pipe study needs the preset `{preset}`"),
            ));
        }
    }
    let mut runs = Vec::new();
    for &n in resolutions(tier) {
        let dx = case
            .spacings(Tier::Full)
            .iter()
            .copied()
            .find(|dx| (r / dx - f64::from(n)).abs() < 1e-6)
            .ok_or_else(|| {
                HarnessError::case(
                    &case.case,
                    format!("the pipe study needs R/dx = {n} among the full tier's spacings"),
                )
            })?;
        for preset in PRESETS {
            let scheme = crate::sweep::spec(case, preset, dx)?.scheme;
            runs.push(PipePlanned { dx, r_over_dx: n, preset, scheme, threads });
        }
    }
    let ratios = resolutions(tier).iter().map(|n| format!("R/{n}")).collect::<Vec<_>>().join(", ");
    let text = format!(
        "3D pipe (Hagen–Poiseuille, Re = 1, dummy-particle wall shell, to ν t/R² = 1), {ratios}: the case's presets {} \
         (ISPH) and {} (WCSPH) as the validation runs them, one run at a time on {threads} threads.",
        PRESETS[0], PRESETS[1]
    );
    Ok((runs, text))
}

/// The boundary particles the solver seeds for `scene` besides its fluid, when this rule
/// knows them: with dummy walls, no wall plane and no open boundary (the pipe), the wall
/// bodies' dummy particles exactly as the solver's set-up seeds them
/// (`meniscus::scene::seeding::seed_walls`); 0 for a scene without walls or open
/// boundaries; `None` otherwise (mirror particles, plane layers and buffers are laid by the
/// stages, and MPS lays its own walls).
pub fn wall_particles(scene: &Scene) -> Option<usize> {
    let open = scene.boundaries.inflow.is_some() || scene.boundaries.outflow.is_some();
    if open || matches!(scene.scheme, Scheme::Mps(_)) || !scene.boundaries.walls.is_empty() {
        return None;
    }
    if !scene.has_walls() {
        return Some(0);
    }
    if scene.boundaries.wall_model != WallModel::Dummy {
        return None;
    }
    Some(match scene.dimension {
        2 => seeding::seed_walls::<2>(scene).len(),
        3 => seeding::seed_walls::<3>(scene).len(),
        _ => return None,
    })
}

/// One pipe run. A diverged run is a row with its status and no error value.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PipeRow {
    /// Stable id ([`PipePlanned::id`]).
    pub id: String,
    /// Spacing \[m\].
    pub dx: f64,
    /// R/Δx.
    pub r_over_dx: u32,
    /// The scheme of the run's scene: `isph` or `wcsph`.
    pub scheme: String,
    /// The case preset (`qiu`, `wcsph_xu`).
    pub preset: String,
    /// Rayon threads.
    pub threads: usize,
    /// Size and cost of the run; its `particles` are the fluid particles (the solver's
    /// summary counts no boundary particle).
    #[serde(flatten)]
    pub cost: Cost,
    /// The wall's dummy particles ([`wall_particles`]); `None` when not known.
    pub wall_particles: Option<usize>,
    /// Fluid particles × steps / wall time \[particle-steps/s\]; `None` before a step.
    pub particle_steps_per_s: Option<f64>,
    /// The run's peak memory \[bytes\]: the peak resident set of the process during the
    /// run less its resident set before it ([`memory::PeakMemory::peak_bytes`]); `None`
    /// where it cannot be read (off Linux).
    pub memory_peak_bytes: Option<u64>,
    /// The process's resident set when the run started \[bytes\].
    pub memory_rss_before_bytes: Option<u64>,
    /// `memory_peak_bytes` over the fluid and wall particles \[bytes/particle\].
    pub bytes_per_particle: Option<f64>,
    /// Steady profile error at ν t/R² = 1 (`u_profile_l2_rel_steady`); `None` when diverged.
    pub error: Option<f64>,
    /// Largest start-up profile error, ν t/R² < 1 (`u_profile_l2_rel_startup_max`).
    pub error_startup_max: Option<f64>,
    /// `ok` or `diverged: <cause>`.
    pub status: String,
    /// Taken from the run cache of an earlier invocation (see `RunRow::reused`); its times
    /// and memory are those measured then.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub reused: bool,
}

impl PipeRow {
    /// Whether the run reached its end time.
    pub fn ok(&self) -> bool {
        self.status == "ok"
    }
}

/// The pipe in `results.json` (its `pipe` field).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PipeStudy {
    /// `hagen_poiseuille`.
    pub case: String,
    /// The error measure.
    pub error_metric: String,
    /// How the peak memory is measured.
    pub memory: String,
    /// The parts of the design.
    pub design: Vec<String>,
    /// Every run, in the order run.
    pub runs: Vec<PipeRow>,
}

impl PipeStudy {
    /// An empty study of `design`.
    pub fn new(design: String) -> PipeStudy {
        PipeStudy {
            case: CASE.into(),
            error_metric: format!(
                "{METRIC}: sqrt(Σ (u − u_ref)² / Σ u_ref²) over the radial velocity bins at ν t/R² = 1, against the \
                 start-up series of REFERENCES.md 3(d)"
            ),
            memory: memory::METHOD.into(),
            design: vec![design],
            runs: Vec::new(),
        }
    }
}

/// The row of a planned run from how it ran, with `memory` its peak memory (if measured)
/// and `walls` its wall particles ([`wall_particles`]).
pub fn row(
    case: &Case,
    planned: &PipePlanned,
    ran: &Ran,
    walls: Option<usize>,
    memory: Option<memory::PeakMemory>,
) -> Result<PipeRow> {
    let m = measure(case, ran)?;
    let get = |k: &str| m.metrics.get(k).copied();
    let work = (m.cost.particles * m.cost.steps) as f64;
    let particle_steps_per_s = (m.cost.steps > 0 && m.cost.wall_s > 0.0).then(|| work / m.cost.wall_s);
    let peak = memory.map(|p| p.peak_bytes());
    let total = walls.map(|w| m.cost.particles + w).filter(|&n| n > 0);
    Ok(PipeRow {
        id: planned.id(),
        dx: planned.dx,
        r_over_dx: planned.r_over_dx,
        scheme: planned.scheme.clone(),
        preset: planned.preset.to_string(),
        threads: planned.threads,
        wall_particles: walls,
        particle_steps_per_s,
        memory_peak_bytes: peak,
        memory_rss_before_bytes: memory.map(|p| p.rss_before_bytes),
        bytes_per_particle: peak.zip(total).map(|(b, n)| b as f64 / n as f64),
        error: get(METRIC),
        error_startup_max: get("u_profile_l2_rel_startup_max"),
        cost: m.cost,
        status: m.status,
        reused: ran.reused(),
    })
}

/// Runs (or, resuming, reuses) one planned run through `runner` into `dir`, alone, and
/// measures its peak memory around it ([`memory::Window`]); `line` records the row (the
/// study writes `results.json`) and returns the line printed for it.
pub fn run(
    runner: &Runner,
    dir: &Path,
    case: &Case,
    planned: &PipePlanned,
    line: impl Fn(&PipeRow) -> Result<String> + Sync,
) -> Result<PipeRow> {
    let job = planned.job(case)?;
    let walls = wall_particles(&job.spec.scene);
    let hash = job.spec.hash.clone();
    let id = planned.id();
    let window = memory::Window::open();
    let mut rows = runner.run(dir, None, std::slice::from_ref(&job), |_, ran| {
        // Read first: the peak of the run, before the row's own work.
        let measured = window.close();
        let memory = memory::kept(dir, &id, &hash, &ran, measured);
        let row = row(case, planned, &ran, walls, memory)?;
        let text = line(&row)?;
        Ok((row, text))
    })?;
    rows.pop().ok_or_else(|| HarnessError::case(&case.case, format!("run {id}: no row")))
}

/// Peak memory of one in-process run, from the kernel's accounting of the process's
/// resident set (Linux `/proc`).
///
/// Why this way: the study runs the pipe's runs inside its own process, one at a time and
/// each alone in its batch, so the process's peak resident set during a run is the run's. Linux keeps that peak (`VmHWM` in
/// `/proc/self/status`) and resets it to the current resident set when `5` is written to
/// `/proc/self/clear_refs` (since Linux 4.0): reset before the run, read after it, less the
/// resident set before it (`VmRSS`), it is the run's peak growth, every allocation and
/// thread stack of the solver included, without instrumenting the allocator. The crates
/// looked at do not give a per-run peak as cleanly: `memory-stats` reads the current
/// resident set only (no peak); `peak_alloc` and `peakmem-alloc` count heap bytes through a
/// `#[global_allocator]` that each binary (xtask, the test harness) would have to install,
/// and `peak_alloc` cannot reset its peak; `procfs` wraps the same two files behind a
/// dependency tree of its own, for what is a dozen lines here.
///
/// A lower bound: memory the allocator kept resident from earlier runs of the process and
/// hands to this one is not counted again (the study's runs before the pipe are smaller
/// 2D ones; `rss_before_bytes` is kept beside it). `None` off Linux, on a kernel without
/// the reset, or on any read error; never a panic.
pub mod memory {
    use crate::io;
    use crate::runner::Ran;
    use serde::{Deserialize, Serialize};
    use std::path::{Path, PathBuf};

    /// How the study measures memory, for `results.json` and the page.
    pub const METHOD: &str = "peak resident set of the process during the run (Linux VmHWM, reset through \
        /proc/self/clear_refs before it) less its resident set before it (VmRSS): the run's peak growth, a lower \
        bound when the allocator reuses memory an earlier run left resident";

    /// The resident set around one run \[bytes\].
    #[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
    pub struct PeakMemory {
        /// The process's resident set when the run started \[bytes\].
        pub rss_before_bytes: u64,
        /// The process's peak resident set during the run \[bytes\].
        pub peak_rss_bytes: u64,
    }

    impl PeakMemory {
        /// The run's peak memory: peak resident set less the resident set before \[bytes\].
        pub fn peak_bytes(&self) -> u64 {
            self.peak_rss_bytes.saturating_sub(self.rss_before_bytes)
        }
    }

    /// A field of `/proc/self/status` in bytes (the file gives kB = 1024 bytes).
    fn status_bytes(field: &str) -> Option<u64> {
        let status = std::fs::read_to_string("/proc/self/status").ok()?;
        let line = status.lines().find_map(|l| l.strip_prefix(field)?.strip_prefix(':'))?;
        let mut words = line.split_whitespace();
        let kib: u64 = words.next()?.parse().ok()?;
        (words.next() == Some("kB")).then_some(kib * 1024)
    }

    /// A measurement window: the peak reset and the resident set read when it opened.
    #[derive(Debug, Clone, Copy)]
    pub struct Window {
        rss_before_bytes: Option<u64>,
    }

    impl Window {
        /// Resets the process's peak resident set and reads the current one; a window that
        /// could do neither measures nothing.
        pub fn open() -> Window {
            let reset = std::fs::write("/proc/self/clear_refs", "5").is_ok();
            Window { rss_before_bytes: if reset { status_bytes("VmRSS") } else { None } }
        }

        /// The peak since [`Window::open`], if measured.
        pub fn close(&self) -> Option<PeakMemory> {
            let before = self.rss_before_bytes?;
            let peak = status_bytes("VmHWM")?;
            Some(PeakMemory { rss_before_bytes: before, peak_rss_bytes: peak.max(before) })
        }
    }

    /// Where the memory of run `id` is kept beside its cached record.
    fn path(dir: &Path, id: &str) -> PathBuf {
        dir.join("runs").join(format!("{id}.memory.json"))
    }

    #[derive(Serialize, Deserialize)]
    struct Kept {
        scene_hash: String,
        #[serde(flatten)]
        memory: PeakMemory,
    }

    /// The memory of a run: for a run taken from the cache, what was measured when it ran
    /// (kept in `<dir>/runs/<id>.memory.json` with its scene hash; `None` if absent or for
    /// another scene); for a run just made, `measured`, kept there for a later `--resume`
    /// when the run was cached (a failed write keeps nothing).
    pub fn kept(
        dir: &Path,
        id: &str,
        hash: &str,
        ran: &Ran,
        measured: Option<PeakMemory>,
    ) -> Option<PeakMemory> {
        if ran.reused() {
            let k: Kept = io::read_json(&path(dir, id)).ok()?;
            return (k.scene_hash == hash).then_some(k.memory);
        }
        if let (Some(memory), Some(_)) = (measured, ran.record()) {
            let _ = io::write_json(&path(dir, id), &Kept { scene_hash: hash.to_string(), memory });
        }
        measured
    }

    #[cfg(test)]
    mod tests {
        use super::*;

        /// On Linux a window around an allocation of 64 MiB that is touched sees it (in the
        /// peak resident set, which other tests of the process cannot lower: they may
        /// reset the peak, never below the resident set, which holds it).
        #[test]
        fn a_window_sees_a_touched_allocation() {
            let window = Window::open();
            let v = std::hint::black_box(vec![1u8; 64 << 20]);
            let m = window.close();
            drop(v);
            if cfg!(target_os = "linux") {
                let m = m.expect("measured on Linux");
                assert!(m.peak_rss_bytes >= 64 << 20, "{m:?}");
                assert!(m.rss_before_bytes > 0 && m.peak_rss_bytes >= m.rss_before_bytes);
                assert_eq!(m.peak_bytes(), m.peak_rss_bytes - m.rss_before_bytes);
            }
            let kib = status_bytes("VmRSS");
            assert_eq!(kib.is_some(), cfg!(target_os = "linux"));
            assert_eq!(status_bytes("NoSuchField"), None);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::case::testing::committed;
    use crate::io;
    use crate::io::testing::Scratch;
    use crate::progress::Progress;
    use crate::work_precision::record::Study;

    #[test]
    fn design_takes_the_case_spacings_and_presets() {
        let c = committed(CASE);
        let (quick, text) = design(&c, Tier::Quick, 2).unwrap();
        assert_eq!(
            quick.iter().map(|p| (p.dx, p.preset)).collect::<Vec<_>>(),
            [(0.00125, "qiu"), (0.00125, "wcsph_xu")]
        );
        assert!(text.contains("R/8") && text.contains("wcsph_xu"), "{text}");
        assert_eq!(quick[0].id(), "pipe_dx0.00125_t2_qiu");
        let (default, _) = design(&c, Tier::Default, 2).unwrap();
        assert_eq!(default.len(), 4);
        let (full, _) = design(&c, Tier::Full, 1).unwrap();
        let ratios: Vec<u32> = full.iter().map(|p| p.r_over_dx).collect();
        assert_eq!(ratios, [8, 8, 12, 12, 16, 16]);
        for p in &full {
            assert!(c.spacings(Tier::Full).contains(&p.dx));
            // The validation's own scene, under the study's id.
            let job = p.job(&c).unwrap();
            assert_eq!(job.spec.scene, crate::sweep::spec(&c, p.preset, p.dx).unwrap().scene);
            assert_eq!((job.spec.slug.as_str(), job.threads), (p.id().as_str(), Some(1)));
        }
        assert_eq!(full[1].job(&c).unwrap().spec.scheme, "wcsph");
        assert_eq!(full.iter().map(|p| p.scheme.as_str()).collect::<Vec<_>>()[..2], ["isph", "wcsph"]);
    }

    /// The wall count is the dummy shell's: about (1.32² − 1) = 0.74 of the fluid's rings.
    #[test]
    fn the_pipe_wall_is_counted() {
        let c = committed(CASE);
        let scene = crate::sweep::spec(&c, "qiu", 0.00125).unwrap().scene;
        let walls = wall_particles(&scene).unwrap();
        let fluid = seeding::seed_bodies::<3>(&scene).x.len();
        assert_eq!(fluid, 2412, "the case file's count");
        let ratio = walls as f64 / fluid as f64;
        assert!((0.6..0.9).contains(&ratio), "{walls} walls, {fluid} fluid");
        let channel = crate::sweep::spec(&committed("poiseuille_periodic"), "re4", 0.01).unwrap().scene;
        assert_eq!(wall_particles(&channel), None, "mirror planes are laid every step");
    }

    /// The pipe at R/4 (both presets, to ν t/R² = 1 as the case runs it): twice as long
    /// (2 R, so that the period holds twice the support 2h = 3 Δx) in a shell out to 1.65 R
    /// (the outer fluid ring's support): 400 fluid and 832 wall particles, 37 and 147 steps.
    fn tiny_pipe() -> (Case, Vec<PipePlanned>) {
        let mut case = committed(CASE);
        let s = &mut case.scene;
        for body in 0..2 {
            let cylinder = &mut s["bodies"][body]["shape"]["cylinder"];
            cylinder["center"][0] = serde_json::json!(0.01);
            cylinder["length"] = serde_json::json!(0.02);
        }
        s["bodies"][1]["shape"]["cylinder"]["radius"] = serde_json::json!(0.0165);
        s["boundaries"]["periodic"][0]["max"] = serde_json::json!(0.02);
        let planned = PRESETS
            .iter()
            .map(|&preset| PipePlanned {
                dx: 0.0025,
                r_over_dx: 4,
                preset,
                scheme: crate::sweep::spec(&case, preset, 0.0025).unwrap().scheme,
                threads: 1,
            })
            .collect();
        (case, planned)
    }

    /// Both presets of a tiny pipe: finite positive rows, the memory measured on Linux,
    /// kept for a resumed study and shown on the page; `results.json` reads with and without
    /// the pipe.
    #[test]
    fn a_pipe_run_gives_a_row_with_its_memory_and_a_page_section() {
        let (case, planned) = tiny_pipe();
        let dir = Scratch::new("work-precision-pipe");
        let runner = Runner::new(Progress::silent(), true, 1);
        let mut rows = Vec::new();
        for p in &planned {
            let row = run(&runner, dir.path(), &case, p, |row| Ok(row.id.clone())).unwrap();
            assert!(row.ok() && !row.reused, "{}: {}", row.id, row.status);
            assert_eq!(
                (row.scheme.as_str(), row.preset.as_str(), row.r_over_dx),
                (p.scheme.as_str(), p.preset, 4)
            );
            let scene = p.job(&case).unwrap().spec.scene;
            let fluid = seeding::seed_bodies::<3>(&scene).x.len();
            assert_eq!(row.cost.particles, fluid, "fluid particles");
            let walls = row.wall_particles.unwrap();
            assert!(walls > 0, "{walls}");
            assert!(row.cost.steps > 0 && row.cost.wall_s > 0.0);
            assert!(row.cost.cpu_s.is_some_and(|c| c.is_finite() && c >= 0.0), "{:?}", row.cost.cpu_s);
            let throughput = row.particle_steps_per_s.unwrap();
            assert!(throughput.is_finite() && throughput > 0.0);
            assert!(
                (throughput * row.cost.wall_s - (fluid * row.cost.steps) as f64).abs() < 1e-6 * throughput,
                "fluid particles × steps / wall"
            );
            assert!(row.error.is_some_and(|e| e.is_finite() && e > 0.0), "{:?}", row.error);
            assert!(row.error_startup_max.is_some_and(|e| e.is_finite() && e > 0.0));
            if cfg!(target_os = "linux") {
                let peak = row.memory_peak_bytes.expect("measured on Linux");
                assert!(peak > 0 && row.memory_rss_before_bytes.is_some_and(|b| b > 0));
                let per = row.bytes_per_particle.unwrap();
                assert!(per.is_finite() && per > 0.0);
                assert!((per - peak as f64 / (fluid + walls) as f64).abs() < 1e-9);
            }
            rows.push(row);
        }
        assert_eq!(rows.iter().map(|r| r.scheme.as_str()).collect::<Vec<_>>(), ["isph", "wcsph"]);
        // Resumed: the cached runs with the memory measured when they ran.
        let resumed = Runner::new(Progress::silent(), false, 1);
        for (p, row) in planned.iter().zip(&rows) {
            let again = run(&resumed, dir.path(), &case, p, |r| Ok(r.id.clone())).unwrap();
            assert!(again.reused);
            assert_eq!(PipeRow { reused: false, ..again }, *row);
        }
        let mut study = Study::for_test(vec!["test".into()], vec![], None);
        let mut pipe = PipeStudy::new("test".into());
        pipe.runs = rows;
        study.pipe = Some(pipe);
        super::super::write(dir.path(), &study).unwrap();
        let html = std::fs::read_to_string(dir.path().join("index.html")).unwrap();
        assert!(html.contains("<h2>3D pipe</h2>") && html.contains("bytes/particle"), "the pipe's section");
        assert!(
            html.contains("pipe_<wbr>dx0.00250_<wbr>t1_<wbr>wcsph_<wbr>xu")
                && html.contains("particle-steps/s")
        );
        let svg = std::fs::read_to_string(dir.path().join("pipe_work_precision.svg")).unwrap();
        assert!(svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"));
        assert!(svg.contains("qiu R/4") && svg.contains("wcsph_xu R/4"), "both points labelled");
        let back: Study = io::read_json(&dir.path().join("results.json")).unwrap();
        assert_eq!(back, study);
        // A file written before the pipe existed still reads, and one without it omits it.
        let mut old = serde_json::to_value(&study).unwrap();
        assert!(old.get("pipe").is_some());
        old.as_object_mut().unwrap().remove("pipe");
        let old: Study = serde_json::from_value(old).unwrap();
        assert_eq!(old, Study { pipe: None, ..study });
        assert!(serde_json::to_value(&old).unwrap().get("pipe").is_none());
    }
}
