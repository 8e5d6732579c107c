//! A drop of diameter `D` hitting a flat dry wall at speed `V` (Xu 2016 §3.2; CASES.md
//! "3D cases"): dimensionless time `T = tV/D` from first contact, spread factor
//! `β = d/D` of the wetted diameter `d`.
//!
//! - Early spreading (inertial, `T ≲ 0.2`): `β = √(6T)` (Riboux & Gordillo 2014, Phys.
//!   Rev. Lett. 113:024507: the wetted radius `r/R = √(3 tV/R)`), wider than the sphere's
//!   geometric cut through the wall, `2√(T − T²)`.
//! - Maximum spread factor `β_max` from published correlations in the Weber number
//!   `We = ρV²D/σ`, the Reynolds number `Re = ρVD/μ` and the Ohnesorge number
//!   `Oh = √We/Re`; they disagree by about ±10 %, which is the band a simulation is judged
//!   against ([`beta_max_band`]).

use crate::error::positive;
use crate::{ReferenceError, Result};
use serde::{Deserialize, Serialize};

/// The dimensionless numbers of an impact.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Impact {
    /// Weber number `ρV²D/σ`.
    pub we: f64,
    /// Reynolds number `ρVD/μ`.
    pub re: f64,
}

impl Impact {
    /// The numbers of a drop of `diameter` D \[m\] at `speed` V \[m/s\] of a liquid of
    /// `density` ρ \[kg/m³\], `viscosity` μ \[Pa·s\] and `sigma` σ \[N/m\].
    pub fn new(diameter: f64, speed: f64, density: f64, viscosity: f64, sigma: f64) -> Result<Self> {
        for (name, v) in [
            ("diameter", diameter),
            ("speed", speed),
            ("density", density),
            ("viscosity", viscosity),
            ("sigma", sigma),
        ] {
            positive(name, v)?;
        }
        Ok(Self {
            we: density * speed * speed * diameter / sigma,
            re: density * speed * diameter / viscosity,
        })
    }

    /// Ohnesorge number `√We / Re = μ/√(ρσD)`.
    pub fn oh(&self) -> f64 {
        self.we.sqrt() / self.re
    }

    /// Pasandideh-Fard et al. 1996 (Phys. Fluids 8:650, eq. 6): energy balance with a
    /// viscous boundary layer, `β_max = √((We + 12) / (3(1 − cos θ) + 4 We/√Re))` for the
    /// advancing contact angle `theta` \[rad\] (0 < θ < π).
    pub fn pasandideh_fard(&self, theta: f64) -> Result<f64> {
        if !(theta > 0.0 && theta < std::f64::consts::PI) {
            return Err(ReferenceError::InvalidParameter {
                name: "theta",
                value: theta,
                rule: "must lie in (0, π)",
            });
        }
        Ok(((self.we + 12.0) / (3.0 * (1.0 - theta.cos()) + 4.0 * self.we / self.re.sqrt())).sqrt())
    }

    /// Clanet et al. 2004 (J. Fluid Mech. 517:199): `β_max = 0.9 We^¼` (the impact
    /// parameter `We Re^{−4/5}` below 1, as here).
    pub fn clanet(&self) -> f64 {
        0.9 * self.we.powf(0.25)
    }

    /// Roisman 2009 (Phys. Fluids 21:052104, eq. 30):
    /// `β_max = 0.87 Re^{1/5} − 0.40 Re^{2/5} We^{−1/2}`.
    pub fn roisman(&self) -> f64 {
        0.87 * self.re.powf(0.2) - 0.40 * self.re.powf(0.4) / self.we.sqrt()
    }

    /// Laan et al. 2014 (Phys. Rev. Applied 2:044018): `β_max = Re^{1/5} √P / (A + √P)`,
    /// `P = We Re^{−2/5}`, `A = 1.24`.
    pub fn laan(&self) -> f64 {
        let p = self.we * self.re.powf(-0.4);
        self.re.powf(0.2) * p.sqrt() / (1.24 + p.sqrt())
    }

    /// Scheller & Bousfield 1995 (AIChE J. 41:1357): `β_max = 0.61 (Re² Oh)^{0.166}`.
    pub fn scheller_bousfield(&self) -> f64 {
        0.61 * (self.re * self.re * self.oh()).powf(0.166)
    }

    /// Every correlation above, `(name, β_max)`; Pasandideh-Fard at 60°, 90° and 120°.
    pub fn correlations(&self) -> Vec<(&'static str, f64)> {
        let deg = |a: f64| a.to_radians();
        let pf = |a: f64| self.pasandideh_fard(deg(a)).unwrap_or(f64::NAN);
        vec![
            ("Pasandideh-Fard 1996, 60°", pf(60.0)),
            ("Pasandideh-Fard 1996, 90°", pf(90.0)),
            ("Pasandideh-Fard 1996, 120°", pf(120.0)),
            ("Clanet 2004", self.clanet()),
            ("Roisman 2009", self.roisman()),
            ("Laan 2014", self.laan()),
            ("Scheller & Bousfield 1995", self.scheller_bousfield()),
        ]
    }
}

/// The smallest and largest `β_max` of [`Impact::correlations`].
pub fn beta_max_band(impact: &Impact) -> (f64, f64) {
    impact
        .correlations()
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &(_, b)| (lo.min(b), hi.max(b)))
}

/// Early spreading factor `β = √(6T)` at `T = tV/D ≥ 0` (Riboux & Gordillo 2014).
pub fn early_spread(t_star: f64) -> Result<f64> {
    if t_star.is_finite() && t_star >= 0.0 {
        Ok((6.0 * t_star).sqrt())
    } else {
        Err(ReferenceError::InvalidParameter {
            name: "t_star",
            value: t_star,
            rule: "must be non-negative and finite",
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Xu 2016's drop: D = 0.5 mm, V = 2.7 m/s, water (ρ 1000, μ 1e-3, σ 0.0728).
    fn xu() -> Impact {
        Impact::new(5e-4, 2.7, 1000.0, 1e-3, 0.0728).unwrap()
    }

    /// The numbers and correlations as CASES.md evaluates them (to the digits it gives).
    #[test]
    fn xu_2016_numbers_and_correlations() {
        let i = xu();
        assert!(
            (i.we - 50.07).abs() < 0.01 && (i.re - 1350.0).abs() < 1e-9 && (i.oh() - 0.00524).abs() < 1e-5
        );
        let c = i.correlations();
        let want = [2.99, 2.71, 2.50, 2.39, 2.67, 2.43, 2.79];
        for ((name, got), want) in c.iter().zip(want) {
            assert!((got - want).abs() < 0.005, "{name}: {got} against {want}");
        }
        let (lo, hi) = beta_max_band(&i);
        assert!((lo - 2.394).abs() < 1e-3 && (hi - 2.988).abs() < 1e-3, "{lo} {hi}");
    }

    /// A holdout impact (D = 2 mm, water-like): every correlation grows with the speed.
    #[test]
    fn correlations_grow_with_weber_and_reynolds() {
        let a = Impact::new(2e-3, 1.0, 1000.0, 1e-3, 0.07).unwrap();
        let faster = Impact::new(2e-3, 2.0, 1000.0, 1e-3, 0.07).unwrap();
        for ((name, b0), (_, b1)) in a.correlations().iter().zip(faster.correlations()) {
            assert!(b1 > *b0, "{name}: {b0} → {b1}");
        }
        // Pasandideh-Fard at 90° with no viscous loss reduces to √((We + 12)/3).
        let inviscid = Impact { we: 100.0, re: 1e300 };
        assert!(
            (inviscid.pasandideh_fard(std::f64::consts::FRAC_PI_2).unwrap() - (112.0f64 / 3.0).sqrt()).abs()
                < 1e-12
        );
    }

    #[test]
    fn early_spread_and_bad_input() {
        assert!((early_spread(1.0 / 6.0).unwrap() - 1.0).abs() < 1e-15);
        assert!(early_spread(-0.1).is_err() && early_spread(f64::NAN).is_err());
        assert!(Impact::new(0.0, 1.0, 1.0, 1.0, 1.0).is_err());
        assert!(xu().pasandideh_fard(0.0).is_err() && xu().pasandideh_fard(4.0).is_err());
    }
}
