//! Particle shifting with the Taylor velocity correction, Xu's and Lind's laws (pairs per
//! second).

use crate::{Per, bench_stage};
use criterion::Criterion;
use meniscus::scene::Shifting;
use meniscus_benches::with_shifting;

/// The `shifting` stage, Xu (C = 0.02) and Fickian (A = 2).
pub(crate) fn bench(c: &mut Criterion) {
    bench_stage(c, "shifting", "xu", "shifting", Per::Pair, true, |s| {
        with_shifting(s, Shifting::Xu { coefficient: 0.02, smooth: false })
    });
    bench_stage(c, "shifting", "fickian", "shifting", Per::Pair, true, |s| {
        with_shifting(s, Shifting::Fickian { coefficient: 2.0 })
    });
}
