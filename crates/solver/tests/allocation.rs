//! No allocation inside a warm step (issue #7: "no allocation inside a step after the
//! first"): the step's buffers are kept and reused, so after a warm-up the only heap
//! traffic left is the amortised growth of a buffer whose size follows the problem (the
//! cell grid follows the particles' bounding box).

mod common;

use meniscus::profile::Stepper;
use serde_json::{Value, json};
use stats_alloc::{INSTRUMENTED_SYSTEM, Region, StatsAlloc};
use std::alloc::System;

/// The system allocator with global (all-thread) allocation statistics; this test binary
/// only, so the other tests keep the plain allocator.
#[global_allocator]
static GLOBAL: &StatsAlloc<System> = &INSTRUMENTED_SYSTEM;

/// (fresh allocations, reallocations) during `steps` steps of `scene` after `warm` steps,
/// on a one-thread pool built beforehand (its own start-up is not the step's).
fn heap_traffic(scene: &meniscus::Scene, warm: usize, steps: usize) -> (usize, usize) {
    let pool = rayon::ThreadPoolBuilder::new().num_threads(1).build().expect("pool");
    pool.install(|| {
        let mut s = Stepper::<2>::new(scene).expect("scene builds");
        for _ in 0..warm {
            s.step_once().expect("warm-up step");
        }
        let region = Region::new(GLOBAL);
        for _ in 0..steps {
            s.step_once().expect("step");
        }
        let change = region.change();
        (change.allocations, change.reallocations)
    })
}

#[test]
fn a_warm_drop_step_does_not_allocate() {
    let scene = common::drop_scene(|v| {
        v["dx"] = json!(0.05);
        v["time"]["end"] = json!(1.0);
    });
    // 60 steps span two cell reorders (every 25 steps), which once allocated their
    // permutation and a copy of every particle array.
    let (fresh, grown) = heap_traffic(&scene, 30, 60);
    assert_eq!(fresh, 0, "{fresh} allocations in 60 warm steps of the drop");
    // The drop stretches: its cell grid (one count and one offset per cell) outgrows its
    // capacity about once here (two reallocations of ~1.5 kB, measured).
    assert!(grown <= 2, "{grown} reallocations in 60 warm steps of the drop");
}

#[test]
fn a_warm_walled_periodic_channel_step_does_not_allocate() {
    let case: Value = serde_json::from_str(include_str!("../../../validation/poiseuille_periodic.json"))
        .expect("case JSON");
    let mut v = case["scene"].clone();
    v["dx"] = json!(0.2 / 18.0);
    v["body_force"] = json!([6e-8, 0.0]);
    let scene = meniscus::Scene::from_json(&v.to_string()).expect("valid scene");
    let (fresh, grown) = heap_traffic(&scene, 30, 60);
    assert_eq!(
        (fresh, grown),
        (0, 0),
        "heap traffic in 60 warm steps of the channel (mirror walls, periodic x)"
    );
}
