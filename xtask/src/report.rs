//! `cargo xtask report [--out DIR]`: re-render the report from existing results files.

use std::path::PathBuf;
use std::process::ExitCode;

/// Options of `cargo xtask report`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Directory holding <case>/results.json [default: <workspace>/reports].
    #[arg(long, value_name = "DIR")]
    out: Option<PathBuf>,
}

/// Re-renders every case page, summary.json and index.html.
pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    let out = args.out.unwrap_or_else(|| crate::workspace_root().join("reports"));
    let results = meniscus_harness::report::render_all(&out)?;
    if results.is_empty() {
        anyhow::bail!("no <case>/results.json under {}: run `cargo xtask validate` first", out.display());
    }
    eprintln!("rendered {} case(s) into {}", results.len(), out.join("index.html").display());
    Ok(ExitCode::SUCCESS)
}
