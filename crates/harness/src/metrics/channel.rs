//! Metrics of the inflow/outflow channel (CASES.md "poiseuille_channel", Lan et al. 2022)
//! against the laminar entrance flow of `meniscus_reference::entrance_flow` (Bodoia &
//! Osterle 1961) and the fully developed parabola `u = 6 U (y/D)(1 − y/D)`.
//!
//! Probes read (in this order in the scene): `velocity_profile` along the flow axis in a
//! thin slab about the centre line (the centre-line velocity against x), `velocity_profile_1`
//! across the channel in a thin slab about the station `x_s` (the profile there), and
//! `mass_balance`.
//!
//! The flow is steady once it has developed, but a particle sample is noisy, so both
//! profiles are averaged over the samples of the last [`AVERAGE_FRACTION`] of the run
//! (bin by bin: positions and velocities). With `U` the inflow speed:
//!
//! - `u_center_station` (m/s), `u_center_ref_station` (the entrance flow at `x_s`),
//!   `u_center_rel_err_station` = |measured − entrance flow| / entrance flow, and
//!   `u_center_rel_err_developed` = |measured − 1.5 U| / 1.5 U (the paper's error measure);
//!   the centre line is interpolated linearly between the bins' mean positions;
//! - `u_max_station`: the fastest bin of the cross profile (the paper's `u_max`);
//! - `u_profile_l2_rel_station`: relative L2 error of the cross profile against the
//!   parabola (meaningful where the flow is developed), `u_profile_l2_rel_station_ref`
//!   against the entrance-flow profile at `x_s`;
//! - `development_length_over_d`: the first bin position (from the inlet, over D) where
//!   the averaged centre-line velocity reaches 99 % of 1.5 U (NaN if it never does), beside
//!   `development_length_ref_over_d` (boundary-layer model) and
//!   `development_length_durst_over_d` (Durst et al. 2005);
//! - `mass_balance_rel_err`: over the second half of the run, |Δm_out − Δm_in| / Δm_in (a
//!   steady channel lets out what comes in), and `mass_drift`: the largest relative change
//!   of the fluid mass in the channel;
//! - `ut_over_d_final`: how far the run got, `U t / D`.
//!
//! Series: `t` with `u_center_station_t` (the instantaneous centre-line velocity at `x_s`,
//! to judge steadiness) and `u_center_ref_station_t`; spatial series (not aligned with `t`)
//! `x_over_d`, `u_center_over_u`, `u_center_ref_over_u` along the channel and `y_over_d`,
//! `u_station_over_u`, `u_station_parabola_over_u`, `u_station_ref_over_u` across it.

use super::Measured;
use meniscus::ProbeRecord;
use meniscus_reference::ReferenceError;
use meniscus_reference::entrance_flow::EntranceFlow;
use meniscus_reference::entrance_length::channel_durst;

/// Fraction of the run (at its end) over which the profiles are averaged.
pub const AVERAGE_FRACTION: f64 = 0.2;

/// The channel of a run: the case's geometry with the run scene's inflow and fluid.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Channel {
    /// Entrance-flow reference (width D, inflow U, ν).
    pub flow: EntranceFlow,
    /// Position of the lower wall \[m\].
    pub wall: f64,
    /// Position of the inlet plane \[m\].
    pub inlet: f64,
    /// Station, as a distance from the inlet \[m\].
    pub station: f64,
}

impl Channel {
    /// The channel of width `width` with its lower wall at `wall`; U, the inlet position
    /// and ν from the run's `scene`, and the station from the slab of its second
    /// `velocity_profile` probe (the cross profile: the slab's midpoint).
    pub fn new(width: f64, wall: f64, scene: &serde_json::Value) -> Result<Self, ReferenceError> {
        let num = |v: &serde_json::Value| v.as_f64().unwrap_or(f64::NAN);
        let nu = num(&scene["fluid"]["viscosity"]) / num(&scene["fluid"]["density"]);
        let inflow = &scene["boundaries"]["inflow"];
        let flow = EntranceFlow::new(width, num(&inflow["velocity"]), nu)?;
        let inlet = num(&inflow["position"]);
        let cross = scene["probes"]
            .as_array()
            .into_iter()
            .flatten()
            .filter_map(|p| p.get("velocity_profile"))
            .nth(1)
            .map(|p| &p["slab"]["range"]);
        let station = cross.map(|r| 0.5 * (num(&r[0]) + num(&r[1])) - inlet).unwrap_or(f64::NAN);
        Ok(Self { flow, wall, inlet, station })
    }
}

/// Bin-by-bin time average of a `velocity_profile` probe over the samples from index
/// `from` on: (mean position, mean velocity) of every bin that was never empty.
fn averaged(probes: &ProbeRecord, key: &str, from: usize) -> Vec<(f64, f64)> {
    let mut out = Vec::new();
    for k in 0.. {
        let (Some(y), Some(u)) =
            (probes.get(key, &format!("y_{k:03}")), probes.get(key, &format!("u_{k:03}")))
        else {
            break;
        };
        let (ys, us) = (&y[from.min(y.len())..], &u[from.min(u.len())..]);
        if ys.is_empty() || ys.iter().any(|v| !v.is_finite()) {
            continue;
        }
        let n = ys.len() as f64;
        out.push((ys.iter().sum::<f64>() / n, us.iter().sum::<f64>() / n));
    }
    out
}

/// Linear interpolation of `(x, v)` points (sorted by x) at `x`; NaN outside.
fn interpolate(points: &[(f64, f64)], x: f64) -> f64 {
    for w in points.windows(2) {
        let ((x0, v0), (x1, v1)) = (w[0], w[1]);
        if x0 <= x && x <= x1 && x1 > x0 {
            return v0 + (v1 - v0) * (x - x0) / (x1 - x0);
        }
    }
    f64::NAN
}

/// Relative L2 error `sqrt(Σ (u − r)² / Σ r²)`; NaN when empty or not finite.
fn l2_rel(pairs: impl Iterator<Item = (f64, f64)>) -> f64 {
    let (mut num, mut den, mut n) = (0.0, 0.0, 0);
    for (u, r) in pairs {
        num += (u - r) * (u - r);
        den += r * r;
        n += 1;
    }
    if n == 0 || den == 0.0 { f64::NAN } else { (num / den).sqrt() }
}

/// Computes the metrics and series listed in the module documentation.
pub fn compute(ch: &Channel, probes: &ProbeRecord) -> Result<Measured, ReferenceError> {
    let mut m = Measured::default();
    let (d, u_in) = (ch.flow.width(), ch.flow.mean_velocity());
    let t = probes.t.clone();
    let t_final = t.last().copied().unwrap_or(f64::NAN);
    let from = t.iter().position(|&s| s >= (1.0 - AVERAGE_FRACTION) * t_final).unwrap_or(t.len());
    let centre = averaged(probes, "velocity_profile", from);
    let station_x = ch.inlet + ch.station;
    let u_c = interpolate(&centre, station_x);
    let u_c_ref = ch.flow.centreline_velocity(ch.station)?;
    let developed = 1.5 * u_in;
    let metrics = &mut m.metrics;
    metrics.insert("u_center_station".into(), u_c);
    metrics.insert("u_center_ref_station".into(), u_c_ref);
    metrics.insert("u_center_rel_err_station".into(), ((u_c - u_c_ref) / u_c_ref).abs());
    metrics.insert("u_center_rel_err_developed".into(), ((u_c - developed) / developed).abs());
    let cross = averaged(probes, "velocity_profile_1", from);
    let u_max = super::nan_max(&cross.iter().map(|&(_, u)| u).collect::<Vec<_>>());
    metrics.insert("u_max_station".into(), u_max);
    metrics.insert("u_max_rel_err_developed".into(), ((u_max - developed) / developed).abs());
    let eta = |y: f64| ((y - ch.wall) / d).clamp(0.0, 1.0);
    let parabola: Vec<f64> = cross.iter().map(|&(y, _)| 6.0 * u_in * eta(y) * (1.0 - eta(y))).collect();
    let ys: Vec<f64> = cross.iter().map(|&(y, _)| eta(y) * d).collect();
    let reference = ch.flow.profile(ch.station, &ys)?;
    metrics.insert(
        "u_profile_l2_rel_station".into(),
        l2_rel(cross.iter().zip(&parabola).map(|(&(_, u), &r)| (u, r))),
    );
    metrics.insert(
        "u_profile_l2_rel_station_ref".into(),
        l2_rel(cross.iter().zip(&reference).map(|(&(_, u), &r)| (u, r))),
    );
    let reached = centre.iter().find(|&&(_, u)| u >= 0.99 * developed).map(|&(x, _)| (x - ch.inlet) / d);
    metrics.insert("development_length_over_d".into(), reached.unwrap_or(f64::NAN));
    metrics.insert("development_length_ref_over_d".into(), ch.flow.development_length(0.99)? / d);
    metrics.insert("development_length_durst_over_d".into(), channel_durst(ch.flow.reynolds())?);
    let get = |q: &str| probes.get("mass_balance", q).map(<[f64]>::to_vec).unwrap_or_default();
    let (mass, inflow, outflow) = (get("mass"), get("inflow"), get("outflow"));
    let half = t.iter().position(|&s| s >= 0.5 * t_final).unwrap_or(0);
    let delta = |v: &[f64]| v.last().zip(v.get(half)).map(|(b, a)| b - a).unwrap_or(f64::NAN);
    let (d_in, d_out) = (delta(&inflow), delta(&outflow));
    metrics.insert("mass_balance_rel_err".into(), ((d_out - d_in) / d_in).abs());
    metrics.insert("mass_drift".into(), super::drift(&mass));
    metrics.insert("ut_over_d_final".into(), u_in * t_final / d);
    // Series.
    let at_station: Vec<f64> = (0..t.len())
        .map(|i| {
            let pts: Vec<(f64, f64)> = (0..)
                .map_while(|k| {
                    let y = probes.get("velocity_profile", &format!("y_{k:03}"))?;
                    let u = probes.get("velocity_profile", &format!("u_{k:03}"))?;
                    Some((y[i], u[i]))
                })
                .filter(|p| p.0.is_finite())
                .collect();
            interpolate(&pts, station_x)
        })
        .collect();
    m.series.insert("u_center_station_t".into(), at_station);
    m.series.insert("u_center_ref_station_t".into(), vec![u_c_ref; t.len()]);
    m.series.insert("t".into(), t);
    let x_over_d: Vec<f64> = centre.iter().map(|&(x, _)| (x - ch.inlet) / d).collect();
    let reference_c = centre
        .iter()
        .map(|&(x, _)| ch.flow.centreline_velocity((x - ch.inlet).max(0.0)))
        .collect::<Result<Vec<_>, _>>()?;
    m.series.insert("u_center_over_u".into(), centre.iter().map(|&(_, u)| u / u_in).collect());
    m.series.insert("u_center_ref_over_u".into(), reference_c.iter().map(|r| r / u_in).collect());
    m.series.insert("x_over_d".into(), x_over_d);
    m.series.insert("y_over_d".into(), ys.iter().map(|y| y / d).collect());
    m.series.insert("u_station_over_u".into(), cross.iter().map(|&(_, u)| u / u_in).collect());
    m.series.insert("u_station_parabola_over_u".into(), parabola.iter().map(|r| r / u_in).collect());
    m.series.insert("u_station_ref_over_u".into(), reference.iter().map(|r| r / u_in).collect());
    Ok(m)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn interpolation_and_norms() {
        let pts = [(0.0, 1.0), (1.0, 3.0), (3.0, 3.0)];
        assert!((interpolate(&pts, 0.5) - 2.0).abs() < 1e-15);
        assert!((interpolate(&pts, 2.0) - 3.0).abs() < 1e-15);
        assert!(interpolate(&pts, 3.5).is_nan());
        assert!((l2_rel([(1.1, 1.0), (2.0, 2.0)].into_iter()) - (0.01f64 / 5.0).sqrt()).abs() < 1e-12);
        assert!(l2_rel(std::iter::empty()).is_nan());
    }

    /// A synthetic developed channel: every metric measures what it claims, and a 3 %
    /// slower centre line gives a 3 % error.
    #[test]
    fn developed_channel_metrics() {
        let scene = serde_json::json!({
            "fluid": {"density": 1000.0, "viscosity": 1e-3},
            "boundaries": {"inflow": {"axis": 0, "position": 0.0, "velocity": 2e-4}},
            "probes": [
                {"velocity_profile": {"axis": 0, "slab": {"axis": 1, "range": [0.09, 0.11]}}},
                {"kinetic_energy": {}},
                {"velocity_profile": {"axis": 1, "slab": {"axis": 0, "range": [1.99, 2.01]}}}
            ]
        });
        let ch = Channel::new(0.2, 0.0, &scene).expect("channel");
        assert!((ch.station - 2.0).abs() < 1e-12);
        let mut probes = ProbeRecord::default();
        let push = |probes: &mut ProbeRecord, kind: &str, q: &str, v: f64| {
            probes.series.entry(kind.into()).or_default().entry(q.into()).or_default().push(v);
        };
        let u = 2e-4;
        for (i, t) in [0.0, 5000.0, 10000.0].into_iter().enumerate() {
            probes.t.push(t);
            for k in 0..30 {
                let x = 0.05 + 0.1 * k as f64;
                push(&mut probes, "velocity_profile", &format!("y_{k:03}"), x);
                push(&mut probes, "velocity_profile", &format!("u_{k:03}"), 0.97 * 1.5 * u);
            }
            for k in 0..20 {
                let y = 0.005 + 0.01 * k as f64;
                let eta = y / 0.2;
                push(&mut probes, "velocity_profile_1", &format!("y_{k:03}"), y);
                push(&mut probes, "velocity_profile_1", &format!("u_{k:03}"), 6.0 * u * eta * (1.0 - eta));
            }
            push(&mut probes, "mass_balance", "mass", 40.0);
            push(&mut probes, "mass_balance", "inflow", 1.0 * i as f64);
            push(&mut probes, "mass_balance", "outflow", 1.01 * i as f64);
        }
        let m = compute(&ch, &probes).expect("metrics").metrics;
        assert!((m["u_center_rel_err_station"] - 0.03).abs() < 1e-3, "{m:?}");
        assert!((m["u_center_rel_err_developed"] - 0.03).abs() < 1e-12);
        assert!(m["u_profile_l2_rel_station"] < 1e-12);
        assert!((m["mass_balance_rel_err"] - 0.01).abs() < 1e-9);
        assert!(m["mass_drift"].abs() < 1e-15);
        assert!(m["development_length_over_d"].is_nan(), "97 % of 1.5 U never reaches 99 %");
        assert!((m["ut_over_d_final"] - 10.0).abs() < 1e-12);
    }
}
