//! Two-level preconditioner for the PPE: Jacobi plus a coarse-space correction by plain
//! aggregation (the additive two-level Schwarz / aggregation-AMG idea: Vaněk, Mandel &
//! Brezina 1996; Toselli & Widlund 2005 ch. 2), `M⁻¹ = D⁻¹ + P A_c⁻¹ Pᵀ`, `A_c = Pᵀ A P`.
//!
//! Why: Jacobi leaves the smooth pressure modes to the Krylov solver, and their number of
//! iterations grows with the domain's size in particle spacings; the coarse space removes
//! the smooth modes (iterations measured: docs/notes/ppe-solvers.md).
//!
//! Aggregates are built from the matrix graph (no geometry): rows are visited in order,
//! and an unassigned row starts an aggregate with its unassigned neighbours, so an
//! aggregate is about one kernel support of particles. `P` is piecewise constant on the
//! aggregates; `A_c` is assembled row by row with a sparse accumulator and factorised by
//! faer's sparse Cholesky when it is symmetric (to rounding) and positive definite, which
//! it is when `A` is (free-surface, closed and periodic systems, mirror walls), and by
//! faer's sparse LU otherwise: the open channel's `A` is not symmetric (an inlet buffer
//! particle shares the unknown of a fluid particle, a one-way link), and a Cholesky
//! factor of its `A_c` fails.
//!
//! **The coarse space outlives a solve** ([`CoarseSpace`]): building it (aggregation,
//! assembly, the symbolic and numeric factorisation) costs several Krylov iterations.
//! Given a stable key per row (the particle id), the aggregates follow the particles, and
//! the factor of the last rebuild serves the next `refresh` solves: particles move little
//! relative to their neighbours in a step, so a factor a few steps old is still a good
//! coarse solve (docs/notes/ppe-solvers.md). Where it
//! ages faster (the open channel, whose particles enter, leave and shear), a solve that
//! takes over twice the iterations of the first one after the rebuild brings the next
//! rebuild forward ([`CoarseSpace::record`]). A row whose
//! key had no aggregate at the last rebuild (a particle that left the free surface, or came
//! in through an inlet) gets the Jacobi part only until the next rebuild. A stale Cholesky
//! factor is still symmetric positive definite, so `M` is a fixed SPD operator between
//! rebuilds and CG applies (an LU factor serves BiCGSTAB, the solver for a non-symmetric
//! `A`). Between rebuilds nothing is allocated; a rebuild allocates inside faer's symbolic
//! factorisation (the coarse pattern is new), and reuses every buffer of its own.
//!
//! A system with no Dirichlet row (a closed or periodic domain) has the constant vector as
//! its null space, and so has `A_c`: there the coarse unknown 0 is grounded (its row and
//! column replaced by the identity, its residual set to zero), which gives a generalised
//! inverse of `A_c` on mean-zero residuals and keeps `M` symmetric positive definite.
//!
//! faer has no incomplete factorisation or AMG, hence this small hand-written coarse space.

use super::CsrMatrix;
use super::krylov::Preconditioner;
use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::linalg::cholesky::llt::factor::LltRegularization;
use faer::sparse::linalg::cholesky::{
    CholeskySymbolicParams, LltRef, SymbolicCholesky, SymmetricOrdering, factorize_symbolic_cholesky,
};
use faer::sparse::linalg::lu::{LuRef, NumericLu, SymbolicLu, factorize_symbolic_lu};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use faer::{Conj, MatMut, Par, Side};
use rayon::prelude::*;
use std::sync::Mutex;

/// No aggregate (a row or key outside the coarse space).
const NONE: u32 = u32::MAX;

/// Solves between coarse-space rebuilds when the scene does not say
/// (`scheme.isph.ppe.coarse_refresh`).
pub const DEFAULT_REFRESH: usize = 25;

/// Relative asymmetry `|a_gh − a_hg| / (|a_gg| + |a_hh|)` above which `A_c` is taken as
/// non-symmetric: the rounding of the Galerkin sums of a symmetric `A` is ~1e-16, an inlet
/// link is a whole pair coefficient (~1e-2).
const ASYMMETRY: f64 = 1e-10;

/// Whether a solve of `iterations` shows the kept coarse space has degraded against the
/// `fresh` iterations of the first solve after its rebuild: more than 2 × fresh + 4.
///
/// Why: how fast a kept factor ages depends on the flow: on the elliptical drop a factor
/// 25 solves old costs nothing (its iteration spikes right after a rebuild must not trip
/// the rule), in the open channel particles enter, leave and shear past each other and the
/// iterations jump two or three solves after a rebuild (docs/notes/ppe-solvers.md).
fn degraded(iterations: usize, fresh: usize) -> bool {
    iterations > 2 * fresh + 4
}

/// How the coarse matrix was factorised at the last rebuild.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CoarseFactor {
    /// Sparse Cholesky (`A_c` symmetric positive definite).
    Cholesky,
    /// Sparse LU (`A_c` not symmetric, or not numerically positive definite).
    Lu,
}

/// The factorised coarse matrix.
#[derive(Debug)]
enum Factor {
    /// `A_c = L Lᵀ`.
    Cholesky { symbolic: SymbolicCholesky<usize>, values: Vec<f64> },
    /// The LU factors of `A_cᵀ` (the rows of `A_c` read as compressed columns); the
    /// coarse solve is its transposed solve.
    Lu { symbolic: SymbolicLu<usize>, numeric: NumericLu<usize, f64> },
}

/// Scratch of one preconditioner application: the coarse vector and faer's workspace.
#[derive(Default)]
struct ApplyScratch {
    coarse: Vec<f64>,
    /// faer's workspace, and the requirement it was sized for.
    mem: Option<(MemBuffer, StackReq)>,
}

/// The coarse space of the two-level preconditioner, kept across solves (see the module
/// documentation): aggregates keyed by a stable key per row and the factor of `A_c`,
/// rebuilt every `refresh` solves, or sooner when a solve shows it `degraded`.
#[derive(Debug)]
pub struct CoarseSpace {
    refresh: usize,
    /// Solves since the last rebuild.
    age: usize,
    /// Krylov iterations of the first solve after the last rebuild.
    fresh_iterations: usize,
    /// Whether a solve since the last rebuild took `degraded` iterations.
    degraded: bool,
    /// Whether the last rebuild grounded coarse unknown 0 (a singular system).
    grounded: bool,
    /// Aggregate of each key at the last rebuild (`NONE`: none).
    of_key: Vec<u32>,
    /// Aggregate of each row of the current system.
    of_row: Vec<u32>,
    /// Number of aggregates.
    nc: usize,
    factor: Option<Factor>,
    build: BuildScratch,
    scratch: Mutex<ApplyScratch>,
}

/// Buffers of a rebuild, kept so that a rebuild allocates only inside faer.
#[derive(Debug, Default)]
struct BuildScratch {
    /// Aggregate start offsets into `members`.
    start: Vec<usize>,
    /// Rows of each aggregate, aggregate by aggregate.
    members: Vec<u32>,
    acc: Vec<f64>,
    mark: Vec<u32>,
    touched: Vec<u32>,
    /// `A_c` in compressed sparse rows (columns sorted within a row).
    row_ptr: Vec<usize>,
    col_idx: Vec<usize>,
    values: Vec<f64>,
    /// The lower triangle of a symmetric `A_c` in compressed sparse columns (column g is
    /// row g's upper part).
    lower_ptr: Vec<usize>,
    lower_idx: Vec<usize>,
    lower_values: Vec<f64>,
}

impl CoarseSpace {
    /// An empty coarse space rebuilt every `refresh` solves (at least 1).
    pub fn new(refresh: usize) -> Self {
        Self {
            refresh: refresh.max(1),
            age: 0,
            fresh_iterations: 0,
            degraded: false,
            grounded: false,
            of_key: Vec::new(),
            of_row: Vec::new(),
            nc: 0,
            factor: None,
            build: BuildScratch::default(),
            scratch: Mutex::new(ApplyScratch::default()),
        }
    }

    /// Number of aggregates of the last rebuild.
    pub fn coarse_size(&self) -> usize {
        self.nc
    }

    /// How the last rebuild factorised `A_c` (`None`: it could not, Jacobi alone).
    pub fn factor_kind(&self) -> Option<CoarseFactor> {
        self.factor.as_ref().map(|f| match f {
            Factor::Cholesky { .. } => CoarseFactor::Cholesky,
            Factor::Lu { .. } => CoarseFactor::Lu,
        })
    }

    /// Readies the coarse space for a solve of `a`: rebuilds it when there is none yet (or
    /// the last one could not be factorised), when `refresh` solves have passed since the
    /// last rebuild, when a solve since then showed it `degraded`, when the system's
    /// kind (singular or not) changed, or when there are no `keys` (then every solve
    /// rebuilds); otherwise maps the current
    /// rows to the kept aggregates through `keys` (one per row). Returns whether a coarse
    /// correction is available (a coarse matrix that faer cannot factorise leaves Jacobi
    /// alone).
    pub fn prepare(&mut self, a: &CsrMatrix, keys: Option<&[u32]>, singular: bool) -> bool {
        let stale = keys.is_none()
            || self.factor.is_none()
            || self.age >= self.refresh
            || self.degraded
            || self.grounded != singular;
        match keys {
            Some(keys) if !stale => {
                debug_assert_eq!(keys.len(), a.n());
                let of_key = &self.of_key;
                self.of_row.clear();
                self.of_row.extend(keys.iter().map(|&k| of_key.get(k as usize).copied().unwrap_or(NONE)));
            }
            _ => {
                self.rebuild(a, singular);
                if let Some(keys) = keys {
                    let len = keys.iter().map(|&k| k as usize + 1).max().unwrap_or(0);
                    self.of_key.clear();
                    self.of_key.resize(len, NONE);
                    for (&k, &g) in keys.iter().zip(&self.of_row) {
                        self.of_key[k as usize] = g;
                    }
                }
                self.age = 0;
                self.degraded = false;
            }
        }
        self.age += 1;
        self.factor.is_some()
    }

    /// Records the Krylov iterations of the solve just preconditioned: the first solve
    /// after a rebuild sets the reference, and a later one that took `degraded`
    /// iterations schedules a rebuild for the next solve.
    pub fn record(&mut self, iterations: usize) {
        if self.age == 1 {
            self.fresh_iterations = iterations;
        } else if degraded(iterations, self.fresh_iterations) {
            self.degraded = true;
        }
    }

    /// The preconditioner `D⁻¹ + P A_c⁻¹ Pᵀ` for the current rows, `inv_diag` being
    /// `diag(A)⁻¹` of the current matrix.
    pub fn preconditioner<'a>(&'a self, inv_diag: &'a [f64]) -> TwoLevel<'a> {
        TwoLevel { space: self, inv_diag }
    }

    /// Aggregates the rows of `a`, assembles `A_c` and factorises it.
    fn rebuild(&mut self, a: &CsrMatrix, singular: bool) {
        let n = a.n();
        self.grounded = singular;
        let of_row = &mut self.of_row;
        of_row.clear();
        of_row.resize(n, NONE);
        let mut nc = 0u32;
        for i in 0..n {
            if of_row[i] != NONE {
                continue;
            }
            of_row[i] = nc;
            for &j in &a.cols[a.row_ptr[i]..a.row_ptr[i + 1]] {
                if of_row[j as usize] == NONE {
                    of_row[j as usize] = nc;
                }
            }
            nc += 1;
        }
        let nc = nc as usize;
        self.nc = nc;
        if nc == 0 {
            self.factor = None;
            return;
        }
        let b = &mut self.build;
        // Members of each aggregate (counting sort of the rows by aggregate).
        b.start.clear();
        b.start.resize(nc + 1, 0);
        for &g in of_row.iter() {
            b.start[g as usize + 1] += 1;
        }
        for g in 0..nc {
            b.start[g + 1] += b.start[g];
        }
        b.members.resize(n, 0);
        let BuildScratch { start, members, mark, .. } = b;
        mark.clear();
        mark.extend(start[..nc].iter().map(|&s| s as u32));
        for (i, &g) in of_row.iter().enumerate() {
            let slot = &mut mark[g as usize];
            members[*slot as usize] = i as u32;
            *slot += 1;
        }
        // A_c row by row (row g sums the rows of aggregate g, column h the entries in
        // aggregate h's columns), columns sorted; a grounded unknown 0 keeps only its unit
        // diagonal, in its row and its column.
        b.acc.clear();
        b.acc.resize(nc, 0.0);
        b.mark.clear();
        b.mark.resize(nc, NONE);
        b.row_ptr.clear();
        b.col_idx.clear();
        b.values.clear();
        b.row_ptr.push(0);
        for g in 0..nc {
            if singular && g == 0 {
                b.col_idx.push(0);
                b.values.push(1.0);
                b.row_ptr.push(b.col_idx.len());
                continue;
            }
            for &i in &b.members[b.start[g]..b.start[g + 1]] {
                for (j, v) in a.row(i as usize) {
                    let h = of_row[j as usize];
                    if singular && h == 0 {
                        continue;
                    }
                    if b.mark[h as usize] != g as u32 {
                        b.mark[h as usize] = g as u32;
                        b.touched.push(h);
                    }
                    b.acc[h as usize] += v;
                }
            }
            b.touched.sort_unstable();
            for &h in &b.touched {
                b.col_idx.push(h as usize);
                b.values.push(b.acc[h as usize]);
                b.acc[h as usize] = 0.0;
            }
            b.touched.clear();
            b.row_ptr.push(b.col_idx.len());
        }
        let values = match self.factor.take() {
            Some(Factor::Cholesky { values, .. }) => values,
            _ => Vec::new(),
        };
        let cholesky = if symmetric(nc, b) { cholesky(nc, b, values, &self.scratch) } else { None };
        self.factor = cholesky.or_else(|| lu(nc, b, &self.scratch));
        if self.factor.is_some() {
            let mut s = self.scratch.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
            s.coarse.resize(nc, 0.0);
        }
    }
}

/// Whether `A_c` (compressed rows in `b`) is symmetric to rounding: every `a_gh` has an
/// `a_hg` within `ASYMMETRY (|a_gg| + |a_hh|)`. Copies the upper part of each row into
/// `b`'s lower-triangle arrays (column g of the lower triangle), which the Cholesky
/// factorisation reads.
fn symmetric(nc: usize, b: &mut BuildScratch) -> bool {
    let BuildScratch { row_ptr, col_idx, values, lower_ptr, lower_idx, lower_values, .. } = b;
    let entry = |g: usize, h: usize| {
        let (s, e) = (row_ptr[g], row_ptr[g + 1]);
        col_idx[s..e].binary_search(&h).ok().map(|k| values[s + k])
    };
    lower_ptr.clear();
    lower_idx.clear();
    lower_values.clear();
    lower_ptr.push(0);
    for g in 0..nc {
        let a_gg = entry(g, g).unwrap_or(0.0).abs();
        for k in row_ptr[g]..row_ptr[g + 1] {
            let (h, v) = (col_idx[k], values[k]);
            if h < g {
                continue;
            }
            if h > g {
                let a_hh = entry(h, h).unwrap_or(0.0).abs();
                let tol = ASYMMETRY * (a_gg + a_hh);
                if entry(h, g).is_none_or(|w| (w - v).abs() > tol) {
                    return false;
                }
            }
            lower_idx.push(h);
            lower_values.push(v);
        }
        lower_ptr.push(lower_idx.len());
    }
    true
}

/// faer's workspace in `slot`, grown to at least `req`.
fn workspace(slot: &mut Option<(MemBuffer, StackReq)>, req: StackReq) -> &mut MemBuffer {
    let fits = slot.as_ref().is_some_and(|(_, have)| {
        have.size_bytes() >= req.size_bytes() && have.align_bytes() >= req.align_bytes()
    });
    if !fits {
        let grown = slot.as_ref().map_or(req, |(_, have)| have.or(req));
        *slot = Some((MemBuffer::new(grown), grown));
    }
    &mut slot.as_mut().expect("sized above").0
}

/// The Cholesky factor of the lower triangle of `A_c` (`b`'s lower-triangle arrays), its
/// values stored in `values` (a buffer reused across rebuilds); `None` when faer rejects
/// the pattern or the matrix is not numerically positive definite. Sizes the application
/// workspace for the factor.
fn cholesky(
    nc: usize,
    b: &BuildScratch,
    mut values: Vec<f64>,
    scratch: &Mutex<ApplyScratch>,
) -> Option<Factor> {
    let pattern = SymbolicSparseColMatRef::new_checked(nc, nc, &b.lower_ptr, None, &b.lower_idx);
    let lower = SparseColMatRef::new(pattern, &b.lower_values);
    let symbolic = factorize_symbolic_cholesky(
        pattern,
        Side::Lower,
        SymmetricOrdering::Amd,
        CholeskySymbolicParams::default(),
    )
    .ok()?;
    values.clear();
    values.resize(symbolic.len_val(), 0.0);
    let req = StackReq::any_of(&[
        symbolic.factorize_numeric_llt_scratch::<f64>(Par::Seq, Default::default()),
        symbolic.solve_in_place_scratch::<f64>(1, Par::Seq),
    ]);
    let mut s = scratch.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
    symbolic
        .factorize_numeric_llt(
            &mut values,
            lower,
            Side::Lower,
            LltRegularization::default(),
            Par::Seq,
            MemStack::new(workspace(&mut s.mem, req)),
            Default::default(),
        )
        .ok()?;
    Some(Factor::Cholesky { symbolic, values })
}

/// The LU factors of `A_cᵀ` (`b`'s compressed rows of `A_c` read as compressed columns);
/// `None` when faer rejects the pattern or the matrix is singular. Sizes the application
/// workspace for the factor.
///
/// The numeric factors are allocated afresh: faer 0.24's simplicial LU, refactorising
/// into the storage of a larger matrix's factors, kept the old column pointers and
/// panicked in the solve (found here, coarse sizes 1878 then 1809).
fn lu(nc: usize, b: &BuildScratch, scratch: &Mutex<ApplyScratch>) -> Option<Factor> {
    let mut numeric = NumericLu::new();
    let pattern = SymbolicSparseColMatRef::new_checked(nc, nc, &b.row_ptr, None, &b.col_idx);
    let transposed = SparseColMatRef::new(pattern, &b.values);
    let symbolic = factorize_symbolic_lu(pattern, Default::default()).ok()?;
    let req = StackReq::any_of(&[
        symbolic.factorize_numeric_lu_scratch::<f64>(Par::Seq, Default::default()),
        symbolic.solve_transpose_in_place_scratch::<f64>(1, Par::Seq),
    ]);
    let mut s = scratch.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
    symbolic
        .factorize_numeric_lu(
            &mut numeric,
            transposed,
            Par::Seq,
            MemStack::new(workspace(&mut s.mem, req)),
            Default::default(),
        )
        .ok()?;
    Some(Factor::Lu { symbolic, numeric })
}

impl std::fmt::Debug for ApplyScratch {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let bytes = self.mem.as_ref().map_or(0, |(_, req)| req.size_bytes());
        write!(f, "ApplyScratch {{ coarse: {}, workspace bytes: {bytes} }}", self.coarse.len())
    }
}

/// The two-level preconditioner of one system: a view of a [`CoarseSpace`] with the
/// current matrix's inverse diagonal.
#[derive(Debug, Clone, Copy)]
pub struct TwoLevel<'a> {
    space: &'a CoarseSpace,
    inv_diag: &'a [f64],
}

impl Preconditioner for TwoLevel<'_> {
    /// `z = D⁻¹ r + P A_c⁻¹ Pᵀ r`: the restriction sums the residual over each aggregate
    /// (serially, in row order), the coarse solve is faer's, the prolongation runs in
    /// parallel over the rows (element-wise: the same bits for any thread count).
    fn apply(&self, r: &[f64], z: &mut [f64]) {
        let space = self.space;
        let Some(factor) = &space.factor else {
            z.par_iter_mut().zip(r).zip(self.inv_diag).for_each(|((zi, ri), di)| *zi = di * ri);
            return;
        };
        let mut guard = space.scratch.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
        let ApplyScratch { coarse, mem } = &mut *guard;
        coarse.fill(0.0);
        for (ri, &g) in r.iter().zip(&space.of_row) {
            if g != NONE {
                coarse[g as usize] += ri;
            }
        }
        if space.grounded {
            coarse[0] = 0.0;
        }
        let (mem, _) = mem.as_mut().expect("sized with the factor");
        let rhs = MatMut::from_column_major_slice_mut(coarse.as_mut_slice(), space.nc, 1);
        let stack = MemStack::new(mem);
        match factor {
            Factor::Cholesky { symbolic, values } => {
                LltRef::new(symbolic, values).solve_in_place_with_conj(Conj::No, rhs, Par::Seq, stack)
            }
            Factor::Lu { symbolic, numeric } => LuRef::new_unchecked(symbolic, numeric)
                .solve_transpose_in_place_with_conj(Conj::No, rhs, Par::Seq, stack),
        }
        let coarse = &*coarse;
        z.par_iter_mut().zip(r).zip(self.inv_diag).zip(&space.of_row).with_min_len(1024).for_each(
            |(((zi, ri), di), &g)| {
                *zi = di * ri + if g == NONE { 0.0 } else { coarse[g as usize] };
            },
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::linalg::testing::{strip, strip_with_inlet_links};
    use crate::linalg::{LinearSolver, Method, PreconditionerKind, SolverParams};

    /// On a long strip (400 × 8, like a channel) the two-level preconditioner gives the
    /// Jacobi solution in a fraction of the iterations.
    #[test]
    fn two_level_preconditioner_cuts_the_iterations_of_a_long_strip() {
        let a = strip(400, 8);
        let n = a.n();
        let b: Vec<f64> = (0..n).map(|i| 1.0 + ((i * 7919) % 97) as f64 / 97.0).collect();
        let solve = |preconditioner, solver| {
            let opts = SolverParams {
                method: solver,
                tolerance: 1e-10,
                max_iterations: 20_000,
                preconditioner,
                coarse_refresh: 1,
            };
            let mut p = vec![0.0; n];
            let info = LinearSolver::new(opts).solve(&a, &b, &mut p, false).expect("converges");
            (p, info.iterations)
        };
        for solver in [Method::Cg, Method::Bicgstab] {
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
        s: &mut LinearSolver,
        a: &CsrMatrix,
        b: &[f64],
        keys: &[u32],
        singular: bool,
    ) -> (Vec<f64>, usize) {
        let mut p = vec![0.0; a.n()];
        let info = s.solve_keyed(a, b, &mut p, singular, Some(keys)).expect("converges");
        (p, info.iterations)
    }

    fn two_level_cg(refresh: usize) -> LinearSolver {
        LinearSolver::new(SolverParams {
            method: Method::Cg,
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
        let mut r = CsrMatrix { row_ptr: vec![0], ..Default::default() };
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

    /// A non-symmetric system (the open channel's PPE) gets an LU coarse factor and the
    /// two-level BiCGSTAB keeps its advantage over Jacobi; symmetric systems keep the
    /// Cholesky factor.
    #[test]
    fn non_symmetric_system_gets_an_lu_coarse_factor() {
        let solver = |preconditioner| {
            LinearSolver::new(SolverParams {
                method: Method::Bicgstab,
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
        assert_eq!(s.coarse().factor_kind(), Some(CoarseFactor::Cholesky));
        let mut pt = vec![0.0; n];
        let two = s.solve(&a, &b, &mut pt, false).expect("converges").iterations;
        assert_eq!(s.coarse().factor_kind(), Some(CoarseFactor::Lu));
        let mut pd = vec![0.0; n];
        super::super::direct::solve(&a, &b, &mut pd, false).expect("LU solves");
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
        let mut a = CsrMatrix { row_ptr: vec![0], ..Default::default() };
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
        let mut jacobi = LinearSolver::new(SolverParams {
            method: Method::Cg,
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

    /// Every row is in one aggregate; for a symmetric system the factor is Cholesky and
    /// `M⁻¹` is symmetric (so CG applies); a residual made of coarse modes, `r = A P c`, gets
    /// its coarse part back exactly: `M⁻¹ r − D⁻¹ r = P c`.
    #[test]
    fn the_preconditioner_is_symmetric_and_exact_on_coarse_modes() {
        let a = strip(60, 6);
        let n = a.n();
        let mut space = CoarseSpace::new(5);
        assert!(space.prepare(&a, None, false));
        let nc = space.coarse_size();
        assert!(nc > 1 && 2 * nc <= n, "{nc} aggregates of {n} rows");
        assert!(space.of_row.iter().all(|&g| (g as usize) < nc));
        assert_eq!(space.factor_kind(), Some(CoarseFactor::Cholesky));
        let m = space.preconditioner(&a.inv_diag);
        let apply = |r: &[f64]| {
            let mut z = vec![0.0; n];
            m.apply(r, &mut z);
            z
        };
        let x: Vec<f64> = (0..n).map(|i| (i as f64 * 0.37).sin()).collect();
        let y: Vec<f64> = (0..n).map(|i| (i as f64 * 0.11).cos()).collect();
        let dot = |p: &[f64], q: &[f64]| p.iter().zip(q).map(|(p, q)| p * q).sum::<f64>();
        let (xy, yx) = (dot(&x, &apply(&y)), dot(&y, &apply(&x)));
        assert!((xy - yx).abs() <= 1e-12 * xy.abs().max(1.0), "{xy} vs {yx}");
        let c: Vec<f64> = (0..nc).map(|g| 1.0 + (g % 5) as f64).collect();
        let pc: Vec<f64> = space.of_row.iter().map(|&g| c[g as usize]).collect();
        let mut r = vec![0.0; n];
        a.mul(&pc, &mut r);
        let z = apply(&r);
        for i in 0..n {
            let coarse = z[i] - a.inv_diag[i] * r[i];
            assert!((coarse - pc[i]).abs() < 1e-9 * pc[i].abs(), "row {i}: {coarse} vs {}", pc[i]);
        }
    }
}
