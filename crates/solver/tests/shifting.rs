//! Shifting must not deform a drop whose exact motion is rigid (NUMERICS.md "Shifting"):
//! a translating drop keeps its volume (particle count × V) and its axes, and its
//! surface is not pushed outward.

mod common;

use serde_json::json;

fn translate(shifting: serde_json::Value) -> (f64, f64) {
    let scene = common::drop_scene(|v| {
        v["dx"] = json!(0.04);
        v["bodies"][0]["velocity"] =
            json!({"affine": {"gradient": [[0.0, 0.0], [0.0, 0.0]], "offset": [1.0, 0.0]}});
        v["bodies"][0]["pressure"] = json!("zero");
        v["time"] = json!({"end": 0.02, "step": {"fixed": 1e-4}});
        v["scheme"]["isph"]["shifting"] = shifting;
    });
    let report = meniscus::run(&scene, &mut meniscus::Quiet).expect("scene builds");
    assert!(report.error.is_none(), "{:?}", report.error);
    let a = report.probes.get("ellipse_axes", "a_moment").expect("probe");
    let b = report.probes.get("ellipse_axes", "b_moment").expect("probe");
    let x = report.probes.get("ellipse_axes", "x_centroid").expect("probe");
    assert!((x[x.len() - 1] - 0.02).abs() < 1e-6, "centroid moved by {}", x[x.len() - 1]);
    ((a[a.len() - 1] - a[0]) / a[0], (b[b.len() - 1] - b[0]) / b[0])
}

#[test]
fn xu_shifting_keeps_a_translating_drop_round() {
    let (da, db) = translate(json!({"xu": {"coefficient": 0.02}}));
    assert!(da.abs() < 2e-3 && db.abs() < 2e-3, "axes changed by {da:.2e}, {db:.2e}");
}

#[test]
fn fickian_shifting_keeps_a_translating_drop_round() {
    let (da, db) = translate(json!({"fickian": {"coefficient": 2.0}}));
    assert!(da.abs() < 2e-3 && db.abs() < 2e-3, "axes changed by {da:.2e}, {db:.2e}");
}
