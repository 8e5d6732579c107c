//! faer's sparse LU, the direct solver of the particle systems.

use super::CsrMatrix;
use faer::Mat;
use faer::sparse::linalg::LuError;
use faer::sparse::linalg::solvers::Lu;
use faer::sparse::{SparseColMat, Triplet};

/// faer's sparse LU of `m`, with faer's global parallelism set to sequential first.
///
/// Why: faer parallelises by default (rayon over every thread of the current pool), and
/// one direct-solver run slowed every later two-thread run in the same process, skewing
/// the timings of `cargo xtask bench` (docs/notes/ppe-solvers.md). The solver's own loops
/// are its only parallel work.
pub fn sparse_lu(m: &SparseColMat<usize, f64>) -> Result<Lu<usize, f64>, LuError> {
    faer::set_global_parallelism(faer::Par::Seq);
    m.sp_lu()
}

/// faer's sparse LU solve of `A x = b` into `x`; a singular system gets `x_0 = 0` pinned
/// (its mean is fixed by the caller). The error is faer's, as text.
pub fn solve(a: &CsrMatrix, b: &[f64], x: &mut [f64], singular: bool) -> Result<(), String> {
    let n = a.n();
    let mut trip = a.to_triplets();
    let mut rhs = Mat::<f64>::from_fn(n, 1, |i, _| b[i]);
    if singular {
        // Pin p_0 = 0: replace row 0 by the identity.
        trip.retain(|t| t.row != 0);
        trip.push(Triplet::new(0, 0, 1.0));
        rhs[(0, 0)] = 0.0;
    }
    let m = SparseColMat::<usize, f64>::try_new_from_triplets(n, n, &trip).map_err(|e| format!("{e:?}"))?;
    let lu = sparse_lu(&m).map_err(|e| format!("{e:?}"))?;
    use faer::linalg::solvers::SolveCore;
    lu.solve_in_place_with_conj(faer::Conj::No, rhs.as_mut());
    for (xi, i) in x.iter_mut().zip(0..n) {
        *xi = rhs[(i, 0)];
    }
    Ok(())
}
