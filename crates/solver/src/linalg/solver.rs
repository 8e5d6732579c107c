//! The front end of the linear solvers: Krylov (CG, BiCGSTAB) with the Jacobi or the
//! two-level preconditioner, or faer's sparse LU; singular systems (no Dirichlet row)
//! projected; the true residual measured on request.

use super::krylov::{self, KrylovError, KrylovParams, Preconditioner, Workspace};
use super::two_level::CoarseSpace;
use super::{CsrMatrix, Method, PreconditionerKind, SolveError, SolveInfo, SolverParams};
use rayon::prelude::*;

/// Jacobi preconditioner `M⁻¹ = diag(A)⁻¹`.
#[derive(Debug, Clone, Copy)]
struct Jacobi<'a>(&'a [f64]);

impl Preconditioner for Jacobi<'_> {
    fn apply(&self, r: &[f64], z: &mut [f64]) {
        // Element-wise, so the parallel result is the serial one.
        z.par_iter_mut().zip(r).zip(self.0).with_min_len(krylov::BLOCK).for_each(|((zi, ri), di)| {
            *zi = di * ri;
        });
    }

    fn diagonal(&self) -> Option<&[f64]> {
        Some(self.0)
    }
}

/// A linear solver (Krylov with a preconditioner, or direct) with reusable workspace: the
/// front end of [`super`].
#[derive(Debug)]
pub struct LinearSolver {
    params: SolverParams,
    measure_residual: bool,
    b: Vec<f64>,
    r: Vec<f64>,
    workspace: Workspace,
    coarse: CoarseSpace,
}

impl LinearSolver {
    /// A solver with `params`, measuring the residual.
    pub fn new(params: SolverParams) -> Self {
        Self {
            params,
            measure_residual: true,
            b: Vec::new(),
            r: Vec::new(),
            workspace: Workspace::default(),
            coarse: CoarseSpace::new(params.coarse_refresh),
        }
    }

    /// Whether to measure the true residual after each solve: one more matrix product and
    /// a pass (a few % of a solve). The run driver asks for
    /// it only in scenes with a `solver` probe, the one reader of [`SolveInfo::residual`].
    pub fn measuring_residual(mut self, on: bool) -> Self {
        self.measure_residual = on;
        self
    }

    /// The coarse space of the two-level preconditioner.
    #[cfg(test)]
    pub(crate) fn coarse(&self) -> &CoarseSpace {
        &self.coarse
    }

    /// The solver's parameters.
    pub fn params(&self) -> &SolverParams {
        &self.params
    }

    /// Whether the solver keeps a coarse space across solves (the two-level
    /// preconditioner), which [`LinearSolver::solve_keyed`] maps to the rows by their keys.
    pub fn uses_row_keys(&self) -> bool {
        self.params.preconditioner == PreconditionerKind::TwoLevel && self.params.method != Method::Direct
    }

    /// Solves `A p = b`; `p` holds the warm start on entry and the solution on exit. With
    /// no row keys, a two-level preconditioner is rebuilt for this solve.
    pub fn solve(
        &mut self,
        a: &CsrMatrix,
        b: &[f64],
        p: &mut [f64],
        singular: bool,
    ) -> Result<SolveInfo, SolveError> {
        self.solve_keyed(a, b, p, singular, None)
    }

    /// [`LinearSolver::solve`] with a stable key per row (a particle id, unique among the
    /// rows), so that the two-level preconditioner's coarse space follows the particles
    /// from solve to solve and is rebuilt only every `coarse_refresh` solves.
    ///
    /// `singular` marks a system with no Dirichlet row (closed or periodic domain): `A`
    /// then has the constant vector as null space, so `b` is projected onto mean zero and
    /// the returned `p` has mean zero (NUMERICS.md).
    pub fn solve_keyed(
        &mut self,
        a: &CsrMatrix,
        b: &[f64],
        p: &mut [f64],
        singular: bool,
        keys: Option<&[u32]>,
    ) -> Result<SolveInfo, SolveError> {
        let n = a.n();
        if n == 0 {
            return Ok(SolveInfo::default());
        }
        // The projected right-hand side of a singular system; otherwise `b` itself.
        let mean_b = if singular { b.iter().sum::<f64>() / n as f64 } else { 0.0 };
        let b = if singular {
            self.b.clear();
            self.b.extend(b.iter().map(|bi| bi - mean_b));
            &self.b[..]
        } else {
            b
        };
        let bnorm = b.iter().map(|v| v * v).sum::<f64>().sqrt();
        if bnorm == 0.0 {
            p.iter_mut().for_each(|v| *v = 0.0);
            return Ok(SolveInfo { iterations: 0, residual: self.measure_residual.then_some(0.0) });
        }
        let iterations = match self.params.method {
            Method::Cg | Method::Bicgstab => {
                let cg = self.params.method == Method::Cg;
                let coarse = self.params.preconditioner == PreconditionerKind::TwoLevel
                    && self.coarse.prepare(a, keys, singular);
                if coarse {
                    let iterations = krylov_with(
                        &self.params,
                        a,
                        &self.coarse.preconditioner(&a.inv_diag),
                        b,
                        p,
                        cg,
                        &mut self.workspace,
                    )?;
                    self.coarse.record(iterations);
                    iterations
                } else {
                    krylov_with(&self.params, a, &Jacobi(&a.inv_diag), b, p, cg, &mut self.workspace)?
                }
            }
            Method::Direct => {
                super::direct::solve(a, b, p, singular)
                    .map_err(|reason| SolveError::Breakdown { method: "direct", reason })?;
                0
            }
        };
        if singular {
            let mean_x = p.iter().sum::<f64>() / n as f64;
            p.iter_mut().for_each(|x| *x -= mean_x);
        }
        // The residual as measured here, whatever the solver's internal norm.
        let residual = self.measure_residual.then(|| {
            self.r.resize(n, 0.0);
            a.mul(p, &mut self.r);
            self.r.iter().zip(b).map(|(ri, bi)| (bi - ri).powi(2)).sum::<f64>().sqrt() / bnorm
        });
        Ok(SolveInfo { iterations, residual })
    }
}

/// A Krylov solve of `A x = b` from the guess in `x` (CG if `cg`, else BiCGSTAB) with the
/// preconditioner `m`; returns the iterations.
fn krylov_with(
    params: &SolverParams,
    a: &CsrMatrix,
    m: &impl Preconditioner,
    b: &[f64],
    x: &mut [f64],
    cg: bool,
    ws: &mut Workspace,
) -> Result<usize, SolveError> {
    let params = KrylovParams { tolerance: params.tolerance, max_iterations: params.max_iterations };
    let result = if cg {
        krylov::conjugate_gradient(a, m, b, x, params, ws)
    } else {
        krylov::bicgstab(a, m, b, x, params, ws)
    };
    let method = if cg { "cg" } else { "bicgstab" };
    match result {
        Ok(iterations) => Ok(iterations),
        Err(KrylovError::NoConvergence { residual }) => {
            Err(SolveError::NoConvergence { method, residual, iterations: params.max_iterations })
        }
        Err(KrylovError::Breakdown { what }) => {
            Err(SolveError::Breakdown { method, reason: format!("{what} is zero or not finite") })
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::linalg::testing::grid;

    #[test]
    fn all_solvers_agree_on_a_poisson_problem() {
        let a = grid(20);
        let n = a.n();
        let x_true: Vec<f64> = (0..n).map(|i| ((i * 7919) % 97) as f64 / 97.0).collect();
        let mut b = vec![0.0; n];
        a.mul(&x_true, &mut b);
        for solver in [Method::Cg, Method::Bicgstab, Method::Direct] {
            let mut s = LinearSolver::new(SolverParams {
                method: solver,
                tolerance: 1e-10,
                max_iterations: 1000,
                preconditioner: PreconditionerKind::Jacobi,
                coarse_refresh: 1,
            });
            let mut p = vec![0.0; n];
            let info = s.solve(&a, &b, &mut p, false).unwrap();
            let err = p.iter().zip(&x_true).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max);
            assert!(err < 1e-7, "{solver:?}: error {err}, {info:?}");
            assert!(info.residual.expect("measured") < 1e-9, "{solver:?}: {info:?}");
        }
    }

    #[test]
    fn non_convergence_is_a_typed_error() {
        let a = grid(30);
        let b = vec![1.0; a.n()];
        let mut s = LinearSolver::new(SolverParams {
            method: Method::Cg,
            tolerance: 1e-12,
            max_iterations: 3,
            preconditioner: PreconditionerKind::Jacobi,
            coarse_refresh: 1,
        });
        let mut p = vec![0.0; a.n()];
        assert!(matches!(s.solve(&a, &b, &mut p, false), Err(SolveError::NoConvergence { .. })));
    }

    #[test]
    fn singular_system_is_projected() {
        // Periodic 1D Laplacian: rows sum to zero.
        let n = 50;
        let mut a = CsrMatrix { row_ptr: vec![0], ..Default::default() };
        for i in 0..n {
            for (c, v) in [((i + n - 1) % n, -1.0), (i, 2.0), ((i + 1) % n, -1.0)] {
                a.push(c, v);
            }
            a.end_row();
        }
        let b: Vec<f64> = (0..n).map(|i| (i as f64 * 0.3).sin() + 0.7).collect();
        for solver in [Method::Cg, Method::Bicgstab, Method::Direct] {
            let mut s = LinearSolver::new(SolverParams {
                method: solver,
                tolerance: 1e-10,
                max_iterations: 2000,
                preconditioner: PreconditionerKind::Jacobi,
                coarse_refresh: 1,
            });
            let mut p = vec![0.0; n];
            let info = s.solve(&a, &b, &mut p, true).unwrap();
            assert!(info.residual.expect("measured") < 1e-8, "{solver:?} {info:?}");
            assert!(p.iter().sum::<f64>().abs() < 1e-8);
        }
    }
}
