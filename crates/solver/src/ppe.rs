//! The pressure Poisson system `A p = b` and its solvers (faer).
//!
//! `A = −L` is the Shao–Lo Laplacian (Qiu 2013 eq. 12, NUMERICS.md "Signs and the PPE
//! matrix") restricted to the particles that are not free-surface particles (their p = 0
//! is a Dirichlet condition, so their columns drop out). Rows are assembled in parallel
//! straight into compressed sparse rows (the diagonal apart, the off-diagonals in `f32`:
//! see [`PpeMatrix`]) from the neighbour lists, in the fixed neighbour order: the pattern
//! is known, so the sort that a triplet assembly performs is not needed per step.
//! [`PpeMatrix::to_triplets`] gives the triplet form for the direct solver and for tests
//! that check the fast assembly against faer's triplet assembly.
//!
//! The Krylov solvers (Jacobi-preconditioned CG and BiCGSTAB) are [`crate::krylov`]'s,
//! whose parallel vector operations give the same bits for any thread count; the direct
//! solver is faer's sparse LU. The operator is applied row-parallel (each row written by
//! one task).

use crate::error::Cause;
use crate::krylov::{self, KrylovError, KrylovParams, Preconditioner, Workspace};
use crate::scene::{PpeOptions, PpeSolver, Preconditioner as PreconditionerKind};
use crate::two_level::CoarseSpace;
use faer::Mat;
use faer::sparse::linalg::LuError;
use faer::sparse::linalg::solvers::Lu;
use faer::sparse::{SparseColMat, Triplet};
use rayon::prelude::*;

/// Sparse PPE matrix: the diagonal in `f64`, the off-diagonal entries in compressed sparse
/// rows with `f32` values, and the inverse diagonal (Jacobi).
///
/// Why `f32` off-diagonals: the matrix products are bound by memory traffic once the
/// matrix outgrows the cache (the drop at Δx = 0.005, 125 676 rows of ~28 entries: 43 MB
/// at 12 bytes per entry against a 32 MB L3); at 8 bytes per entry one BiCGSTAB iteration
/// there took 3.77 instead of 4.43 ms (2 threads, tuned preset, alternating runs of 100
/// steps, whose trajectories parted: 17.2 against 15.7 iterations per step), and 0.174
/// instead of 0.196 ms at Δx = 0.02 (7860 rows; full runs, 11.32 against 11.33 iterations
/// per step). The assemblies round each pair coefficient to `f32` *before* using it, for the off-diagonal
/// entry and in the diagonal sum alike, so the stored matrix is exactly a Laplacian whose pair
/// coefficients moved by ≤ 6e-8 relative (far below the discretisation error), its rows
/// still sum to zero where the Laplacian's do, and it is still symmetric where the
/// Laplacian is (the constant null space of a closed domain is kept). The products are
/// summed in `f64`.
#[derive(Debug, Clone, Default)]
pub struct PpeMatrix {
    /// Diagonal entries (length n), in units of `(1/ρ) ∇²` \[m/kg\].
    pub diag: Vec<f64>,
    /// Offsets of each row's off-diagonal entries (length n + 1).
    pub row_ptr: Vec<usize>,
    /// Column of each off-diagonal entry, row by row (a column may repeat: a wall mirror
    /// shares its source's unknown).
    pub cols: Vec<u32>,
    /// Value of each off-diagonal entry, row by row. Columns and values are separate
    /// arrays: the product streams 8 bytes per entry instead of the 16 of a padded
    /// `(u32, f64)` pair.
    pub vals: Vec<f32>,
    /// 1 / A_ii.
    pub inv_diag: Vec<f64>,
}

impl PpeMatrix {
    /// Number of unknowns.
    pub fn n(&self) -> usize {
        self.diag.len()
    }

    /// y = A x (row-parallel, deterministic).
    pub fn mul(&self, x: &[f64], y: &mut [f64]) {
        y.par_iter_mut().enumerate().with_min_len(256).for_each(|(i, yi)| *yi = self.row_dot(i, x));
    }

    /// (A x)_i: the diagonal term and the row's off-diagonal entries in their stored order
    /// dealt round-robin to four partial sums (the diagonal term starts the first), added
    /// as (s₀ + s₁) + (s₂ + s₃) (a fixed order: the result does not depend on the thread
    /// count).
    ///
    /// One running sum chains every addition to the previous one (its latency, not the
    /// loads, then sets the pace); four independent sums overlap them. Measured on the drop
    /// at Δx = 0.02, one thread: 0.484 → 0.435 ms per BiCGSTAB iteration (−10 %).
    #[inline]
    pub fn row_dot(&self, i: usize, x: &[f64]) -> f64 {
        let (s, e) = (self.row_ptr[i], self.row_ptr[i + 1]);
        let (cols, vals) = (&self.cols[s..e], &self.vals[s..e]);
        let mut acc = [self.diag[i] * x[i], 0.0, 0.0, 0.0];
        let (cq, cr) = cols.as_chunks::<4>();
        let (vq, vr) = vals.as_chunks::<4>();
        for (c, v) in cq.iter().zip(vq) {
            for k in 0..4 {
                acc[k] += f64::from(v[k]) * x[c[k] as usize];
            }
        }
        for (k, (&c, &v)) in cr.iter().zip(vr).enumerate() {
            acc[k] += f64::from(v) * x[c as usize];
        }
        (acc[0] + acc[1]) + (acc[2] + acc[3])
    }

    /// Sizes the off-diagonal arrays for the row offsets already in `row_ptr`, and the
    /// diagonals for its rows.
    pub fn resize_entries(&mut self) {
        let nnz = self.row_ptr.last().copied().unwrap_or(0);
        self.cols.resize(nnz, 0);
        self.vals.resize(nnz, 0.0);
        self.diag.resize(self.row_ptr.len().saturating_sub(1), 0.0);
    }

    /// Sets `inv_diag` from `diag`.
    pub fn invert_diagonal(&mut self) {
        self.inv_diag.resize(self.diag.len(), 0.0);
        self.inv_diag.par_iter_mut().zip(&self.diag).with_min_len(512).for_each(|(d, a)| *d = 1.0 / a);
    }

    /// The (column, value) entries of row `i`: the diagonal first, then the off-diagonals.
    pub fn row(&self, i: usize) -> impl Iterator<Item = (u32, f64)> + '_ {
        let (s, e) = (self.row_ptr[i], self.row_ptr[i + 1]);
        let off = self.cols[s..e].iter().copied().zip(self.vals[s..e].iter().map(|&v| f64::from(v)));
        std::iter::once((i as u32, self.diag[i])).chain(off)
    }

    /// Appends an entry to the row being built (building a matrix row by row from
    /// `row_ptr = [0]`; call [`PpeMatrix::end_row`] after each row's entries). An entry in
    /// the diagonal column is added to the diagonal; an off-diagonal value is stored as
    /// `f32`.
    pub fn push(&mut self, col: usize, val: f64) {
        let row = self.open_row();
        if col == row {
            self.diag[row] += val;
        } else {
            self.cols.push(col as u32);
            self.vals.push(val as f32);
        }
    }

    /// Ends the row being built (see [`PpeMatrix::push`]) and sets its inverse diagonal.
    pub fn end_row(&mut self) {
        let row = self.open_row();
        self.row_ptr.push(self.vals.len());
        self.inv_diag.push(1.0 / self.diag[row]);
    }

    /// The index of the row being built, its diagonal allocated.
    fn open_row(&mut self) -> usize {
        let row = self.row_ptr.len() - 1;
        if self.diag.len() == row {
            self.diag.push(0.0);
        }
        row
    }

    /// The matrix as triplets (row, column, value).
    pub fn to_triplets(&self) -> Vec<Triplet<usize, usize, f64>> {
        let mut t = Vec::with_capacity(self.vals.len() + self.n());
        for i in 0..self.n() {
            t.extend(self.row(i).map(|(c, v)| Triplet::new(i, c as usize, v)));
        }
        t
    }
}

/// A pair coefficient rounded to the `f32` the matrix stores (see [`PpeMatrix`]): the
/// assemblies use the rounded value both off the diagonal and in the diagonal sum.
#[inline]
pub fn stored(c: f64) -> f64 {
    f64::from(c as f32)
}

/// faer's sparse LU of `m`, with faer's global parallelism set to sequential first.
///
/// Why: faer parallelises by default (rayon over every thread of the current pool), and
/// one direct-solver run left every later two-thread run in the same process about 40 %
/// slower (the drop at Δx = 0.02: 2.04 s before, 2.88 s after; sequential: 2.17 s after),
/// which skewed every timing of `cargo xtask bench` taken after its sparse-LU runs. The
/// solver's own loops are its only parallel work.
pub fn sparse_lu(m: &SparseColMat<usize, f64>) -> Result<Lu<usize, f64>, LuError> {
    faer::set_global_parallelism(faer::Par::Seq);
    m.sp_lu()
}

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

/// What a solve did.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct PpeInfo {
    /// Krylov iterations (0 for the direct solver).
    pub iterations: usize,
    /// Final relative residual ‖b − A p‖ / ‖b‖, when the solver measures it
    /// ([`PpeSolve::measuring_residual`]).
    pub residual: Option<f64>,
}

/// A PPE solver with reusable workspace.
#[derive(Debug)]
pub struct PpeSolve {
    opts: PpeOptions,
    measure_residual: bool,
    b: Vec<f64>,
    r: Vec<f64>,
    workspace: Workspace,
    coarse: CoarseSpace,
}

impl PpeSolve {
    /// A solver configured by the scene's `scheme.isph.ppe` options, measuring the
    /// residual.
    pub fn new(opts: PpeOptions) -> Self {
        Self {
            opts,
            measure_residual: true,
            b: Vec::new(),
            r: Vec::new(),
            workspace: Workspace::default(),
            coarse: CoarseSpace::new(opts.coarse_refresh),
        }
    }

    /// Whether to measure the true residual after each solve: one more matrix product and
    /// a pass, 4–5 % of a BiCGSTAB solve of the drop at Δx = 0.02. The run driver asks for
    /// it only in scenes with a `solver` probe, the one reader of [`PpeInfo::residual`].
    pub fn measuring_residual(mut self, on: bool) -> Self {
        self.measure_residual = on;
        self
    }

    /// Name of the configured solver.
    pub fn name(&self) -> &'static str {
        match self.opts.solver {
            PpeSolver::Bicgstab => "bicgstab",
            PpeSolver::Cg => "cg",
            PpeSolver::Direct => "direct",
        }
    }

    /// Whether the solver keeps a coarse space across solves (the two-level
    /// preconditioner), which [`PpeSolve::solve_keyed`] maps to the rows by their keys.
    pub fn uses_row_keys(&self) -> bool {
        self.opts.preconditioner == PreconditionerKind::TwoLevel && self.opts.solver != PpeSolver::Direct
    }

    /// Solves `A p = b`; `p` holds the warm start on entry and the solution on exit. With
    /// no row keys, a two-level preconditioner is rebuilt for this solve.
    pub fn solve(
        &mut self,
        a: &PpeMatrix,
        b: &[f64],
        p: &mut [f64],
        singular: bool,
    ) -> Result<PpeInfo, Cause> {
        self.solve_keyed(a, b, p, singular, None)
    }

    /// [`PpeSolve::solve`] with a stable key per row (a particle id, unique among the
    /// rows), so that the two-level preconditioner's coarse space follows the particles
    /// from solve to solve and is rebuilt only every `coarse_refresh` solves.
    ///
    /// `singular` marks a system with no Dirichlet row (closed or periodic domain): `A`
    /// then has the constant vector as null space, so `b` is projected onto mean zero and
    /// the returned `p` has mean zero (NUMERICS.md).
    pub fn solve_keyed(
        &mut self,
        a: &PpeMatrix,
        b: &[f64],
        p: &mut [f64],
        singular: bool,
        keys: Option<&[u32]>,
    ) -> Result<PpeInfo, Cause> {
        let n = a.n();
        if n == 0 {
            return Ok(PpeInfo::default());
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
            return Ok(PpeInfo { iterations: 0, residual: self.measure_residual.then_some(0.0) });
        }
        let iterations = match self.opts.solver {
            PpeSolver::Cg | PpeSolver::Bicgstab => {
                let cg = self.opts.solver == PpeSolver::Cg;
                let coarse = self.opts.preconditioner == PreconditionerKind::TwoLevel
                    && self.coarse.prepare(a, keys, singular);
                if coarse {
                    let iterations = krylov_with(
                        &self.opts,
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
                    krylov_with(&self.opts, a, &Jacobi(&a.inv_diag), b, p, cg, &mut self.workspace)?
                }
            }
            PpeSolver::Direct => {
                direct(a, b, p, singular)?;
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
        Ok(PpeInfo { iterations, residual })
    }
}

/// A Krylov solve of `A x = b` from the guess in `x` (CG if `cg`, else BiCGSTAB) with the
/// preconditioner `m`; returns the iterations.
fn krylov_with(
    opts: &PpeOptions,
    a: &PpeMatrix,
    m: &impl Preconditioner,
    b: &[f64],
    x: &mut [f64],
    cg: bool,
    ws: &mut Workspace,
) -> Result<usize, Cause> {
    let params = KrylovParams { tolerance: opts.tolerance, max_iterations: opts.max_iterations };
    let result = if cg {
        krylov::conjugate_gradient(a, m, b, x, params, ws)
    } else {
        krylov::bicgstab(a, m, b, x, params, ws)
    };
    let solver = if cg { "cg" } else { "bicgstab" };
    match result {
        Ok(iterations) => Ok(iterations),
        Err(KrylovError::NoConvergence { residual }) => {
            Err(Cause::PpeNoConvergence { solver, residual, iterations: params.max_iterations })
        }
        Err(KrylovError::Breakdown { what }) => {
            Err(Cause::PpeBreakdown { solver, reason: format!("{what} is zero or not finite") })
        }
    }
}

/// faer's sparse LU solve of `A x = b` into `x`; a singular system gets `x_0 = 0` pinned
/// (its mean is fixed afterwards).
fn direct(a: &PpeMatrix, b: &[f64], x: &mut [f64], singular: bool) -> Result<(), Cause> {
    let n = a.n();
    let mut trip = a.to_triplets();
    let mut rhs = Mat::<f64>::from_fn(n, 1, |i, _| b[i]);
    if singular {
        // Pin p_0 = 0: replace row 0 by the identity.
        trip.retain(|t| t.row != 0);
        trip.push(Triplet::new(0, 0, 1.0));
        rhs[(0, 0)] = 0.0;
    }
    let m = SparseColMat::<usize, f64>::try_new_from_triplets(n, n, &trip)
        .map_err(|e| Cause::PpeBreakdown { solver: "direct", reason: format!("{e:?}") })?;
    let lu = sparse_lu(&m).map_err(|e| Cause::PpeBreakdown { solver: "direct", reason: format!("{e:?}") })?;
    use faer::linalg::solvers::SolveCore;
    lu.solve_in_place_with_conj(faer::Conj::No, rhs.as_mut());
    for (xi, i) in x.iter_mut().zip(0..n) {
        *xi = rhs[(i, 0)];
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::two_level::CoarseFactor;

    /// 5-point Laplacian on an m×m grid with Dirichlet boundary, as a PpeMatrix.
    fn grid(m: usize) -> PpeMatrix {
        strip(m, m)
    }

    /// 5-point Laplacian on an `rows`×`m` grid with Dirichlet boundary.
    fn strip(rows: usize, m: usize) -> PpeMatrix {
        let mut a = PpeMatrix { row_ptr: vec![0], ..Default::default() };
        for i in 0..rows {
            for j in 0..m {
                let k = i * m + j;
                let mut push = |c: usize, v: f64| a.push(c, v);
                if i > 0 {
                    push(k - m, -1.0);
                }
                if j > 0 {
                    push(k - 1, -1.0);
                }
                push(k, 4.0);
                if j + 1 < m {
                    push(k + 1, -1.0);
                }
                if i + 1 < rows {
                    push(k + m, -1.0);
                }
                a.end_row();
            }
        }
        a
    }

    /// On a long strip (400 × 8, like a channel) the two-level preconditioner gives the
    /// Jacobi solution in a fraction of the iterations.
    #[test]
    fn two_level_preconditioner_cuts_the_iterations_of_a_long_strip() {
        let a = strip(400, 8);
        let n = a.n();
        let b: Vec<f64> = (0..n).map(|i| 1.0 + ((i * 7919) % 97) as f64 / 97.0).collect();
        let solve = |preconditioner, solver| {
            let opts = PpeOptions {
                solver,
                tolerance: 1e-10,
                max_iterations: 20_000,
                preconditioner,
                coarse_refresh: 1,
            };
            let mut p = vec![0.0; n];
            let info = PpeSolve::new(opts).solve(&a, &b, &mut p, false).expect("converges");
            (p, info.iterations)
        };
        for solver in [PpeSolver::Cg, PpeSolver::Bicgstab] {
            let (pj, jacobi) = solve(PreconditionerKind::Jacobi, solver);
            let (pt, two) = solve(PreconditionerKind::TwoLevel, solver);
            let err = pj.iter().zip(&pt).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max);
            let scale = pj.iter().map(|x| x.abs()).fold(0.0, f64::max);
            assert!(err < 1e-7 * scale, "{solver:?}: {err} vs {scale}");
            assert!(2 * two < jacobi, "{solver:?}: two-level {two} iterations, Jacobi {jacobi}");
        }
    }

    /// The two-level solve of `a` (CG) with the given keys on solver `s`; returns the
    /// iterations.
    fn keyed_cg(
        s: &mut PpeSolve,
        a: &PpeMatrix,
        b: &[f64],
        keys: &[u32],
        singular: bool,
    ) -> (Vec<f64>, usize) {
        let mut p = vec![0.0; a.n()];
        let info = s.solve_keyed(a, b, &mut p, singular, Some(keys)).expect("converges");
        (p, info.iterations)
    }

    fn two_level_cg(refresh: usize) -> PpeSolve {
        PpeSolve::new(PpeOptions {
            solver: PpeSolver::Cg,
            tolerance: 1e-10,
            max_iterations: 20_000,
            preconditioner: PreconditionerKind::TwoLevel,
            coarse_refresh: refresh,
        })
    }

    /// The coarse space is kept between solves and follows the rows by their keys: a
    /// renumbered system with its keys renumbered alike is solved with the same
    /// preconditioner; rows whose keys it has never seen get Jacobi alone until the
    /// rebuild that `coarse_refresh` schedules.
    #[test]
    fn coarse_space_follows_the_keys_and_is_rebuilt_on_schedule() {
        let a = strip(200, 8);
        let n = a.n();
        let b: Vec<f64> = (0..n).map(|i| 1.0 + ((i * 7919) % 97) as f64 / 97.0).collect();
        let keys: Vec<u32> = (0..n as u32).collect();
        let mut s = two_level_cg(3);
        let (p0, fresh) = keyed_cg(&mut s, &a, &b, &keys, false);
        // The same system renumbered (row k of `r` is row perm[k] of `a`).
        let perm: Vec<usize> = (0..n).map(|k| (k * 37) % n).collect();
        let mut inv = vec![0; n];
        for (k, &i) in perm.iter().enumerate() {
            inv[i] = k;
        }
        let mut r = PpeMatrix { row_ptr: vec![0], ..Default::default() };
        for &i in &perm {
            for (c, v) in a.row(i) {
                r.push(inv[c as usize], v);
            }
            r.end_row();
        }
        let rb: Vec<f64> = perm.iter().map(|&i| b[i]).collect();
        let rkeys: Vec<u32> = perm.iter().map(|&i| i as u32).collect();
        let (pr, kept) = keyed_cg(&mut s, &r, &rb, &rkeys, false);
        assert!(kept.abs_diff(fresh) <= 1, "renumbered: {kept} iterations against {fresh}");
        let err = perm.iter().enumerate().map(|(k, &i)| (pr[k] - p0[i]).abs()).fold(0.0, f64::max);
        let scale = p0.iter().map(|x| x.abs()).fold(0.0, f64::max);
        assert!(err < 1e-7 * scale, "{err} vs {scale}");
        // Unknown keys: Jacobi alone until the third solve since the rebuild rebuilds.
        let new_keys: Vec<u32> = (n as u32..2 * n as u32).collect();
        let (_, jacobi) = keyed_cg(&mut s, &a, &b, &new_keys, false);
        let (_, rebuilt) = keyed_cg(&mut s, &a, &b, &new_keys, false);
        assert!(jacobi > 2 * fresh, "unknown keys: {jacobi} iterations against {fresh}");
        assert_eq!(rebuilt, fresh, "rebuilt on schedule");
    }

    /// A coarse space that has aged (here: every row's key unseen, so the coarse
    /// correction is gone) is rebuilt at the next solve once a solve took more than
    /// twice the iterations of the first solve after the last rebuild (plus 4), long
    /// before the `coarse_refresh` schedule would.
    #[test]
    fn degraded_coarse_space_is_rebuilt_early() {
        let a = strip(200, 8);
        let n = a.n();
        let b: Vec<f64> = (0..n).map(|i| 1.0 + ((i * 7919) % 97) as f64 / 97.0).collect();
        let keys: Vec<u32> = (0..n as u32).collect();
        let new_keys: Vec<u32> = (n as u32..2 * n as u32).collect();
        let mut s = two_level_cg(1000);
        let (_, fresh) = keyed_cg(&mut s, &a, &b, &keys, false);
        let (_, jacobi) = keyed_cg(&mut s, &a, &b, &new_keys, false);
        let (_, rebuilt) = keyed_cg(&mut s, &a, &b, &new_keys, false);
        assert!(jacobi > 2 * fresh + 4, "unknown keys: {jacobi} iterations against {fresh}");
        assert_eq!(rebuilt, fresh, "rebuilt after the degraded solve");
    }

    /// The strip with one-way links in its first row of cells, as an open channel's inlet
    /// buffer makes them (a buffer particle shares the unknown of the fluid particle
    /// inside it: the rows next to it gain that unknown's column, whose row does not gain
    /// theirs), keeping the rows' sums.
    fn strip_with_inlet_links(rows: usize, m: usize) -> PpeMatrix {
        let s = strip(rows, m);
        let mut a = PpeMatrix { row_ptr: vec![0], ..Default::default() };
        for k in 0..s.n() {
            for (c, v) in s.row(k) {
                a.push(c as usize, v);
            }
            if k < m {
                a.push(k + 2 * m, -0.5);
                a.push(k, 0.5);
            }
            a.end_row();
        }
        a
    }

    /// A non-symmetric system (the open channel's PPE) gets an LU coarse factor and the
    /// two-level BiCGSTAB keeps its advantage over Jacobi; symmetric systems keep the
    /// Cholesky factor.
    #[test]
    fn non_symmetric_system_gets_an_lu_coarse_factor() {
        let solver = |preconditioner| {
            PpeSolve::new(PpeOptions {
                solver: PpeSolver::Bicgstab,
                tolerance: 1e-10,
                max_iterations: 20_000,
                preconditioner,
                coarse_refresh: 1,
            })
        };
        let symmetric = strip(400, 8);
        let a = strip_with_inlet_links(400, 8);
        let n = a.n();
        let b: Vec<f64> = (0..n).map(|i| 1.0 + ((i * 7919) % 97) as f64 / 97.0).collect();
        let mut p = vec![0.0; n];
        let mut s = solver(PreconditionerKind::TwoLevel);
        s.solve(&symmetric, &b, &mut p, false).expect("converges");
        assert_eq!(s.coarse.factor_kind(), Some(CoarseFactor::Cholesky));
        let mut pt = vec![0.0; n];
        let two = s.solve(&a, &b, &mut pt, false).expect("converges").iterations;
        assert_eq!(s.coarse.factor_kind(), Some(CoarseFactor::Lu));
        let mut pd = vec![0.0; n];
        direct(&a, &b, &mut pd, false).expect("LU solves");
        let mut pj = vec![0.0; n];
        let jacobi =
            solver(PreconditionerKind::Jacobi).solve(&a, &b, &mut pj, false).expect("converges").iterations;
        let scale = pd.iter().map(|x| x.abs()).fold(0.0, f64::max);
        for (name, x) in [("two-level", &pt), ("Jacobi", &pj)] {
            let err = pd.iter().zip(x).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max);
            assert!(err < 1e-7 * scale, "{name}: {err} vs {scale}");
        }
        assert!(3 * two < jacobi, "two-level {two} iterations, Jacobi {jacobi}");
    }

    /// A system with no Dirichlet row (the periodic channel's PPE) keeps its coarse
    /// correction: the coarse null space is grounded.
    #[test]
    fn two_level_solves_a_singular_system() {
        // A periodic 400 × 8 strip: the 5-point Laplacian wrapped along the long axis and
        // with Neumann rows across (rows sum to zero).
        let (rows, m) = (400, 8);
        let mut a = PpeMatrix { row_ptr: vec![0], ..Default::default() };
        for i in 0..rows {
            for j in 0..m {
                let k = i * m + j;
                let mut off = vec![((i + rows - 1) % rows) * m + j, ((i + 1) % rows) * m + j];
                if j > 0 {
                    off.push(k - 1);
                }
                if j + 1 < m {
                    off.push(k + 1);
                }
                a.push(k, off.len() as f64);
                for c in off {
                    a.push(c, -1.0);
                }
                a.end_row();
            }
        }
        let n = a.n();
        let b: Vec<f64> = (0..n).map(|i| (i as f64 * 0.013).sin() + 0.3).collect();
        let keys: Vec<u32> = (0..n as u32).collect();
        let mut jacobi = PpeSolve::new(PpeOptions {
            solver: PpeSolver::Cg,
            tolerance: 1e-10,
            max_iterations: 20_000,
            preconditioner: PreconditionerKind::Jacobi,
            coarse_refresh: 1,
        });
        let mut pj = vec![0.0; n];
        let j = jacobi.solve(&a, &b, &mut pj, true).expect("Jacobi converges").iterations;
        let (pt, t) = keyed_cg(&mut two_level_cg(25), &a, &b, &keys, true);
        let err = pj.iter().zip(&pt).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max);
        let scale = pj.iter().map(|x| x.abs()).fold(0.0, f64::max);
        assert!(err < 1e-7 * scale, "{err} vs {scale}");
        assert!(pt.iter().sum::<f64>().abs() < 1e-8 * scale * n as f64);
        assert!(2 * t < j, "two-level {t} iterations, Jacobi {j}");
    }

    #[test]
    fn all_solvers_agree_on_a_poisson_problem() {
        let a = grid(20);
        let n = a.n();
        let x_true: Vec<f64> = (0..n).map(|i| ((i * 7919) % 97) as f64 / 97.0).collect();
        let mut b = vec![0.0; n];
        a.mul(&x_true, &mut b);
        for solver in [PpeSolver::Cg, PpeSolver::Bicgstab, PpeSolver::Direct] {
            let mut s = PpeSolve::new(PpeOptions {
                solver,
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
    fn triplet_form_is_the_same_matrix() {
        let a = grid(7);
        let m = SparseColMat::<usize, f64>::try_new_from_triplets(a.n(), a.n(), &a.to_triplets()).unwrap();
        let x: Vec<f64> = (0..a.n()).map(|i| (i as f64).sin()).collect();
        let mut y = vec![0.0; a.n()];
        a.mul(&x, &mut y);
        let xm = faer::Mat::<f64>::from_fn(a.n(), 1, |i, _| x[i]);
        let ym = &m * &xm;
        for i in 0..a.n() {
            assert!((ym[(i, 0)] - y[i]).abs() < 1e-12);
        }
    }

    #[test]
    fn non_convergence_is_a_typed_error() {
        let a = grid(30);
        let b = vec![1.0; a.n()];
        let mut s = PpeSolve::new(PpeOptions {
            solver: PpeSolver::Cg,
            tolerance: 1e-12,
            max_iterations: 3,
            preconditioner: PreconditionerKind::Jacobi,
            coarse_refresh: 1,
        });
        let mut p = vec![0.0; a.n()];
        assert!(matches!(s.solve(&a, &b, &mut p, false), Err(Cause::PpeNoConvergence { .. })));
    }

    #[test]
    fn singular_system_is_projected() {
        // Periodic 1D Laplacian: rows sum to zero.
        let n = 50;
        let mut a = PpeMatrix { row_ptr: vec![0], ..Default::default() };
        for i in 0..n {
            for (c, v) in [((i + n - 1) % n, -1.0), (i, 2.0), ((i + 1) % n, -1.0)] {
                a.push(c, v);
            }
            a.end_row();
        }
        let b: Vec<f64> = (0..n).map(|i| (i as f64 * 0.3).sin() + 0.7).collect();
        for solver in [PpeSolver::Cg, PpeSolver::Bicgstab, PpeSolver::Direct] {
            let mut s = PpeSolve::new(PpeOptions {
                solver,
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
