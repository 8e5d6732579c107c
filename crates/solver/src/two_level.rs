//! Two-level preconditioner for the PPE: Jacobi plus a coarse-space correction by plain
//! aggregation (the additive two-level Schwarz / aggregation-AMG idea: Vaněk, Mandel &
//! Brezina 1996; Toselli & Widlund 2005 ch. 2), `M⁻¹ = D⁻¹ + P A_c⁻¹ Pᵀ`, `A_c = Pᵀ A P`.
//!
//! Why: Jacobi leaves the smooth pressure modes to the Krylov solver, and their number of
//! iterations grows with the domain's length in particle spacings. A 15 D channel at D/36
//! (540 spacings long, one Dirichlet end) took 443 BiCGSTAB iterations per step; the
//! coarse space removes the smooth modes (measured in the commit that added it).
//!
//! Aggregates are built from the matrix graph (no geometry): rows are visited in order,
//! and an unassigned row starts an aggregate with its unassigned neighbours, so an
//! aggregate is about one kernel support of particles. `P` is piecewise constant on the
//! aggregates; `A_c` is assembled row by row with a sparse accumulator and factorised by
//! faer's sparse LU. faer has no incomplete factorisation or AMG, hence this small
//! hand-written coarse space.

use crate::ppe::PpeMatrix;
use faer::dyn_stack::{MemStack, StackReq};
use faer::linalg::solvers::SolveCore;
use faer::mat::{MatMut, MatRef};
use faer::matrix_free::{LinOp, Precond};
use faer::sparse::linalg::solvers::Lu;
use faer::sparse::{SparseColMat, Triplet};
use faer::{Mat, Par};
use std::sync::Mutex;

/// The preconditioner of one PPE matrix.
pub struct TwoLevel<'a> {
    inv_diag: &'a [f64],
    aggregate: Vec<u32>,
    lu: Lu<usize, f64>,
    coarse: Mutex<Mat<f64>>,
}

impl std::fmt::Debug for TwoLevel<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "TwoLevel {{ n: {}, coarse: {} }}", self.inv_diag.len(), self.coarse_size())
    }
}

impl<'a> TwoLevel<'a> {
    /// Builds the aggregates and factorises the coarse matrix of `a`; `None` when the
    /// coarse matrix is singular (a system with no Dirichlet row: the caller keeps Jacobi).
    pub fn new(a: &'a PpeMatrix) -> Option<Self> {
        let n = a.n();
        let mut aggregate = vec![u32::MAX; n];
        let mut count = 0u32;
        for i in 0..n {
            if aggregate[i] != u32::MAX {
                continue;
            }
            aggregate[i] = count;
            for &j in &a.cols[a.row_ptr[i]..a.row_ptr[i + 1]] {
                if aggregate[j as usize] == u32::MAX {
                    aggregate[j as usize] = count;
                }
            }
            count += 1;
        }
        let nc = count as usize;
        // Members of each aggregate, then A_c row by row with a sparse accumulator.
        let mut start = vec![0usize; nc + 1];
        for &g in &aggregate {
            start[g as usize + 1] += 1;
        }
        for g in 0..nc {
            start[g + 1] += start[g];
        }
        let mut members = vec![0u32; n];
        let mut fill = start.clone();
        for (i, &g) in aggregate.iter().enumerate() {
            members[fill[g as usize]] = i as u32;
            fill[g as usize] += 1;
        }
        let mut acc = vec![0.0; nc];
        let mut mark = vec![u32::MAX; nc];
        let mut touched: Vec<u32> = Vec::new();
        let mut triplets = Vec::new();
        for g in 0..nc {
            for &i in &members[start[g]..start[g + 1]] {
                let i = i as usize;
                for (j, v) in a.row(i) {
                    let h = aggregate[j as usize];
                    if mark[h as usize] != g as u32 {
                        mark[h as usize] = g as u32;
                        touched.push(h);
                    }
                    acc[h as usize] += v;
                }
            }
            for &h in &touched {
                triplets.push(Triplet::new(g, h as usize, acc[h as usize]));
                acc[h as usize] = 0.0;
            }
            touched.clear();
        }
        let m = SparseColMat::<usize, f64>::try_new_from_triplets(nc, nc, &triplets).ok()?;
        let lu = m.sp_lu().ok()?;
        // A singular coarse matrix factorises with a zero (or tiny) pivot: test it.
        let mut probe = Mat::<f64>::from_fn(nc, 1, |i, _| 1.0 + i as f64 / nc as f64);
        lu.solve_in_place_with_conj(faer::Conj::No, probe.as_mut());
        if !(0..nc).all(|i| probe[(i, 0)].is_finite()) || probe.norm_l2() > 1e12 * nc as f64 {
            return None;
        }
        Some(Self { inv_diag: &a.inv_diag, aggregate, lu, coarse: Mutex::new(Mat::zeros(nc, 1)) })
    }

    /// Number of aggregates.
    pub fn coarse_size(&self) -> usize {
        self.coarse.lock().map(|c| c.nrows()).unwrap_or(0)
    }
}

impl LinOp<f64> for TwoLevel<'_> {
    fn apply_scratch(&self, _rhs_ncols: usize, _par: Par) -> StackReq {
        StackReq::EMPTY
    }
    fn nrows(&self) -> usize {
        self.inv_diag.len()
    }
    fn ncols(&self) -> usize {
        self.inv_diag.len()
    }
    fn apply(&self, mut out: MatMut<'_, f64>, rhs: MatRef<'_, f64>, _par: Par, _stack: &mut MemStack) {
        let mut coarse = self.coarse.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
        for j in 0..rhs.ncols() {
            let x = rhs.col(j).try_as_col_major().expect("faer columns are contiguous");
            coarse.fill(0.0);
            for (xi, &g) in x.as_slice().iter().zip(&self.aggregate) {
                coarse[(g as usize, 0)] += xi;
            }
            self.lu.solve_in_place_with_conj(faer::Conj::No, coarse.as_mut());
            let y = out.as_mut().col_mut(j).try_as_col_major_mut().expect("faer columns are contiguous");
            for (((yi, xi), di), &g) in
                y.as_slice_mut().iter_mut().zip(x.as_slice()).zip(self.inv_diag).zip(&self.aggregate)
            {
                *yi = di * xi + coarse[(g as usize, 0)];
            }
        }
    }
    fn conj_apply(&self, out: MatMut<'_, f64>, rhs: MatRef<'_, f64>, par: Par, stack: &mut MemStack) {
        self.apply(out, rhs, par, stack);
    }
}

impl Precond<f64> for TwoLevel<'_> {}
