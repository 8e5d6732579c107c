//! `cargo xtask bench [--quick|--full] [--out DIR] [--threads N] [--resume]`: the work-precision
//! study of the elliptical drop, the periodic Poiseuille channel and the 3D pipe into
//! `reports/work_precision/`, in a release build (a dev-build invocation re-runs itself through
//! `cargo run --release` unless `--dev-build`).

use anyhow::Context;
use meniscus_harness::work_precision::{self, Options};
use std::path::PathBuf;
use std::process::ExitCode;

/// Options of `cargo xtask bench`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Drop Δx 0.04 and 0.02 only, few option sets; the channel at D/36 only, the pipe at R/8 (about 2 minutes).
    #[arg(long, conflicts_with = "full")]
    quick: bool,
    /// Adds drop Δx = 0.005 (the full range for the cost-per-step exponent), channel Δx = 0.0025 and the pipe at R/16.
    #[arg(long)]
    full: bool,
    /// Output directory [default: <workspace>/reports/work_precision].
    #[arg(long, value_name = "DIR")]
    out: Option<PathBuf>,
    /// Threads of the main runs (the thread study compares 1 with this).
    #[arg(long, value_name = "N", default_value_t = 2)]
    threads: usize,
    /// No line per run.
    #[arg(long)]
    no_progress: bool,
    /// Reuse the runs an interrupted study of the same build left in <out>/runs/ (marked
    /// cached in results.json and on the page; their times are those measured then).
    #[arg(long)]
    resume: bool,
    /// Run in the build `cargo xtask` was started in (dev: opt-level 3 with debug
    /// assertions, about 8 % slower) instead of re-running in a release build.
    #[arg(long)]
    dev_build: bool,
    #[command(flatten)]
    executor: crate::executor::ExecutorArgs,
}

/// Runs the study and prints the targets' verdicts; exits 1 when a target is missed (the
/// report gives the machine's load: timings on a shared machine), 2 when it could not run.
/// CI does not run it.
pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    // The performance targets are stated for a release build: from the dev build, run
    // the same command again through `cargo run --release`.
    if cfg!(debug_assertions) && !args.dev_build {
        eprintln!("bench: re-running in a release build (cargo run --release; --dev-build skips this)");
        let status = std::process::Command::new(std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into()))
            .args(["run", "--release", "--quiet", "--package", "xtask", "--"])
            .args(std::env::args_os().skip(1))
            .status()
            .context("could not start cargo for the release build")?;
        return Ok(ExitCode::from(status.code().map_or(2, |c| c.clamp(0, 255) as u8)));
    }
    let root = crate::workspace_root();
    let tier = crate::tier(args.quick, args.full);
    let opts = Options {
        tier,
        out: args.out.unwrap_or_else(|| root.join("reports").join("work_precision")),
        validation_dir: root.join("validation"),
        workspace: root.clone(),
        threads: args.threads.max(1),
        progress: !args.no_progress,
        resume: args.resume,
        slurm: args.executor.connect(&root)?,
    };
    let study = work_precision::run(&opts).context("the work-precision study could not run")?;
    let diverged = study.runs.iter().filter(|r| !r.ok()).count();
    eprintln!(
        "drop: {} runs ({diverged} diverged); the study in {:.0} s, tier {}, {} threads",
        study.runs.len(),
        study.elapsed_s,
        study.tier,
        study.threads
    );
    if let Some(c) = &study.channel {
        let diverged = c.runs.iter().filter(|r| !r.ok()).count();
        eprintln!(
            "channel: {} runs ({diverged} diverged), Pareto front: {}",
            c.runs.len(),
            c.pareto.join(", ")
        );
    }
    if let Some(p) = &study.pipe {
        let diverged = p.runs.iter().filter(|r| r.status != "ok").count();
        eprintln!("pipe: {} runs ({diverged} diverged)", p.runs.len());
    }
    for t in &study.targets {
        let value = t.value.map_or("n/a".to_string(), |v| format!("{v:.3}"));
        let op = if t.kind == "max" { "<=" } else { ">=" };
        eprintln!("  {:<4} {}: {value} {} ({op} {}) — {}", t.verdict(), t.name, t.unit, t.threshold, t.note);
    }
    eprintln!("report: {}", opts.out.join("index.html").display());
    let missed = study.targets.iter().filter(|t| t.pass == Some(false)).count();
    if missed > 0 {
        eprintln!(
            "bench: {missed} target(s) missed (load average {} at the start, {} at the end)",
            study.machine.loadavg_start.as_deref().unwrap_or("?").trim(),
            study.machine.loadavg_end.as_deref().unwrap_or("?").trim()
        );
        return Ok(ExitCode::from(1));
    }
    Ok(ExitCode::SUCCESS)
}
