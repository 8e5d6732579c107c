//! The MPS operators of Lan 2022 (eqs. 5–9), each with its own radius and the n0 (and λ)
//! of that radius on the initial lattice ([`LatticeSums`]). `r_ij = r_j − r_i`, d the
//! dimension:
//! - number density `n_i = Σ_j w(|r_ij|)` (eq. 9);
//! - gradient `⟨∇φ⟩_i = (d/n0) Σ_j (φ_j − φ_i) r_ij w_ij/|r_ij|²` (eq. 6);
//! - divergence `⟨∇·Π⟩_i = (d/n0) Σ_j (Π_j − Π_i)·r_ij w_ij/|r_ij|²` (eq. 7);
//! - Laplacian `⟨∇²φ⟩_i = (2d/(λ n0)) Σ_j (φ_j − φ_i) w_ij` (eq. 8).
//!
//! The sums take pair coefficients ([`Operators::gradient_weight`],
//! [`Operators::laplacian_weight`]) so that the stages fuse them into their own loops.

use super::weight::{LatticeSums, Weight};
use crate::fields::{Matrix, Vector};
use crate::scene::MpsRadii;

/// The operator set of a scene: radii in metres and their lattice constants.
#[derive(Debug, Clone, Copy)]
pub struct Operators<W: Weight, const D: usize> {
    /// Number-density radius \[m\].
    pub re_n: f64,
    /// Gradient and divergence radius \[m\].
    pub re_g: f64,
    /// Laplacian radius \[m\].
    pub re_l: f64,
    /// Lattice sums of the number-density radius.
    pub number_density: LatticeSums,
    /// Lattice sums of the gradient radius.
    pub gradient: LatticeSums,
    /// Lattice sums of the Laplacian radius.
    pub laplacian: LatticeSums,
    weight: std::marker::PhantomData<W>,
}

impl<W: Weight, const D: usize> Operators<W, D> {
    /// The operators of `radii` (in units of `l0`) on the lattice of spacing `l0` \[m\].
    pub fn new(radii: MpsRadii, l0: f64) -> Self {
        let (re_n, re_g, re_l) = (radii.number_density * l0, radii.gradient * l0, radii.laplacian * l0);
        Self {
            re_n,
            re_g,
            re_l,
            number_density: LatticeSums::of::<W, D>(re_n, l0),
            gradient: LatticeSums::of::<W, D>(re_g, l0),
            laplacian: LatticeSums::of::<W, D>(re_l, l0),
            weight: std::marker::PhantomData,
        }
    }

    /// The largest radius \[m\]: the neighbour lists must reach it.
    pub fn reach(&self) -> f64 {
        self.re_n.max(self.re_g).max(self.re_l)
    }

    /// The number-density weight `w(r)` of a pair at distance `r` \[m\].
    #[inline(always)]
    pub fn density_weight(&self, r: f64) -> f64 {
        W::w(r, self.re_n)
    }

    /// `(d/n0) w(r)/r²` \[1/m²\]: a pair's factor in the gradient and divergence.
    #[inline(always)]
    pub fn gradient_weight(&self, r: f64) -> f64 {
        if r >= self.re_g || r == 0.0 {
            return 0.0;
        }
        D as f64 / self.gradient.n0 * W::w(r, self.re_g) / (r * r)
    }

    /// `(2d/(λ n0)) w(r)` \[1/m²\]: a pair's factor in the Laplacian.
    #[inline(always)]
    pub fn laplacian_weight(&self, r: f64) -> f64 {
        2.0 * D as f64 / (self.laplacian.lambda * self.laplacian.n0) * W::w(r, self.re_l)
    }

    /// The gradient `(d/n0) Σ (φ_j − φ_i) r_ij w/|r|²` of pairs `(r_ij, φ_j − φ_i)`.
    pub fn gradient(&self, pairs: impl Iterator<Item = (Vector<D>, f64)>) -> Vector<D> {
        pairs.fold(Vector::zeros(), |g, (r, dphi)| g + r * (dphi * self.gradient_weight(r.norm())))
    }

    /// The divergence `(d/n0) Σ (Π_j − Π_i)·r_ij w/|r|²` of pairs `(r_ij, Π_j − Π_i)`.
    pub fn divergence(&self, pairs: impl Iterator<Item = (Vector<D>, Vector<D>)>) -> f64 {
        pairs.map(|(r, dv)| dv.dot(&r) * self.gradient_weight(r.norm())).sum()
    }

    /// The Laplacian `(2d/(λ n0)) Σ (φ_j − φ_i) w` of pairs `(r_ij, φ_j − φ_i)`.
    pub fn laplacian(&self, pairs: impl Iterator<Item = (Vector<D>, f64)>) -> f64 {
        pairs.map(|(r, dphi)| dphi * self.laplacian_weight(r.norm())).sum()
    }

    /// The moment `(d/n0) Σ w r⊗r/|r|²` of pairs `r_ij`, whose inverse is the corrective
    /// matrix of the gradient (identity on the full lattice).
    pub fn moment(&self, pairs: impl Iterator<Item = Vector<D>>) -> Matrix<D> {
        pairs.fold(Matrix::zeros(), |m, r| m + r * r.transpose() * self.gradient_weight(r.norm()))
    }
}

#[cfg(test)]
mod tests {
    use super::super::weight::{Classic, Lan};
    use super::*;

    /// The lattice points within `reach` of the origin, as `r_ij`.
    fn lattice<const D: usize>(l0: f64, reach: f64) -> Vec<Vector<D>> {
        let mut out = Vec::new();
        super::super::weight::for_each_offset::<D>(reach, l0, |r| out.push(r));
        out
    }

    /// On the lattice, `⟨∇²|r|²⟩ = 2d` and `⟨∇x⟩ = e_x` hold exactly for any radius, at
    /// any particle `r_i` (not only the origin: the linear part of `|r|²` sums to zero).
    fn check_lattice_identities<W: Weight, const D: usize>(radii: MpsRadii) {
        let l0 = 0.004;
        let ops = Operators::<W, D>::new(radii, l0);
        let pairs = lattice::<D>(l0, ops.reach());
        let x_i = Vector::<D>::from_fn(|k, _| 0.37 + 0.11 * k as f64);
        let r2 = |x: Vector<D>| x.norm_squared();
        let lap = ops.laplacian(pairs.iter().map(|&r| (r, r2(x_i + r) - r2(x_i))));
        assert!((lap - 2.0 * D as f64).abs() < 1e-9, "⟨∇²|r|²⟩ = {lap} in {D}D, radii {radii:?}");
        let grad = ops.gradient(pairs.iter().map(|&r| (r, r[0])));
        let e_x = Vector::<D>::from_fn(|k, _| if k == 0 { 1.0 } else { 0.0 });
        assert!((grad - e_x).norm() < 1e-12, "⟨∇x⟩ = {grad:?} in {D}D");
        // The divergence of the field r is d, and the moment is the identity.
        let div = ops.divergence(pairs.iter().map(|&r| (r, r)));
        assert!((div - D as f64).abs() < 1e-12, "⟨∇·r⟩ = {div} in {D}D");
        let m = ops.moment(pairs.iter().copied());
        assert!((m - Matrix::<D>::identity()).norm() < 1e-12, "moment {m:?}");
    }

    #[test]
    fn lattice_identities_hold_in_2d_and_3d() {
        let lan = MpsRadii { number_density: 2.1, gradient: 2.1, laplacian: 4.1 };
        let classic = MpsRadii { number_density: 2.1, gradient: 2.1, laplacian: 3.1 };
        check_lattice_identities::<Lan, 2>(lan);
        check_lattice_identities::<Lan, 3>(lan);
        check_lattice_identities::<Classic, 2>(classic);
        check_lattice_identities::<Classic, 3>(classic);
        // A holdout radius no case uses.
        check_lattice_identities::<Lan, 2>(MpsRadii { number_density: 2.6, gradient: 3.3, laplacian: 3.7 });
    }

    /// The number density of an interior lattice particle is n0.
    #[test]
    fn number_density_of_the_lattice_is_n0() {
        let ops = Operators::<Lan, 2>::new(crate::scene::MpsWeight::Lan.default_radii(), 0.01);
        let n: f64 = lattice::<2>(0.01, ops.reach()).iter().map(|r| ops.density_weight(r.norm())).sum();
        assert!((n - ops.number_density.n0).abs() < 1e-12);
    }
}
