//! Neighbour search: the cell-list build with CSR output alone on the initial lattice, and
//! the solver's `neighbours` stage (search + pair cache, reordering every 25th call).

use crate::{Per, bench_stage};
use criterion::{Criterion, Throughput};
use meniscus::neighbours::{CellSearch, Domain, NeighbourList};
use meniscus_benches::scenes;
use std::hint::black_box;

/// Cell lists + CSR over the particles of each scene at t = 0 (pairs per second).
pub(crate) fn neighbour_search(c: &mut Criterion) {
    let mut group = c.benchmark_group("neighbour_search");
    for s in scenes() {
        let sim = meniscus::profile::Stepper::<2>::new(&s.scene).expect("bench scenes are valid");
        let x = sim.state().particles.x.clone();
        let mut search = CellSearch::new(2.0 * s.scene.h(), Domain::default());
        let mut list = NeighbourList::default();
        search.build(&x, &mut list);
        group.throughput(Throughput::Elements(list.pairs() as u64));
        group.bench_function(format!("build_csr/{}", s.label), |b| {
            b.iter(|| {
                search.build(black_box(&x), &mut list);
                black_box(list.pairs())
            })
        });
    }
    group.finish();
}

/// The `neighbours` stage of a step (pairs per second).
pub(crate) fn neighbours_stage(c: &mut Criterion) {
    bench_stage(c, "neighbours", "stage", "neighbours", Per::Pair, false, Clone::clone);
}
