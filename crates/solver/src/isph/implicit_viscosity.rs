//! Backward-Euler viscous predictor: Qiu 2013 eq. 4 with the viscous part taken implicitly,
//! `u* − Δt ν L(u*) = uⁿ + Δt g` (the body force, applied by the stage before, is inside
//! the solve: applied after it, the steady state would carry a spurious `Δt g`, measured
//! 2 % of u_max in the Re = 4 channel at Δt = 100 s), with the Shao–Lo Laplacian of eq. 13 (CASES.md erratum 2)
//! `L(u)_a = Σ_b 2 V_b (r_ab·∇_aW_ab)/(r² + 0.01 h²) (u_a − u_b)`, one sparse solve per
//! velocity component with the same matrix.
//!
//! The matrix `I − Δt ν L` is symmetric positive definite for equal particle volumes (an
//! M-matrix: `r·∇W ≤ 0`), so it is solved by Jacobi-preconditioned CG ([`crate::linalg`]), warm-started
//! from `uⁿ`. It removes the explicit viscous limit `Δt ≤ α_d h²/ν` (Qiu eq. 18), which
//! binds low-Reynolds channels. Boundary neighbours: a mirror (`u = σ u_source`) couples to
//! its source's unknown with the factor σ; a dummy wall particle's velocity (extrapolated
//! from `uⁿ`) is known and moves to the right-hand side.

use crate::boundary_map::Link;
use crate::error::Cause;
use crate::linalg::{CsrMatrix, LinearSolver, SolverParams, par_csr_rows_mut, stored};
use crate::operators::ShaoLo;
use crate::stage::{Stage, StepContext};
use crate::state::State;
use rayon::prelude::*;

/// The implicit viscous predictor stage.
#[derive(Debug)]
pub struct ImplicitViscosity {
    nu: f64,
    matrix: CsrMatrix,
    solver: LinearSolver,
    rhs: Vec<f64>,
    x: Vec<f64>,
}

impl ImplicitViscosity {
    /// A stage for kinematic viscosity `nu` = μ/ρ \[m²/s\].
    pub fn new(nu: f64) -> Self {
        Self {
            nu,
            matrix: CsrMatrix::default(),
            solver: LinearSolver::new(SolverParams::viscous()).measuring_residual(false),
            rhs: Vec::new(),
            x: Vec::new(),
        }
    }
}

impl<const D: usize, O> Stage<D, O> for ImplicitViscosity {
    fn name(&self) -> &'static str {
        "viscosity_implicit"
    }

    fn run(&mut self, s: &mut State<D>, _own: &mut O, ctx: &StepContext) -> Result<(), Cause> {
        let n = s.particles.fluid;
        let (list, pairs) = (&s.neighbours, &s.pairs);
        let (shao_lo, c) = (ShaoLo::new(s.h), ctx.dt * self.nu * 2.0 * s.volume);
        let links = &s.links;
        // The unknown a neighbour couples to, with its factor (None: a known value, as for
        // open-boundary buffers, dummy wall particles and the mirrors of buffers).
        let column = |b: usize| -> Option<(u32, f64)> {
            match links.velocity(b) {
                Link::Unknown => Some((b as u32, 1.0)),
                Link::Shares { source, sign } if (source as usize) < n => Some((source, sign)),
                Link::Shares { .. } | Link::Known => None,
            }
        };
        let m = &mut self.matrix;
        m.row_ptr.resize(n + 1, 0);
        m.row_ptr[0] = 0;
        m.row_ptr[1..].par_iter_mut().enumerate().with_min_len(256).for_each(|(a, len)| {
            *len = list
                .of(a)
                .iter()
                .filter(|&&b| column(b as usize).is_some_and(|(col, _)| col as usize != a))
                .count();
        });
        for a in 0..n {
            m.row_ptr[a + 1] += m.row_ptr[a];
        }
        m.resize_entries();
        let row = |a, cols: &mut [u32], vals: &mut [f32], diag: &mut f64| {
            let (lo, hi) = (list.offsets[a], list.offsets[a + 1]);
            *diag = 1.0;
            let mut k = 0;
            for (p, &b) in pairs[lo..hi].iter().zip(&list.indices[lo..hi]) {
                // −Δt ν L: w = −c (r·∇W)/(r² + η²) ≥ 0 per pair, (u_a − u_b) w; rounded as
                // stored, here and in the diagonal (see `CsrMatrix`).
                let w = stored(shao_lo.coefficient(p, -c, 1.0));
                *diag += w;
                match column(b as usize) {
                    Some((col, f)) if col as usize == a => *diag -= w * f,
                    Some((col, f)) => {
                        (cols[k], vals[k]) = (col, (-w * f) as f32);
                        k += 1;
                    }
                    None => {}
                }
            }
        };
        par_csr_rows_mut(&m.row_ptr, &mut m.cols, &mut m.vals, &mut m.diag, &row);
        m.invert_diagonal();
        let (u_old, u) = (&s.particles.u_old, &mut s.particles.u);
        for k in 0..D {
            self.rhs.resize(n, 0.0);
            self.rhs.par_iter_mut().enumerate().with_min_len(256).for_each(|(a, r)| {
                let (lo, hi) = (list.offsets[a], list.offsets[a + 1]);
                let mut known = 0.0;
                for (p, &b) in pairs[lo..hi].iter().zip(&list.indices[lo..hi]) {
                    if column(b as usize).is_none() {
                        known += shao_lo.coefficient(p, -c, 1.0) * u_old[b as usize][k];
                    }
                }
                *r = u[a][k] + known;
            });
            self.x.clear();
            self.x.extend(u[..n].iter().map(|u| u[k]));
            self.solver.solve(&self.matrix, &self.rhs, &mut self.x, false).map_err(crate::ppe::cause)?;
            for (u, &x) in u[..n].iter_mut().zip(&self.x) {
                u[k] = x;
            }
        }
        Ok(())
    }
}
