//! The pressure Poisson equation: assembly (pairs per second) with either divergence
//! form, and the solve per solver (particles per second), each solve starting from the
//! pressure at the start of the step.

use crate::{Per, bench_stage};
use criterion::Criterion;
use meniscus::scene::{PpeSolver, Preconditioner};
use meniscus_benches::{with_corrected_divergence, with_ppe_solver};

/// `ppe_assemble` with Qiu's eq. 10 divergence and with the corrected one.
pub(crate) fn assemble(c: &mut Criterion) {
    bench_stage(c, "ppe_assemble", "standard", "ppe_assemble", Per::Pair, true, Clone::clone);
    bench_stage(c, "ppe_assemble", "corrected", "ppe_assemble", Per::Pair, true, with_corrected_divergence);
}

/// `ppe_solve` with BiCGSTAB and CG (Jacobi, tolerance 1e-3), CG with the two-level
/// preconditioner (its coarse space kept across the repeated solves and rebuilt every 25,
/// as in a run) and the sparse LU.
pub(crate) fn solve(c: &mut Criterion) {
    for (id, solver, preconditioner) in [
        ("bicgstab", PpeSolver::Bicgstab, Preconditioner::Jacobi),
        ("cg", PpeSolver::Cg, Preconditioner::Jacobi),
        ("cg_two_level", PpeSolver::Cg, Preconditioner::TwoLevel),
        ("direct", PpeSolver::Direct, Preconditioner::Jacobi),
    ] {
        bench_stage(c, "ppe_solve", id, "ppe_solve", Per::Particle, true, |s| {
            with_ppe_solver(s, solver, preconditioner)
        });
    }
}
