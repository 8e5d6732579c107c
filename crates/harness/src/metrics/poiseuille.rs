//! Metrics of a viscous start-up from rest against its series: the periodic Poiseuille
//! channel (CASES.md "poiseuille_periodic", `meniscus_reference::poiseuille`, Morris, Fox &
//! Zhu 1997) and the Hagen–Poiseuille pipe (`meniscus_reference::pipe`), one [`compute`]
//! for both through [`StartupFlow`].
//!
//! The solver's profile probe gives, per sample time, the mean position and the mean
//! streamwise velocity `u_###` of the particles in each bin across the flow: for the channel
//! (`velocity_profile`) the wall-normal position `y_###`, for the pipe (`radial_profile`)
//! the distance `r_###` from the axis. Each bin is compared with the series at its own
//! measured mean position, so the comparison carries no interpolation error. With `τ = t / T`,
//! `T` the flow's viscous time (`D²/ν` for the channel of width `D`, `R²/ν` for the pipe of
//! radius `R`):
//!
//! - `u_profile_l2_rel_tNNN` / `u_profile_linf_rel_tNNN`: the profile error at
//!   `τ = NNN / 100` (the scene's `output.probe_times`), relative L2
//!   `sqrt(Σ (u − u_ref)² / Σ u_ref²)` over the bins and Linf `max |u − u_ref| / max |u_ref|`;
//! - `u_profile_l2_rel_startup_max`: the largest L2 error over the samples with `τ < 1`;
//! - `u_profile_l2_rel_steady`, `u_profile_linf_rel_steady`, `u_center_rel_err_steady` (the
//!   fastest bin against the reference at its position, over the steady centre-line velocity
//!   `u_max`: `F D² / 8ν` for the channel, `G R² / 4ν` for the pipe): at `τ = 1`, or at the
//!   sample where the steady-state stop (`time.steady`) ended the run before it, against the
//!   series at that time (which holds what is left of the transient), with `tau_steady` its
//!   `τ`. At `τ = 1` the channel's transient is `e^{−π²} ≈ 5e-5` of `u_max`, below every error
//!   reported; the pipe's is `≈ 3.4e-3` of `u_max` on the axis (`1 − 0.99659`, REFERENCES.md
//!   §3d), still compared exactly since the series holds it;
//! - `u_profile_drift`: for runs past `τ = 1`, the largest `‖u(t) − u(τ=1)‖₂ / ‖u_ref‖₂` after
//!   it (a stable steady state does not drift; the pipe's exact solution drifts by what is
//!   left of its transient at `τ = 1`, `≈ 3.2e-3` over 20 even bins of `r`);
//! - `tau_final`: how far the run got.
//!
//! Series: `t`, `tau`, `u_center` (the largest bin velocity), `u_center_ref` and
//! `u_profile_l2_rel` at every sample.
//!
//! Parameters: the geometry from the case (the channel's `width` and `wall` = lower wall
//! position; the pipe's `radius` and `axis`); `ν = μ/ρ` and the driving body force component
//! (the channel's x, the pipe's along its axis) from each run's scene, so presets may change
//! the Reynolds number.

use super::{Measured, sticky_max};
use meniscus::ProbeRecord;
use meniscus_reference::ReferenceError;
use meniscus_reference::pipe::HagenPoiseuille;
use meniscus_reference::poiseuille::PlanePoiseuille;

/// The channel's probe.
const PROFILE: &str = "velocity_profile";

/// The pipe's probe.
const RADIAL_PROFILE: &str = "radial_profile";

/// Dimensionless sample times `τ = t / T` (`T` the flow's viscous time) of the named
/// start-up metrics.
pub const TAUS: [f64; 5] = [0.05, 0.1, 0.2, 0.5, 1.0];

/// Relative tolerance on `τ` when matching a sample to a named time.
const TAU_MATCH: f64 = 1e-6;

/// A flow started from rest whose start-up series [`compute`] compares a profile probe with.
pub trait StartupFlow {
    /// The probe read (its key in the run's probe record).
    const PROBE: &'static str;
    /// Prefix of the probe's per-bin position keys (`<POSITION>_###`, \[m\]).
    const POSITION: &'static str;
    /// The series' velocity \[m/s\] at distance `s` \[m\] from the flow's origin (the
    /// channel's lower wall, the pipe's axis) and time `t` \[s\], `s` clamped into the flow (a
    /// bin mean is inside unless a particle crossed a wall).
    fn velocity_at(&self, s: f64, t: f64) -> Result<f64, ReferenceError>;
    /// Steady centre-line velocity \[m/s\].
    fn u_max(&self) -> f64;
    /// Viscous time `T` \[s\] (`τ = t / T`).
    fn viscous_time(&self) -> f64;
}

impl StartupFlow for PlanePoiseuille {
    const PROBE: &'static str = PROFILE;
    const POSITION: &'static str = "y";

    fn velocity_at(&self, s: f64, t: f64) -> Result<f64, ReferenceError> {
        self.velocity(s.clamp(0.0, self.width()), t)
    }

    fn u_max(&self) -> f64 {
        PlanePoiseuille::u_max(self)
    }

    fn viscous_time(&self) -> f64 {
        PlanePoiseuille::viscous_time(self)
    }
}

impl StartupFlow for HagenPoiseuille {
    const PROBE: &'static str = RADIAL_PROFILE;
    const POSITION: &'static str = "r";

    fn velocity_at(&self, s: f64, t: f64) -> Result<f64, ReferenceError> {
        self.velocity(s.clamp(0.0, self.radius()), t)
    }

    fn u_max(&self) -> f64 {
        HagenPoiseuille::u_max(self)
    }

    fn viscous_time(&self) -> f64 {
        HagenPoiseuille::viscous_time(self)
    }
}

/// `μ/ρ` \[m²/s\] of a run's scene (NaN when a field is missing).
fn kinematic_viscosity(scene: &serde_json::Value) -> f64 {
    num(&scene["fluid"]["viscosity"]) / num(&scene["fluid"]["density"])
}

/// A scene number, NaN when absent (the reference then rejects it).
fn num(v: &serde_json::Value) -> f64 {
    v.as_f64().unwrap_or(f64::NAN)
}

/// The channel of a run: the case's geometry with the run scene's fluid and force.
pub fn channel(width: f64, scene: &serde_json::Value) -> Result<PlanePoiseuille, ReferenceError> {
    PlanePoiseuille::new(width, num(&scene["body_force"][0]), kinematic_viscosity(scene))
}

/// The pipe of a run: radius \[m\] and axis (0 = x, 1 = y, 2 = z) from the case, the run
/// scene's fluid and its body force component along `axis` \[m/s²\]; an axis beyond the
/// scene's `dimension` is an error.
pub fn pipe(radius: f64, axis: usize, scene: &serde_json::Value) -> Result<HagenPoiseuille, ReferenceError> {
    if scene["dimension"].as_u64().is_some_and(|d| axis as u64 >= d) {
        return Err(ReferenceError::InvalidCount {
            name: "axis",
            value: axis,
            rule: "must be less than the scene's `dimension`",
        });
    }
    HagenPoiseuille::new(radius, num(&scene["body_force"][axis]), kinematic_viscosity(scene))
}

/// One sampled profile of `F`'s probe: the bins' mean positions and velocities (empty bins
/// dropped).
fn profile<F: StartupFlow>(probes: &ProbeRecord, i: usize) -> Vec<(f64, f64)> {
    let mut out = Vec::new();
    for k in 0.. {
        let (Some(y), Some(u)) = (
            probes.get(F::PROBE, &format!("{}_{k:03}", F::POSITION)),
            probes.get(F::PROBE, &format!("u_{k:03}")),
        ) else {
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

/// Computes the metrics and series of one run of `flow`; `origin` \[m\] is the probe
/// coordinate of the flow's origin (the channel's lower wall; 0 for the pipe, whose probe
/// measures from the axis), `steady_at` \[s\] the time at which the steady-state stop ended
/// the run, if it did.
pub fn compute<F: StartupFlow>(
    flow: &F,
    origin: f64,
    probes: &ProbeRecord,
    steady_at: Option<f64>,
) -> Result<Measured, ReferenceError> {
    let mut out = Measured::default();
    let t = &probes.t;
    if t.is_empty() || probes.get(F::PROBE, "u_000").is_none() {
        return Ok(out);
    }
    let big_t = flow.viscous_time();
    // The reference at a measured position.
    let at = |y: f64, time: f64| flow.velocity_at(y - origin, time);
    let (mut tau_s, mut centre, mut centre_ref, mut l2s) = (vec![], vec![], vec![], vec![]);
    let mut steady: Option<Vec<(f64, f64)>> = None;
    let mut drift = None::<f64>;
    let mut startup_max = None::<f64>;
    let m = &mut out.metrics;
    for (i, &ti) in t.iter().enumerate() {
        let tau = ti / big_t;
        let prof = profile::<F>(probes, i);
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
            m.insert("u_center_rel_err_steady".into(), (uc - uc_ref).abs() / flow.u_max().abs());
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

    /// Probes of `flow` sampled at `taus`: 20 even bins across `extent` \[m\] from its
    /// origin, each at the velocity `u(s, t)` off by the factor `1 + bias`.
    fn sampled<F: StartupFlow>(
        flow: &F,
        extent: f64,
        taus: &[f64],
        bias: f64,
        u: impl Fn(f64, f64) -> f64,
    ) -> ProbeRecord {
        let bins = 20;
        let t: Vec<f64> = taus.iter().map(|x| x * flow.viscous_time()).collect();
        let mut q = BTreeMap::new();
        for k in 0..bins {
            let s = (k as f64 + 0.5) / bins as f64 * extent;
            q.insert(format!("{}_{k:03}", F::POSITION), vec![s; t.len()]);
            q.insert(format!("u_{k:03}"), t.iter().map(|&ti| u(s, ti) * (1.0 + bias)).collect());
        }
        ProbeRecord { t, series: BTreeMap::from([(F::PROBE.to_string(), q)]) }
    }

    /// Probes of a channel sampled at `taus`, every bin off by the factor `1 + bias`.
    fn synthetic(ch: &PlanePoiseuille, taus: &[f64], bias: f64) -> ProbeRecord {
        sampled(ch, ch.width(), taus, bias, |y, t| ch.velocity(y, t).unwrap())
    }

    /// Probes of a pipe sampled at `taus`, every bin off by the factor `1 + bias`; the
    /// series summed to `1e-12 u_max`, independently of the metrics' default tolerance.
    fn synthetic_pipe(p: &HagenPoiseuille, taus: &[f64], bias: f64) -> ProbeRecord {
        sampled(p, p.radius(), taus, bias, |r, t| p.velocity_with_tolerance(r, t, 1e-12).unwrap())
    }

    /// The pipe of [`pipe_scene`]: R = 1 cm, ν = 1e-6 m²/s, G = 4e-4 m/s², u_max = 1 cm/s.
    fn test_pipe() -> HagenPoiseuille {
        HagenPoiseuille::new(0.01, 4e-4, 1e-6).unwrap()
    }

    /// A 3D scene of the fluid and force of [`test_pipe`] along `axis`.
    fn pipe_scene(axis: usize) -> serde_json::Value {
        let mut force = vec![0.0; 3];
        force[axis] = 4e-4;
        serde_json::json!({ "dimension": 3, "fluid": { "density": 1000.0, "viscosity": 1e-3 }, "body_force": force })
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

    #[test]
    fn exact_pipe_profiles_have_no_error_and_a_bias_is_measured() {
        let p = test_pipe();
        // (No τ = 0 sample: the series at t = 0 to 1e-12 takes ~1e8 terms.)
        let taus = [0.05, 0.1, 0.2, 0.5, 1.0];
        let m = compute(&p, 0.0, &synthetic_pipe(&p, &taus, 0.0), None).unwrap().metrics;
        for name in ["t005", "t010", "t020", "t050", "t100", "steady"] {
            for norm in ["l2", "linf"] {
                let v = m[&format!("u_profile_{norm}_rel_{name}")];
                assert!(v < 1e-7, "{norm} {name} = {v:e}");
            }
        }
        assert!(m["u_center_rel_err_steady"] < 1e-7 && m["u_profile_l2_rel_startup_max"] < 1e-7, "{m:?}");
        assert!((m["tau_final"] - 1.0).abs() < 1e-12);
        let m = compute(&p, 0.0, &synthetic_pipe(&p, &taus, 0.01), None).unwrap().metrics;
        for name in ["t005", "t010", "t020", "t050", "t100", "steady"] {
            for norm in ["l2", "linf"] {
                let v = m[&format!("u_profile_{norm}_rel_{name}")];
                assert!((v - 0.01).abs() < 1e-6, "{norm} {name} = {v}");
            }
        }
        assert!((m["u_profile_l2_rel_startup_max"] - 0.01).abs() < 1e-6);
        // The fastest bin is half a bin off the axis, against u_max (not its own reference).
        let t = p.viscous_time();
        let centre = 0.01 * p.velocity(p.radius() / 40.0, t).unwrap() / p.u_max();
        assert!((m["u_center_rel_err_steady"] - centre).abs() < 1e-9, "{m:?}");
        // The pipe's probe only: the channel's keys give no metrics.
        let ch = PlanePoiseuille::new(0.2, 6e-8, 1e-6).unwrap();
        assert!(compute(&p, 0.0, &synthetic(&ch, &taus, 0.0), None).unwrap().metrics.is_empty());
    }

    /// The pipe's exact solution drifts past τ = 1 by what is left of its transient there
    /// (the module documentation's 3.2e-3); a steady stop before τ = 1 gives the steady
    /// metrics there, as for the channel.
    #[test]
    fn pipe_drift_and_steady_stop() {
        let p = test_pipe();
        let m = compute(&p, 0.0, &synthetic_pipe(&p, &[0.5, 1.0, 2.0, 4.0], 0.0), None).unwrap().metrics;
        assert!((m["u_profile_drift"] - 3.22e-3).abs() < 1e-5, "{}", m["u_profile_drift"]);
        let mut probes = synthetic_pipe(&p, &[0.5, 0.8], 0.0);
        for (name, v) in probes.series.get_mut(RADIAL_PROFILE).unwrap().iter_mut() {
            if name.starts_with("u_") {
                v[1] *= 1.01;
            }
        }
        let m = compute(&p, 0.0, &probes, Some(0.8 * p.viscous_time())).unwrap().metrics;
        assert!((m["u_profile_l2_rel_steady"] - 0.01).abs() < 1e-7, "{m:?}");
        assert!((m["tau_steady"] - 0.8).abs() < 1e-12);
    }

    #[test]
    fn pipe_reads_the_run_scene() {
        for axis in 0..3 {
            let p = pipe(0.01, axis, &pipe_scene(axis)).unwrap();
            assert_eq!([p.radius(), p.gradient()].map(f64::to_bits), [0.01, 4e-4].map(f64::to_bits));
            assert!((p.viscosity() - 1e-6).abs() < 1e-21 && (p.u_max() - 0.01).abs() < 1e-15);
        }
        // The component along another axis is zero: no flow, not the x component.
        assert_eq!(pipe(0.01, 1, &pipe_scene(0)).unwrap().gradient().to_bits(), 0.0f64.to_bits());
        assert!(pipe(0.01, 0, &serde_json::json!({})).is_err());
        // Without a `dimension`, an axis the body force lacks is a missing field.
        let planar = serde_json::json!({ "fluid": { "density": 1000.0, "viscosity": 1e-3 }, "body_force": [4e-4, 0.0] });
        assert!(pipe(0.01, 0, &planar).is_ok() && pipe(0.01, 2, &planar).is_err());
        let e = pipe(0.01, 3, &pipe_scene(0)).unwrap_err();
        assert!(e.to_string().contains("axis = 3"), "{e}");
        assert!(pipe(0.0, 0, &pipe_scene(0)).is_err());
    }

    /// A case's `"hagen_poiseuille"` reference reaches the pipe metrics through the dispatch.
    #[test]
    fn hagen_poiseuille_reference_dispatches_to_the_pipe() {
        let spec: crate::case::ReferenceSpec =
            serde_json::from_value(serde_json::json!({ "hagen_poiseuille": { "radius": 0.01, "axis": 2 } }))
                .unwrap();
        assert_eq!(spec, crate::case::ReferenceSpec::HagenPoiseuille { radius: 0.01, axis: 2 });
        let extra = serde_json::json!({ "hagen_poiseuille": { "radius": 0.01, "axis": 2, "wall": 0.0 } });
        assert!(serde_json::from_value::<crate::case::ReferenceSpec>(extra).is_err());
        let p = test_pipe();
        let probes = synthetic_pipe(&p, &[0.5, 1.0], 0.01);
        let m = super::super::compute(&spec, &pipe_scene(2), &probes, 1234, None).unwrap().metrics;
        assert!((m["u_profile_l2_rel_steady"] - 0.01).abs() < 1e-6, "{m:?}");
        assert_eq!(m["particles"].to_bits(), 1234.0f64.to_bits());
    }
}
