//! Projection ISPH (Qiu 2013 §2.2–2.6; Cummins & Rudman 1999; Shao & Lo 2003).
//!
//! The step, built from the scene (a stage the scene does not need is not built):
//! `reorder` (locality) → `advect` (eq. 3) → `walls` (§2.4.2; mirror walls only) →
//! `neighbours` (with `div r`, and the kernel-gradient correction when a corrected
//! divergence or gradient reads it) → `dummy_walls` (dummy walls only: Adami 2012
//! extrapolation) →
//! `inlet_sources` (inflow only) → `boundary_links` (walls or open boundaries: the
//! boundary map) → `free_surface` (eq. 16) → `viscosity` (eqs. 4, 13; explicit, μ > 0 only) → `body_force`
//! (eq. 4; g ≠ 0 only) → `surface_extrapolation` (`free_surface_pressure: extrapolated`:
//! p = (Δx/2) ∂p/∂n on the free surface) → `surface_tension` (σ > 0 only: u* += Δt a_st) or
//! `surface_pressure` (σ > 0, `young_laplace`: p = σκ on the free surface, added to the
//! extrapolated value) → `viscosity_implicit` (backward Euler instead of `viscosity`) →
//! `mirror_velocity` | `dummy_velocity` (walls only) → `particle_density` (density
//! relaxation only) → `ppe_assemble`
//! (eqs. 10, 12) → `ppe_solve` (eq. 5) → `dummy_pressure` (dummy walls only) →
//! `correction` (eqs. 6, 15) → `position` (eq. 7) →
//! `shifting` (eqs. 20–21; when configured) → `open_boundaries` (inflow/outflow only:
//! buffer transfer).
//!
//! Own data ([`IsphData`]): the PPE system and the summation density, both rebuilt every
//! step (no per-particle field to carry). Time step ([`Isph::stable_step`]): the CFL limit
//! `α_c h/|u|_max`, the viscous limit `α_d ρ h²/μ` when the viscosity is explicit (eq. 18;
//! smaller by (D+2)/D for the Monaghan–Cleary operator) and the capillary limit when
//! σ > 0.

pub mod consistent_viscosity;
pub mod implicit_viscosity;
pub mod particle_density;
pub mod predictor;
pub mod projection;

use crate::error::{Cause, SceneError};
use crate::fields::{ColumnMut, ColumnRef, Field, Fields};
use crate::kernel::{Kernel, Scaled};
use crate::linalg::LinearSolver;
use crate::scene::{
    Divergence, FreeSurfacePressure, IsphOptions, PressureGradient, Probe, Scene, Scheme as SceneScheme,
};
use crate::scene::{ViscousIntegration, ViscousOperator, WallModel};
use crate::scheme::{Adaptive, Composed, Scheme};
use crate::stage::{Stage, StepContext};
use crate::stages::boundary_links::BoundaryLinks;
use crate::stages::dummy::{DummyWalls, Extrapolate};
use crate::stages::neighbours::{Neighbours, Rows};
use crate::stages::open_boundary::{InletSources, OpenBoundaries, OpenSetup};
use crate::stages::surface_extrapolation::SurfaceExtrapolation;
use crate::stages::surface_tension::{Force, SurfaceTension};
use crate::stages::young_laplace::SurfacePressure;
use crate::stages::{free_surface::FreeSurface, reorder::Reorder, shifting, walls};
use crate::state::{State, Vector};
use crate::time_step;
use rayon::prelude::*;

/// Particles are reordered by cell every this many steps.
const REORDER_EVERY: usize = 25;

/// The projection scheme (its parameters; see the module documentation).
#[derive(Debug)]
pub struct Isph {
    /// Dynamic viscosity μ \[Pa s\] (0: inviscid).
    mu: f64,
    /// Stiffness of the explicit viscous operator relative to Shao–Lo's; `None` when the
    /// viscosity is implicit (no viscous limit).
    viscous_stiffness: Option<f64>,
    /// Surface-tension coefficient σ \[N/m\].
    sigma: f64,
}

/// The projection scheme's own data, rebuilt every step.
#[derive(Debug, Default)]
pub struct IsphData {
    /// The pressure Poisson system of the step.
    pub ppe: crate::ppe::PpeSystem,
    /// ρ/ρ₀ by kernel summation (`particle_density`), computed each step before the PPE
    /// assembly that reads it; empty unless the density relaxation is on.
    pub particle_density: Vec<f64>,
}

/// No per-particle field to carry from step to step: both arrays are rebuilt every step
/// before they are read, so the reorder has nothing of this scheme's to permute.
impl<const D: usize> Fields<D> for IsphData {
    fn visit(&self, _: &mut dyn FnMut(Field<ColumnRef<'_, D>>)) {}
    fn visit_mut(&mut self, _: &mut dyn FnMut(Field<ColumnMut<'_, D>>)) {}
}

impl<const D: usize> Scheme<D> for Isph {
    type Own = IsphData;

    fn build<K: Kernel>(scene: &Scene, kernel: Scaled<K, D>) -> Result<Composed<D, Self>, SceneError> {
        let SceneScheme::Isph(opts) = &scene.scheme else {
            return Err(SceneError::new("scheme", "not isph", "must be `isph` for the projection scheme"));
        };
        let (state, open) = crate::setup::particle_state::<D>(scene, kernel.h, kernel.support);
        let explicit = opts.viscosity == ViscousIntegration::Explicit;
        // The Monaghan–Cleary operator acts along r̂_ab with weight 2(D+2) against
        // Shao–Lo's 2 on all components: its largest eigenvalue is (D+2)/D times larger,
        // so its stable step smaller.
        let stiffness = match opts.viscous_operator {
            ViscousOperator::ShaoLo | ViscousOperator::Consistent => 1.0,
            ViscousOperator::MonaghanCleary => (D as f64 + 2.0) / D as f64,
        };
        let scheme = Isph {
            mu: scene.fluid.viscosity,
            viscous_stiffness: explicit.then_some(stiffness),
            sigma: scene.fluid.surface_tension,
        };
        let stages = build_stages::<K, D>(scene, opts, kernel, state.domain, open.as_ref());
        Ok(Composed { scheme, state, own: IsphData::default(), stages })
    }

    fn stable_step(&self, rule: Adaptive, s: &State<D>, _own: &IsphData) -> f64 {
        let h = s.h;
        let mut dt = rule.max.min(time_step::advective(rule.cfl, h, s.max_speed()));
        if let Some(stiffness) = self.viscous_stiffness {
            dt = dt.min(time_step::viscous(rule.viscous, s.density, h, self.mu, stiffness));
        }
        dt.min(time_step::capillary(s.density, h, self.sigma))
    }
}

/// The surface-tension stage of the projection: `u* += Δt a_st` in the predictor.
impl<const D: usize> Stage<D, IsphData> for SurfaceTension<D> {
    fn name(&self) -> &'static str {
        Self::NAME
    }

    fn run(&mut self, s: &mut State<D>, _own: &mut IsphData, ctx: &StepContext) -> Result<(), Cause> {
        let dt = ctx.dt;
        let nf = s.particles.fluid;
        let accel = self.compute(s, None);
        s.particles.u[..nf].par_iter_mut().zip(accel.par_iter()).with_min_len(1024).for_each(|(u, st)| {
            *u += st * dt;
        });
        Ok(())
    }
}

/// Builds the ISPH stage list for `scene` (`open`: its inflow/outflow, when it has them).
fn build_stages<K: Kernel, const D: usize>(
    scene: &Scene,
    opts: &IsphOptions,
    kernel: Scaled<K, D>,
    domain: crate::neighbours::Domain<D>,
    open: Option<&OpenSetup>,
) -> Vec<Box<dyn Stage<D, IsphData>>> {
    let mut stages: Vec<Box<dyn Stage<D, IsphData>>> =
        vec![Box::new(Reorder::new(kernel.support, domain, REORDER_EVERY)), Box::new(predictor::Advect)];
    let g = Vector::<D>::from_fn(|i, _| scene.body_force.get(i).copied().unwrap_or(0.0));
    let walls = scene.has_walls().then_some(scene.boundaries.wall_model);
    if walls == Some(WallModel::Mirror) {
        stages.push(Box::new(walls::Walls::new(&scene.boundaries.walls, kernel.support)));
    }
    let rows = if walls == Some(WallModel::Dummy) { Rows::All } else { Rows::Fluid };
    // `div r` for the free-surface flags is summed in the neighbours' pair pass, and the
    // kernel-gradient correction inverted there for the corrected divergence and gradient
    // (and then read by the shifting's Taylor correction, instead of computing its own).
    let corrected =
        opts.divergence == Divergence::Corrected || opts.pressure_gradient == PressureGradient::Corrected;
    let neighbours = Neighbours::new(kernel, domain, rows).summing_div_r();
    stages.push(Box::new(if corrected { neighbours.inverting_moments() } else { neighbours }));
    if walls == Some(WallModel::Dummy) {
        stages.push(Box::new(DummyWalls::new(kernel, g, Extrapolate::Start)));
    }
    if open.is_some() {
        stages.push(Box::new(InletSources));
    }
    if walls.is_some() || open.is_some() {
        stages.push(Box::new(BoundaryLinks));
    }
    stages.push(Box::new(FreeSurface { threshold: opts.free_surface_threshold(D) }));
    // Explicit: u* = uⁿ + Δt ν L(uⁿ), then + Δt g. Implicit: uⁿ + Δt g first, then the
    // solve (the force inside it keeps the steady state exact).
    let nu = scene.fluid.viscosity / scene.fluid.density;
    let implicit = opts.viscosity == ViscousIntegration::Implicit;
    if nu > 0.0 && !implicit {
        match opts.viscous_operator {
            ViscousOperator::ShaoLo => stages.push(Box::new(predictor::Viscosity { nu })),
            ViscousOperator::MonaghanCleary => stages.push(Box::new(predictor::CentralViscosity { nu })),
            ViscousOperator::Consistent => {
                stages.push(Box::new(consistent_viscosity::ConsistentViscosity { nu }))
            }
        }
    }
    if g.norm_squared() > 0.0 {
        stages.push(Box::new(predictor::BodyForce { g }));
    }
    let sigma = scene.fluid.surface_tension;
    let force = Force::of(scene.fluid.surface_tension_model);
    let young_laplace = sigma > 0.0 && force.is_none();
    let extrapolated = opts.free_surface_pressure == FreeSurfacePressure::Extrapolated;
    if extrapolated {
        stages.push(Box::new(SurfaceExtrapolation::default()));
    }
    if young_laplace {
        let stage = SurfacePressure::new(sigma, scene.fluid.surface_tension_threshold, kernel);
        stages.push(Box::new(if extrapolated { stage.adding() } else { stage }));
    }
    let surface_pressure = young_laplace || extrapolated;
    if let Some(force) = force.filter(|_| sigma > 0.0) {
        stages.push(Box::new(SurfaceTension::new(
            crate::stages::surface_tension::effective_sigma(scene, &kernel),
            force,
            scene.fluid.surface_tension_threshold,
            kernel.h,
        )));
    }
    if nu > 0.0 && implicit {
        stages.push(Box::new(implicit_viscosity::ImplicitViscosity::new(nu)));
    }
    match walls {
        Some(WallModel::Mirror) => stages.push(Box::new(walls::MirrorVelocity)),
        Some(WallModel::Dummy) => stages.push(Box::new(DummyWalls::new(kernel, g, Extrapolate::Velocity))),
        None => {}
    }
    let relaxation = (opts.density_relaxation > 0.0).then_some(opts.density_relaxation);
    if relaxation.is_some() {
        stages.push(Box::new(particle_density::ParticleDensity::new(kernel, scene.dx)));
    }
    stages.push(Box::new(projection::PpeAssemble {
        divergence: opts.divergence,
        relaxation,
        dt_max: 0.0,
        surface_pressure,
    }));
    // Only a `solver` probe reads the measured residual.
    let solver = LinearSolver::new(crate::ppe::solver_params(&opts.ppe))
        .measuring_residual(scene.probes.iter().any(|p| matches!(p, Probe::Solver {})));
    stages.push(Box::new(projection::PpeSolveStage { solver, surface_pressure }));
    if walls == Some(WallModel::Dummy) {
        stages.push(Box::new(DummyWalls::new(kernel, g, Extrapolate::Pressure)));
    }
    stages.push(Box::new(projection::Correction { form: opts.pressure_gradient }));
    stages.push(Box::new(projection::Position));
    if let Some(law) = shifting::Law::of(opts.shifting) {
        let shift = shifting::Shifting::new(law, kernel, opts.free_surface_threshold(D));
        stages.push(Box::new(if corrected { shift.reading_moments() } else { shift }));
    }
    if let Some(o) = open {
        stages.push(Box::new(OpenBoundaries::new(o)));
    }
    stages
}
