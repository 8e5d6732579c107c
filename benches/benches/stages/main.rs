//! Criterion benches of the hot stages (throughput in particles per second).

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use meniscus::neighbours::{CellSearch, Domain, NeighbourList};
use meniscus::scene::Shape;
use meniscus::scene::lattice::lattice_points;
use meniscus_benches::drop_scene;
use std::hint::black_box;

fn neighbour_search(c: &mut Criterion) {
    let mut group = c.benchmark_group("neighbour_search");
    for dx in [0.04, 0.02, 0.01] {
        let x = lattice_points::<2>(&Shape::Circle { center: vec![0.0, 0.0], radius: 1.0 }, dx);
        let mut search = CellSearch::new(3.0 * dx, Domain::default());
        let mut list = NeighbourList::default();
        group.throughput(Throughput::Elements(x.len() as u64));
        group.bench_function(format!("drop_dx{dx}"), |b| {
            b.iter(|| {
                search.build(black_box(&x), &mut list);
                black_box(list.pairs())
            })
        });
    }
    group.finish();
}

fn drop_steps(c: &mut Criterion) {
    let mut group = c.benchmark_group("drop_10_steps");
    group.sample_size(10);
    for dx in [0.04, 0.02] {
        let scene = drop_scene(dx, 10);
        let n = meniscus::AnySimulation::new(&scene).expect("valid").particles();
        group.throughput(Throughput::Elements((10 * n) as u64));
        group.bench_function(format!("dx{dx}"), |b| {
            b.iter(|| black_box(meniscus::run(&scene, &mut meniscus::Quiet).expect("valid").summary.steps))
        });
    }
    group.finish();
}

criterion_group!(benches, neighbour_search, drop_steps);
criterion_main!(benches);
