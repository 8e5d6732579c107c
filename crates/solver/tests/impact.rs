//! A drop hitting a wall in 3D (WCSPH, Hu–Adams surface stress, dummy wall particles): the
//! `spread` probe's wetted diameter grows as the early law √(6T) says, the run is the same
//! on 1 and 2 threads, and the probe's bad inputs are named.

use meniscus::Scene;
use serde_json::{Value, json};

/// A holdout impact (not the case's): D = 1 mm at V = 1.2 m/s (We 19.8, Re 1200), D/Δx = 10,
/// on a plate 2.4 D wide, to T = tV/D = `t_end`.
fn impact(t_end: f64) -> Value {
    let (d, v) = (1e-3, 1.2);
    let dx = d / 10.0;
    json!({
        "name": "impact", "dimension": 3, "dx": dx,
        "kernel": { "kind": "cubic_spline", "h_over_dx": 1.5 },
        "fluid": { "density": 1000.0, "viscosity": 1e-3, "surface_tension": 0.0728 },
        "body_force": [0.0, 0.0, -9.81],
        "bodies": [
            { "role": "fluid", "shape": { "sphere": { "center": [0.0, 0.0, 0.5 * d], "radius": 0.5 * d } },
              "packing": "shells",
              "velocity": { "affine": { "gradient": [[0.0, 0.0, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, 0.0]],
                                        "offset": [0.0, 0.0, -v] } } },
            { "role": "wall", "shape": { "box": { "min": [-1.2 * d, -1.2 * d, -3.0 * dx], "max": [1.2 * d, 1.2 * d, 0.0] } } }
        ],
        "boundaries": { "wall_model": "dummy" },
        "scheme": { "wcsph": { "sound_speed": 15.0, "artificial_viscosity": { "alpha": 0.4, "beta": 0.0 },
                               "density_diffusion": 0.1 } },
        "time": { "end": t_end * d / v, "step": { "adaptive": { "cfl": 0.25, "viscous": 0.2, "max": 1e-5 } } },
        "probes": [{ "spread": { "axis": 2, "position": 0.0 } }],
        "output": { "probe_every": 4 }
    })
}

fn run(scene: &Value, threads: usize) -> meniscus::ProbeRecord {
    let scene = Scene::from_json(&scene.to_string()).expect("impact scene");
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().expect("pool");
    let report = pool.install(|| meniscus::run(&scene, &mut meniscus::Quiet)).expect("builds");
    assert!(report.error.is_none(), "{:?}", report.error);
    report.probes
}

#[test]
fn the_wetted_diameter_follows_the_early_law_the_same_on_any_thread_count() {
    let scene = impact(0.3);
    let p = run(&scene, 1);
    let (d, v) = (1e-3, 1.2);
    let diameter = p.get("spread", "diameter").expect("diameter");
    // Between T = 0.15 and 0.3 the wetted diameter is within 20 % of √(6T) D at D/10 (the first
    // row's layer widens it by O(√(Δx D)) earlier on), and grows.
    let (mut last, mut checked) = (0.0, 0);
    for (t, dm) in p.t.iter().zip(diameter) {
        let ts = t * v / d;
        if ts >= 0.15 {
            checked += 1;
            let law = (6.0 * ts).sqrt() * d;
            assert!((dm / law - 1.0).abs() < 0.2, "T = {ts}: d/D = {} against {}", dm / d, law / d);
            assert!(*dm >= last - 0.5e-4, "the wetted diameter shrank at T = {ts}");
            last = *dm;
        }
    }
    assert!(checked > 5, "{checked} samples in 0.15 <= T <= 0.3");
    let height = p.get("spread", "height").expect("height");
    assert!(height[0] > 0.99 * d && *height.last().unwrap() < 0.9 * d, "{height:?}");
    let two = run(&scene, 2);
    for q in ["diameter", "width", "height"] {
        let (a, b) = (p.get("spread", q).unwrap(), two.get("spread", q).unwrap());
        assert!(a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits()), "{q} differs on 2 threads");
    }
}

#[test]
fn bad_spread_probes_are_named() {
    for (probe, field) in [
        (json!({ "spread": { "axis": 3, "position": 0.0 } }), "probes[0].spread.axis"),
        (json!({ "spread": { "axis": 2, "position": 0.0, "layer": -1e-4 } }), "probes[0].spread.layer"),
    ] {
        let mut scene = impact(0.1);
        scene["probes"] = json!([probe]);
        let err = Scene::from_json(&scene.to_string()).expect_err("rejected");
        assert!(err.to_string().contains(field), "{err} (want {field})");
    }
}
