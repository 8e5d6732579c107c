//! What the runs cost (issue #33), for the index and `summary.md`: per case and for the
//! tier the wall and CPU seconds, the particle-steps, and the cost of one particle-step;
//! the ten costliest runs with their threads, steps and rates.
//!
//! CPU seconds are those of the threads that ran each run ([`crate::runner`]); a run's
//! cost per particle-step is `cpu_s / (particles × steps)` in core-µs, which compares runs
//! of any thread count, and its ratio to the floor of NUMERICS.md
//! ([`FLOOR_CORE_US_PER_PARTICLE_PASS`]: one fused pair pass) says how many such passes a
//! step is worth. Times of cached runs are those measured when they ran.

use crate::results::{CaseResults, FLOOR_CORE_US_PER_PARTICLE_PASS, RunResult, Totals};
use maud::{Markup, html};
use std::fmt::Write;

/// How many of the costliest runs the tables list.
pub const TOP: usize = 10;

/// A run with its case.
pub type CaseRun<'a> = (&'a str, &'a RunResult);

/// The `n` costliest runs over `results`, by CPU time (wall time for runs without one).
pub fn costliest(results: &[CaseResults], n: usize) -> Vec<CaseRun<'_>> {
    let mut all: Vec<CaseRun<'_>> =
        results.iter().flat_map(|c| c.runs.iter().map(move |r| (c.case.as_str(), r))).collect();
    let cost = |r: &RunResult| r.cpu_s.unwrap_or(r.wall_s);
    all.sort_by(|a, b| cost(b.1).total_cmp(&cost(a.1)));
    all.truncate(n);
    all
}

fn opt(v: Option<f64>, digits: usize) -> String {
    v.map_or("—".into(), |x| format!("{x:.digits$}"))
}

fn cpu(t: &Totals) -> String {
    opt(t.measured_cpu_s(), 1)
}

/// Rate as text: `1.23e6`.
fn rate(v: Option<f64>) -> String {
    v.map_or("—".into(), |x| format!("{x:.3e}"))
}

/// The row cells of a run: case, run, threads, particles, steps, wall, CPU, steps/s,
/// particle-steps/s, core-µs per particle-step.
fn run_cells(case: &str, r: &RunResult) -> [String; 11] {
    let steps_per_s = (r.wall_s > 0.0).then(|| r.steps as f64 / r.wall_s);
    [
        case.to_string(),
        r.slug(),
        r.threads.map_or("—".into(), |t| t.to_string()),
        r.particles.to_string(),
        r.steps.to_string(),
        format!("{:.1}", r.wall_s),
        opt(r.cpu_s, 1),
        opt(steps_per_s, 1),
        rate(r.particle_steps_per_s()),
        opt(r.core_us_per_particle_step(), 2),
        opt(r.floor_ratio(), 1),
    ]
}

const RUN_HEADER: [&str; 11] = [
    "case",
    "run",
    "threads",
    "particles",
    "steps",
    "wall [s]",
    "CPU [s]",
    "steps/s",
    "particle-steps/s",
    "core-µs per particle-step",
    "× floor",
];

/// The cells of a case's (or the tier's) totals: runs, wall, CPU, particle-steps,
/// particle-steps per wall second, core-µs per particle-step and its ratio to the floor.
fn total_cells(t: &Totals) -> [String; 7] {
    [
        t.runs.to_string(),
        format!("{:.1}", t.wall_s),
        cpu(t),
        format!("{:.3e}", t.particle_steps),
        rate((t.wall_s > 0.0).then(|| t.particle_steps / t.wall_s)),
        opt(t.core_us_per_particle_step(), 2),
        opt(t.core_us_per_particle_step().map(|c| c / FLOOR_CORE_US_PER_PARTICLE_PASS), 1),
    ]
}

const TOTAL_HEADER: [&str; 7] = [
    "runs",
    "wall [s]",
    "CPU [s]",
    "particle-steps",
    "particle-steps/s",
    "core-µs per particle-step",
    "× floor",
];

fn tier_note(results: &[CaseResults], elapsed_s: Option<f64>) -> String {
    let t = Totals::of(results.iter().flat_map(|c| &c.runs));
    let mut s = format!(
        "Summed over the {} runs: {:.0} s of run wall time, {} s of CPU time.",
        t.runs,
        t.wall_s,
        cpu(&t)
    );
    if let Some(e) = elapsed_s {
        let _ = write!(s, " The last invocation that ran runs took {e:.0} s wall.");
    }
    s
}

/// The run-time section of `index.html`.
pub fn html_section(results: &[CaseResults], elapsed_s: Option<f64>) -> Markup {
    let tier = Totals::of(results.iter().flat_map(|c| &c.runs));
    html! {
        h2 { "Run time" }
        p { (tier_note(results, elapsed_s)) }
        p class="note" {
            "CPU time: the threads that ran the run. A run's cost per particle-step is its CPU time over particles × steps (comparable across thread counts); × floor divides it by "
            (format!("{FLOOR_CORE_US_PER_PARTICLE_PASS:.3}"))
            " core-µs, one fused pair pass per particle at the floor of NUMERICS.md (2.2 ns per pair, 0.42 ms for the drop at Δx = 0.02 on two threads). Times of cached runs are those measured when they ran."
        }
        table {
            tr { th class="l" { "case" } @for h in TOTAL_HEADER { th { (h) } } }
            @for c in results {
                tr {
                    td class="l" { (c.case) }
                    @for cell in total_cells(&Totals::of(&c.runs)) { td { (cell) } }
                }
            }
            tr {
                td class="l" { b { "tier" } }
                @for cell in total_cells(&tier) { td { b { (cell) } } }
            }
        }
        h3 { "The " (TOP) " costliest runs" }
        table {
            tr { @for (i, h) in RUN_HEADER.iter().enumerate() { th class=(if i < 2 { "l" } else { "" }) { (h) } } }
            @for (case, r) in costliest(results, TOP) {
                tr {
                    @for (i, cell) in run_cells(case, r).iter().enumerate() {
                        td class=(if i < 2 { "l" } else { "" }) { (cell) }
                    }
                }
            }
        }
    }
}

/// The run-time section of `summary.md`.
pub fn markdown_section(
    md: &mut String,
    results: &[CaseResults],
    elapsed_s: Option<f64>,
) -> std::fmt::Result {
    writeln!(md, "\n## Run time\n")?;
    writeln!(md, "{}\n", tier_note(results, elapsed_s))?;
    writeln!(
        md,
        "× floor: core-µs per particle-step over {FLOOR_CORE_US_PER_PARTICLE_PASS:.3}, one fused pair pass per particle (NUMERICS.md).\n"
    )?;
    writeln!(md, "| case | {} |", TOTAL_HEADER.join(" | "))?;
    writeln!(md, "|---|{}", "---:|".repeat(TOTAL_HEADER.len()))?;
    for c in results {
        writeln!(md, "| {} | {} |", c.case, total_cells(&Totals::of(&c.runs)).join(" | "))?;
    }
    let tier = Totals::of(results.iter().flat_map(|c| &c.runs));
    writeln!(md, "| **tier** | {} |", total_cells(&tier).join(" | "))?;
    writeln!(md, "\nThe {TOP} costliest runs:\n")?;
    writeln!(md, "| {} |", RUN_HEADER.join(" | "))?;
    writeln!(md, "|---|---|{}", "---:|".repeat(RUN_HEADER.len() - 2))?;
    for (case, r) in costliest(results, TOP) {
        writeln!(md, "| {} |", run_cells(case, r).map(|c| c.replace('|', "\\|")).join(" | "))?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::BTreeMap;

    fn run(preset: &str, particles: usize, steps: usize, wall_s: f64, cpu_s: Option<f64>) -> RunResult {
        RunResult {
            scheme: "isph".into(),
            preset: preset.into(),
            dx: 0.02,
            start: None,
            particles,
            steps,
            wall_s,
            cpu_s,
            threads: Some(2),
            steady_at: None,
            status: "ok".into(),
            metrics: BTreeMap::new(),
            series: BTreeMap::new(),
        }
    }

    fn case(name: &str, runs: Vec<RunResult>) -> CaseResults {
        CaseResults {
            case: name.into(),
            scheme: "isph".into(),
            tier: "default".into(),
            runs,
            convergence: BTreeMap::new(),
            checks: Vec::new(),
        }
    }

    #[test]
    fn totals_rates_and_the_costliest_runs() {
        let results = vec![
            case("a", vec![run("p", 1000, 100, 1.0, Some(0.3)), run("q", 2000, 50, 4.0, Some(7.0))]),
            case("b", vec![run("r", 500, 10, 2.0, None)]),
        ];
        let t = Totals::of(&results[0].runs);
        assert_eq!((t.runs, t.without_cpu), (2, 0));
        assert!((t.particle_steps - 200_000.0).abs() < 1e-9 && (t.cpu_s - 7.3).abs() < 1e-12);
        assert!((t.core_us_per_particle_step().unwrap() - 36.5).abs() < 1e-9);
        // A run without a CPU time leaves the cost per particle-step undefined.
        assert_eq!(Totals::of(&results[1].runs).core_us_per_particle_step(), None);
        let top: Vec<String> =
            costliest(&results, 2).iter().map(|(c, r)| format!("{c}/{}", r.preset)).collect();
        assert_eq!(top, ["a/q", "b/r"], "by CPU time, wall time without one");
        let cells = run_cells("a", &results[0].runs[1]);
        assert_eq!(cells[4], "50");
        assert_eq!(cells[8], "2.500e4", "particle-steps per wall second");
        assert_eq!(cells[9], "70.00", "core-µs per particle-step");
        assert_eq!(cells[10], format!("{:.1}", 70.0 / FLOOR_CORE_US_PER_PARTICLE_PASS));
        let mut md = String::new();
        markdown_section(&mut md, &results, Some(12.0)).unwrap();
        assert!(md.contains("| **tier** | 3 | 7.0 | 7.3 | 2.050e5 |"), "{md}");
        assert!(md.contains("took 12 s wall"), "{md}");
        let page = html_section(&results, None).into_string();
        assert!(page.contains("costliest runs") && page.contains("isph-q_dx0.02"));
    }
}
