//! The projection u = u* − Δt ∇p/ρ (symmetric gradient, Qiu eq. 15; pairs per second).

use crate::{Per, bench_stage};
use criterion::Criterion;

/// The `correction` stage.
pub(crate) fn bench(c: &mut Criterion) {
    bench_stage(c, "correction", "stage", "correction", Per::Pair, true, Clone::clone);
}
