//! The right-hand sides of the weakly compressible scheme, each in one pass over the
//! neighbour pairs: dρ/dt ([`Continuity`]) and the acceleration ([`Momentum`]).
//!
//! With `∇_a W_ab = f r_ab` from the pair cache, `u_ab = u_a − u_b`, constant mass `m`,
//! `η² = 0.01 h²`:
//! - continuity (Liu & Liu 2003, *Smoothed Particle Hydrodynamics*, eq. 4.32; Monaghan 1992
//!   eq. 2.17): `dρ_a/dt = Σ_b m u_ab·∇_aW_ab`, evaluated at the mid-step separation
//!   `r_ab^{n+½} = r_ab^{n+1} − ½Δt u_ab^{n+½}` (so that the density update is the
//!   second-order leapfrog step of [`super::integrator`]); or, with
//!   `"continuity": "corrected"`, `dρ_a/dt = −ρ_a tr(G_a M_a⁻¹)` with the Bonet & Lok 1999
//!   moment matrix (exact for linear velocity fields, also at a free surface);
//! - density diffusion (Molteni & Colagrossi 2009, Comput. Phys. Commun. 180:861, eq. 11;
//!   optional): `+ δ h c₀ Σ_b 2 (m/ρ_b) (ρ_a − ρ_b) (r_ab·∇_aW_ab)/(r² + η²)`;
//! - pressure gradient (Monaghan 1992, Annu. Rev. Astron. Astrophys. 30:543, eq. 3.3):
//!   `− Σ_b m (p_a/ρ_a² + p_b/ρ_b²) ∇_aW_ab`;
//! - laminar viscosity (Shao & Lo 2003, Adv. Water Resour. 26:787, eq. 11; Morris 1997):
//!   `+ Σ_b m 4 (μ_a + μ_b)/(ρ_a + ρ_b)² (r_ab·∇_aW_ab)/(r² + η²) u_ab`, with μ_a = μ_b = μ;
//! - artificial viscosity (Monaghan 1992 eq. 4.1; optional): `− Σ_b m Π_ab ∇_aW_ab`,
//!   `Π_ab = (−α c₀ μ_ab + β μ_ab²)/ρ̄_ab` when `u_ab·r_ab < 0` (else 0),
//!   `μ_ab = h u_ab·r_ab/(r² + η²)`, `ρ̄_ab = (ρ_a + ρ_b)/2`;
//! - body force `+ g`.
//!
//! Boundary particles (mirrors, dummy walls) enter with their velocity and pressure; their
//! density is the inverse Tait density of their pressure.

use super::WcFields;
use super::eos::Tait;
use crate::error::Cause;
use crate::kernel::{Kernel, Scaled};
use crate::operators::ShaoLo;
use crate::stage::{Stage, StepContext};
use crate::state::{State, Vector};
use nalgebra::SMatrix;
use rayon::prelude::*;

/// Physical and numerical parameters of the force stages ([`momentum`], [`continuity`]).
#[derive(Debug, Clone, Copy)]
pub struct ForceParams<const D: usize> {
    /// Equation of state.
    pub eos: Tait,
    /// Particle mass m = ρ₀ Δx^D \[kg (per unit depth in 2D: kg/m)\].
    pub mass: f64,
    /// Dynamic viscosity μ \[Pa s\].
    pub mu: f64,
    /// Smoothing length h \[m\].
    pub h: f64,
    /// Sound speed c₀ \[m/s\].
    pub c0: f64,
    /// Artificial viscosity α.
    pub alpha: f64,
    /// Artificial viscosity β.
    pub beta: f64,
    /// Density diffusion δ.
    pub delta: f64,
    /// Body force g \[m/s²\].
    pub g: Vector<D>,
}

/// Writes the fluid's `dρ/dt` (continuity, density diffusion) at the mid-step geometry,
/// then advances `ρ^{n+1} = ρⁿ + Δt dρ/dt` and `p^{n+1} = p(ρ^{n+1})`, and refreshes the
/// pressure of mirror particles from their sources. `DIFF`: density diffusion; `CORR`: the
/// kernel-gradient-corrected divergence ([`crate::scene::ContinuityForm::Corrected`]).
#[derive(Debug)]
pub struct Continuity<K: Kernel, const D: usize, const DIFF: bool, const CORR: bool> {
    /// Parameters.
    pub params: ForceParams<D>,
    /// The kernel.
    pub kernel: Scaled<K, D>,
}

/// The [`Continuity`] stage with exactly the terms `params` needs (`corrected`: the
/// kernel-gradient-corrected divergence).
pub fn continuity<K: Kernel, const D: usize>(
    params: ForceParams<D>,
    kernel: Scaled<K, D>,
    corrected: bool,
) -> Box<dyn Stage<D, WcFields<D>>> {
    match (params.delta > 0.0, corrected) {
        (true, false) => Box::new(Continuity::<K, D, true, false> { params, kernel }),
        (false, false) => Box::new(Continuity::<K, D, false, false> { params, kernel }),
        (true, true) => Box::new(Continuity::<K, D, true, true> { params, kernel }),
        (false, true) => Box::new(Continuity::<K, D, false, true> { params, kernel }),
    }
}

impl<K: Kernel, const D: usize, const DIFF: bool, const CORR: bool> Stage<D, WcFields<D>>
    for Continuity<K, D, DIFF, CORR>
{
    fn name(&self) -> &'static str {
        "continuity"
    }

    fn run(&mut self, s: &mut State<D>, wc: &mut WcFields<D>, ctx: &StepContext) -> Result<(), Cause> {
        let prm = self.params;
        let (nf, total) = (s.particles.fluid, s.particles.total());
        boundary_density(s, wc, &prm.eos);
        wc.drho.resize(nf, 0.0);
        let (list, pairs, u, rho, k) = (&s.neighbours, &s.pairs, &s.particles.u, &wc.rho, self.kernel);
        let m = prm.mass;
        let shao_lo = ShaoLo::new(prm.h);
        let diff_c = prm.delta * prm.h * prm.c0 * 2.0 * m;
        let half = 0.5 * ctx.dt;
        wc.drho.par_iter_mut().enumerate().with_min_len(128).for_each(|(a, drho)| {
            let (lo, hi) = (list.offsets[a], list.offsets[a + 1]);
            let (ra, ua) = (rho[a], u[a]);
            let mut sum = 0.0;
            let mut g = SMatrix::<f64, D, D>::zeros();
            let mut mm = SMatrix::<f64, D, D>::zeros();
            for (pair, &b) in pairs[lo..hi].iter().zip(&list.indices[lo..hi]) {
                let b = b as usize;
                let u_ab = ua - u[b];
                let r_mid = pair.r_ab - u_ab * half;
                let f_mid = k.grad_factor(r_mid.norm());
                if CORR {
                    let grad = r_mid * (f_mid * m / rho[b]);
                    g -= u_ab * grad.transpose();
                    mm -= r_mid * grad.transpose();
                } else {
                    sum += m * f_mid * u_ab.dot(&r_mid);
                }
                if DIFF {
                    let rb = rho[b];
                    sum += shao_lo.coefficient(pair, diff_c * (ra - rb), rb);
                }
            }
            if CORR {
                // Fallback (singular moment matrix, e.g. an isolated particle): Σ V ∇W form.
                sum -= ra * mm.try_inverse().map_or(g.trace(), |mi| (g * mi).trace());
            }
            *drho = sum;
        });
        let (dt, eos) = (ctx.dt, prm.eos);
        let p = &mut s.particles.p;
        (&mut wc.rho[..nf], &mut p[..nf], &wc.drho[..nf]).into_par_iter().with_min_len(512).for_each(
            |(rho, p, drho)| {
                *rho += drho * dt;
                *p = eos.pressure(*rho);
            },
        );
        let (fluid, boundary) = p.split_at_mut(nf);
        for (pb, &src) in boundary.iter_mut().zip(&s.mirrors.source) {
            *pb = fluid[src as usize];
        }
        debug_assert!(s.mirrors.source.len() <= total - nf);
        Ok(())
    }
}

/// Densities of the boundary particles from their pressures (inverse Tait equation).
fn boundary_density<const D: usize>(s: &State<D>, wc: &mut WcFields<D>, eos: &Tait) {
    let (nf, total) = (s.particles.fluid, s.particles.total());
    wc.rho.resize(total, eos.rho0);
    let p = &s.particles.p;
    wc.rho[nf..].par_iter_mut().zip(p[nf..].par_iter()).with_min_len(512).for_each(|(r, &pb)| {
        *r = eos.density(pb);
    });
}

/// Computes the acceleration of every fluid particle into [`WcFields::accel`]
/// (pressure gradient, laminar and artificial viscosity, body force). The terms a scene
/// does not use are compiled out (`AV`: artificial viscosity, `VISC`: laminar viscosity).
#[derive(Debug)]
pub struct Momentum<const D: usize, const AV: bool, const VISC: bool> {
    /// Parameters.
    pub params: ForceParams<D>,
}

/// The [`Momentum`] stage with exactly the terms `params` needs.
pub fn momentum<const D: usize>(params: ForceParams<D>) -> Box<dyn Stage<D, WcFields<D>>> {
    let av = params.alpha > 0.0 || params.beta > 0.0;
    let visc = params.mu > 0.0;
    match (av, visc) {
        (false, false) => Box::new(Momentum::<D, false, false> { params }),
        (false, true) => Box::new(Momentum::<D, false, true> { params }),
        (true, false) => Box::new(Momentum::<D, true, false> { params }),
        (true, true) => Box::new(Momentum::<D, true, true> { params }),
    }
}

impl<const D: usize, const AV: bool, const VISC: bool> Stage<D, WcFields<D>> for Momentum<D, AV, VISC> {
    fn name(&self) -> &'static str {
        "momentum"
    }

    fn run(&mut self, s: &mut State<D>, wc: &mut WcFields<D>, _ctx: &StepContext) -> Result<(), Cause> {
        let prm = self.params;
        let nf = s.particles.fluid;
        boundary_density(s, wc, &prm.eos);
        wc.accel.resize(nf, Vector::zeros());
        let (list, pairs, u, rho, p) = (&s.neighbours, &s.pairs, &s.particles.u, &wc.rho, &s.particles.p);
        let m = prm.mass;
        let shao_lo = ShaoLo::new(prm.h);
        let visc_c = 8.0 * prm.mu * m;
        let (ac, bc) = (prm.alpha * prm.c0, prm.beta);
        wc.accel.par_iter_mut().enumerate().with_min_len(128).for_each(|(a, acc)| {
            let (lo, hi) = (list.offsets[a], list.offsets[a + 1]);
            let (ra, ua) = (rho[a], u[a]);
            let pa_r2 = p[a] / (ra * ra);
            let mut sum = Vector::<D>::zeros();
            for (pair, &b) in pairs[lo..hi].iter().zip(&list.indices[lo..hi]) {
                let b = b as usize;
                let rb = rho[b];
                // Scalar factor of ∇_aW_ab = f r_ab.
                let mut s_grad = -m * (pa_r2 + p[b] / (rb * rb));
                if AV || VISC {
                    let u_ab = ua - u[b];
                    if AV {
                        let vr = u_ab.dot(&pair.r_ab);
                        if vr < 0.0 {
                            let mu_ab = prm.h * vr / shao_lo.denominator(pair);
                            s_grad -= m * (-ac * mu_ab + bc * mu_ab * mu_ab) * 2.0 / (ra + rb);
                        }
                    }
                    if VISC {
                        let rs = ra + rb;
                        sum += u_ab * (visc_c * pair.f * pair.r2() / (shao_lo.denominator(pair) * rs * rs));
                    }
                }
                sum += pair.r_ab * (pair.f * s_grad);
            }
            *acc = sum + prm.g;
        });
        Ok(())
    }
}
