//! The viscous operator on a free body in rigid rotation (`rotating_square`, Qiu 2013 §3.2):
//! the exact flow has no viscous stress, and no external torque acts on the body, so its
//! angular momentum is conserved. The Shao–Lo operator (Qiu eq. 13) is not central and
//! brakes the rotation where the free surface truncates the support; the Monaghan–Cleary
//! operator is central and vanishes for rigid motion.

use meniscus::Scene;
use serde_json::json;

/// Relative angular-momentum change of the spinning square (Δx = 0.04, μ = 1000 Pa s) after
/// `steps` steps of 1e-4 s with the viscous operator `operator`, without shifting.
fn lz_drift(operator: &str, steps: usize) -> f64 {
    let v = json!({
        "name": "spin", "dimension": 2, "dx": 0.04,
        "kernel": { "kind": "cubic_spline", "h_over_dx": 1.5 },
        "fluid": { "density": 1000.0, "viscosity": 1000.0 },
        "bodies": [ { "role": "fluid", "shape": { "rectangle": { "min": [-0.5, -0.5], "max": [0.5, 0.5] } },
                      "velocity": { "affine": { "gradient": [[0.0, 100.0], [-100.0, 0.0]], "offset": [0.0, 0.0] } } } ],
        "scheme": { "isph": { "ppe": { "solver": "bicgstab", "tolerance": 1e-6, "max_iterations": 2000 },
                              "free_surface_threshold": 1.5, "viscous_operator": operator } },
        "time": { "end": steps as f64 * 1e-4, "step": { "fixed": 1e-4 } },
        "probes": [ { "momentum": {} } ],
        "output": { "probe_every": 1 }
    });
    let scene = Scene::from_json(&v.to_string()).expect("valid scene");
    let report = meniscus::run(&scene, &mut meniscus::Quiet).expect("scene builds");
    assert!(report.error.is_none(), "{:?}", report.error);
    let lz = report.probes.get("momentum", "lz").expect("probe");
    (lz[lz.len() - 1] - lz[0]) / lz[0]
}

#[test]
fn the_central_operator_keeps_the_angular_momentum_of_a_spinning_body() {
    let central = lz_drift("monaghan_cleary", 20);
    let shao_lo = lz_drift("shao_lo", 20);
    // Measured after 20 steps (2 ms): −0.084 % (the projection's time discretisation)
    // against −2.2 % with Shao–Lo.
    assert!(central.abs() < 2e-3, "Monaghan–Cleary: {central:.3e}");
    assert!(shao_lo < -0.015, "Shao–Lo no longer brakes the rotation: {shao_lo:.3e}");
}
