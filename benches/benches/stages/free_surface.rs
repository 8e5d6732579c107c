//! Free-surface detection: the flags from `div r` (summed by the neighbours stage, whose
//! bench includes that sum), per pair as the other stages.

use crate::{Per, bench_stage};
use criterion::Criterion;

/// The `free_surface` stage.
pub(crate) fn bench(c: &mut Criterion) {
    bench_stage(c, "free_surface", "stage", "free_surface", Per::Pair, true, Clone::clone);
}
