//! How the harness writes numbers, the same in checks and their notes, tables, the index,
//! `summary.md` and the console:
//! relative errors, drifts and relative changes in percent to three significant digits;
//! other values to four significant digits with their unit; counts as integers; observed
//! orders to two decimals; spacings as written.

use crate::results::CheckKind;
use crate::results::CheckResult;

/// Significant digits of a percentage.
const PERCENT_DIGITS: usize = 3;
/// Significant digits of any other value.
const VALUE_DIGITS: usize = 4;

/// Whether `metric` is a relative quantity written in percent: a relative error
/// (`rel_err`, `_l2_rel`, `_linf_rel`) or a drift.
pub fn is_relative(metric: &str) -> bool {
    ["rel_err", "_l2_rel", "_linf_rel", "drift"].iter().any(|k| metric.contains(k))
}

/// Whether `metric` counts something (particles, steps, clusters): written as an integer.
fn is_count(metric: &str) -> bool {
    matches!(metric, "particles" | "steps" | "clusters_max" | "free_surface_count_final" | "period_crossings")
}

/// The SI unit of an absolute metric, by its name: times (`period`, `t_final`, `wall_s`)
/// in s, rates (`damping_rate`) in 1/s, pressure jumps (`dp_*`) in Pa, velocities (`u_*`)
/// in m/s; `None` for a dimensionless one (`beta_max`, `*_over_d`, `ke_ratio_final`, ...)
/// and for relative ones ([`is_relative`]).
pub fn unit(metric: &str) -> Option<&'static str> {
    if is_relative(metric) || is_count(metric) {
        return None;
    }
    match metric {
        "period" | "period_ref" | "t_final" | "wall_s" | "cpu_s" => Some("s"),
        "damping_rate" | "damping_ref" => Some("1/s"),
        m if m.starts_with("dp_") => Some("Pa"),
        m if m.starts_with("u_") => Some("m/s"),
        _ => None,
    }
}

/// `x` to `digits` significant digits: plain between 1e-3 and 1e5, else in scientific
/// notation (`1.235e-5`); rounded first, so 9.9996 to four digits is `10.00`.
pub fn significant(x: f64, digits: usize) -> String {
    if x.is_nan() {
        return "NaN".to_string();
    }
    if x.is_infinite() {
        return if x > 0.0 { "inf" } else { "-inf" }.to_string();
    }
    if x == 0.0 {
        return "0".to_string();
    }
    let prec = digits.saturating_sub(1);
    let scientific = format!("{x:.prec$e}");
    // The exponent after rounding to `digits`.
    let exponent: i32 = scientific.rsplit('e').next().and_then(|e| e.parse().ok()).unwrap_or(0);
    if (-3..5).contains(&exponent) {
        let decimals = (prec as i32 - exponent).max(0) as usize;
        format!("{x:.decimals$}")
    } else {
        scientific
    }
}

/// A fraction in percent to three significant digits (`0.0280` → `2.80 %`).
pub fn percent(fraction: f64) -> String {
    format!("{} %", significant(fraction * 100.0, PERCENT_DIGITS))
}

/// A metric as the report writes it: relative ones in percent, counts as integers, others
/// to four significant digits with their unit ([`unit()`]); `—` when absent.
pub fn format_metric(name: &str, v: Option<f64>) -> String {
    match v {
        None => "—".to_string(),
        Some(x) if x.is_nan() => "NaN".to_string(),
        Some(x) if is_relative(name) => percent(x),
        Some(x) if is_count(name) && x.is_finite() => format!("{x:.0}"),
        Some(x) => match unit(name) {
            Some(u) => format!("{} {u}", significant(x, VALUE_DIGITS)),
            None => significant(x, VALUE_DIGITS),
        },
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

/// A spacing \[m\] as text: as written when short (`0.02`), else to 4 significant digits
/// (`5.556e-3` for D/36).
pub fn format_dx(dx: f64) -> String {
    let plain = dx.to_string();
    if plain.len() <= 8 { plain } else { format!("{dx:.3e}") }
}

/// Spacings as `0.02, 0.01` ([`format_dx`] each).
pub fn dx_list(dx: &[f64]) -> String {
    dx.iter().map(|&d| format_dx(d)).collect::<Vec<_>>().join(", ")
}

/// A check's value or threshold `v` as the check reads it: a bound in its metric's form
/// ([`format_metric`]), an order to two decimals, a `decreasing` ratio to three significant
/// digits, a `finest_change` in percent; a check that records no metric (a count of runs)
/// as a plain number.
pub fn check_number(check: &CheckResult, v: f64) -> String {
    match &check.judges {
        Some(j) => match j.kind {
            CheckKind::Max | CheckKind::Min | CheckKind::Equals => format_metric(&j.metric, Some(v)),
            CheckKind::Order => format_order(Some(v)),
            CheckKind::Decreasing => significant(v, PERCENT_DIGITS),
            CheckKind::FinestChange => percent(v),
        },
        None if v.fract() == 0.0 && v.abs() < 1e15 => format!("{v:.0}"),
        None => significant(v, VALUE_DIGITS),
    }
}

/// A check's bound as text with its relation (`≤ 1.00 %`, `≥ 1.50`, `= 7860`, `< 1.00`);
/// empty when it has none.
pub fn check_bound(check: &CheckResult) -> String {
    let Some(t) = check.threshold else { return String::new() };
    let relation = match check.judges.as_ref().map(|j| j.kind) {
        Some(CheckKind::Max | CheckKind::FinestChange) => "≤",
        Some(CheckKind::Min | CheckKind::Order) => "≥",
        Some(CheckKind::Equals) => "=",
        Some(CheckKind::Decreasing) => "<",
        None => "≤",
    };
    format!("{relation} {}", check_number(check, t))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::results::{Judged, Selector};

    #[test]
    fn rounding_decides_the_notation() {
        assert_eq!(significant(9.9996, 4), "10.00");
        assert_eq!(significant(0.000_999_96, 4), "0.001000");
        assert_eq!(significant(99_999.6, 4), "1.000e5");
        assert_eq!(significant(-0.012_345, 3), "-0.0123");
        assert_eq!(significant(f64::INFINITY, 3), "inf");
        assert_eq!(percent(0.009_999_6), "1.00 %");
    }

    #[test]
    fn percentages_keep_three_significant_digits() {
        assert_eq!(percent(1.299_84), "130 %");
        assert_eq!(percent(0.028_04), "2.80 %");
        assert_eq!(percent(0.000_954), "0.0954 %");
        assert_eq!(percent(0.000_04), "0.00400 %");
        assert_eq!(percent(1.234e-8), "1.23e-6 %");
        assert_eq!(percent(0.0), "0 %");
    }

    #[test]
    fn metrics_read_with_their_units() {
        assert_eq!(format_metric("u_profile_l2_rel_steady", Some(0.0095)), "0.950 %");
        assert_eq!(format_metric("b_rel_err_max", Some(0.001)), "0.100 %");
        assert_eq!(format_metric("lz_drift", Some(0.225_24)), "22.5 %");
        assert_eq!(format_metric("particles", Some(648.0)), "648");
        assert_eq!(format_metric("min_pair_over_dx_min", Some(0.41579)), "0.4158");
        assert_eq!(format_metric("beta_max", Some(1.563_6)), "1.564");
        assert_eq!(format_metric("beta_max", Some(3.0)), "3.000");
        assert_eq!(format_metric("dp_late", Some(5.004)), "5.004 Pa");
        assert_eq!(format_metric("u_spurious_max_late", Some(4.975e-6)), "4.975e-6 m/s");
        assert_eq!(format_metric("period", Some(0.2294)), "0.2294 s");
        assert_eq!(format_metric("damping_rate", Some(2.0)), "2.000 1/s");
        assert_eq!(format_metric("x", None), "—");
        assert_eq!(format_metric("x", Some(f64::NAN)), "NaN");
        assert_eq!(format_dx(0.02), "0.02");
        assert_eq!(format_dx(0.0025), "0.0025");
        assert_eq!(format_dx(0.2 / 36.0), "5.556e-3");
    }

    #[test]
    fn checks_read_in_their_metric_form() {
        let check = |kind, metric: &str, threshold| CheckResult {
            name: "c".into(),
            value: None,
            threshold: Some(threshold),
            pass: true,
            note: None,
            expected_failure: None,
            judges: Some(Judged { metric: metric.into(), kind, select: Selector::default() }),
        };
        assert_eq!(check_bound(&check(CheckKind::Max, "b_rel_err_max", 0.01)), "≤ 1.00 %");
        assert_eq!(check_bound(&check(CheckKind::Order, "b_rel_err_max", 1.5)), "≥ 1.50");
        assert_eq!(check_bound(&check(CheckKind::Equals, "particles", 1976.0)), "= 1976");
        assert_eq!(check_bound(&check(CheckKind::Decreasing, "b_rel_err_max", 1.0)), "< 1.00");
        assert_eq!(check_bound(&check(CheckKind::FinestChange, "beta_max", 0.05)), "≤ 5.00 %");
        assert_eq!(check_number(&check(CheckKind::Min, "min_pair_over_dx_min", 0.5), 0.41579), "0.4158");
        let unrecorded = CheckResult { judges: None, ..check(CheckKind::Max, "x", 0.0) };
        assert_eq!(check_number(&unrecorded, 2.0), "2");
        assert_eq!(check_number(&unrecorded, 0.123_456), "0.1235");
    }
}
