//! Predictor stages of the projection method (Qiu 2013 §2.2, eqs. 3–4).

use crate::error::Cause;
use crate::operators::ShaoLo;
use crate::stage::{Stage, StepContext};
use crate::state::{State, Vector};
use rayon::prelude::*;

/// Qiu eq. 3: saves `r^n`, `u^n` and advects `r* = r^n + Δt u^n`.
#[derive(Debug)]
pub struct Advect;

impl<const D: usize, O> Stage<D, O> for Advect {
    fn name(&self) -> &'static str {
        "advect"
    }

    fn run(&mut self, s: &mut State<D>, _own: &mut O, ctx: &StepContext) -> Result<(), Cause> {
        s.particles.x_old.clone_from(&s.particles.x);
        s.particles.u_old.clone_from(&s.particles.u);
        let (dt, dom, nf) = (ctx.dt, s.domain, s.particles.fluid);
        let periodic = dom.is_periodic();
        let (x, u) = (&mut s.particles.x[..nf], &s.particles.u[..nf]);
        x.par_iter_mut().zip(u.par_iter()).with_min_len(512).for_each(|(x, u)| {
            *x += u * dt;
            if periodic {
                dom.wrap(x);
            }
        });
        Ok(())
    }
}

/// Qiu eq. 4 viscous part with the Shao–Lo Laplacian (eq. 13 with the `1/ρ` of CASES.md
/// erratum 2): `u*_a = u^n_a + Δt ν Σ_b 2 V_b (r_ab·∇_aW_ab)/(r² + 0.01 h²) (u_a − u_b)`,
/// evaluated at the advected positions `r*` with the velocities `u^n`.
#[derive(Debug)]
pub struct Viscosity {
    /// Kinematic viscosity ν = μ/ρ \[m²/s\].
    pub nu: f64,
}

impl<const D: usize, O> Stage<D, O> for Viscosity {
    fn name(&self) -> &'static str {
        "viscosity"
    }

    fn run(&mut self, s: &mut State<D>, _own: &mut O, ctx: &StepContext) -> Result<(), Cause> {
        let shao_lo = ShaoLo::new(s.h);
        let c = ctx.dt * self.nu * 2.0 * s.volume;
        let (list, pairs, u_old) = (&s.neighbours, &s.pairs, &s.particles.u_old);
        s.particles.u[..s.particles.fluid].par_iter_mut().enumerate().with_min_len(256).for_each(|(a, u)| {
            let (lo, hi) = (list.offsets[a], list.offsets[a + 1]);
            let mut lap = Vector::<D>::zeros();
            for (p, &b) in pairs[lo..hi].iter().zip(&list.indices[lo..hi]) {
                lap += (u_old[a] - u_old[b as usize]) * shao_lo.coefficient(p, 1.0, 1.0);
            }
            *u = u_old[a] + lap * c;
        });
        Ok(())
    }
}

/// Qiu eq. 4 viscous part with the Monaghan–Cleary operator
/// ([`crate::scene::ViscousOperator::MonaghanCleary`]):
/// `u*_a = u^n_a + Δt 2(D+2) ν Σ_b V_b (u_ab·r_ab) f_ab r_ab/(r² + 0.01 h²)`, with
/// `∇_aW_ab = f_ab r_ab`, at the advected positions `r*` with the velocities `u^n`.
#[derive(Debug)]
pub struct CentralViscosity {
    /// Kinematic viscosity ν = μ/ρ \[m²/s\].
    pub nu: f64,
}

impl<const D: usize, O> Stage<D, O> for CentralViscosity {
    fn name(&self) -> &'static str {
        "viscosity"
    }

    fn run(&mut self, s: &mut State<D>, _own: &mut O, ctx: &StepContext) -> Result<(), Cause> {
        let shao_lo = ShaoLo::new(s.h);
        let c = ctx.dt * self.nu * 2.0 * (D as f64 + 2.0) * s.volume;
        let (list, pairs, u_old) = (&s.neighbours, &s.pairs, &s.particles.u_old);
        s.particles.u[..s.particles.fluid].par_iter_mut().enumerate().with_min_len(256).for_each(|(a, u)| {
            let (lo, hi) = (list.offsets[a], list.offsets[a + 1]);
            let mut acc = Vector::<D>::zeros();
            for (p, &b) in pairs[lo..hi].iter().zip(&list.indices[lo..hi]) {
                let u_ab = u_old[a] - u_old[b as usize];
                acc += p.r_ab * (u_ab.dot(&p.r_ab) * p.f / shao_lo.denominator(p));
            }
            *u = u_old[a] + acc * c;
        });
        Ok(())
    }
}

/// Qiu eq. 4 body-force part: `u* += Δt g`.
#[derive(Debug)]
pub struct BodyForce<const D: usize> {
    /// g \[m/s²\].
    pub g: Vector<D>,
}

impl<const D: usize, O> Stage<D, O> for BodyForce<D> {
    fn name(&self) -> &'static str {
        "body_force"
    }

    fn run(&mut self, s: &mut State<D>, _own: &mut O, ctx: &StepContext) -> Result<(), Cause> {
        let du = self.g * ctx.dt;
        s.particles.u[..s.particles.fluid].par_iter_mut().with_min_len(1024).for_each(|u| *u += du);
        Ok(())
    }
}
