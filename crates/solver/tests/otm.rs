//! The OTM scheme through the driver (issue #38): Zhou's static drop from a scene file, the
//! rules on its input, a mid-run failure as a typed error with the probes kept.

use meniscus::{Quiet, Scene, SceneError};
use serde_json::{Value, json};

/// Zhou 2021's static drop (R = 0.2, ρ = 1, σ = 1, μ = 0.5) with the OTM scheme (c₀ = 50)
/// at `dx` to `end`, its mean pressure recorded over every material point.
fn static_drop(dx: f64, end: f64) -> Value {
    json!({
        "name": "otm_static_drop",
        "dimension": 2,
        "dx": dx,
        "kernel": {"kind": "cubic_spline", "h_over_dx": 1.5},
        "fluid": {"density": 1.0, "viscosity": 0.5, "surface_tension": 1.0},
        "body_force": [0.0, 0.0],
        "bodies": [{"role": "fluid", "shape": {"circle": {"center": [0.0, 0.0], "radius": 0.2}}}],
        "scheme": {"otm": {"sound_speed": 50.0}},
        "time": {"end": end, "step": {"adaptive": {"cfl": 0.25, "viscous": 0.2, "max": 0.001}}},
        "probes": [{"mean_pressure": {"center": [0.0, 0.0], "radius": 0.2}}, {"kinetic_energy": {}}],
        "output": {"probe_every": 10}
    })
}

fn error_of(v: Value) -> SceneError {
    Scene::from_json(&v.to_string()).expect_err("the scene should be rejected")
}

/// The drop settles at σ/R = 5 Pa within 1 % (0.25 % measured at R/10), and the run is
/// the same on one thread and on two.
#[test]
fn the_static_drop_settles_at_the_laplace_pressure() {
    let scene = Scene::from_json(&static_drop(0.02, 0.3).to_string()).expect("valid scene");
    let report = meniscus::run(&scene, &mut Quiet).expect("builds");
    assert!(report.error.is_none(), "{:?}", report.error);
    let p = report.probes.get("mean_pressure", "p").expect("recorded");
    let last = *p.last().unwrap();
    assert!((last / 5.0 - 1.0).abs() < 0.01, "mean pressure {last} Pa");
    assert_eq!(report.summary.particles, 600, "one material point per triangle: 6 K² for K = 10 rings");
    let one = rayon::ThreadPoolBuilder::new().num_threads(1).build().unwrap();
    let again = one.install(|| meniscus::run(&scene, &mut Quiet).expect("builds"));
    assert_eq!(again.probes, report.probes, "bit for bit on one thread");
}

#[test]
fn bad_otm_input_names_the_field() {
    let mut v = static_drop(0.02, 0.3);
    v["scheme"]["otm"]["locality"] = json!(0.0);
    let e = error_of(v).to_string();
    assert!(e.contains("scheme.otm.locality") && e.contains("(0, 10]"), "{e}");
    let mut v = static_drop(0.02, 0.3);
    v["scheme"]["otm"]["sound_speed"] = json!(-1.0);
    assert!(error_of(v).to_string().contains("scheme.otm.sound_speed"));
    // A disc the mesher cannot triangulate (no ring of nodes: dx > 2R) is the scene rule
    // of every scheme.
    let e = error_of(static_drop(0.5, 0.3)).to_string();
    assert!(e.contains("bodies[0].shape.circle.radius") && e.contains("holds no particle"), "{e}");
    // OTM options inside an SPH scheme are unknown fields of that scheme.
    let mut v = static_drop(0.02, 0.3);
    v["scheme"] = json!({"wcsph": {"sound_speed": 50.0, "locality": 1.5}});
    let e = error_of(v).to_string();
    assert!(e.contains("locality"), "{e}");
    // What the scheme does not run yet: walls, two bodies; nor a locality beyond 10.
    let mut v = static_drop(0.02, 0.3);
    v["boundaries"] = json!({"walls": [{"axis": 1, "position": -0.3, "fluid_side": "above"}]});
    let e = error_of(v).to_string();
    assert!(e.contains("otm"), "{e}");
    let mut v = static_drop(0.02, 0.3);
    let body = v["bodies"][0].clone();
    v["bodies"] = json!([body.clone(), body]);
    assert!(error_of(v).to_string().contains("exactly one fluid body"));
    let mut v = static_drop(0.02, 0.3);
    v["scheme"]["otm"]["locality"] = json!(12.0);
    assert!(error_of(v).to_string().contains("(0, 10]"));
    // An initial pressure that the equation of state turns into a negative density.
    let mut v = static_drop(0.02, 0.3);
    v["bodies"][0]["pressure"] =
        json!({"quadratic": {"center": [0.0, 0.0], "value": -3000.0, "hessian": [[0.0, 0.0], [0.0, 0.0]]}});
    let scene = Scene::from_json(&v.to_string()).expect("valid scene file");
    let e = meniscus::run(&scene, &mut Quiet).expect_err("a negative density").to_string();
    assert!(e.contains("bodies[0].pressure") && e.contains("non-positive density"), "{e}");
}

/// A step far beyond the stable one folds the nodal map: the run stops with the OTM's
/// typed error (the stage, step and time), the probes recorded so far kept.
#[test]
fn a_folded_map_stops_the_run_with_a_typed_error() {
    let mut v = static_drop(0.02, 0.05);
    v["time"]["step"] = json!({"fixed": 0.01});
    v["bodies"][0]["velocity"] =
        json!({"affine": {"gradient": [[0.0, 30.0], [-30.0, 0.0]], "offset": [0.0, 0.0]}});
    let scene = Scene::from_json(&v.to_string()).expect("valid scene");
    let report = meniscus::run(&scene, &mut Quiet).expect("builds");
    let e = report.error.expect("the run must stop");
    assert_eq!(e.stage, "otm_step");
    let text = e.to_string();
    assert!(text.contains("material point") && text.contains("at step"), "{text}");
    assert!(!report.probes.get("mean_pressure", "p").expect("kept").is_empty());
}
