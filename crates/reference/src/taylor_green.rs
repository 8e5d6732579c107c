//! The 2D periodic Taylor–Green vortex (Taylor & Green 1937; CASES.md phase 2).
//!
//! In a periodic box of period `L` with wavenumber `k = 2 pi / L`, velocity scale `U`,
//! kinematic viscosity `nu` and density `rho`:
//!
//! ```text
//! u = -U cos(k x) sin(k y) exp(-2 k^2 nu t)
//! v = +U sin(k x) cos(k y) exp(-2 k^2 nu t)
//! p = -(rho U^2 / 4) (cos(2 k x) + cos(2 k y)) exp(-4 k^2 nu t)
//! ```
//!
//! This is an exact solution of the incompressible Navier–Stokes equations: the velocity is
//! divergence free, `(u . grad) u = -grad p / rho` and `du/dt = nu lap u` (checked by finite
//! differences in the tests). The pressure is defined up to a constant; this one has zero mean.

use crate::Result;
use crate::error::{finite, non_negative, positive};
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// The Taylor–Green vortex; build with [`TaylorGreen::new`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct TaylorGreen {
    velocity_scale: f64,
    period: f64,
    viscosity: f64,
    density: f64,
}

impl TaylorGreen {
    /// Vortex of velocity scale `velocity_scale = U` (m/s) (finite, any sign), box period
    /// `period = L` (m) (> 0), kinematic viscosity `viscosity = nu` (m^2/s) (>= 0; 0 gives
    /// the steady Euler solution) and density `density = rho` (kg/m^3) (> 0).
    pub fn new(velocity_scale: f64, period: f64, viscosity: f64, density: f64) -> Result<Self> {
        Ok(Self {
            velocity_scale: finite("velocity_scale", velocity_scale)?,
            period: positive("period", period)?,
            viscosity: non_negative("viscosity", viscosity)?,
            density: positive("density", density)?,
        })
    }

    /// Wavenumber `k = 2 pi / L` (1/m).
    pub fn wavenumber(&self) -> f64 {
        2.0 * PI / self.period
    }

    /// Decay rate of the velocity amplitude, `2 k^2 nu` (1/s) (the kinetic energy and the
    /// pressure decay at twice this rate).
    pub fn decay_rate(&self) -> f64 {
        2.0 * self.wavenumber().powi(2) * self.viscosity
    }

    /// Reynolds number `U L / nu` (infinite for `nu = 0`).
    pub fn reynolds(&self) -> f64 {
        self.velocity_scale.abs() * self.period / self.viscosity
    }

    fn amplitude(&self, t: f64) -> Result<f64> {
        non_negative("t", t)?;
        Ok(self.velocity_scale * (-self.decay_rate() * t).exp())
    }

    /// Velocity `(u, v)` (m/s) at `(x, y)` (m) (finite) and time `t >= 0` (s).
    pub fn velocity(&self, x: f64, y: f64, t: f64) -> Result<[f64; 2]> {
        let a = self.amplitude(t)?;
        let k = self.wavenumber();
        let (kx, ky) = (k * finite("x", x)?, k * finite("y", y)?);
        Ok([-a * kx.cos() * ky.sin(), a * kx.sin() * ky.cos()])
    }

    /// Pressure (Pa) `-(rho U^2 / 4)(cos 2kx + cos 2ky) exp(-4 k^2 nu t)` at `(x, y)` (m) and
    /// `t >= 0` (s) (zero mean over the box).
    pub fn pressure(&self, x: f64, y: f64, t: f64) -> Result<f64> {
        let a = self.amplitude(t)?;
        let k = self.wavenumber();
        let (kx, ky) = (k * finite("x", x)?, k * finite("y", y)?);
        Ok(-0.25 * self.density * a * a * ((2.0 * kx).cos() + (2.0 * ky).cos()))
    }

    /// Box-averaged kinetic energy per unit mass `<|u|^2> / 2 = (U^2 / 4) exp(-4 k^2 nu t)`
    /// (m^2/s^2) at `t >= 0` (s).
    pub fn mean_kinetic_energy(&self, t: f64) -> Result<f64> {
        let a = self.amplitude(t)?;
        Ok(0.25 * a * a)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn navier_stokes_residual_by_finite_differences() {
        let tg = TaylorGreen::new(0.7, 1.0, 7e-3, 1000.0).unwrap();
        let (nu, rho) = (tg.viscosity, tg.density);
        let h = 1e-4;
        let ht = 1e-4;
        let vel = |x: f64, y: f64, t: f64| tg.velocity(x, y, t).unwrap();
        let p = |x: f64, y: f64, t: f64| tg.pressure(x, y, t).unwrap();
        for (x, y, t) in [(0.1, 0.2, 0.3), (0.37, 0.81, 1.0), (0.9, 0.05, 2.0), (0.5, 0.5, 0.5)] {
            let [u, v] = vel(x, y, t);
            let (xp, xm, yp, ym) = (vel(x + h, y, t), vel(x - h, y, t), vel(x, y + h, t), vel(x, y - h, t));
            let (tp, tm) = (vel(x, y, t + ht), vel(x, y, t - ht));
            let px = (p(x + h, y, t) - p(x - h, y, t)) / (2.0 * h);
            let py = (p(x, y + h, t) - p(x, y - h, t)) / (2.0 * h);
            let grad_p = [px, py];
            let div = (xp[0] - xm[0]) / (2.0 * h) + (yp[1] - ym[1]) / (2.0 * h);
            assert!(div.abs() <= 1e-7, "div u = {div} at ({x}, {y}, {t})");
            let scale = tg.wavenumber() * tg.velocity_scale.powi(2);
            for i in 0..2 {
                let dudt = (tp[i] - tm[i]) / (2.0 * ht);
                let dudx = (xp[i] - xm[i]) / (2.0 * h);
                let dudy = (yp[i] - ym[i]) / (2.0 * h);
                let centre = [u, v][i];
                let lap = (xp[i] + xm[i] + yp[i] + ym[i] - 4.0 * centre) / (h * h);
                let residual = dudt + u * dudx + v * dudy + grad_p[i] / rho - nu * lap;
                assert!(
                    residual.abs() <= 1e-6 * scale,
                    "component {i} residual {residual:e} at ({x}, {y}, {t})"
                );
            }
        }
    }

    #[test]
    fn signs_decay_and_energy() {
        let tg = TaylorGreen::new(1.0, 2.0, 0.01, 1.0).unwrap();
        // u = -U cos(kx) sin(ky): at (0, L/4), u = -U.
        let [u, v] = tg.velocity(0.0, 0.5, 0.0).unwrap();
        assert!((u + 1.0).abs() <= 1e-15 && v.abs() <= 1e-15);
        let t = 3.0;
        let [u_t, _] = tg.velocity(0.0, 0.5, t).unwrap();
        assert!((u_t + (-2.0 * PI * PI * 0.01 * t).exp()).abs() <= 1e-15);
        // Mean kinetic energy by midpoint quadrature over the box (exact for trigonometric
        // polynomials of low degree).
        let n = 16;
        let mut e = 0.0;
        for i in 0..n {
            for j in 0..n {
                let (x, y) = ((i as f64 + 0.5) * 2.0 / n as f64, (j as f64 + 0.5) * 2.0 / n as f64);
                let [u, v] = tg.velocity(x, y, t).unwrap();
                e += 0.5 * (u * u + v * v);
            }
        }
        e /= (n * n) as f64;
        assert!((e - tg.mean_kinetic_energy(t).unwrap()).abs() <= 1e-14);
        // Pressure minimum at the vortex centres, maximum at the saddles.
        assert!(
            tg.pressure(0.0, 0.0, 0.0).unwrap() < 0.0 && tg.pressure(0.5, 0.0, 0.0).unwrap().abs() <= 1e-15
        );
        assert!((tg.reynolds() - 200.0).abs() <= 1e-9);
    }

    #[test]
    fn rejects_bad_parameters() {
        assert!(TaylorGreen::new(1.0, 0.0, 0.01, 1.0).unwrap_err().to_string().contains("period"));
        assert!(TaylorGreen::new(f64::NAN, 1.0, 0.01, 1.0).is_err());
        assert!(TaylorGreen::new(1.0, 1.0, -0.01, 1.0).is_err());
        let tg = TaylorGreen::new(1.0, 1.0, 0.0, 1.0).unwrap();
        assert!(tg.velocity(0.0, 0.0, -1.0).is_err());
        assert!(tg.pressure(f64::NAN, 0.0, 1.0).is_err());
    }
}
