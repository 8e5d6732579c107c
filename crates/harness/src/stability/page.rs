//! `reports/stability/index.html`: the envelope's rows, grouped by study, self-contained.

use super::{Config, Row, StabilityResults, pct};
use crate::numbers::format_dx;
use crate::report::html::{ExtraPage, checks_table, page as html_page};
use maud::{Markup, html};

impl StabilityResults {
    /// The line of the report's index that links this page.
    pub fn index_entry(&self) -> ExtraPage {
        let (passed, failed) = self.counts();
        ExtraPage {
            href: format!("{}/index.html", super::NAME),
            title: "Stability envelope".into(),
            summary: format!(
                "largest stable time step and Reynolds number, jittered lattices, long runs: {} rows \
                 ({} runs, {:.0} s), {passed} / {} checks passed{}",
                self.runs.len(),
                self.runs.iter().map(|r| r.trials.len()).sum::<usize>(),
                self.elapsed_s,
                passed + failed,
                if self.complete { "" } else { " (incomplete)" }
            ),
            pass: self.pass() && self.complete,
        }
    }
}

const STUDIES: [(&str, &str, &str); 4] = [
    (
        "dt_max",
        "Largest stable time step",
        "Δt = k × the adaptive step of Qiu 2013 eqs. 17–18 with α_c = α_d = 0.2 (the CFL and viscous \
         limits; for WCSPH also the acoustic limit α_c h/(c0 + u_max) and the force limit), k bisected \
         geometrically; the scene rule cfl ≤ 1 caps k at 5. For the drop at dx = 0.04, the paper's fixed \
         Δt = 2e-5 s is k ≈ 1/6 of the initial CFL step.",
    ),
    (
        "re_max",
        "Largest stable Reynolds number (periodic channel)",
        "Re = U D / ν with the body force F = 12 ν U / D² at fixed ν, run to the end time with the adaptive \
         step (α = 0.2), Re bisected geometrically. ISPH only: WCSPH's acoustic step (c0 = 10 u_max ∝ Re) \
         needs about 1e3 Re steps to 1 D²/ν (39 064 at Re = 40), four million at Re = 4000.",
    ),
    (
        "jitter",
        "Jittered initial lattice",
        "Every particle displaced by a vector uniform in the disc of radius f dx (bodies[0].jitter, ChaCha8 \
         with the stated seed), the case's own time step; velocities and pressures are those of the \
         lattice position.",
    ),
    (
        "long_run",
        "Long run of the drop",
        "The drop to t = 0.02 s (the case ends at 0.008 s) with the case's time step: the exact flow \
         conserves kinetic energy, so the drift max |E(t)/E(0) − 1| measures the scheme's dissipation \
         (or growth).",
    ),
];

fn trials_text(r: &Row) -> String {
    let mut t: Vec<&super::Trial> = r.trials.iter().collect();
    t.sort_by(|a, b| a.value.total_cmp(&b.value));
    t.iter()
        .map(|t| {
            format!(
                "{}: {} ({} steps, error {})",
                super::bisect::sig3(t.value),
                if t.stable { "stable" } else { "unstable" },
                t.steps,
                pct(t.error)
            )
        })
        .collect::<Vec<_>>()
        .join("; ")
}

fn row(r: &Row) -> Markup {
    let stable = r.outcome == "ok";
    html! {
        tr {
            td class="l" { (r.case) }
            td class="l" { code { (r.run.preset) } }
            td { (format_dx(r.run.dx)) }
            td { (r.run.particles) }
            td class="l" { b { (r.measured) } }
            td class=(if stable { "l pass" } else { "l fail" }) { (r.outcome) }
            td { (r.trials.len()) }
            td { (format!("{:.1}", r.run.wall_s)) }
            td class="l note" { (r.config) br; (trials_text(r)) }
        }
    }
}

/// The page of `res`, the option sets described as in `config`.
pub fn render(res: &StabilityResults, config: &Config) -> String {
    let s = &res.settings;
    let (passed, failed) = res.counts();
    let trials: usize = res.runs.iter().map(|r| r.trials.len()).sum();
    let body = html! {
        p { a href="../index.html" { "← all cases" } }
        h1 { "Stability envelope (projection ISPH)" }
        p {
            "Where the scheme stops working, per option set: the largest stable time step and Reynolds number, "
            "the tolerance of a disordered initial lattice, and the energy drift of a long run, for the elliptical "
            "drop (dx = " (format_dx(s.drop_dx)) ") and the periodic Poiseuille channel (dx = " (format_dx(s.channel_dx))
            ", to " (s.channel_tau) " D²/ν). A run is " b { "stable" } " when it reaches its end time with no guard "
            "tripped and its error is within the bound: the larger of the a and b semi-axis errors over the history ≤ "
            (pct(s.drop_bound)) " for the drop, the velocity profile's L2 error at the end ≤ " (pct(s.channel_bound))
            " for the channel. Otherwise the outcome column gives the solver's typed error (stage, step, time, cause) "
            "or the error above its bound."
        }
        p {
            "Budget: coarse spacings so that the study stays under about 15 minutes on 2 cores. This run: tier "
            code { (res.tier) } ", " (res.runs.len()) " rows, " (trials) " runs (" (res.executed) " executed, "
            (res.reused) " from the cache), " (format!("{:.0}", res.elapsed_s)) " s wall with "
            (res.provenance.threads) " threads"
            @if !res.complete { ", " b { "incomplete (interrupted)" } }
            ". Commit " code { (res.provenance.git_commit.as_deref().unwrap_or("unknown")) } ", "
            (res.provenance.date_utc) "."
        }
        p class=(if failed == 0 { "pass" } else { "fail" }) { (passed) " / " (passed + failed) " checks passed" }
        h2 { "Checks" }
        (checks_table(&res.checks))
        h2 { "Option sets" }
        ul {
            @for set in config.option_sets.iter().filter(|o| s.option_sets.contains(&o.name)) {
                li { code { (set.name) } ": " (set.description) }
            }
        }
        @for (study, title, what) in STUDIES {
            @let rows: Vec<&Row> = res.runs.iter().filter(|r| r.study == study).collect();
            @if !rows.is_empty() {
                h2 id=(study) { (title) " (" code { (study) } ")" }
                p { (what) }
                table {
                    tr {
                        th class="l" { "case" } th class="l" { "option set" } th { "dx" } th { "particles" }
                        th class="l" { "measured" } th class="l" { "outcome" } th { "runs" } th { "wall [s]" }
                        th class="l" { "configuration and runs (value: verdict)" }
                    }
                    @for r in rows { (row(r)) }
                }
            }
        }
    };
    html_page("Meniscus: stability envelope", body)
}
