//! Laminar development (entrance) length from a uniform inlet (REFERENCES.md §3c).
//!
//! All functions take the Reynolds number of the channel or pipe and return the
//! development length in units of the plate spacing `H` (channel) or the diameter `D`
//! (pipe). The Durst et al. correlations are marked "recalled" in REFERENCES.md, so they are kept
//! here as formulas with their source, not as case constants.

use crate::Result;
use crate::error::non_negative;

/// Plane channel, Durst, Ray, Ünsal & Bayoumi 2005 (J. Fluids Eng. 127:1154):
/// `L_e / H = 0.631 / (1 + 0.044 Re) + 0.0442 Re`, `Re = U H / nu` (`U` mean velocity, `H`
/// plate spacing; `Re >= 0`, finite). Dimensionless.
pub fn channel_durst(reynolds: f64) -> Result<f64> {
    let re = non_negative("reynolds", reynolds)?;
    Ok(0.631 / (1.0 + 0.044 * re) + 0.0442 * re)
}

/// Plane channel, Chen 1973: `L_e / D_h = 0.315 / (1 + 0.0175 Re_Dh) + 0.011 Re_Dh` with
/// `D_h = 2H`; returned as `L_e / H` for `Re = U H / nu` (REFERENCES.md §3c cross-check).
pub fn channel_chen(reynolds: f64) -> Result<f64> {
    let re_dh = 2.0 * non_negative("reynolds", reynolds)?;
    Ok(2.0 * (0.315 / (1.0 + 0.0175 * re_dh) + 0.011 * re_dh))
}

/// Pipe, Durst et al. 2005: `L_e / D = [0.619^1.6 + (0.0567 Re)^1.6]^(1/1.6)`,
/// `Re = U D / nu` (`Re >= 0`, finite). Dimensionless.
pub fn pipe_durst(reynolds: f64) -> Result<f64> {
    let re = non_negative("reynolds", reynolds)?;
    Ok((0.619f64.powf(1.6) + (0.0567 * re).powf(1.6)).powf(1.0 / 1.6))
}

/// Pipe, classical textbook estimate `L_e / D = 0.06 Re` (White), `Re = U D / nu`.
pub fn pipe_classical(reynolds: f64) -> Result<f64> {
    Ok(0.06 * non_negative("reynolds", reynolds)?)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn table_of_references() {
        // REFERENCES.md §3c: Re, channel Durst, channel Chen, pipe Durst (3 decimals or
        // 4 significant digits as printed).
        for (re, ch, chen, pipe, tol) in [
            (1.0, 0.649, 0.653, 0.627, 5e-4),
            (10.0, 0.880, 0.907, 0.915, 5e-4),
            (50.0, 2.407, 2.429, 2.988, 5e-4),
            (100.0, 4.537, 4.540, 5.772, 5e-4),
            (500.0, 22.13, 22.03, 28.39, 5e-3),
            (1000.0, 44.21, 44.02, 56.73, 5e-3),
        ] {
            assert!(
                (channel_durst(re).unwrap() - ch).abs() <= tol,
                "channel Re = {re}: {}",
                channel_durst(re).unwrap()
            );
            assert!((channel_chen(re).unwrap() - chen).abs() <= tol, "Chen Re = {re}");
            assert!(
                (pipe_durst(re).unwrap() - pipe).abs() <= tol,
                "pipe Re = {re}: {}",
                pipe_durst(re).unwrap()
            );
            assert!((pipe_classical(re).unwrap() - 0.06 * re).abs() <= 1e-12 * re);
        }
        // CASES.md: about 0.7 D, 2 D and 17.7 D at Re = 4, 40, 400.
        for (re, le) in [(4.0, 0.7), (40.0, 2.0), (400.0, 17.7)] {
            assert!((channel_durst(re).unwrap() - le).abs() <= 0.06, "Re = {re}");
        }
        assert!((channel_durst(0.0).unwrap() - 0.631).abs() <= 1e-15);
    }

    #[test]
    fn rejects_bad_parameters() {
        assert!(channel_durst(-1.0).unwrap_err().to_string().contains("reynolds"));
        assert!(pipe_durst(f64::NAN).is_err());
        assert!(channel_chen(f64::INFINITY).is_err());
        assert!(pipe_classical(-0.5).is_err());
    }
}
