//! Plane Poiseuille flow between no-slip plates at `y = 0` and `y = D`: the steady profile
//! and the start-up from rest under a body force (REFERENCES.md §3a, §3b).
//!
//! Start-up (Morris, Fox & Zhu 1997, JCP 136:214, with the corrected sign of REFERENCES.md §3a
//! and CASES.md so that a positive force gives a positive flow):
//!
//! ```text
//! u(y, t) = F/(2 nu) y (D - y)
//!         - sum_{k = 1, 3, 5, ...} 4 F D^2 / (nu pi^3 k^3) sin(k pi y / D) exp(-k^2 pi^2 nu t / D^2)
//! ```
//!
//! # Truncation bound
//! With `u_max = F D^2 / (8 nu)` and `tau = nu t / D^2`, the term of odd index `k` is at most
//! `32 / (pi^3 k^3) exp(-k^2 pi^2 tau)` in units of `|u_max|` (since `|sin| <= 1`). For a
//! decreasing `f`, `sum_{k = K, K+2, ...} f(k) <= f(K) + (1/2) int_K^inf f(x) dx`, and
//! `exp(-x^2 pi^2 tau) <= exp(-K^2 pi^2 tau)` for `x >= K`, so the terms left out when the sum
//! stops before the odd index `K` total at most
//!
//! ```text
//! E(K, tau) = 32 / pi^3 * exp(-K^2 pi^2 tau) * (1 / K^3 + 1 / (4 K^2))     [units of |u_max|]
//! ```
//!
//! The sum stops at the first `K` with `E(K, tau) <= tol` ([`startup_tail_bound`]), so the
//! error is at most `tol |u_max|` at every `y` and every `t >= 0`, including `t = 0`, where
//! the series converges only algebraically and the default `tol = 1e-8` needs 2541 terms
//! ([`startup_terms`]); for `tau >= 1e-3` it needs at most 16.

use crate::error::{finite, non_negative, positive, within};
use crate::{ReferenceError, Result};
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// Default truncation tolerance of the start-up series, relative to `|u_max|`.
pub const STARTUP_TOLERANCE: f64 = 1e-8;

/// Upper bound, in units of `|u_max|`, of the sum of the start-up series terms with odd index
/// `k >= k_first` at dimensionless time `tau = nu t / D^2` (see the module documentation):
/// `E = 32/pi^3 exp(-k_first^2 pi^2 tau) (1/k_first^3 + 1/(4 k_first^2))`.
/// `k_first` must be >= 1; `tau` finite and >= 0.
pub fn startup_tail_bound(k_first: usize, tau: f64) -> Result<f64> {
    non_negative("tau", tau)?;
    if k_first == 0 {
        return Err(ReferenceError::InvalidCount { name: "k_first", value: 0, rule: "must be at least 1" });
    }
    Ok(tail_bound(k_first as f64, tau))
}

fn tail_bound(k: f64, tau: f64) -> f64 {
    32.0 / PI.powi(3) * (-k * k * PI * PI * tau).exp() * (1.0 / (k * k * k) + 0.25 / (k * k))
}

/// Number of series terms (odd indices 1, 3, ..., 2N-1) that the bound requires for an error
/// at most `tol |u_max|` at `tau = nu t / D^2` (`tau >= 0`, `tol > 0`, both finite).
pub fn startup_terms(tau: f64, tol: f64) -> Result<usize> {
    non_negative("tau", tau)?;
    positive("tol", tol)?;
    let mut terms = 0usize;
    while tail_bound((2 * terms + 1) as f64, tau) > tol {
        terms += 1;
    }
    Ok(terms)
}

/// Steady plane Poiseuille profile from the mean velocity: `u = 6 U (y/D)(1 - y/D)` (m/s) for
/// channel width `width = D` (m) (> 0), mean velocity `mean_velocity = U` (m/s) (finite, any
/// sign) and `0 <= y <= D` (m); `u_max = 1.5 U` (REFERENCES.md §3b; Lan 2022 eq. 10 corrected,
/// CASES.md erratum 5).
pub fn steady_profile(width: f64, mean_velocity: f64, y: f64) -> Result<f64> {
    positive("width", width)?;
    finite("mean_velocity", mean_velocity)?;
    within("y", y, 0.0, width, "must lie in [0, width]")?;
    let eta = y / width;
    Ok(6.0 * mean_velocity * eta * (1.0 - eta))
}

/// Body force per unit mass (m/s^2) that drives mean velocity `U` (m/s) through a plane
/// channel of width `D` (m) with kinematic viscosity `nu` (m^2/s): `F = 12 nu U / D^2`
/// (equivalently `-dp/dx = 12 mu U / D^2`; REFERENCES.md §3b).
pub fn body_force_for_mean_velocity(width: f64, mean_velocity: f64, viscosity: f64) -> Result<f64> {
    positive("width", width)?;
    finite("mean_velocity", mean_velocity)?;
    positive("viscosity", viscosity)?;
    Ok(12.0 * viscosity * mean_velocity / (width * width))
}

/// Plane channel of width `D` driven from rest by a body force `F`; build with
/// [`PlanePoiseuille::new`] or [`PlanePoiseuille::from_mean_velocity`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct PlanePoiseuille {
    width: f64,
    force: f64,
    viscosity: f64,
}

impl PlanePoiseuille {
    /// Channel of width `width = D` (m) (> 0), body force per unit mass `force = F` (m/s^2)
    /// along x (finite, any sign) and kinematic viscosity `viscosity = nu` (m^2/s) (> 0).
    pub fn new(width: f64, force: f64, viscosity: f64) -> Result<Self> {
        Ok(Self {
            width: positive("width", width)?,
            force: finite("force", force)?,
            viscosity: positive("viscosity", viscosity)?,
        })
    }

    /// Channel whose steady mean velocity is `mean_velocity = U` (m/s): `F = 12 nu U / D^2`.
    pub fn from_mean_velocity(width: f64, mean_velocity: f64, viscosity: f64) -> Result<Self> {
        Self::new(width, body_force_for_mean_velocity(width, mean_velocity, viscosity)?, viscosity)
    }

    /// Channel width `D` (m).
    pub fn width(&self) -> f64 {
        self.width
    }

    /// Body force per unit mass `F` (m/s^2).
    pub fn force(&self) -> f64 {
        self.force
    }

    /// Kinematic viscosity `nu` (m^2/s).
    pub fn viscosity(&self) -> f64 {
        self.viscosity
    }

    /// Steady centre-line velocity `u_max = F D^2 / (8 nu)` (m/s) (REFERENCES.md §3a).
    pub fn u_max(&self) -> f64 {
        self.force * self.width * self.width / (8.0 * self.viscosity)
    }

    /// Steady mean velocity `U = F D^2 / (12 nu) = (2/3) u_max` (m/s) (REFERENCES.md §3b).
    pub fn mean_velocity(&self) -> f64 {
        self.force * self.width * self.width / (12.0 * self.viscosity)
    }

    /// Viscous time `D^2 / nu` (s); `tau = t nu / D^2` is the dimensionless time.
    pub fn viscous_time(&self) -> f64 {
        self.width * self.width / self.viscosity
    }

    /// Steady velocity `u(y) = F/(2 nu) y (D - y)` (m/s) at `0 <= y <= D` (m).
    pub fn steady_velocity(&self, y: f64) -> Result<f64> {
        within("y", y, 0.0, self.width, "must lie in [0, width]")?;
        Ok(self.force / (2.0 * self.viscosity) * y * (self.width - y))
    }

    /// Start-up velocity `u(y, t)` (m/s) at `0 <= y <= D` (m), time `t >= 0` (s), with error at
    /// most [`STARTUP_TOLERANCE`]` |u_max|` (guaranteed by the tail bound of the module
    /// documentation; Morris et al. 1997 with the corrected sign, REFERENCES.md §3a).
    pub fn velocity(&self, y: f64, t: f64) -> Result<f64> {
        self.velocity_with_tolerance(y, t, STARTUP_TOLERANCE)
    }

    /// As [`PlanePoiseuille::velocity`] with a chosen truncation tolerance `tol` (> 0,
    /// relative to `|u_max|`). The number of terms grows like `tol^(-1/2)` at `t = 0` and
    /// like `sqrt(ln(1/tol) / tau)` for `t > 0`.
    pub fn velocity_with_tolerance(&self, y: f64, t: f64, tol: f64) -> Result<f64> {
        within("y", y, 0.0, self.width, "must lie in [0, width]")?;
        non_negative("t", t)?;
        positive("tol", tol)?;
        let eta = y / self.width;
        let tau = t * self.viscosity / (self.width * self.width);
        let mut sum = 0.0;
        let mut k = 1.0;
        while tail_bound(k, tau) > tol {
            sum += 32.0 / (PI.powi(3) * k * k * k) * (k * PI * eta).sin() * (-k * k * PI * PI * tau).exp();
            k += 2.0;
        }
        Ok(self.u_max() * (4.0 * eta * (1.0 - eta) - sum))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Morris's recalled set, F = 2e-4: D^2/nu = 1 s.
    fn morris() -> PlanePoiseuille {
        PlanePoiseuille::new(1e-3, 2e-4, 1e-6).unwrap()
    }

    #[test]
    fn steady_forms_agree_and_vanish_at_walls() {
        let (d, u_mean, nu) = (0.2, 2e-3, 1e-6);
        let ch = PlanePoiseuille::from_mean_velocity(d, u_mean, nu).unwrap();
        assert!((ch.force() - 12.0 * nu * u_mean / (d * d)).abs() <= 1e-15 * ch.force());
        assert!((ch.u_max() - 1.5 * u_mean).abs() <= 1e-12 * u_mean);
        assert!((ch.mean_velocity() - u_mean).abs() <= 1e-12 * u_mean);
        for i in 0..=20 {
            let y = d * i as f64 / 20.0;
            let a = steady_profile(d, u_mean, y).unwrap();
            let b = ch.steady_velocity(y).unwrap();
            assert!((a - b).abs() <= 1e-12 * u_mean, "y = {y}");
        }
        assert!(ch.steady_velocity(0.0).unwrap().abs() <= 0.0);
        assert!(ch.steady_velocity(d).unwrap().abs() <= 1e-18);
        assert!((steady_profile(d, u_mean, d / 2.0).unwrap() - 1.5 * u_mean).abs() <= 1e-15);
        // Mean of the profile by Simpson's rule (exact for a parabola).
        let n = 10;
        let h = d / n as f64;
        let mut s = 0.0;
        for i in 0..=n {
            let w = if i == 0 || i == n {
                1.0
            } else if i % 2 == 1 {
                4.0
            } else {
                2.0
            };
            s += w * steady_profile(d, u_mean, i as f64 * h).unwrap();
        }
        assert!((s * h / 3.0 / d - u_mean).abs() <= 1e-12 * u_mean);
    }

    #[test]
    fn startup_centreline_table() {
        // REFERENCES.md §3a: u(L/2, t) / u_max against nu t / L^2.
        let ch = morris();
        let table = [
            (0.0225, 0.1786190006),
            (0.045, 0.3387656446),
            (0.1125, 0.6599931076),
            (0.2, 0.8566368905),
            (0.5, 0.9925776232),
            (1.0, 0.9999466191),
        ];
        for (tau, ratio) in table {
            let t = tau * ch.viscous_time();
            let exact = ch.velocity_with_tolerance(5e-4, t, 1e-13).unwrap() / ch.u_max();
            assert!((exact - ratio).abs() <= 6e-11, "tau = {tau}: {exact:.11} vs {ratio}");
            let default = ch.velocity(5e-4, t).unwrap() / ch.u_max();
            assert!((default - ratio).abs() <= 1e-8, "tau = {tau}: {default:.11} vs {ratio}");
        }
        // Dimensional values with F = 2e-4 (printed to 7 significant digits).
        for (t, u) in [(0.0225, 4.465475e-6), (0.045, 8.469141e-6), (0.1125, 1.649983e-5)] {
            let v = ch.velocity(5e-4, t).unwrap();
            assert!((v - u).abs() <= 0.6e-6 * u, "t = {t}: {v:e} vs {u:e}");
        }
        assert!((ch.u_max() - 2.5e-5).abs() <= 1e-18);
        // 99 % of u_max at tau = ln(32 / (0.01 pi^3)) / pi^2 = 0.469798.
        let t99 = 0.469798 * ch.viscous_time();
        assert!((ch.velocity(5e-4, t99).unwrap() / ch.u_max() - 0.99).abs() <= 1e-6);
    }

    #[test]
    fn startup_is_zero_at_t0_within_bound() {
        // No special case at t = 0: the series itself must vanish to 1e-8 u_max.
        let ch = morris();
        let mut worst: f64 = 0.0;
        for i in 0..=200 {
            let y = ch.width() * i as f64 / 200.0;
            worst = worst.max(ch.velocity(y, 0.0).unwrap().abs() / ch.u_max());
        }
        assert!(worst <= 1e-8, "max |u(y, 0)| / u_max = {worst:e}");
        assert!(worst > 0.0, "the series should be summed, not special-cased");
        assert_eq!(startup_terms(0.0, 1e-8).unwrap(), 2541);
        assert_eq!(startup_terms(1e-3, 1e-8).unwrap(), 16);
    }

    #[test]
    fn truncation_error_is_within_bound_at_small_times() {
        let ch = morris();
        for tau in [1e-7, 1e-5, 1e-3, 0.01] {
            for eta in [0.01, 0.1, 0.37, 0.5, 0.93] {
                let y = eta * ch.width();
                let t = tau * ch.viscous_time();
                let coarse = ch.velocity(y, t).unwrap();
                let fine = ch.velocity_with_tolerance(y, t, 1e-11).unwrap();
                assert!((coarse - fine).abs() <= (1e-8 + 1e-11) * ch.u_max(), "tau = {tau}, eta = {eta}");
            }
        }
    }

    #[test]
    fn startup_satisfies_diffusion_equation() {
        // u_t = nu u_yy + F by central differences, relative to F.
        let ch = PlanePoiseuille::new(0.2, 3e-5, 1e-3).unwrap();
        let (d, nu, f) = (ch.width(), ch.viscosity(), ch.force());
        let u = |y: f64, t: f64| ch.velocity_with_tolerance(y, t, 1e-14).unwrap();
        for tau in [0.01, 0.05, 0.2, 0.6] {
            let t = tau * ch.viscous_time();
            let ht = 1e-4 * t;
            for eta in [0.05, 0.2, 0.5, 0.77] {
                let y = eta * d;
                let hy = 1e-3 * d;
                let ut = (u(y, t + ht) - u(y, t - ht)) / (2.0 * ht);
                let uyy = (u(y + hy, t) - 2.0 * u(y, t) + u(y - hy, t)) / (hy * hy);
                let residual = ut - nu * uyy - f;
                assert!(
                    residual.abs() <= 1e-5 * f,
                    "tau = {tau}, eta = {eta}: residual / F = {}",
                    residual / f
                );
            }
        }
    }

    #[test]
    fn walls_sign_and_steady_limit() {
        let ch = morris();
        for tau in [0.0, 1e-4, 0.05, 0.3, 3.0] {
            let t = tau * ch.viscous_time();
            assert!(ch.velocity(0.0, t).unwrap().abs() <= 1e-15 * ch.u_max());
            assert!(ch.velocity(ch.width(), t).unwrap().abs() <= 1e-13 * ch.u_max());
        }
        // Positive force gives positive flow; negative force the mirror image.
        let back = PlanePoiseuille::new(1e-3, -2e-4, 1e-6).unwrap();
        let (v, w) = (morris().velocity(3e-4, 0.05).unwrap(), back.velocity(3e-4, 0.05).unwrap());
        assert!(v > 0.0 && (v + w).abs() <= 1e-20);
        // Steady limit: at tau = 5 the transient is exp(-5 pi^2) ~ 1e-21.
        for eta in [0.1, 0.5, 0.8] {
            let y = eta * ch.width();
            let diff = ch.velocity(y, 5.0).unwrap() - ch.steady_velocity(y).unwrap();
            assert!(diff.abs() <= 1e-12 * ch.u_max());
        }
    }

    #[test]
    fn tail_bound_dominates_actual_tail() {
        // The sum of |terms| from K on, summed far out, never exceeds the bound.
        for tau in [0.0, 1e-4, 1e-2] {
            for k_first in [1usize, 3, 11, 51] {
                let mut tail = 0.0;
                let mut k = k_first as f64;
                while k < 2e5 {
                    tail += 32.0 / (PI.powi(3) * k * k * k) * (-k * k * PI * PI * tau).exp();
                    k += 2.0;
                }
                assert!(tail <= startup_tail_bound(k_first, tau).unwrap());
            }
        }
    }

    #[test]
    fn rejects_bad_parameters() {
        assert!(PlanePoiseuille::new(0.0, 1.0, 1.0).is_err());
        assert!(PlanePoiseuille::new(1.0, f64::NAN, 1.0).is_err());
        let e = PlanePoiseuille::new(1.0, 1.0, -1.0).unwrap_err();
        assert!(e.to_string().contains("viscosity"));
        let ch = morris();
        assert!(ch.velocity(-1e-4, 0.1).is_err());
        assert!(ch.velocity(2e-3, 0.1).is_err());
        assert!(ch.velocity(5e-4, -0.1).unwrap_err().to_string().contains("t = -0.1"));
        assert!(ch.velocity_with_tolerance(5e-4, 0.1, 0.0).is_err());
        assert!(steady_profile(1.0, 1.0, 1.5).is_err());
        assert!(body_force_for_mean_velocity(1.0, f64::INFINITY, 1.0).is_err());
        assert!(startup_tail_bound(0, 0.1).is_err());
        assert!(startup_terms(0.0, -1.0).is_err());
    }
}
