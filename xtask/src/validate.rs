//! `cargo xtask validate [--quick|--full] [--case NAME…] [--out DIR] [--force] [--jobs N]
//! [--baseline DIR]`.

use anyhow::Context;
use meniscus_harness::ValidateOptions;
use meniscus_harness::numbers::{check_bound, check_number};
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;

/// Options of `cargo xtask validate`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The CI tier (coarse spacings, under 10 minutes).
    #[arg(long, conflicts_with = "full")]
    quick: bool,
    /// The extended sweeps (finer spacings, long runs).
    #[arg(long)]
    full: bool,
    /// Run only this case (repeatable); all of validation/*.json by default. `stability`
    /// runs the stability envelope (reports/stability/, its data in
    /// validation/studies/stability.json), which the full tier also runs.
    #[arg(long = "case", value_name = "NAME")]
    cases: Vec<String>,
    /// Output directory [default: <workspace>/reports].
    #[arg(long, value_name = "DIR")]
    out: Option<PathBuf>,
    /// Rerun every run even when a valid cached result exists.
    #[arg(long)]
    force: bool,
    /// Runs executed concurrently [default: the machine's threads]. Runs of 50 000
    /// particles or more take every thread and run alone, first.
    #[arg(long, value_name = "N")]
    jobs: Option<usize>,
    /// No progress bars.
    #[arg(long)]
    no_progress: bool,
    /// A previous reports/ directory: mark every metric better / worse / unchanged against it
    /// (in the HTML and summary.md). The exit code still depends on the checks only.
    #[arg(long, value_name = "DIR")]
    baseline: Option<PathBuf>,
    #[command(flatten)]
    executor: crate::executor::ExecutorArgs,
}

/// Runs the validation; the exit code is 0 only when every check passes.
pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    let root = crate::workspace_root();
    let tier = crate::tier(args.quick, args.full);
    let (cases, run_cases, run_stability) = meniscus_harness::stability::split_cases(&args.cases, tier);
    let slurm = args.executor.connect(&root)?;
    let opts = ValidateOptions {
        tier,
        cases,
        out: args.out.unwrap_or_else(|| root.join("reports")),
        validation_dir: root.join("validation"),
        workspace: root.clone(),
        force: args.force,
        jobs: args.jobs.unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get())).max(1),
        progress: !args.no_progress,
        baseline: args.baseline,
        slurm: slurm.clone(),
    };
    let start = Instant::now();
    let outcome = if run_cases {
        meniscus_harness::validate(&opts).context("validation could not run")?
    } else {
        meniscus_harness::Outcome { results: Vec::new(), executed: 0, reused: 0, comparison: None }
    };
    for r in &outcome.results {
        let (passed, failed) = r.counts();
        let xfail = meniscus_harness::results::expected_failures(&r.checks);
        eprintln!("{:<24} {:>3} passed {:>3} failed {:>3} expected to fail", r.case, passed, failed, xfail);
        for c in r.checks.iter().filter(|c| !c.pass || c.expected_failure.is_some()) {
            let value = c.value.map_or("n/a".to_string(), |v| check_number(c, v));
            let bound = Some(check_bound(c)).filter(|b| !b.is_empty()).map(|b| format!(" (bound {b})"));
            let note = c.note.as_deref().map(|n| format!(" [{n}]")).unwrap_or_default();
            eprintln!("  {} {}: {value}{}{note}", c.verdict().label(), c.name, bound.unwrap_or_default());
        }
    }
    if let Some(cmp) = &outcome.comparison {
        eprintln!("against baseline {}: {}", cmp.baseline.display(), cmp.tally().describe());
    }
    let mut stability_pass = true;
    if run_stability {
        use meniscus_harness::stability;
        let s0 = Instant::now();
        let res = stability::run(&stability::StabilityOptions {
            out: opts.out.clone(),
            validation_dir: opts.validation_dir.clone(),
            workspace: root.clone(),
            tier,
            config: stability::Config::load(&opts.validation_dir)?,
            force: opts.force,
            jobs: opts.jobs,
            progress: opts.progress,
            slurm,
        })
        .context("the stability envelope could not run")?;
        let (passed, failed) = res.counts();
        eprintln!(
            "{:<24} {:>3} passed {:>3} failed ({} rows, {:.1} s) -> {}",
            "stability",
            passed,
            failed,
            res.runs.len(),
            s0.elapsed().as_secs_f64(),
            opts.out.join("stability/index.html").display()
        );
        for c in res.checks.iter().filter(|c| !c.verdict().expected()) {
            let value = c.value.map_or("n/a".to_string(), |v| check_number(c, v));
            let note = c.note.as_deref().map(|n| format!(" [{n}]")).unwrap_or_default();
            eprintln!("  {} {}: {value}{note}", c.verdict().label(), c.name);
        }
        stability_pass = res.pass();
    }
    if run_cases {
        eprintln!(
            "{} runs executed, {} cached, {:.1} s; report: {} (summary: {})",
            outcome.executed,
            outcome.reused,
            start.elapsed().as_secs_f64(),
            opts.out.join("index.html").display(),
            opts.out.join("summary.md").display()
        );
    }
    Ok(if outcome.pass() && stability_pass { ExitCode::SUCCESS } else { ExitCode::FAILURE })
}
