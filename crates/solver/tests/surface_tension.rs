//! Surface tension of a single fluid: stage composition and the sign and size of the
//! Laplace pressure on a small static drop.

use meniscus::Scene;
use serde_json::json;

/// The static drop of `validation/static_drop.json` at Δx = R/10, run to 0.15 s.
fn drop(model: &str, scheme: serde_json::Value, sigma: f64) -> Scene {
    let v = json!({
        "name": "static_drop", "dimension": 2, "dx": 0.02,
        "kernel": { "kind": "cubic_spline", "h_over_dx": 1.5 },
        "fluid": { "density": 1.0, "viscosity": 0.5, "surface_tension": sigma,
                   "surface_tension_model": model, "surface_tension_threshold": 0.1 },
        "bodies": [ { "role": "fluid", "shape": { "circle": { "center": [0.0, 0.0], "radius": 0.2 } } } ],
        "scheme": scheme,
        "time": { "end": 0.15, "step": { "adaptive": { "cfl": 0.25, "max": 1e-3 } } },
        "probes": [ { "pressure_at": { "point": [0.0, 0.0] } }, { "max_speed": {} }, { "drop_shape": {} } ],
        "output": { "probe_every": 10 }
    });
    Scene::from_json(&v.to_string()).expect("valid scene")
}

fn wcsph() -> serde_json::Value {
    json!({ "wcsph": { "sound_speed": 50.0, "density_diffusion": 0.1 } })
}

#[test]
fn no_surface_tension_builds_no_stage() {
    let with = meniscus::AnySimulation::new(&drop("hu_adams", wcsph(), 1.0)).expect("builds");
    assert!(with.stage_names().contains(&"surface_tension"), "{:?}", with.stage_names());
    let without = meniscus::AnySimulation::new(&drop("hu_adams", wcsph(), 0.0)).expect("builds");
    assert!(!without.stage_names().contains(&"surface_tension"), "{:?}", without.stage_names());
    let isph = json!({ "isph": { "ppe": { "solver": "cg", "tolerance": 1e-6, "max_iterations": 500 },
                                 "free_surface_threshold": 1.5 } });
    let i = meniscus::AnySimulation::new(&drop("csf", isph, 1.0)).expect("builds");
    assert!(i.stage_names().contains(&"surface_tension"), "{:?}", i.stage_names());
}

#[test]
fn both_forms_compress_the_drop_to_their_measured_laplace_pressure() {
    // Starting from p = 0, the surface tension squeezes the drop until the inside pressure
    // balances it: one body, spurious speeds well below the capillary speed
    // √(σ/(ρR)) = 2.2 m/s, and an inside pressure short of σ/R = 5 Pa by what each model
    // is known to miss here (threshold 0.1/h, not normalised: the single-fluid colour
    // gradient carries about half of the surface delta; docs/notes/surface-tension.md).
    // The bands pin those shortfalls (2.23 Pa Hu–Adams, 3.71 Pa CSF over the last quarter
    // of 0.15 s, measured 2026-12-05) to ±10 %, so that a change either way shows; the
    // models' accuracy is judged, failing, by the static_drop case's expected failures.
    for (model, measured) in [("hu_adams", 2.23), ("csf", 3.71)] {
        let report = meniscus::run(&drop(model, wcsph(), 1.0), &mut meniscus::Quiet).expect("builds");
        assert!(report.error.is_none(), "{model}: {:?}", report.error);
        let p = report.probes.get("pressure_at", "p").expect("probe");
        let n = p.len();
        let late: f64 = p[3 * n / 4..].iter().sum::<f64>() / (n - 3 * n / 4) as f64;
        assert!(
            (late - measured).abs() <= 0.1 * measured,
            "{model}: inside pressure {late} Pa, {measured} Pa measured"
        );
        let u = report.probes.get("max_speed", "u_max").expect("probe");
        assert!(u[n - 1] < 0.2, "{model}: spurious speed {} m/s", u[n - 1]);
        let clusters = report.probes.get("drop_shape", "clusters").expect("probe");
        assert!(clusters.iter().all(|&c| (c - 1.0).abs() < 0.5), "{model}: the drop broke up");
    }
}

#[test]
fn drop_shape_counts_separate_bodies() {
    let mut v = serde_json::to_value(drop("csf", wcsph(), 0.0)).expect("serialises");
    v["bodies"] = json!([
        { "role": "fluid", "shape": { "circle": { "center": [0.0, 0.0], "radius": 0.1 } } },
        { "role": "fluid", "shape": { "circle": { "center": [0.5, 0.0], "radius": 0.1 } } }
    ]);
    v["time"]["end"] = json!(1e-3);
    let scene = Scene::from_json(&v.to_string()).expect("valid");
    let report = meniscus::run(&scene, &mut meniscus::Quiet).expect("builds");
    let clusters = report.probes.get("drop_shape", "clusters").expect("probe");
    assert!(clusters.iter().all(|&c| (c - 2.0).abs() < 0.5), "{clusters:?}");
    // r_max: the farthest particle from the centroid (0.25, 0), about 0.25 + 0.1 − Δx/2.
    let r = report.probes.get("drop_shape", "r_max").expect("probe")[0];
    assert!((r - 0.34).abs() < 0.011, "{r}");
}
