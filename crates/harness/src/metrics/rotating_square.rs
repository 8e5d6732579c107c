//! Metrics of the rotating square patch (CASES.md "rotating_square", Qiu 2013 §3.2): the
//! first pressure field against the analytical pressure of the inviscid patch
//! (`meniscus_reference::rotating_square`, Colagrossi's series), particle disorder,
//! angular momentum and energy.
//!
//! The scene's `pressure_at` probes (`pressure_at`, `pressure_at_1`, ...) sample the
//! pressure (Shepard average) at fixed points; the first probe is the centre. With the
//! first sample after `t = 0` (the first PPE solve):
//! - `pc_rel_err_first`: centre pressure against `−0.1473427 ρ ω² L²`;
//! - `p_points_l2_rel_first`: relative L2 error over all the probe points.
//!
//! From the `disorder` probe: `min_pair_over_dx_min` (smallest over the history),
//! `close_fraction_max`, `close_fraction_final`. From `momentum`: `lz_drift` (largest
//! `|L_z(t) − L_z(0)| / |L_z(0)|`). From `kinetic_energy`: `ke_ratio_final` = `E(end)/E(0)`.
//! From `solver`: `free_surface_count_final`. And `t_final`. Series: `t`, `p_centre`,
//! `pc_ref` (the initial analytical value, drawn for the first solves), `min_pair_over_dx`,
//! `close_fraction`, `lz`, `e`, `free_surface_count`.

use super::{Measured, drift, nan_max};
use meniscus::ProbeRecord;
use meniscus_reference::ReferenceError;
use meniscus_reference::rotating_square::RotatingSquare;

/// Computes the metrics of one run; `points` are the scene's `pressure_at` points in
/// probe order (the first is the centre).
pub fn compute(
    patch: &RotatingSquare,
    points: &[[f64; 2]],
    probes: &ProbeRecord,
) -> Result<Measured, ReferenceError> {
    let mut out = Measured::default();
    let t = &probes.t;
    if t.is_empty() {
        return Ok(out);
    }
    let m = &mut out.metrics;
    m.insert("t_final".into(), t[t.len() - 1]);
    let first = t.iter().position(|&x| x > 0.0);
    let key = |i: usize| if i == 0 { "pressure_at".to_string() } else { format!("pressure_at_{i}") };
    if let Some(i) = first {
        let (mut num, mut den) = (0.0, 0.0);
        for (k, pt) in points.iter().enumerate() {
            let Some(p) = probes.get(&key(k), "p") else { continue };
            let r = patch.pressure(pt[0], pt[1])?;
            num += (p[i] - r).powi(2);
            den += r * r;
            if k == 0 {
                m.insert("pc_rel_err_first".into(), ((p[i] - r) / r).abs());
            }
        }
        if den > 0.0 {
            m.insert("p_points_l2_rel_first".into(), (num / den).sqrt());
        }
    }
    if let Some(p) = probes.get("pressure_at", "p") {
        out.series.insert("p_centre".into(), p.to_vec());
        out.series.insert("pc_ref".into(), vec![patch.centre_pressure(); t.len()]);
    }
    if let Some(v) = probes.get("disorder", "min_pair_over_dx") {
        m.insert("min_pair_over_dx_min".into(), -nan_max(&v.iter().map(|x| -x).collect::<Vec<_>>()));
        out.series.insert("min_pair_over_dx".into(), v.to_vec());
    }
    if let Some(v) = probes.get("disorder", "close_fraction") {
        m.insert("close_fraction_max".into(), nan_max(v));
        m.insert("close_fraction_final".into(), v[v.len() - 1]);
        out.series.insert("close_fraction".into(), v.to_vec());
    }
    if let Some(v) = probes.get("momentum", "lz") {
        m.insert("lz_drift".into(), drift(v));
        out.series.insert("lz".into(), v.to_vec());
    }
    if let Some(v) = probes.get("kinetic_energy", "e") {
        m.insert("ke_ratio_final".into(), v[v.len() - 1] / v[0]);
        out.series.insert("e".into(), v.to_vec());
    }
    if let Some(v) = probes.get("solver", "free_surface_count") {
        m.insert("free_surface_count_final".into(), v[v.len() - 1]);
        out.series.insert("free_surface_count".into(), v.to_vec());
    }
    out.series.insert("t".into(), t.clone());
    Ok(out)
}

/// The `pressure_at` points of a run's scene, in probe order.
pub fn pressure_points(scene: &serde_json::Value) -> Vec<[f64; 2]> {
    let Some(probes) = scene["probes"].as_array() else { return Vec::new() };
    probes
        .iter()
        .filter_map(|p| p["pressure_at"]["point"].as_array())
        .map(|pt| {
            let c = |i: usize| pt.get(i).and_then(serde_json::Value::as_f64).unwrap_or(f64::NAN);
            [c(0), c(1)]
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::BTreeMap;

    fn patch() -> RotatingSquare {
        RotatingSquare::new(1.0, 100.0, 1000.0).unwrap()
    }

    /// Probes at t = 0, 1e-4 with the pressure at `points` scaled by `1 + bias`.
    fn synthetic(points: &[[f64; 2]], bias: f64) -> ProbeRecord {
        let mut series = BTreeMap::new();
        for (k, pt) in points.iter().enumerate() {
            let key = if k == 0 { "pressure_at".to_string() } else { format!("pressure_at_{k}") };
            let p = patch().pressure(pt[0], pt[1]).unwrap();
            series.insert(key, BTreeMap::from([("p".to_string(), vec![0.0, p * (1.0 + bias)])]));
        }
        series.insert("momentum".into(), BTreeMap::from([("lz".to_string(), vec![-100.0, -99.0])]));
        series.insert(
            "disorder".into(),
            BTreeMap::from([
                ("min_pair_over_dx".to_string(), vec![1.0, 0.4]),
                ("close_fraction".to_string(), vec![0.0, 0.02]),
            ]),
        );
        ProbeRecord { t: vec![0.0, 1e-4], series }
    }

    #[test]
    fn first_pressure_errors_disorder_and_drift() {
        let points = [[0.0, 0.0], [0.2, 0.0], [0.2, 0.3], [-0.4, 0.1]];
        let m = compute(&patch(), &points, &synthetic(&points, 0.0)).unwrap().metrics;
        assert!(m["pc_rel_err_first"] < 1e-12 && m["p_points_l2_rel_first"] < 1e-12);
        let m = compute(&patch(), &points, &synthetic(&points, 0.05)).unwrap().metrics;
        assert!((m["pc_rel_err_first"] - 0.05).abs() < 1e-12);
        assert!((m["p_points_l2_rel_first"] - 0.05).abs() < 1e-12);
        assert!((m["min_pair_over_dx_min"] - 0.4).abs() < 1e-15);
        assert!((m["close_fraction_max"] - 0.02).abs() < 1e-15);
        assert!((m["lz_drift"] - 0.01).abs() < 1e-12);
    }

    #[test]
    fn points_come_from_the_scene_in_order() {
        let scene = serde_json::json!({ "probes": [ { "pressure_at": { "point": [0.0, 0.0] } }, { "kinetic_energy": {} },
                                                     { "pressure_at": { "point": [0.1, -0.2] } } ] });
        assert_eq!(pressure_points(&scene), vec![[0.0, 0.0], [0.1, -0.2]]);
    }
}
