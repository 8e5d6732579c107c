//! Metrics of a drop at rest under gravity (Zhou 2021 §3.4, `drop_on_plate`): the
//! `pressure_gradient` probe's least-squares gradient over the drop's interior against the
//! hydrostatic `∇p = ρ g` (ρ the scene's `fluid.density`, g its `body_force`).
//!
//! - `dpdg_rel_err_late`, `dpdg_rel_err_final`: the gradient's component along g against
//!   `ρ|g|`, averaged over the last quarter of the run (relative), and at its last sample;
//! - `dp_transverse_late`: the largest component across g over the last quarter, over
//!   `ρ|g|` (0 at rest);
//! - `dpdg_late` \[Pa/m\]: the gradient along g, averaged over the last quarter;
//! - `u_max_late` \[m/s\]: the largest particle speed over the last quarter (`max_speed`);
//! - with a `young_laplace` probe, the outline's pressure against `γ κ` of the local circle
//!   fits (Zhou 2021 §3.4), each over the mean `γ κ` and averaged over the last quarter:
//!   `young_laplace_rel_err_late` (the RMS of `p − γ κ` over the outline),
//!   `young_laplace_bias_late` (the mean of `p − γ κ`, signed) and
//!   `young_laplace_max_rel_late` (the largest `|p − γ κ|`, the largest over the quarter).

use super::{Measured, nan_max, rel_err_final, rel_err_late};
use meniscus::ProbeRecord;
use meniscus_reference::ReferenceError;

/// The hydrostatic gradient `ρ g` \[Pa/m\] of a run's scene (one component per axis).
pub fn gravity(scene: &serde_json::Value) -> Result<Vec<f64>, ReferenceError> {
    let rho = super::fluid_property(scene, "density");
    let g: Vec<f64> =
        scene["body_force"].as_array().map_or(Vec::new(), |v| v.iter().filter_map(|x| x.as_f64()).collect());
    let norm = g.iter().map(|x| x * x).sum::<f64>().sqrt();
    if !(rho.is_finite() && rho > 0.0) {
        return Err(ReferenceError::InvalidParameter {
            name: "fluid.density",
            value: rho,
            rule: "must be positive and finite",
        });
    }
    if !(norm.is_finite() && norm > 0.0) {
        return Err(ReferenceError::InvalidParameter {
            name: "|body_force|",
            value: norm,
            rule: "must be positive and finite (a drop at rest under gravity)",
        });
    }
    Ok(g.iter().map(|x| rho * x).collect())
}

/// The metrics of the module documentation for the hydrostatic gradient `rho_g` \[Pa/m\]
/// (NaN, failing their checks, when the run has no `pressure_gradient` probe).
pub fn compute(rho_g: &[f64], probes: &ProbeRecord) -> Result<Measured, ReferenceError> {
    let names = ["dp_dx", "dp_dy", "dp_dz"];
    let nan = vec![f64::NAN; probes.t.len()];
    let series: Vec<&[f64]> =
        names.iter().take(rho_g.len()).map(|n| probes.get("pressure_gradient", n).unwrap_or(&nan)).collect();
    let norm = rho_g.iter().map(|x| x * x).sum::<f64>().sqrt();
    let unit: Vec<f64> = rho_g.iter().map(|x| x / norm).collect();
    let t = &probes.t;
    let along: Vec<f64> =
        (0..t.len()).map(|k| series.iter().zip(&unit).map(|(s, e)| s[k] * e).sum()).collect();
    let across: Vec<f64> = (0..t.len())
        .map(|k| {
            let a = along[k];
            series.iter().zip(&unit).map(|(s, e)| (s[k] - a * e).powi(2)).sum::<f64>().sqrt() / norm
        })
        .collect();
    let reference = vec![norm; t.len()];
    let late = |v: &[f64]| -> Vec<f64> {
        let from = t.last().copied().unwrap_or(0.0) * 0.75 + t.first().copied().unwrap_or(0.0) * 0.25;
        t.iter().zip(v).filter(|(ti, _)| **ti >= from).map(|(_, x)| *x).collect()
    };
    let mut m = Measured::default();
    m.metrics.insert("dpdg_rel_err_late".into(), rel_err_late(t, &along, &reference, 0.25));
    m.metrics.insert("dpdg_rel_err_final".into(), rel_err_final(&along, &reference));
    let along_late = late(&along);
    m.metrics.insert("dpdg_late".into(), along_late.iter().sum::<f64>() / along_late.len().max(1) as f64);
    m.metrics.insert("dp_transverse_late".into(), nan_max(&late(&across)));
    if let Some(u) = probes.get("max_speed", "u_max") {
        m.metrics.insert("u_max_late".into(), nan_max(&late(u)));
    }
    if let (Some(rms), Some(max), Some(laplace), Some(p)) = (
        probes.get("young_laplace", "error_rms"),
        probes.get("young_laplace", "error_max"),
        probes.get("young_laplace", "laplace_mean"),
        probes.get("young_laplace", "p_mean"),
    ) {
        let over = |v: &[f64]| -> Vec<f64> { v.iter().zip(laplace).map(|(e, l)| e / l).collect() };
        let bias: Vec<f64> = p.iter().zip(laplace).map(|(p, l)| (p - l) / l).collect();
        let mean = |v: Vec<f64>| v.iter().sum::<f64>() / v.len() as f64;
        m.metrics.insert("young_laplace_rel_err_late".into(), mean(late(&over(rms))));
        m.metrics.insert("young_laplace_bias_late".into(), mean(late(&bias)));
        m.metrics.insert("young_laplace_max_rel_late".into(), nan_max(&late(&over(max))));
        m.series.insert("young_laplace_rel_err".into(), over(rms));
        m.series.insert("young_laplace_p".into(), p.to_vec());
        m.series.insert("young_laplace_ref".into(), laplace.to_vec());
    }
    m.series.insert("t".into(), t.clone());
    m.series.insert("dpdg".into(), along);
    m.series.insert("dpdg_ref".into(), reference);
    Ok(m)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_gradient_two_percent_steep_is_a_two_percent_error() {
        let t: Vec<f64> = (0..=100).map(|i| i as f64 * 0.04).collect();
        let mut r = ProbeRecord { t: t.clone(), ..Default::default() };
        let g = r.series.entry("pressure_gradient".into()).or_default();
        g.insert("dp_dx".into(), vec![0.1; t.len()]);
        g.insert("dp_dy".into(), t.iter().map(|ti| if *ti < 3.0 { 0.0 } else { -10.2 }).collect());
        let scene = serde_json::json!({"fluid": {"density": 1.0}, "body_force": [0.0, -10.0]});
        let m = compute(&gravity(&scene).unwrap(), &r).unwrap().metrics;
        assert!((m["dpdg_rel_err_late"] - 0.02).abs() < 1e-12, "{m:?}");
        assert!((m["dpdg_late"] - 10.2).abs() < 1e-12);
        assert!((m["dp_transverse_late"] - 0.01).abs() < 1e-12);
        let e = gravity(&serde_json::json!({"fluid": {"density": 1.0}, "body_force": [0.0, 0.0]}));
        assert!(e.is_err());
        assert!(!m.contains_key("young_laplace_rel_err_late"), "no young_laplace probe, no metric");
    }

    /// The outline's RMS and mean error over the mean `γ κ`, averaged over the last quarter
    /// (the first three quarters, far off, do not count).
    #[test]
    fn the_outline_error_is_read_over_the_last_quarter() {
        let t: Vec<f64> = (0..=100).map(|i| i as f64 * 0.04).collect();
        let early = |late: f64, off: f64| t.iter().map(|ti| if *ti < 3.0 { off } else { late }).collect();
        let mut r = ProbeRecord { t: t.clone(), ..Default::default() };
        let y = r.series.entry("young_laplace".into()).or_default();
        y.insert("error_rms".into(), early(0.5, 9.0));
        y.insert("error_max".into(), early(1.0, 9.0));
        y.insert("laplace_mean".into(), vec![10.0; t.len()]);
        y.insert("p_mean".into(), early(9.8, 0.0));
        let m = compute(&[0.0, -10.0], &r).unwrap().metrics;
        assert!((m["young_laplace_rel_err_late"] - 0.05).abs() < 1e-12, "{m:?}");
        assert!((m["young_laplace_bias_late"] + 0.02).abs() < 1e-12, "{m:?}");
        assert!((m["young_laplace_max_rel_late"] - 0.1).abs() < 1e-12, "{m:?}");
    }
}
