//! Surface tension of a single fluid as the Young–Laplace dynamic condition of the
//! projection scheme (`fluid.surface_tension_model: young_laplace`, ISPH only).
//!
//! With no fluid outside, the stress balance at a free surface is the Young–Laplace
//! condition `p_s = σ κ` (Laplace's formula, Landau & Lifshitz, Fluid Mechanics §61, with no
//! outer pressure; the normal viscous stress is neglected, as for the p = 0 free surface of Qiu
//! 2013, eq. 16). The projection already imposes a Dirichlet value on the free-surface
//! particles (`free_surface` stage, Qiu eq. 16); this stage replaces its 0 by `σ κ`, so the
//! surface force enters through the pressure gradient and no body force is needed.
//!
//! - Normal: the colour gradient `n_a = Σ_b V_b ∇_aW_ab` (pointing into the fluid), used
//!   where `|n_a| > ε`, `ε = fluid.surface_tension_threshold / h`; `n̂ = n/|n|`.
//! - Curvature `κ_a = −∇_s·n̂_a` (the surface divergence of the inward normal) on the
//!   free-surface particles, from a weighted least-squares tangential gradient over the
//!   free-surface neighbours `b` with a normal: with `P_a = I − n̂_a ⊗ n̂_a` and
//!   `t_ab = P_a (r_b − r_a)`, `G_a = Σ_b W_ab (n̂_b − n̂_a) ⊗ t_ab`,
//!   `A_a = n̂_a ⊗ n̂_a + Σ_b W_ab t_ab ⊗ t_ab`, `κ_a = −tr(G_a A_a⁻¹)` (exact for a normal
//!   field linear along the surface; `G_a n̂_a = 0`, so the added `n̂_a ⊗ n̂_a` only makes
//!   `A_a` invertible). Only surface particles enter: the colour gradient of the particles
//!   beneath is O(disorder/h) with a random direction once the particles move, and a
//!   corrected volume divergence over all particles with `|n| > ε` (Bonet & Lok 1999) was
//!   biased by it (measured: σκ 20 % high on the relaxed static drop at Δx = R/40).
//! - Smoothing: `κ̄_a = Σ_b W_ab κ_b / Σ_b W_ab` over the free-surface particles with a
//!   curvature (Shepard filter), which removes the particle-scale noise of the second
//!   derivative of the colour.
//! - Offset: the free-surface particles sit half a spacing inside the surface of the
//!   volume they represent; the surface there is parallel to theirs, with curvature
//!   `κ_s = κ̄ / (1 + κ̄ Δx / (2(D − 1)))` (`κ̄` sums the D − 1 principal curvatures: a
//!   circle of radius 1/κ̄, a sphere of radius 2/κ̄, grown by Δx/2), after clamping
//!   `|κ̄| ≤ (D − 1)/Δx` (no radius of curvature below one spacing is resolved).
//!
//! The free-surface Dirichlet value is `p_a = σ κ_s,a` \[Pa\]; the PPE moves it to the
//! right-hand side (`isph::projection::PpeAssemble::surface_pressure`).

use crate::error::Cause;
use crate::kernel::{Kernel, Scaled};
use crate::stage::{Stage, StepContext};
use crate::state::{State, Vector};
use nalgebra::SMatrix;
use rayon::prelude::*;

/// The Young–Laplace free-surface pressure stage (see the module documentation).
#[derive(Debug)]
pub struct SurfacePressure<K: Kernel, const D: usize> {
    /// σ \[N/m\].
    sigma: f64,
    /// ε \[1/m\].
    eps: f64,
    kernel: Scaled<K, D>,
    /// Unit normals into the fluid (zero where `|n| ≤ ε`).
    normal: Vec<Vector<D>>,
    /// Curvature of the free-surface particles \[1/m\] (NaN elsewhere or unmeasured).
    kappa: Vec<f64>,
    /// Add `σ κ` to the free-surface pressure already set (by
    /// `stages::surface_extrapolation`) instead of replacing it.
    adds: bool,
}

impl<K: Kernel, const D: usize> SurfacePressure<K, D> {
    /// A stage with coefficient `sigma` \[N/m\] and the normal threshold
    /// `ε = threshold / h`.
    pub fn new(sigma: f64, threshold: f64, kernel: Scaled<K, D>) -> Self {
        Self { sigma, eps: threshold / kernel.h, kernel, normal: Vec::new(), kappa: Vec::new(), adds: false }
    }

    /// The same stage adding `σ κ` to the free-surface pressure set before it.
    pub fn adding(self) -> Self {
        Self { adds: true, ..self }
    }
}

/// Unit colour-gradient normals `n̂_a` (into the fluid) of the fluid particles, zero where
/// `|Σ_b V ∇_aW_ab| ≤ eps`.
fn unit_normals<const D: usize>(s: &State<D>, eps: f64, out: &mut Vec<Vector<D>>) {
    let (list, pairs, v) = (&s.neighbours, &s.pairs, s.volume);
    out.resize(s.particles.fluid, Vector::zeros());
    out.par_iter_mut().enumerate().with_min_len(256).for_each(|(a, n)| {
        let row = &pairs[list.offsets[a]..list.offsets[a + 1]];
        let sum: Vector<D> = row.iter().map(|p| p.r_ab * (p.f * v)).sum();
        let l = sum.norm();
        *n = if l > eps { sum / l } else { Vector::zeros() };
    });
}

/// Curvature `κ_a = −∇_s·n̂_a` of free-surface particle `a` by a weighted least-squares
/// surface gradient over its free-surface neighbours with a normal (see the module
/// documentation); None without a normal or with a singular fit.
fn surface_curvature<K: Kernel, const D: usize>(
    s: &State<D>,
    normal: &[Vector<D>],
    kernel: &Scaled<K, D>,
    a: usize,
) -> Option<f64> {
    let na = normal[a];
    if na.norm_squared() < 0.25 {
        return None;
    }
    let (list, pairs) = (&s.neighbours, &s.pairs);
    let (lo, hi) = (list.offsets[a], list.offsets[a + 1]);
    let proj = SMatrix::<f64, D, D>::identity() - na * na.transpose();
    let mut g = SMatrix::<f64, D, D>::zeros();
    let mut m = na * na.transpose();
    for (p, &b) in pairs[lo..hi].iter().zip(&list.indices[lo..hi]) {
        let b = b as usize;
        if b >= s.particles.fluid || !s.particles.free_surface[b] {
            continue;
        }
        let Some(nb) = normal.get(b).copied().filter(|n| n.norm_squared() > 0.25) else {
            continue;
        };
        // Tangential separation r_b − r_a projected on the tangent space of a.
        let t = proj * (-p.r_ab);
        let w = kernel.w(p.r2().sqrt());
        g += (nb - na) * t.transpose() * w;
        m += t * t.transpose() * w;
    }
    let mi = m.try_inverse()?;
    Some(-(g * mi).trace())
}

impl<K: Kernel, const D: usize, O> Stage<D, O> for SurfacePressure<K, D> {
    fn name(&self) -> &'static str {
        "surface_pressure"
    }

    fn run(&mut self, s: &mut State<D>, _own: &mut O, _ctx: &StepContext) -> Result<(), Cause> {
        let nf = s.particles.fluid;
        unit_normals(s, self.eps, &mut self.normal);
        let normal = &self.normal;
        let state = &*s;
        let raw: Vec<f64> = (0..nf)
            .into_par_iter()
            .with_min_len(256)
            .map(|a| {
                if state.particles.free_surface[a] {
                    surface_curvature(state, normal, &self.kernel, a).unwrap_or(f64::NAN)
                } else {
                    f64::NAN
                }
            })
            .collect();
        shepard(s, &self.kernel, &raw, &mut self.kappa);
        // κ is the sum of the D − 1 principal curvatures: each at most 1/Δx, each radius
        // grown by Δx/2 to the surface.
        let (sigma, half, m) = (self.sigma, 0.5 * s.dx, (D - 1) as f64);
        let (kappa, fs, adds) = (&self.kappa, &s.particles.free_surface, self.adds);
        s.particles.p[..nf].par_iter_mut().enumerate().with_min_len(1024).for_each(|(a, p)| {
            if fs[a] {
                let k = kappa[a].clamp(-0.5 * m / half, 0.5 * m / half);
                let surface = if k.is_finite() { sigma * k / (1.0 + k * half / m) } else { 0.0 };
                *p = if adds { *p + surface } else { surface };
            }
        });
        Ok(())
    }
}

/// Shepard filter of `raw` over the particles where it is finite:
/// `out_a = Σ_b W_ab raw_b / Σ_b W_ab` (b = a included; NaN where `raw_a` is NaN).
fn shepard<K: Kernel, const D: usize>(s: &State<D>, kernel: &Scaled<K, D>, raw: &[f64], out: &mut Vec<f64>) {
    let (list, pairs) = (&s.neighbours, &s.pairs);
    let w0 = kernel.w(0.0);
    out.resize(raw.len(), f64::NAN);
    out.par_iter_mut().enumerate().with_min_len(256).for_each(|(a, k)| {
        *k = f64::NAN;
        if !raw[a].is_finite() {
            return;
        }
        let (lo, hi) = (list.offsets[a], list.offsets[a + 1]);
        let (mut num, mut den) = (w0 * raw[a], w0);
        for (p, &b) in pairs[lo..hi].iter().zip(&list.indices[lo..hi]) {
            if let Some(&kb) = raw.get(b as usize)
                && kb.is_finite()
            {
                let w = kernel.w(p.r2().sqrt());
                num += w * kb;
                den += w;
            }
        }
        *k = num / den;
    });
}
