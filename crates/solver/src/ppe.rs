//! The pressure Poisson system of a projection scheme (ISPH: Qiu 2013 eqs. 5, 10, 12; MPS:
//! Lan 2022 eq. 4) as the scheme holds it between its assembly and its solve, and the
//! mapping of the scene's `ppe` options onto the linear solver ([`crate::linalg`]).

use crate::error::Cause;
use crate::linalg::{
    CsrMatrix, LinearSolver, Method, PreconditionerKind, SolveError, SolveInfo, SolverParams,
};
use crate::scene::{PpeOptions, PpeSolver, Preconditioner};
use rayon::prelude::*;

/// The PPE of the current step: matrix, right-hand side and the particle ↔ row maps.
#[derive(Debug, Clone, Default)]
pub struct PpeSystem {
    /// Matrix over the rows of non-free-surface particles.
    pub matrix: CsrMatrix,
    /// Right-hand side: ISPH `−div u* / Δt` \[Pa/m² per kg/m³\], MPS the negated mixed
    /// source of Lan eq. 4 \[Pa/m²\].
    pub rhs: Vec<f64>,
    /// (diagonal, right-hand side) of each row as the assembly's pair pass leaves them.
    pub row_out: Vec<[f64; 2]>,
    /// Row of each particle (`u32::MAX` for particles whose pressure is known).
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
}

impl PpeSystem {
    /// Moves each row's (diagonal, right-hand side), as the assembly's pair pass left them
    /// in `row_out`, into the matrix diagonal, its inverse and `rhs`.
    pub fn finish_rows(&mut self) {
        let rows = self.row_out.len();
        let m = &mut self.matrix;
        m.diag.resize(rows, 0.0);
        m.inv_diag.resize(rows, 0.0);
        self.rhs.resize(rows, 0.0);
        m.diag
            .par_iter_mut()
            .zip(m.inv_diag.par_iter_mut())
            .zip(self.rhs.par_iter_mut())
            .zip(self.row_out.par_iter())
            .with_min_len(512)
            .for_each(|(((d, inv), r), out)| {
                (*d, *inv, *r) = (out[0], 1.0 / out[0], out[1]);
            });
    }

    /// Solves the system with `solver`, warm-started from the pressures `p` of the rows'
    /// particles; `key(particle)` keys each row for a coarse space kept across steps (asked
    /// only when the solver keeps one). The pressures are left in `solution`.
    pub fn solve(
        &mut self,
        solver: &mut LinearSolver,
        p: &[f64],
        key: impl Fn(usize) -> u32,
    ) -> Result<SolveInfo, Cause> {
        self.solution.clear();
        self.solution.extend(self.particle_of.iter().map(|&a| p[a as usize]));
        let keys = if solver.uses_row_keys() {
            self.row_key.clear();
            self.row_key.extend(self.particle_of.iter().map(|&a| key(a as usize)));
            Some(&self.row_key[..])
        } else {
            None
        };
        solver.solve_keyed(&self.matrix, &self.rhs, &mut self.solution, self.singular, keys).map_err(cause)
    }
}

/// The linear solver settings of the scene's PPE options.
pub fn solver_params(opts: &PpeOptions) -> SolverParams {
    SolverParams {
        method: match opts.solver {
            PpeSolver::Cg => Method::Cg,
            PpeSolver::Bicgstab => Method::Bicgstab,
            PpeSolver::Direct => Method::Direct,
        },
        tolerance: opts.tolerance,
        max_iterations: opts.max_iterations,
        preconditioner: match opts.preconditioner {
            Preconditioner::Jacobi => PreconditionerKind::Jacobi,
            Preconditioner::TwoLevel => PreconditionerKind::TwoLevel,
        },
        coarse_refresh: opts.coarse_refresh,
    }
}

/// The run's failure cause of a failed pressure (or viscous) solve.
pub fn cause(e: SolveError) -> Cause {
    match e {
        SolveError::NoConvergence { method, residual, iterations } => {
            Cause::PpeNoConvergence { solver: method, residual, iterations }
        }
        SolveError::Breakdown { method, reason } => Cause::PpeBreakdown { solver: method, reason },
    }
}
