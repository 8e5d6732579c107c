//! Particle shifting (Qiu 2013 §2.6) with the Taylor correction of the velocity.
//!
//! - Xu et al. 2009 (Qiu eqs. 20–21): `δr_a = C Δt u_max Σ_b (r̄_a² / r_ab²) n_ab`,
//!   `n_ab = r_ab / r_ab`, `r̄_a` the mean neighbour distance (neighbours within the support).
//!   Smooth variant (`smooth: true`): every term of the sum and of the mean is weighted by
//!   `w_ab = (1 − r_ab²/(2h)²)²`, `r̄_a = Σ w r / Σ w`, so that the shift is continuous in
//!   the positions; the published law jumps when a pair crosses the support.
//! - Lind et al. 2012 (Fickian): `δr_a = −A h |u_a| Δt ∇C_a`, `∇C_a = Σ_b V_b ∇_aW_ab`.
//!
//! Free surface: both formulas push particles near the surface outward (their support
//! is truncated: nothing pulls from outside). The shift is therefore scaled by
//! `clamp((div r − t) / (D − t), 0, 1)` with `t` the free-surface threshold (the
//! DualSPHysics treatment, REFERENCES.md §5): free-surface particles, which carry the
//! p = 0 condition, are not shifted, the rows below them partly, the bulk in full. Removing
//! only the normal component on surface particles (Lind et al. 2012) was measured too: the
//! first interior rows were then still pushed into the surface layer and the drop's centre
//! pressure at Δx = 0.02 ended 12 % off instead of 4 % (docs/notes/shifting.md).
//!
//! Cap: a shift longer than [`MAX_SHIFT`] Δx is shortened to it. Xu's `1/r²` sum grows
//! without bound when two particles come close, and where particles are squeezed (the
//! corner of a uniform inlet and a no-slip wall, a large Δt) one shift threw a particle
//! across the wall and out of the channel; a healthy flow shifts by far less (the drop at
//! Δx = 0.02: below 1e-3 Δx per step), so the cap only acts where the law breaks down.
//!
//! Velocity (Xu 2009; Qiu §2.6): `u_a ← u_a + (∇u)_a δr_a` with the kernel-gradient
//! corrected velocity gradient `∇u_a = G_a M_a⁻¹`, `G_a = Σ_b V_b (u_b − u_a) ⊗ ∇_aW_ab`,
//! `M_a = Σ_b V_b (r_b − r_a) ⊗ ∇_aW_ab` (Bonet & Lok 1999), which stays first-order
//! accurate near the surface where the kernel support is truncated (where `M` is near
//! singular, with few neighbours, the uncorrected `G` is used).

use crate::error::Cause;
use crate::kernel::{Kernel, Scaled};
use crate::stage::{Stage, StepContext};
use crate::state::{State, Vector};
use nalgebra::SMatrix;
use rayon::prelude::*;

/// Largest shift per step, in units of Δx.
pub const MAX_SHIFT: f64 = 0.2;

/// Which shifting law.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Law {
    /// Xu 2009 with coefficient C, smooth at the support or as published.
    Xu {
        /// C.
        coefficient: f64,
        /// Weights `(1 − r²/(2h)²)²` on the sum and the mean distance.
        smooth: bool,
    },
    /// Lind 2012 Fickian with coefficient A.
    Fickian(f64),
}

impl Law {
    /// The law a scene's `shifting` option asks for (None: no shifting stage), for either
    /// scheme.
    pub fn of(spec: crate::scene::Shifting) -> Option<Law> {
        match spec {
            crate::scene::Shifting::None => None,
            crate::scene::Shifting::Xu { coefficient, smooth } => Some(Law::Xu { coefficient, smooth }),
            crate::scene::Shifting::Fickian { coefficient } => Some(Law::Fickian(coefficient)),
        }
    }
}

/// The shifting stage. It runs after the position update and reuses the step's pair
/// geometry from r*: the particles have moved by `Δt (uⁿ⁺¹ − uⁿ)/2` since, about 1e-5 Δx
/// in the drop, far below what the shift's heuristic resolves, and recomputing the
/// geometry would cost a pair pass (docs/notes/performance.md).
#[derive(Debug)]
pub struct Shifting<K: Kernel, const D: usize> {
    law: Law,
    threshold: f64,
    kernel: Scaled<K, D>,
    /// Read the step's kernel-gradient correction from `State::moments` instead of
    /// computing it in this stage's pair pass.
    stored_moments: bool,
    shift: Vec<Vector<D>>,
    du: Vec<Vector<D>>,
}

impl<K: Kernel, const D: usize> Shifting<K, D> {
    /// A stage applying `law` with `kernel`; `threshold` is the free-surface threshold on
    /// `div r`.
    pub fn new(law: Law, kernel: Scaled<K, D>, threshold: f64) -> Self {
        Self { law, threshold, kernel, stored_moments: false, shift: Vec::new(), du: Vec::new() }
    }

    /// Reads the kernel-gradient correction `L_a` that this step's `neighbours` stage
    /// inverted ([`crate::stages::neighbours::Neighbours::inverting_moments`]) instead of
    /// inverting the same matrix again (the same arithmetic: the same bits).
    pub fn reading_moments(mut self) -> Self {
        self.stored_moments = true;
        self
    }
}

impl<K: Kernel, const D: usize, O> Stage<D, O> for Shifting<K, D> {
    fn name(&self) -> &'static str {
        "shifting"
    }

    fn run(&mut self, s: &mut State<D>, _own: &mut O, ctx: &StepContext) -> Result<(), Cause> {
        let n = s.particles.len();
        self.shift.resize(n, Vector::zeros());
        self.du.resize(n, Vector::zeros());
        let u_max = s.max_speed();
        let (k, law, dt, v, dom) = (self.kernel, self.law, ctx.dt, s.volume, s.domain);
        let (u, list, pairs, moments) = (&s.particles.u, &s.neighbours, &s.pairs, &s.moments);
        let (div_r, threshold, cap) = (&s.particles.div_r, self.threshold, MAX_SHIFT * s.dx);
        let (xu, smooth) = match law {
            Law::Xu { smooth, .. } => (true, smooth),
            Law::Fickian(_) => (false, false),
        };
        let inv_support2 = 1.0 / (k.support * k.support);
        let stored = self.stored_moments;
        self.shift.par_iter_mut().zip(self.du.par_iter_mut()).enumerate().with_min_len(128).for_each(
            |(a, (shift, du))| {
                let mut grad_c = Vector::<D>::zeros();
                let mut g = SMatrix::<f64, D, D>::zeros();
                let mut m = SMatrix::<f64, D, D>::zeros();
                let mut xu_sum = Vector::<D>::zeros();
                let mut r_sum = 0.0;
                let mut w_sum = 0.0;
                let (lo, hi) = (list.offsets[a], list.offsets[a + 1]);
                for (p, &b) in pairs[lo..hi].iter().zip(&list.indices[lo..hi]) {
                    let r2 = p.r2();
                    if r2 == 0.0 {
                        continue;
                    }
                    let grad = p.r_ab * (v * p.f);
                    grad_c += grad;
                    g += (u[b as usize] - u[a]) * grad.transpose();
                    if !stored {
                        // The moment matrix (`operators::moment`) in this pass.
                        m -= p.r_ab * grad.transpose();
                    }
                    if xu {
                        // n_ab / r_ab² (r̄² applied after the loop).
                        let r = r2.sqrt();
                        if smooth {
                            let w = (1.0 - r2 * inv_support2).max(0.0).powi(2);
                            xu_sum += p.r_ab * (w / (r2 * r));
                            r_sum += w * r;
                            w_sum += w;
                        } else {
                            xu_sum += p.r_ab / (r2 * r);
                            r_sum += r;
                            w_sum += 1.0;
                        }
                    }
                }
                let mut d = match law {
                    Law::Xu { coefficient: c, .. } if w_sum > 0.0 => {
                        let rbar = r_sum / w_sum;
                        xu_sum * (c * dt * u_max * rbar * rbar)
                    }
                    Law::Xu { .. } => Vector::zeros(),
                    Law::Fickian(c) => -grad_c * (c * k.h * u[a].norm() * dt),
                };
                // Near the surface: scale by (div r − t)/(D − t) in [0, 1]; surface particles
                // (div r < t) are not shifted.
                d *= ((div_r[a] - threshold) / (D as f64 - threshold)).clamp(0.0, 1.0);
                let len = d.norm();
                if len > cap {
                    d *= cap / len;
                }
                // M ≈ I in the bulk; fall back to G where M is near singular (few
                // neighbours: |L| ≥ 10), with the step's correction L = M⁻¹.
                let l = if stored { moments[a] } else { m.try_inverse() };
                let grad_u = match l {
                    Some(l) if l.norm() < 10.0 => g * l,
                    _ => g,
                };
                *shift = d;
                *du = grad_u * d;
            },
        );
        let periodic = dom.is_periodic();
        let (shift, du) = (&self.shift, &self.du);
        s.particles.x[..n]
            .par_iter_mut()
            .zip(s.particles.u[..n].par_iter_mut())
            .enumerate()
            .with_min_len(512)
            .for_each(|(a, (x, u))| {
                *x += shift[a];
                *u += du[a];
                if periodic {
                    dom.wrap(x);
                }
            });
        Ok(())
    }
}
