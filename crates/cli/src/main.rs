//! `meniscus`: run and check scene files, print analytical reference data.
//!
//! Exit codes: 0 success, 1 I/O or internal failure, 2 bad input (scene or arguments),
//! 3 a run that diverged (its outputs are still written).

mod reference;
mod run;
mod vtk;

use clap::{Parser, Subcommand};
use std::path::PathBuf;
use std::process::ExitCode;

/// Bad command-line input: reported with exit code 2.
#[derive(Debug)]
pub struct UsageError(pub String);

impl std::fmt::Display for UsageError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for UsageError {}

/// A run that diverged: reported with exit code 3 after its outputs are written.
#[derive(Debug)]
pub struct Diverged(pub String);

impl std::fmt::Display for Diverged {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for Diverged {}

#[derive(Parser, Debug)]
#[command(name = "meniscus", version = meniscus::VERSION, about = "Particle-method CFD: run scenes, print reference solutions")]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Run a scene file; writes summary.json, probes.json and optional VTK frames to --out.
    Run {
        /// Scene file (JSON, see DESIGN.md).
        scene: PathBuf,
        /// Output directory.
        #[arg(long, default_value = "out")]
        out: PathBuf,
        /// Write a VTK frame (frames/*.vtu) every N steps (overrides output.vtk_every). A run
        /// that diverges always writes the particles before the failing step to
        /// frames/last_good.vtu.
        #[arg(long)]
        vtk_every: Option<usize>,
        /// Worker threads (default: all cores).
        #[arg(long)]
        threads: Option<usize>,
        /// Stop after N steps if the end time is not reached before (a truncated run: the
        /// outputs cover the steps taken; summary.json's t_end is the time reached).
        #[arg(long)]
        max_steps: Option<usize>,
    },
    /// Validate a scene file and print what a run would build.
    Check {
        /// Scene file (JSON).
        scene: PathBuf,
    },
    /// Print analytical reference data (JSON with --json).
    #[command(subcommand)]
    Reference(reference::ReferenceCommand),
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match &cli.command {
        Command::Run { scene, out, vtk_every, threads, max_steps } => {
            run::run(scene, out, *vtk_every, *threads, *max_steps)
        }
        Command::Check { scene } => run::check(scene),
        Command::Reference(cmd) => reference::run(cmd),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            if e.downcast_ref::<UsageError>().is_some() || e.downcast_ref::<meniscus::SceneError>().is_some()
            {
                ExitCode::from(2)
            } else if e.downcast_ref::<Diverged>().is_some() {
                ExitCode::from(3)
            } else {
                ExitCode::FAILURE
            }
        }
    }
}
