//! The viscous term of the MPS predictor (MPS.md step 1): the Laplacian of Lan eq. 8,
//! `⟨∇²u⟩_i = (2d/(λ n0)) Σ_j (u_j − u_i) w_ij`, over the fluid, the no-slip images of the
//! fluid across the walls (Lan Fig. 2: velocity −u_j) and the pushing plate (moving at U),
//! taken explicitly ([`Predictor`]) or implicitly ([`ImplicitPredictor`]).

use super::MpsData;
use super::open_channel::PlateLayout;
use super::operators::Operators;
use super::walls::Mirror;
use super::weight::Weight;
use crate::error::Cause;
use crate::linalg::{CsrMatrix, LinearSolver, SolverParams, par_csr_rows_mut, stored};
use crate::neighbours::{Domain, NeighbourList};
use crate::stage::{Stage, StepContext};
use crate::state::{State, Vector};
use rayon::prelude::*;

/// One term of fluid particle i's Laplacian, with its factor `(2d/(λ n0)) w` \[1/m²\].
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Term {
    /// Fluid neighbour j: `(u_j − u_i) w`.
    Fluid(usize, f64),
    /// The image of fluid particle j (i itself included) across a wall near i, moving at
    /// −u_j: `(−u_j − u_i) w`.
    Image(usize, f64),
    /// Plate particle j, of known velocity: `(u_j − u_i) w`.
    Known(usize, f64),
}

/// The Laplacian's terms of the fluid particles at the positions `x` (rⁿ).
#[derive(Debug)]
pub struct Terms<'a, W: Weight, const D: usize> {
    /// The operators (the Laplacian's radius and weight).
    pub ops: &'a Operators<W, D>,
    /// The walls' no-slip images.
    pub mirror: &'a Mirror,
    /// Neighbour lists at `x`.
    pub list: &'a NeighbourList,
    /// Positions \[m\].
    pub x: &'a [Vector<D>],
    /// Number of fluid particles (the first ones).
    pub fluid: usize,
    /// The pushing plate's particles.
    pub plate: PlateLayout,
    /// Number of type-1 boundary particles.
    pub type1: usize,
    /// Periodic axes.
    pub domain: Domain<D>,
}

impl<W: Weight, const D: usize> Terms<'_, W, D> {
    /// Calls `f` with every term of fluid particle `i` (in a fixed order: deterministic
    /// sums). Wall particles other than the plate's are not in the sum: their images stand
    /// for them.
    #[inline]
    pub fn each(&self, i: usize, mut f: impl FnMut(Term)) {
        let (ops, nf, x_i) = (self.ops, self.fluid, &self.x[i]);
        let walls = !self.mirror.is_empty();
        if walls {
            self.mirror.images(x_i, x_i, &Vector::zeros(), ops.re_l, |r2| {
                f(Term::Image(i, ops.laplacian_weight(r2.sqrt())));
            });
        }
        for &j in self.list.of(i) {
            let j = j as usize;
            let r_ij = self.domain.displacement(&self.x[j], x_i);
            let w = ops.laplacian_weight(r_ij.norm());
            if w == 0.0 {
                // Beyond the radius; so is every image (never nearer than j).
                continue;
            }
            if j < nf {
                f(Term::Fluid(j, w));
                if walls {
                    self.mirror.images(x_i, &self.x[j], &r_ij, ops.re_l, |r2| {
                        f(Term::Image(j, ops.laplacian_weight(r2.sqrt())));
                    });
                }
            } else if self.plate.holds(j, nf, self.type1) {
                f(Term::Known(j, w));
            }
        }
    }

    /// `⟨∇²u⟩_i` for the velocities `u`.
    #[inline]
    pub fn laplacian(&self, i: usize, u: &[Vector<D>]) -> Vector<D> {
        let u_i = u[i];
        let mut lap = Vector::<D>::zeros();
        self.each(i, |t| match t {
            Term::Fluid(j, w) | Term::Known(j, w) => lap += (u[j] - u_i) * w,
            Term::Image(j, w) => lap -= (u[j] + u_i) * w,
        });
        lap
    }
}

/// MPS.md step 1: `u* = uⁿ + Δt (ν⟨∇²u⟩ⁿ + g)` with the Laplacian over the fluid, its
/// no-slip wall images (Lan eq. 8, Fig. 2) and the pushing plate (moving at U), then
/// `r* = rⁿ + Δt u*`.
#[derive(Debug)]
pub struct Predictor<W: Weight, const D: usize> {
    /// The operators.
    pub ops: Operators<W, D>,
    /// Kinematic viscosity ν \[m²/s\].
    pub nu: f64,
    /// Body force per unit mass \[m/s²\].
    pub g: Vector<D>,
    /// The walls' no-slip images.
    pub mirror: Mirror,
}

impl<W: Weight, const D: usize> Predictor<W, D> {
    /// The Laplacian's terms of the fluid at the positions `x` (rⁿ) with lists `list`.
    pub fn terms<'a>(
        &'a self,
        list: &'a NeighbourList,
        x: &'a [Vector<D>],
        fluid: usize,
        domain: Domain<D>,
        own: &MpsData<D>,
    ) -> Terms<'a, W, D> {
        let (plate, type1) = (own.plate, own.type1);
        Terms { ops: &self.ops, mirror: &self.mirror, list, x, fluid, plate, type1, domain }
    }
}

impl<W: Weight, const D: usize> Stage<D, MpsData<D>> for Predictor<W, D> {
    fn name(&self) -> &'static str {
        "predictor"
    }

    fn run(&mut self, s: &mut State<D>, own: &mut MpsData<D>, ctx: &StepContext) -> Result<(), Cause> {
        let (dt, nf, dom) = (ctx.dt, s.particles.fluid, s.domain);
        let (nu, g) = (self.nu, self.g);
        let periodic = dom.is_periodic();
        let part = &mut s.particles;
        let terms = self.terms(&s.neighbours, &part.x_old, nf, dom, own);
        let (x_old, u_old, u, x) = (&part.x_old, &part.u_old, &mut part.u, &mut part.x);
        u[..nf].par_iter_mut().zip(x[..nf].par_iter_mut()).enumerate().with_min_len(256).for_each(
            |(i, (u, x))| {
                let mut a = g;
                if nu > 0.0 {
                    a += terms.laplacian(i, u_old) * nu;
                }
                *u = u_old[i] + a * dt;
                *x = x_old[i] + *u * dt;
                if periodic {
                    dom.wrap(x);
                }
            },
        );
        Ok(())
    }
}

/// MPS.md step 1 with the viscous term backward Euler: `u* − Δt ν ⟨∇²u*⟩ = uⁿ + Δt g`, one
/// sparse solve per velocity component with the same matrix, then `r* = rⁿ + Δt u*`. Not
/// Lan's (explicit) step: it lifts the viscous limit `Δt ≤ α_d λ/(2dν)`, which binds the
/// low-Reynolds channels (at Re = 4 and l0 = 0.0025 m, ≈ 0.6 s against a CFL step of 17 s),
/// as ISPH's `viscosity: implicit` does (`isph::implicit_viscosity`).
///
/// The matrix `I + Δt ν Σ w (…)` is symmetric (a pair's weight and its image distance are
/// symmetric in i and j) and diagonally dominant, so CG with Jacobi solves it, warm-started
/// from uⁿ + Δt g. Plate particles move at U, a known value on the right-hand side.
#[derive(Debug)]
pub struct ImplicitPredictor<W: Weight, const D: usize> {
    /// The physics (operators, ν, g, wall images) of the explicit predictor.
    pub physics: Predictor<W, D>,
    matrix: CsrMatrix,
    solver: LinearSolver,
    /// The right-hand side `uⁿ + Δt g` plus the plate's known terms, per fluid particle.
    rhs_all: Vec<Vector<D>>,
    rhs: Vec<f64>,
    x: Vec<f64>,
}

impl<W: Weight, const D: usize> ImplicitPredictor<W, D> {
    /// The stage with the physics of `physics`.
    pub fn new(physics: Predictor<W, D>) -> Self {
        let solver = LinearSolver::new(SolverParams::viscous()).measuring_residual(false);
        Self {
            physics,
            matrix: CsrMatrix::default(),
            solver,
            rhs_all: Vec::new(),
            rhs: Vec::new(),
            x: Vec::new(),
        }
    }
}

impl<W: Weight, const D: usize> Stage<D, MpsData<D>> for ImplicitPredictor<W, D> {
    fn name(&self) -> &'static str {
        "predictor_implicit"
    }

    fn run(&mut self, s: &mut State<D>, own: &mut MpsData<D>, ctx: &StepContext) -> Result<(), Cause> {
        let (dt, nf) = (ctx.dt, s.particles.fluid);
        let c = dt * self.physics.nu;
        let part = &mut s.particles;
        let terms = self.physics.terms(&s.neighbours, &part.x_old, nf, s.domain, own);
        // Off-diagonal entries: one per fluid term and per image of another particle.
        let m = &mut self.matrix;
        m.row_ptr.resize(nf + 1, 0);
        m.row_ptr[0] = 0;
        m.row_ptr[1..].par_iter_mut().enumerate().with_min_len(256).for_each(|(i, len)| {
            let mut k = 0;
            terms.each(i, |t| {
                if matches!(t, Term::Fluid(..)) || matches!(t, Term::Image(j, _) if j != i) {
                    k += 1;
                }
            });
            *len = k;
        });
        for i in 0..nf {
            m.row_ptr[i + 1] += m.row_ptr[i];
        }
        m.resize_entries();
        // Row i of `u − Δt ν ⟨∇²u⟩`: a fluid term adds c w to the diagonal and −c w to
        // column j; an image adds c w to the diagonal and +c w to column j (2 c w to the
        // diagonal for i's own image); a plate term adds c w to the diagonal and c w U_j to
        // the right-hand side. Coefficients rounded as stored (see `CsrMatrix`).
        let row = |i, cols: &mut [u32], vals: &mut [f32], diag: &mut f64| {
            *diag = 1.0;
            let mut k = 0;
            terms.each(i, |t| match t {
                Term::Fluid(j, w) => {
                    let w = stored(c * w);
                    *diag += w;
                    (cols[k], vals[k]) = (j as u32, -w as f32);
                    k += 1;
                }
                Term::Image(j, w) if j == i => *diag += 2.0 * stored(c * w),
                Term::Image(j, w) => {
                    let w = stored(c * w);
                    *diag += w;
                    (cols[k], vals[k]) = (j as u32, w as f32);
                    k += 1;
                }
                Term::Known(_, w) => *diag += stored(c * w),
            });
        };
        par_csr_rows_mut(&m.row_ptr, &mut m.cols, &mut m.vals, &mut m.diag, &row);
        m.invert_diagonal();
        let (u_old, g) = (&part.u_old, self.physics.g);
        // The right-hand side of every component in one pass over the terms.
        self.rhs_all.resize(nf, Vector::zeros());
        self.rhs_all.par_iter_mut().enumerate().with_min_len(256).for_each(|(i, r)| {
            let mut known = Vector::<D>::zeros();
            terms.each(i, |t| {
                if let Term::Known(j, w) = t {
                    known += u_old[j] * stored(c * w);
                }
            });
            *r = u_old[i] + g * dt + known;
        });
        for k in 0..D {
            self.rhs.clear();
            self.rhs.extend(self.rhs_all.iter().map(|r| r[k]));
            self.x.clear();
            self.x.extend_from_slice(&self.rhs);
            self.solver.solve(&self.matrix, &self.rhs, &mut self.x, false).map_err(crate::ppe::cause)?;
            for (u, &x) in part.u[..nf].iter_mut().zip(&self.x) {
                u[k] = x;
            }
        }
        let (dom, periodic) = (s.domain, s.domain.is_periodic());
        let (x_old, u, x) = (&part.x_old, &part.u, &mut part.x);
        x[..nf].par_iter_mut().enumerate().with_min_len(256).for_each(|(i, x)| {
            *x = x_old[i] + u[i] * dt;
            if periodic {
                dom.wrap(x);
            }
        });
        Ok(())
    }
}
