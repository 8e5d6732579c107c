//! 3D pipe: a fluid cylinder inside a cylindrical shell of dummy wall particles (Adami,
//! Hu & Adams 2012), driven from rest by a body force, against the start-up series of
//! `meniscus_reference::pipe`; its bad inputs; thread independence in 3D.

use meniscus::{Scene, SceneError};
use meniscus_reference::pipe::HagenPoiseuille;
use serde_json::{Value, json};

/// Pipe radius \[m\], length \[m\], viscosity ν \[m²/s\] and body force G \[m/s²\]: a holdout
/// of the `hagen_poiseuille` case (R = 5 mm instead of 10, Re = 2 U R / ν = 2).
const R: f64 = 0.005;
const LENGTH: f64 = 0.0075;
const NU: f64 = 2e-6;
const G: f64 = 8.0 * NU * 2e-4 / (R * R);

/// The pipe at `R / dx = n` with `scheme`, to `tau_end = ν t / R²`.
fn pipe(n: usize, scheme: Value, tau_end: f64) -> Value {
    let dx = R / n as f64;
    let c = [LENGTH / 2.0, 0.0, 0.0];
    let end = tau_end * R * R / NU;
    json!({
        "name": "pipe", "dimension": 3, "dx": dx,
        "kernel": { "kind": "cubic_spline", "h_over_dx": 1.5 },
        "fluid": { "density": 1000.0, "viscosity": 1000.0 * NU },
        "body_force": [G, 0.0, 0.0],
        "bodies": [
            { "role": "fluid", "packing": "rings",
              "shape": { "cylinder": { "center": c, "axis": 0, "radius": R, "length": LENGTH } } },
            { "role": "wall", "packing": "rings",
              "shape": { "cylinder": { "center": c, "axis": 0, "radius": R + 2.6 * dx, "length": LENGTH,
                                       "inner_radius": R } } }
        ],
        "boundaries": { "periodic": [{ "axis": 0, "min": 0.0, "max": LENGTH }], "wall_model": "dummy" },
        "scheme": scheme,
        "time": { "end": end, "step": { "adaptive": { "cfl": 0.2, "viscous": 0.2, "max": 10.0 } } },
        "probes": [{ "radial_profile": { "axis": 0, "center": [0.0, 0.0, 0.0], "radius": R, "component": 0 } },
                   { "kinetic_energy": {} }],
        "output": { "probe_every": 1000, "probe_times": [end] }
    })
}

fn isph() -> Value {
    json!({ "isph": { "ppe": { "solver": "bicgstab", "tolerance": 1e-3, "max_iterations": 2000,
                               "preconditioner": "two_level" },
                      "shifting": { "xu": { "coefficient": 0.02 } } } })
}

fn wcsph() -> Value {
    json!({ "wcsph": { "sound_speed": 4e-3 } })
}

fn run(scene: &Value, threads: usize) -> meniscus::RunReport {
    let scene = Scene::from_json(&scene.to_string()).expect("pipe scene");
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().expect("pool");
    pool.install(|| meniscus::run(&scene, &mut meniscus::Quiet).expect("scene builds"))
}

/// Relative L2 error of the last radial profile against the series.
fn profile_error(report: &meniscus::RunReport) -> f64 {
    let pipe = HagenPoiseuille::new(R, G, NU).expect("pipe");
    let p = &report.probes;
    let i = p.t.len() - 1;
    let t = p.t[i];
    let (mut num, mut den) = (0.0, 0.0);
    for k in 0.. {
        let (Some(r), Some(u)) =
            (p.get("radial_profile", &format!("r_{k:03}")), p.get("radial_profile", &format!("u_{k:03}")))
        else {
            break;
        };
        if !r[i].is_finite() {
            continue;
        }
        let u_ref = pipe.velocity(r[i].min(R), t).expect("series");
        num += (u[i] - u_ref).powi(2);
        den += u_ref * u_ref;
    }
    (num / den).sqrt()
}

#[test]
fn isph_and_wcsph_pipes_follow_the_start_up_series() {
    // R/dx = 8, to ν t / R² = 0.3 (the centre line at 80 % of u_max); measured 2026-12-06:
    // ISPH 1.34 %, WCSPH 1.24 % (R/dx = 6: 2.25 %, 1.77 %). The case's sweep (R = 10 mm,
    // R/dx = 8 / 12 / 16) is the validation.
    for (name, scheme) in [("isph", isph()), ("wcsph", wcsph())] {
        let report = run(&pipe(8, scheme, 0.3), 2);
        assert!(report.error.is_none(), "{name}: {:?}", report.error);
        let e = profile_error(&report);
        assert!(e < 0.02, "{name}: profile L2 error {e}");
    }
}

#[test]
fn a_3d_pipe_gives_identical_probes_on_one_and_two_threads() {
    for scheme in [isph(), wcsph()] {
        let scene = pipe(6, scheme, 0.02);
        let (a, b) = (run(&scene, 1), run(&scene, 2));
        assert!(a.error.is_none() && b.error.is_none(), "{:?}", a.error);
        let json = |r: &meniscus::RunReport| serde_json::to_string(&r.probes).expect("serialisable");
        assert_eq!(json(&a), json(&b), "3D probe series differ between 1 and 2 threads");
        assert_eq!(a.final_frame, b.final_frame);
    }
}

fn error_of(edit: impl FnOnce(&mut Value)) -> SceneError {
    let mut v = pipe(6, isph(), 0.1);
    edit(&mut v);
    Scene::from_json(&v.to_string()).expect_err("scene should be rejected")
}

#[test]
fn bad_pipes_are_errors_naming_the_field() {
    type Edit = Box<dyn FnOnce(&mut Value)>;
    let cases: Vec<(&str, Edit)> = vec![
        ("boundaries.wall_model", Box::new(|v| v["boundaries"]["wall_model"] = json!("mirror"))),
        (
            // The shell reaches into the fluid.
            "bodies[1].shape",
            Box::new(|v| v["bodies"][1]["shape"]["cylinder"]["inner_radius"] = json!(0.8 * R)),
        ),
        (
            // A pipe no wider than the kernel support (2h = 3 dx = R/2 here).
            "bodies[0].shape.cylinder.radius",
            Box::new(|v| {
                v["dx"] = json!(R / 1.9);
                v["boundaries"]["periodic"][0]["max"] = json!(0.1);
            }),
        ),
        (
            "bodies[1].velocity",
            Box::new(
                |v| v["bodies"][1]["velocity"] = json!({"affine": {"gradient": [[0.0, 0.0, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, 0.0]], "offset": [1.0, 0.0, 0.0]}}),
            ),
        ),
        ("bodies[1].jitter", Box::new(|v| v["bodies"][1]["jitter"] = json!({"fraction": 0.1, "seed": 1}))),
        (
            "bodies[0].shape.cylinder.axis",
            Box::new(|v| v["bodies"][0]["shape"]["cylinder"]["axis"] = json!(3)),
        ),
        (
            "bodies[0].shape.cylinder.length",
            Box::new(|v| v["bodies"][0]["shape"]["cylinder"]["length"] = json!(-1.0)),
        ),
        (
            "bodies[1].shape.cylinder.radius",
            Box::new(|v| v["bodies"][1]["shape"]["cylinder"]["radius"] = json!(R)),
        ),
        (
            // A cross-section too wide to scan.
            "bodies[1].shape.cylinder.radius",
            Box::new(|v| v["bodies"][1]["shape"]["cylinder"]["radius"] = json!(4000.0 * R / 6.0)),
        ),
        (
            // Rings inside a radius below dx would be closer than dx.
            "bodies[0].shape.cylinder.inner_radius",
            Box::new(|v| v["bodies"][0]["shape"]["cylinder"]["inner_radius"] = json!(0.5 * R / 6.0)),
        ),
        (
            // A wall shell whose rings (spacing 6.4/6 dx here, the first at 6.93 dx) leave it empty.
            "bodies[1].shape",
            Box::new(|v| {
                v["bodies"][1]["shape"]["cylinder"]["inner_radius"] = json!(6.4 * R / 6.0);
                v["bodies"][1]["shape"]["cylinder"]["radius"] = json!(6.92 * R / 6.0);
            }),
        ),
        (
            // Rings fill a disc or a cylinder's cross-section, not a ball.
            "bodies[0].packing",
            Box::new(|v| {
                v["bodies"] = json!([{ "role": "fluid", "packing": "rings",
                                       "shape": { "sphere": { "center": [0.0, 0.0, 0.0], "radius": R } } }]);
                v["boundaries"] = json!({});
            }),
        ),
        (
            "probes[0].radial_profile.center",
            Box::new(|v| v["probes"][0]["radial_profile"]["center"] = json!([0.0])),
        ),
        (
            "probes[0].radial_profile.radius",
            Box::new(|v| v["probes"][0]["radial_profile"]["radius"] = json!(0.0)),
        ),
        (
            "probes[0].radial_profile.component",
            Box::new(|v| v["probes"][0]["radial_profile"]["component"] = json!(5)),
        ),
        ("probes[0].ellipse_axes", Box::new(|v| v["probes"] = json!([{"ellipse_axes": {}}]))),
        (
            "bodies[1].role",
            Box::new(|v| {
                v["scheme"] = json!({"mps": {"gamma": 0.01, "ppe": {"solver": "cg", "tolerance": 1e-6, "max_iterations": 2000}}});
                v["boundaries"]["wall_model"] = json!("mirror");
            }),
        ),
    ];
    for (field, edit) in cases {
        let e = error_of(edit);
        assert!(e.to_string().contains(field), "expected an error naming {field}, got: {e}");
    }
}

#[test]
fn a_cylinder_in_a_2d_scene_and_a_radial_profile_in_2d_are_errors() {
    let mut v: Value =
        serde_json::from_str(include_str!("../../../validation/scenes/elliptical_drop.json")).expect("drop");
    v["bodies"][0]["shape"] =
        json!({ "cylinder": { "center": [0.0, 0.0], "axis": 0, "radius": 1.0, "length": 1.0 } });
    let e = Scene::from_json(&v.to_string()).expect_err("2D cylinder");
    assert!(e.to_string().contains("bodies[0].shape.cylinder"), "{e}");
    let mut v: Value =
        serde_json::from_str(include_str!("../../../validation/scenes/elliptical_drop.json")).expect("drop");
    v["probes"] =
        json!([{ "radial_profile": { "axis": 0, "center": [0.0, 0.0], "radius": 1.0, "component": 0 } }]);
    let e = Scene::from_json(&v.to_string()).expect_err("2D radial profile");
    assert!(e.to_string().contains("probes[0].radial_profile"), "{e}");
}
