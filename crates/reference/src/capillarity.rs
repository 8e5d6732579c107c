//! Capillarity of a drop of radius `R`: Laplace pressure jump, small-amplitude oscillation
//! frequencies and viscous damping rates (REFERENCES.md §4).
//!
//! | quantity | 2D (cylindrical drop) | 3D (spherical drop) |
//! |---|---|---|
//! | pressure jump | `sigma / R` | `2 sigma / R` |
//! | `omega_n^2`, free drop (Lamb) | `n (n^2 - 1) sigma / (rho R^3)` | `n (n - 1)(n + 2) sigma / (rho R^3)` |
//! | damping rate `beta_n` (amplitude `~ exp(-beta t)`) | `2 n (n - 1) nu / R^2` | `(n - 1)(2n + 1) nu / R^2` |
//!
//! The 2D frequency is confirmed in Basilisk's `src/test/oscillation.c`, the 3D frequency and
//! damping in Lamb's solution as used in public post-processing scripts; the 2D damping rate
//! is derived by the potential-flow dissipation method (REFERENCES.md §4, open point 9).

use crate::error::{non_negative, positive};
use crate::{ReferenceError, Result};
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// Space dimension of the drop: a cylinder (2D) or a sphere (3D).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum Dimension {
    /// 2D: a circular (cylindrical) drop.
    Two,
    /// 3D: a spherical drop.
    Three,
}

fn mode(n: usize) -> Result<f64> {
    if n >= 2 {
        Ok(n as f64)
    } else {
        Err(ReferenceError::InvalidCount {
            name: "mode",
            value: n,
            rule: "must be at least 2 (modes 0 and 1 do not oscillate)",
        })
    }
}

/// Laplace pressure jump `p_inside - p_outside` (Pa) for surface tension `sigma` (N/m) and
/// radius `radius` (m): `sigma / R` in 2D, `2 sigma / R` in 3D (REFERENCES.md §4).
pub fn laplace_pressure(dim: Dimension, sigma: f64, radius: f64) -> Result<f64> {
    positive("sigma", sigma)?;
    positive("radius", radius)?;
    Ok(match dim {
        Dimension::Two => sigma / radius,
        Dimension::Three => 2.0 * sigma / radius,
    })
}

/// Angular frequency `omega_n` (rad/s) of the inviscid small-amplitude oscillation of mode
/// `mode = n >= 2` of a free drop (no outer fluid): `omega_n^2 = n (n^2 - 1) sigma / (rho R^3)`
/// in 2D, `n (n - 1)(n + 2) sigma / (rho R^3)` in 3D (Lamb; REFERENCES.md §4). `sigma` (N/m),
/// `density = rho` (kg/m^3), `radius = R` (m).
pub fn oscillation_angular_frequency(
    dim: Dimension,
    mode: usize,
    sigma: f64,
    density: f64,
    radius: f64,
) -> Result<f64> {
    oscillation_angular_frequency_two_fluid(dim, mode, sigma, density, 0.0, radius)
}

/// As [`oscillation_angular_frequency`] with an outer fluid of density `outer_density`
/// (kg/m^3) (>= 0; 0 gives the free drop): `omega_n^2 = n (n^2 - 1) sigma /
/// ((rho_in + rho_out) R^3)` in 2D and `n (n + 1)(n - 1)(n + 2) sigma / (((n + 1) rho_in +
/// n rho_out) R^3)` in 3D (Lamb; REFERENCES.md §4).
pub fn oscillation_angular_frequency_two_fluid(
    dim: Dimension,
    mode: usize,
    sigma: f64,
    density: f64,
    outer_density: f64,
    radius: f64,
) -> Result<f64> {
    let n = self::mode(mode)?;
    positive("sigma", sigma)?;
    positive("density", density)?;
    non_negative("outer_density", outer_density)?;
    positive("radius", radius)?;
    let r3 = radius.powi(3);
    let omega2 = match dim {
        Dimension::Two => n * (n * n - 1.0) * sigma / ((density + outer_density) * r3),
        Dimension::Three => {
            n * (n + 1.0) * (n - 1.0) * (n + 2.0) * sigma / (((n + 1.0) * density + n * outer_density) * r3)
        }
    };
    Ok(omega2.sqrt())
}

/// Oscillation period `T_n = 2 pi / omega_n` (s) of mode `n >= 2` of a free drop (see
/// [`oscillation_angular_frequency`]); in 2D mode 2, `T = 2 pi sqrt(rho R^3 / (6 sigma))`.
pub fn oscillation_period(dim: Dimension, mode: usize, sigma: f64, density: f64, radius: f64) -> Result<f64> {
    Ok(2.0 * PI / oscillation_angular_frequency(dim, mode, sigma, density, radius)?)
}

/// Viscous damping rate `beta_n` (1/s) of the amplitude of mode `n >= 2` of a free drop with
/// weak kinematic viscosity `viscosity = nu` (m^2/s) and radius `R` (m): `2 n (n - 1) nu / R^2`
/// in 2D (derived, REFERENCES.md §4), `(n - 1)(2n + 1) nu / R^2` in 3D (Lamb). The kinetic
/// energy decays at `2 beta_n`.
pub fn damping_rate(dim: Dimension, mode: usize, viscosity: f64, radius: f64) -> Result<f64> {
    let n = self::mode(mode)?;
    positive("viscosity", viscosity)?;
    positive("radius", radius)?;
    let factor = match dim {
        Dimension::Two => 2.0 * n * (n - 1.0),
        Dimension::Three => (n - 1.0) * (2.0 * n + 1.0),
    };
    Ok(factor * viscosity / (radius * radius))
}

/// Radius (m) of the circle (2D) or sphere (3D) with the area or volume of a square or cube of
/// side `side` (m): `a / sqrt(pi)` in 2D, `a (3 / (4 pi))^(1/3)` in 3D (REFERENCES.md §4,
/// square droplet).
pub fn equivalent_radius_of_square(dim: Dimension, side: f64) -> Result<f64> {
    positive("side", side)?;
    Ok(match dim {
        Dimension::Two => side / PI.sqrt(),
        Dimension::Three => side * (3.0 / (4.0 * PI)).cbrt(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use Dimension::{Three, Two};

    fn close(x: f64, reference: f64, rel: f64) -> bool {
        ((x - reference) / reference).abs() <= rel
    }

    #[test]
    fn published_values() {
        // Zhou 2021 / PySPH oscillating rod as a free drop: R = 0.2, sigma = 1, rho = 1.
        let t = oscillation_period(Two, 2, 1.0, 1.0, 0.2).unwrap();
        assert!((t - 0.229429).abs() <= 0.6e-6, "T = {t}");
        assert!(close(t, 2.0 * PI * (0.2f64.powi(3) / 6.0).sqrt(), 1e-14));
        assert!((damping_rate(Two, 2, 0.05, 0.2).unwrap() - 5.0).abs() <= 1e-12);
        // The same rod with equal density outside: T = 0.324462.
        let w = oscillation_angular_frequency_two_fluid(Two, 2, 1.0, 1.0, 1.0, 0.2).unwrap();
        assert!((2.0 * PI / w - 0.324462).abs() <= 0.6e-6);
        // Basilisk: R = 0.1, sigma = 1, rho 1 / 1e-3: omega = 77.4210, T = 0.081156.
        let w = oscillation_angular_frequency_two_fluid(Two, 2, 1.0, 1.0, 1e-3, 0.1).unwrap();
        assert!((w - 77.4210).abs() <= 0.6e-4 && (2.0 * PI / w - 0.081156).abs() <= 0.6e-6, "{w}");
        // Water, R = 1 mm: 2D T = 9.507 ms, 3D T = 8.233 ms, 2D beta_2 = 4 1/s.
        let (sigma, rho, r) = (0.0728, 1000.0, 1e-3);
        assert!((oscillation_period(Two, 2, sigma, rho, r).unwrap() - 9.507e-3).abs() <= 0.6e-6);
        assert!((oscillation_period(Three, 2, sigma, rho, r).unwrap() - 8.233e-3).abs() <= 0.6e-6);
        assert!((damping_rate(Two, 2, 1e-6, r).unwrap() - 4.0).abs() <= 1e-12);
        assert!((damping_rate(Three, 2, 1e-6, r).unwrap() - 5.0).abs() <= 1e-12);
        // Laplace pressure: Zhou static drop 5 Pa (2D), 10 Pa (3D); SPHinXsys square 1.77245.
        assert!((laplace_pressure(Two, 1.0, 0.2).unwrap() - 5.0).abs() <= 1e-12);
        assert!((laplace_pressure(Three, 1.0, 0.2).unwrap() - 10.0).abs() <= 1e-12);
        let r_eq = equivalent_radius_of_square(Two, 1.0).unwrap();
        assert!((laplace_pressure(Two, 1.0, r_eq).unwrap() - 1.77245).abs() <= 0.6e-5);
        // Water square of side 7.5 mm: R_eq = 4.2314e-3, 17.20 Pa; cube 4.6526e-3, 31.29 Pa.
        let r2 = equivalent_radius_of_square(Two, 7.5e-3).unwrap();
        let r3 = equivalent_radius_of_square(Three, 7.5e-3).unwrap();
        assert!((r2 - 4.2314e-3).abs() <= 0.6e-7 && (r3 - 4.6526e-3).abs() <= 0.6e-7);
        assert!((laplace_pressure(Two, sigma, r2).unwrap() - 17.20).abs() <= 0.006);
        assert!((laplace_pressure(Three, sigma, r3).unwrap() - 31.29).abs() <= 0.006);
    }

    #[test]
    fn mode_formulas() {
        // 2D damping 4, 12, 24 nu/R^2 for n = 2, 3, 4; 3D 5, 14, 27.
        for (n, b2, b3) in [(2, 4.0, 5.0), (3, 12.0, 14.0), (4, 24.0, 27.0)] {
            assert!((damping_rate(Two, n, 1.0, 1.0).unwrap() - b2).abs() <= 1e-12);
            assert!((damping_rate(Three, n, 1.0, 1.0).unwrap() - b3).abs() <= 1e-12);
        }
        // Mode 2: omega^2 = 6 (2D) and 8 (3D) sigma/(rho R^3); two-fluid with no outer fluid
        // is the free drop.
        assert!(close(oscillation_angular_frequency(Two, 2, 1.0, 1.0, 1.0).unwrap(), 6f64.sqrt(), 1e-15));
        assert!(close(oscillation_angular_frequency(Three, 2, 1.0, 1.0, 1.0).unwrap(), 8f64.sqrt(), 1e-15));
        assert!(close(
            oscillation_angular_frequency(Three, 5, 0.3, 2.0, 0.7).unwrap(),
            (5.0 * 4.0 * 7.0 * 0.3 / (2.0 * 0.343f64)).sqrt(),
            1e-14
        ));
    }

    #[test]
    fn rejects_bad_parameters() {
        assert!(oscillation_period(Two, 1, 1.0, 1.0, 1.0).unwrap_err().to_string().contains("mode"));
        assert!(damping_rate(Three, 0, 1.0, 1.0).is_err());
        assert!(laplace_pressure(Two, -1.0, 1.0).unwrap_err().to_string().contains("sigma"));
        assert!(laplace_pressure(Two, 1.0, f64::NAN).is_err());
        assert!(oscillation_angular_frequency_two_fluid(Two, 2, 1.0, 1.0, -1.0, 1.0).is_err());
        assert!(oscillation_period(Three, 2, 1.0, 0.0, 1.0).is_err());
        assert!(equivalent_radius_of_square(Three, f64::INFINITY).is_err());
    }
}
