//! HTML pages (maud): self-contained (inline CSS, no scripts, figures by relative link).

use super::FigureFile;
use super::header::Header;
use super::matrix::{Cell, Judgement, Matrix};
use crate::baseline::{CaseComparison, Comparison, Mark, MetricChange, Speed, WallChange};
use crate::case::{CaseRecord, Published};
use crate::checks::same_spacing;
use crate::numbers::{check_number, dx_list, format_dx, format_metric, format_order, significant};
use crate::results::{CaseResults, CheckResult, RunResult, Summary, Verdict, expected_failures};
use maud::{DOCTYPE, Markup, PreEscaped, html};

const CSS: &str = "body{font-family:system-ui,sans-serif;margin:2em;max-width:1320px;color:#222}\
table{border-collapse:collapse;margin:1em 0;max-width:100%}th,td{border:1px solid #ccc;padding:3px 8px;text-align:right}\
th{background:#f0f0f0}td.l,th.l{text-align:left}.pass{background:#d9f2d9;color:#145214}\
.fail{background:#f8d7d7;color:#7a1010}pre{background:#f6f6f6;padding:1em;overflow-x:auto;font-size:85%}\
figure{display:inline-block;margin:0.5em;max-width:100%}figure img{max-width:100%;height:auto}\
figcaption{font-size:90%;color:#555}code{font-size:90%}\
.better{background:#d9f2d9;color:#145214}.worse{background:#f8d7d7;color:#7a1010}\
.changed{background:#fff3cd;color:#664d03}.note{color:#555;font-size:90%}\
.xfail{background:#ececec;color:#444}.info{background:#fff;color:#333;border:1px dashed #aaa}\
.chip{display:inline-block;padding:1px 6px;border-radius:3px;margin:1px 0}\
.best{color:#7a5a00;font-weight:bold}td.cell{vertical-align:top;min-width:12em}\
table.header th{width:8em}small{font-size:80%}td:not(.l){white-space:nowrap}";

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

/// Tables of every metric (rows) of every matched run (columns, [`RUN_COLUMNS`] per table); a moved value shows
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
        @for runs in case.runs.chunks(RUN_COLUMNS) {
            table {
                tr { th class="l" { "metric" } @for r in runs { th { code { (breakable(&r.slug)) } } } }
                @for n in &names {
                    tr {
                        td class="l" { code { (breakable(n)) } }
                        @for r in runs {
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

/// The table of checks: name, value and threshold (in the form of what each judges,
/// [`check_number`]), verdict, note.
pub(crate) fn checks_table(checks: &[CheckResult]) -> Markup {
    html! {
        table {
            tr { th class="l" { "check" } th { "value" } th { "threshold" } th { "result" } th class="l" { "note" } }
            @for c in checks {
                tr {
                    td class="l" { (c.name) }
                    td { (c.value.map_or("—".to_string(), |v| check_number(c, v))) }
                    td { (c.threshold.map_or("—".to_string(), |v| check_number(c, v))) }
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

/// Metric columns per error table: more are split into further tables, so a table fits a
/// 1400 px wide window.
const METRIC_COLUMNS: usize = 6;

/// Run columns per table of the baseline comparison's metrics (split like the errors).
const RUN_COLUMNS: usize = 5;

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
    dx_list(&dx)
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
            "Schemes " code { (schemes(results).join(", ")) } ", tier " code { (results.tier) } ", "
            (results.runs.len()) " runs at dx = " (resolutions(&results.runs)) ". "
            span class=(if failed == 0 { "pass" } else { "fail" }) {
                (passed) " / " (passed + failed) " checks passed"
            }
            @let xfail = expected_failures(&results.checks);
            @if xfail > 0 { " " span class="xfail" { (xfail) " expected failure(s)" } }
        }
        h2 { "Checks" }
        (checks_table(&results.checks))
        @if let Some(cmp) = comparison {
            @if let Some(case) = cmp.case(&results.case) { (baseline_section(cmp, case)) }
        }
        h2 { "Runs" }
        table {
            tr {
                th class="l" { "run" } th class="l" { "status" } th { "particles" } th { "steps" } th { "wall [s]" }
            }
            @for r in &results.runs {
                tr {
                    td class="l" { code { (breakable(&r.slug())) } }
                    @if r.ok() {
                        td class="l pass" {
                            "ok" @if let Some(t) = r.steady_at { " (steady at t = " (significant(t, 4)) " s)" }
                        }
                    } @else { td class="l fail" { (r.status) } }
                    td { (r.particles) } td { (r.steps) } td { (format!("{:.2}", r.wall_s)) }
                }
            }
        }
        h2 { "Errors" }
        @for chunk in columns.chunks(METRIC_COLUMNS) {
            table {
                tr { th class="l" { "run" } @for m in chunk { th { code { (breakable(m)) } } } }
                @for r in &results.runs {
                    tr {
                        td class=(if r.ok() { "l" } else { "l fail" }) { code { (breakable(&r.slug())) } }
                        @for m in chunk { td { (format_metric(m, r.metric(m))) } }
                    }
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
                        td class="l" { (p.source) } td class="l" { code { (breakable(&p.metric)) } }
                        td class="l" { (p.preset) } td { (format_dx(*dx)) }
                        td { (format_metric(&p.metric, Some(*value))) }
                        td { (measured.map(|m| format_metric(&p.metric, Some(m))).unwrap_or_default()) }
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

/// The schemes a case runs, in the order its runs name them.
pub(crate) fn schemes(results: &CaseResults) -> Vec<&str> {
    let mut out: Vec<&str> = Vec::new();
    for r in &results.runs {
        if !out.contains(&r.scheme.as_str()) {
            out.push(&r.scheme);
        }
    }
    out
}

/// The CSS class and label of a verdict; `None` (no check judges the value) is
/// information.
fn verdict_mark(v: Option<Verdict>) -> (&'static str, &'static str) {
    match v {
        Some(Verdict::Pass) => ("pass", "pass"),
        Some(Verdict::Fail) => ("fail", "FAIL"),
        Some(Verdict::UnexpectedPass) => ("fail", "UNEXPECTED PASS"),
        Some(Verdict::ExpectedFail) => ("xfail", "expected fail"),
        None => ("info", "not judged"),
    }
}

/// A judged value: the value in its verdict's colour, the bound beside it and the verdict
/// (with the check's own value when it judged more runs); an unjudged one as information.
fn judged(text: &str, j: &Judgement) -> Markup {
    let (class, label) = verdict_mark(j.verdict);
    html! {
        span class=(format!("chip {class}")) title=(label) {
            b { (text) }
            @if !j.bound.is_empty() { " " (j.bound) }
            " " small { (label) @if let Some(v) = &j.checked { " (checked: worst " (v) ")" } }
        }
    }
}

/// One cell of the scheme-by-case matrix.
fn matrix_cell(cell: &Cell, metric: Option<&str>) -> Markup {
    let value = match (cell.value, metric) {
        (Some(v), Some(m)) => format_metric(m, Some(v)),
        _ => format!("— ({})", cell.missing),
    };
    let tally_class = if cell.tally.failed > 0 { "fail" } else { "pass" };
    html! {
        td class="l cell" {
            div { (judged(&value, &cell.value_check)) @if cell.best { " " span class="best" title="smallest error of the case" { "★ best" } } }
            div class="note" {
                (cell.preset) ", dx " (format_dx(cell.dx))
                @if cell.starts > 1 { " (mean of " (cell.starts) " starts)" }
                ", " (format!("{:.1}", cell.wall_s)) " s"
            }
            @if let Some(o) = cell.order { div { "order " (judged(&format_order(Some(o)), &cell.order_check)) } }
            div { span class=(format!("chip {tally_class}")) { (cell.tally.describe()) } }
        }
    }
}

/// The scheme-by-case matrix ([`Matrix`]).
fn matrix_table(m: &Matrix) -> Markup {
    html! {
        table class="matrix" {
            tr {
                th class="l" { "case" } th class="l" { "headline metric" }
                @for s in &m.schemes { th class="l" { (s.to_uppercase()) } }
            }
            @for row in &m.rows {
                tr {
                    td class="l" {
                        a href=(format!("{}/index.html", row.case)) { (row.case) }
                        @if !row.title.is_empty() { br; span class="note" { (row.title) } }
                        br; span class=(if row.pass { "chip pass" } else { "chip fail" }) { (if row.pass { "PASS" } else { "FAIL" }) }
                    }
                    td class="l" { code { (breakable(row.metric.as_deref().unwrap_or("—"))) } }
                    @for c in &row.cells {
                        @match c {
                            Some(c) => (matrix_cell(c, row.metric.as_deref())),
                            None => td class="l note" { "not run" },
                        }
                    }
                }
            }
        }
    }
}

/// `text` with a line-break opportunity after each `_` and `-` (long metric names and run
/// slugs wrap instead of widening their tables).
pub(crate) fn breakable(text: &str) -> Markup {
    let mut out = String::new();
    for ch in text.chars() {
        match ch {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            c => out.push(c),
        }
        if ch == '_' || ch == '-' {
            out.push_str("<wbr>");
        }
    }
    PreEscaped(out)
}

/// What [`index_page`] shows besides the results.
pub struct IndexParts<'a> {
    /// The header's facts.
    pub header: &'a Header,
    /// The scheme-by-case matrix.
    pub matrix: &'a Matrix,
    /// The overview figure's file (relative to the index), when drawn.
    pub overview: Option<&'a str>,
    /// The pages beside the cases.
    pub extras: &'a [ExtraPage],
}

/// `reports/index.html`: the header (what ran, when, where, how long; links to every
/// page), the scheme-by-case matrix, the overview figure, one row per case (with a
/// comparison, a "vs baseline" column), the run times and the pages beside the cases.
pub fn index_page(
    results: &[CaseResults],
    summary: &Summary,
    comparison: Option<&Comparison>,
    parts: &IndexParts,
) -> String {
    let body = html! {
        h1 { "Meniscus validation" }
        p class=(if summary.pass { "pass" } else { "fail" }) {
            b { (if summary.pass { "PASS" } else { "FAIL" }) } ": "
            (summary.passed) " / " (summary.passed + summary.failed) " checks passed over " (results.len()) " cases"
            @if summary.expected_failures > 0 { ", " (summary.expected_failures) " expected failure(s) apart" }
        }
        table class="header" {
            @for (label, value) in parts.header.lines() {
                tr { th class="l" { (label) } td class="l" { (value) } }
            }
            tr {
                th class="l" { "pages" }
                td class="l" {
                    @for (i, r) in results.iter().enumerate() {
                        @if i > 0 { " · " }
                        a href=(format!("{}/index.html", r.case)) { (r.case) }
                    }
                    @for e in parts.extras { " · " a href=(e.href) { b { (e.title) } } }
                }
            }
        }
        @if let Some(cmp) = comparison {
            p { "Compared with baseline " code { (cmp.baseline.display()) } ": " (cmp.tally().describe()) "." }
            p class="note" { (cmp.band.describe()) }
        }
        h2 { "Schemes by case" }
        p class="note" {
            "Per case and scheme: the best preset's headline error (the case's first key error) at the \
             finest spacing the scheme ran, in the colour of the checks that bound it, with the bound \
             (grey: expected to fail; white: no check judges it, information only); its observed \
             order; the run's wall time; every check that selects the scheme's runs. ★ marks the \
             scheme with the smallest error of the case. A check over more spacings than the one \
             shown judges its worst value, given beside its verdict."
        }
        (matrix_table(parts.matrix))
        @if let Some(f) = parts.overview {
            figure {
                a href=(f) { img src=(f) alt="headline error against wall time, every case and scheme" width="1000"; }
                figcaption { "Every case's headline error against the wall time of its runs: one colour per case, one marker per scheme, a line through the best preset's spacings (coarse to fine)." }
            }
        }
        h2 { "Cases" }
        table {
            tr {
                th class="l" { "case" } th class="l" { "schemes" } th class="l" { "tier" } th class="l" { "resolutions (dx)" }
                th { "runs" } th { "wall [s]" } th { "checks" } th { "result" }
                @if comparison.is_some() { th class="l" { "vs baseline" } }
            }
            @for r in results {
                @let (passed, failed) = r.counts();
                @let diverged = r.runs.iter().filter(|x| !x.ok()).count();
                tr {
                    td class="l" { a href=(format!("{}/index.html", r.case)) { (r.case) } }
                    td class="l" { (schemes(r).join(", ")) }
                    td class="l" { (r.tier) }
                    td class="l" { (resolutions(&r.runs)) }
                    td { (r.runs.len()) @if diverged > 0 { " (" (diverged) " diverged)" } }
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
        @if !parts.extras.is_empty() {
            h2 { "Other pages" }
            table {
                tr { th class="l" { "page" } th class="l" { "what" } th { "result" } }
                @for e in parts.extras {
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
    fn long_names_break_after_underscores_and_escape() {
        assert_eq!(breakable("b_rel<x>").into_string(), "b_<wbr>rel&lt;x&gt;");
        assert_eq!(breakable("isph-paper_dx0.02").into_string(), "isph-<wbr>paper_<wbr>dx0.02");
    }
}
