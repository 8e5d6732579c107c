//! The study's self-contained HTML page (maud; inline CSS, figures inlined as SVG).

use super::channel::{ChannelRow, ChannelStudy};
use super::pipe::{PipeRow, PipeStudy};
use super::record::{Cost, RunRow, SchemeCost, Study};
use crate::report::html::breakable;
use crate::results::FLOOR_CORE_US_PER_PARTICLE_PASS;
use maud::{DOCTYPE, Markup, PreEscaped, html};

const CSS: &str = "body{font-family:system-ui,sans-serif;margin:2em;max-width:1250px;color:#222}\
table{border-collapse:collapse;margin:1em 0;max-width:100%}th,td{border:1px solid #ccc;padding:3px 8px;text-align:right}\
th{background:#f0f0f0}td.l,th.l{text-align:left}.pass{background:#d9f2d9;color:#145214}\
.fail{background:#f8d7d7;color:#7a1010}.na{background:#eee;color:#555}tr.front td{font-weight:bold}\
figure{display:inline-block;margin:0.5em;vertical-align:top}figcaption{font-size:90%;color:#555;max-width:820px}\
code{font-size:90%}.small{font-size:85%}table.small td,table.small th{padding:2px 4px}";

/// A figure: file name (without `.svg`), SVG text and caption.
pub struct Figure {
    /// File name without extension.
    pub file: String,
    /// The SVG document.
    pub svg: String,
    /// What it shows.
    pub caption: String,
}

fn pct(v: Option<f64>) -> String {
    v.map_or("—".into(), |x| if x.is_finite() { crate::numbers::percent(x) } else { "NaN".into() })
}

fn value(v: Option<f64>, unit: &str) -> String {
    v.map_or("—".into(), |x| if unit.is_empty() { format!("{x:.3}") } else { format!("{x:.3} {unit}") })
}

/// Which half of a wide table a row function renders: the run's options, or what it
/// measured (each beginning with the run's id), so no table is wider than the page.
#[derive(Clone, Copy, PartialEq)]
enum Half {
    Options,
    Measured,
}

/// The id cell that begins both halves of a row.
fn id_cell(id: &str, reused: bool) -> Markup {
    html! { td class="l" { code { (breakable(id)) } @if reused { " (cached)" } } }
}

fn run_row(r: &RunRow, front: bool, half: Half) -> Markup {
    let ms = r.cost.per_step().map_or("—".into(), |s| format!("{:.2}", 1e3 * s));
    html! {
        tr class=(if front { "front" } else { "" }) {
            (id_cell(&r.id, r.reused))
            @if half == Half::Options {
                td { (r.dx) }
                td class="l" { (r.scheme) }
                @match r.variant {
                    Some(v) => {
                        td class="l" { (snake(v.ppe)) }
                        td class="l" { (format!("{:?}", v.gradient).to_lowercase()) }
                        td class="l" { (format!("{:?}", v.divergence).to_lowercase()) }
                        td class="l" { (format!("{:?}", v.shifting).to_lowercase()) }
                        td class="l" { (format!("{:?}", v.dt).to_lowercase()) }
                    }
                    None => { td class="l" colspan="5" { "the case preset's own options" } }
                }
                td class="l" { (r.preset.as_deref().unwrap_or("")) }
            } @else {
                (cost_cells(r.threads, &r.cost, &ms))
                td { (pct(r.b_err)) }
                td { (pct(r.b_err_max)) }
                td { (pct(r.a_err)) }
                (status_cell(r.ok(), &r.status, r.expected_divergence.as_deref()))
            }
        }
    }
}

/// A row's status; a divergence the case file expects at the row's spacing (`expected`,
/// its reason in the cell's title) reads as expected, and a completion there says so.
fn status_cell(ok: bool, status: &str, expected: Option<&str>) -> Markup {
    html! {
        @match (ok, expected) {
            (true, None) => { td class="l" { (status) } }
            (true, Some(why)) => { td class="l" title=(why) { (status) " (the case file expects a divergence here)" } }
            (false, None) => { td class="l fail" { (status) } }
            (false, Some(why)) => { td class="l na" title=(why) { "expected (case file): " (status) } }
        }
    }
}

/// The cells both studies' rows share: threads, particles, steps, wall time \[s\], CPU/wall,
/// `ms` per step (formatted by the caller), mean PPE iterations, core-µs per particle-step
/// and its ratio to the floor ([`Cost::floor_ratio`]).
fn cost_cells(threads: usize, c: &Cost, ms: &str) -> Markup {
    html! {
        td { (threads) }
        td { (c.particles) }
        td { (c.steps) }
        td { (format!("{:.3}", c.wall_s)) }
        td { (c.cpu_s.map_or("—".into(), |cpu| format!("{:.2}", cpu / c.wall_s.max(1e-12)))) }
        td { (ms) }
        td { (format!("{:.1}", c.ppe_iterations_mean)) }
        td { (c.core_us_per_particle_step().map_or("—".into(), |u| format!("{u:.2}"))) }
        td { (c.floor_ratio().map_or("—".into(), |x| format!("{x:.1}"))) }
    }
}

/// A serde enum value as its snake_case name.
fn snake<T: serde::Serialize>(v: T) -> String {
    serde_json::to_value(v).ok().and_then(|v| v.as_str().map(String::from)).unwrap_or_default()
}

fn channel_row(r: &ChannelRow, front: bool, half: Half) -> Markup {
    let ms = if r.cost.steps > 0 {
        format!("{:.3}", 1e3 * r.cost.wall_s / r.cost.steps as f64)
    } else {
        "—".into()
    };
    html! {
        tr class=(if front { "front" } else { "" }) {
            (id_cell(&r.id, r.reused))
            @if half == Half::Options {
                td { (format!("{:.5}", r.dx)) }
                td class="l" { (r.scheme) }
                @match r.variant {
                    Some(v) => {
                        td class="l" { (snake(v.viscosity)) }
                        td class="l" { (snake(v.shifting)) }
                        td class="l" { (snake(v.ppe)) }
                    }
                    None => { td class="l" colspan="3" { "the preset's scheme options" } }
                }
                td class="l" { (r.series().unwrap_or_default()) }
            } @else {
                (cost_cells(r.threads, &r.cost, &ms))
                td { (pct(r.error)) }
                td { (pct(r.error_startup_max)) }
                td class=(if r.ok() { "l" } else { "l fail" }) { (r.status) }
            }
        }
    }
}

fn channel_section(c: &ChannelStudy) -> Markup {
    html! {
        h2 { "Periodic channel" }
        p {
            "Case " code { (c.case) } " (preset re4, mirror walls, periodic in x), from rest to τ = νt/D² = 1. Error: "
            (c.error_metric) ". Bold rows are on their scheme's Pareto front of (error, wall time)."
        }
        ul { @for d in &c.design { li { (d) } } }
        table class="small" {
            tr {
                th class="l" { "run" } th { "Δx" } th class="l" { "scheme" } th class="l" { "viscosity" } th class="l" { "shifting" } th class="l" { "PPE" }
                th class="l" { "preset" }
            }
            @for r in &c.runs { (channel_row(r, c.pareto.contains(&r.id), Half::Options)) }
        }
        table class="small" {
            tr {
                th class="l" { "run" } th { "threads" } th { "particles" } th { "steps" } th { "wall [s]" } th { "CPU/wall" }
                th { "ms/step" } th { "PPE its" } th { "core-µs per particle-step" } th { "× floor" } th { "profile error (τ = 1)" } th { "start-up max" } th class="l" { "status" }
            }
            @for r in &c.runs { (channel_row(r, c.pareto.contains(&r.id), Half::Measured)) }
        }
    }
}

fn pipe_row(r: &PipeRow, half: Half) -> Markup {
    let opt = |v: Option<f64>, digits: usize| v.map_or("—".into(), |x| format!("{x:.digits$}"));
    let particles = match r.wall_particles {
        Some(w) => format!("{} + {w}", r.cost.particles),
        None => r.cost.particles.to_string(),
    };
    html! {
        tr {
            (id_cell(&r.id, r.reused))
            @if half == Half::Options {
                td class="l" { (r.scheme) }
                td class="l" { (r.preset) }
                td { (r.r_over_dx) }
                td { (r.threads) }
                td { (particles) }
                td { (r.cost.steps) }
            } @else {
                td { (format!("{:.2}", r.cost.wall_s)) }
                td { (opt(r.cost.cpu_s, 2)) }
                td { (r.particle_steps_per_s.map_or("—".into(), |v| format!("{v:.3e}"))) }
                td { (opt(r.memory_peak_bytes.map(|b| b as f64 / 1e6), 1)) }
                td { (opt(r.memory_rss_before_bytes.map(|b| b as f64 / 1e6), 1)) }
                td { (opt(r.bytes_per_particle, 0)) }
                td { (pct(r.error)) }
                td { (pct(r.error_startup_max)) }
                td class=(if r.ok() { "l" } else { "l fail" }) { (r.status) }
            }
        }
    }
}

fn pipe_section(p: &PipeStudy) -> Markup {
    html! {
        h2 { "3D pipe" }
        p {
            "Case " code { (p.case) } " (periodic Hagen–Poiseuille pipe, dummy-particle wall shell, Re = 1), from rest to ν t/R² = 1, "
            "its presets as the validation runs them. Error: " (p.error_metric) ". Particles: fluid + wall (the wall's dummy particles counted "
            "from the scene as the solver seeds them); particle-steps/s is fluid particles × steps over the wall time. Peak memory: "
            (p.memory) " (the process's resident set before each run is shown beside it); bytes/particle divides it by the fluid and wall particles. MB = 10⁶ bytes."
        }
        ul { @for d in &p.design { li { (d) } } }
        table class="small" {
            tr {
                th class="l" { "run" } th class="l" { "scheme" } th class="l" { "preset" } th { "R/Δx" } th { "threads" } th { "particles (fluid + wall)" }
                th { "steps" }
            }
            @for r in &p.runs { (pipe_row(r, Half::Options)) }
        }
        table class="small" {
            tr {
                th class="l" { "run" } th { "wall [s]" } th { "CPU [s]" } th { "particle-steps/s" } th { "peak [MB]" } th { "resident before [MB]" } th { "bytes/particle" }
                th { "profile error (ν t/R² = 1)" } th { "start-up max" } th class="l" { "status" }
            }
            @for r in &p.runs { (pipe_row(r, Half::Measured)) }
        }
    }
}

/// The table of each scheme's cost per particle-step on each case ([`SchemeCost`]), and
/// the floor it is measured against.
fn scheme_cost_section(costs: &[SchemeCost], threads: usize) -> Markup {
    let list = |v: Vec<String>| v.join(", ");
    let opt = |v: Option<f64>, digits: usize| v.map_or("—".into(), |x| format!("{x:.digits$}"));
    html! {
        h2 { "Cost per particle-step by scheme" }
        p {
            "Per case and per scheme, each named series' CPU time over particles × steps (core-µs per particle-step), from its finished runs with "
            (threads) " threads, at each spacing and pooled over them (summed core-seconds over summed particle-steps), and its ratio to the floor. "
            "The floor is NUMERICS.md's (\"Performance floor\", measured on the 2-core machine): one fused pair pass costs about 2.2 ns per pair with "
            "two threads, 0.42 ms over the drop's 7860 particles at Δx = 0.02 (24 pairs each), so " (format!("{FLOOR_CORE_US_PER_PARTICLE_PASS:.3}"))
            " core-µs per particle; × floor is how many such passes a step is worth. It counts passes of the ISPH drop's neighbourhood: MPS's "
            "neighbour lists reach its largest operator radius plus a 0.5 l0 skin, beyond ISPH's 2h = 3 Δx, so one of its passes visits more pairs."
        }
        table {
            tr {
                th class="l" { "case" } th class="l" { "scheme" } th class="l" { "series" } th class="l" { "Δx" } th class="l" { "particles" }
                th class="l" { "steps" } th class="l" { "core-µs per particle-step" } th class="l" { "× floor" }
                th { "pooled core-µs per particle-step" } th { "pooled × floor" }
            }
            @for c in costs {
                tr {
                    td class="l" { (c.case) } td class="l" { (c.scheme) } td class="l" { (c.series) }
                    td class="l" { (list(c.spacings.iter().map(|s| format!("{}", (s.dx * 1e6).round() / 1e6)).collect())) }
                    td class="l" { (list(c.spacings.iter().map(|s| s.particles.to_string()).collect())) }
                    td class="l" { (list(c.spacings.iter().map(|s| s.steps.to_string()).collect())) }
                    td class="l" { (list(c.spacings.iter().map(|s| opt(s.core_us_per_particle_step, 3)).collect())) }
                    td class="l" { (list(c.spacings.iter().map(|s| opt(s.floor_ratio, 1)).collect())) }
                    td { (opt(c.core_us_per_particle_step, 3)) }
                    td { (opt(c.floor_ratio, 1)) }
                }
            }
        }
    }
}

/// The page of a study, with its figures inlined.
pub fn render(study: &Study, figures: &[Figure]) -> String {
    let m = &study.machine;
    let p = &m.provenance;
    let front: Vec<&RunRow> =
        study.pareto.iter().filter_map(|id| study.runs.iter().find(|r| &r.id == id)).collect();
    let diverged = study.runs.iter().filter(|r| !r.ok()).count();
    let expected = study.runs.iter().filter(|r| !r.ok() && r.expected_divergence.is_some()).count();
    let reused = study.runs.iter().filter(|r| r.reused).count()
        + study.channel.iter().flat_map(|c| &c.runs).filter(|r| r.reused).count()
        + study.pipe.iter().flat_map(|p| &p.runs).filter(|r| r.reused).count();
    html! {
        (DOCTYPE)
        html lang="en" {
            head {
                meta charset="utf-8";
                title { "Meniscus work-precision study (elliptical drop, periodic channel, 3D pipe)" }
                style { (PreEscaped(CSS)) }
            }
            body {
                h1 { "Work-precision study: elliptical drop, periodic channel and 3D pipe" }
                p {
                    "Wall time against the relative error of the semi-axis b at t = 0.008 s (second moments, against the ellipse ODE), for "
                    (study.runs.len()) " runs of the " code { (study.case) } " scene ("
                    (diverged) " diverged" @if expected > 0 { ", " (expected) " of them where the case file expects it" } "), tier " b { (study.tier) } ", " b { (m.build) } " build, " (study.threads) " threads for the main runs; the study took "
                    (format!("{:.0}", study.elapsed_s)) " s (every part)."
                    @if !study.complete { " " b { "Incomplete: the study was interrupted." } }
                    @if reused > 0 {
                        " " b { (reused) " runs (marked cached) were taken from the run cache of an earlier invocation" }
                        " (" code { "--resume" } "): their times were measured then, under that invocation's load."
                    }
                    @if study.channel.is_some() { " The periodic channel's study has its own section and figure below." }
                    @if study.pipe.is_some() { " So has the 3D pipe, with each run's particle-steps per second and peak memory." }
                    " Beside the ISPH option sets, both studies run the other schemes (WCSPH, MPS; see Design) as separate series, each with its own Pareto front."
                }
                h2 { "Targets" }
                table {
                    tr { th class="l" { "target" } th { "measured" } th { "threshold" } th { "verdict" } th class="l" { "how" } }
                    @for t in &study.targets {
                        tr {
                            td class="l" { (t.name) }
                            td { (value(t.value, &t.unit)) }
                            td { (if t.kind == "max" { "≤ " } else { "≥ " }) (value(Some(t.threshold), &t.unit)) }
                            td class=(match t.pass { Some(true) => "pass", Some(false) => "fail", None => "na" }) { (t.verdict()) }
                            td class="l small" { (t.note) }
                        }
                    }
                }
                p class="small" {
                    "Timings were taken on a shared machine (load average "
                    (m.loadavg_start.as_deref().unwrap_or("?")) " at the start, "
                    (m.loadavg_end.as_deref().unwrap_or("?")) " at the end): compare them as ratios within one study. CPU/wall in the run tables is the CPU time of the run's threads over its wall time; well below the run's thread count, the run waited for the CPU. Core-µs per particle-step is that CPU time over particles × steps, and × floor divides it by " (format!("{FLOOR_CORE_US_PER_PARTICLE_PASS:.3}")) " core-µs, one fused pair pass per particle at the floor of NUMERICS.md (2.2 ns per pair): how many such passes a step is worth."
                }
                h2 { "Figures" }
                @for f in figures {
                    figure {
                        (PreEscaped(&f.svg))
                        figcaption { (f.caption) " (" a href=(format!("{}.svg", f.file)) { (f.file) ".svg" } ")" }
                    }
                }
                (scheme_cost_section(&study.scheme_costs, study.threads))
                h2 { "Pareto fronts" }
                p {
                    "One front per scheme: the runs of a scheme that no other run of that scheme (" (study.threads) " threads) beats on both wall time and b error, cheapest first. "
                    "The fronts are per scheme because the study's error ranks the option sets of one scheme but not the schemes: the b error alone "
                    "does not say how well a scheme holds the drop (the MPS preset keeps b within 0.7 % while its a is 15 % off, docs/notes/mps.md, "
                    "and the a error column of the run table shows it), so a front across schemes would reward a scheme for the one axis it keeps. "
                    "The targets are the ISPH presets' (the performance issue's)."
                }
                table {
                    tr { th class="l" { "scheme" } th class="l" { "run" } th { "wall [s]" } th { "b error" } th { "a error" } }
                    @for r in &front {
                        tr { td class="l" { (r.scheme) } td class="l" { code { (breakable(&r.id)) } } td { (format!("{:.3}", r.cost.wall_s)) } td { (pct(r.b_err)) } td { (pct(r.a_err)) } }
                    }
                }
                h2 { "Cost per step and threads" }
                table {
                    tr { th class="l" { "preset" } th { "threads" } th { "fitted exponent" } th class="l" { "Δx" } th class="l" { "particles" } th class="l" { "ms per step" } }
                    @for f in &study.cost_fits {
                        tr {
                            td class="l" { (f.preset) } td { (f.threads) } td { (value(f.exponent, "")) }
                            td class="l" { (f.dx.iter().map(|d| d.to_string()).collect::<Vec<_>>().join(", ")) }
                            td class="l" { (f.particles.iter().map(|d| d.to_string()).collect::<Vec<_>>().join(", ")) }
                            td class="l" { (f.cost_per_step_s.iter().map(|s| format!("{:.2}", 1e3 * s)).collect::<Vec<_>>().join(", ")) }
                        }
                    }
                }
                table {
                    tr { th class="l" { "preset" } th { "Δx" } th { "particles" } th { "1 thread [s]" } th { "parallel [s]" } th { "threads" } th { "speed-up" } }
                    @for s in &study.speedups {
                        tr {
                            td class="l" { (s.preset) } td { (s.dx) } td { (s.particles) } td { (format!("{:.3}", s.wall_1_s)) }
                            td { (format!("{:.3}", s.wall_n_s)) } td { (s.threads) } td { (format!("{:.2}", s.speedup)) }
                        }
                    }
                }
                @if let Some(c) = &study.channel { (channel_section(c)) }
                @if let Some(p) = &study.pipe { (pipe_section(p)) }
                h2 { "Design" }
                ul { @for d in &study.design { li { (d) } } }
                p class="small" {
                    "Factors: PPE solver and tolerance (BiCGSTAB 1e-3, BiCGSTAB 1e-5, CG 1e-3, sparse LU), pressure gradient "
                    "(symmetric Qiu eq. 15, difference), divergence (Qiu eq. 10, kernel-corrected), shifting (none, Xu C = 0.02, "
                    "Fickian A = 2), time step (the case's fixed Δt = 2e-5 s scaled with Δx below 0.02, adaptive Qiu eqs. 17–19 "
                    "with α = 0.2). Presets: paper = BiCGSTAB 1e-3 (two-level), symmetric, eq. 10, Xu, fixed; tuned = paper with the "
                    "corrected divergence, Fickian shifting and two-level CG. The other schemes' rows run the case file's presets as "
                    "they are (validation/elliptical_drop.json: wcsph_tuned, mps), their options in the case file. Runs go one at a "
                    "time, each on its own rayon pool."
                }
                h2 { "Machine" }
                table {
                    tr { th class="l" { "git commit" } td class="l" { code { (p.git_commit.as_deref().unwrap_or("unknown")) } (if p.git_dirty == Some(true) { " (uncommitted changes)" } else { "" }) } }
                    tr { th class="l" { "CPU" } td class="l" { (p.cpu.as_deref().unwrap_or("unknown")) } }
                    tr { th class="l" { "logical CPUs" } td class="l" { (p.cpus.map_or("unknown".into(), |c| c.to_string())) } }
                    tr { th class="l" { "threads (main runs)" } td class="l" { (study.threads) } }
                    tr { th class="l" { "host" } td class="l" { (p.hostname.as_deref().unwrap_or("unknown")) } }
                    tr { th class="l" { "date (UTC)" } td class="l" { (p.date_utc) } }
                }
                h2 { "All runs" }
                p class="small" {
                    "Bold rows are on their scheme's Pareto front. A divergence the case file expects of the preset at that spacing "
                    "(its expected_divergence; the reason in the cell's tooltip) reads as expected. Data: " a href="results.json" { "results.json" } "."
                }
                table class="small" {
                    tr {
                        th class="l" { "run" } th { "Δx" } th class="l" { "scheme" } th class="l" { "PPE" } th class="l" { "gradient" } th class="l" { "divergence" }
                        th class="l" { "shifting" } th class="l" { "Δt" } th class="l" { "preset" }
                    }
                    @for r in &study.runs { (run_row(r, study.pareto.contains(&r.id), Half::Options)) }
                }
                table class="small" {
                    tr {
                        th class="l" { "run" } th { "threads" } th { "particles" }
                        th { "steps" } th { "wall [s]" } th { "CPU/wall" } th { "ms/step" } th { "PPE its" } th { "core-µs per particle-step" } th { "× floor" } th { "b error (t = 0.008)" } th { "b error (max)" } th { "a error (t = 0.008)" } th class="l" { "status" }
                    }
                    @for r in &study.runs { (run_row(r, study.pareto.contains(&r.id), Half::Measured)) }
                }
            }
        }
    }
    .into_string()
}
