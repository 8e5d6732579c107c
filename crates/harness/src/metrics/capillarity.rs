//! Metrics of the capillarity cases (CASES.md "static_drop and oscillating_drop",
//! "square_drop_tension") against `meniscus_reference::capillarity`, for a circular drop
//! (2D) or, for the static and oscillating drops, a spherical one (3D).
//!
//! The dimension is the run scene's `dimension` (2 or 3; 2 when absent, [`dimension`]); it
//! selects the reference formula and, for the oscillating drop, the shape probe. The metric
//! names are the same in both, so a 3D case file uses the same checks.
//!
//! Common: the inside pressure \[Pa\] is the `mean_pressure` probe's `p` (the mean pressure
//! of the fluid particles within a radius of a point inside the drop, away from its surface)
//! when the run records it, else the `pressure_at` probe's `p` at the drop's centre
//! (Shepard average); with both, `mean_pressure` is read, in 2D as in 3D (the 2D cases
//! record only `pressure_at`). As the weakly compressible pressure carries acoustic noise,
//! the pressure jump is also averaged over the last quarter of the run (`*_late`).
//!
//! | | 2D (circle) | 3D (sphere) |
//! |---|---|---|
//! | Laplace jump Δp \[Pa\] | `σ/R` | `2σ/R` |
//! | mode-2 period \[s\] | `2π √(ρR³/(6σ))` | `2π √(ρR³/(8σ))` |
//! | amplitude damping rate \[1/s\] | `4ν/R²` | `5ν/R²` |
//! | deformation d \[m\] | `a_moment − b_moment` (`ellipse_axes`) | `a_moment − c_moment` (`ellipsoid_axes`) |
//!
//! (`laplace_pressure`, `oscillation_period` with mode 2 and `damping_rate` with mode 2 of
//! `meniscus_reference::capillarity` with the run's `Dimension`.)
//!
//! - static drop (`R` \[m\], `σ` \[N/m\]): `dp_rel_err_final`, `dp_rel_err_late` (relative)
//!   and `dp_late` \[Pa\] against the Laplace jump Δp above;
//!   `u_spurious_max_final`, `u_spurious_max_late` (largest particle speed \[m/s\], from the
//!   `max_speed` probe), `u_spurious_rms_late` \[m/s\].
//! - oscillating drop (`R` \[m\], `σ` \[N/m\], `ρ` \[kg/m³\]; ν \[m²/s\] from the scene): the
//!   deformation d(t) above (in 3D the drop starts with `u = ε (x, y, −2z)`, axisymmetric
//!   about z, so mode 2 shows as `a_moment − c_moment`, the moment semi-axes
//!   `√(5⟨(x_i − c_i)²⟩)` along x and z); its period `period` \[s\] from the mean
//!   spacing of its zero crossings (linear interpolation; at least two crossings; a
//!   crossing counts only after an excursion beyond ±[`HYSTERESIS`] × max |d| (over the
//!   first reference period) on the other side, so a deformation that touches zero and
//!   bounces back adds none) and
//!   `period_rel_err` against the mode-2 period above; the amplitude decay rate
//!   `damping_rate` \[1/s\] (least-squares fit of `ln |d|` at the extremum of every half
//!   cycle) and `damping_rel_err` against the damping rate above.
//! - square drop, 2D only (side `L`, `σ`, `ρ`): `R = L/√π`; `dp_rel_err_final`, `dp_rel_err_late`
//!   against `σ/R`; `clusters_max` (largest number of separate bodies over the run, from
//!   the `drop_shape` probe) and `r_max_over_r_final` (largest distance from the centroid
//!   over R; 1.25 for the square, → 1 for a circle); `period` / `period_rel_err` of
//!   `a_extent` (the x half-extent) against mode 4, `ω² = 60 σ/(ρR³)`, from the mean spacing
//!   of its crossings of its own mean over the second half of the run. A 3D scene is an
//!   error.

use super::{Measured, nan_max, sticky_max};
use meniscus::ProbeRecord;
use meniscus_reference::ReferenceError;
use meniscus_reference::capillarity::{self, Dimension};

/// Which capillarity case, with its parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Capillary {
    /// A drop at rest: radius \[m\], σ \[N/m\].
    Static {
        /// R \[m\].
        radius: f64,
        /// σ \[N/m\].
        sigma: f64,
    },
    /// Mode-2 oscillation: radius \[m\], σ \[N/m\], ρ \[kg/m³\], ν \[m²/s\].
    Oscillating {
        /// R \[m\].
        radius: f64,
        /// σ \[N/m\].
        sigma: f64,
        /// ρ \[kg/m³\].
        density: f64,
        /// ν \[m²/s\] (from the scene).
        nu: f64,
    },
    /// Square relaxing to a circle: side \[m\], σ \[N/m\], ρ \[kg/m³\].
    Square {
        /// L \[m\].
        side: f64,
        /// σ \[N/m\].
        sigma: f64,
        /// ρ \[kg/m³\].
        density: f64,
    },
}

/// Times of the sign changes of `v − level` (linear interpolation between samples).
pub fn crossings(t: &[f64], v: &[f64], level: f64) -> Vec<f64> {
    let mut out = Vec::new();
    for i in 1..t.len().min(v.len()) {
        let (a, b) = (v[i - 1] - level, v[i] - level);
        if a != 0.0 && a.signum() != b.signum() && b != 0.0 || (b == 0.0 && a != 0.0) {
            out.push(t[i - 1] + (t[i] - t[i - 1]) * a / (a - b));
        }
    }
    out
}

/// Times at which `v − level` changes side between two excursions beyond `±band`: a
/// crossing is counted only once the signal has gone further than `band` on the other side
/// (hysteresis), so that noise which touches `level` and bounces back, or dithers about it,
/// adds no crossing. Each time is the last sign change (linear interpolation) before the
/// excursion; with `band = 0` this is [`crossings`].
pub fn crossings_with_hysteresis(t: &[f64], v: &[f64], level: f64, band: f64) -> Vec<f64> {
    let mut out = Vec::new();
    let (mut side, mut last_change) = (0_i8, None);
    for i in 0..t.len().min(v.len()) {
        let b = v[i] - level;
        if i > 0 {
            let a = v[i - 1] - level;
            if a != 0.0 && a.signum() != b.signum() && b != 0.0 || (b == 0.0 && a != 0.0) {
                last_change = Some(t[i - 1] + (t[i] - t[i - 1]) * a / (a - b));
            }
        }
        let here: i8 = if b > band {
            1
        } else if b < -band {
            -1
        } else {
            0
        };
        if here != 0 && here != side {
            if side != 0
                && let Some(c) = last_change
            {
                out.push(c);
            }
            side = here;
        }
    }
    out
}

/// Period `2 × mean spacing` of successive crossings (NaN with fewer than two).
pub fn period_from_crossings(c: &[f64]) -> f64 {
    if c.len() < 2 { f64::NAN } else { 2.0 * (c[c.len() - 1] - c[0]) / (c.len() - 1) as f64 }
}

/// The hysteresis band of the deformation's zero crossings as a fraction of its largest
/// magnitude over the first reference period.
pub const HYSTERESIS: f64 = 0.2;

/// Mean of the samples with `t ≥ from`.
fn mean_after(t: &[f64], v: &[f64], from: f64) -> f64 {
    let (s, n) =
        t.iter().zip(v).filter(|(x, _)| **x >= from).fold((0.0, 0usize), |(s, n), (_, y)| (s + y, n + 1));
    if n == 0 { f64::NAN } else { s / n as f64 }
}

/// Least-squares slope of `y` against `x` (NaN with fewer than two points).
fn slope(x: &[f64], y: &[f64]) -> f64 {
    let n = x.len().min(y.len());
    if n < 2 {
        return f64::NAN;
    }
    let (mx, my) = (x.iter().sum::<f64>() / n as f64, y.iter().sum::<f64>() / n as f64);
    let sxy: f64 = x.iter().zip(y).map(|(a, b)| (a - mx) * (b - my)).sum();
    let sxx: f64 = x.iter().map(|a| (a - mx) * (a - mx)).sum();
    sxy / sxx
}

/// The dimension of a run: its scene's `dimension`, 2 ([`Dimension::Two`]) or 3
/// ([`Dimension::Three`]); 2 when the scene has none. Any other value is an error.
pub fn dimension(scene: &serde_json::Value) -> Result<Dimension, ReferenceError> {
    match &scene["dimension"] {
        serde_json::Value::Null => Ok(Dimension::Two),
        v => match v.as_u64() {
            Some(2) => Ok(Dimension::Two),
            Some(3) => Ok(Dimension::Three),
            _ => Err(ReferenceError::InvalidParameter {
                name: "dimension",
                value: v.as_f64().unwrap_or(f64::NAN),
                rule: "the scene's dimension must be 2 or 3",
            }),
        },
    }
}

/// Computes the metrics and series of one run of a drop in `dim` (the module docs give the
/// probe and the reference formula read in each dimension). The square drop is 2D only: in
/// 3D it is an error.
pub fn compute(dim: Dimension, case: &Capillary, probes: &ProbeRecord) -> Result<Measured, ReferenceError> {
    if dim == Dimension::Three && matches!(case, Capillary::Square { .. }) {
        return Err(ReferenceError::InvalidParameter {
            name: "dimension",
            value: 3.0,
            rule: "the square drop's metrics are 2D only",
        });
    }
    let mut out = Measured::default();
    let t = &probes.t;
    if t.is_empty() {
        return Ok(out);
    }
    let t_end = t[t.len() - 1];
    let late = 0.75 * t_end;
    let m = &mut out.metrics;
    m.insert("t_final".into(), t_end);
    out.series.insert("t".into(), t.clone());
    // The inside pressure: `mean_pressure` when recorded, else `pressure_at`.
    let inside = probes.get("mean_pressure", "p").or_else(|| probes.get("pressure_at", "p"));
    let mut pressure = |dp: f64, m: &mut std::collections::BTreeMap<String, f64>| {
        if let Some(p) = inside {
            m.insert("dp_rel_err_final".into(), ((p[p.len() - 1] - dp) / dp).abs());
            m.insert("dp_rel_err_late".into(), ((mean_after(t, p, late) - dp) / dp).abs());
            m.insert("dp_late".into(), mean_after(t, p, late));
            out.series.insert("p".into(), p.to_vec());
            out.series.insert("dp_ref".into(), vec![dp; t.len()]);
        }
    };
    match *case {
        Capillary::Static { radius, sigma } => {
            pressure(capillarity::laplace_pressure(dim, sigma, radius)?, m);
            if let Some(u) = probes.get("max_speed", "u_max") {
                m.insert("u_spurious_max_final".into(), u[u.len() - 1]);
                m.insert("u_spurious_max_late".into(), mean_after(t, u, late));
                out.series.insert("u_max".into(), u.to_vec());
            }
            if let Some(u) = probes.get("max_speed", "u_rms") {
                m.insert("u_spurious_rms_late".into(), mean_after(t, u, late));
            }
        }
        Capillary::Oscillating { radius, sigma, density, nu } => {
            let period_ref = capillarity::oscillation_period(dim, 2, sigma, density, radius)?;
            m.insert("period_ref".into(), period_ref);
            // The mode-2 deformation: x against y in 2D, x against the symmetry axis z in 3D.
            let (a, b) = match dim {
                Dimension::Two => {
                    (probes.get("ellipse_axes", "a_moment"), probes.get("ellipse_axes", "b_moment"))
                }
                Dimension::Three => {
                    (probes.get("ellipsoid_axes", "a_moment"), probes.get("ellipsoid_axes", "c_moment"))
                }
            };
            if let (Some(a), Some(b)) = (a, b) {
                let d: Vec<f64> = a.iter().zip(b).map(|(a, b)| a - b).collect();
                // Crossings of zero between excursions beyond a fifth of the deformation's
                // scale: its largest |d| over the first reference period (the imposed
                // deformation, before surface particles that may leave later bias the
                // moments).
                let scale = t
                    .iter()
                    .zip(&d)
                    .filter(|(x, _)| **x <= t[0] + period_ref)
                    .fold(0.0_f64, |m, (_, y)| sticky_max(m, y.abs()));
                let band = HYSTERESIS * scale;
                let c = crossings_with_hysteresis(t, &d, 0.0, band);
                let period = period_from_crossings(&c);
                m.insert("period_crossings".into(), c.len() as f64);
                m.insert("period".into(), period);
                m.insert("period_rel_err".into(), ((period - period_ref) / period_ref).abs());
                // Extremum of |d| in every complete half cycle.
                let (mut tp, mut lp) = (Vec::new(), Vec::new());
                for w in c.windows(2) {
                    let best = t
                        .iter()
                        .zip(&d)
                        .filter(|(x, _)| **x > w[0] && **x < w[1])
                        .max_by(|p, q| p.1.abs().total_cmp(&q.1.abs()));
                    if let Some((x, y)) = best
                        && y.abs() > 0.0
                    {
                        tp.push(*x);
                        lp.push(y.abs().ln());
                    }
                }
                let beta = -slope(&tp, &lp);
                m.insert("damping_rate".into(), beta);
                if nu > 0.0 {
                    let beta_ref = capillarity::damping_rate(dim, 2, nu, radius)?;
                    m.insert("damping_ref".into(), beta_ref);
                    m.insert("damping_rel_err".into(), ((beta - beta_ref) / beta_ref).abs());
                }
                out.series.insert("deformation".into(), d);
            }
        }
        Capillary::Square { side, sigma, density } => {
            let r = capillarity::equivalent_radius_of_square(Dimension::Two, side)?;
            pressure(capillarity::laplace_pressure(Dimension::Two, sigma, r)?, m);
            if let Some(c) = probes.get("drop_shape", "clusters") {
                m.insert("clusters_max".into(), nan_max(c));
                out.series.insert("clusters".into(), c.to_vec());
            }
            if let Some(rm) = probes.get("drop_shape", "r_max") {
                m.insert("r_max_over_r_final".into(), rm[rm.len() - 1] / r);
                out.series.insert("r_max_over_r".into(), rm.iter().map(|x| x / r).collect());
            }
            let period_ref = capillarity::oscillation_period(Dimension::Two, 4, sigma, density, r)?;
            m.insert("period_ref".into(), period_ref);
            if let Some(a) = probes.get("ellipse_axes", "a_extent") {
                let level = mean_after(t, a, 0.5 * t_end);
                let period = period_from_crossings(&crossings(t, a, level));
                m.insert("period".into(), period);
                m.insert("period_rel_err".into(), ((period - period_ref) / period_ref).abs());
                out.series.insert("a_extent".into(), a.to_vec());
            }
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn record(t: &[f64], series: &[(&str, &str, Vec<f64>)]) -> ProbeRecord {
        let mut r = ProbeRecord { t: t.to_vec(), ..Default::default() };
        for (k, q, v) in series {
            r.series.entry(k.to_string()).or_default().insert(q.to_string(), v.clone());
        }
        r
    }

    #[test]
    fn period_and_damping_of_a_synthetic_oscillation() {
        // d = 0.01 e^{−βt} cos(ωt + φ) with the mode-2 frequency of R = 0.2, σ = ρ = 1.
        let (radius, sigma, density, nu) = (0.2, 1.0, 1.0, 5e-3);
        let tp = capillarity::oscillation_period(Dimension::Two, 2, sigma, density, radius).unwrap();
        let w = 2.0 * std::f64::consts::PI / tp;
        let beta = 4.0 * nu / (radius * radius);
        let t: Vec<f64> = (0..4000).map(|i| i as f64 * 2e-4).collect();
        let d: Vec<f64> = t.iter().map(|x| 0.01 * (-beta * x).exp() * (w * x + 0.3).sin()).collect();
        let a: Vec<f64> = d.iter().map(|x| 0.2 + x / 2.0).collect();
        let b: Vec<f64> = d.iter().map(|x| 0.2 - x / 2.0).collect();
        let r = record(&t, &[("ellipse_axes", "a_moment", a), ("ellipse_axes", "b_moment", b)]);
        let m = compute(Dimension::Two, &Capillary::Oscillating { radius, sigma, density, nu }, &r)
            .unwrap()
            .metrics;
        assert!(m["period_rel_err"] < 1e-3, "{m:?}");
        assert!(m["damping_rel_err"] < 0.05, "{m:?}");
        // A 10 % slower oscillation is measured as such.
        let d2: Vec<f64> = t.iter().map(|x| (w / 1.1 * x + 0.3).sin()).collect();
        let r2 = record(
            &t,
            &[("ellipse_axes", "a_moment", d2.clone()), ("ellipse_axes", "b_moment", vec![0.0; 4000])],
        );
        let m2 = compute(Dimension::Two, &Capillary::Oscillating { radius, sigma, density, nu }, &r2)
            .unwrap()
            .metrics;
        assert!((m2["period_rel_err"] - 0.1).abs() < 2e-3, "{m2:?}");
    }

    #[test]
    fn hysteresis_ignores_bounces_and_dither_at_zero() {
        let t: Vec<f64> = (0..2000).map(|i| i as f64 * 5e-4).collect();
        // A deformation that comes down to zero, dips to −1 % of its amplitude and goes back
        // (a bounce, not a half cycle), twice over the second: four plain crossings, none
        // with hysteresis.
        let bounce: Vec<f64> = t.iter().map(|x| 0.0101 * (1.0 + (10.0 * x).cos()) / 2.0 - 1e-4).collect();
        assert_eq!(crossings(&t, &bounce, 0.0).len(), 4);
        assert!(crossings_with_hysteresis(&t, &bounce, 0.0, 0.2 * 0.01).is_empty());
        // A 0.25 s oscillation with particle-scale dither of 5 % of its amplitude at a
        // frequency 37 times higher: the dither crosses zero several times at every node.
        let w = 2.0 * std::f64::consts::PI / 0.25;
        let d: Vec<f64> =
            t.iter().map(|x| 0.01 * (w * x).sin() + 5e-4 * (37.0 * w * x + 1.0).sin()).collect();
        let plain = crossings(&t, &d, 0.0);
        let c = crossings_with_hysteresis(&t, &d, 0.0, 0.2 * 0.01);
        assert_eq!(c.len(), 7, "{c:?}");
        assert!(plain.len() > c.len(), "{plain:?}");
        let p = period_from_crossings(&c);
        assert!((p / 0.25 - 1.0).abs() < 0.01, "{p}");
        // Without noise, hysteresis and plain crossings agree.
        let clean: Vec<f64> = t.iter().map(|x| (w * x + 0.3).sin()).collect();
        assert_eq!(crossings(&t, &clean, 0.0), crossings_with_hysteresis(&t, &clean, 0.0, 0.2));
    }

    #[test]
    fn static_drop_pressure_jump() {
        let t: Vec<f64> = (0..=100).map(|i| i as f64 * 0.01).collect();
        let p: Vec<f64> = t.iter().map(|x| if *x < 0.75 { 0.0 } else { 5.25 }).collect();
        let u = vec![1e-3; t.len()];
        let r = record(&t, &[("pressure_at", "p", p), ("max_speed", "u_max", u)]);
        let m = compute(Dimension::Two, &Capillary::Static { radius: 0.2, sigma: 1.0 }, &r).unwrap().metrics;
        assert!((m["dp_rel_err_late"] - 0.05).abs() < 1e-12, "{m:?}");
        assert!((m["u_spurious_max_late"] - 1e-3).abs() < 1e-15);
    }

    #[test]
    fn static_3d_drop_reads_mean_pressure_against_two_sigma_over_r() {
        let (radius, sigma) = (0.2, 1.0);
        let jump = 2.0 * sigma / radius;
        let t: Vec<f64> = (0..=100).map(|i| i as f64 * 0.01).collect();
        let case = Capillary::Static { radius, sigma };
        // At 2σ/R: no error, whatever a `pressure_at` probe beside it says.
        let r = record(
            &t,
            &[
                ("mean_pressure", "p", vec![jump; t.len()]),
                ("pressure_at", "p", vec![0.5 * jump; t.len()]),
                ("max_speed", "u_max", vec![2e-3; t.len()]),
                ("max_speed", "u_rms", vec![5e-4; t.len()]),
            ],
        );
        let m = compute(Dimension::Three, &case, &r).unwrap().metrics;
        assert!(m["dp_rel_err_late"].abs() < 1e-12 && m["dp_rel_err_final"].abs() < 1e-12, "{m:?}");
        assert!((m["dp_late"] - jump).abs() < 1e-12, "{m:?}");
        assert!(
            (m["u_spurious_max_late"] - 2e-3).abs() < 1e-15
                && (m["u_spurious_rms_late"] - 5e-4).abs() < 1e-15
        );
        // 5 % above 2σ/R: a 5 % error (in 2D the same series would be 110 % off σ/R).
        let r = record(&t, &[("mean_pressure", "p", vec![1.05 * jump; t.len()])]);
        let m = compute(Dimension::Three, &case, &r).unwrap().metrics;
        assert!((m["dp_rel_err_late"] - 0.05).abs() < 1e-12 && (m["dp_rel_err_final"] - 0.05).abs() < 1e-12);
        let m2 = compute(Dimension::Two, &case, &r).unwrap().metrics;
        assert!((m2["dp_rel_err_late"] - 1.1).abs() < 1e-12, "{m2:?}");
        // With only `pressure_at`, the 3D drop reads it.
        let r = record(&t, &[("pressure_at", "p", vec![0.95 * jump; t.len()])]);
        let m = compute(Dimension::Three, &case, &r).unwrap().metrics;
        assert!((m["dp_rel_err_late"] - 0.05).abs() < 1e-12, "{m:?}");
    }

    #[test]
    fn static_2d_drop_with_both_pressure_probes_reads_mean_pressure() {
        let t: Vec<f64> = (0..=100).map(|i| i as f64 * 0.01).collect();
        // σ/R = 5: `mean_pressure` is exact, `pressure_at` 20 % off; the first wins.
        let r = record(
            &t,
            &[("pressure_at", "p", vec![6.0; t.len()]), ("mean_pressure", "p", vec![5.0; t.len()])],
        );
        let case = Capillary::Static { radius: 0.2, sigma: 1.0 };
        let m = compute(Dimension::Two, &case, &r).unwrap();
        assert!(m.metrics["dp_rel_err_late"].abs() < 1e-12, "{:?}", m.metrics);
        assert_eq!(m.series["p"], vec![5.0; t.len()]);
    }

    #[test]
    fn period_and_damping_of_a_synthetic_3d_oscillation() {
        // d = A e^{−5νt/R²} cos(2πt/T₃), T₃ = 2π √(ρR³/(8σ)), R = 0.2, σ = ρ = 1, spread as an
        // axisymmetric ellipsoid: a = b = R + d/3, c = R − 2d/3 (a − c = d).
        let (radius, sigma, density, nu): (f64, f64, f64, f64) = (0.2, 1.0, 1.0, 5e-3);
        let t3 = 2.0 * std::f64::consts::PI * (density * radius.powi(3) / (8.0 * sigma)).sqrt();
        let beta = 5.0 * nu / (radius * radius);
        let t: Vec<f64> = (0..4000).map(|i| i as f64 * 2e-4).collect();
        let d: Vec<f64> = t
            .iter()
            .map(|x| 0.01 * (-beta * x).exp() * (2.0 * std::f64::consts::PI * x / t3).cos())
            .collect();
        let a: Vec<f64> = d.iter().map(|x| radius + x / 3.0).collect();
        let c: Vec<f64> = d.iter().map(|x| radius - 2.0 * x / 3.0).collect();
        let r = record(
            &t,
            &[
                ("ellipsoid_axes", "a_moment", a.clone()),
                ("ellipsoid_axes", "b_moment", a),
                ("ellipsoid_axes", "c_moment", c),
            ],
        );
        let case = Capillary::Oscillating { radius, sigma, density, nu };
        let out = compute(Dimension::Three, &case, &r).unwrap();
        let m = &out.metrics;
        assert!((m["period_ref"] / t3 - 1.0).abs() < 1e-12, "{m:?}");
        assert!(m["period_rel_err"] < 1e-3, "{m:?}");
        assert!((m["damping_ref"] / beta - 1.0).abs() < 1e-12, "{m:?}");
        assert!(m["damping_rel_err"] < 0.05, "{m:?}");
        assert!((m["damping_rate"] / beta - 1.0).abs() < 0.05, "{m:?}");
        let dd = &out.series["deformation"];
        assert!(dd.iter().zip(&d).all(|(x, y)| (x - y).abs() < 1e-12));
        // The 3D drop reads `ellipsoid_axes` only: a 2D `ellipse_axes` record gives no period.
        let r2 = record(
            &t,
            &[("ellipse_axes", "a_moment", d.clone()), ("ellipse_axes", "b_moment", vec![0.0; 4000])],
        );
        let m2 = compute(Dimension::Three, &case, &r2).unwrap().metrics;
        assert!(!m2.contains_key("period") && !m2.contains_key("damping_rel_err"), "{m2:?}");
        // The same signal judged as 2D is off by the ratio of the periods, √(8/6) − 1.
        let m3 = compute(Dimension::Two, &case, &r2).unwrap().metrics;
        let t2 = t3 * (8.0_f64 / 6.0).sqrt();
        assert!((m3["period_rel_err"] - (1.0 - t3 / t2)).abs() < 2e-3, "{m3:?}");
    }

    #[test]
    fn dimension_from_the_scene() {
        use serde_json::json;
        assert_eq!(dimension(&json!({})).unwrap(), Dimension::Two);
        assert_eq!(dimension(&json!({ "dimension": 2 })).unwrap(), Dimension::Two);
        assert_eq!(dimension(&json!({ "dimension": 3 })).unwrap(), Dimension::Three);
        for bad in [json!(1), json!(4), json!(2.5), json!("3")] {
            assert!(dimension(&json!({ "dimension": bad })).is_err(), "{bad}");
        }
        // The square drop has no 3D metrics.
        let r = record(&[0.0, 1.0], &[]);
        let square = Capillary::Square { side: 0.2, sigma: 1.0, density: 1.0 };
        assert!(compute(Dimension::Three, &square, &r).is_err());
        assert!(compute(Dimension::Two, &square, &r).is_ok());
    }
}
