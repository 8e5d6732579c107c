//! Preconditioned conjugate gradient and BiCGSTAB over any [`RowOperator`], with parallel
//! vector operations whose results do not depend on the thread count.
//!
//! Why not faer's `matrix_free` solvers, which the solver used before: with `Par::Seq`
//! their vector updates and dot products run on one thread, and the solve became the part
//! of a step that scales worst (1.39× on 2 threads at Δx = 0.01 in the elliptical drop,
//! where it is half the step); with `Par::rayon` their reductions split by thread count,
//! so 1 and 2 threads give different bits, which breaks the determinism contract (the same
//! scene gives bit-identical probes with any thread count). Here every reduction sums
//! fixed blocks of [`BLOCK`] entries in parallel and adds the block sums serially in block
//! order, so the result is the same for every thread count.
//!
//! Every pass over the vectors is one parallel loop over those blocks (the matrix product
//! also splits each block's rows among the threads), and the work of an
//! iteration is fused into as few passes as the recurrence allows: a matrix product with
//! the dot product that follows it, a vector update with its norm, and with a diagonal
//! (Jacobi) preconditioner also with the preconditioner's application. On cache-resident
//! vectors a pass costs less than the fork-join that starts it, so the number of passes,
//! not the arithmetic, sets the time: BiCGSTAB takes 5 passes per iteration instead of
//! 10, CG 3 instead of 6 (docs/notes/ppe-solvers.md). The fused passes do the
//! same arithmetic in the same order as the separate ones, so the iterates are the same
//! bits.
//!
//! Algorithms: Saad, *Iterative Methods for Sparse Linear Systems*, 2nd ed., Alg. 9.1
//! (preconditioned CG) and van der Vorst 1992 / Barrett et al., *Templates* (1994) §2.3.8
//! (BiCGSTAB, right preconditioned). Both stop when the recursively updated residual
//! satisfies `‖r‖ ≤ tol ‖b‖`; the caller measures the true residual afterwards.

use super::RowOperator;
use rayon::prelude::*;

/// Entries per block of a reduction: the unit of parallel work and of the fixed
/// summation order.
pub const BLOCK: usize = 2048;

/// `z = M⁻¹ r` for a preconditioner `M`.
pub trait Preconditioner: Sync {
    /// Writes `M⁻¹ r` into `z` (both of the system's size).
    fn apply(&self, r: &[f64], z: &mut [f64]);

    /// `Some(d)` when `M⁻¹ = diag(d)`: the solvers then apply it inside their vector
    /// passes instead of in a pass of its own (the same products, so the same bits).
    fn diagonal(&self) -> Option<&[f64]> {
        None
    }
}

/// Stopping rule of a solve.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct KrylovParams {
    /// Relative tolerance on the residual, `‖b − A x‖ ≤ tol ‖b‖`.
    pub tolerance: f64,
    /// Iteration cap.
    pub max_iterations: usize,
}

/// A solve that ended without meeting its tolerance.
#[derive(Debug, Clone, PartialEq)]
pub enum KrylovError {
    /// The iteration cap was reached; `residual` is the last `‖r‖/‖b‖`.
    NoConvergence {
        /// Last relative residual.
        residual: f64,
    },
    /// A scalar of the recurrence was zero or not finite (`what` names it).
    Breakdown {
        /// The scalar that broke down.
        what: &'static str,
    },
}

/// Reusable vectors of the solvers (resized on use: no allocation per step once the
/// system size has been seen).
#[derive(Debug, Default, Clone)]
pub struct Workspace {
    r: Vec<f64>,
    r_hat: Vec<f64>,
    p: Vec<f64>,
    p_hat: Vec<f64>,
    v: Vec<f64>,
    s: Vec<f64>,
    s_hat: Vec<f64>,
    t: Vec<f64>,
    partials: Vec<[f64; 2]>,
}

impl Workspace {
    fn resize(&mut self, n: usize) {
        for v in [
            &mut self.r,
            &mut self.r_hat,
            &mut self.p,
            &mut self.p_hat,
            &mut self.v,
            &mut self.s,
            &mut self.s_hat,
            &mut self.t,
        ] {
            v.resize(n, 0.0);
        }
        self.partials.resize(n.div_ceil(BLOCK), [0.0; 2]);
    }
}

/// The block sums added in block order.
fn total(partials: &[[f64; 2]]) -> [f64; 2] {
    partials.iter().fold([0.0; 2], |s, p| [s[0] + p[0], s[1] + p[1]])
}

/// `(Σ g₀(i), Σ g₁(i))` over `0..n`, summed block by block (deterministic).
fn reduce(n: usize, partials: &mut [[f64; 2]], g: impl Fn(usize) -> [f64; 2] + Sync) -> [f64; 2] {
    partials.par_iter_mut().enumerate().for_each(|(blk, acc)| {
        let mut sum = [0.0; 2];
        for i in blk * BLOCK..((blk + 1) * BLOCK).min(n) {
            let [a, b] = g(i);
            sum[0] += a;
            sum[1] += b;
        }
        *acc = sum;
    });
    total(partials)
}

/// One pass over the blocks: `out[i] = f(i, out[i])`, and `z[i] = d[i] out[i]` when a
/// diagonal `(z, d)` is given; returns `(Σ g₀, Σ g₁)` of `g(i, out[i])` (the new values)
/// summed block by block.
fn pass(
    out: &mut [f64],
    z: Option<(&mut [f64], &[f64])>,
    partials: &mut [[f64; 2]],
    f: impl Fn(usize, f64) -> f64 + Sync,
    g: impl Fn(usize, f64) -> [f64; 2] + Sync,
) -> [f64; 2] {
    let body = |blk: usize, chunk: &mut [f64], mut zd: Option<(&mut [f64], &[f64])>, acc: &mut [f64; 2]| {
        let mut sum = [0.0; 2];
        for (k, o) in chunk.iter_mut().enumerate() {
            let i = blk * BLOCK + k;
            *o = f(i, *o);
            if let Some((zc, d)) = zd.as_mut() {
                zc[k] = d[i] * *o;
            }
            let [a, b] = g(i, *o);
            sum[0] += a;
            sum[1] += b;
        }
        *acc = sum;
    };
    match z {
        Some((z, d)) => out
            .par_chunks_mut(BLOCK)
            .zip(z.par_chunks_mut(BLOCK))
            .zip(partials.par_iter_mut())
            .enumerate()
            .for_each(|(blk, ((chunk, zc), acc))| body(blk, chunk, Some((zc, d)), acc)),
        None => out
            .par_chunks_mut(BLOCK)
            .zip(partials.par_iter_mut())
            .enumerate()
            .for_each(|(blk, (chunk, acc))| body(blk, chunk, None, acc)),
    }
    total(partials)
}

/// `out[i] = f(i, out[i])`, returning `(Σ g₀, Σ g₁)` of the new values (one pass).
fn update(
    out: &mut [f64],
    partials: &mut [[f64; 2]],
    f: impl Fn(usize, f64) -> f64 + Sync,
    g: impl Fn(usize, f64) -> [f64; 2] + Sync,
) -> [f64; 2] {
    pass(out, None, partials, f, g)
}

/// [`update`], then `z = M⁻¹ out`: in the same pass when `m` is diagonal.
fn update_preconditioned(
    out: &mut [f64],
    z: &mut [f64],
    m: &impl Preconditioner,
    partials: &mut [[f64; 2]],
    f: impl Fn(usize, f64) -> f64 + Sync,
    g: impl Fn(usize, f64) -> [f64; 2] + Sync,
) -> [f64; 2] {
    match m.diagonal() {
        Some(d) => pass(out, Some((z, d)), partials, f, g),
        None => {
            let sums = pass(out, None, partials, f, g);
            m.apply(out, z);
            sums
        }
    }
}

/// `y[i] = h(i, (A x)_i)`, returning `(Σ g₀, Σ g₁)` of `g(i, y[i])` summed block by block
/// (one pass). The product is split finer than a block, so that few blocks still share
/// out evenly among the threads (docs/notes/ppe-solvers.md); each block then sums its rows
/// in order, so the sums are still the same bits.
fn mul_reduce(
    a: &impl RowOperator,
    x: &[f64],
    y: &mut [f64],
    partials: &mut [[f64; 2]],
    h: impl Fn(usize, f64) -> f64 + Sync,
    g: impl Fn(usize, f64) -> [f64; 2] + Sync,
) -> [f64; 2] {
    y.par_chunks_mut(BLOCK).zip(partials.par_iter_mut()).enumerate().for_each(|(blk, (chunk, acc))| {
        let base = blk * BLOCK;
        chunk.par_iter_mut().enumerate().with_min_len(256).for_each(|(k, yi)| {
            *yi = h(base + k, a.row_dot(base + k, x));
        });
        let mut sum = [0.0; 2];
        for (k, &yi) in chunk.iter().enumerate() {
            let [p, q] = g(base + k, yi);
            sum[0] += p;
            sum[1] += q;
        }
        *acc = sum;
    });
    total(partials)
}

/// A scalar that must be finite and non-zero for the recurrence to go on.
fn usable(value: f64, what: &'static str) -> Result<f64, KrylovError> {
    if value.is_finite() && value != 0.0 { Ok(value) } else { Err(KrylovError::Breakdown { what }) }
}

/// `‖b‖`, and `r = b − A x` with `‖r‖²`.
fn start(a: &impl RowOperator, b: &[f64], x: &[f64], ws: &mut Workspace) -> (f64, f64) {
    let n = b.len();
    ws.resize(n);
    let b_norm = reduce(n, &mut ws.partials, |i| [b[i] * b[i], 0.0])[0].sqrt();
    let rr = mul_reduce(a, x, &mut ws.r, &mut ws.partials, |i, ax| b[i] - ax, |_, r| [r * r, 0.0])[0];
    (b_norm, rr)
}

/// Preconditioned conjugate gradient (Saad Alg. 9.1) for symmetric positive (semi-)definite
/// `A`: solves `A x = b` from the initial guess in `x`; returns the iterations taken.
pub fn conjugate_gradient(
    a: &impl RowOperator,
    m: &impl Preconditioner,
    b: &[f64],
    x: &mut [f64],
    params: KrylovParams,
    ws: &mut Workspace,
) -> Result<usize, KrylovError> {
    let n = b.len();
    let (b_norm, mut rr) = start(a, b, x, ws);
    let stop = params.tolerance * b_norm;
    if rr.sqrt() <= stop {
        return Ok(0);
    }
    let Workspace { r, p, v: q, s: z, partials, .. } = ws;
    m.apply(r, z);
    p.copy_from_slice(z);
    let mut rz = reduce(n, partials, |i| [r[i] * z[i], 0.0])[0];
    for it in 1..=params.max_iterations {
        // q = A p with pᵀq.
        let pq = mul_reduce(a, p, q, partials, |_, y| y, |i, qi| [p[i] * qi, 0.0])[0];
        let alpha = rz / usable(pq, "pᵀAp")?;
        // x += α p and r −= α q in one pass, with ‖r‖², z = M⁻¹ r and rᵀz.
        let [r2, rz_new] = match m.diagonal() {
            Some(d) => {
                x.par_chunks_mut(BLOCK)
                    .zip(r.par_chunks_mut(BLOCK))
                    .zip(z.par_chunks_mut(BLOCK))
                    .zip(partials.par_iter_mut())
                    .enumerate()
                    .for_each(|(blk, (((xc, rc), zc), acc))| {
                        let mut sum = [0.0; 2];
                        for k in 0..rc.len() {
                            let i = blk * BLOCK + k;
                            xc[k] += alpha * p[i];
                            rc[k] -= alpha * q[i];
                            zc[k] = d[i] * rc[k];
                            sum[0] += rc[k] * rc[k];
                            sum[1] += rc[k] * zc[k];
                        }
                        *acc = sum;
                    });
                total(partials)
            }
            None => {
                update(x, partials, |i, xi| xi + alpha * p[i], |_, _| [0.0; 2]);
                let r2 = update(r, partials, |i, ri| ri - alpha * q[i], |_, r| [r * r, 0.0])[0];
                m.apply(r, z);
                [r2, reduce(n, partials, |i| [r[i] * z[i], 0.0])[0]]
            }
        };
        rr = r2;
        if rr.sqrt() <= stop {
            return Ok(it);
        }
        let beta = rz_new / usable(rz, "rᵀz")?;
        rz = rz_new;
        let z = &*z;
        update(p, partials, |i, pi| z[i] + beta * pi, |_, _| [0.0; 2]);
    }
    Err(KrylovError::NoConvergence { residual: rr.sqrt() / b_norm })
}

/// BiCGSTAB with right preconditioning (van der Vorst 1992; *Templates* §2.3.8): solves
/// `A x = b` from the initial guess in `x`; returns the iterations taken.
pub fn bicgstab(
    a: &impl RowOperator,
    m: &impl Preconditioner,
    b: &[f64],
    x: &mut [f64],
    params: KrylovParams,
    ws: &mut Workspace,
) -> Result<usize, KrylovError> {
    let (b_norm, mut rr) = start(a, b, x, ws);
    let stop = params.tolerance * b_norm;
    if rr.sqrt() <= stop {
        return Ok(0);
    }
    let Workspace { r, r_hat, p, p_hat, v, s, s_hat, t, partials } = ws;
    r_hat.copy_from_slice(r);
    // p = v = 0, so the first direction is p = r.
    p.fill(0.0);
    v.fill(0.0);
    let (mut rho_prev, mut alpha, mut omega) = (1.0, 1.0, 1.0);
    let mut rho = rr;
    for it in 1..=params.max_iterations {
        usable(rho, "r̂ᵀr")?;
        let beta = (rho / rho_prev) * (alpha / omega);
        // p = r + β (p − ω v), p̂ = M⁻¹ p.
        {
            let (r, v) = (&*r, &*v);
            update_preconditioned(
                p,
                p_hat,
                m,
                partials,
                |i, pi| r[i] + beta * (pi - omega * v[i]),
                |_, _| [0.0; 2],
            );
        }
        // v = A p̂ with r̂ᵀv.
        let rv = mul_reduce(a, p_hat, v, partials, |_, y| y, |i, vi| [r_hat[i] * vi, 0.0])[0];
        alpha = rho / usable(rv, "r̂ᵀv")?;
        // s = r − α v with ‖s‖², ŝ = M⁻¹ s.
        let ss = {
            let (r, v) = (&*r, &*v);
            update_preconditioned(s, s_hat, m, partials, |i, _| r[i] - alpha * v[i], |_, s| [s * s, 0.0])[0]
        };
        if ss.sqrt() <= stop {
            let p_hat = &*p_hat;
            update(x, partials, |i, xi| xi + alpha * p_hat[i], |_, _| [0.0; 2]);
            return Ok(it);
        }
        // t = A ŝ with tᵀs and tᵀt.
        let [ts, tt] = mul_reduce(a, s_hat, t, partials, |_, y| y, |i, ti| [ti * s[i], ti * ti]);
        omega = usable(ts / usable(tt, "tᵀt")?, "ω")?;
        // x += α p̂ + ω ŝ and r = s − ω t in one pass, with ‖r‖² and r̂ᵀr.
        x.par_chunks_mut(BLOCK)
            .zip(r.par_chunks_mut(BLOCK))
            .zip(partials.par_iter_mut())
            .enumerate()
            .for_each(|(blk, ((xc, rc), acc))| {
                let mut sum = [0.0; 2];
                for k in 0..rc.len() {
                    let i = blk * BLOCK + k;
                    xc[k] = xc[k] + alpha * p_hat[i] + omega * s_hat[i];
                    rc[k] = s[i] - omega * t[i];
                    sum[0] += rc[k] * rc[k];
                    sum[1] += r_hat[i] * rc[k];
                }
                *acc = sum;
            });
        let [r2, rho_next] = total(partials);
        rr = r2;
        if rr.sqrt() <= stop {
            return Ok(it);
        }
        rho_prev = rho;
        rho = rho_next;
    }
    Err(KrylovError::NoConvergence { residual: rr.sqrt() / b_norm })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::linalg::CsrMatrix;

    /// 5-point Laplacian on an m×m grid (Dirichlet boundary) plus `skew` times a centred
    /// first difference along x (non-symmetric for `skew ≠ 0`).
    fn operator(m: usize, skew: f64) -> CsrMatrix {
        let mut a = CsrMatrix { row_ptr: vec![0], ..Default::default() };
        for i in 0..m {
            for j in 0..m {
                let k = i * m + j;
                a.push(k, 4.0);
                for (ok, c, v) in [
                    (i > 0, k.wrapping_sub(m), -1.0),
                    (j > 0, k.wrapping_sub(1), -1.0 - skew),
                    (j + 1 < m, k + 1, -1.0 + skew),
                    (i + 1 < m, k + m, -1.0),
                ] {
                    if ok {
                        a.push(c, v);
                    }
                }
                a.end_row();
            }
        }
        a
    }

    struct Jacobi<'a>(&'a [f64]);
    impl Preconditioner for Jacobi<'_> {
        fn apply(&self, r: &[f64], z: &mut [f64]) {
            z.iter_mut().zip(r).zip(self.0).for_each(|((z, r), d)| *z = d * r);
        }
    }

    type Solver = fn(
        &CsrMatrix,
        &Jacobi<'_>,
        &[f64],
        &mut [f64],
        KrylovParams,
        &mut Workspace,
    ) -> Result<usize, KrylovError>;

    fn cg(
        a: &CsrMatrix,
        m: &Jacobi<'_>,
        b: &[f64],
        x: &mut [f64],
        p: KrylovParams,
        w: &mut Workspace,
    ) -> Result<usize, KrylovError> {
        conjugate_gradient(a, m, b, x, p, w)
    }

    fn bi(
        a: &CsrMatrix,
        m: &Jacobi<'_>,
        b: &[f64],
        x: &mut [f64],
        p: KrylovParams,
        w: &mut Workspace,
    ) -> Result<usize, KrylovError> {
        bicgstab(a, m, b, x, p, w)
    }

    fn solve_with(threads: usize, a: &CsrMatrix, solver: Solver) -> (Vec<f64>, usize) {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().expect("a thread pool");
        pool.install(|| {
            let b: Vec<f64> = (0..a.n()).map(|i| ((i * 7919) % 101) as f64 / 101.0 - 0.4).collect();
            let mut x = vec![0.0; a.n()];
            let params = KrylovParams { tolerance: 1e-10, max_iterations: 2000 };
            let it = solver(a, &Jacobi(&a.inv_diag), &b, &mut x, params, &mut Workspace::default())
                .expect("converges");
            let mut ax = vec![0.0; a.n()];
            a.mul(&x, &mut ax);
            let res = ax.iter().zip(&b).map(|(p, q)| (p - q) * (p - q)).sum::<f64>().sqrt();
            let bn = b.iter().map(|q| q * q).sum::<f64>().sqrt();
            assert!(res <= 1e-9 * bn, "true residual {res} vs ‖b‖ {bn}");
            (x, it)
        })
    }

    /// Several blocks (m² = 4900 > 2 BLOCK): the same bits with 1, 2 and 3 threads, and
    /// the true residual meets the tolerance.
    #[test]
    fn solutions_are_bit_identical_for_any_thread_count() {
        for (a, solver) in [(operator(70, 0.0), cg as Solver), (operator(70, 0.3), bi as Solver)] {
            let (x1, it1) = solve_with(1, &a, solver);
            for threads in [2, 3] {
                let (x, it) = solve_with(threads, &a, solver);
                assert_eq!(it, it1);
                assert!(x.iter().zip(&x1).all(|(p, q)| p.to_bits() == q.to_bits()), "{threads} threads");
            }
        }
    }

    #[test]
    fn a_singular_operator_is_a_typed_breakdown() {
        let mut a = operator(10, 0.0);
        a.vals.iter_mut().for_each(|v| *v = 0.0);
        a.diag.iter_mut().for_each(|v| *v = 0.0);
        let b = vec![1.0; a.n()];
        let params = KrylovParams { tolerance: 1e-8, max_iterations: 50 };
        for solver in [cg as Solver, bi as Solver] {
            let mut x = vec![0.0; a.n()];
            let got = solver(&a, &Jacobi(&a.inv_diag), &b, &mut x, params, &mut Workspace::default());
            assert!(matches!(got, Err(KrylovError::Breakdown { .. })), "{got:?}");
        }
    }

    #[test]
    fn the_iteration_cap_is_a_typed_error_with_the_residual() {
        let a = operator(30, 0.0);
        let b = vec![1.0; a.n()];
        let mut x = vec![0.0; a.n()];
        let params = KrylovParams { tolerance: 1e-12, max_iterations: 3 };
        match bicgstab(&a, &Jacobi(&a.inv_diag), &b, &mut x, params, &mut Workspace::default()) {
            Err(KrylovError::NoConvergence { residual }) => {
                assert!(residual > 1e-12 && residual.is_finite(), "{residual}")
            }
            other => panic!("{other:?}"),
        }
    }
}
