//! HTML pages (maud): self-contained (inline CSS, no scripts, figures by relative link).

use super::FigureFile;
use crate::baseline::{CaseComparison, Comparison, Mark, MetricChange, Speed, WallChange};
use crate::case::{CaseRecord, Published};
use crate::checks::same_spacing;
use crate::results::{CaseResults, CheckResult, RunResult, Summary, Verdict, expected_failures};
use maud::{DOCTYPE, Markup, PreEscaped, html};

const CSS: &str = "body{font-family:system-ui,sans-serif;margin:2em;max-width:1200px;color:#222}\
table{border-collapse:collapse;margin:1em 0}th,td{border:1px solid #ccc;padding:3px 8px;text-align:right}\
th{background:#f0f0f0}td.l,th.l{text-align:left}.pass{background:#d9f2d9;color:#145214}\
.fail{background:#f8d7d7;color:#7a1010}pre{background:#f6f6f6;padding:1em;overflow-x:auto;font-size:85%}\
figure{display:inline-block;margin:0.5em}figcaption{font-size:90%;color:#555}code{font-size:90%}\
.better{background:#d9f2d9;color:#145214}.worse{background:#f8d7d7;color:#7a1010}\
.changed{background:#fff3cd;color:#664d03}.note{color:#555;font-size:90%}\
.xfail{background:#ececec;color:#444}";

/// Formats a metric: relative errors (`rel_err`, `_l2_rel`, `_linf_rel`) and drifts in
/// percent, counts as integers.
pub fn format_metric(name: &str, v: Option<f64>) -> String {
    let relative = ["rel_err", "_l2_rel", "_linf_rel", "drift"].iter().any(|k| name.contains(k));
    match v {
        None => "—".to_string(),
        Some(x) if !x.is_finite() => "NaN".to_string(),
        Some(x) if relative => format!("{:.3} %", x * 100.0),
        Some(x) if x.fract().abs() < 1e-12 && x.abs() < 1e15 => format!("{x:.0}"),
        Some(x) => format!("{x:.4e}"),
    }
}

/// The change of a metric as text: `+12.3 %` of the baseline, or `—` when undefined.
pub fn format_change(m: &MetricChange) -> String {
    match m.relative() {
        Some(r) => format!("{:+.1} %", r * 100.0),
        None => "—".to_string(),
    }
}

/// A wall-time ratio as text: `×1.31 (slower)`, `×0.95`.
pub fn format_ratio(w: &WallChange) -> String {
    let flag = match w.flag {
        Some(Speed::Slower) => " (slower)",
        Some(Speed::Faster) => " (faster)",
        None => "",
    };
    if w.ratio.is_finite() { format!("×{:.2}{flag}", w.ratio) } else { "—".to_string() }
}

/// CSS class of a mark (`better`, `worse`, `changed`, or none).
fn mark_class(m: Mark) -> &'static str {
    match m {
        Mark::Better => "better",
        Mark::Worse => "worse",
        Mark::Changed | Mark::Added | Mark::Removed => "changed",
        Mark::Unchanged => "",
    }
}

fn speed_class(w: &WallChange) -> &'static str {
    match w.flag {
        Some(Speed::Slower) => "worse",
        Some(Speed::Faster) => "better",
        None => "",
    }
}

/// An observed order as text (`1.73`, `—`).
pub fn format_order(v: Option<f64>) -> String {
    match v {
        Some(x) if x.is_finite() => format!("{x:.2}"),
        Some(_) => "NaN".to_string(),
        None => "—".to_string(),
    }
}

/// A value that may have moved: the new value, and when it moved the baseline value and
/// the relative change (`0.095 % (was 0.048 %, +100.0 %)`).
fn moved_value(m: &MetricChange, fmt: impl Fn(Option<f64>) -> String) -> String {
    match m.mark {
        Mark::Unchanged => fmt(m.new),
        _ => format!("{} (was {}, {})", fmt(m.new), fmt(m.old), format_change(m)),
    }
}

/// Rows `name | value | mark` of the observed orders.
fn order_rows(changes: &[MetricChange]) -> Markup {
    html! {
        @for m in changes {
            tr {
                td class="l" { code { (m.name) } }
                td { (moved_value(m, format_order)) }
                td class=(mark_class(m.mark)) { (m.mark.label()) }
            }
        }
    }
}

/// One table of every metric (rows) of every matched run (columns); a moved value shows
/// its baseline and change and is coloured by its mark.
fn metric_table(case: &CaseComparison) -> Markup {
    let mut names: Vec<&str> = Vec::new();
    for r in &case.runs {
        for m in &r.metrics {
            if !names.contains(&m.name.as_str()) {
                names.push(&m.name);
            }
        }
    }
    names.sort_unstable();
    html! {
        table {
            tr { th class="l" { "metric" } @for r in &case.runs { th { code { (r.slug) } } } }
            @for n in &names {
                tr {
                    td class="l" { code { (n) } }
                    @for r in &case.runs {
                        @match r.metrics.iter().find(|m| m.name == *n) {
                            Some(m) => td class=(mark_class(m.mark)) title=(m.mark.label()) {
                                (moved_value(m, |v| format_metric(n, v)))
                            },
                            None => td { "—" },
                        }
                    }
                }
            }
        }
    }
}

/// The "Compared with baseline" section of a case page.
fn baseline_section(cmp: &Comparison, case: &CaseComparison) -> Markup {
    html! {
        h2 { "Compared with baseline" }
        p { "Baseline " code { (cmp.baseline.display()) } ": " (case.tally().describe()) "." }
        p class="note" { (cmp.band.describe()) }
        @if !case.in_baseline { p class="changed" { "This case is not in the baseline." } }
        @if !case.added_runs.is_empty() { p { "Runs not in the baseline: " (case.added_runs.join(", ")) } }
        @if !case.removed_runs.is_empty() { p { "Baseline runs not run now: " (case.removed_runs.join(", ")) } }
        @if !case.checks.is_empty() {
            h3 { "Checks whose outcome changed" }
            table {
                tr { th class="l" { "check" } th class="l" { "change" } }
                @for c in &case.checks {
                    tr {
                        td class="l" { (c.name) }
                        td class=(if c.newly_failing() { "l worse" } else if c.newly_passing() { "l better" } else { "l changed" }) { (c.label()) }
                    }
                }
            }
        }
        @if !case.runs.is_empty() {
            h3 { "Wall time" }
            table {
                tr { th class="l" { "run" } th class="l" { "status (baseline → now)" } th { "baseline [s]" } th { "now [s]" } th { "ratio" } }
                @for r in &case.runs {
                    tr {
                        td class="l" { code { (r.slug) } }
                        td class=(format!("l {}", mark_class(r.status))) {
                            @if r.old_status == r.new_status { (r.new_status) } @else { (r.old_status) " → " (r.new_status) }
                        }
                        td { (format!("{:.2}", r.wall.old)) }
                        td { (format!("{:.2}", r.wall.new)) }
                        td class=(speed_class(&r.wall)) { (format_ratio(&r.wall)) }
                    }
                }
            }
        }
        @if !case.orders.is_empty() {
            h3 { "Observed orders" }
            table {
                tr { th class="l" { "metric" } th { "order (baseline, change)" } th { "mark" } }
                (order_rows(&case.orders))
            }
        }
        @if !case.runs.is_empty() {
            h3 { "Metrics" }
            p class="note" { "Values now; a value that moved beyond the band shows its baseline and the change, green when better, red when worse, yellow when changed without a direction." }
            (metric_table(case))
        }
    }
}

/// A check's verdict: pass, FAIL, expected fail (grey) or UNEXPECTED PASS (red).
pub(crate) fn verdict_cell(v: Verdict) -> Markup {
    let class = match v {
        Verdict::Pass => "pass",
        Verdict::ExpectedFail => "xfail",
        Verdict::Fail | Verdict::UnexpectedPass => "fail",
    };
    html! { td class=(class) { (v.label()) } }
}

/// The note of a check: why it failed, and why it is expected to.
fn check_note(c: &CheckResult) -> String {
    let expected = c.expected_failure.as_deref().map(|r| format!("expected to fail: {r}"));
    [c.note.clone(), expected].into_iter().flatten().collect::<Vec<_>>().join("; ")
}

pub(crate) fn pass_cell(pass: bool) -> Markup {
    html! { td class=(if pass { "pass" } else { "fail" }) { (if pass { "PASS" } else { "FAIL" }) } }
}

/// The table of checks: name, value and threshold (written by `number`), verdict, note.
pub(crate) fn checks_table(checks: &[CheckResult], number: fn(f64) -> String) -> Markup {
    html! {
        table {
            tr { th class="l" { "check" } th { "value" } th { "threshold" } th { "result" } th class="l" { "note" } }
            @for c in checks {
                tr {
                    td class="l" { (c.name) }
                    td { (c.value.map_or("—".to_string(), number)) }
                    td { (c.threshold.map_or("—".to_string(), number)) }
                    (verdict_cell(c.verdict()))
                    td class="l" { (check_note(c)) }
                }
            }
        }
    }
}

pub(crate) fn page(title: &str, body: Markup) -> String {
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
pub(crate) fn resolutions(runs: &[RunResult]) -> String {
    let mut dx: Vec<f64> = runs.iter().map(|r| r.dx).collect();
    dx.sort_by(|a, b| b.total_cmp(a));
    dx.dedup_by(|a, b| (*a - *b).abs() <= 1e-12 * b.abs());
    dx.iter().map(|&d| format_dx(d)).collect::<Vec<_>>().join(", ")
}

/// A spacing as text: as written when short (`0.02`), else to 4 significant digits
/// Spacings as `0.02, 0.01` ([`format_dx`] each).
fn dx_list(dx: &[f64]) -> String {
    dx.iter().map(|&d| format_dx(d)).collect::<Vec<_>>().join(", ")
}

/// (`5.556e-3` for D/36).
pub fn format_dx(dx: f64) -> String {
    let plain = dx.to_string();
    if plain.len() <= 8 { plain } else { format!("{dx:.3e}") }
}

/// The page of one case; with a comparison, a "Compared with baseline" section follows the
/// checks.
pub fn case_page(
    results: &CaseResults,
    record: Option<&CaseRecord>,
    figures: &[FigureFile],
    comparison: Option<&Comparison>,
) -> String {
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
            @let xfail = expected_failures(&results.checks);
            @if xfail > 0 { " " span class="xfail" { (xfail) " expected failure(s)" } }
        }
        h2 { "Checks" }
        (checks_table(&results.checks, |v| format!("{v:.4e}")))
        @if let Some(cmp) = comparison {
            @if let Some(case) = cmp.case(&results.case) { (baseline_section(cmp, case)) }
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
                    @if r.ok() {
                        td class="l pass" {
                            "ok" @if let Some(t) = r.steady_at { " (steady at t = " (format!("{t:.4e}")) " s)" }
                        }
                    } @else { td class="l fail" { (r.status) } }
                    td { (r.particles) } td { (r.steps) } td { (format!("{:.2}", r.wall_s)) }
                    @for m in &columns { td { (format_metric(m, r.metric(m))) } }
                }
            }
        }
        @if let Some(c) = case {
            @if !c.published.is_empty() { (published_table(&c.published, &results.runs)) }
        }
        @if !results.convergence.is_empty() {
            h2 { "Observed orders" }
            p { "Least-squares fit of log(error) against log(dx) over the completed runs (at a spacing with perturbed starts, their mean)." }
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
                @if let Some(e) = &p.expected_divergence {
                    p class="note" { "Expected to diverge at dx = " (dx_list(&e.dx)) ": " (e.reason) }
                }
                @if let Some(s) = &p.perturbed_starts {
                    p class="note" {
                        "Perturbed starts at dx = " (dx_list(&s.dx)) ": seeds " (format!("{:?}", s.seeds))
                        ", lattice displaced by " (format!("{:e}", s.fraction)) " dx. " (s.reason)
                    }
                }
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

/// The papers' published values beside the measured ones: per value, the unperturbed run
/// of its preset at its spacing (blank when that run is not in this tier or diverged).
fn published_table(published: &[Published], runs: &[RunResult]) -> Markup {
    html! {
        h2 { "Published values" }
        table {
            tr {
                th class="l" { "source" } th class="l" { "metric" } th class="l" { "preset" } th { "dx" }
                th { "published" } th { "measured" } th { "measured / published − 1" }
            }
            @for p in published {
                @for [dx, value] in &p.values {
                    @let run = runs.iter().find(|r| {
                        r.preset == p.preset && r.start.is_none() && r.ok() && same_spacing(r.dx, *dx)
                    });
                    @let measured = run.and_then(|r| r.metric(&p.metric));
                    tr {
                        td class="l" { (p.source) } td class="l" { code { (p.metric) } }
                        td class="l" { (p.preset) } td { (format_dx(*dx)) }
                        td { (format!("{value:.4e}")) }
                        td { (measured.map(|m| format!("{m:.4e}")).unwrap_or_default()) }
                        td { (measured.map(|m| format!("{:+.2}%", 100.0 * (m / value - 1.0))).unwrap_or_default()) }
                    }
                }
            }
        }
        @for p in published.iter().filter(|p| !p.note.is_empty()) {
            p class="note" { (p.source) ": " (p.note) }
        }
    }
}

/// Key errors of a case for the index: each key metric at the finest spacing of the primary
/// preset that has a completed run. Where that spacing has perturbed starts, the value is
/// their mean as the checks and order fits take it ([`crate::checks::per_spacing`]: none
/// when a start diverged or lacks the metric, and the text says so) with the range of the
/// starts that have it.
pub(crate) fn key_errors(results: &CaseResults, record: Option<&CaseRecord>) -> String {
    let keys: Vec<String> = record.map(|r| r.case.key_metrics.clone()).unwrap_or_default();
    let primary = record
        .map(|r| r.case.primary_preset().to_string())
        .or_else(|| results.runs.first().map(|r| r.preset.clone()));
    let runs: Vec<&RunResult> = results.runs.iter().filter(|r| Some(&r.preset) == primary.as_ref()).collect();
    let Some(finest) = runs.iter().filter(|r| r.ok()).map(|r| r.dx).min_by(f64::total_cmp) else {
        return "—".to_string();
    };
    let members: Vec<&RunResult> = runs.into_iter().filter(|r| same_spacing(r.dx, finest)).collect();
    let first = members.iter().find(|r| r.ok()).copied().unwrap_or(members[0]);
    let keys = if keys.is_empty() { first.metrics.keys().take(2).cloned().collect() } else { keys };
    let parts: Vec<String> = keys
        .iter()
        .map(|k| {
            if members.len() == 1 {
                return format!("{k} {}", format_metric(k, first.metric(k)));
            }
            let values: Vec<f64> = members
                .iter()
                .filter(|r| r.ok())
                .filter_map(|r| r.metric(k))
                .filter(|v| v.is_finite())
                .collect();
            let lo = values.iter().copied().fold(f64::INFINITY, f64::min);
            let hi = values.iter().copied().fold(f64::NEG_INFINITY, f64::max);
            let range = if values.is_empty() {
                String::new()
            } else {
                format!(", {} – {}", format_metric(k, Some(lo)), format_metric(k, Some(hi)))
            };
            let mean = crate::checks::per_spacing(&members, k).first().and_then(|(_, m)| *m);
            match mean {
                Some(m) => {
                    format!("{k} {} (mean of {} starts{range})", format_metric(k, Some(m)), members.len())
                }
                None => format!(
                    "{k} — ({} of {} starts diverged or lack it{range})",
                    members.len() - values.len(),
                    members.len()
                ),
            }
        })
        .collect();
    format!("{} ({} dx={})", parts.join(", "), first.preset, format_dx(first.dx))
}

/// The order shown on the index: the first convergence metric of the case.
pub(crate) fn key_order(results: &CaseResults, record: Option<&CaseRecord>) -> String {
    let first = record
        .and_then(|r| r.case.convergence.iter().find(|m| results.convergence.contains_key(*m)).cloned())
        .or_else(|| results.convergence.keys().next().cloned());
    match first.and_then(|m| results.convergence.get(&m).map(|c| (m, c))) {
        Some((m, c)) => format!("{m}: {:.2}", c.order),
        None => "—".to_string(),
    }
}

/// The "vs baseline" cell of the index: the case's tally, coloured by whether it regressed.
fn baseline_cell(case: Option<&CaseComparison>) -> Markup {
    match case {
        None => html! { td class="l" { "—" } },
        Some(c) if !c.in_baseline => html! { td class="l changed" { "not in baseline" } },
        Some(c) => {
            let t = c.tally();
            let class = if t.regressed() {
                "l worse"
            } else if t.better + t.faster + t.newly_passing > 0 {
                "l better"
            } else {
                "l"
            };
            html! { td class=(class) { (t.describe()) } }
        }
    }
}

/// A page of the report beside the cases (the stability envelope), linked from the index.
#[derive(Debug, Clone, PartialEq)]
pub struct ExtraPage {
    /// Relative link (`stability/index.html`).
    pub href: String,
    /// Link text.
    pub title: String,
    /// One line about it (tier, rows, checks).
    pub summary: String,
    /// Whether its checks passed.
    pub pass: bool,
}

/// `reports/index.html`: one row per case (with a comparison, a "vs baseline" column), then
/// links to the `extras` pages.
pub fn index_page(
    results: &[CaseResults],
    records: &[Option<&CaseRecord>],
    summary: &Summary,
    comparison: Option<&Comparison>,
    extras: &[ExtraPage],
) -> String {
    let body = html! {
        h1 { "Meniscus validation" }
        p class=(if summary.pass { "pass" } else { "fail" }) {
            (summary.passed) " / " (summary.passed + summary.failed) " checks passed over " (results.len()) " cases"
            @if summary.expected_failures > 0 { ", " (summary.expected_failures) " expected failure(s) apart" }
        }
        @if let Some(cmp) = comparison {
            p { "Compared with baseline " code { (cmp.baseline.display()) } ": " (cmp.tally().describe()) "." }
            p class="note" { (cmp.band.describe()) }
        }
        table {
            tr {
                th class="l" { "case" } th class="l" { "scheme" } th class="l" { "tier" } th class="l" { "resolutions (dx)" }
                th class="l" { "key errors" } th class="l" { "observed order" } th { "wall [s]" } th { "checks" } th { "result" }
                @if comparison.is_some() { th class="l" { "vs baseline" } }
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
                    td {
                        (passed) " / " (passed + failed)
                        @let xfail = expected_failures(&r.checks);
                        @if xfail > 0 { " (+" (xfail) " expected fail)" }
                    }
                    (pass_cell(failed == 0))
                    @if let Some(cmp) = comparison { (baseline_cell(cmp.case(&r.case))) }
                }
            }
        }
        (super::timing::html_section(results, summary.elapsed_s))
        @if !extras.is_empty() {
            h2 { "Stress tests" }
            table {
                tr { th class="l" { "page" } th class="l" { "what" } th { "result" } }
                @for e in extras {
                    tr {
                        td class="l" { a href=(e.href) { (e.title) } }
                        td class="l" { (e.summary) }
                        (pass_cell(e.pass))
                    }
                }
            }
        }
    };
    page("Meniscus validation", body)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn metrics_and_spacings_read_well() {
        assert_eq!(format_metric("u_profile_l2_rel_steady", Some(0.0095)), "0.950 %");
        assert_eq!(format_metric("b_rel_err_max", Some(0.001)), "0.100 %");
        assert_eq!(format_metric("particles", Some(648.0)), "648");
        assert_eq!(format_metric("min_pair_over_dx_min", Some(0.41579)), "4.1579e-1");
        assert_eq!(format_dx(0.02), "0.02");
        assert_eq!(format_dx(0.0025), "0.0025");
        assert_eq!(format_dx(0.2 / 36.0), "5.556e-3");
    }

    #[test]
    fn key_errors_take_the_finest_spacing_and_its_starts_mean() {
        let run = |dx: f64, start: Option<u64>, err: f64| RunResult {
            scheme: "isph".into(),
            preset: "p".into(),
            dx,
            start,
            particles: 100,
            steps: 10,
            wall_s: 1.0,
            cpu_s: None,
            threads: None,
            steady_at: None,
            status: "ok".into(),
            metrics: [("u_l2_rel".to_string(), err)].into(),
            series: Default::default(),
        };
        let mut results = CaseResults {
            case: "c".into(),
            scheme: "isph".into(),
            tier: "default".into(),
            runs: vec![run(0.02, None, 0.01), run(0.01, None, 0.002)],
            convergence: Default::default(),
            checks: Vec::new(),
        };
        assert_eq!(key_errors(&results, None), "u_l2_rel 0.200 % (p dx=0.01)");
        results.runs.push(run(0.01, Some(1), 0.004));
        results.runs.push(run(0.01, Some(2), 0.003));
        assert_eq!(
            key_errors(&results, None),
            "u_l2_rel 0.300 % (mean of 3 starts, 0.200 % – 0.400 %) (p dx=0.01)"
        );
        // A start that diverged leaves the spacing without a mean, as in the order fits.
        results.runs[3].status = "diverged".into();
        assert_eq!(
            key_errors(&results, None),
            "u_l2_rel — (1 of 3 starts diverged or lack it, 0.200 % – 0.400 %) (p dx=0.01)"
        );
        // Every run at the finest spacing diverged: the next one down is shown.
        for r in &mut results.runs[1..] {
            r.status = "diverged".into();
        }
        assert_eq!(key_errors(&results, None), "u_l2_rel 1.000 % (p dx=0.02)");
    }
}
