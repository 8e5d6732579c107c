//! The step as a list of stages built once from the scene by its scheme (DESIGN.md
//! "composed from the scene"): dynamic dispatch between stages, static (monomorphised)
//! inside them.

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

/// One stage of a step of a scheme whose own data (beside the shared [`State`]) is `O`
/// ([`crate::scheme::Scheme::Own`]). Stages shared by several schemes are generic over `O`.
pub trait Stage<const D: usize, O>: Send + std::fmt::Debug {
    /// Name used in `summary.json` stage timings and in error messages.
    fn name(&self) -> &'static str;
    /// Advances `state` (and the scheme's own data `own`) by this stage.
    fn run(&mut self, state: &mut State<D>, own: &mut O, ctx: &StepContext) -> Result<(), Cause>;
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
