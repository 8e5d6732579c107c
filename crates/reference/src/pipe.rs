//! Hagen–Poiseuille flow in a pipe of radius `R`: the steady profile and the start-up from
//! rest under a pressure gradient (REFERENCES.md §3d).
//!
//! With `G = -(dp/dx) / rho` (m/s^2), `u_max = G R^2 / (4 nu)`, `tau = nu t / R^2` and
//! `l_k` the zeros of `J0`:
//!
//! ```text
//! u(r)    = G/(4 nu) (R^2 - r^2)
//! u(r, t) = G R^2/(4 nu) [1 - (r/R)^2 - 8 sum_k J0(l_k r/R) / (l_k^3 J1(l_k)) exp(-l_k^2 tau)]
//! ```
//!
//! `J0` and `J1` are puruspe's (`puruspe::Jn`, rational approximations of Numerical Recipes
//! 3rd ed., accurate to a few ulps of the function's amplitude). The zeros `l_k` start from
//! McMahon's asymptotic expansion (Abramowitz & Stegun 9.5.12) and are polished by Newton's
//! method, `x <- x + J0(x) / J1(x)`.
//!
//! # Truncation bound
//! `w = sqrt(x) J0(x)` solves `w'' + q w = 0` with `q = 1 + 1/(4 x^2)` decreasing, so by
//! Sonin's theorem `S = w^2 + w'^2 / q` is non-decreasing; at the zeros of `J0`,
//! `S = l_k J1(l_k)^2 / q(l_k)`, hence `l_k J1(l_k)^2 >= S(l_1) = c = 0.6212774...` for every
//! `k`. With `|J0| <= 1` the `k`-th term is at most `(8 / sqrt(c)) l_k^(-5/2) exp(-l_k^2 tau)`
//! in units of `|u_max|`. With `l_k > (k - 1/4) pi` (the zeros interlace with McMahon's
//! leading term) and `sum_{k >= K} f(k) <= f(K) + int_K^inf f` for decreasing `f`, the terms
//! from `K` on total at most
//!
//! ```text
//! E(K, tau) = (8 / sqrt(c)) exp(-l_K^2 tau) [ b^(-5/2) + (2 / (3 pi)) b^(-3/2) ],  b = (K - 1/4) pi
//! ```
//!
//! The sum stops at the first `K` with `E <= tol`, so the error is at most `tol |u_max|` at
//! every `r` and every `t >= 0`. At `t = 0` the series converges only like `K^(-3/2)`: the
//! default `tol = 1e-8` then takes about 114 000 terms (some tens of milliseconds); the
//! 200-term truncation that REFERENCES.md checked leaves about 2.3e-6 there. For
//! `tau >= 1e-3` a few dozen terms suffice.

use crate::error::{finite, non_negative, positive, within};
use crate::{ReferenceError, Result};
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// Default truncation tolerance of the start-up series, relative to `|u_max|`.
pub const STARTUP_TOLERANCE: f64 = 1e-8;

/// First zero of `J0` (used for the constant of the tail bound).
const J0_FIRST_ZERO: f64 = 2.404_825_557_695_773;

/// `J0(x)`, Bessel function of the first kind of order 0 (puruspe).
fn j0(x: f64) -> f64 {
    puruspe::Jn(0, x)
}

/// `J1(x)`, Bessel function of the first kind of order 1 (puruspe).
fn j1(x: f64) -> f64 {
    puruspe::Jn(1, x)
}

/// The `k`-th positive zero of `J0` (`k >= 1`, so `bessel_j0_zero(1) = 2.404825557695773`).
/// McMahon's expansion `b + 1/(8b) - 124/(3 (8b)^3) + 120928/(15 (8b)^5)`, `b = (k - 1/4) pi`
/// (Abramowitz & Stegun 9.5.12), then Newton's method on puruspe's `J0`, `J1`.
pub fn bessel_j0_zero(k: usize) -> Result<f64> {
    if k == 0 {
        return Err(ReferenceError::InvalidCount { name: "k", value: 0, rule: "must be at least 1" });
    }
    Ok(j0_zero(k))
}

fn j0_zero(k: usize) -> f64 {
    let b = (k as f64 - 0.25) * PI;
    let e = 1.0 / (8.0 * b);
    let mut x = b + e - 124.0 / 3.0 * e.powi(3) + 120_928.0 / 15.0 * e.powi(5);
    for _ in 0..20 {
        let dx = j0(x) / j1(x);
        x += dx;
        if dx.abs() <= 4.0 * f64::EPSILON * x {
            break;
        }
    }
    x
}

/// `c = l_1 J1(l_1)^2 / (1 + 1/(4 l_1^2))`, the lower bound of `l_k J1(l_k)^2` (Sonin).
fn sonin_constant() -> f64 {
    let l1 = J0_FIRST_ZERO;
    l1 * j1(l1).powi(2) / (1.0 + 0.25 / (l1 * l1))
}

/// Upper bound, in units of `|u_max|`, of the sum of the start-up series terms with index
/// `k >= k_first` (`k_first >= 1`) at `tau = nu t / R^2 >= 0` (see the module documentation).
pub fn startup_tail_bound(k_first: usize, tau: f64) -> Result<f64> {
    non_negative("tau", tau)?;
    let l = bessel_j0_zero(k_first)?;
    Ok(tail_bound(k_first, l, tau, 8.0 / sonin_constant().sqrt()))
}

fn tail_bound(k: usize, l_k: f64, tau: f64, scale: f64) -> f64 {
    let b = (k as f64 - 0.25) * PI;
    scale * (-l_k * l_k * tau).exp() * (b.powf(-2.5) + 2.0 / (3.0 * PI) * b.powf(-1.5))
}

/// Steady velocity of a pipe of radius `R` (m) with mean velocity `U` (m/s) at radius
/// `0 <= r <= R` (m): `u = 2 U (1 - r^2/R^2)`, `u_max = 2 U` (REFERENCES.md §3d).
pub fn steady_profile(radius: f64, mean_velocity: f64, r: f64) -> Result<f64> {
    positive("radius", radius)?;
    finite("mean_velocity", mean_velocity)?;
    within("r", r, 0.0, radius, "must lie in [0, radius]")?;
    Ok(2.0 * mean_velocity * (1.0 - (r / radius).powi(2)))
}

/// Pressure gradient per unit density `G = -(dp/dx)/rho = 8 nu U / R^2` (m/s^2) that drives
/// mean velocity `U` (m/s) through a pipe of radius `R` (m), kinematic viscosity `nu`
/// (m^2/s) (REFERENCES.md §3d).
pub fn gradient_for_mean_velocity(radius: f64, mean_velocity: f64, viscosity: f64) -> Result<f64> {
    positive("radius", radius)?;
    finite("mean_velocity", mean_velocity)?;
    positive("viscosity", viscosity)?;
    Ok(8.0 * viscosity * mean_velocity / (radius * radius))
}

/// Pipe of radius `R` driven from rest by `G = -(dp/dx)/rho`; build with
/// [`HagenPoiseuille::new`] or [`HagenPoiseuille::from_mean_velocity`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct HagenPoiseuille {
    radius: f64,
    gradient: f64,
    viscosity: f64,
}

impl HagenPoiseuille {
    /// Pipe of radius `radius = R` (m) (> 0), driving `gradient = G = -(dp/dx)/rho` (m/s^2)
    /// (finite, any sign; a body force per unit mass acts the same) and kinematic viscosity
    /// `viscosity = nu` (m^2/s) (> 0).
    pub fn new(radius: f64, gradient: f64, viscosity: f64) -> Result<Self> {
        Ok(Self {
            radius: positive("radius", radius)?,
            gradient: finite("gradient", gradient)?,
            viscosity: positive("viscosity", viscosity)?,
        })
    }

    /// Pipe whose steady mean velocity is `mean_velocity = U` (m/s): `G = 8 nu U / R^2`.
    pub fn from_mean_velocity(radius: f64, mean_velocity: f64, viscosity: f64) -> Result<Self> {
        Self::new(radius, gradient_for_mean_velocity(radius, mean_velocity, viscosity)?, viscosity)
    }

    /// Radius `R` (m).
    pub fn radius(&self) -> f64 {
        self.radius
    }

    /// Driving gradient `G` (m/s^2).
    pub fn gradient(&self) -> f64 {
        self.gradient
    }

    /// Kinematic viscosity `nu` (m^2/s).
    pub fn viscosity(&self) -> f64 {
        self.viscosity
    }

    /// Steady centre-line velocity `u_max = G R^2 / (4 nu)` (m/s).
    pub fn u_max(&self) -> f64 {
        self.gradient * self.radius * self.radius / (4.0 * self.viscosity)
    }

    /// Steady mean velocity `U = u_max / 2` (m/s).
    pub fn mean_velocity(&self) -> f64 {
        0.5 * self.u_max()
    }

    /// Steady volume flow rate `Q = pi R^4 G / (8 nu)` (m^3/s) (Hagen–Poiseuille law).
    pub fn flow_rate(&self) -> f64 {
        PI * self.radius.powi(4) * self.gradient / (8.0 * self.viscosity)
    }

    /// Viscous time `R^2 / nu` (s); `tau = nu t / R^2`.
    pub fn viscous_time(&self) -> f64 {
        self.radius * self.radius / self.viscosity
    }

    /// Steady velocity `u(r) = G/(4 nu)(R^2 - r^2)` (m/s) at `0 <= r <= R` (m).
    pub fn steady_velocity(&self, r: f64) -> Result<f64> {
        within("r", r, 0.0, self.radius, "must lie in [0, radius]")?;
        Ok(self.gradient / (4.0 * self.viscosity) * (self.radius * self.radius - r * r))
    }

    /// Start-up velocity `u(r, t)` (m/s) at `0 <= r <= R` (m) and `t >= 0` (s), with error at
    /// most [`STARTUP_TOLERANCE`]` |u_max|` (tail bound of the module documentation).
    pub fn velocity(&self, r: f64, t: f64) -> Result<f64> {
        self.velocity_with_tolerance(r, t, STARTUP_TOLERANCE)
    }

    /// As [`HagenPoiseuille::velocity`] with a chosen tolerance `tol` (> 0, relative to
    /// `|u_max|`). At `t = 0` the number of terms grows like `tol^(-2/3)`.
    pub fn velocity_with_tolerance(&self, r: f64, t: f64, tol: f64) -> Result<f64> {
        within("r", r, 0.0, self.radius, "must lie in [0, radius]")?;
        non_negative("t", t)?;
        positive("tol", tol)?;
        let rho = r / self.radius;
        let tau = t * self.viscosity / (self.radius * self.radius);
        let scale = 8.0 / sonin_constant().sqrt();
        let mut sum = 0.0;
        let mut k = 1;
        loop {
            let l = j0_zero(k);
            if tail_bound(k, l, tau, scale) <= tol {
                break;
            }
            sum += j0(l * rho) / (l.powi(3) * j1(l)) * (-l * l * tau).exp();
            k += 1;
        }
        Ok(self.u_max() * (1.0 - rho * rho - 8.0 * sum))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn zeros_of_j0() {
        // Abramowitz & Stegun table 9.5.
        let known =
            [2.404825557695773, 5.520078110286311, 8.653727912911013, 11.79153443901428, 14.93091770848779];
        for (k, z) in known.iter().enumerate() {
            let l = bessel_j0_zero(k + 1).unwrap();
            assert!((l - z).abs() <= 1e-13 * z, "zero {}: {l} vs {z}", k + 1);
        }
        // Every zero is a zero, lies in ((k - 1/4) pi, (k - 1/8) pi) and satisfies the Sonin
        // bound l J1(l)^2 >= c used for the tail.
        let c = sonin_constant();
        assert!((c - 0.621_277_4).abs() <= 1e-7, "c = {c}");
        let mut previous = 0.0;
        for k in (1..2000).chain([10_000, 100_000]) {
            let l = bessel_j0_zero(k).unwrap();
            // |J0(l)| within rounding: 1e-14, or the slope times a few ulps of l.
            assert!(j0(l).abs() <= 1e-14_f64.max(j1(l).abs() * 1e-15 * l), "J0(l_{k}) = {}", j0(l));
            assert!(l > (k as f64 - 0.25) * PI && l < (k as f64 - 0.125) * PI, "l_{k} = {l}");
            assert!(l * j1(l).powi(2) >= c * (1.0 - 1e-12), "k = {k}");
            if k > 1 && k < 2000 {
                // Consecutive zeros are less than pi apart (Sturm comparison, q > 1) and
                // well separated: no zero skipped or found twice.
                let gap = l - previous;
                assert!(gap > 3.0 && gap < PI, "l_{k} - l_{} = {gap}", k - 1);
            }
            previous = l;
        }
        assert!(bessel_j0_zero(0).is_err());
    }

    #[test]
    fn centreline_table() {
        // REFERENCES.md §3d: u(0, t) / u_max against nu t / R^2.
        let pipe = HagenPoiseuille::new(0.5, 2.0, 0.01).unwrap();
        let table = [
            (0.05, 0.1996166161),
            (0.1, 0.3851895036),
            (0.2, 0.6517955920),
            (0.5, 0.9385183702),
            (1.0, 0.9965885207),
        ];
        for (tau, ratio) in table {
            let t = tau * pipe.viscous_time();
            let v = pipe.velocity_with_tolerance(0.0, t, 1e-13).unwrap() / pipe.u_max();
            assert!((v - ratio).abs() <= 6e-11, "tau = {tau}: {v:.11} vs {ratio}");
            let d = pipe.velocity(0.0, t).unwrap() / pipe.u_max();
            assert!((d - ratio).abs() <= 1e-8, "tau = {tau}");
        }
        // 99 % at tau = 0.814040 (printed to 6 decimals).
        let v = pipe.velocity(0.0, 0.814040 * pipe.viscous_time()).unwrap() / pipe.u_max();
        assert!((v - 0.99).abs() <= 1e-7, "{v}");
    }

    #[test]
    fn startup_satisfies_radial_diffusion_equation() {
        // u_t = nu (u_rr + u_r / r) + G by central differences, relative to G.
        let pipe = HagenPoiseuille::new(3e-3, 0.2, 1e-6).unwrap();
        let (rad, nu, g) = (pipe.radius(), pipe.viscosity(), pipe.gradient());
        let u = |r: f64, t: f64| pipe.velocity_with_tolerance(r, t, 1e-14).unwrap();
        for tau in [0.01, 0.05, 0.2, 0.7] {
            let t = tau * pipe.viscous_time();
            let ht = 1e-4 * t;
            for rho in [0.1, 0.3, 0.6, 0.9] {
                let r = rho * rad;
                let h = 1e-3 * rad;
                let ut = (u(r, t + ht) - u(r, t - ht)) / (2.0 * ht);
                let urr = (u(r + h, t) - 2.0 * u(r, t) + u(r - h, t)) / (h * h);
                let ur = (u(r + h, t) - u(r - h, t)) / (2.0 * h);
                let residual = ut - nu * (urr + ur / r) - g;
                assert!(
                    residual.abs() <= 1e-5 * g,
                    "tau = {tau}, r/R = {rho}: residual / G = {}",
                    residual / g
                );
            }
        }
    }

    #[test]
    fn initial_wall_and_steady_values() {
        let pipe = HagenPoiseuille::from_mean_velocity(3.175e-3, 0.01, 3.6e-3 / 1050.0).unwrap();
        assert!((pipe.u_max() - 0.02).abs() <= 1e-15);
        let q = PI * pipe.radius().powi(2) * 0.01;
        assert!((pipe.flow_rate() - q).abs() <= 1e-12 * q);
        // At t = 0 the series is summed (no special case) to 1e-8 u_max.
        let mut worst: f64 = 0.0;
        for rho in [0.0, 0.25, 0.5, 0.75, 0.99] {
            worst = worst.max((pipe.velocity(rho * pipe.radius(), 0.0).unwrap() / pipe.u_max()).abs());
        }
        assert!(worst <= 1e-8 && worst > 0.0, "max |u(r, 0)| / u_max = {worst:e}");
        for tau in [0.0, 0.01, 0.3] {
            let t = tau * pipe.viscous_time();
            let wall = pipe.velocity(pipe.radius(), t).unwrap();
            assert!(wall.abs() <= 1e-8 * pipe.u_max(), "u(R, {t}) = {wall:e}");
        }
        for rho in [0.0, 0.5, 0.9] {
            let r = rho * pipe.radius();
            let v = pipe.velocity(r, 6.0 * pipe.viscous_time()).unwrap();
            let s = pipe.steady_velocity(r).unwrap();
            assert!((v - s).abs() <= 1e-12 * pipe.u_max());
            let p = steady_profile(pipe.radius(), 0.01, r).unwrap();
            assert!((p - s).abs() <= 1e-14);
        }
    }

    #[test]
    fn tail_bound_dominates_actual_tail() {
        let scale = 8.0 / sonin_constant().sqrt();
        for tau in [0.0, 1e-3, 0.05] {
            for k_first in [1usize, 5, 40] {
                let mut tail = 0.0;
                for k in k_first..20_000 {
                    let l = j0_zero(k);
                    tail += 1.0 / (l.powi(3) * j1(l).abs()) * (-l * l * tau).exp();
                }
                let bound = tail_bound(k_first, j0_zero(k_first), tau, scale);
                assert!(8.0 * tail <= bound, "tau = {tau}, K = {k_first}: {} > {bound}", 8.0 * tail);
            }
        }
        assert!(startup_tail_bound(1, -1.0).is_err());
    }

    #[test]
    fn rejects_bad_parameters() {
        assert!(HagenPoiseuille::new(-1.0, 1.0, 1.0).unwrap_err().to_string().contains("radius"));
        assert!(HagenPoiseuille::new(1.0, f64::NAN, 1.0).is_err());
        assert!(HagenPoiseuille::new(1.0, 1.0, 0.0).is_err());
        let pipe = HagenPoiseuille::new(1.0, 1.0, 1.0).unwrap();
        assert!(pipe.velocity(1.5, 0.1).is_err());
        assert!(pipe.velocity(0.5, f64::NAN).is_err());
        assert!(pipe.velocity(-0.1, 0.1).is_err());
        assert!(steady_profile(1.0, 1.0, 2.0).is_err());
        assert!(gradient_for_mean_velocity(1.0, 1.0, -1.0).is_err());
    }
}
