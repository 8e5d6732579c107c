//! Linear algebra of the particle systems, independent of the scene schema: the sparse
//! matrix ([`CsrMatrix`]), preconditioned CG and BiCGSTAB over any row operator
//! ([`krylov`]; deterministic parallel reductions), the two-level preconditioner
//! ([`two_level`]), faer's sparse LU ([`direct`]) and the solver front end
//! ([`LinearSolver`]), with their parameters ([`SolverParams`]), what a solve did
//! ([`SolveInfo`]) and how it failed ([`SolveError`]) — faer's params / info / error
//! habit. A scheme maps its scene options onto [`SolverParams`] (the PPE:
//! `ppe::solver_params`; the implicit viscous system: fixed CG settings).

pub mod csr;
pub mod direct;
pub mod krylov;
pub mod solver;
pub mod two_level;

#[cfg(test)]
mod testing;

pub use csr::{CsrMatrix, par_csr_rows_mut, stored};
pub use solver::LinearSolver;

/// A linear operator applied one row at a time, `(A x)_i`: what the Krylov solvers need
/// of a matrix (the fused passes of [`krylov`] evaluate rows inside their reductions).
pub trait RowOperator: Sync {
    /// Number of rows (and columns).
    fn rows(&self) -> usize;
    /// `(A x)_i`; the same bits whichever thread computes it.
    fn row_dot(&self, i: usize, x: &[f64]) -> f64;
}

/// The solver of a [`LinearSolver`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Method {
    /// Preconditioned conjugate gradient (symmetric positive (semi-)definite systems).
    Cg,
    /// BiCGSTAB (non-symmetric systems).
    Bicgstab,
    /// faer's sparse LU.
    Direct,
}

impl Method {
    /// The method's name in errors and reports.
    pub fn name(self) -> &'static str {
        match self {
            Method::Cg => "cg",
            Method::Bicgstab => "bicgstab",
            Method::Direct => "direct",
        }
    }
}

/// The preconditioner of the Krylov methods.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PreconditionerKind {
    /// `diag(A)⁻¹`.
    Jacobi,
    /// Jacobi plus a coarse-space correction kept across solves ([`two_level`]).
    TwoLevel,
}

/// Parameters of a [`LinearSolver`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SolverParams {
    /// The method.
    pub method: Method,
    /// Relative residual tolerance `‖b − A x‖ ≤ tol ‖b‖` of the Krylov methods.
    pub tolerance: f64,
    /// Iteration cap of the Krylov methods.
    pub max_iterations: usize,
    /// Preconditioner of the Krylov methods.
    pub preconditioner: PreconditionerKind,
    /// Most solves between rebuilds of the two-level coarse space (at least 1).
    pub coarse_refresh: usize,
}

impl SolverParams {
    /// The implicit viscous solves (ISPH's and MPS's): CG with Jacobi to a relative residual
    /// of 1e-8 (well below the PPE's: the matrix `I − Δt ν L` is symmetric and diagonally
    /// dominant, so a few iterations reach it).
    pub fn viscous() -> Self {
        Self {
            method: Method::Cg,
            tolerance: 1e-8,
            max_iterations: 2000,
            preconditioner: PreconditionerKind::Jacobi,
            coarse_refresh: 1,
        }
    }
}

/// What a solve did.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct SolveInfo {
    /// Krylov iterations (0 for the direct solver).
    pub iterations: usize,
    /// Final relative residual ‖b − A p‖ / ‖b‖, when the solver measures it
    /// ([`LinearSolver::measuring_residual`]).
    pub residual: Option<f64>,
}

/// How a solve failed.
#[derive(Debug, Clone, PartialEq)]
pub enum SolveError {
    /// The iteration cap was reached.
    NoConvergence {
        /// The method ([`Method::name`]).
        method: &'static str,
        /// Last relative residual.
        residual: f64,
        /// Iterations taken (the cap).
        iterations: usize,
    },
    /// A scalar of the recurrence was zero or not finite, or the factorisation failed.
    Breakdown {
        /// The method ([`Method::name`]).
        method: &'static str,
        /// What broke down.
        reason: String,
    },
}
