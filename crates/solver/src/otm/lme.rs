//! Local max-entropy (LME) shape functions (Arroyo & Ortiz 2006, IJNME 65:2167; OTM.md
//! "Local max-entropy shape functions"): the nodal interpolation of the OTM scheme.
//!
//! At a point `x` with nodes `x_a`, `p_a(x) = exp(−β|x − x_a|² + λ*·(x − x_a)) / Z(x, λ*)`,
//! `Z = Σ_b exp(−β|x − x_b|² + λ*·(x − x_b))`, where `λ* = argmin_λ log Z` (A&O eq. 19):
//! the condition `∇_λ log Z = r(λ) = Σ p_a (x − x_a) = 0` is the reproduction of linear
//! fields. `log Z` is convex in `λ`, so Newton's method with the Hessian
//! `J = Σ p_a (x − x_a) ⊗ (x − x_a) − r ⊗ r` (A&O eq. 23) and a backtracking line search
//! on `log Z` converges from any start while `x` lies inside the convex hull of its nodes;
//! outside it `log Z` has no minimum and `|λ|` grows without bound, which is reported as
//! [`LmeError::OutsideHull`], never as NaN. The gradient is `∇p_a = −p_a J⁻¹ (x − x_a)`
//! (A&O eq. 26). Locality `β = γ / h²` with `h` the local nodal spacing.
//!
//! No maintained Rust crate provides LME shape functions (OTM.md), hence this module.

use nalgebra::{SMatrix, SVector};

/// Parameters of the shape functions (faer's params / info / error triple).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LmeParams {
    /// Locality `γ_LME` (dimensionless, > 0): `β = γ / h²`; 1.5 is common (OTM.md).
    pub gamma: f64,
    /// Newton stops when `|r| ≤ tolerance · h`.
    pub tolerance: f64,
    /// Newton iterations before giving up.
    pub max_iterations: usize,
}

impl Default for LmeParams {
    fn default() -> Self {
        LmeParams { gamma: 1.5, tolerance: 1e-13, max_iterations: 100 }
    }
}

impl LmeParams {
    /// `β = γ / h²` \[1/m²\] for the nodal spacing `h` \[m\].
    pub fn beta(&self, h: f64) -> f64 {
        self.gamma / (h * h)
    }

    /// The support radius \[m\] beyond which `exp(−β r²) < tol`: `h √(−ln tol / γ)`
    /// (4.16 h / 3.03 h / 1.86 h for γ = 0.8 / 1.5 / 4 at tol = 1e-6, OTM.md).
    pub fn cutoff(&self, h: f64, tol: f64) -> f64 {
        h * (-tol.ln() / self.gamma).sqrt()
    }
}

/// How a solve went.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LmeInfo {
    /// Newton iterations taken.
    pub iterations: usize,
    /// The final `|r| / h`.
    pub residual: f64,
}

/// Why no shape functions exist at a point.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum LmeError {
    /// The point lies outside the convex hull of its nodes (or on its boundary, where the
    /// minimiser is at infinity): `log Z` has no minimum.
    #[error(
        "point {point:?} m lies outside the convex hull of its {nodes} nodes (|λ| h reached {lambda_h:.3e}, residual {residual:.3e} h)"
    )]
    OutsideHull {
        /// The point \[m\].
        point: Vec<f64>,
        /// Nodes it was given.
        nodes: usize,
        /// `|λ| h` when the solve stopped.
        lambda_h: f64,
        /// `|r| / h` when it stopped.
        residual: f64,
    },
    /// The point or its nodes are not finite.
    #[error("point {point:?} m: the shape functions are not finite (a non-finite position)")]
    NotFinite {
        /// The point \[m\].
        point: Vec<f64>,
    },
    /// No node was given.
    #[error("point {point:?} m has no nodes")]
    NoNodes {
        /// The point \[m\].
        point: Vec<f64>,
    },
}

/// `|r| / h` below which a Newton iteration that no longer halves the residual has reached
/// round-off (OTM.md's stopping tolerance).
const STALL: f64 = 1e-10;

/// `|λ| h` beyond which the point counts as outside the hull: the weights then differ by
/// `exp(|λ| h)` across one spacing, far beyond any interior solution (|λ| h ≲ 2 γ there).
const LAMBDA_H_MAX: f64 = 200.0;

/// `log Z(λ)` and the weights `w_a = exp(f_a − max f)` (unnormalised `p_a`) into `w`.
fn log_z<const D: usize>(
    x: &SVector<f64, D>,
    nodes: &[SVector<f64, D>],
    beta: f64,
    lambda: &SVector<f64, D>,
    w: &mut [f64],
) -> f64 {
    let mut max = f64::NEG_INFINITY;
    for (wa, xa) in w.iter_mut().zip(nodes) {
        let d = x - xa;
        *wa = -beta * d.norm_squared() + lambda.dot(&d);
        max = max.max(*wa);
    }
    let mut sum = 0.0;
    for wa in w.iter_mut() {
        *wa = (*wa - max).exp();
        sum += *wa;
    }
    max + sum.ln()
}

/// `r = Σ p_a (x − x_a)` and `J = Σ p_a (x − x_a) ⊗ (x − x_a) − r ⊗ r` with `p` normalised.
fn residual_and_hessian<const D: usize>(
    x: &SVector<f64, D>,
    nodes: &[SVector<f64, D>],
    p: &[f64],
) -> (SVector<f64, D>, SMatrix<f64, D, D>) {
    let mut r = SVector::<f64, D>::zeros();
    let mut j = SMatrix::<f64, D, D>::zeros();
    for (pa, xa) in p.iter().zip(nodes) {
        let d = x - xa;
        r += d * *pa;
        j += d * d.transpose() * *pa;
    }
    (r, j - r * r.transpose())
}

/// The shape functions of `nodes` at `x` into `values` and their gradients \[1/m\] into
/// `gradients` (both of `nodes.len()`), for the nodal spacing `h` \[m\]. `lambda` is the
/// start (the previous step's `λ*`, or zero) and returns `λ*` \[1/m\]. Allocation-free.
///
/// # Panics
/// When `values` or `gradients` is not as long as `nodes` (a caller's bug).
pub fn shape_functions<const D: usize>(
    x: &SVector<f64, D>,
    nodes: &[SVector<f64, D>],
    h: f64,
    params: &LmeParams,
    lambda: &mut SVector<f64, D>,
    values: &mut [f64],
    gradients: &mut [SVector<f64, D>],
) -> Result<LmeInfo, LmeError> {
    assert!(values.len() == nodes.len() && gradients.len() == nodes.len(), "one value and gradient per node");
    let point = || x.iter().copied().collect::<Vec<f64>>();
    if nodes.is_empty() {
        return Err(LmeError::NoNodes { point: point() });
    }
    let beta = params.beta(h);
    let outside = |lambda: &SVector<f64, D>, res: f64| LmeError::OutsideHull {
        point: point(),
        nodes: nodes.len(),
        lambda_h: lambda.norm() * h,
        residual: res,
    };
    let mut f = log_z(x, nodes, beta, lambda, values);
    let mut iterations = 0;
    let mut previous = f64::INFINITY;
    loop {
        let sum: f64 = values.iter().sum();
        values.iter_mut().for_each(|w| *w /= sum);
        let (r, j) = residual_and_hessian(x, nodes, values);
        let res = r.norm() / h;
        if !res.is_finite() {
            return Err(LmeError::NotFinite { point: point() });
        }
        // Converged; or stalled at round-off (|r| below 1e-10 h, OTM.md's tolerance, and no
        // longer halving), which many nodes' sums can reach before 1e-13 h.
        let stalled = res <= STALL && res > 0.5 * previous;
        previous = res;
        if res <= params.tolerance || stalled {
            // ∇p_a = −p_a J⁻¹ (x − x_a) (A&O eq. 26).
            let j_inv = j.try_inverse().ok_or_else(|| outside(lambda, res))?;
            for ((g, pa), xa) in gradients.iter_mut().zip(values.iter()).zip(nodes) {
                *g = -(j_inv * (x - xa)) * *pa;
            }
            return Ok(LmeInfo { iterations, residual: res });
        }
        if iterations >= params.max_iterations || lambda.norm() * h > LAMBDA_H_MAX {
            return Err(outside(lambda, res));
        }
        iterations += 1;
        // Newton step; where J is not positive definite (nodes around x nearly collinear)
        // on J + |r| h I, the safeguard of OTM.md in consistent units.
        let step = j
            .cholesky()
            .or_else(|| (j + SMatrix::<f64, D, D>::identity() * (r.norm() * h)).cholesky())
            .map(|c| -c.solve(&r))
            .ok_or_else(|| outside(lambda, res))?;
        // Backtracking on the convex log Z: halve until it decreases enough (Armijo,
        // c = 1e-4), or at all where the change is at round-off level and log Z cannot tell
        // steps apart any more.
        let slope = r.dot(&step);
        let round_off = 1e-13 * (1.0 + f.abs());
        let mut t = 1.0;
        loop {
            let trial = *lambda + step * t;
            let ft = log_z(x, nodes, beta, &trial, values);
            if ft <= f + 1e-4 * t * slope || ft - f <= round_off || t < 1e-12 {
                *lambda = trial;
                f = ft;
                break;
            }
            t *= 0.5;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// A jittered lattice of `n^D` nodes of spacing `h` (±0.3 h).
    fn jittered<const D: usize>(n: usize, h: f64, rng: &mut ChaCha8Rng) -> Vec<SVector<f64, D>> {
        let total = n.pow(D as u32);
        (0..total)
            .map(|mut i| {
                SVector::<f64, D>::from_fn(|_, _| {
                    let k = i % n;
                    i /= n;
                    (k as f64 + rng.random_range(-0.3..0.3)) * h
                })
            })
            .collect()
    }

    /// Partition of unity, linear reproduction, Σ ∇p_a = 0 and Σ ∇p_a ⊗ x_a = I to 1e-12 at
    /// random points inside jittered node sets, in a few Newton steps.
    fn consistency<const D: usize>(n: usize, gamma: f64) {
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        let h = 0.1;
        let nodes = jittered::<D>(n, h, &mut rng);
        let params = LmeParams { gamma, ..LmeParams::default() };
        let mut values = vec![0.0; nodes.len()];
        let mut gradients = vec![SVector::<f64, D>::zeros(); nodes.len()];
        for _ in 0..20 {
            // Well inside: away from the jittered hull by two spacings.
            let x = SVector::<f64, D>::from_fn(|_, _| rng.random_range(2.0 * h..(n as f64 - 3.0) * h));
            let mut lambda = SVector::<f64, D>::zeros();
            let info =
                shape_functions(&x, &nodes, h, &params, &mut lambda, &mut values, &mut gradients).unwrap();
            assert!(info.iterations <= 8, "{info:?}");
            let sum: f64 = values.iter().sum();
            assert!((sum - 1.0).abs() < 1e-12, "partition of unity: {sum}");
            let reproduced: SVector<f64, D> = values.iter().zip(&nodes).map(|(p, xa)| xa * *p).sum();
            assert!(
                (reproduced - x).norm() < 1e-12 * h * n as f64,
                "linear reproduction: {}",
                (reproduced - x).norm()
            );
            let grad_sum: SVector<f64, D> = gradients.iter().sum();
            assert!(grad_sum.norm() * h < 1e-12, "Σ ∇p_a = 0: {grad_sum}");
            // Σ ∇p_a ⊗ x_a, with x_a taken from x (the same sum, as Σ ∇p_a = 0, without the
            // round-off of coordinates far from the origin).
            let mut identity = SMatrix::<f64, D, D>::zeros();
            for (g, xa) in gradients.iter().zip(&nodes) {
                identity += g * (xa - x).transpose();
            }
            assert!(
                (identity - SMatrix::<f64, D, D>::identity()).norm() < 1e-12,
                "Σ ∇p_a ⊗ x_a = I: {identity}"
            );
            // A warm start from λ* converges at once.
            let again =
                shape_functions(&x, &nodes, h, &params, &mut lambda, &mut values, &mut gradients).unwrap();
            assert_eq!(again.iterations, 0);
        }
    }

    #[test]
    fn consistent_on_jittered_nodes_2d() {
        consistency::<2>(8, 1.5);
        consistency::<2>(8, 0.8);
        consistency::<2>(8, 4.0);
    }

    #[test]
    fn consistent_on_jittered_nodes_3d() {
        consistency::<3>(6, 1.5);
    }

    /// The gradient is the derivative: central differences of p_a agree to 1e-6.
    #[test]
    fn gradients_match_finite_differences() {
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        let h = 0.1;
        let nodes = jittered::<2>(7, h, &mut rng);
        let params = LmeParams::default();
        let n = nodes.len();
        let at = |x: SVector<f64, 2>| {
            let (mut v, mut g, mut l) = (vec![0.0; n], vec![SVector::<f64, 2>::zeros(); n], SVector::zeros());
            shape_functions(&x, &nodes, h, &params, &mut l, &mut v, &mut g).unwrap();
            (v, g)
        };
        let x = SVector::<f64, 2>::new(0.31, 0.27);
        let (_, g) = at(x);
        let e = 1e-6;
        for k in 0..2 {
            let mut dx = SVector::<f64, 2>::zeros();
            dx[k] = e;
            let (plus, _) = at(x + dx);
            let (minus, _) = at(x - dx);
            for a in 0..n {
                let fd = (plus[a] - minus[a]) / (2.0 * e);
                assert!((fd - g[a][k]).abs() < 1e-6 / h, "node {a}, axis {k}: {fd} against {}", g[a][k]);
            }
        }
    }

    /// A point outside its nodes' convex hull is a typed error, never NaN.
    #[test]
    fn outside_the_hull_is_an_error() {
        let nodes: Vec<SVector<f64, 2>> =
            [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0], [1.0, 1.0]].iter().map(|p| SVector::from(*p)).collect();
        let mut values = vec![0.0; 4];
        let mut gradients = vec![SVector::zeros(); 4];
        let mut lambda = SVector::zeros();
        let params = LmeParams::default();
        let x = SVector::<f64, 2>::new(1.2, 0.5);
        let e =
            shape_functions(&x, &nodes, 1.0, &params, &mut lambda, &mut values, &mut gradients).unwrap_err();
        assert!(matches!(e, LmeError::OutsideHull { nodes: 4, .. }), "{e}");
        assert!(e.to_string().contains("outside the convex hull"), "{e}");
        let none = shape_functions::<2>(&x, &[], 1.0, &params, &mut lambda, &mut [], &mut []).unwrap_err();
        assert!(matches!(none, LmeError::NoNodes { .. }));
        // Inside the same square: fine, and the weights are finite.
        let mut lambda = SVector::zeros();
        let inside = SVector::<f64, 2>::new(0.9, 0.5);
        shape_functions(&inside, &nodes, 1.0, &params, &mut lambda, &mut values, &mut gradients).unwrap();
        assert!(values.iter().all(|v| v.is_finite() && *v >= 0.0));
    }

    #[test]
    fn cutoff_radii_of_otm_md() {
        let r = |gamma: f64| LmeParams { gamma, ..LmeParams::default() }.cutoff(1.0, 1e-6);
        assert!((r(0.8) - 4.16).abs() < 0.01 && (r(1.5) - 3.03).abs() < 0.01 && (r(4.0) - 1.86).abs() < 0.01);
    }
}
