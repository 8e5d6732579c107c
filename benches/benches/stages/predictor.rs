//! The viscous predictor u* = uⁿ + Δt ν ∇²uⁿ (pairs per second).

use crate::{Per, bench_stage};
use criterion::Criterion;

/// The `viscosity` stage.
pub(crate) fn bench(c: &mut Criterion) {
    bench_stage(c, "viscosity", "stage", "viscosity", Per::Pair, true, Clone::clone);
}
