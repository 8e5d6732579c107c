//! `reports/summary.md`: the report in GitHub-flavoured Markdown, for a CI job summary or
//! a pull-request comment. The header, the scheme-by-case matrix ([`Matrix`]), one row per
//! case, the failed checks below the tables, and with a baseline the regressions and
//! improvements beyond the noise band.

use super::header::Header;
use super::html::{format_change, format_ratio, resolutions, schemes};
use super::matrix::{Cell, Judgement, Matrix};
use crate::baseline::{CaseComparison, Comparison, Mark};
use crate::numbers::{check_number, format_metric, format_order};
use crate::results::{CaseResults, Summary, Verdict};
use std::fmt::Write;

/// Makes `text` safe inside a table cell (no pipes, no line breaks).
fn cell(text: &str) -> String {
    text.replace('|', "\\|").replace(['\n', '\r'], " ")
}

/// The whole `summary.md`.
pub fn summary(
    results: &[CaseResults],
    header: &Header,
    matrix: &Matrix,
    summary: &Summary,
    comparison: Option<&Comparison>,
) -> String {
    let mut md = String::new();
    // Writing to a String cannot fail.
    let _ = write_summary(&mut md, results, header, matrix, summary, comparison);
    md
}

/// A judged value: `**0.095 %** ≤ 1.00 % ✅`; unjudged: `**0.095 %** (not judged)`.
fn judged(text: &str, j: &Judgement) -> String {
    let mark = match j.verdict {
        Some(Verdict::Pass) => "✅",
        Some(Verdict::Fail) => "❌",
        Some(Verdict::UnexpectedPass) => "❌ unexpected pass",
        Some(Verdict::ExpectedFail) => "⚪ expected fail",
        None => "(not judged)",
    };
    let bound = if j.bound.is_empty() { String::new() } else { format!(" {}", j.bound) };
    let checked = j.checked.as_ref().map(|v| format!(" (checked: worst {v})")).unwrap_or_default();
    format!("**{text}**{bound} {mark}{checked}")
}

/// A matrix cell on one line.
fn matrix_cell(c: &Cell, metric: Option<&str>) -> String {
    let value = match (c.value, metric) {
        (Some(v), Some(m)) => format_metric(m, Some(v)),
        _ => format!("— ({})", c.missing),
    };
    let mut s = judged(&value, &c.value_check);
    if c.best {
        s.push_str(" ★");
    }
    s.push_str(&format!("<br>{}, dx {}", c.preset, crate::numbers::format_dx(c.dx)));
    if c.starts > 1 {
        s.push_str(&format!(" (mean of {} starts)", c.starts));
    }
    s.push_str(&format!(", {:.1} s", c.wall_s));
    if let Some(o) = c.order {
        s.push_str(&format!("<br>order {}", judged(&format_order(Some(o)), &c.order_check)));
    }
    let mark = if c.tally.failed > 0 { "❌" } else { "✅" };
    s.push_str(&format!("<br>{mark} {}", c.tally.describe()));
    s
}

fn write_matrix(md: &mut String, m: &Matrix) -> std::fmt::Result {
    writeln!(
        md,
        "## Schemes by case
"
    )?;
    writeln!(
        md,
        "The best preset's headline error at the finest spacing with the bound of the check that \
         judges it, its observed order, wall time, and the scheme's checks; ★ the smallest error \
         of the case.\n"
    )?;
    write!(md, "| case | headline metric |")?;
    for s in &m.schemes {
        write!(md, " {} |", s.to_uppercase())?;
    }
    write!(md, "\n|---|---|")?;
    for _ in &m.schemes {
        write!(md, "---|")?;
    }
    writeln!(md)?;
    for row in &m.rows {
        write!(
            md,
            "| {} {} | `{}` |",
            cell(&row.case),
            if row.pass { "✅" } else { "❌" },
            cell(row.metric.as_deref().unwrap_or("—"))
        )?;
        for c in &row.cells {
            let text = c.as_ref().map_or("not run".to_string(), |c| matrix_cell(c, row.metric.as_deref()));
            write!(md, " {} |", cell(&text))?;
        }
        writeln!(md)?;
    }
    writeln!(md)
}

fn write_summary(
    md: &mut String,
    results: &[CaseResults],
    header: &Header,
    matrix: &Matrix,
    summary: &Summary,
    comparison: Option<&Comparison>,
) -> std::fmt::Result {
    writeln!(md, "# Meniscus validation\n")?;
    writeln!(
        md,
        "**{}**: {} / {} checks passed over {} case(s){}.\n",
        if summary.pass { "PASS" } else { "FAIL" },
        summary.passed,
        summary.passed + summary.failed,
        results.len(),
        if summary.expected_failures > 0 {
            format!(", {} expected failure(s) apart", summary.expected_failures)
        } else {
            String::new()
        }
    )?;
    for (label, value) in header.lines() {
        writeln!(md, "- {label}: {}", cell(&value))?;
    }
    writeln!(md)?;
    write_matrix(md, matrix)?;
    writeln!(md, "## Cases\n")?;
    let with_baseline = comparison.is_some();
    write!(md, "| case | schemes | tier | dx | runs | wall [s] | checks | result |")?;
    writeln!(md, "{}", if with_baseline { " vs baseline |" } else { "" })?;
    write!(md, "|---|---|---|---|---:|---:|---:|---|")?;
    writeln!(md, "{}", if with_baseline { "---|" } else { "" })?;
    for r in results {
        let (passed, failed) = r.counts();
        let diverged = r.runs.iter().filter(|x| !x.ok()).count();
        write!(
            md,
            "| {} | {} | {} | {} | {}{} | {:.1} | {} / {} | {} |",
            cell(&r.case),
            cell(&schemes(r).join(", ")),
            cell(&r.tier),
            resolutions(&r.runs),
            r.runs.len(),
            if diverged > 0 { format!(" ({diverged} diverged)") } else { String::new() },
            r.runs.iter().map(|x| x.wall_s).sum::<f64>(),
            passed,
            passed + failed,
            if failed == 0 { "PASS" } else { "FAIL" }
        )?;
        if let Some(cmp) = comparison {
            let text = match cmp.case(&r.case) {
                Some(c) if c.in_baseline => c.tally().describe(),
                Some(_) => "not in baseline".to_string(),
                None => "—".to_string(),
            };
            write!(md, " {} |", cell(&text))?;
        }
        writeln!(md)?;
    }
    writeln!(md, "\n## Failed checks\n")?;
    write_checks(md, results, |v| !v.expected())?;
    if summary.expected_failures > 0 {
        writeln!(md, "\n## Expected failures\n")?;
        write_checks(md, results, |v| v == Verdict::ExpectedFail)?;
    }
    super::timing::markdown_section(md, results, summary.elapsed_s)?;
    if let Some(cmp) = comparison {
        write_comparison(md, cmp)?;
    }
    Ok(())
}

/// One line per check whose verdict `shown` picks, or `None.`.
fn write_checks(
    md: &mut String,
    results: &[CaseResults],
    shown: impl Fn(Verdict) -> bool,
) -> std::fmt::Result {
    let mut any = false;
    for r in results {
        for c in r.checks.iter().filter(|c| shown(c.verdict())) {
            any = true;
            let value = c.value.map_or("n/a".to_string(), |v| check_number(c, v));
            let threshold = c.threshold.map_or("n/a".to_string(), |v| check_number(c, v));
            let note = c.note.as_deref().map(|n| format!(" — {n}")).unwrap_or_default();
            let verdict = c.verdict().label();
            let reason = c
                .expected_failure
                .as_deref()
                .map(|r| format!(" (expected to fail: {r})"))
                .unwrap_or_default();
            writeln!(
                md,
                "- `{}`: {}: {verdict}, value {value}, threshold {threshold}{note}{reason}",
                r.case, c.name
            )?;
        }
    }
    if !any {
        writeln!(md, "None.")?;
    }
    Ok(())
}

fn write_comparison(md: &mut String, cmp: &Comparison) -> std::fmt::Result {
    writeln!(md, "\n## Compared with baseline `{}`\n", cmp.baseline.display())?;
    writeln!(md, "{}\n", cmp.band.describe())?;
    writeln!(md, "Overall: {}.", cmp.tally().describe())?;
    for case in &cmp.cases {
        write_case_comparison(md, case)?;
    }
    Ok(())
}

fn write_case_comparison(md: &mut String, case: &CaseComparison) -> std::fmt::Result {
    writeln!(md, "\n### {}\n", case.case)?;
    if !case.in_baseline {
        return writeln!(md, "Not in the baseline.");
    }
    if !case.added_runs.is_empty() {
        writeln!(md, "Runs not in the baseline: {}.\n", case.added_runs.join(", "))?;
    }
    if !case.removed_runs.is_empty() {
        writeln!(md, "Baseline runs not run now: {}.\n", case.removed_runs.join(", "))?;
    }
    for c in &case.checks {
        writeln!(md, "- check {}: **{}**", c.name, c.label())?;
    }
    if !case.checks.is_empty() {
        writeln!(md)?;
    }
    let moved = |m: Mark| m != Mark::Unchanged;
    // (run, change, whether it is an observed order)
    let rows: Vec<(String, &crate::baseline::MetricChange, bool)> = case
        .runs
        .iter()
        .flat_map(|r| r.metrics.iter().filter(|m| moved(m.mark)).map(move |m| (r.slug.clone(), m, false)))
        .chain(case.orders.iter().filter(|m| moved(m.mark)).map(|m| ("observed order".to_string(), m, true)))
        .collect();
    let unchanged = case.tally().unchanged;
    if rows.is_empty() {
        writeln!(md, "Every metric within the noise band ({unchanged} compared).\n")?;
    } else {
        writeln!(md, "| run | metric | baseline | now | change | mark |")?;
        writeln!(md, "|---|---|---:|---:|---:|---|")?;
        for (run, m, is_order) in &rows {
            let mark = match m.mark {
                Mark::Worse | Mark::Better => format!("**{}**", m.mark.label()),
                other => other.label().to_string(),
            };
            let fmt = |v| if *is_order { format_order(v) } else { format_metric(&m.name, v) };
            writeln!(
                md,
                "| {} | `{}` | {} | {} | {} | {mark} |",
                cell(run),
                m.name,
                fmt(m.old),
                fmt(m.new),
                format_change(m)
            )?;
        }
        writeln!(md, "\n{unchanged} other metric(s) within the noise band.\n")?;
    }
    if !case.runs.is_empty() {
        writeln!(md, "| run | status | wall baseline [s] | wall now [s] | ratio |")?;
        writeln!(md, "|---|---|---:|---:|---|")?;
        for r in &case.runs {
            let status = if r.old_status == r.new_status {
                r.new_status.clone()
            } else {
                format!("{} → {} (**{}**)", r.old_status, r.new_status, r.status.label())
            };
            writeln!(
                md,
                "| {} | {} | {:.2} | {:.2} | {} |",
                r.slug,
                cell(&status),
                r.wall.old,
                r.wall.new,
                if r.wall.flag.is_some() {
                    format!("**{}**", format_ratio(&r.wall))
                } else {
                    format_ratio(&r.wall)
                }
            )?;
        }
    }
    Ok(())
}
