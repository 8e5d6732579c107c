//! Initial pressure of the inviscid rotating square patch (Colagrossi 2005;
//! REFERENCES.md §2).
//!
//! A square `[-L/2, L/2]^2` with free surface (`p = 0` on the edges) and velocity
//! `u = omega y`, `v = -omega x`. The pressure solves
//! `lap p = -rho (du_i/dx_j)(du_j/dx_i) = 2 rho omega^2` with `p = 0` on the edges. With
//! `xi = x/L + 1/2` and `eta = y/L` (both measured so the patch is `xi in [0, 1]`,
//! `eta in [-1/2, 1/2]`), the single series (REFERENCES.md §2, "Equivalent single series") is
//!
//! ```text
//! p / (rho omega^2 L^2) = xi (xi - 1)
//!     + sum_{m odd} 8 / (pi^3 m^3) sin(m pi xi) cosh(m pi eta) / cosh(m pi / 2)
//! ```
//!
//! The problem is symmetric in x and y, so the series is taken along the axis for which the
//! point is closer to the centre line, `|eta| <= |xi - 1/2|`. With `d = 1/2 - |eta|`,
//! `cosh(m pi eta) / cosh(m pi / 2) <= min(1, 2 exp(-m pi d))`, and the terms from the odd
//! index `M` on total at most `8/pi^3 min(1, 2 exp(-M pi d)) (1/M^3 + 1/(4 M^2))`; the sum
//! stops when that bound is below [`SERIES_TOLERANCE`]. At the centre this takes 6 terms.

use crate::Result;
use crate::error::{finite, positive, within};
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// Absolute truncation tolerance of the series, in units of `rho omega^2 L^2`
/// (the centre value is -0.147..., so it is about 7e-11 relative there).
pub const SERIES_TOLERANCE: f64 = 1e-11;

/// The rotating square patch; build with [`RotatingSquare::new`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct RotatingSquare {
    side: f64,
    omega: f64,
    density: f64,
}

impl RotatingSquare {
    /// Square of side `side = L` (m) (> 0) centred at the origin, angular velocity
    /// `omega` (rad/s) (finite, either sign: the pressure depends on `omega^2`) and density
    /// `density = rho` (kg/m^3) (> 0).
    pub fn new(side: f64, omega: f64, density: f64) -> Result<Self> {
        Ok(Self {
            side: positive("side", side)?,
            omega: finite("omega", omega)?,
            density: positive("density", density)?,
        })
    }

    /// Side `L` (m).
    pub fn side(&self) -> f64 {
        self.side
    }

    /// Angular velocity `omega` (rad/s).
    pub fn omega(&self) -> f64 {
        self.omega
    }

    /// Density `rho` (kg/m^3).
    pub fn density(&self) -> f64 {
        self.density
    }

    /// Initial velocity `(u, v) = (omega y, -omega x)` (m/s) at `(x, y)` (m).
    pub fn initial_velocity(&self, x: f64, y: f64) -> [f64; 2] {
        [self.omega * y, -self.omega * x]
    }

    /// Initial pressure (Pa) at `(x, y)` (m) from the centre, both in `[-L/2, L/2]`; it is
    /// negative inside and 0 on the edges. Error at most [`SERIES_TOLERANCE`]` rho omega^2 L^2`.
    pub fn pressure(&self, x: f64, y: f64) -> Result<f64> {
        let half = 0.5 * self.side;
        within("x", x, -half, half, "must lie in [-side/2, side/2]")?;
        within("y", y, -half, half, "must lie in [-side/2, side/2]")?;
        let (mut s, mut c) = (x / self.side, y / self.side);
        if c.abs() > s.abs() {
            std::mem::swap(&mut s, &mut c);
        }
        Ok(self.density * self.omega * self.omega * self.side * self.side * unit_pressure(s + 0.5, c.abs()))
    }

    /// Centre pressure (Pa), `-0.1473427066 rho omega^2 L^2` (REFERENCES.md §2).
    pub fn centre_pressure(&self) -> f64 {
        self.density * self.omega * self.omega * self.side * self.side * unit_pressure(0.5, 0.0)
    }
}

/// `p / (rho omega^2 L^2)` at `xi = x*/L in [0, 1]` (sine axis) and `c = |y|/L in [0, 1/2]`
/// (cosh axis); 0 on the edges.
fn unit_pressure(xi: f64, c: f64) -> f64 {
    let d = 0.5 - c;
    if d <= 0.0 || xi <= 0.0 || xi >= 1.0 {
        return 0.0;
    }
    let amplitude = 8.0 / PI.powi(3);
    let mut sum = 0.0;
    let mut m = 1.0_f64;
    loop {
        let decay = (2.0 * (-m * PI * d).exp()).min(1.0);
        if amplitude * decay * (1.0 / (m * m * m) + 0.25 / (m * m)) <= SERIES_TOLERANCE {
            break;
        }
        // cosh(m pi c) / cosh(m pi / 2), written without overflow.
        let ratio = (-m * PI * d).exp() * (1.0 + (-2.0 * m * PI * c).exp()) / (1.0 + (-m * PI).exp());
        sum += amplitude / (m * m * m) * (m * PI * xi).sin() * ratio;
        m += 2.0;
    }
    xi * (xi - 1.0) + sum
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn published_values() {
        let unit = RotatingSquare::new(1.0, 1.0, 1.0).unwrap();
        let c = unit.centre_pressure();
        assert!((c + 0.1473427066).abs() <= 6e-11, "centre {c:.12}");
        assert!(((c + 0.1473427066) / 0.1473427066).abs() <= 1e-8);
        for (x, y, p) in [
            (0.0, 0.0, -0.1473427066),
            (0.25, 0.0, -0.1146698129),
            (0.25, 0.25, -0.0905723162),
            (0.4, 0.4, -0.0261429069),
            (0.5, 0.0, 0.0),
        ] {
            for (px, py) in [(x, y), (-x, y), (y, x), (x, -y), (-y, -x)] {
                let v = unit.pressure(px, py).unwrap();
                assert!((v - p).abs() <= 6e-11, "p({px}, {py}) = {v:.12} vs {p}");
            }
        }
        // Colagrossi's set: omega = 100, rho = 1000, L = 1 gives -1.473427e6 Pa.
        let paper = RotatingSquare::new(1.0, -100.0, 1000.0).unwrap();
        assert!((paper.centre_pressure() + 1.473427066e6).abs() <= 1e-3);
        // Scaling with L^2.
        let big = RotatingSquare::new(2.0, 1.0, 1.0).unwrap();
        assert!((big.pressure(0.5, 0.5).unwrap() - 4.0 * -0.0905723162).abs() <= 1e-9);
    }

    #[test]
    fn poisson_equation_by_finite_differences() {
        let patch = RotatingSquare::new(0.8, 3.0, 950.0).unwrap();
        let rhs = 2.0 * patch.density() * patch.omega().powi(2);
        let h = 1e-3 * patch.side();
        let p = |x: f64, y: f64| patch.pressure(x, y).unwrap();
        for (x, y) in [(0.0, 0.0), (0.1, -0.05), (-0.2, 0.3), (0.3, 0.3), (0.35, -0.1), (0.01, 0.2)] {
            let lap = (p(x + h, y) + p(x - h, y) + p(x, y + h) + p(x, y - h) - 4.0 * p(x, y)) / (h * h);
            assert!(((lap - rhs) / rhs).abs() <= 1e-5, "lap p at ({x}, {y}) = {lap}, expected {rhs}");
        }
    }

    #[test]
    fn zero_on_edges_negative_inside() {
        let patch = RotatingSquare::new(1.0, 1.0, 1.0).unwrap();
        for i in 0..=40 {
            let s = -0.5 + i as f64 / 40.0;
            for (x, y) in [(s, 0.5), (s, -0.5), (0.5, s), (-0.5, s)] {
                assert!(patch.pressure(x, y).unwrap().abs() <= 0.0);
            }
            // Just inside the edge the series must already be small and negative.
            if s.abs() < 0.5 {
                let v = patch.pressure(s, 0.5 - 1e-6).unwrap();
                assert!(v < 0.0 && v > -1e-6, "p({s}, 0.5 - 1e-6) = {v:e}");
            }
        }
        for (x, y) in [(0.49, 0.49), (0.2, -0.45), (0.0, 0.1)] {
            assert!(patch.pressure(x, y).unwrap() < 0.0);
        }
        let [u, v] = patch.initial_velocity(0.0, 0.5);
        assert!((u - 0.5).abs() <= 0.0 && v.abs() <= 0.0);
    }

    #[test]
    fn rejects_bad_parameters() {
        assert!(RotatingSquare::new(0.0, 1.0, 1.0).unwrap_err().to_string().contains("side"));
        assert!(RotatingSquare::new(1.0, f64::NAN, 1.0).is_err());
        assert!(RotatingSquare::new(1.0, 1.0, -1.0).is_err());
        let patch = RotatingSquare::new(1.0, 1.0, 1.0).unwrap();
        assert!(patch.pressure(0.6, 0.0).unwrap_err().to_string().contains('x'));
        assert!(patch.pressure(0.0, f64::NAN).is_err());
    }
}
