//! Pair formulas used by more than one stage, named and cited once, with `∇_aW_ab = f r_ab`
//! from the pair cache ([`Pair`]): the Shao–Lo Laplacian's pair coefficient with its
//! regularisation ([`ShaoLo`]), the velocity divergence in its difference and
//! kernel-corrected forms ([`divergence`], [`corrected_divergence`]), and the moment
//! matrix of the kernel-gradient correction ([`moment`]), which the `neighbours` stage
//! inverts once per step, in the pass that makes the pairs, for every stage that corrects
//! a gradient ([`crate::stages::neighbours::Neighbours::inverting_moments`]: the corrected
//! divergence, the corrected pressure gradient, the shifting's Taylor correction).
//!
//! Each function evaluates its formula in one fixed order of operations, the order the
//! stages used before it was shared, so that moving a stage onto it changes no bit.

use crate::fields::Matrix;
use crate::state::{Pair, Vector};

/// η²/h² of the Shao–Lo regularisation `r² + η²`, η² = 0.01 h² (Shao & Lo 2003 eq. 11;
/// Qiu 2013 eq. 13; Morris, Fox & Zhu 1997 eq. 8): keeps the pair factor finite as
/// r → 0.
pub const SHAO_LO_ETA2: f64 = 0.01;

/// The Shao–Lo Laplacian `L(φ)_a = Σ_b 2 V_b (r_ab·∇_aW_ab)/(r² + η²) (φ_a − φ_b)` (Shao &
/// Lo 2003 eq. 11; Qiu 2013 eqs. 12–13 with CASES.md erratum 2), and the `r² + η²` it
/// shares with the Monaghan–Cleary viscosity and Monaghan's artificial viscosity.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShaoLo {
    /// η² = 0.01 h² \[m²\].
    pub eta2: f64,
}

impl ShaoLo {
    /// The regularisation of smoothing length `h` \[m\].
    pub fn new(h: f64) -> Self {
        Self { eta2: SHAO_LO_ETA2 * h * h }
    }

    /// `r² + η²` \[m²\].
    #[inline(always)]
    pub fn denominator<const D: usize>(&self, p: &Pair<D>) -> f64 {
        p.r2() + self.eta2
    }

    /// The pair coefficient `scale (r_ab·∇_aW_ab) / (divisor (r² + η²))` =
    /// `scale f r² / (divisor (r² + η²))`: `scale = 2 V` and `divisor = ρ` give the PPE's
    /// `−L/ρ` (with the sign in `scale`), `scale = Δt ν 2 V` the viscous operator's.
    #[inline(always)]
    pub fn coefficient<const D: usize>(&self, p: &Pair<D>, scale: f64, divisor: f64) -> f64 {
        let r2 = p.r2();
        scale * p.f * r2 / (divisor * (r2 + self.eta2))
    }
}

/// The velocity divergence at particle `a` in the difference form of Qiu 2013 eq. 10,
/// `V Σ_b (u_b − u_a)·∇_aW_ab`, over `a`'s `pairs` and neighbours `nbrs`.
#[inline]
pub fn divergence<const D: usize>(
    u: &[Vector<D>],
    a: usize,
    pairs: &[Pair<D>],
    nbrs: &[u32],
    volume: f64,
) -> f64 {
    let mut div = 0.0;
    for (p, &b) in pairs.iter().zip(nbrs) {
        div += (u[b as usize] - u[a]).dot(&p.r_ab) * p.f;
    }
    volume * div
}

/// The velocity gradient sum `G_a = Σ_b V_b (u_b − u_a) ⊗ ∇_aW_ab`.
#[inline]
pub fn velocity_gradient_sum<const D: usize>(
    u: &[Vector<D>],
    a: usize,
    (pairs, nbrs): (&[Pair<D>], &[u32]),
    volume: f64,
) -> Matrix<D> {
    let mut g = Matrix::<D>::zeros();
    for (p, &b) in pairs.iter().zip(nbrs) {
        g += (u[b as usize] - u[a]) * (p.r_ab * (volume * p.f)).transpose();
    }
    g
}

/// The kernel-gradient corrected divergence (Bonet & Lok 1999): `tr(G_a L_a)` with
/// [`velocity_gradient_sum`] `G_a` and the correction `l` = `L_a` (the inverse of the
/// [`moment`] matrix); exact for linear velocity fields on any arrangement, a free surface
/// included. Where the moment matrix is singular (`None`: an isolated particle) it falls
/// back to `tr G_a`, the difference form.
#[inline]
pub fn corrected_divergence<const D: usize>(
    u: &[Vector<D>],
    a: usize,
    row: (&[Pair<D>], &[u32]),
    volume: f64,
    l: Option<&Matrix<D>>,
) -> f64 {
    let g = velocity_gradient_sum(u, a, row, volume);
    match l {
        Some(l) => (g * l).trace(),
        None => g.trace(),
    }
}

/// The moment matrix of the kernel-gradient correction (Bonet & Lok 1999 eq. 43),
/// `M_a = Σ_b V_b (r_b − r_a) ⊗ ∇_aW_ab = −Σ_b r_ab ⊗ V f r_ab` (symmetric; ≈ I in the
/// bulk of a lattice); `L_a = M_a⁻¹` corrects a gradient: `L_a Σ_b V_b (φ_b ∓ φ_a) ∇_aW_ab`
/// (dimensionless).
#[inline]
pub fn moment<const D: usize>(pairs: &[Pair<D>], volume: f64) -> Matrix<D> {
    let mut m = Matrix::<D>::zeros();
    for p in pairs {
        let grad = p.r_ab * (volume * p.f);
        m -= p.r_ab * grad.transpose();
    }
    m
}
