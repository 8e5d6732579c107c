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
//! The time step ([`crate::run`]) is fixed or adaptive: `Δt = min(α_c h/(c₀ + |u|_max),
//! α_d ρ h²/μ, 0.25 √(h/|a|_max), max)` (Monaghan 1992 §10; Morris 1997 eq. 23).

pub mod eos;
pub mod forces;
pub mod integrator;

use crate::isph::shifting::Law;
use crate::kernel::{Kernel, Scaled};
use crate::scene::{Scene, WallModel, WcsphOptions};
use crate::stage::Stage;
use crate::stages::dummy::{DummyWalls, Extrapolate};
use crate::stages::free_surface::FreeSurface;
use crate::stages::neighbours::{Neighbours, Rows};
use crate::stages::surface_tension::{Apply, Force, SurfaceTension};
use crate::stages::{reorder::Reorder, walls};
use crate::state::Vector;
use eos::Tait;
use forces::ForceParams;

/// Particles are reordered by cell every this many steps.
const REORDER_EVERY: usize = 25;

/// The equation of state of a scene with options `opts`.
pub fn tait(scene: &Scene, opts: &WcsphOptions) -> Tait {
    Tait::new(scene.fluid.density, opts.sound_speed, opts.gamma)
}

/// Builds the WCSPH stage list for `scene`.
pub fn build_stages<K: Kernel, const D: usize>(
    scene: &Scene,
    opts: &WcsphOptions,
    kernel: Scaled<K, D>,
    domain: crate::neighbours::Domain<D>,
) -> Vec<Box<dyn Stage<D>>> {
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
    let walls = (!scene.boundaries.walls.is_empty()).then_some(scene.boundaries.wall_model);
    // Boundaries and neighbours at the current positions.
    // `div_r`: the neighbours stage also sums `div r` (for the shifting's free-surface flags).
    let boundaries = |div_r: bool| {
        let mut v: Vec<Box<dyn Stage<D>>> = Vec::new();
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
    let tension = || -> Option<Box<dyn Stage<D>>> {
        // `young_laplace` (no force form) is rejected for WCSPH by the scene validation.
        Force::of(scene.fluid.surface_tension_model).filter(|_| sigma > 0.0).map(|force| {
            Box::new(SurfaceTension::new(
                sigma,
                force,
                scene.fluid.surface_tension_threshold,
                kernel.h,
                Apply::Acceleration,
            )) as Box<dyn Stage<D>>
        })
    };
    let mut prime = boundaries(false);
    let shifting = Law::of(opts.shifting);
    prime.push(forces::momentum(params));
    prime.extend(tension());
    let mut stages: Vec<Box<dyn Stage<D>>> = vec![
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
        stages.push(Box::new(crate::isph::shifting::Shifting::new(law, kernel, threshold)));
    }
    stages
}
