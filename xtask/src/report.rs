//! `cargo xtask report [--out DIR] [--baseline DIR]`: re-render the report from existing
//! results files, optionally compared with a previous reports directory.

use meniscus_harness::report::{Baseline, RenderOptions};
use std::path::PathBuf;
use std::process::ExitCode;

/// Options of `cargo xtask report`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Directory holding <case>/results.json [default: <workspace>/reports].
    #[arg(long, value_name = "DIR")]
    out: Option<PathBuf>,
    /// A previous reports/ directory: mark every metric better / worse / unchanged against it
    /// (in the HTML and summary.md).
    #[arg(long, value_name = "DIR")]
    baseline: Option<PathBuf>,
}

/// Re-renders every case page (of the cases in validation/), summary.json, summary.md and
/// index.html.
pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    let root = crate::workspace_root();
    let out = args.out.unwrap_or_else(|| root.join("reports"));
    let cases = meniscus_harness::case::known_cases(&root.join("validation"))?;
    let baseline = args.baseline.as_deref().map(|dir| Baseline::load(dir, Some(&cases))).transpose()?;
    let extras = meniscus_harness::validate::extra_pages(&out);
    let rendered = meniscus_harness::report::render(
        &out,
        &RenderOptions { cases: Some(cases), baseline, extras, elapsed_s: None },
    )?;
    if rendered.results.is_empty() {
        anyhow::bail!("no <case>/results.json under {}: run `cargo xtask validate` first", out.display());
    }
    if let Some(cmp) = &rendered.comparison {
        eprintln!("against baseline {}: {}", cmp.baseline.display(), cmp.tally().describe());
    }
    eprintln!(
        "rendered {} case(s) into {} (summary: {})",
        rendered.results.len(),
        out.join("index.html").display(),
        out.join("summary.md").display()
    );
    Ok(ExitCode::SUCCESS)
}
