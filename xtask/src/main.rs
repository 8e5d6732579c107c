//! Project tasks: `cargo xtask validate | bench | report | deps` (DESIGN.md "Command lines").
//!
//! Thin by design: parsing and dispatch only; the logic lives in `meniscus-harness` (and,
//! for `deps`, in this package's library, which tests call).

mod bench;
mod executor;
mod report;
mod validate;

use clap::{Parser, Subcommand};
use std::path::PathBuf;
use std::process::ExitCode;

/// Meniscus project tasks.
#[derive(Debug, Parser)]
#[command(name = "cargo xtask", bin_name = "cargo xtask")]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

/// One subcommand per module.
#[derive(Debug, Subcommand)]
enum Command {
    /// Run the validation cases, write reports/<case>/results.json, summary.json and the
    /// HTML report; exit code 0 only when every check passes.
    Validate(validate::Args),
    /// Run the work-precision study of the elliptical drop into reports/work_precision/
    /// (results.json, SVGs, index.html) and print the performance targets' verdicts.
    Bench(bench::Args),
    /// Re-render the HTML report and summary.json from the existing results files (no runs).
    Report(report::Args),
    /// Print a crate's module graph (who uses whom, in layers); exit code 1 on an import
    /// cycle.
    Deps(xtask::deps::Args),
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Validate(args) => validate::run(args),
        Command::Bench(args) => bench::run(args),
        Command::Report(args) => report::run(args),
        Command::Deps(args) => xtask::deps::run(args, &workspace_root()),
    };
    match result {
        Ok(code) => code,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::from(2)
        }
    }
}

/// The workspace root (the parent of this package's directory).
fn workspace_root() -> PathBuf {
    let manifest = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    manifest.parent().map(PathBuf::from).unwrap_or(manifest)
}

/// The tier named by a command's `--quick` / `--full` flags (neither: the default tier).
fn tier(quick: bool, full: bool) -> meniscus_harness::Tier {
    use meniscus_harness::Tier;
    if quick {
        Tier::Quick
    } else if full {
        Tier::Full
    } else {
        Tier::Default
    }
}
