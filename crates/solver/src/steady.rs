//! The steady-state stop (`time.steady`, [`SteadyStop`]): whether a run's probe record
//! shows a steady flow, so that a steady case ends once it is there instead of at a fixed
//! end time chosen for its slowest resolution (issue #33; the channel's numbers:
//! `validation/poiseuille_channel.json`).

use crate::probes::ProbeRecord;
use crate::scene::SteadyStop;

/// Fewest samples in each window for a verdict: fewer, and one noisy sample decides.
pub const MIN_SAMPLES: usize = 3;

/// Whether `record`, up to its last sample, shows the flow steady by `spec`: both windows
/// hold at least [`MIN_SAMPLES`] samples, the last sample is at or after `spec.after`, and
/// the window means of the selected quantities changed by at most `spec.tolerance` of
/// their norm (equation in [`SteadyStop`]). A probe or quantity that is absent, or a mean
/// that is not finite, is never steady.
pub fn is_steady(spec: &SteadyStop, record: &ProbeRecord) -> bool {
    let Some(&now) = record.t.last() else { return false };
    if now < spec.after || now < 2.0 * spec.window {
        return false;
    }
    // Sample indices of (now − 2w, now − w] and (now − w, now]: `t` is increasing.
    let start = |t0: f64| record.t.partition_point(|&t| t <= t0);
    let (i0, i1, i2) = (start(now - 2.0 * spec.window), start(now - spec.window), record.t.len());
    if i1 - i0 < MIN_SAMPLES || i2 - i1 < MIN_SAMPLES {
        return false;
    }
    let Some(series) = record.series.get(&spec.probe) else { return false };
    let prefix = spec.quantities.as_deref().unwrap_or("");
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
    let (mut change, mut size, mut compared) = (0.0, 0.0, 0);
    for values in series.iter().filter(|(name, _)| name.starts_with(prefix)).map(|(_, v)| v) {
        let (m0, m1) = (mean(&values[i0..i1]), mean(&values[i1..i2]));
        if !(m0.is_finite() && m1.is_finite()) {
            return false;
        }
        change += (m1 - m0) * (m1 - m0);
        size += m1 * m1;
        compared += 1;
    }
    compared > 0 && size > 0.0 && change.sqrt() <= spec.tolerance * size.sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A record of `u_000`, `u_001` and `y_000` sampled every second to `end`, the velocities
    /// `u(t)`, `y` a fast-changing position that the `u_` selection leaves out.
    fn record(end: usize, u: impl Fn(f64) -> f64) -> ProbeRecord {
        let mut r = ProbeRecord::default();
        for i in 0..=end {
            let t = i as f64;
            r.t.push(t);
            let probe = r.series.entry("velocity_profile_1".into()).or_default();
            probe.entry("u_000".into()).or_default().push(u(t));
            probe.entry("u_001".into()).or_default().push(2.0 * u(t));
            probe.entry("y_000".into()).or_default().push(t);
        }
        r
    }

    fn spec(tolerance: f64) -> SteadyStop {
        SteadyStop {
            probe: "velocity_profile_1".into(),
            quantities: Some("u_".into()),
            window: 10.0,
            tolerance,
            after: 0.0,
        }
    }

    #[test]
    fn a_flow_still_developing_is_not_steady_and_a_settled_one_is() {
        // u = 1 − e^(−t/5) settles: its window means differ by about 5 % at t = 30, by
        // 1e-7 at t = 100.
        let developing = record(30, |t| 1.0 - (-t / 5.0).exp());
        assert!(!is_steady(&spec(1e-3), &developing));
        let settled = record(100, |t| 1.0 - (-t / 5.0).exp());
        assert!(is_steady(&spec(1e-3), &settled));
        // The same record, every quantity compared: `y` grows with t, never steady.
        let all = SteadyStop { quantities: None, ..spec(1e-3) };
        assert!(!is_steady(&all, &settled));
    }

    #[test]
    fn the_change_is_measured_between_window_means() {
        // A constant plus a sample-to-sample alternation of ±0.1: each window's mean is
        // within 0.1/10 of the constant, though two samples differ by 20 %.
        let noisy = record(40, |t| 1.0 + if (t as usize).is_multiple_of(2) { 0.1 } else { -0.1 });
        assert!(is_steady(&spec(0.03), &noisy));
        // A drift of 1 % per window is not steady at 0.5 %, steady at 2 %.
        let drifting = record(40, |t| 1.0 + 1e-3 * t);
        assert!(!is_steady(&spec(0.005), &drifting));
        assert!(is_steady(&spec(0.02), &drifting));
    }

    #[test]
    fn too_early_too_few_or_absent_data_is_never_steady() {
        let flat = record(40, |_| 1.0);
        assert!(is_steady(&spec(1e-3), &flat));
        assert!(!is_steady(&SteadyStop { after: 50.0, ..spec(1e-3) }, &flat), "before `after`");
        assert!(!is_steady(&spec(1e-3), &record(15, |_| 1.0)), "shorter than two windows");
        let sparse = SteadyStop { window: 1.0, ..spec(1e-3) };
        assert!(!is_steady(&sparse, &flat), "one sample per window");
        assert!(!is_steady(&SteadyStop { probe: "mass_balance".into(), ..spec(1e-3) }, &flat));
        assert!(!is_steady(&SteadyStop { quantities: Some("v_".into()), ..spec(1e-3) }, &flat));
        let mut gap = record(40, |_| 1.0);
        gap.series.get_mut("velocity_profile_1").unwrap().get_mut("u_001").unwrap()[38] = f64::NAN;
        assert!(!is_steady(&spec(1e-3), &gap), "an empty bin in a window");
        assert!(!is_steady(&spec(1e-3), &record(40, |_| 0.0)), "a zero profile has no scale");
        assert!(!is_steady(&spec(1e-3), &ProbeRecord::default()));
    }
}
