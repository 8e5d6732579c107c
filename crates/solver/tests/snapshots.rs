//! `output.snapshot_times` and `bodies[i].jitter`: snapshots land on their times without
//! changing the probes, a step landing on a time is never a sliver, and a jittered lattice
//! is seeded and bounded.

mod common;

use serde_json::json;

/// The DESIGN drop at Δx = 0.1 (a few hundred particles), 20 fixed steps of 2e-5 s.
fn small(edit: impl FnOnce(&mut serde_json::Value)) -> meniscus::Scene {
    common::drop_scene(|v| {
        v["dx"] = json!(0.1);
        v["time"]["end"] = json!(4e-4);
        edit(v);
    })
}

#[test]
fn snapshots_land_on_their_times_and_leave_the_probes_alone() {
    let run = |times: &[f64]| {
        let r = meniscus::run(&small(|v| v["output"]["snapshot_times"] = json!(times)), &mut meniscus::Quiet)
            .unwrap();
        assert!(r.error.is_none());
        r
    };
    let plain = run(&[]);
    assert!(plain.snapshots.is_empty());
    // Times on the step grid: the same steps and probes as without snapshots (to rounding:
    // a step that lands on a requested time takes that time exactly, not t + Δt).
    let on_grid = run(&[0.0, 2e-4, 4e-4]);
    assert_eq!(on_grid.summary.steps, plain.summary.steps);
    assert_eq!(on_grid.probes.t.len(), plain.probes.t.len());
    for (kind, quantities) in &plain.probes.series {
        for (q, values) in quantities {
            let other = &on_grid.probes.series[kind][q];
            for (a, b) in values.iter().zip(other) {
                assert!((a - b).abs() <= 1e-12 * a.abs().max(1e-6), "{kind}.{q}: {a} vs {b}");
            }
        }
    }
    assert_eq!(on_grid.snapshots.len(), 3);
    assert_eq!(on_grid.snapshots[2].x, on_grid.final_frame.x, "the last is the final state");
    assert!(on_grid.snapshots[0].p.iter().zip(&on_grid.snapshots[1].p).any(|(a, b)| (a - b).abs() > 1.0));
    // 1.3e-4 is not a multiple of Δt: the step before it is shortened to land on it.
    let off_grid = run(&[1.3e-4, 3e-4]);
    let got: Vec<f64> = off_grid.snapshots.iter().map(|f| f.time).collect();
    assert_eq!(got.len(), 2, "{got:?}");
    assert!((got[0] - 1.3e-4).abs() <= 1e-15 && (got[1] - 3e-4).abs() <= 1e-15, "{got:?}");
    assert_eq!(off_grid.snapshots[0].p.len(), plain.summary.particles);
    // Serialisable (`meniscus run` writes them as JSON).
    let text = serde_json::to_string(&off_grid.snapshots[1]).unwrap();
    let back: meniscus::Frame = serde_json::from_str(&text).unwrap();
    let orig = &off_grid.snapshots[1];
    assert_eq!((back.step, back.x.len(), &back.free_surface), (orig.step, orig.x.len(), &orig.free_surface));
    let close = |a: f64, b: f64| (a - b).abs() <= 1e-14 * a.abs().max(1.0);
    assert!(back.p.iter().zip(&orig.p).all(|(a, b)| close(*a, *b)), "pressures survive JSON");
    assert!(back.x.iter().zip(&orig.x).all(|(a, b)| (0..3).all(|k| close(a[k], b[k]))));
}

#[test]
fn a_remainder_between_one_and_two_steps_is_split_in_halves() {
    // End at 2.5 Δt (Δt = 2e-5 s): Δt, then 0.75 Δt twice, not Δt, Δt and a 0.5 Δt sliver.
    let r = meniscus::run(
        &small(|v| {
            v["time"]["end"] = json!(5e-5);
            v["output"]["probe_every"] = json!(1);
        }),
        &mut meniscus::Quiet,
    )
    .unwrap();
    assert!(r.error.is_none());
    let t = &r.probes.t;
    let expected = [0.0, 2e-5, 3.5e-5, 5e-5];
    assert_eq!(t.len(), expected.len(), "{t:?}");
    assert!(t.iter().zip(expected).all(|(a, b)| (a - b).abs() <= 1e-15), "{t:?}");
}

#[test]
fn jittered_lattice_is_seeded_bounded_and_runs() {
    let jitter = |fraction: f64, seed: u64| {
        small(|v| {
            v["time"]["end"] = json!(2e-5);
            v["output"]["snapshot_times"] = json!([0.0]);
            v["bodies"][0]["jitter"] = json!({"fraction": fraction, "seed": seed});
        })
    };
    let first = |s: &meniscus::Scene| meniscus::run(s, &mut meniscus::Quiet).unwrap().snapshots.remove(0);
    let lattice = first(&jitter(0.0, 1));
    let a = first(&jitter(0.3, 42));
    assert_eq!(a, first(&jitter(0.3, 42)), "deterministic for a seed");
    assert_ne!(a.x, first(&jitter(0.3, 43)).x);
    let dx = 0.1;
    let moved: Vec<f64> =
        a.x.iter()
            .zip(&lattice.x)
            .map(|(p, q)| ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2)).sqrt() / dx)
            .collect();
    assert!(moved.iter().all(|&m| m <= 0.3 + 1e-12), "bounded by 0.3 dx");
    assert!(moved.iter().filter(|&&m| m > 0.1).count() > moved.len() / 2, "most particles moved");
}
