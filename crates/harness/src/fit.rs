//! Observed order of convergence: least-squares fit of `log e = log C + p log dx`.

/// A fitted power law `e ≈ C dx^p`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PowerLaw {
    /// The observed order `p`.
    pub order: f64,
    /// The constant `C`.
    pub constant: f64,
    /// Number of points used.
    pub points: usize,
}

impl PowerLaw {
    /// `C dx^p`.
    pub fn eval(&self, dx: f64) -> f64 {
        self.constant * dx.powf(self.order)
    }
}

/// Fits `e = C dx^p` by least squares in log-log over the points where both `dx` and `e`
/// are finite and positive. `None` with fewer than two such points or when all spacings
/// coincide.
pub fn fit_power_law(dx: &[f64], err: &[f64]) -> Option<PowerLaw> {
    let pts: Vec<(f64, f64)> = dx
        .iter()
        .zip(err)
        .filter(|(d, e)| d.is_finite() && **d > 0.0 && e.is_finite() && **e > 0.0)
        .map(|(d, e)| (d.ln(), e.ln()))
        .collect();
    if pts.len() < 2 {
        return None;
    }
    let n = pts.len() as f64;
    let mx = pts.iter().map(|p| p.0).sum::<f64>() / n;
    let my = pts.iter().map(|p| p.1).sum::<f64>() / n;
    let sxx: f64 = pts.iter().map(|p| (p.0 - mx).powi(2)).sum();
    let sxy: f64 = pts.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    if sxx <= f64::EPSILON * n {
        return None;
    }
    let order = sxy / sxx;
    Some(PowerLaw { order, constant: (my - order * mx).exp(), points: pts.len() })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn recovers_second_order() {
        let dx = [0.04, 0.02, 0.01, 0.005];
        let e: Vec<f64> = dx.iter().map(|d| 3.0 * d * d).collect();
        let fit = fit_power_law(&dx, &e).unwrap();
        assert!((fit.order - 2.0).abs() < 1e-12, "{}", fit.order);
        assert!((fit.constant - 3.0).abs() < 1e-10);
        assert_eq!(fit.points, 4);
        assert!((fit.eval(0.1) - 0.03).abs() < 1e-12);
        assert_eq!(format!("{:.3}", fit.order), "2.000");
    }

    #[test]
    fn two_points_give_the_pairwise_order() {
        let fit = fit_power_law(&[0.04, 0.02], &[0.02, 0.01]).unwrap();
        assert!((fit.order - 1.0).abs() < 1e-12);
    }

    #[test]
    fn skips_bad_points_and_refuses_degenerate_data() {
        let fit = fit_power_law(&[0.04, 0.02, 0.01], &[0.016, f64::NAN, 0.001]).unwrap();
        assert!((fit.order - 2.0).abs() < 1e-12);
        assert_eq!(fit.points, 2);
        assert!(fit_power_law(&[0.04], &[0.1]).is_none());
        assert!(fit_power_law(&[0.04, 0.04], &[0.1, 0.2]).is_none());
        assert!(fit_power_law(&[0.04, 0.02], &[0.0, 0.1]).is_none());
    }
}
