//! Metrics of the periodic Poiseuille channel (CASES.md "poiseuille_periodic") against the
//! start-up series of `meniscus_reference::poiseuille` (Morris, Fox & Zhu 1997).
//!
//! The solver's `velocity_profile` probe gives, per sample time, the mean wall-normal
//! position `y_###` and the mean streamwise velocity `u_###` of the particles in each bin
//! across the channel. Each bin is compared with the series at its own measured mean
//! position, so the comparison carries no interpolation error. With `τ = ν t / D²`:
//!
//! - `u_profile_l2_rel_tNNN` / `u_profile_linf_rel_tNNN`: the profile error at
//!   `τ = NNN / 100` (the scene's `output.probe_times`), relative L2
//!   `sqrt(Σ (u − u_ref)² / Σ u_ref²)` over the bins and Linf `max |u − u_ref| / max |u_ref|`;
//! - `u_profile_l2_rel_startup_max`: the largest L2 error over the samples with `τ < 1`;
//! - `u_profile_l2_rel_steady`, `u_profile_linf_rel_steady`, `u_center_rel_err_steady` (the
//!   fastest bin against the reference at its position, over `u_max = F D² / 8ν`): at `τ = 1`
//!   (where the transient is `e^{−π²} ≈ 5e-5` of `u_max`, below every error reported), or
//!   at the sample where the steady-state stop (`time.steady`) ended the run before it,
//!   against the series at that time (which holds what is left of the transient), with
//!   `tau_steady` its `τ`;
//! - `u_profile_drift`: for runs past `τ = 1`, the largest `‖u(t) − u(τ=1)‖₂ / ‖u_ref‖₂` after
//!   it (a stable steady state does not drift);
//! - `tau_final`: how far the run got.
//!
//! Series: `t`, `tau`, `u_center` (the largest bin velocity), `u_center_ref` and
//! `u_profile_l2_rel` at every sample.
//!
//! Parameters: the channel (`width`, `wall` = lower wall position) from the case; `ν = μ/ρ`
//! and `F` = the x component of the body force from each run's scene, so presets may change
//! the Reynolds number.

use super::{Measured, sticky_max};
use meniscus::ProbeRecord;
use meniscus_reference::ReferenceError;
use meniscus_reference::poiseuille::PlanePoiseuille;

/// The probe read.
const PROFILE: &str = "velocity_profile";

/// Dimensionless sample times `τ = ν t / D²` of the named start-up metrics.
pub const TAUS: [f64; 5] = [0.05, 0.1, 0.2, 0.5, 1.0];

/// Relative tolerance on `τ` when matching a sample to a named time.
const TAU_MATCH: f64 = 1e-6;

/// The channel of a run: the case's geometry with the run scene's fluid and force.
pub fn channel(width: f64, scene: &serde_json::Value) -> Result<PlanePoiseuille, ReferenceError> {
    let num = |v: &serde_json::Value| v.as_f64().unwrap_or(f64::NAN);
    let nu = num(&scene["fluid"]["viscosity"]) / num(&scene["fluid"]["density"]);
    PlanePoiseuille::new(width, num(&scene["body_force"][0]), nu)
}

/// One sampled profile: the bins' mean positions and velocities (empty bins dropped).
fn profile(probes: &ProbeRecord, i: usize) -> Vec<(f64, f64)> {
    let mut out = Vec::new();
    for k in 0.. {
        let (Some(y), Some(u)) =
            (probes.get(PROFILE, &format!("y_{k:03}")), probes.get(PROFILE, &format!("u_{k:03}")))
        else {
            break;
        };
        if let (Some(&y), Some(&u)) = (y.get(i), u.get(i))
            && y.is_finite()
        {
            out.push((y, u));
        }
    }
    out
}

/// L2 and Linf relative errors of a profile against `u_ref(y)`; NaN for a non-finite
/// velocity (never skipped) or an empty profile.
fn errors(
    prof: &[(f64, f64)],
    u_ref: impl Fn(f64) -> Result<f64, ReferenceError>,
) -> Result<(f64, f64), ReferenceError> {
    if prof.is_empty() {
        return Ok((f64::NAN, f64::NAN));
    }
    let (mut num, mut den, mut emax, mut rmax) = (0.0, 0.0, 0.0f64, 0.0f64);
    for &(y, u) in prof {
        let r = u_ref(y)?;
        let e = u - r;
        if !e.is_finite() {
            return Ok((f64::NAN, f64::NAN));
        }
        num += e * e;
        den += r * r;
        emax = emax.max(e.abs());
        rmax = rmax.max(r.abs());
    }
    Ok(((num / den).sqrt(), emax / rmax))
}

/// Computes the metrics and series of one run; `wall` is the lower wall's position,
/// `steady_at` \[s\] the time at which the steady-state stop ended the run, if it did.
pub fn compute(
    channel: &PlanePoiseuille,
    wall: f64,
    probes: &ProbeRecord,
    steady_at: Option<f64>,
) -> Result<Measured, ReferenceError> {
    let mut out = Measured::default();
    let t = &probes.t;
    if t.is_empty() || probes.get(PROFILE, "u_000").is_none() {
        return Ok(out);
    }
    let d = channel.width();
    let big_t = channel.viscous_time();
    // The reference at a measured position, clamped into the channel (a bin mean is inside
    // unless a particle crossed a wall).
    let at = |y: f64, time: f64| channel.velocity((y - wall).clamp(0.0, d), time);
    let (mut tau_s, mut centre, mut centre_ref, mut l2s) = (vec![], vec![], vec![], vec![]);
    let mut steady: Option<Vec<(f64, f64)>> = None;
    let mut drift = None::<f64>;
    let mut startup_max = None::<f64>;
    let m = &mut out.metrics;
    for (i, &ti) in t.iter().enumerate() {
        let tau = ti / big_t;
        let prof = profile(probes, i);
        let (l2, linf) = if ti > 0.0 { errors(&prof, |y| at(y, ti))? } else { (f64::NAN, f64::NAN) };
        let (yc, uc) =
            prof.iter().copied().fold((f64::NAN, f64::NEG_INFINITY), |a, b| if b.1 > a.1 { b } else { a });
        tau_s.push(tau);
        centre.push(uc);
        let uc_ref = if yc.is_finite() { at(yc, ti)? } else { f64::NAN };
        centre_ref.push(uc_ref);
        l2s.push(l2);
        let mut steady_here = false;
        for &target in &TAUS {
            if (tau - target).abs() <= TAU_MATCH * target {
                let name = format!("t{:03}", (target * 100.0).round() as u32);
                m.insert(format!("u_profile_l2_rel_{name}"), l2);
                m.insert(format!("u_profile_linf_rel_{name}"), linf);
                if target < 1.0 {
                    startup_max = Some(startup_max.map_or(l2, |s| sticky_max(s, l2)));
                } else {
                    steady_here = true;
                }
            }
        }
        // The steady-state stop's sample, when it came before τ = 1.
        if let Some(ts) = steady_at
            && (ti - ts).abs() <= TAU_MATCH * ts
            && tau < 1.0 - TAU_MATCH
        {
            m.insert("tau_steady".into(), tau);
            steady_here = true;
        }
        if steady_here {
            m.insert("u_profile_l2_rel_steady".into(), l2);
            m.insert("u_profile_linf_rel_steady".into(), linf);
            m.insert("u_center_rel_err_steady".into(), (uc - uc_ref).abs() / channel.u_max().abs());
            steady = Some(prof.clone());
        }
        if let Some(s) = &steady
            && tau > 1.0 + TAU_MATCH
        {
            let norm: f64 = s.iter().map(|&(y, _)| at(y, big_t).map(|r| r * r)).sum::<Result<f64, _>>()?;
            let diff: f64 = if s.len() == prof.len() {
                s.iter().zip(&prof).map(|(a, b)| (a.1 - b.1).powi(2)).sum()
            } else {
                f64::NAN
            };
            let dr = (diff / norm).sqrt();
            drift = Some(drift.map_or(dr, |x| sticky_max(x, dr)));
        }
    }
    if let Some(s) = startup_max {
        m.insert("u_profile_l2_rel_startup_max".into(), s);
    }
    if let Some(dr) = drift {
        m.insert("u_profile_drift".into(), dr);
    }
    m.insert("tau_final".into(), tau_s[tau_s.len() - 1]);
    out.series.insert("t".into(), t.clone());
    out.series.insert("tau".into(), tau_s);
    out.series.insert("u_center".into(), centre);
    out.series.insert("u_center_ref".into(), centre_ref);
    out.series.insert("u_profile_l2_rel".into(), l2s);
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::BTreeMap;

    /// Probes of a channel sampled at `taus`, every bin off by the factor `1 + bias`.
    fn synthetic(ch: &PlanePoiseuille, taus: &[f64], bias: f64) -> ProbeRecord {
        let bins = 20;
        let t: Vec<f64> = taus.iter().map(|x| x * ch.viscous_time()).collect();
        let mut q = BTreeMap::new();
        for k in 0..bins {
            let y = (k as f64 + 0.5) / bins as f64 * ch.width();
            q.insert(format!("y_{k:03}"), vec![y; t.len()]);
            q.insert(
                format!("u_{k:03}"),
                t.iter().map(|&ti| ch.velocity(y, ti).unwrap() * (1.0 + bias)).collect(),
            );
        }
        ProbeRecord { t, series: BTreeMap::from([(PROFILE.to_string(), q)]) }
    }

    #[test]
    fn exact_profiles_have_no_error_and_a_bias_is_measured() {
        let ch = PlanePoiseuille::new(0.2, 6e-8, 1e-6).unwrap();
        let taus = [0.0, 0.05, 0.1, 0.2, 0.5, 1.0];
        let m = compute(&ch, 0.0, &synthetic(&ch, &taus, 0.0), None).unwrap().metrics;
        assert!(m["u_profile_l2_rel_steady"] < 1e-7, "{m:?}");
        assert!(m["u_profile_l2_rel_t005"] < 1e-6);
        let m = compute(&ch, 0.0, &synthetic(&ch, &taus, 0.01), None).unwrap().metrics;
        for name in ["u_profile_l2_rel_t005", "u_profile_l2_rel_t050", "u_profile_l2_rel_steady"] {
            assert!((m[name] - 0.01).abs() < 1e-6, "{name} = {}", m[name]);
        }
        assert!((m["u_profile_linf_rel_steady"] - 0.01).abs() < 1e-6);
        // The fastest bin is half a bin from the centre: u = u_max (1 − (1/20)²).
        assert!((m["u_center_rel_err_steady"] - 0.01 * (1.0 - 0.0025)).abs() < 1e-6);
        assert!((m["u_profile_l2_rel_startup_max"] - 0.01).abs() < 1e-6);
        assert!(!m.contains_key("u_profile_drift"));
    }

    #[test]
    fn drift_after_steady_state() {
        let ch = PlanePoiseuille::new(0.2, 6e-8, 1e-6).unwrap();
        let mut p = synthetic(&ch, &[0.5, 1.0, 1.5, 2.0], 0.0);
        // A 2 % change of the last profile (plus the transient's 5e-5 between τ = 1 and 2).
        for (name, v) in p.series.get_mut(PROFILE).unwrap().iter_mut() {
            if name.starts_with("u_") {
                v[3] *= 1.02;
            }
        }
        let m = compute(&ch, 0.0, &p, None).unwrap().metrics;
        assert!((m["u_profile_drift"] - 0.02).abs() < 1e-4, "{}", m["u_profile_drift"]);
        assert!((m["tau_final"] - 2.0).abs() < 1e-12);
    }

    #[test]
    fn a_steady_stop_before_tau_one_gives_the_steady_metrics_there() {
        let ch = PlanePoiseuille::new(0.2, 6e-8, 1e-6).unwrap();
        let mut p = synthetic(&ch, &[0.5, 0.6, 0.68], 0.0);
        // 1 % off at the stop only: measured against the series at τ = 0.68.
        for (name, v) in p.series.get_mut(PROFILE).unwrap().iter_mut() {
            if name.starts_with("u_") {
                v[2] *= 1.01;
            }
        }
        let stop = 0.68 * ch.viscous_time();
        let m = compute(&ch, 0.0, &p, Some(stop)).unwrap().metrics;
        assert!((m["u_profile_l2_rel_steady"] - 0.01).abs() < 1e-9, "{m:?}");
        assert!((m["tau_steady"] - 0.68).abs() < 1e-12);
        assert!(m["u_profile_l2_rel_startup_max"] < 1e-9, "the start-up samples are exact");
        // A run that ended there for another reason has no steady value.
        let m = compute(&ch, 0.0, &p, None).unwrap().metrics;
        assert!(!m.contains_key("u_profile_l2_rel_steady") && !m.contains_key("tau_steady"));
        // A stop at τ = 1 is the τ = 1 sample, and a stop time that matches no sample is none.
        let full = synthetic(&ch, &[0.5, 1.0], 0.0);
        let m = compute(&ch, 0.0, &full, Some(ch.viscous_time())).unwrap().metrics;
        assert!(m["u_profile_l2_rel_steady"] < 1e-9 && !m.contains_key("tau_steady"), "{m:?}");
        let m = compute(&ch, 0.0, &p, Some(0.65 * ch.viscous_time())).unwrap().metrics;
        assert!(!m.contains_key("u_profile_l2_rel_steady"), "{m:?}");
    }

    #[test]
    fn non_finite_velocity_is_an_error_not_a_skip() {
        let ch = PlanePoiseuille::new(0.2, 6e-8, 1e-6).unwrap();
        let mut p = synthetic(&ch, &[1.0], 0.0);
        p.series.get_mut(PROFILE).unwrap().get_mut("u_003").unwrap()[0] = f64::NAN;
        let m = compute(&ch, 0.0, &p, None).unwrap().metrics;
        assert!(m["u_profile_l2_rel_steady"].is_nan());
    }

    #[test]
    fn channel_reads_the_run_scene() {
        let scene = serde_json::json!({ "fluid": { "density": 1000.0, "viscosity": 1e-3 }, "body_force": [6e-8, 0.0] });
        let ch = channel(0.2, &scene).unwrap();
        assert!((ch.mean_velocity() - 2e-4).abs() < 1e-15);
        assert!(channel(0.2, &serde_json::json!({})).is_err());
    }
}
