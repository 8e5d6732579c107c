//! The sparse matrix of the particle systems: compressed sparse rows with the diagonal
//! apart and `f32` off-diagonal values ([`CsrMatrix`]), assembled row-parallel
//! ([`par_csr_rows_mut`]).

use super::RowOperator;
use faer::sparse::Triplet;
use rayon::prelude::*;

/// Sparse matrix (the PPE's, the implicit viscous system's): the diagonal in `f64`, the off-diagonal entries in compressed sparse
/// rows with `f32` values, and the inverse diagonal (Jacobi).
///
/// Why `f32` off-diagonals: the matrix products are bound by memory traffic once the
/// matrix outgrows the cache, and 8 bytes per entry instead of 12 make an iteration
/// faster (measured: docs/notes/ppe-solvers.md). The assemblies round each pair coefficient to `f32` *before* using it, for the off-diagonal
/// entry and in the diagonal sum alike, so the stored matrix is exactly a Laplacian whose pair
/// coefficients moved by ≤ 6e-8 relative (far below the discretisation error), its rows
/// still sum to zero where the Laplacian's do, and it is still symmetric where the
/// Laplacian is (the constant null space of a closed domain is kept). The products are
/// summed in `f64`.
#[derive(Debug, Clone, Default)]
pub struct CsrMatrix {
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

impl CsrMatrix {
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
    /// loads, then sets the pace); four independent sums overlap them
    /// (docs/notes/ppe-solvers.md).
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
    /// `row_ptr = [0]`; call [`CsrMatrix::end_row`] after each row's entries). An entry in
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

    /// Ends the row being built (see [`CsrMatrix::push`]) and sets its inverse diagonal.
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

/// A pair coefficient rounded to the `f32` the matrix stores (see [`CsrMatrix`]): the
/// assemblies use the rounded value both off the diagonal and in the diagonal sum.
#[inline]
pub fn stored(c: f64) -> f64 {
    f64::from(c as f32)
}

impl RowOperator for CsrMatrix {
    fn rows(&self) -> usize {
        self.n()
    }

    #[inline]
    fn row_dot(&self, i: usize, x: &[f64]) -> f64 {
        CsrMatrix::row_dot(self, i, x)
    }
}

/// Fills the rows of a compressed sparse row matrix with a separate diagonal in parallel
/// (by recursive halving, each row written by one task; no allocation): `f(a, &mut cols[row a], &mut vals[row a], &mut diag[a])`.
pub fn par_csr_rows_mut<X: Send, Y: Send, Z: Send, F: Fn(usize, &mut [X], &mut [Y], &mut Z) + Sync>(
    offsets: &[usize],
    cols: &mut [X],
    vals: &mut [Y],
    diag: &mut [Z],
    f: &F,
) {
    fn rec<X: Send, Y: Send, Z: Send, F: Fn(usize, &mut [X], &mut [Y], &mut Z) + Sync>(
        lo: usize,
        hi: usize,
        offsets: &[usize],
        xs: &mut [X],
        ys: &mut [Y],
        zs: &mut [Z],
        f: &F,
    ) {
        if hi - lo <= 256 {
            let base = offsets[lo];
            for (a, z) in (lo..hi).zip(zs) {
                let (s, e) = (offsets[a] - base, offsets[a + 1] - base);
                f(a, &mut xs[s..e], &mut ys[s..e], z);
            }
        } else {
            let mid = lo + (hi - lo) / 2;
            let (xl, xr) = xs.split_at_mut(offsets[mid] - offsets[lo]);
            let (yl, yr) = ys.split_at_mut(offsets[mid] - offsets[lo]);
            let (zl, zr) = zs.split_at_mut(mid - lo);
            rayon::join(|| rec(lo, mid, offsets, xl, yl, zl, f), || rec(mid, hi, offsets, xr, yr, zr, f));
        }
    }
    let n = offsets.len().saturating_sub(1);
    if n > 0 {
        rec(0, n, offsets, cols, vals, &mut diag[..n], f);
    }
}

#[cfg(test)]
mod tests {
    use crate::linalg::testing::grid;
    use faer::sparse::SparseColMat;

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
}
