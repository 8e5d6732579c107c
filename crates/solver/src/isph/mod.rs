//! Projection ISPH (Qiu 2013 §2.2–2.6; Cummins & Rudman 1999; Shao & Lo 2003).
//!
//! The step, built from the scene (a stage the scene does not need is not built):
//! `reorder` (locality) → `advect` (eq. 3) → `walls` (§2.4.2; mirror walls only) →
//! `neighbours` → `dummy_walls` (dummy walls only: Adami 2012 extrapolation) →
//! `free_surface` (eq. 16) → `viscosity` (eqs. 4, 13; explicit, μ > 0 only) → `body_force`
//! (eq. 4; g ≠ 0 only) → `surface_tension` (σ > 0 only: u* += Δt a_st) → `viscosity_implicit` (backward Euler instead of `viscosity`) →
//! `mirror_velocity` | `dummy_velocity` (walls only) → `ppe_assemble`
//! (eqs. 10, 12) → `ppe_solve` (eq. 5) → `dummy_pressure` (dummy walls only) →
//! `correction` (eqs. 6, 15) → `position` (eq. 7) → `shifting` (eqs. 20–21; when
//! configured).

pub mod implicit_viscosity;
pub mod predictor;
pub mod projection;
pub mod shifting;

use crate::kernel::{Kernel, Scaled};
use crate::ppe::PpeSolve;
use crate::scene::{IsphOptions, Scene, Shifting as ShiftSpec};
use crate::scene::{ViscousIntegration, WallModel};
use crate::stage::Stage;
use crate::stages::dummy::{DummyWalls, Extrapolate};
use crate::stages::surface_tension::{Apply, SurfaceTension};
use crate::stages::{free_surface::FreeSurface, neighbours::Neighbours, reorder::Reorder, walls};
use crate::state::Vector;

/// Particles are reordered by cell every this many steps.
const REORDER_EVERY: usize = 25;

/// Builds the ISPH stage list for `scene`.
pub fn build_stages<K: Kernel, const D: usize>(
    scene: &Scene,
    opts: &IsphOptions,
    kernel: Scaled<K, D>,
    domain: crate::neighbours::Domain<D>,
) -> Vec<Box<dyn Stage<D>>> {
    let mut stages: Vec<Box<dyn Stage<D>>> =
        vec![Box::new(Reorder::new(kernel.support, domain, REORDER_EVERY)), Box::new(predictor::Advect)];
    let g = Vector::<D>::from_fn(|i, _| scene.body_force.get(i).copied().unwrap_or(0.0));
    let walls = (!scene.boundaries.walls.is_empty()).then_some(scene.boundaries.wall_model);
    if walls == Some(WallModel::Mirror) {
        stages.push(Box::new(walls::Walls::new(&scene.boundaries.walls, kernel.support)));
    }
    stages.push(Box::new(Neighbours::new(kernel, domain, walls == Some(WallModel::Dummy))));
    if walls == Some(WallModel::Dummy) {
        stages.push(Box::new(DummyWalls::new(kernel, g, Extrapolate::Start)));
    }
    stages.push(Box::new(FreeSurface { threshold: opts.free_surface_threshold }));
    // Explicit: u* = uⁿ + Δt ν L(uⁿ), then + Δt g. Implicit: uⁿ + Δt g first, then the
    // solve (the force inside it keeps the steady state exact).
    let nu = scene.fluid.viscosity / scene.fluid.density;
    let implicit = opts.viscosity == ViscousIntegration::Implicit;
    if nu > 0.0 && !implicit {
        stages.push(Box::new(predictor::Viscosity { nu }));
    }
    if g.norm_squared() > 0.0 {
        stages.push(Box::new(predictor::BodyForce { g }));
    }
    if scene.fluid.surface_tension > 0.0 {
        stages.push(Box::new(SurfaceTension::new(
            crate::stages::surface_tension::effective_sigma(scene, &kernel),
            scene.fluid.surface_tension_model,
            scene.fluid.surface_tension_threshold,
            kernel.h,
            Apply::Velocity,
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
    stages.push(Box::new(projection::PpeAssemble { divergence: opts.divergence }));
    stages.push(Box::new(projection::PpeSolveStage { solver: PpeSolve::new(opts.ppe) }));
    if walls == Some(WallModel::Dummy) {
        stages.push(Box::new(DummyWalls::new(kernel, g, Extrapolate::Pressure)));
    }
    stages.push(Box::new(projection::Correction { form: opts.pressure_gradient }));
    stages.push(Box::new(projection::Position));
    match opts.shifting {
        ShiftSpec::None => {}
        ShiftSpec::Xu { coefficient } => stages.push(Box::new(shifting::Shifting::new(
            shifting::Law::Xu(coefficient),
            kernel,
            opts.free_surface_threshold,
        ))),
        ShiftSpec::Fickian { coefficient } => stages.push(Box::new(shifting::Shifting::new(
            shifting::Law::Fickian(coefficient),
            kernel,
            opts.free_surface_threshold,
        ))),
    }
    stages
}
