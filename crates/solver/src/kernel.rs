//! Smoothing kernels as traits of associated functions (monomorphised in the hot loops).
//!
//! A kernel is `W(r, h) = σ_D / h^D · f(q)`, `q = r / h`, with compact support `q < 2`.
//! [`Kernel`] gives the dimensionless shape `f`, its derivative and the normalisation;
//! [`Scaled`] binds it to a smoothing length and dimension and precomputes the factors.

use nalgebra::SVector;
use std::f64::consts::PI;
use std::marker::PhantomData;

/// A kernel shape: `W = sigma(D) / h^D · f(q)`.
pub trait Kernel: Copy + Send + Sync + std::fmt::Debug + 'static {
    /// Name used in scene files and outputs.
    const NAME: &'static str;
    /// Support radius in units of h (W = 0 for q ≥ SUPPORT).
    const SUPPORT: f64;
    /// Normalisation σ_D (D = 2 or 3), so that ∫ W dV = 1.
    fn sigma(dim: usize) -> f64;
    /// Shape f(q) (dimensionless).
    fn f(q: f64) -> f64;
    /// Derivative df/dq.
    fn df(q: f64) -> f64;
}

/// Cubic B-spline (Monaghan & Lattanzio 1985; Qiu 2013 eq. 8):
/// `f = 1 − 3/2 q² + 3/4 q³` (q < 1), `¼ (2 − q)³` (1 ≤ q < 2);
/// σ₂ = 10/(7π), σ₃ = 1/π.
#[derive(Debug, Clone, Copy, Default)]
pub struct CubicSpline;

impl Kernel for CubicSpline {
    const NAME: &'static str = "cubic_spline";
    const SUPPORT: f64 = 2.0;
    #[inline]
    fn sigma(dim: usize) -> f64 {
        match dim {
            2 => 10.0 / (7.0 * PI),
            3 => 1.0 / PI,
            _ => 2.0 / 3.0,
        }
    }
    /// `f(q) = ¼ (2 − q)₊³ − (1 − q)₊³` (= `1 − 1.5 q² + 0.75 q³` for q < 1,
    /// `¼ (2 − q)³` for 1 ≤ q < 2): written with `max` instead of branches on q, whose
    /// outcome is random from pair to pair (a mispredicted branch per pair cost more than
    /// the two polynomials).
    #[inline(always)]
    fn f(q: f64) -> f64 {
        let (a, b) = ((2.0 - q).max(0.0), (1.0 - q).max(0.0));
        0.25 * a * a * a - b * b * b
    }
    /// `f'(q) = −¾ (2 − q)₊² + 3 (1 − q)₊²` (branch-free, as [`Self::f`]).
    #[inline(always)]
    fn df(q: f64) -> f64 {
        let (a, b) = ((2.0 - q).max(0.0), (1.0 - q).max(0.0));
        3.0 * b * b - 0.75 * a * a
    }
}

/// Wendland C2 (Wendland 1995; Dehnen & Aly 2012 with support 2h):
/// `f = (1 − q/2)⁴ (2q + 1)` for q < 2; σ₂ = 7/(4π), σ₃ = 21/(16π).
#[derive(Debug, Clone, Copy, Default)]
pub struct WendlandC2;

impl Kernel for WendlandC2 {
    const NAME: &'static str = "wendland_c2";
    const SUPPORT: f64 = 2.0;
    #[inline]
    fn sigma(dim: usize) -> f64 {
        match dim {
            2 => 7.0 / (4.0 * PI),
            3 => 21.0 / (16.0 * PI),
            // The 1D Wendland C2 is a different polynomial; the solver runs D = 2, 3 only.
            _ => f64::NAN,
        }
    }
    #[inline(always)]
    fn f(q: f64) -> f64 {
        if q < 2.0 {
            let t = 1.0 - 0.5 * q;
            let t2 = t * t;
            t2 * t2 * (2.0 * q + 1.0)
        } else {
            0.0
        }
    }
    #[inline(always)]
    fn df(q: f64) -> f64 {
        if q < 2.0 {
            let t = 1.0 - 0.5 * q;
            -5.0 * q * t * t * t
        } else {
            0.0
        }
    }
}

/// A kernel bound to a smoothing length h \[m\] and dimension D, with precomputed factors.
#[derive(Debug, Clone, Copy)]
pub struct Scaled<K: Kernel, const D: usize> {
    /// Smoothing length h \[m\].
    pub h: f64,
    inv_h: f64,
    w_norm: f64,
    dw_norm: f64,
    /// Support radius \[m\].
    pub support: f64,
    _k: PhantomData<K>,
}

impl<K: Kernel, const D: usize> Scaled<K, D> {
    /// Binds `K` to smoothing length `h` \[m\].
    pub fn new(h: f64) -> Self {
        let w_norm = K::sigma(D) / h.powi(D as i32);
        Self { h, inv_h: 1.0 / h, w_norm, dw_norm: w_norm / h, support: K::SUPPORT * h, _k: PhantomData }
    }

    /// W(r) \[1/m^D\].
    #[inline(always)]
    pub fn w(&self, r: f64) -> f64 {
        self.w_norm * K::f(r * self.inv_h)
    }

    /// dW/dr \[1/m^(D+1)\] (≤ 0).
    #[inline(always)]
    pub fn dw(&self, r: f64) -> f64 {
        self.dw_norm * K::df(r * self.inv_h)
    }

    /// `F(r) = (dW/dr) / r`, so that `∇_a W_ab = F(r) r_ab` (zero at r = 0).
    #[inline(always)]
    pub fn grad_factor(&self, r: f64) -> f64 {
        if r > 0.0 { self.dw(r) / r } else { 0.0 }
    }

    /// ∇_a W_ab for `r_ab = r_a − r_b` \[1/m^(D+1)\].
    #[inline(always)]
    pub fn grad(&self, r_ab: &SVector<f64, D>) -> SVector<f64, D> {
        r_ab * self.grad_factor(r_ab.norm())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// ∫ W dV by the midpoint rule on a fine lattice.
    fn integral<K: Kernel, const D: usize>(h: f64) -> f64 {
        let k = Scaled::<K, D>::new(h);
        let n = 160i64;
        let s = k.support;
        let step = 2.0 * s / n as f64;
        let mut sum = 0.0;
        let mut idx = [0i64; D];
        loop {
            let x = SVector::<f64, D>::from_fn(|i, _| -s + (idx[i] as f64 + 0.5) * step);
            sum += k.w(x.norm());
            let mut d = 0;
            loop {
                idx[d] += 1;
                if idx[d] < n {
                    break;
                }
                idx[d] = 0;
                d += 1;
                if d == D {
                    return sum * step.powi(D as i32);
                }
            }
        }
    }

    macro_rules! for_kernels_and_dims {
        ($name:ident, $body:ident) => {
            #[test]
            fn $name() {
                $body::<CubicSpline, 2>();
                $body::<CubicSpline, 3>();
                $body::<WendlandC2, 2>();
                $body::<WendlandC2, 3>();
            }
        };
    }

    fn normalised<K: Kernel, const D: usize>() {
        let i = integral::<K, D>(0.37);
        assert!((i - 1.0).abs() < 2e-3, "{} D={D}: ∫W = {i}", K::NAME);
    }
    for_kernels_and_dims!(kernels_are_normalised, normalised);

    fn derivative_matches_finite_difference<K: Kernel, const D: usize>() {
        let k = Scaled::<K, D>::new(0.5);
        for i in 1..80 {
            let r = i as f64 * 0.0125;
            let e = 1e-6;
            let fd = (k.w(r + e) - k.w(r - e)) / (2.0 * e);
            assert!((fd - k.dw(r)).abs() < 1e-6 * (1.0 + k.dw(r).abs()), "{} r={r}", K::NAME);
        }
        assert!(k.w(k.support).abs() < 1e-15 && k.dw(k.support).abs() < 1e-15);
    }
    for_kernels_and_dims!(gradient_is_consistent, derivative_matches_finite_difference);

    /// Σ_b V_b (x_b − x_a) ⊗ ∇_a W_ab = I on a full lattice (first-moment consistency).
    fn lattice_moment<K: Kernel, const D: usize>() {
        let dx = 0.1;
        let k = Scaled::<K, D>::new(1.5 * dx);
        let n = 4i64;
        let mut m = nalgebra::SMatrix::<f64, D, D>::zeros();
        let mut idx = [-n; D];
        loop {
            let x = SVector::<f64, D>::from_fn(|i, _| idx[i] as f64 * dx);
            m += x * k.grad(&(-x)).transpose() * dx.powi(D as i32);
            let mut d = 0;
            loop {
                idx[d] += 1;
                if idx[d] <= n {
                    break;
                }
                idx[d] = -n;
                d += 1;
                if d == D {
                    let err = (m - nalgebra::SMatrix::<f64, D, D>::identity()).norm();
                    assert!(err < 0.03, "{} D={D}: moment error {err}", K::NAME);
                    return;
                }
            }
        }
    }
    for_kernels_and_dims!(first_moment_on_lattice, lattice_moment);

    proptest! {
        #[test]
        fn gradient_is_antisymmetric_and_points_inward(
            x in prop::array::uniform3(-1.0f64..1.0), h in 0.2f64..1.0
        ) {
            let k = Scaled::<CubicSpline, 3>::new(h);
            let r = SVector::<f64, 3>::from(x);
            let g1 = k.grad(&r);
            let g2 = k.grad(&(-r));
            prop_assert!((g1 + g2).norm() <= 1e-12 * (1.0 + g1.norm()));
            prop_assert!(r.dot(&g1) <= 0.0);
            let kw = Scaled::<WendlandC2, 2>::new(h);
            let r2 = SVector::<f64, 2>::new(x[0], x[1]);
            prop_assert!((kw.grad(&r2) + kw.grad(&(-r2))).norm() <= 1e-12 * (1.0 + kw.grad(&r2).norm()));
            prop_assert!(kw.w(r2.norm()) >= 0.0);
        }
    }
}
