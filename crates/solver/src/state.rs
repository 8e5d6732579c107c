//! Particle storage (structure of arrays) and the per-step shared data (pair cache).

pub use crate::fields::Vector;
use crate::neighbours::{Domain, NeighbourList};

crate::particle_fields! {
    /// Particles, structure of arrays: the `fluid` fluid particles first, then the boundary
    /// particles which only enter neighbour sums: open-boundary buffers ([`State::buffer`]
    /// of them), then wall mirrors (rebuilt every step) or dummy wall particles. Fluid
    /// particles are reordered by cell for locality; `id` keeps each one's index in the
    /// initial order. Arrays are as long as the particles they cover: `id` and
    /// `free_surface` the fluid, the others the fluid and the boundary particles (`div_r`
    /// the particles with neighbour rows).
    pub struct Particles<const D: usize> {
        /// Number of fluid particles (the leading entries of every array).
        pub fluid: usize,
    } per_particle {
        /// Initial index of each fluid particle.
        pub id: Ids,
        /// Positions \[m\].
        pub x: Vectors => "position",
        /// Velocities \[m/s\].
        pub u: Vectors => "velocity",
        /// Pressures \[Pa\].
        pub p: Scalars => "pressure",
        /// Positions at the start of the step (rⁿ) \[m\].
        pub x_old: Vectors,
        /// Velocities at the start of the step (uⁿ) \[m/s\].
        pub u_old: Vectors,
        /// `div r` (Qiu eq. 16 corrected): ≈ D in the bulk, lower at a free surface.
        pub div_r: Scalars => "div_r",
        /// Free-surface flags (`div r` below the threshold): p = 0 there.
        pub free_surface: Flags => "free_surface",
    }
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

/// The particles and the per-step data every particle scheme shares (a scheme's own data
/// is beside it: [`crate::scheme::Scheme::Own`]).
#[derive(Debug, Clone)]
pub struct State<const D: usize> {
    /// The particles.
    pub particles: Particles<D>,
    /// Neighbour lists at the positions of the pair cache.
    pub neighbours: NeighbourList,
    /// Pair geometry, aligned with `neighbours.indices`.
    pub pairs: Vec<Pair<D>>,
    /// Particle volume V = Δx^D \[m^D\] (equal for all particles, unless `volumes` says
    /// otherwise).
    pub volume: f64,
    /// Each fluid particle's own volume \[m^D\] where they differ (OTM's material points:
    /// the probes weight by it), empty where every particle has `volume`.
    pub volumes: Vec<f64>,
    /// Set where the fluid particles are the material points of an axisymmetric body (OTM
    /// in 3D, Zhou 2021 §2.3.3): the axis is parallel to z through this (x, y) point, the
    /// particle at (x + r, y, z) stands for the ring of radius r it traces about the axis,
    /// and `volumes` holds the rings' volumes. The probes see each ring as
    /// [`crate::probes::AZIMUTHS`] copies around the axis.
    pub axis: Option<[f64; 2]>,
    /// Density ρ \[kg/m³\].
    pub density: f64,
    /// Initial spacing Δx \[m\].
    pub dx: f64,
    /// Smoothing length h \[m\].
    pub h: f64,
    /// Periodicity.
    pub domain: Domain<D>,
    /// Where each mirror particle's values come from.
    pub mirrors: Mirrors,
    /// Number of open-boundary buffer particles, stored right after the fluid (inlet
    /// buffer first, then outlet buffer); mirrors or dummy wall particles follow them.
    pub buffer: usize,
    /// Cumulative masses through the open boundaries.
    pub flux: Flux,
    /// Where the inlet buffer takes its pressure from.
    pub inlet: InletLink,
    /// What each boundary particle's pressure and velocity are to the implicit systems
    /// (rebuilt every step by the `boundary_links` stage of a scene with boundaries).
    pub links: crate::boundary_map::BoundaryMap,
    /// The kernel-gradient correction `L_a = M_a⁻¹` of every fluid particle (`None` where
    /// `M_a` is singular), from this step's pairs ([`crate::operators::moment`]): filled by the
    /// `neighbours` stage of a scheme that corrects a divergence or a gradient
    /// ([`crate::stages::neighbours::Neighbours::inverting_moments`]), empty otherwise.
    pub moments: Vec<Option<crate::fields::Matrix<D>>>,
    /// Iterations and residual of the step's pressure solve (none for explicit schemes).
    pub solve: crate::linalg::SolveInfo,
    /// A scheme's own outline of its fluid \[m\], counter-clockwise (OTM's boundary
    /// polyline in 2D), which the `young_laplace` probe reads instead of tracing one from the
    /// particles; empty for the particle schemes.
    pub outline: Vec<Vector<D>>,
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

/// Boundary particles that mirror fluid particles: boundary particle `fluid + k` takes its
/// velocity as `sign[k] · u[source[k]]` and its pressure as `p[source[k]]`.
#[derive(Debug, Clone, Default)]
pub struct Mirrors {
    /// Fluid particle mirrored.
    pub source: Vec<u32>,
    /// Velocity factor: −1 after one no-slip reflection, +1 after two (a corner).
    pub sign: Vec<f64>,
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
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every declared particle field moves with the reorder's permutation.
    #[test]
    fn every_particle_field_is_permuted() {
        crate::fields::check_permutes_every_field(&mut Particles::<2>::default());
        crate::fields::check_permutes_every_field(&mut Particles::<3>::default());
    }
}
