//! Metrics of a drop impact (`droplet_impact`, Xu 2016 §3.2–3.3) from the run's `spread`
//! probe against `meniscus_reference::impact`: the spread factor `β = d/D` of the wetted
//! diameter against `T = tV/D` (t = 0 at first contact), its early growth against `√(6T)`
//! and its maximum against the published correlations.

use super::{Measured, nan_max};
use meniscus::ProbeRecord;
use meniscus_reference::ReferenceError;
use meniscus_reference::impact::{Impact, beta_max_band, early_spread};

/// The early-spreading window `[T_0, T_1]` of `T = tV/D` (issue #36: `0.05 ≤ T ≤ 0.2`;
/// CASES.md gives `T < 0.2`): after the first rows of particles have touched, before the
/// lamella's growth slows.
pub const EARLY: [f64; 2] = [0.05, 0.2];

/// The early reference `√(6T)` is drawn up to this `T` (beyond it the law does not hold).
const EARLY_DRAWN_TO: f64 = 0.5;

/// The impact: drop diameter D \[m\], speed V \[m/s\], and the liquid's ρ \[kg/m³\],
/// μ \[Pa·s\], σ \[N/m\] (from the run's scene).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Params {
    /// D \[m\].
    pub diameter: f64,
    /// V \[m/s\].
    pub speed: f64,
    /// ρ \[kg/m³\].
    pub density: f64,
    /// μ \[Pa·s\].
    pub viscosity: f64,
    /// σ \[N/m\].
    pub sigma: f64,
}

impl Params {
    /// The impact of a drop of `diameter` at `speed` in the liquid of `scene`'s `fluid`.
    pub fn new(diameter: f64, speed: f64, scene: &serde_json::Value) -> Self {
        let num = |k: &str| super::fluid_property(scene, k);
        Self {
            diameter,
            speed,
            density: num("density"),
            viscosity: num("viscosity"),
            sigma: num("surface_tension"),
        }
    }
}

/// Series `t_star` (T), `beta` (wetted diameter / D), `width_over_d` (spread width / D),
/// `height_over_d` and `beta_early` (√(6T) up to T = 0.5, NaN after); metrics
/// `spread_early_rel_err_max` (largest |β/√(6T) − 1| over [`EARLY`]), `beta_max` and the
/// `t_star_beta_max` it is reached at, `width_max_over_d`, `clusters_max` (the most separate
/// bodies of the `drop_shape` probe over the run: a lamella that tore, or two drops before
/// they merge), the correlations' band `beta_max_ref_lo` / `beta_max_ref_hi`, `we` and `re`.
pub fn compute(p: &Params, probes: &ProbeRecord) -> Result<Measured, ReferenceError> {
    let impact = Impact::new(p.diameter, p.speed, p.density, p.viscosity, p.sigma)?;
    let t = &probes.t;
    let get =
        |q: &str| probes.get("spread", q).map(<[f64]>::to_vec).unwrap_or_else(|| vec![f64::NAN; t.len()]);
    let over_d = |v: Vec<f64>| v.into_iter().map(|x| x / p.diameter).collect::<Vec<f64>>();
    let t_star: Vec<f64> = t.iter().map(|t| t * p.speed / p.diameter).collect();
    let beta = over_d(get("diameter"));
    let width = over_d(get("width"));
    let mut early_err = Vec::new();
    let mut beta_early = Vec::with_capacity(t.len());
    for (&ts, &b) in t_star.iter().zip(&beta) {
        let reference = if ts <= EARLY_DRAWN_TO { early_spread(ts.max(0.0))? } else { f64::NAN };
        beta_early.push(reference);
        if (EARLY[0]..=EARLY[1]).contains(&ts) {
            early_err.push((b / reference - 1.0).abs());
        }
    }
    let (mut beta_max, mut at) = (f64::NAN, f64::NAN);
    for (&ts, &b) in t_star.iter().zip(&beta) {
        if b.is_nan() {
            (beta_max, at) = (f64::NAN, f64::NAN);
            break;
        }
        if beta_max.is_nan() || b > beta_max {
            (beta_max, at) = (b, ts);
        }
    }
    let (lo, hi) = beta_max_band(&impact);
    let mut m = Measured::default();
    m.metrics.insert("spread_early_rel_err_max".into(), nan_max(&early_err));
    m.metrics.insert("beta_max".into(), beta_max);
    m.metrics.insert("t_star_beta_max".into(), at);
    m.metrics.insert("width_max_over_d".into(), nan_max(&width));
    let clusters = probes.get("drop_shape", "clusters").map_or(f64::NAN, nan_max);
    m.metrics.insert("clusters_max".into(), clusters);
    m.metrics.insert("beta_max_ref_lo".into(), lo);
    m.metrics.insert("beta_max_ref_hi".into(), hi);
    m.metrics.insert("we".into(), impact.we);
    m.metrics.insert("re".into(), impact.re);
    m.series.insert("t".into(), t.clone());
    m.series.insert("t_star".into(), t_star);
    m.series.insert("beta".into(), beta);
    m.series.insert("width_over_d".into(), width);
    m.series.insert("height_over_d".into(), over_d(get("height")));
    m.series.insert("beta_early".into(), beta_early);
    Ok(m)
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    fn params() -> Params {
        let scene = json!({ "fluid": { "density": 1000.0, "viscosity": 1e-3, "surface_tension": 0.0728 } });
        Params::new(5e-4, 2.7, &scene)
    }

    /// A synthetic run that spreads 5 % faster than √(6T), peaks at β = 2.6 and recedes:
    /// the early error is 5 %, the maximum and its time are read back.
    #[test]
    fn early_error_and_maximum_of_a_synthetic_spread() {
        let p = params();
        let t_of = |ts: f64| ts * p.diameter / p.speed;
        let ts: Vec<f64> = (0..=300).map(|i| i as f64 * 0.01).collect();
        let beta = |x: f64| if x < 0.3 { 1.05 * (6.0 * x).sqrt() } else { 2.6 - (x - 2.0).powi(2) * 0.1 };
        let mut probes = ProbeRecord { t: ts.iter().map(|&x| t_of(x)).collect(), ..Default::default() };
        let s = probes.series.entry("spread".into()).or_default();
        s.insert("diameter".into(), ts.iter().map(|&x| beta(x) * p.diameter).collect());
        s.insert("width".into(), ts.iter().map(|&x| beta(x).max(1.0) * p.diameter).collect());
        s.insert("height".into(), vec![p.diameter; ts.len()]);
        let mut pieces = vec![1.0; ts.len()];
        pieces[200] = 3.0;
        probes.series.entry("drop_shape".into()).or_default().insert("clusters".into(), pieces);
        let m = compute(&p, &probes).unwrap();
        assert!((m.metrics["spread_early_rel_err_max"] - 0.05).abs() < 1e-9);
        assert!(
            (m.metrics["beta_max"] - 2.6).abs() < 1e-9 && (m.metrics["t_star_beta_max"] - 2.0).abs() < 1e-9
        );
        assert!((m.metrics["clusters_max"] - 3.0).abs() < 1e-12);
        assert!(m.metrics["beta_max_ref_lo"] < 2.4 && m.metrics["beta_max_ref_hi"] > 2.98);
        assert!(
            m.series["beta_early"][60].is_nan() && (m.series["beta_early"][10] - 0.6f64.sqrt()).abs() < 1e-12
        );
        // A NaN sample (a diverged step) makes the maximum NaN, never a smaller number.
        probes.series.get_mut("spread").unwrap().get_mut("diameter").unwrap()[250] = f64::NAN;
        assert!(compute(&p, &probes).unwrap().metrics["beta_max"].is_nan());
        probes.series.get_mut("drop_shape").unwrap().get_mut("clusters").unwrap()[5] = f64::NAN;
        assert!(compute(&p, &probes).unwrap().metrics["clusters_max"].is_nan());
    }

    #[test]
    fn missing_probe_and_bad_fluid() {
        let p = params();
        let probes = ProbeRecord { t: vec![0.0, 1e-5], ..Default::default() };
        let m = compute(&p, &probes).unwrap();
        assert!(m.metrics["beta_max"].is_nan() && m.metrics["clusters_max"].is_nan());
        let no_sigma = Params::new(5e-4, 2.7, &json!({ "fluid": { "density": 1000.0, "viscosity": 1e-3 } }));
        assert!(compute(&no_sigma, &probes).is_err());
    }
}
