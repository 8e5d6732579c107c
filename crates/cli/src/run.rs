//! `meniscus run` and `meniscus check`.

use crate::{Diverged, UsageError, vtk};
use anyhow::Context;
use indicatif::{ProgressBar, ProgressStyle};
use meniscus::{AnySimulation, Frame, Observer, Scene};
use std::path::{Path, PathBuf};

/// Progress bar and VTK frame writer.
struct CliObserver {
    bar: ProgressBar,
    frames: Option<PathBuf>,
    error: Option<anyhow::Error>,
}

impl Observer for CliObserver {
    fn progress(&mut self, step: usize, time: f64, t_end: f64) {
        self.bar.set_position((1000.0 * time / t_end).round() as u64);
        if step.is_multiple_of(50) {
            self.bar.set_message(format!("step {step}, t = {time:.4e} s"));
        }
    }

    fn frame(&mut self, frame: &Frame) {
        if let (Some(dir), None) = (&self.frames, &self.error)
            && let Err(e) = vtk::write_frame(dir, frame)
        {
            self.error = Some(e);
        }
    }
}

/// Writes `value` as pretty JSON to `path` atomically (temporary file, then rename).
pub fn write_json_atomic(path: &Path, value: &impl serde::Serialize) -> anyhow::Result<()> {
    let tmp = path.with_extension("json.tmp");
    std::fs::write(&tmp, serde_json::to_vec_pretty(value)?)
        .with_context(|| format!("writing {}", tmp.display()))?;
    std::fs::rename(&tmp, path).with_context(|| format!("renaming to {}", path.display()))?;
    Ok(())
}

/// `meniscus run SCENE --out DIR`.
pub fn run(
    scene_path: &Path,
    out: &Path,
    vtk_every: Option<usize>,
    threads: Option<usize>,
) -> anyhow::Result<()> {
    let mut scene = Scene::from_path(scene_path)?;
    if let Some(n) = vtk_every {
        scene.output.vtk_every = n;
    }
    if let Some(n) = threads {
        if n == 0 {
            return Err(UsageError("--threads must be at least 1".into()).into());
        }
        rayon::ThreadPoolBuilder::new().num_threads(n).build_global().context("starting the thread pool")?;
    }
    std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
    let frames = (scene.output.vtk_every > 0).then(|| out.join("frames"));
    if let Some(dir) = &frames {
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    }
    let mut sim = AnySimulation::new(&scene)?;
    let bar = ProgressBar::new(1000);
    bar.set_style(
        ProgressStyle::with_template("{prefix} [{bar:40}] {percent:>3}% {elapsed_precise} {msg}")
            .expect("static template")
            .progress_chars("=> "),
    );
    bar.set_prefix(format!("{} ({} particles)", scene.name, sim.particles()));
    let mut obs = CliObserver { bar, frames, error: None };
    let report = sim.run(&mut obs);
    obs.bar.finish_and_clear();
    write_json_atomic(&out.join("probes.json"), &report.probes)?;
    write_json_atomic(&out.join("summary.json"), &report.summary)?;
    if let Some(e) = obs.error {
        return Err(e);
    }
    let s = &report.summary;
    eprintln!(
        "{}: {} particles, {} steps to t = {:.6} s in {:.2} s wall ({} threads) -> {}",
        s.scene,
        s.particles,
        s.steps,
        s.t_end,
        s.wall_s,
        s.threads,
        out.display()
    );
    match &report.error {
        None => Ok(()),
        Some(e) => Err(Diverged(e.to_string()).into()),
    }
}

/// `meniscus check SCENE`.
pub fn check(scene_path: &Path) -> anyhow::Result<()> {
    let scene = Scene::from_path(scene_path)?;
    let sim = AnySimulation::new(&scene)?;
    println!("scene `{}` is valid", scene.name);
    println!(
        "  dimension {}, dx = {} m, h = {} m ({:?})",
        scene.dimension,
        scene.dx,
        scene.h(),
        scene.kernel.kind
    );
    println!("  particles: {}", sim.particles());
    println!("  stages per step: {}", sim.stage_names().join(" -> "));
    println!(
        "  probes: {}",
        scene.probes.iter().map(meniscus::probes::kind_name).collect::<Vec<_>>().join(", ")
    );
    Ok(())
}
