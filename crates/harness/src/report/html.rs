//! HTML pages (maud): self-contained (inline CSS, no scripts, figures by relative link).

use super::FigureFile;
use crate::results::{CaseRecord, CaseResults, RunResult, Summary};
use maud::{DOCTYPE, Markup, PreEscaped, html};

const CSS: &str = "body{font-family:system-ui,sans-serif;margin:2em;max-width:1200px;color:#222}\
table{border-collapse:collapse;margin:1em 0}th,td{border:1px solid #ccc;padding:3px 8px;text-align:right}\
th{background:#f0f0f0}td.l,th.l{text-align:left}.pass{background:#d9f2d9;color:#145214}\
.fail{background:#f8d7d7;color:#7a1010}pre{background:#f6f6f6;padding:1em;overflow-x:auto;font-size:85%}\
figure{display:inline-block;margin:0.5em}figcaption{font-size:90%;color:#555}code{font-size:90%}";

/// Formats a metric: relative errors and drifts in percent, counts as integers.
pub fn format_metric(name: &str, v: Option<f64>) -> String {
    match v {
        None => "—".to_string(),
        Some(x) if !x.is_finite() => "NaN".to_string(),
        Some(x) if name.contains("rel_err") || name.contains("drift") => format!("{:.3} %", x * 100.0),
        Some(x) if x.fract().abs() < 1e-12 && x.abs() < 1e15 => format!("{x:.0}"),
        Some(x) => format!("{x:.4e}"),
    }
}

fn pass_cell(pass: bool) -> Markup {
    html! { td class=(if pass { "pass" } else { "fail" }) { (if pass { "PASS" } else { "FAIL" }) } }
}

fn page(title: &str, body: Markup) -> String {
    html! {
        (DOCTYPE)
        html lang="en" {
            head {
                meta charset="utf-8";
                title { (title) }
                style { (PreEscaped(CSS)) }
            }
            body { (body) }
        }
    }
    .into_string()
}

/// Metric columns of the error table: the case's list, else every metric seen (without
/// the run fields that have their own columns).
fn metric_columns(results: &CaseResults, record: Option<&CaseRecord>) -> Vec<String> {
    let mut names: Vec<String> = match record.filter(|r| !r.case.metrics.is_empty()) {
        Some(r) => r.case.metrics.clone(),
        None => {
            let mut all: Vec<String> = results.runs.iter().flat_map(|r| r.metrics.keys().cloned()).collect();
            all.sort();
            all.dedup();
            all
        }
    };
    names.retain(|m| !matches!(m.as_str(), "particles" | "steps" | "wall_s"));
    names
}

/// Distinct spacings, coarse to fine, as text.
fn resolutions(runs: &[RunResult]) -> String {
    let mut dx: Vec<f64> = runs.iter().map(|r| r.dx).collect();
    dx.sort_by(|a, b| b.total_cmp(a));
    dx.dedup_by(|a, b| (*a - *b).abs() <= 1e-12 * b.abs());
    dx.iter().map(|d| d.to_string()).collect::<Vec<_>>().join(", ")
}

/// The page of one case.
pub fn case_page(results: &CaseResults, record: Option<&CaseRecord>, figures: &[FigureFile]) -> String {
    let columns = metric_columns(results, record);
    let (passed, failed) = results.counts();
    let case = record.map(|r| &r.case);
    let body = html! {
        p { a href="../index.html" { "← all cases" } }
        h1 { (results.case) }
        @if let Some(c) = case {
            @if !c.title.is_empty() { h2 { (c.title) } }
            @if !c.description.is_empty() { p { (c.description) } }
        }
        p {
            "Scheme " code { (results.scheme) } ", tier " code { (results.tier) } ", "
            (results.runs.len()) " runs at dx = " (resolutions(&results.runs)) ". "
            span class=(if failed == 0 { "pass" } else { "fail" }) {
                (passed) " / " (passed + failed) " checks passed"
            }
        }
        h2 { "Checks" }
        table {
            tr { th class="l" { "check" } th { "value" } th { "threshold" } th { "result" } th class="l" { "note" } }
            @for c in &results.checks {
                tr {
                    td class="l" { (c.name) }
                    td { (c.value.map_or("—".to_string(), |v| format!("{v:.4e}"))) }
                    td { (c.threshold.map_or("—".to_string(), |v| format!("{v:.4e}"))) }
                    (pass_cell(c.pass))
                    td class="l" { (c.note.as_deref().unwrap_or("")) }
                }
            }
        }
        h2 { "Errors" }
        table {
            tr {
                th class="l" { "run" } th class="l" { "status" } th { "particles" } th { "steps" } th { "wall [s]" }
                @for m in &columns { th { (m) } }
            }
            @for r in &results.runs {
                tr {
                    td class="l" { code { (r.slug()) } }
                    @if r.ok() { td class="l pass" { "ok" } } @else { td class="l fail" { (r.status) } }
                    td { (r.particles) } td { (r.steps) } td { (format!("{:.2}", r.wall_s)) }
                    @for m in &columns { td { (format_metric(m, r.metric(m))) } }
                }
            }
        }
        @if !results.convergence.is_empty() {
            h2 { "Observed orders" }
            p { "Least-squares fit of log(error) against log(dx) over the completed runs." }
            table {
                tr { th class="l" { "metric" } th class="l" { "preset" } th { "order" } th class="l" { "other presets" } }
                @for (m, c) in &results.convergence {
                    tr {
                        td class="l" { code { (m) } }
                        td class="l" { (c.preset) }
                        td { (format!("{:.2}", c.order)) }
                        td class="l" {
                            (c.by_preset.iter().filter(|(p, _)| **p != c.preset).map(|(p, o)| format!("{p}: {o:.2}")).collect::<Vec<_>>().join(", "))
                        }
                    }
                }
            }
        }
        @if !figures.is_empty() {
            h2 { "Figures" }
            @for f in figures {
                figure {
                    a href=(f.file) { img src=(f.file) alt=(f.caption) width="760"; }
                    figcaption { (f.caption) }
                }
            }
        }
        @if let Some(c) = case {
            @if !c.errata.is_empty() {
                h2 { "Errata applied" }
                ul { @for e in &c.errata { li { (e) } } }
            }
            h2 { "Scene parameters" }
            p { "Template (each run replaces " code { "dx" } "):" }
            pre { (serde_json::to_string_pretty(&c.scene).unwrap_or_default()) }
            h3 { "Presets (JSON merge patches on the template)" }
            @for p in &c.sweep.presets {
                p { b { (p.name) } @if !p.description.is_empty() { " — " (p.description) } }
                pre { (serde_json::to_string_pretty(&p.patch).unwrap_or_default()) }
            }
        }
        @if let Some(r) = record {
            h2 { "Provenance" }
            table {
                tr { th class="l" { "date (UTC)" } td class="l" { (r.provenance.date_utc) } }
                tr { th class="l" { "git commit" } td class="l" {
                    code { (r.provenance.git_commit.as_deref().unwrap_or("unknown")) }
                    @if r.provenance.git_dirty == Some(true) { " (with uncommitted changes)" }
                } }
                tr { th class="l" { "machine" } td class="l" { (r.provenance.hostname.as_deref().unwrap_or("unknown")) } }
                tr { th class="l" { "CPU" } td class="l" {
                    (r.provenance.cpu.as_deref().unwrap_or("unknown"))
                    @if let Some(n) = r.provenance.cpus { " (" (n) " logical CPUs)" }
                } }
                tr { th class="l" { "rayon threads" } td class="l" { (r.provenance.threads) } }
                tr { th class="l" { "harness" } td class="l" { (r.provenance.harness_version) } }
            }
            h3 { "Scene hashes (SHA-256 of the effective scene JSON)" }
            table {
                @for (slug, hash) in &r.scene_hashes {
                    tr { td class="l" { code { (slug) } } td class="l" { code { (hash) } } }
                }
            }
        }
    };
    page(&format!("Meniscus validation: {}", results.case), body)
}

/// Key errors of a case for the index: each key metric at the finest completed run of the
/// primary preset.
fn key_errors(results: &CaseResults, record: Option<&CaseRecord>) -> String {
    let keys: Vec<String> = record.map(|r| r.case.key_metrics.clone()).unwrap_or_default();
    let primary = record
        .map(|r| r.case.primary_preset().to_string())
        .or_else(|| results.runs.first().map(|r| r.preset.clone()));
    let finest = results
        .runs
        .iter()
        .filter(|r| r.ok() && Some(&r.preset) == primary.as_ref())
        .min_by(|a, b| a.dx.total_cmp(&b.dx));
    match finest {
        None => "—".to_string(),
        Some(run) => {
            let keys = if keys.is_empty() { run.metrics.keys().take(2).cloned().collect() } else { keys };
            let parts: Vec<String> =
                keys.iter().map(|k| format!("{k} {}", format_metric(k, run.metric(k)))).collect();
            format!("{} ({} dx={})", parts.join(", "), run.preset, run.dx)
        }
    }
}

/// The order shown on the index: the first convergence metric of the case.
fn key_order(results: &CaseResults, record: Option<&CaseRecord>) -> String {
    let first = record
        .and_then(|r| r.case.convergence.iter().find(|m| results.convergence.contains_key(*m)).cloned())
        .or_else(|| results.convergence.keys().next().cloned());
    match first.and_then(|m| results.convergence.get(&m).map(|c| (m, c))) {
        Some((m, c)) => format!("{m}: {:.2}", c.order),
        None => "—".to_string(),
    }
}

/// `reports/index.html`: one row per case.
pub fn index_page(results: &[CaseResults], records: &[Option<&CaseRecord>], summary: &Summary) -> String {
    let body = html! {
        h1 { "Meniscus validation" }
        p class=(if summary.pass { "pass" } else { "fail" }) {
            (summary.passed) " / " (summary.passed + summary.failed) " checks passed over " (results.len()) " cases"
        }
        table {
            tr {
                th class="l" { "case" } th class="l" { "scheme" } th class="l" { "tier" } th class="l" { "resolutions (dx)" }
                th class="l" { "key errors" } th class="l" { "observed order" } th { "wall [s]" } th { "checks" } th { "result" }
            }
            @for (i, r) in results.iter().enumerate() {
                @let rec = records.get(i).copied().flatten();
                @let (passed, failed) = r.counts();
                tr {
                    td class="l" { a href=(format!("{}/index.html", r.case)) { (r.case) } }
                    td class="l" { (r.scheme) }
                    td class="l" { (r.tier) }
                    td class="l" { (resolutions(&r.runs)) }
                    td class="l" { (key_errors(r, rec)) }
                    td class="l" { (key_order(r, rec)) }
                    td { (format!("{:.1}", r.runs.iter().map(|x| x.wall_s).sum::<f64>())) }
                    td { (passed) " / " (passed + failed) }
                    (pass_cell(failed == 0))
                }
            }
        }
    };
    page("Meniscus validation", body)
}
