//! The step as a list of stages built once from the scene (DESIGN.md "composed from the
//! scene"): dynamic dispatch between stages, static (monomorphised) inside them.

use crate::error::Cause;
use crate::state::State;

/// Time-step data passed to every stage.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepContext {
    /// Step number being taken (1-based).
    pub step: usize,
    /// Time at the start of the step \[s\].
    pub time: f64,
    /// Step size Δt \[s\].
    pub dt: f64,
}

/// One stage of a step.
pub trait Stage<const D: usize>: Send + std::fmt::Debug {
    /// Name used in `summary.json` stage timings and in error messages.
    fn name(&self) -> &'static str;
    /// Advances `state` by this stage.
    fn run(&mut self, state: &mut State<D>, ctx: &StepContext) -> Result<(), Cause>;
}

/// Calls `f(a, row, &mut out[a])` for every particle `a` with
/// `row = data[offsets[a]..offsets[a + 1]]`, in parallel by recursive halving (no
/// allocation; each row and its output are written by one task).
pub fn par_rows_mut<T: Send, U: Send, F: Fn(usize, &mut [T], &mut U) + Sync>(
    offsets: &[usize],
    data: &mut [T],
    out: &mut [U],
    f: &F,
) {
    fn rec<T: Send, U: Send, F: Fn(usize, &mut [T], &mut U) + Sync>(
        lo: usize,
        hi: usize,
        offsets: &[usize],
        data: &mut [T],
        out: &mut [U],
        f: &F,
    ) {
        if hi - lo <= 256 {
            let base = offsets[lo];
            for (a, o) in (lo..hi).zip(out) {
                f(a, &mut data[offsets[a] - base..offsets[a + 1] - base], o);
            }
        } else {
            let mid = lo + (hi - lo) / 2;
            let (l, r) = data.split_at_mut(offsets[mid] - offsets[lo]);
            let (ol, or) = out.split_at_mut(mid - lo);
            rayon::join(|| rec(lo, mid, offsets, l, ol, f), || rec(mid, hi, offsets, r, or, f));
        }
    }
    let n = offsets.len().saturating_sub(1);
    if n > 0 {
        rec(0, n, offsets, data, &mut out[..n], f);
    }
}

/// [`par_rows_mut`] over the rows of a compressed sparse row matrix with a separate
/// diagonal: `f(a, &mut cols[row a], &mut vals[row a], &mut diag[a])`.
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
