//! One whole step (time step, every stage, guard) of the paper preset, always from the
//! same saved state (particles per second).

use criterion::{Criterion, SamplingMode, Throughput};
use meniscus_benches::{StepBench, pipe_3d, scenes};

/// A whole step of every scene, and of the 3D pipe at about 100 k particles.
pub(crate) fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("step");
    g.sampling_mode(SamplingMode::Flat).sample_size(10);
    for s in scenes() {
        let mut bench = StepBench::<2>::new(&s.scene);
        g.throughput(Throughput::Elements(bench.particles() as u64));
        g.bench_function(format!("paper/{}", s.label), |b| b.iter_custom(|iters| bench.time(iters)));
    }
    let pipe = pipe_3d();
    let mut bench = StepBench::<3>::new(&pipe.scene);
    g.throughput(Throughput::Elements(bench.particles() as u64));
    g.bench_function(format!("isph/{}", pipe.label), |b| b.iter_custom(|iters| bench.time(iters)));
    g.finish();
}
