//! No allocation inside a warm step (issue #7: "no allocation inside a step after the
//! first"): the step's buffers are kept and reused, so after a warm-up the only heap
//! traffic left is the amortised growth of a buffer whose size follows the problem (the
//! cell grid follows the particles' bounding box).

mod common;

use meniscus::profile::Stepper;
use serde_json::json;
use stats_alloc::{INSTRUMENTED_SYSTEM, Region, StatsAlloc};
use std::alloc::System;

/// The system allocator with global (all-thread) allocation statistics; this test binary
/// only, so the other tests keep the plain allocator.
#[global_allocator]
static GLOBAL: &StatsAlloc<System> = &INSTRUMENTED_SYSTEM;

/// (fresh allocations, reallocations) during `steps` steps of `scene` after `warm` steps,
/// on a pool of `threads` built beforehand (its own start-up is not the step's).
fn heap_traffic(scene: &meniscus::Scene, warm: usize, steps: usize, threads: usize) -> (usize, usize) {
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().expect("pool");
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

/// One test function for both scenes: the statistics are global, so a second test running
/// beside this one would be counted in its steps.
#[test]
fn a_warm_step_does_not_allocate() {
    drop_steps();
    two_level_drop_steps();
    walled_periodic_channel_steps();
}

fn drop_steps() {
    let scene = common::drop_scene(|v| {
        v["dx"] = json!(0.05);
        v["time"]["end"] = json!(1.0);
    });
    // 60 steps span two cell reorders (every 25 steps), which once allocated their
    // permutation and a copy of every particle array.
    for threads in [1, 2] {
        let (fresh, grown) = heap_traffic(&scene, 30, 60, threads);
        assert_eq!(fresh, 0, "{fresh} allocations in 60 warm steps of the drop, {threads} threads");
        // The drop stretches: its cell grid (one count and one offset per cell) outgrows
        // its capacity about once here (two reallocations of ~1.5 kB, measured).
        assert!(grown <= 2, "{grown} reallocations in 60 warm steps of the drop, {threads} threads");
    }
}

/// The drop with the two-level preconditioner (CG), whose coarse space is kept across
/// steps: the steps that reuse it allocate nothing; a rebuild (every `coarse_refresh`
/// solves) allocates inside faer's symbolic Cholesky analysis of the new coarse pattern.
fn two_level_drop_steps() {
    let scene = |refresh: usize| {
        common::drop_scene(|v| {
            v["dx"] = json!(0.05);
            v["time"]["end"] = json!(1.0);
            v["scheme"]["isph"]["ppe"]["solver"] = json!("cg");
            v["scheme"]["isph"]["ppe"]["preconditioner"] = json!("two_level");
            v["scheme"]["isph"]["ppe"]["coarse_refresh"] = json!(refresh);
        })
    };
    for threads in [1, 2] {
        // Built during the warm-up and reused through the 60 steps.
        let (fresh, grown) = heap_traffic(&scene(1000), 30, 60, threads);
        assert_eq!(
            fresh, 0,
            "{fresh} allocations in 60 warm steps reusing the coarse space, {threads} threads"
        );
        assert!(
            grown <= 2,
            "{grown} reallocations in 60 warm steps reusing the coarse space, {threads} threads"
        );
        // Rebuilt every 25 solves: two rebuilds in these 60 steps (solves 50 and 75), each
        // with the allocations of faer's symbolic analysis alone (6 measured).
        let (fresh, _) = heap_traffic(&scene(25), 30, 60, threads);
        assert!(
            (1..=2 * 8).contains(&fresh),
            "{fresh} allocations in 60 steps with two rebuilds, {threads} threads"
        );
    }
}

/// The periodic channel's scene as its case file has it (BiCGSTAB with the two-level
/// preconditioner, mirror walls, shifting): with the coarse space kept through the 60
/// steps nothing is allocated; with the case's refresh rule (rebuilt every 25 solves) only
/// the rebuilds' symbolic analyses allocate, as in `two_level_drop_steps`.
fn walled_periodic_channel_steps() {
    let scene = |refresh: Option<usize>| {
        common::periodic_channel_scene(|v| {
            v["dx"] = json!(0.2 / 18.0);
            v["body_force"] = json!([6e-8, 0.0]);
            if let Some(r) = refresh {
                v["scheme"]["isph"]["ppe"]["coarse_refresh"] = json!(r);
            }
        })
    };
    for threads in [1, 2] {
        let traffic = heap_traffic(&scene(Some(1000)), 30, 60, threads);
        assert_eq!(traffic, (0, 0), "heap traffic in 60 warm steps of the channel, {threads} threads");
        // Two rebuilds, each with the allocations of faer's symbolic analysis alone
        // (12 in all measured with one thread).
        let (fresh, grown) = heap_traffic(&scene(None), 30, 60, threads);
        assert!(
            (1..=2 * 8).contains(&fresh) && grown == 0,
            "({fresh}, {grown}) allocations in 60 steps of the channel with two rebuilds, {threads} threads"
        );
    }
}
