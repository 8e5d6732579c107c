//! Criterion benches of the solver's hot stages and of whole steps, on every scene of
//! `meniscus_benches::scenes()` (the elliptical drop at Δx = 0.04, 0.02, 0.01 and the
//! periodic channel at D/36).
//!
//! Throughput: the per-pair passes (`neighbour_search`, `neighbours`, `free_surface`,
//! `viscosity`, `ppe_assemble`, `correction`, `shifting`) report neighbour pairs per
//! second; the PPE solves, the channel's `walls`, the implicit viscous predictor and the
//! whole step report particles per second. The particle and
//! pair counts of every scene are printed first, to convert one into the other. How each
//! bench re-runs a stage with a step's worth of work is documented in `meniscus_benches`.
//!
//! One module per hot stage; `cargo bench` runs all of them in a few minutes (1 s warm-up,
//! 2 s of measurement per bench; flat sampling for the slow ones).

mod correction;
mod free_surface;
mod ppe;
mod predictor;
mod search;
mod shifting;
mod step;
mod walls;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use meniscus_benches::{StageBench, scenes};
use std::time::Duration;

/// The unit a bench's throughput counts.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Per {
    /// Neighbour pairs.
    Pair,
    /// Particles.
    Particle,
}

/// Benches stage `stage` of every scene (built by `variant` from the scene) in group
/// `group` under id `<id>/<scene label>`, restoring the state before each run when
/// `restore` (see `meniscus_benches::StageBench`).
pub(crate) fn bench_stage(
    c: &mut Criterion,
    group: &str,
    id: &str,
    stage: &str,
    per: Per,
    restore: bool,
    variant: impl Fn(&meniscus::Scene) -> meniscus::Scene,
) {
    let mut g = c.benchmark_group(group);
    for s in scenes() {
        let Some(mut bench) = StageBench::new(&variant(&s.scene), stage, restore) else {
            eprintln!("{group}: {} builds no `{stage}` stage; skipped", s.label);
            continue;
        };
        let size = bench.size();
        let n = match per {
            Per::Pair => size.pairs,
            Per::Particle => size.particles,
        };
        g.throughput(Throughput::Elements(n as u64));
        if size.particles > 20_000 || stage == "ppe_solve" {
            g.sampling_mode(criterion::SamplingMode::Flat).sample_size(10);
        } else {
            g.sampling_mode(criterion::SamplingMode::Auto).sample_size(30);
        }
        g.bench_function(format!("{id}/{}", s.label), |b| b.iter_custom(|iters| bench.time(iters)));
    }
    g.finish();
}

/// Prints the particle and pair counts of every scene (once, before the benches).
fn sizes(_c: &mut Criterion) {
    for s in scenes() {
        if let Some(b) = StageBench::new(&s.scene, "free_surface", true) {
            let size = b.size();
            eprintln!(
                "{}: {} particles, {} pairs ({:.1} per particle)",
                s.label,
                size.particles,
                size.pairs,
                size.pairs as f64 / size.particles as f64
            );
        }
    }
}

fn config() -> Criterion {
    Criterion::default().warm_up_time(Duration::from_secs(1)).measurement_time(Duration::from_secs(2))
}

criterion_group! {
    name = benches;
    config = config();
    targets = sizes, search::neighbour_search, search::neighbours_stage, free_surface::bench,
        predictor::bench, ppe::assemble, ppe::solve, correction::bench, shifting::bench, walls::walls,
        walls::implicit_viscosity, step::bench
}
criterion_main!(benches);
