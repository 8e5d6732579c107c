//! The Tait equation of state (Monaghan 1994, J. Comput. Phys. 110:399, eq. 3.3; after
//! Batchelor 1967): `p = B ((ρ/ρ₀)^γ − 1)`, `B = ρ₀ c₀² / γ`, and its inverse.

/// Tait equation of state with reference density ρ₀ \[kg/m³\], sound speed c₀ \[m/s\] and
/// exponent γ.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Tait {
    /// Reference density ρ₀ \[kg/m³\] (p = 0 there).
    pub rho0: f64,
    /// Stiffness B = ρ₀ c₀² / γ \[Pa\].
    pub b: f64,
    /// Exponent γ.
    pub gamma: f64,
    /// γ when it is an integer (then `powi`, about 5 times cheaper than `powf`).
    gamma_int: Option<i32>,
}

impl Tait {
    /// The equation for ρ₀ \[kg/m³\], c₀ \[m/s\] and γ.
    pub fn new(rho0: f64, c0: f64, gamma: f64) -> Self {
        let gamma_int = (gamma.fract() == 0.0 && gamma.abs() < 64.0).then_some(gamma as i32);
        Self { rho0, b: rho0 * c0 * c0 / gamma, gamma, gamma_int }
    }

    /// p(ρ) = B ((ρ/ρ₀)^γ − 1) \[Pa\].
    #[inline(always)]
    pub fn pressure(&self, rho: f64) -> f64 {
        let r = rho / self.rho0;
        let rg = match self.gamma_int {
            Some(g) => r.powi(g),
            None => r.powf(self.gamma),
        };
        self.b * (rg - 1.0)
    }

    /// ρ(p) = ρ₀ (1 + p/B)^(1/γ) \[kg/m³\] (NaN below p = −B, where no density fits).
    #[inline]
    pub fn density(&self, p: f64) -> f64 {
        let base = 1.0 + p / self.b;
        if base < 0.0 { f64::NAN } else { self.rho0 * base.powf(1.0 / self.gamma) }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn inverse_and_stiffness() {
        let eos = Tait::new(1000.0, 100.0, 7.0);
        assert!((eos.b - 1000.0 * 1e4 / 7.0).abs() < 1e-6);
        assert!(eos.pressure(1000.0).abs() < 1e-9);
        for p in [-1e5, 0.0, 3.0e5, 5.0e6] {
            let rho = eos.density(p);
            assert!((eos.pressure(rho) - p).abs() <= 1e-9 * eos.b, "{p} -> {rho}");
        }
        // Linearised: dp/dρ = c₀² at ρ₀.
        let d = 1e-6;
        let slope = (eos.pressure(1000.0 + d) - eos.pressure(1000.0 - d)) / (2.0 * d);
        assert!((slope / 1e4 - 1.0).abs() < 1e-6, "{slope}");
        // A non-integer exponent takes the powf path and agrees.
        let e2 = Tait::new(1000.0, 100.0, 7.0 + 1e-12);
        assert!((e2.pressure(1010.0) - eos.pressure(1010.0)).abs() < 1e-3);
        assert!(eos.density(-2.0 * eos.b).is_nan());
    }
}
