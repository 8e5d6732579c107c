//! Metrics of a run against the case's analytical reference, per reference kind, plus the
//! generic error norms they are built from.
//!
//! Metric names are snake_case with the quantity and the norm (DESIGN.md):
//! `<quantity>_rel_err_max` (largest relative error over the recorded history),
//! `<quantity>_rel_err_final` (at the last sample), `<quantity>_drift` (largest
//! `|x(t) - x(0)| / |x(0)|`). Non-finite samples make the norm NaN (never silently skipped).

pub mod capillarity;
pub mod channel;
pub mod elliptical_drop;
pub mod hydrostatic;
pub mod impact;
pub mod poiseuille;
pub mod rotating_square;

use crate::case::ReferenceSpec;
use meniscus::ProbeRecord;
use std::collections::BTreeMap;

/// Scalar metrics and plot series of one run.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Measured {
    /// Scalar metrics by name.
    pub metrics: BTreeMap<String, f64>,
    /// Series by name, aligned with `series["t"]`.
    pub series: BTreeMap<String, Vec<f64>>,
}

/// Computes the metrics of a run's probes against `reference`; `scene` is the run's
/// effective scene (references may take physical parameters from it), `steady_at` the
/// time \[s\] at which its steady-state stop (`time.steady`) ended it, if it did.
pub fn compute(
    reference: &ReferenceSpec,
    scene: &serde_json::Value,
    probes: &ProbeRecord,
    particles: usize,
    steady_at: Option<f64>,
) -> Result<Measured, meniscus_reference::ReferenceError> {
    let mut m = match *reference {
        ReferenceSpec::EllipticalDrop { radius, a0, density } => {
            elliptical_drop::compute(&elliptical_drop::Params { radius, a0, density }, probes)?
        }
        ReferenceSpec::PoiseuilleStartup { width, wall } => {
            poiseuille::compute(&poiseuille::channel(width, scene)?, wall, probes, steady_at)?
        }
        ReferenceSpec::HagenPoiseuille { radius, axis } => {
            poiseuille::compute(&poiseuille::pipe(radius, axis, scene)?, 0.0, probes, steady_at)?
        }
        ReferenceSpec::EntranceFlow { width, wall } => {
            channel::compute(&channel::Channel::new(width, wall, scene)?, probes)?
        }
        ReferenceSpec::RotatingSquare { side, omega, density } => {
            let patch = meniscus_reference::rotating_square::RotatingSquare::new(side, omega, density)?;
            rotating_square::compute(&patch, &rotating_square::pressure_points(scene), probes)?
        }
        // The capillarity references take the run's dimension (2 or 3, 2 when absent) from
        // the scene.
        ReferenceSpec::StaticDrop { radius, sigma } => {
            let dim = capillarity::dimension(scene)?;
            capillarity::compute(dim, &capillarity::Capillary::Static { radius, sigma }, probes)?
        }
        ReferenceSpec::OscillatingDrop { radius, sigma, density } => {
            let dim = capillarity::dimension(scene)?;
            let nu = fluid_property(scene, "viscosity") / fluid_property(scene, "density");
            let case = capillarity::Capillary::Oscillating { radius, sigma, density, nu };
            capillarity::compute(dim, &case, probes)?
        }
        ReferenceSpec::DropletImpact { diameter, speed } => {
            impact::compute(&impact::Params::new(diameter, speed, scene), probes)?
        }
        ReferenceSpec::Hydrostatic {} => hydrostatic::compute(&hydrostatic::gravity(scene)?, probes)?,
        ReferenceSpec::SquareDrop { side, sigma, density } => {
            let dim = capillarity::dimension(scene)?;
            capillarity::compute(dim, &capillarity::Capillary::Square { side, sigma, density }, probes)?
        }
    };
    m.metrics.insert("particles".into(), particles as f64);
    Ok(m)
}

/// Pointwise relative errors `|v - r| / |r|` of two aligned series.
pub fn rel_errors(values: &[f64], reference: &[f64]) -> Vec<f64> {
    values.iter().zip(reference).map(|(v, r)| ((v - r) / r).abs()).collect()
}

/// Largest pointwise relative error; NaN if any sample is not finite or the series is empty.
pub fn rel_err_max(values: &[f64], reference: &[f64]) -> f64 {
    nan_max(&rel_errors(values, reference))
}

/// A number of the scene's `fluid` (`density`, `viscosity`, ...), NaN when absent, so that a
/// metric computed from it is NaN and fails its checks rather than passing on a default.
pub fn fluid_property(scene: &serde_json::Value, key: &str) -> f64 {
    scene["fluid"][key].as_f64().unwrap_or(f64::NAN)
}

/// Relative error at the last sample (NaN when empty).
pub fn rel_err_final(values: &[f64], reference: &[f64]) -> f64 {
    match (values.last(), reference.last()) {
        (Some(v), Some(r)) => ((v - r) / r).abs(),
        _ => f64::NAN,
    }
}

/// The ratios `values / reference` at the samples in the last `fraction` of the time span
/// (none when `t` is empty).
fn late_ratios(t: &[f64], values: &[f64], reference: &[f64], fraction: f64) -> Vec<f64> {
    let (Some(&t0), Some(&t1)) = (t.first(), t.last()) else { return Vec::new() };
    let from = t1 - fraction * (t1 - t0);
    t.iter()
        .zip(values.iter().zip(reference))
        .filter(|(ti, _)| **ti >= from)
        .map(|(_, (v, r))| v / r)
        .collect()
}

/// Relative error of an oscillating quantity judged over the late history: the mean of
/// `values / reference` over the samples in the last `fraction` of the time span, minus 1,
/// in absolute value (one sample of an oscillation is a draw, its window mean is not). NaN
/// when a sample in the window is, or there is none.
pub fn rel_err_late(t: &[f64], values: &[f64], reference: &[f64], fraction: f64) -> f64 {
    let ratios = late_ratios(t, values, reference, fraction);
    if ratios.is_empty() {
        return f64::NAN;
    }
    (ratios.iter().sum::<f64>() / ratios.len() as f64 - 1.0).abs()
}

/// Largest relative error over the late history: `max |v/r − 1|` over the samples in the
/// last `fraction` of the time span (an oscillating quantity held over a window, not read
/// at one instant). NaN when a sample in the window is, or there is none.
pub fn rel_err_max_late(t: &[f64], values: &[f64], reference: &[f64], fraction: f64) -> f64 {
    let errors: Vec<f64> =
        late_ratios(t, values, reference, fraction).iter().map(|q| (q - 1.0).abs()).collect();
    nan_max(&errors)
}

/// Largest relative drift from the first sample, `max_t |x(t) - x(0)| / |x(0)|`.
pub fn drift(values: &[f64]) -> f64 {
    match values.first() {
        Some(&x0) => nan_max(&values.iter().map(|x| ((x - x0) / x0).abs()).collect::<Vec<_>>()),
        None => f64::NAN,
    }
}

/// Maximum that propagates NaN (an unstable sample must not vanish from a max norm).
pub fn nan_max(values: &[f64]) -> f64 {
    if values.is_empty() {
        return f64::NAN;
    }
    values.iter().copied().fold(f64::NEG_INFINITY, sticky_max)
}

/// The larger of `a` and `b`, NaN when either is (`f64::max` drops a NaN: a later finite
/// sample must not overwrite an earlier NaN).
pub fn sticky_max(a: f64, b: f64) -> f64 {
    if a.is_nan() || b.is_nan() { f64::NAN } else { a.max(b) }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn late_error_is_that_of_the_window_mean() {
        let t: Vec<f64> = (0..=8).map(f64::from).collect();
        let reference = vec![2.0; 9];
        // ±10 % oscillation about +2 % in the last quarter (t = 6, 7, 8): mean +2 % … of
        // three samples (1.12, 0.92, 1.12) → 1.0533, a 5.3 % error; the last sample alone is 12 %.
        let v: Vec<f64> =
            t.iter().map(|&x| 2.0 * (1.02 + if (x as i32) % 2 == 0 { 0.1 } else { -0.1 })).collect();
        let late = rel_err_late(&t, &v, &reference, 0.25);
        assert!((late - (1.12 + 0.92 + 1.12) / 3.0 + 1.0).abs() < 1e-12, "{late}");
        assert!((rel_err_final(&v, &reference) - 0.12).abs() < 1e-12);
        let mut gap = v.clone();
        gap[7] = f64::NAN;
        assert!(rel_err_late(&t, &gap, &reference, 0.25).is_nan());
        assert!(rel_err_late(&[], &[], &[], 0.25).is_nan());
    }

    #[test]
    fn nan_is_sticky_in_maxima() {
        assert!(sticky_max(f64::NAN, 1.0).is_nan() && sticky_max(1.0, f64::NAN).is_nan());
        assert_eq!(sticky_max(1.0, 2.0).to_bits(), 2.0f64.to_bits());
        // A NaN early in a series survives the later finite samples.
        assert!([0.1, f64::NAN, 0.2, 0.3].into_iter().fold(0.0, sticky_max).is_nan());
        assert!(nan_max(&[0.1, f64::NAN, 0.3]).is_nan() && nan_max(&[]).is_nan());
    }

    #[test]
    fn relative_error_norms() {
        let reference = [1.0, 2.0, 4.0];
        let values = [1.01, 1.9, 4.0];
        assert!((rel_err_max(&values, &reference) - 0.05).abs() < 1e-12);
        assert!(rel_err_final(&values, &reference).abs() < 1e-12);
        assert!((rel_err_final(&[1.0, 4.4], &[1.0, 4.0]) - 0.1).abs() < 1e-12);
        assert!(rel_err_max(&[], &[]).is_nan());
        assert!(rel_err_final(&[], &[]).is_nan());
    }

    #[test]
    fn late_maximum_reads_only_the_window() {
        let t = [0.0, 1.0, 2.0, 3.0, 4.0];
        let reference = [2.0; 5];
        // A 50 % excursion in the first half does not count; the worst late one (10 %) does,
        // and the sample at the window's start (t = 2) belongs to it.
        let values = [3.0, 2.1, 1.8, 2.1, 2.0];
        assert!((rel_err_max_late(&t, &values, &reference, 0.5) - 0.1).abs() < 1e-12);
        assert!((rel_err_max_late(&t, &values, &reference, 1.0) - 0.5).abs() < 1e-12);
        assert!(rel_err_max_late(&t, &[3.0, 2.1, 1.8, f64::NAN, 2.0], &reference, 0.5).is_nan());
        assert!(rel_err_max_late(&[], &[], &[], 0.5).is_nan());
    }

    #[test]
    fn nan_is_not_skipped() {
        assert!(rel_err_max(&[1.0, f64::NAN, 1.0], &[1.0, 1.0, 1.0]).is_nan());
        assert!(nan_max(&[0.1, f64::NAN]).is_nan());
        assert!((nan_max(&[0.1, 0.3, 0.2]) - 0.3).abs() < 1e-15);
    }

    #[test]
    fn capillarity_dimension_comes_from_the_scene() {
        use serde_json::json;
        let (radius, sigma) = (0.2, 1.0);
        let t: Vec<f64> = (0..=10).map(|i| i as f64 * 0.1).collect();
        let mut probes = ProbeRecord { t: t.clone(), ..Default::default() };
        probes
            .series
            .entry("mean_pressure".into())
            .or_default()
            .insert("p".into(), vec![2.0 * sigma / radius; t.len()]);
        let reference = ReferenceSpec::StaticDrop { radius, sigma };
        let err = |scene: serde_json::Value| compute(&reference, &scene, &probes, 1, None).unwrap().metrics["dp_rel_err_late"];
        // 2σ/R is exact for a sphere and twice σ/R for a circle (also without `dimension`).
        assert!(err(json!({ "dimension": 3 })).abs() < 1e-12);
        assert!((err(json!({ "dimension": 2 })) - 1.0).abs() < 1e-12);
        assert!((err(json!({})) - 1.0).abs() < 1e-12);
        assert!(compute(&reference, &json!({ "dimension": 5 }), &probes, 1, None).is_err());
    }

    #[test]
    fn kinetic_energy_drift() {
        let e = [100.0, 99.0, 101.5, 98.5];
        assert!((drift(&e) - 0.015).abs() < 1e-12);
        assert!(drift(&[5.0]).abs() < 1e-15);
        assert!(drift(&[]).is_nan());
    }
}
