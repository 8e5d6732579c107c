//! A second-order consistent viscous Laplacian (`scheme.isph.viscous_operator: consistent`).
//!
//! The Shao–Lo operator (Qiu eq. 13) reproduces `∇²u` only where the particle moment
//! `−Σ_b V_b f_ab r_ab ⊗ r_ab` is the identity. On the cell-centred lattice with
//! `h = 1.5 Δx` it is 0.9952 I, and on a shifted (disordered) arrangement it wanders by
//! about as much again: a viscosity error that does not shrink with `Δx` (`h/Δx` is fixed),
//! which is the error floor of the periodic channel.
//!
//! This operator follows Fatehi & Manzari 2011 (Comput. Math. Appl. 61:482, §4): the
//! second-difference sum is taken with the kernel-corrected gradient subtracted, and the
//! error that gradient itself makes on a quadratic field is solved for, so the result is
//! exact for every quadratic velocity field on any arrangement with a full enough support.
//! Instead of their tensor `B̂` (which yields the Laplacian only) the same linear system is
//! solved for the whole Hessian `H_a` and its trace taken; the two are equivalent.
//!
//! With `r = r_a − r_b`, `f = W'(r)/r` (so `∇_aW_ab = f r`), `q = r² + 0.01 h²` and the
//! symmetric components `s_k = r_m r_n` (`m ≤ n`, `s'_k = s_k` on the diagonal and `2 s_k`
//! off it, so that `r r : H = s'·H`), per particle `a`:
//!
//! - `L = (−Σ f r ⊗ r)⁻¹` and `G = L Σ (u_b − u_a) f r` (Bonet & Lok 1999 eq. 43);
//! - `S = Σ (f/q)(u_a − u_b − r·G) s`;
//! - Taylor expansion: `S = A H` with `A = −½ (Q + R L M₃)`, `Q = Σ (f/q) s ⊗ s'`,
//!   `R = Σ (f/q) s ⊗ r`, `M₃ = Σ f r ⊗ s'` (the last term is `G`'s own error);
//! - `∇²u_a = tr H`, with `H = A⁻¹ S` per velocity component.
//!
//! The particle volume cancels (uniform volumes), as does any positive pair weight in `q`:
//! consistency holds for every weight because `A` and `S` share it. Where `A` or the
//! moment matrix is singular (a particle with too few neighbours, e.g. on a free surface)
//! the Shao–Lo value is used. Not symmetric: linear momentum is not conserved exactly.

use crate::error::Cause;
use crate::operators::ShaoLo;
use crate::stage::{Stage, StepContext};
use crate::state::{State, Vector};
use nalgebra::{SMatrix, SVector};
use rayon::prelude::*;

/// The symmetric index pairs `(m, n)`, `m ≤ n`, of a `D × D` tensor, the diagonal first;
/// `N = D(D+1)/2` of them.
fn sym_pairs<const D: usize, const N: usize>() -> [(usize, usize); N] {
    let mut pairs = [(0, 0); N];
    let mut k = 0;
    for m in 0..D {
        pairs[k] = (m, m);
        k += 1;
    }
    for m in 0..D {
        for n in m + 1..D {
            pairs[k] = (m, n);
            k += 1;
        }
    }
    pairs
}

/// `∇²u_a` \[1/(m s)\] of the velocity field `u` at particle `a` over its neighbours
/// (`pairs`, `nbrs`), exact for quadratic fields; falls back to the Shao–Lo value (Qiu
/// eq. 13, with the particle volume `volume` \[m^D\]) where the local system is singular.
/// `N = D(D+1)/2` (the caller picks it; sized matrices keep the loops unrolled).
fn laplacian<const D: usize, const N: usize>(
    a: usize,
    pairs: &[crate::state::Pair<D>],
    nbrs: &[u32],
    u: &[Vector<D>],
    op: ShaoLo,
    volume: f64,
) -> Vector<D> {
    let sym = sym_pairs::<D, N>();
    // Σ f r ⊗ r; Σ (u_b − u_a)_c f r per component c (column c); Q = Σ (f/q) s ⊗ s';
    // R = Σ (f/q) s ⊗ r; M₃ = Σ f r ⊗ s'; S₀ = Σ (f/q)(u_a − u_b)_c s (column c); and the
    // Shao–Lo sum Σ (u_a − u_b) f r²/q for the fallback.
    let mut m = SMatrix::<f64, D, D>::zeros();
    let mut grad = SMatrix::<f64, D, D>::zeros();
    let mut q = SMatrix::<f64, N, N>::zeros();
    let mut r_t = SMatrix::<f64, N, D>::zeros();
    let mut m3 = SMatrix::<f64, D, N>::zeros();
    let mut s0 = SMatrix::<f64, N, D>::zeros();
    let mut shao_lo = Vector::<D>::zeros();
    for (p, &b) in pairs.iter().zip(nbrs) {
        let r = p.r_ab;
        let fq = p.f / op.denominator(p);
        let du = u[a] - u[b as usize];
        let s = SVector::<f64, N>::from_fn(|k, _| r[sym[k].0] * r[sym[k].1]);
        let s_prime = SVector::<f64, N>::from_fn(|k, _| if sym[k].0 == sym[k].1 { s[k] } else { 2.0 * s[k] });
        let fr = r * p.f;
        let fqs = s * fq;
        m += fr * r.transpose();
        grad -= fr * du.transpose();
        shao_lo += du * (fq * p.r2());
        q += fqs * s_prime.transpose();
        r_t += fqs * r.transpose();
        s0 += fqs * du.transpose();
        m3 += fr * s_prime.transpose();
    }
    let fallback = shao_lo * (2.0 * volume);
    let Some(l) = (-m).try_inverse() else {
        return fallback;
    };
    // A = −½ (Q + R L M₃); S = S₀ − R G with G = L Σ (u_b − u_a) f r.
    let a_mat = (q + r_t * l * m3) * -0.5;
    let Some(a_inv) = a_mat.try_inverse() else {
        return fallback;
    };
    let h: SMatrix<f64, N, D> = a_inv * (s0 - r_t * (l * grad));
    let lap = Vector::<D>::from_fn(|c, _| (0..D).map(|k| h[(k, c)]).sum());
    if lap.iter().all(|v| v.is_finite()) { lap } else { fallback }
}

/// Qiu eq. 4 viscous part with the consistent Laplacian of this module:
/// `u*_a = u^n_a + Δt ν ∇²u^n_a`, evaluated at the advected positions `r*`.
#[derive(Debug)]
pub struct ConsistentViscosity {
    /// Kinematic viscosity ν = μ/ρ \[m²/s\].
    pub nu: f64,
}

impl<const D: usize, O> Stage<D, O> for ConsistentViscosity {
    fn name(&self) -> &'static str {
        "viscosity"
    }

    fn run(&mut self, s: &mut State<D>, _own: &mut O, ctx: &StepContext) -> Result<(), Cause> {
        let shao_lo = ShaoLo::new(s.h);
        let c = ctx.dt * self.nu;
        let (list, pairs, u_old, volume) = (&s.neighbours, &s.pairs, &s.particles.u_old, s.volume);
        s.particles.u[..s.particles.fluid].par_iter_mut().enumerate().with_min_len(128).for_each(|(a, u)| {
            let (lo, hi) = (list.offsets[a], list.offsets[a + 1]);
            let (pairs, nbrs) = (&pairs[lo..hi], &list.indices[lo..hi]);
            // Scenes are 2D or 3D (scene validation): N = 3 or 6.
            let lap = if D == 2 {
                laplacian::<D, 3>(a, pairs, nbrs, u_old, shao_lo, volume)
            } else {
                laplacian::<D, 6>(a, pairs, nbrs, u_old, shao_lo, volume)
            };
            *u = u_old[a] + lap * c;
        });
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kernel::{CubicSpline, Scaled};
    use crate::state::Pair;

    /// The neighbours of the origin on a jittered lattice of spacing `dx` with `h = 1.5 dx`:
    /// their pairs and the field `phi` sampled at them (index 0 is the origin itself).
    fn stencil(phi: impl Fn(f64, f64) -> f64, jitter: f64) -> (Vec<Pair<2>>, Vec<u32>, Vec<Vector<2>>, f64) {
        let dx = 0.1;
        let kernel = Scaled::<CubicSpline, 2>::new(1.5 * dx);
        let mut pairs = Vec::new();
        let mut nbrs = Vec::new();
        let mut u = vec![Vector::<2>::new(phi(0.0, 0.0), 2.0 * phi(0.0, 0.0))];
        let mut seed = 12345u64;
        let mut rand = || {
            seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        for i in -4i32..=4 {
            for j in -4i32..=4 {
                if i == 0 && j == 0 {
                    continue;
                }
                let (x, y) = ((i as f64 + jitter * rand()) * dx, (j as f64 + jitter * rand()) * dx);
                let r2 = x * x + y * y;
                if r2.sqrt() >= kernel.support {
                    continue;
                }
                // r_ab = r_a − r_b with a at the origin.
                pairs.push(Pair { r_ab: Vector::<2>::new(-x, -y), f: kernel.grad_factor(r2.sqrt()) });
                nbrs.push(u.len() as u32);
                u.push(Vector::<2>::new(phi(x, y), 2.0 * phi(x, y)));
            }
        }
        (pairs, nbrs, u, dx * dx)
    }

    #[test]
    fn the_laplacian_of_a_quadratic_field_is_exact_on_a_disordered_arrangement() {
        let phi = |x: f64, y: f64| 0.3 + 2.0 * x - y + x * x + 3.0 * x * y - 2.0 * y * y;
        for jitter in [0.0, 0.3, 0.6] {
            let (pairs, nbrs, u, v) = stencil(phi, jitter);
            let lap = laplacian::<2, 3>(0, &pairs, &nbrs, &u, ShaoLo::new(0.15), v);
            // ∇²φ = 2 − 4 = −2; the second component is 2φ.
            assert!((lap[0] + 2.0).abs() < 1e-9, "jitter {jitter}: {}", lap[0]);
            assert!((lap[1] + 4.0).abs() < 1e-9, "jitter {jitter}: {}", lap[1]);
        }
    }

    #[test]
    fn the_shao_lo_sum_is_off_where_the_consistent_one_is_not() {
        // The check above is sharp: the Shao–Lo fallback itself misses on the same stencil.
        let phi = |x: f64, y: f64| x * x + y * y;
        let (pairs, nbrs, u, v) = stencil(phi, 0.6);
        let op = ShaoLo::new(0.15);
        let mut shao_lo = 0.0;
        for (p, &b) in pairs.iter().zip(&nbrs) {
            shao_lo += (u[0][0] - u[b as usize][0]) * op.coefficient(p, 2.0 * v, 1.0);
        }
        assert!((shao_lo - 4.0).abs() > 0.02, "Shao–Lo {shao_lo}");
        let lap = laplacian::<2, 3>(0, &pairs, &nbrs, &u, op, v);
        assert!((lap[0] - 4.0).abs() < 1e-9, "{}", lap[0]);
    }

    #[test]
    fn the_three_dimensional_laplacian_of_a_quadratic_field_is_exact() {
        let phi = |x: Vector<3>| {
            1.0 + x[0] - 2.0 * x[2] + x[0] * x[0] + 0.5 * x[1] * x[1] - x[2] * x[2] + 2.0 * x[0] * x[1]
                - x[1] * x[2]
        };
        let dx = 0.1;
        let kernel = Scaled::<CubicSpline, 3>::new(1.5 * dx);
        let (mut pairs, mut nbrs) = (Vec::new(), Vec::new());
        let mut u = vec![Vector::<3>::repeat(phi(Vector::zeros()))];
        let mut k = 0u32;
        for i in -3i32..=3 {
            for j in -3i32..=3 {
                for l in -3i32..=3 {
                    k += 1;
                    let wobble = |n: u32| 0.3 * ((n as f64 * 0.7548).sin());
                    let x = Vector::<3>::new(
                        (i as f64 + wobble(3 * k)) * dx,
                        (j as f64 + wobble(3 * k + 1)) * dx,
                        (l as f64 + wobble(3 * k + 2)) * dx,
                    );
                    let r = x.norm();
                    if (i, j, l) == (0, 0, 0) || r >= kernel.support {
                        continue;
                    }
                    pairs.push(Pair { r_ab: -x, f: kernel.grad_factor(r) });
                    nbrs.push(u.len() as u32);
                    u.push(Vector::<3>::repeat(phi(x)));
                }
            }
        }
        let lap = laplacian::<3, 6>(0, &pairs, &nbrs, &u, ShaoLo { eta2: 1e-4 }, dx.powi(3));
        // ∇²φ = 2 + 1 − 2 = 1 in every component.
        assert!((lap - Vector::<3>::repeat(1.0)).norm() < 1e-9, "{lap:?}");
    }

    #[test]
    fn the_three_dimensional_pairs_cover_the_six_components() {
        assert_eq!(sym_pairs::<3, 6>(), [(0, 0), (1, 1), (2, 2), (0, 1), (0, 2), (1, 2)]);
    }
}
