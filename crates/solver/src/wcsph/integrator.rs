//! Kick-drift-kick (velocity-Verlet leapfrog) time integration of the weakly compressible
//! scheme (Monaghan 2005, Rep. Prog. Phys. 68:1703, §8), with the density integrated like
//! the positions (it is driven by the velocity as the positions are):
//!
//! `u^{n+½} = uⁿ + ½Δt aⁿ` (half kick, [`KickDrift`]);
//! `r^{n+1} = rⁿ + Δt u^{n+½}` (drift, [`KickDrift`]);
//! `ρ^{n+1} = ρⁿ + Δt (dρ/dt)(r^{n+½}, u^{n+½})`, `p^{n+1} = p(ρ^{n+1})`
//! ([`super::forces::Continuity`], at the mid-step separations);
//! `a^{n+1} = a(r^{n+1}, ρ^{n+1}, u^{n+½})` ([`super::forces::Momentum`]);
//! `u^{n+1} = u^{n+½} + ½Δt a^{n+1}` (half kick, [`Kick`]).
//!
//! For the acoustic system (u driven by ρ, ρ by u) this is the symplectic velocity-Verlet
//! step, stable for ω Δt < 2; kicking ρ like u instead (both from the same old values)
//! amounts to forward Euler for the sound waves, which grows without bound (measured on
//! the elliptical drop: blow-up at c₀Δt/h = 0.14). The forces of the initial state are
//! computed once, before the first kick ([`Prime`]).

use super::WcFields;
use super::eos::Tait;
use crate::error::Cause;
use crate::stage::{Stage, StepContext};
use crate::state::{State, Vector};
use rayon::prelude::*;

/// First half kick and drift; saves `rⁿ`, `uⁿ` (the wall stages read `u_old`).
#[derive(Debug)]
pub struct KickDrift;

impl<const D: usize> Stage<D, WcFields<D>> for KickDrift {
    fn name(&self) -> &'static str {
        "kick_drift"
    }

    fn run(&mut self, s: &mut State<D>, own: &mut WcFields<D>, ctx: &StepContext) -> Result<(), Cause> {
        s.particles.x_old.clone_from(&s.particles.x);
        s.particles.u_old.clone_from(&s.particles.u);
        let (dt, dom, nf) = (ctx.dt, s.domain, s.particles.fluid);
        let periodic = dom.is_periodic();
        let half = 0.5 * dt;
        let p = &mut s.particles;
        (&mut p.x[..nf], &mut p.u[..nf], &own.accel[..nf]).into_par_iter().with_min_len(512).for_each(
            |(x, u, a)| {
                *u += a * half;
                *x += *u * dt;
                if periodic {
                    dom.wrap(x);
                }
            },
        );
        Ok(())
    }
}

/// Second half kick: `u^{n+1}`.
#[derive(Debug)]
pub struct Kick;

impl<const D: usize> Stage<D, WcFields<D>> for Kick {
    fn name(&self) -> &'static str {
        "kick"
    }

    fn run(&mut self, s: &mut State<D>, own: &mut WcFields<D>, ctx: &StepContext) -> Result<(), Cause> {
        let (nf, half) = (s.particles.fluid, 0.5 * ctx.dt);
        s.particles.u[..nf].par_iter_mut().zip(own.accel[..nf].par_iter()).with_min_len(512).for_each(
            |(u, a)| {
                *u += a * half;
            },
        );
        Ok(())
    }
}

/// Runs once, before the first kick: sets the densities from the initial pressures
/// (inverse Tait equation, so that a scene's initial pressure field is kept) and evaluates
/// the forces of the initial state with its own copies of the boundary, neighbour and
/// force stages. Later steps skip it (one flag test per step).
#[derive(Debug)]
pub struct Prime<const D: usize> {
    eos: Tait,
    stages: Vec<Box<dyn Stage<D, WcFields<D>>>>,
    done: bool,
}

impl<const D: usize> Prime<D> {
    /// Primes with `stages` (boundaries, neighbours, forces, surface tension).
    pub fn new(eos: Tait, stages: Vec<Box<dyn Stage<D, WcFields<D>>>>) -> Self {
        Self { eos, stages, done: false }
    }
}

impl<const D: usize> Stage<D, WcFields<D>> for Prime<D> {
    fn name(&self) -> &'static str {
        "wcsph_prime"
    }

    fn run(&mut self, s: &mut State<D>, own: &mut WcFields<D>, ctx: &StepContext) -> Result<(), Cause> {
        if self.done {
            return Ok(());
        }
        let nf = s.particles.fluid;
        let eos = self.eos;
        own.rho.clear();
        own.rho.extend(s.particles.p[..nf].iter().map(|&p| eos.density(p)));
        own.accel.clear();
        own.accel.resize(nf, Vector::zeros());
        own.drho.clear();
        own.drho.resize(nf, 0.0);
        s.particles.x_old.clone_from(&s.particles.x);
        s.particles.u_old.clone_from(&s.particles.u);
        for stage in &mut self.stages {
            stage.run(s, own, ctx)?;
        }
        self.done = true;
        Ok(())
    }
}
