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
        .with_context(|| format!("cannot write `{}` (through `{}`)", path.display(), tmp.display()))?;
    std::fs::rename(&tmp, path)
        .with_context(|| format!("cannot rename `{}` to `{}`", tmp.display(), path.display()))?;
    Ok(())
}

/// `meniscus run SCENE --out DIR`.
pub fn run(
    scene_path: &Path,
    out: &Path,
    vtk_every: Option<usize>,
    threads: Option<usize>,
    max_steps: Option<usize>,
) -> anyhow::Result<()> {
    // The pool first: validating the scene already runs parallel loops.
    if let Some(n) = threads {
        if n == 0 {
            return Err(UsageError("--threads must be at least 1".into()).into());
        }
        rayon::ThreadPoolBuilder::new().num_threads(n).build_global().context("starting the thread pool")?;
    }
    let mut scene = Scene::from_path(scene_path)?;
    if let Some(n) = vtk_every {
        scene.output.vtk_every = n;
    }
    writable_dir(out)?;
    let frames = (scene.output.vtk_every > 0).then(|| out.join("frames"));
    if let Some(dir) = &frames {
        writable_dir(dir)?;
    }
    let mut sim = AnySimulation::new(&scene)?;
    if let Some(n) = max_steps {
        sim.stop_after(n);
    }
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
    if !report.snapshots.is_empty() {
        let dir = out.join("snapshots");
        writable_dir(&dir)?;
        for (i, frame) in report.snapshots.iter().enumerate() {
            let path = dir.join(format!("snapshot_{i:03}.json"));
            let tmp = path.with_extension("json.tmp");
            std::fs::write(&tmp, serde_json::to_vec(frame)?)
                .with_context(|| format!("cannot write `{}`", tmp.display()))?;
            std::fs::rename(&tmp, &path)
                .with_context(|| format!("cannot rename `{}` to `{}`", tmp.display(), path.display()))?;
        }
    }
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
    let Some(e) = &report.error else { return Ok(()) };
    // The last good state is written whether or not frames were requested: it is what a
    // user opens first to see what went wrong.
    let last_good = match &report.last_good {
        Some(frame) => {
            let dir = obs.frames.clone().unwrap_or_else(|| out.join("frames"));
            writable_dir(&dir)?;
            let path = vtk::write_frame_as(&dir, "last_good", frame)?;
            format!("the particles at the start of step {} are in {}", frame.step + 1, path.display())
        }
        None => "no step had passed the guards, so there is no last good state to write".to_string(),
    };
    Err(Diverged(format!(
        "{e}\n  {last_good}\n  probes and summary up to the divergence are in {}",
        out.display()
    ))
    .into())
}

/// Creates `dir` if needed and checks that files can be created in it, so that a bad
/// output path fails before the run rather than after it.
fn writable_dir(dir: &Path) -> anyhow::Result<()> {
    if dir.exists() && !dir.is_dir() {
        anyhow::bail!("the output directory `{}` exists and is not a directory", dir.display());
    }
    std::fs::create_dir_all(dir)
        .with_context(|| format!("cannot create the output directory `{}`", dir.display()))?;
    let probe = dir.join(".meniscus-write-test");
    std::fs::write(&probe, b"ok")
        .with_context(|| format!("cannot write to the output directory `{}`", dir.display()))?;
    std::fs::remove_file(&probe)
        .with_context(|| format!("cannot remove `{}` from the output directory", probe.display()))?;
    Ok(())
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
        scene.probes.iter().map(meniscus::scene::Probe::kind_name).collect::<Vec<_>>().join(", ")
    );
    Ok(())
}
