//! Particle storage (structure of arrays) and the per-step shared data (pair cache).

use crate::neighbours::{Domain, NeighbourList};
use nalgebra::SVector;

/// Vector type of the solver.
pub type Vector<const D: usize> = SVector<f64, D>;

/// Particles, structure of arrays: the `fluid` fluid particles first, then the boundary
/// particles which only enter neighbour sums: open-boundary buffers ([`State::buffer`] of
/// them), then wall mirrors (rebuilt every step) or dummy wall particles. Fluid
/// particles are reordered by cell for locality; `id` keeps each one's index in the initial
/// order.
#[derive(Debug, Clone, Default)]
pub struct Particles<const D: usize> {
    /// Number of fluid particles (the leading entries of every array).
    pub fluid: usize,
    /// Initial index of each fluid particle.
    pub id: Vec<u32>,
    /// Positions \[m\].
    pub x: Vec<Vector<D>>,
    /// Velocities \[m/s\].
    pub u: Vec<Vector<D>>,
    /// Pressures \[Pa\].
    pub p: Vec<f64>,
}

impl<const D: usize> Particles<D> {
    /// Number of fluid particles.
    pub fn len(&self) -> usize {
        self.fluid
    }

    /// True if there is no fluid particle.
    pub fn is_empty(&self) -> bool {
        self.fluid == 0
    }

    /// Fluid and boundary particles together.
    pub fn total(&self) -> usize {
        self.x.len()
    }
}

/// Geometry of one neighbour pair (a, b) at the current positions, computed once per step
/// and shared by the stages, so that `∇_a W_ab = f · r_ab`.
///
/// 24 bytes in 2D: `|r_ab|²` is recomputed from `r_ab` where a stage needs it (the same
/// operation as when the pair was made, so the same bits) instead of stored, because the
/// pair passes stream the whole cache from memory once it outgrows the last-level cache
/// (the drop at Δx = 0.005: 3.5 million pairs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pair<const D: usize> {
    /// r_a − r_b (minimum image on periodic axes) \[m\].
    pub r_ab: Vector<D>,
    /// f = W'(r)/r \[1/m^(D+2)\] (≤ 0; zero beyond the support).
    pub f: f64,
}

impl<const D: usize> Pair<D> {
    /// |r_ab|² \[m²\].
    #[inline(always)]
    pub fn r2(&self) -> f64 {
        self.r_ab.norm_squared()
    }
}

impl<const D: usize> Default for Pair<D> {
    fn default() -> Self {
        Self { r_ab: Vector::zeros(), f: 0.0 }
    }
}

/// Everything a step reads and writes.
#[derive(Debug, Clone)]
pub struct State<const D: usize> {
    /// The particles.
    pub particles: Particles<D>,
    /// Positions at the start of the step (r^n) \[m\].
    pub x_old: Vec<Vector<D>>,
    /// Velocities at the start of the step (u^n) \[m/s\].
    pub u_old: Vec<Vector<D>>,
    /// Neighbour lists at the positions of the pair cache.
    pub neighbours: NeighbourList,
    /// Pair geometry, aligned with `neighbours.indices`.
    pub pairs: Vec<Pair<D>>,
    /// `div r` (Qiu eq. 16 corrected).
    pub div_r: Vec<f64>,
    /// Free-surface flags (`div r` below the threshold): p = 0 there.
    pub free_surface: Vec<bool>,
    /// ρ/ρ₀ by kernel summation (`isph::particle_density`), computed each step before the
    /// PPE assembly that reads it; empty unless the density relaxation is on.
    pub particle_density: Vec<f64>,
    /// Particle volume V = Δx^D \[m^D\] (equal for all particles).
    pub volume: f64,
    /// Density ρ \[kg/m³\].
    pub density: f64,
    /// Initial spacing Δx \[m\].
    pub dx: f64,
    /// Smoothing length h \[m\].
    pub h: f64,
    /// Periodicity.
    pub domain: Domain<D>,
    /// The assembled pressure Poisson system of the current step.
    pub ppe: PpeSystem,
    /// Where each mirror particle's values come from.
    pub mirrors: Mirrors,
    /// Weakly compressible scheme only (empty otherwise): per-particle data.
    pub wc: WcFields<D>,
    /// Number of open-boundary buffer particles, stored right after the fluid (inlet
    /// buffer first, then outlet buffer); mirrors or dummy wall particles follow them.
    pub buffer: usize,
    /// Cumulative masses through the open boundaries.
    pub flux: Flux,
    /// Where the inlet buffer takes its pressure from.
    pub inlet: InletLink,
}

/// The inlet buffer's pressure link (zero normal gradient at the inlet): every buffer
/// particle of lattice row `r` shares the PPE unknown of the fluid particle that entered
/// last through that row, the fluid particle next to the inlet plane.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct InletLink {
    /// Buffer columns: inlet buffer particle `i` is in row `i / columns`.
    pub columns: usize,
    /// Id of the fluid particle that entered last through each row.
    pub row_id: Vec<u32>,
    /// Current index of the source of each inlet buffer particle (`u32::MAX`: none found;
    /// the buffer particle then keeps its pressure as a known value).
    pub source: Vec<u32>,
}

/// Cumulative masses that crossed the inlet and the outlet \[kg, per metre of depth in
/// 2D\].
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Flux {
    /// Mass that entered through the inlet.
    pub inflow: f64,
    /// Mass that left through the outlet.
    pub outflow: f64,
}

/// Per-particle data of the weakly compressible scheme ([`crate::wcsph`]); empty vectors
/// for the projection scheme.
#[derive(Debug, Clone, Default)]
pub struct WcFields<const D: usize> {
    /// Density ρ \[kg/m³\]: the fluid first (integrated), then the boundary particles
    /// (from their pressure by the inverse Tait equation, every force evaluation).
    pub rho: Vec<f64>,
    /// dρ/dt of the fluid at the last force evaluation \[kg/(m³ s)\].
    pub drho: Vec<f64>,
    /// Acceleration of the fluid at the last force evaluation \[m/s²\] (all forces:
    /// pressure, viscosity, body force, surface tension).
    pub accel: Vec<Vector<D>>,
}

/// Boundary particles that mirror fluid particles: boundary particle `fluid + k` takes its
/// velocity as `sign[k] · u[source[k]]` and its pressure as `p[source[k]]`.
#[derive(Debug, Clone, Default)]
pub struct Mirrors {
    /// Fluid particle mirrored.
    pub source: Vec<u32>,
    /// Velocity factor: −1 after one no-slip reflection, +1 after two (a corner).
    pub sign: Vec<f64>,
}

/// The PPE of the current step: matrix, right-hand side and the particle ↔ row maps.
#[derive(Debug, Clone, Default)]
pub struct PpeSystem {
    /// Matrix over the rows of non-free-surface particles.
    pub matrix: crate::ppe::PpeMatrix,
    /// Right-hand side `−div u* / Δt` \[Pa/m² per kg/m³\].
    pub rhs: Vec<f64>,
    /// (diagonal, right-hand side) of each row as the assembly's pair pass leaves them.
    pub row_out: Vec<[f64; 2]>,
    /// Row of each particle (`u32::MAX` for free-surface particles).
    pub row_of: Vec<u32>,
    /// Particle of each row.
    pub particle_of: Vec<u32>,
    /// Id of each row's particle (the key of the two-level preconditioner's coarse space;
    /// filled only when that preconditioner is configured).
    pub row_key: Vec<u32>,
    /// Unknowns (pressures of the rows) \[Pa\].
    pub solution: Vec<f64>,
    /// True when no row is Dirichlet-constrained (closed or periodic domain).
    pub singular: bool,
    /// Iterations and residual of the last solve.
    pub info: crate::ppe::PpeInfo,
}

impl<const D: usize> State<D> {
    /// Index of the first wall particle (mirror or dummy): after the fluid and the
    /// open-boundary buffers.
    pub fn walls_start(&self) -> usize {
        self.particles.fluid + self.buffer
    }

    /// Largest fluid particle speed \[m/s\] (order-independent reduction).
    pub fn max_speed(&self) -> f64 {
        self.particles.u[..self.particles.fluid].iter().map(|u| u.norm_squared()).fold(0.0, f64::max).sqrt()
    }

    /// Applies the permutation `perm` (new → old) of the fluid particles to every particle
    /// array (the leading `perm.len()` entries; boundary particles keep their place),
    /// through the reusable buffers of `scratch` (no allocation once they are warm).
    pub fn permute(&mut self, perm: &[u32], scratch: &mut PermuteScratch<D>) {
        fn apply<T: Copy>(v: &mut [T], perm: &[u32], tmp: &mut Vec<T>) {
            if v.len() >= perm.len() {
                tmp.clear();
                tmp.extend(perm.iter().map(|&i| v[i as usize]));
                v[..perm.len()].copy_from_slice(tmp);
            }
        }
        let PermuteScratch { ids, vectors, scalars, flags } = scratch;
        apply(&mut self.particles.id, perm, ids);
        apply(&mut self.particles.x, perm, vectors);
        apply(&mut self.particles.u, perm, vectors);
        apply(&mut self.particles.p, perm, scalars);
        apply(&mut self.x_old, perm, vectors);
        apply(&mut self.u_old, perm, vectors);
        apply(&mut self.free_surface, perm, flags);
        apply(&mut self.div_r, perm, scalars);
        apply(&mut self.wc.rho, perm, scalars);
        apply(&mut self.wc.drho, perm, scalars);
        apply(&mut self.wc.accel, perm, vectors);
    }
}

/// Reusable buffers of [`State::permute`], one per element type.
#[derive(Debug, Clone, Default)]
pub struct PermuteScratch<const D: usize> {
    ids: Vec<u32>,
    vectors: Vec<Vector<D>>,
    scalars: Vec<f64>,
    flags: Vec<bool>,
}
