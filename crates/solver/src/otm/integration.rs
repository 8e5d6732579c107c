//! Consistent integration of the OTM nodal forces: the variationally consistent
//! integration (VCI) of Chen, Hillman & Rüter 2013 (IJNME 95:387), of the second order, on
//! the material-point sums.
//!
//! The nodal force `f_a = −Σ_p V_p σ_p ∇N_a(x_p)` is a quadrature of `−∫ σ ∇N_a dV`. It
//! gives the exact force of a constant stress and of a linear one (those of a linear and a
//! quadratic velocity, of a hydrostatic pressure) when the points integrate by parts:
//!
//! - (I0) `Σ_p V_p ∇N_a(x_p) = ∮ N_a n dΓ`,
//! - (I1) `Σ_p V_p ∇N_a(x_p) ⊗ (x_p − x_a) = −Σ_p V_p N_a(x_p) I + ∮ N_a n ⊗ (x − x_a) dΓ`.
//!
//! Points at the set-up triangles' centroids nearly do. Once a shear has slid the rows of
//! points along the rows of nodes, they no longer do. The error does not shrink with the
//! spacing; it grows with the shear strain (docs/notes/otm.md: a periodic channel at
//! Re = 4 ends 5 % off the parabola at h = D/20 and D/40, the velocity up to 13 % fast).
//!
//! The test gradients are corrected per node,
//! `∇Ñ_a(x_p) = ∇N_a(x_p) + N_a(x_p) (ξ_a + Ξ_a (x_p − x_a))`, with `ξ_a` (a vector) and
//! `Ξ_a` (a matrix) solved from (I0, I1) with zero boundary terms. For each component `i`,
//! `M [ξ_i, Ξ_i0, Ξ_i1]ᵀ = −[g_i, G_i0 + A δ_i0, G_i1 + A δ_i1]ᵀ`, where `M` is the 3×3
//! moment matrix `Σ_p V_p N_a e eᵀ` with `e = (1, x_p − x_a)`, `A = M₀₀`, `g = Σ_p V_p ∇N_a`
//! and `G = Σ_p V_p ∇N_a ⊗ (x_p − x_a)`. The boundary terms vanish except for the nodes on
//! the boundary: on the hull's faces the LME functions of every other node are zero (the
//! weak Kronecker property, Arroyo & Ortiz 2006), where the body's boundary is a face of
//! the nodes' hull; next to a concave stretch of a free surface an inner node's functions
//! reach the boundary and its (I0, I1) targets are only approximate. So the nodes on the
//! free surface and those held on a wall keep their plain gradients. Only the test
//! gradients change (a Petrov–Galerkin form). The velocity gradient and `ΔF` keep the
//! plain `∇N_a`, with their linear reproduction.
//!
//! The price: the corrected gradients no longer sum to zero at a point
//! (`Σ_a ∇Ñ_a(x_p) = Σ_a N_a (ξ_a + Ξ_a (x_p − x_a))`), so the internal forces of a
//! varying stress no longer cancel exactly and momentum is not conserved to round-off; and
//! with the pressure's forces corrected (`consistent`) the pressure–volume pair is no
//! longer energy-consistent: a Re = 40 channel diverged that way, where the viscous
//! correction alone (`consistent_viscous`) holds (docs/notes/otm.md).

use super::mesh::Point;
use nalgebra::{Matrix2, Matrix3, Vector3};

/// A node's correction of its test gradients: `(ξ_a [1/m], Ξ_a [1/m²])`.
pub type Correction = (Point, Matrix2<f64>);

/// The quadrature's moments about one node, summed over the support entries that hold it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Moments {
    /// `Σ_p V_p N_a e eᵀ`, `e = (1, x_p − x_a)`.
    m: Matrix3<f64>,
    /// `Σ_p V_p ∇N_a(x_p)`.
    g: Point,
    /// `Σ_p V_p ∇N_a(x_p) ⊗ (x_p − x_a)`.
    gd: Matrix2<f64>,
}

impl Default for Moments {
    fn default() -> Self {
        Moments { m: Matrix3::zeros(), g: Point::zeros(), gd: Matrix2::zeros() }
    }
}

impl Moments {
    /// Adds the entry of a point of volume `volume` at `d = x_p − x_a` from the node, where
    /// the node's shape function is `n` with gradient `grad`.
    pub fn add(&mut self, volume: f64, n: f64, grad: &Point, d: &Point) {
        let e = Vector3::new(1.0, d[0], d[1]);
        self.m += e * e.transpose() * (volume * n);
        self.g += grad * volume;
        self.gd += grad * d.transpose() * volume;
    }

    /// The correction that makes the corrected test gradients meet (I0) and (I1) with zero
    /// boundary terms; none (zero) when the moment matrix is singular to round-off (the
    /// node's points all on a line: `det M / (A³ s⁴) < 1e-10` with `s²` their mean squared
    /// distance from the node).
    pub fn correction(&self) -> Correction {
        let none = (Point::zeros(), Matrix2::zeros());
        let a = self.m[(0, 0)];
        let s2 = (self.m[(1, 1)] + self.m[(2, 2)]) / a;
        if !(a > 0.0 && s2 > 0.0) || self.m.determinant() < 1e-10 * a.powi(3) * s2 * s2 {
            return none;
        }
        let Some(inverse) = self.m.try_inverse() else { return none };
        let mut xi = Point::zeros();
        let mut big = Matrix2::zeros();
        for i in 0..2 {
            let mut rhs = -Vector3::new(self.g[i], self.gd[(i, 0)], self.gd[(i, 1)]);
            rhs[1 + i] -= a;
            let u = inverse * rhs;
            xi[i] = u[0];
            big[(i, 0)] = u[1];
            big[(i, 1)] = u[2];
        }
        (xi, big)
    }
}

/// The corrected test gradient `∇N_a + N_a (ξ_a + Ξ_a d)` \[1/m\] at `d = x_p − x_a`.
pub fn corrected(grad: &Point, n: f64, d: &Point, (xi, big): &Correction) -> Point {
    grad + (xi + big * d) * n
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::otm::lme::{LmeParams, shape_functions};
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// On a node lattice, points sheared off the triangles' centroids (each row of points
    /// slid by its own random amount, random volumes) miss (I0, I1) at the central node by
    /// a part in a few; the corrected gradients meet both to round-off.
    #[test]
    fn corrected_gradients_integrate_by_parts_on_sheared_points() {
        let (h, n) = (0.1, 12);
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        let nodes: Vec<Point> =
            (0..n * n).map(|k| Point::new((k % n) as f64 * h, (k / n) as f64 * h)).collect();
        let centre = nodes[(n / 2) * n + n / 2];
        let lme = LmeParams::default();
        let (mut plain, mut fixed) = (Moments::default(), Moments::default());
        let mut entries = Vec::new();
        for row in 0..2 * (n - 1) {
            let slide = rng.random_range(0.0..h);
            let y = (row / 2) as f64 * h + if row % 2 == 0 { h / 3.0 } else { 2.0 * h / 3.0 };
            for col in 0..n - 1 {
                let x = Point::new(col as f64 * h + h / 3.0 + slide, y);
                if (x - centre).norm() > 3.5 * h {
                    continue;
                }
                let volume = h * h / 2.0 * rng.random_range(0.8..1.2);
                let mut lambda = Point::zeros();
                let mut values = vec![0.0; nodes.len()];
                let mut grads = vec![Point::zeros(); nodes.len()];
                shape_functions(&x, &nodes, h, &lme, &mut lambda, &mut values, &mut grads).unwrap();
                let a = (n / 2) * n + n / 2;
                plain.add(volume, values[a], &grads[a], &(x - centre));
                entries.push((volume, values[a], grads[a], x - centre));
            }
        }
        let c = plain.correction();
        for (volume, value, grad, d) in &entries {
            fixed.add(*volume, *value, &corrected(grad, *value, d, &c), d);
        }
        let a = plain.m[(0, 0)];
        let miss = |m: &Moments| (m.g.norm() * h / a).max((m.gd + Matrix2::identity() * a).norm() / a);
        assert!(miss(&plain) > 1e-3, "the sheared points already integrate by parts: {}", miss(&plain));
        assert!(miss(&fixed) < 1e-12, "{}", miss(&fixed));
    }

    /// Collinear points give a singular moment matrix, along an axis or not (where round-off
    /// leaves its determinant just off zero): no correction, never a NaN or a huge one.
    #[test]
    fn collinear_points_leave_the_gradients_plain() {
        for direction in [Point::new(1.0, 0.0), Point::new(0.6, 0.8), Point::new(0.1, 0.3).normalize()] {
            let mut m = Moments::default();
            for k in 0..4 {
                m.add(1.0, 0.25, &Point::new(1.0, 0.0), &(direction * (0.1 * k as f64 - 0.13)));
            }
            assert_eq!(m.correction(), (Point::zeros(), Matrix2::zeros()), "{direction}");
        }
    }
}
