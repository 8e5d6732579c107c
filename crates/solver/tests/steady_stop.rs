//! `time.steady`: a run stops once its probe shows a steady flow, and only then.

mod common;

use meniscus::Status;
use serde_json::json;

/// The DESIGN drop at Δx = 0.1 to 4 ms (200 fixed steps of 20 µs, a probe sample every
/// 0.2 ms), stopping when its `a` axes (moment and extent) change by under 1e-4 between
/// two 0.8 ms windows; `strain` is the drop's initial strain rate \[1/s\].
fn drop(strain: f64) -> meniscus::Scene {
    common::drop_scene(|v| {
        v["dx"] = json!(0.1);
        v["time"]["end"] = json!(4e-3);
        v["time"]["steady"] =
            json!({"probe": "ellipse_axes", "quantities": "a_", "window": 8e-4, "tolerance": 1e-4});
        v["bodies"][0]["velocity"]["affine"]["gradient"] = json!([[-strain, 0.0], [0.0, strain]]);
    })
}

#[test]
fn a_drop_at_rest_stops_after_two_windows() {
    let r = meniscus::run(&drop(0.0), &mut meniscus::Quiet).unwrap();
    let s = &r.summary;
    assert_eq!(s.status, Status::Ok);
    let at = s.steady_at.expect("a drop at rest is steady");
    assert!((1.6e-3 - 1e-9..=2.0e-3 + 1e-9).contains(&at), "stopped at {at} s");
    assert_eq!(s.t_end.to_bits(), at.to_bits(), "t_end is the stop");
    assert_eq!(s.steps, (at / 2e-5).round() as usize);
    assert_eq!(r.probes.t.last(), Some(&at), "the stop is the last sample");
}

#[test]
fn a_stretching_drop_runs_to_its_end() {
    let r = meniscus::run(&drop(100.0), &mut meniscus::Quiet).unwrap();
    assert_eq!(r.summary.status, Status::Ok);
    assert_eq!(r.summary.steady_at, None);
    assert!((r.summary.t_end - 4e-3).abs() < 1e-12, "{}", r.summary.t_end);
}
