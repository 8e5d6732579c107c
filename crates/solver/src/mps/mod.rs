//! Moving particle semi-implicit (MPS; Koshizuka & Oka 1996) with the operators of Lan,
//! Zhao & Wan 2022 (eqs. 3–9) and Lee et al.'s mixed PPE source (Lan eq. 4): MPS.md.
//!
//! The step, built from the scene: `reorder` (locality) → `neighbour_lists` (lists of every
//! particle within the largest operator radius plus a skin, at rⁿ; saves rⁿ, uⁿ) →
//! `predictor` (`u* = uⁿ + Δt(ν⟨∇²u⟩ + g)` with no-slip wall images, `r* = rⁿ + Δt u*`;
//! `predictor_implicit` with `scheme.mps.viscosity: implicit`, [`viscosity`]) →
//! `neighbour_lists_provisional` (rebuilt only if a particle moved more than half the skin) →
//! `number_density` (n* at r*, free-surface flags) → `ppe_assemble` → `ppe_solve` (CG or
//! BiCGSTAB, Jacobi or two-level) → `wall_pressure` (type-2 walls extrapolated; with walls
//! only) → `correction` (`uⁿ⁺¹ = u* − (Δt/ρ)⟨∇P⟩`, `rⁿ⁺¹ = r* + Δt(uⁿ⁺¹ − u*)`) → with
//! `scheme.mps.shifting` only: the kernel's `neighbours`, `free_surface` and `shifting`
//! of the other schemes (not Lan's MPS: a stabilised variant).
//!
//! Particles: the fluid, then the boundary particles ([`walls`]: type 1 then type 2, fixed;
//! with an inflow the pushing plate's particles lead each type, [`open_channel`]). With an
//! inflow and an outflow, `plate_move` follows the predictor and `recycle` ends the step.
//! The scene's kernel is not used by the step. Time step ([`Mps::stable_step`]):
//! `Δt = min(α_c l0/|u|_max, α_d λ_L/(2dν), max)`: the CFL limit on the spacing, and the
//! explicit viscous limit from the Laplacian's Gershgorin bound (`α_d = 1` is the bound;
//! MPS.md "Time step"; none with the implicit viscous term).

pub mod open_channel;
pub mod operators;
pub mod step;
pub mod viscosity;
pub mod walls;
pub mod weight;

use crate::error::SceneError;
use crate::fields::{ColumnMut, ColumnRef, Field, Fields};
use crate::kernel::{Kernel, Scaled};
use crate::linalg::LinearSolver;
use crate::scene::Probe;
use crate::scene::{MpsOptions, MpsWeight, Scene, Scheme as SceneScheme, ViscousIntegration};
use crate::scheme::{Adaptive, Composed, Scheme};
use crate::stage::Stage;
use crate::stages::free_surface::FreeSurface;
use crate::stages::neighbours::{Neighbours, Rows};
use crate::stages::reorder::Reorder;
use crate::stages::shifting::{Law, Shifting};
use crate::state::{State, Vector};
use crate::time_step;
use operators::Operators;
use weight::{Classic, Lan, Weight};

/// The skin of the neighbour lists in units of l0: at a CFL factor up to 0.25 no pair can
/// come within reach during the predictor unseen, so the lists are built once per step.
const SKIN: f64 = 0.5;

/// Particles are reordered by cell every this many steps.
const REORDER_EVERY: usize = 25;

/// The MPS scheme (its parameters; see the module documentation).
#[derive(Debug)]
pub struct Mps {
    /// Initial spacing l0 \[m\].
    l0: f64,
    /// Kinematic viscosity ν \[m²/s\].
    nu: f64,
    /// λ of the Laplacian radius \[m²\].
    lambda: f64,
    /// Radius of the neighbour lists \[m\].
    reach: f64,
    /// The viscous term is implicit: no viscous time-step limit.
    implicit_viscosity: bool,
}

/// The scheme's own data, rebuilt every step.
#[derive(Debug, Default)]
pub struct MpsData<const D: usize> {
    /// Number of type-1 boundary particles (right after the fluid; the plate's first).
    pub type1: usize,
    /// The pushing plate's particles (none without an inflow).
    pub plate: open_channel::PlateLayout,
    /// Ids of the ghost particles: parked off the flow (zero mass, in no sum), recycled
    /// from the outlet to the inlet; fluid plus ghosts is a constant count.
    pub ghosts: Vec<u32>,
    /// Key of the first wall particle's PPE row for the two-level preconditioner (after
    /// every fluid id).
    pub key_base: u32,
    /// Number density n* at r* and free-surface flag of every particle.
    pub density: Vec<Density>,
    /// The pressure Poisson system of the step.
    pub ppe: crate::ppe::PpeSystem,
    /// The velocity change of the correction, per fluid particle \[m/s\].
    pub du: Vec<Vector<D>>,
}

/// A particle's number density at r* and its free-surface flag.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Density {
    /// n* (dimensionless).
    pub n: f64,
    /// n* below the free-surface threshold: P = 0.
    pub surface: bool,
}

/// No per-particle field to carry from step to step: every array is rebuilt each step
/// before it is read, so the reorder has nothing of this scheme's to permute.
impl<const D: usize> Fields<D> for MpsData<D> {
    fn visit(&self, _: &mut dyn FnMut(Field<ColumnRef<'_, D>>)) {}
    fn visit_mut(&mut self, _: &mut dyn FnMut(Field<ColumnMut<'_, D>>)) {}
}

impl<const D: usize> Scheme<D> for Mps {
    type Own = MpsData<D>;

    fn build<K: Kernel>(scene: &Scene, kernel: Scaled<K, D>) -> Result<Composed<D, Self>, SceneError> {
        let SceneScheme::Mps(opts) = &scene.scheme else {
            return Err(SceneError::new("scheme", "not mps", "must be `mps` for the MPS scheme"));
        };
        Ok(match opts.weight {
            MpsWeight::Lan => build_with::<Lan, K, D>(scene, opts, kernel),
            MpsWeight::Classic => build_with::<Classic, K, D>(scene, opts, kernel),
        })
    }

    fn stable_step(&self, rule: Adaptive, s: &State<D>, _own: &MpsData<D>) -> f64 {
        let mut dt = rule.max.min(time_step::advective(rule.cfl, self.l0, s.max_speed()));
        if self.nu > 0.0 && !self.implicit_viscosity {
            dt = dt.min(rule.viscous * self.lambda / (2.0 * D as f64 * self.nu));
        }
        dt
    }

    fn reach(&self, _kernel_support: f64) -> f64 {
        self.reach
    }
}

/// The MPS scheme of `scene` with weight `W`: particles (fluid and walls) and stages.
fn build_with<W: Weight, K: Kernel, const D: usize>(
    scene: &Scene,
    opts: &MpsOptions,
    kernel: Scaled<K, D>,
) -> Composed<D, Mps> {
    let l0 = scene.dx;
    let ops = Operators::<W, D>::new(opts.radii(), l0);
    let reach = ops.reach() + SKIN * l0;
    let mut state = crate::setup::fluid_state::<D>(scene, kernel.h);
    let fluid = state.particles.fluid;
    let open = match (&scene.boundaries.inflow, &scene.boundaries.outflow) {
        (Some(i), Some(o)) => Some((i, o)),
        _ => None,
    };
    let (plate1, plate2, plate) = match open {
        Some((inflow, _)) => open_channel::plate(inflow, &state.particles.x[..fluid], l0, ops.re_l, ops.re_g),
        None => Default::default(),
    };
    let walls = &scene.boundaries.walls;
    // Type 1: within the gradient radius of the first fluid layer (half a spacing off the
    // plane); the layers reach the Laplacian radius, over the fluid and the plate.
    let extent: Vec<Vector<D>> = state.particles.x[..fluid].iter().chain(&plate2).copied().collect();
    let (wall_x, wall1) =
        walls::wall_particles(walls, &state.domain, &extent, l0, ops.re_l, ops.re_g - 0.5 * l0);
    let type1 = plate.type1 + wall1;
    let mut plate_u = Vector::<D>::zeros();
    if let Some((inflow, _)) = open {
        plate_u[inflow.axis] = inflow.velocity;
    }
    let boundary = plate1
        .into_iter()
        .map(|x| (x, plate_u))
        .chain(wall_x[..wall1].iter().map(|&x| (x, Vector::zeros())))
        .chain(plate2.into_iter().map(|x| (x, plate_u)))
        .chain(wall_x[wall1..].iter().map(|&x| (x, Vector::zeros())));
    for (x, u) in boundary {
        state.particles.x.push(x);
        state.particles.u.push(u);
        state.particles.p.push(0.0);
    }
    // Ghost ids after the fluid's; wall rows of the PPE are keyed after both.
    let reserve = if open.is_some() { open_channel::RESERVE_COLUMNS * plate.rows } else { 0 };
    let ghosts: Vec<u32> = (fluid as u32..(fluid + reserve) as u32).rev().collect();
    let key_base = (fluid + reserve) as u32;
    let g = Vector::<D>::from_fn(|i, _| scene.body_force.get(i).copied().unwrap_or(0.0));
    let nu = scene.fluid.viscosity / scene.fluid.density;
    let domain = state.domain;
    let beta = opts.free_surface.beta.unwrap_or(if D == 3 { 0.98 } else { 0.97 });
    let solver = LinearSolver::new(crate::ppe::solver_params(&opts.ppe))
        .measuring_residual(scene.probes.iter().any(|p| matches!(p, Probe::Solver {})));
    let mut stages: Vec<Box<dyn Stage<D, MpsData<D>>>> = vec![
        Box::new(Reorder::new(reach, domain, REORDER_EVERY)),
        Box::new(step::Lists::start(ops.reach(), SKIN * l0, domain)),
    ];
    let mirror = walls::Mirror::new(walls);
    let implicit_viscosity = opts.viscosity == ViscousIntegration::Implicit;
    let predictor = viscosity::Predictor { ops, nu, g, mirror };
    stages.push(if implicit_viscosity {
        Box::new(viscosity::ImplicitPredictor::new(predictor))
    } else {
        Box::new(predictor)
    });
    if let Some((inflow, _)) = open {
        stages.push(Box::new(open_channel::PlateMove { axis: inflow.axis, speed: inflow.velocity }));
    }
    stages.extend::<[Box<dyn Stage<D, MpsData<D>>>; _]>([
        Box::new(step::Lists::provisional(ops.reach(), SKIN * l0, domain)),
        Box::new(step::NumberDensity { ops, beta, auxiliary: opts.free_surface.auxiliary }),
        Box::new(step::PpeAssemble {
            ops,
            gamma: opts.gamma,
            compressibility: opts.compressibility,
            divergence: opts.divergence,
        }),
        Box::new(step::PpeSolve { solver, clip_negative: opts.clip_negative_pressure }),
    ]);
    if state.particles.total() > state.particles.fluid + type1 {
        stages.push(Box::new(walls::WallPressure { ops, g }));
    }
    stages.push(Box::new(step::Correction { ops, form: opts.pressure_gradient }));
    if let Some(law) = Law::of(opts.shifting) {
        // The other schemes' shifting on the kernel's pairs at rⁿ⁺¹ (the next step builds its
        // own lists again), scaled down near the surface that `div r` flags.
        let threshold = D as f64 - 0.5;
        stages.push(Box::new(Neighbours::new(kernel, domain, Rows::Fluid).summing_div_r()));
        stages.push(Box::new(FreeSurface { threshold }));
        stages.push(Box::new(Shifting::new(law, kernel, threshold)));
    }
    if let Some((inflow, outflow)) = open {
        let rows = state.particles.x[fluid..fluid + plate.rows].iter().map(|x| {
            let mut x = *x;
            x[inflow.axis] += l0;
            x
        });
        stages.push(Box::new(open_channel::Recycle::new(inflow, outflow, rows.collect(), l0)));
    }
    let own = MpsData { type1, plate, ghosts, key_base, ..Default::default() };
    let scheme = Mps { l0, nu, lambda: ops.laplacian.lambda, reach, implicit_viscosity };
    Composed { scheme, state, own, stages }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The scheme's own data declares no field the reorder would have to permute.
    #[test]
    fn every_mps_field_is_permuted() {
        crate::fields::check_permutes_every_field(&mut MpsData::<2>::default());
    }
}
