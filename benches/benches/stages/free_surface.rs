//! Free-surface detection: `div r` and the flags (pairs per second).

use crate::{Per, bench_stage};
use criterion::Criterion;

/// The `free_surface` stage.
pub(crate) fn bench(c: &mut Criterion) {
    bench_stage(c, "free_surface", "stage", "free_surface", Per::Pair, true, Clone::clone);
}
