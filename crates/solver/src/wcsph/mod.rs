//! Weakly compressible SPH (Xu 2016 with the standard forms of CASES.md erratum 6).
//!
//! The step, built from the scene (a stage the scene does not need is not built):
//! `reorder` (locality) → `wcsph_prime` (first step only: initial densities and forces) →
//! `kick_drift` (half kick of u, drift of r; [`integrator`]) → `walls` (mirror walls only)
//! → `neighbours` → `dummy_walls` (dummy walls only: Adami 2012 extrapolation of u and p)
//! → `continuity` (ρ and the Tait pressure; density diffusion; [`forces`]) →
//! `dummy_pressure` (dummy walls only) → `momentum` (Tait pressure gradient, Shao–Lo
//! viscosity, Monaghan artificial viscosity, body force; [`forces`]) → `kick` (second half
//! kick of u) → `free_surface` and `shifting` (only with `scheme.wcsph.shifting`: the ISPH
//! shifting stage with its Taylor correction of u).
//!
//! Own data ([`WcFields`]): density, its rate and the acceleration per particle. The time
//! step ([`Wcsph::stable_step`]) is `Δt = min(α_c h/(c₀ + |u|_max),
//! α_d ρ h²/μ, 0.25 √(h/|a|_max), max)` (Monaghan 1992 §10; Morris 1997 eq. 23), and the
//! capillary limit when σ > 0.

pub mod eos;
pub mod forces;
pub mod integrator;

use crate::error::{Cause, SceneError};
use crate::kernel::{Kernel, Scaled};
use crate::scene::{Scene, Scheme as SceneScheme, WallModel, WcsphOptions};
use crate::scheme::{Adaptive, Composed, Scheme};
use crate::stage::{Stage, StepContext};
use crate::stages::dummy::{DummyWalls, Extrapolate};
use crate::stages::free_surface::FreeSurface;
use crate::stages::neighbours::{Neighbours, Rows};
use crate::stages::shifting::Law;
use crate::stages::surface_tension::{Force, SurfaceTension};
use crate::stages::{reorder::Reorder, walls};
use crate::state::{State, Vector};
use crate::time_step;
use eos::Tait;
use forces::ForceParams;
use rayon::prelude::*;

crate::particle_fields! {
    /// Per-particle data of the weakly compressible scheme.
    pub struct WcFields<const D: usize> {
        /// Density ρ \[kg/m³\]: the fluid first (integrated), then the boundary particles
        /// (from their pressure by the inverse Tait equation, every force evaluation).
        pub rho: Scalars => "density",
        /// dρ/dt of the fluid at the last force evaluation \[kg/(m³ s)\].
        pub drho: Scalars,
        /// Acceleration of the fluid at the last force evaluation \[m/s²\] (all forces:
        /// pressure, viscosity, body force, surface tension).
        pub accel: Vectors => "acceleration",
    }
}

/// The weakly compressible scheme (its parameters; see the module documentation).
#[derive(Debug)]
pub struct Wcsph {
    /// Sound speed c₀ \[m/s\].
    sound_speed: f64,
    /// Dynamic viscosity μ \[Pa s\].
    mu: f64,
    /// Surface-tension coefficient σ \[N/m\].
    sigma: f64,
}

impl<const D: usize> Scheme<D> for Wcsph {
    type Own = WcFields<D>;

    fn build<K: Kernel>(scene: &Scene, kernel: Scaled<K, D>) -> Result<Composed<D, Self>, SceneError> {
        let SceneScheme::Wcsph(opts) = &scene.scheme else {
            return Err(SceneError::new(
                "scheme",
                "not wcsph",
                "must be `wcsph` for the weakly compressible scheme",
            ));
        };
        let (state, _) = crate::setup::particle_state::<D>(scene, kernel.h, kernel.support);
        let scheme = Wcsph {
            sound_speed: opts.sound_speed,
            mu: scene.fluid.viscosity,
            sigma: scene.fluid.surface_tension,
        };
        let stages = build_stages::<K, D>(scene, opts, kernel, state.domain);
        Ok(Composed { scheme, state, own: WcFields::default(), stages })
    }

    fn stable_step(&self, rule: Adaptive, s: &State<D>, own: &WcFields<D>) -> f64 {
        let (h, u) = (s.h, s.max_speed());
        let a = own.accel.iter().map(|a| a.norm_squared()).fold(0.0, f64::max).sqrt();
        // Monaghan 1992 §10: the sound speed enters the CFL; force limit.
        rule.max
            .min(time_step::advective(rule.cfl, h, self.sound_speed + u))
            .min(time_step::viscous(rule.viscous, s.density, h, self.mu, 1.0))
            .min(time_step::force(h, a))
            .min(time_step::capillary(s.density, h, self.sigma))
    }
}

/// The surface-tension stage of the weakly compressible scheme: added to the acceleration
/// before the second half kick, with volumes `m/ρ`.
impl<const D: usize> Stage<D, WcFields<D>> for SurfaceTension<D> {
    fn name(&self) -> &'static str {
        Self::NAME
    }

    fn run(&mut self, s: &mut State<D>, own: &mut WcFields<D>, _ctx: &StepContext) -> Result<(), Cause> {
        let nf = s.particles.fluid;
        let accel = self.compute(s, Some(&own.rho));
        own.accel[..nf].par_iter_mut().zip(accel.par_iter()).with_min_len(1024).for_each(|(a, st)| {
            *a += st;
        });
        Ok(())
    }
}

/// Particles are reordered by cell every this many steps.
const REORDER_EVERY: usize = 25;

/// The equation of state of a scene with options `opts`.
pub fn tait(scene: &Scene, opts: &WcsphOptions) -> Tait {
    Tait::new(scene.fluid.density, opts.sound_speed, opts.gamma)
}

/// Builds the WCSPH stage list for `scene`.
fn build_stages<K: Kernel, const D: usize>(
    scene: &Scene,
    opts: &WcsphOptions,
    kernel: Scaled<K, D>,
    domain: crate::neighbours::Domain<D>,
) -> Vec<Box<dyn Stage<D, WcFields<D>>>> {
    let eos = tait(scene, opts);
    let g = Vector::<D>::from_fn(|i, _| scene.body_force.get(i).copied().unwrap_or(0.0));
    let av = opts.artificial_viscosity.unwrap_or(crate::scene::ArtificialViscosity { alpha: 0.0, beta: 0.0 });
    let params = ForceParams {
        eos,
        mass: scene.fluid.density * scene.dx.powi(D as i32),
        mu: scene.fluid.viscosity,
        h: kernel.h,
        c0: opts.sound_speed,
        alpha: av.alpha,
        beta: av.beta,
        delta: opts.density_diffusion.unwrap_or(0.0),
        g,
    };
    let walls = scene.has_walls().then_some(scene.boundaries.wall_model);
    // Boundaries and neighbours at the current positions.
    // `div_r`: the neighbours stage also sums `div r` (for the shifting's free-surface flags).
    let boundaries = |div_r: bool| {
        let mut v: Vec<Box<dyn Stage<D, WcFields<D>>>> = Vec::new();
        if walls == Some(WallModel::Mirror) {
            v.push(Box::new(walls::Walls::new(&scene.boundaries.walls, kernel.support)));
        }
        let rows = if walls == Some(WallModel::Dummy) { Rows::All } else { Rows::Fluid };
        let neighbours = Neighbours::new(kernel, domain, rows);
        v.push(Box::new(if div_r { neighbours.summing_div_r() } else { neighbours }));
        if walls == Some(WallModel::Dummy) {
            v.push(Box::new(DummyWalls::new(kernel, g, Extrapolate::Start)));
        }
        v
    };
    let sigma = crate::stages::surface_tension::effective_sigma(scene, &kernel);
    let tension = || -> Option<Box<dyn Stage<D, WcFields<D>>>> {
        // `young_laplace` (no force form) is rejected for WCSPH by the scene validation.
        Force::of(scene.fluid.surface_tension_model).filter(|_| sigma > 0.0).map(|force| {
            Box::new(SurfaceTension::new(sigma, force, scene.fluid.surface_tension_threshold, kernel.h))
                as Box<dyn Stage<D, WcFields<D>>>
        })
    };
    let mut prime = boundaries(false);
    let shifting = Law::of(opts.shifting);
    prime.push(forces::momentum(params));
    prime.extend(tension());
    let mut stages: Vec<Box<dyn Stage<D, WcFields<D>>>> = vec![
        Box::new(Reorder::new(kernel.support, domain, REORDER_EVERY)),
        Box::new(integrator::Prime::new(eos, prime)),
        Box::new(integrator::KickDrift),
    ];
    stages.extend(boundaries(shifting.is_some()));
    stages.push(forces::continuity(
        params,
        kernel,
        opts.continuity == crate::scene::ContinuityForm::Corrected,
    ));
    if walls == Some(WallModel::Dummy) {
        stages.push(Box::new(DummyWalls::new(kernel, g, Extrapolate::Pressure)));
    }
    stages.push(forces::momentum(params));
    stages.extend(tension());
    stages.push(Box::new(integrator::Kick));
    if let Some(law) = shifting {
        // The pairs and `div r` are those of this step's positions (the kick moves no
        // particle).
        let threshold = D as f64 - 0.5;
        stages.push(Box::new(FreeSurface { threshold }));
        stages.push(Box::new(crate::stages::shifting::Shifting::new(law, kernel, threshold)));
    }
    stages
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every declared field of the scheme moves with the reorder's permutation.
    #[test]
    fn every_wcsph_field_is_permuted() {
        crate::fields::check_permutes_every_field(&mut WcFields::<2>::default());
    }
}
