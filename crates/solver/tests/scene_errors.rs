//! Bad scenes give errors that name the field; nothing panics.

mod common;

use meniscus::{Scene, SceneError};
use serde_json::{Value, json};

fn error_of(edit: impl FnOnce(&mut Value)) -> SceneError {
    let mut v: Value = serde_json::from_str(common::DROP).expect("scene JSON");
    edit(&mut v);
    Scene::from_json(&v.to_string()).expect_err("scene should be rejected")
}

#[test]
fn design_example_parses_unchanged() {
    let s = Scene::from_json(common::DROP).expect("DESIGN.md scene parses");
    assert_eq!(s.name, "elliptical_drop");
}

/// A `time.steady` block (the drop scene ends at 8 ms).
fn steady(probe: &str, window: f64, tolerance: f64, after: f64) -> Value {
    json!({"probe": probe, "window": window, "tolerance": tolerance, "after": after})
}

#[test]
fn each_invalid_field_is_named() {
    type Edit = Box<dyn FnOnce(&mut Value)>;
    let cases: Vec<(&str, Edit)> = vec![
        ("fluid.density", Box::new(|v| v["fluid"]["density"] = json!(-1000.0))),
        ("fluid.viscosity", Box::new(|v| v["fluid"]["viscosity"] = json!(-1e-3))),
        ("dx", Box::new(|v| v["dx"] = json!(0.0))),
        ("dx", Box::new(|v| v["dx"] = json!("a"))),
        ("dimension", Box::new(|v| v["dimension"] = json!(4))),
        ("kernel.h_over_dx", Box::new(|v| v["kernel"]["h_over_dx"] = json!(-1.5))),
        ("kernel.kind", Box::new(|v| v["kernel"]["kind"] = json!("gaussian"))),
        ("bodies", Box::new(|v| v["bodies"] = json!([]))),
        (
            "bodies[0].shape.circle.radius",
            Box::new(|v| v["bodies"][0]["shape"]["circle"]["radius"] = json!(0.001)),
        ),
        (
            "bodies[0].shape.circle.center",
            Box::new(|v| v["bodies"][0]["shape"]["circle"]["center"] = json!([0.0])),
        ),
        (
            "bodies[0].velocity.affine.gradient",
            Box::new(|v| v["bodies"][0]["velocity"]["affine"]["gradient"] = json!([[1.0, 0.0]])),
        ),
        ("time.end", Box::new(|v| v["time"]["end"] = json!(-1.0))),
        ("time.step.fixed", Box::new(|v| v["time"]["step"]["fixed"] = json!(1.0))),
        ("scheme.isph.ppe.tolerance", Box::new(|v| v["scheme"]["isph"]["ppe"]["tolerance"] = json!(2.0))),
        (
            "scheme.isph.free_surface_threshold",
            Box::new(|v| v["scheme"]["isph"]["free_surface_threshold"] = json!(2.5)),
        ),
        (
            "scheme.isph.shifting.xu.coefficient",
            Box::new(|v| v["scheme"]["isph"]["shifting"]["xu"]["coefficient"] = json!(-0.02)),
        ),
        ("output.probe_every", Box::new(|v| v["output"]["probe_every"] = json!(0))),
        (
            "time.steady.probe",
            Box::new(|v| v["time"]["steady"] = steady("velocity_profile", 1e-3, 0.01, 0.0)),
        ),
        ("time.steady.window", Box::new(|v| v["time"]["steady"] = steady("ellipse_axes", 4e-3, 0.01, 0.0))),
        ("time.steady.tolerance", Box::new(|v| v["time"]["steady"] = steady("ellipse_axes", 1e-3, 0.0, 0.0))),
        ("time.steady.after", Box::new(|v| v["time"]["steady"] = steady("ellipse_axes", 1e-3, 0.01, 0.008))),
        ("dx", Box::new(|v| v["dx"] = json!(1e-5))),
        ("kernel.h_over_dx", Box::new(|v| v["kernel"]["h_over_dx"] = json!(0.5))),
        ("fluid", Box::new(|v| v["fluid"]["colour"] = json!(1))),
        ("unknown_top_level", Box::new(|v| v["unknown_top_level"] = json!(1))),
    ];
    for (field, edit) in cases {
        let msg = error_of(edit).to_string();
        assert!(msg.contains(field), "message `{msg}` does not name `{field}`");
    }
}

#[test]
fn garbage_never_panics() {
    for text in ["", "{", "null", "[]", "{\"name\": 3}", "\u{0}", "{\"dimension\": 1e400}"] {
        assert!(Scene::from_json(text).is_err(), "{text:?}");
    }
}

#[test]
fn missing_file_names_the_path() {
    let e = Scene::from_path(std::path::Path::new("/nonexistent/scene.json")).expect_err("missing");
    assert!(e.to_string().contains("/nonexistent/scene.json"));
}

/// The error of a scene edited by `edit`, from parsing or validation: every scene rule is
/// the validation's, so a scene that validates must build.
fn any_error_of(edit: impl FnOnce(&mut Value)) -> Option<String> {
    let mut v: Value = serde_json::from_str(common::DROP).expect("scene JSON");
    v["dx"] = json!(0.05);
    edit(&mut v);
    match Scene::from_json(&v.to_string()) {
        Err(e) => Some(e.to_string()),
        Ok(scene) => {
            if let Err(e) = meniscus::AnySimulation::new(&scene) {
                panic!("a scene that validates failed to build: {e}");
            }
            None
        }
    }
}

/// A rectangle body at `min`..`max` with zero velocity and pressure.
fn rect(min: [f64; 2], max: [f64; 2]) -> Value {
    json!({"role": "fluid", "shape": {"rectangle": {"min": min, "max": max}}})
}

#[test]
fn malformed_scene_table() {
    type Edit = fn(&mut Value);
    // (field the message must name, a word of the rule or value, the edit)
    let cases: Vec<(&str, &str, Edit)> = vec![
        // Numbers: negative, zero, wrong type, out of range.
        ("dx", "positive", |v| v["dx"] = json!(-0.02)),
        ("dx", "positive", |v| v["dx"] = json!(0)),
        ("dx", "", |v| v["dx"] = json!("NaN")),
        ("dx", "", |v| v["dx"] = json!(null)),
        ("dimension", "", |v| v["dimension"] = json!(-2)),
        ("dimension", "2 or 3", |v| v["dimension"] = json!(1)),
        ("dimension", "", |v| v["dimension"] = json!(2.5)),
        ("fluid.density", "positive", |v| v["fluid"]["density"] = json!(0.0)),
        ("fluid.density", "", |v| v["fluid"]["density"] = json!([1000.0])),
        ("fluid.viscosity", "negative", |v| v["fluid"]["viscosity"] = json!(-1.0)),
        ("fluid.surface_tension", "negative", |v| v["fluid"]["surface_tension"] = json!(-0.07)),
        ("fluid.surface_tension_model", "", |v| v["fluid"]["surface_tension_model"] = json!("marangoni")),
        ("fluid.surface_tension_threshold", "positive", |v| {
            v["fluid"]["surface_tension_threshold"] = json!(-0.01)
        }),
        ("fluid.surface_tension_threshold", "below 1", |v| {
            v["fluid"]["surface_tension_threshold"] = json!(2.0)
        }),
        ("kernel.h_over_dx", "positive", |v| v["kernel"]["h_over_dx"] = json!(0)),
        ("kernel.h_over_dx", "at most 4", |v| v["kernel"]["h_over_dx"] = json!(10)),
        ("kernel.h_over_dx", "", |v| v["kernel"]["h_over_dx"] = json!(true)),
        ("scheme.isph.ppe.tolerance", "positive", |v| v["scheme"]["isph"]["ppe"]["tolerance"] = json!(0)),
        ("scheme.isph.ppe.preconditioner", "", |v| {
            v["scheme"]["isph"]["ppe"]["preconditioner"] = json!("ilu")
        }),
        ("scheme.isph.density_relaxation", "[0, 1]", |v| {
            v["scheme"]["isph"]["density_relaxation"] = json!(1.5)
        }),
        ("scheme.isph.viscous_operator", "explicit only", |v| {
            v["scheme"]["isph"]["viscosity"] = json!("implicit");
            v["scheme"]["isph"]["viscous_operator"] = json!("monaghan_cleary")
        }),
        ("scheme.isph.viscous_operator", "explicit only", |v| {
            v["scheme"]["isph"]["viscosity"] = json!("implicit");
            v["scheme"]["isph"]["viscous_operator"] = json!("consistent")
        }),
        ("scheme.isph.viscous_operator", "", |v| v["scheme"]["isph"]["viscous_operator"] = json!("morris")),
        ("scheme.isph.density_relaxation", "[0, 1]", |v| {
            v["scheme"]["isph"]["density_relaxation"] = json!(-0.1)
        }),
        ("scheme.isph.ppe.tolerance", "positive", |v| v["scheme"]["isph"]["ppe"]["tolerance"] = json!(-1e-3)),
        ("scheme.isph.ppe.max_iterations", "at least 1", |v| {
            v["scheme"]["isph"]["ppe"]["max_iterations"] = json!(0)
        }),
        ("scheme.isph.ppe.max_iterations", "", |v| v["scheme"]["isph"]["ppe"]["max_iterations"] = json!(-5)),
        ("scheme.isph.ppe.solver", "", |v| v["scheme"]["isph"]["ppe"]["solver"] = json!("gmres")),
        ("scheme.isph.ppe.coarse_refresh", "at least 1", |v| {
            v["scheme"]["isph"]["ppe"]["coarse_refresh"] = json!(0)
        }),
        ("scheme.isph.free_surface_threshold", "positive", |v| {
            v["scheme"]["isph"]["free_surface_threshold"] = json!(0)
        }),
        ("scheme.isph.shifting.xu.coefficient", "at most 1", |v| {
            v["scheme"]["isph"]["shifting"]["xu"]["coefficient"] = json!(5.0)
        }),
        ("scheme.isph.shifting.fickian", "missing field", |v| {
            v["scheme"]["isph"]["shifting"] = json!({"xu": {}, "fickian": {}})
        }),
        // `sound_speed` is required.
        ("scheme.wcsph", "sound_speed", |v| v["scheme"] = json!({"wcsph": {}})),
        ("scheme.mps", "gamma", |v| v["scheme"] = json!({"mps": {}})),
        ("scheme", "", |v| v["scheme"] = json!({"lbm": {}})),
        ("scheme.wcsph.sound_speed", "positive", |v| v["scheme"] = json!({"wcsph": {"sound_speed": -10.0}})),
        ("scheme.wcsph.sound_speed", "positive", |v| v["scheme"] = json!({"wcsph": {"sound_speed": 0.0}})),
        ("scheme.wcsph.shifting.xu.coefficient", "at most 1", |v| {
            v["scheme"] = json!({"wcsph": {"sound_speed": 10.0, "shifting": {"xu": {"coefficient": 2.0}}}})
        }),
        ("scheme.wcsph.shifting.fickian.coefficient", "positive", |v| {
            v["scheme"] =
                json!({"wcsph": {"sound_speed": 10.0, "shifting": {"fickian": {"coefficient": 0.0}}}})
        }),
        ("scheme.wcsph.gamma", "1..=10", |v| {
            v["scheme"] = json!({"wcsph": {"sound_speed": 10.0, "gamma": 0.5}})
        }),
        ("scheme.wcsph.artificial_viscosity.alpha", "negative", |v| {
            v["scheme"] = json!({"wcsph": {"sound_speed": 10.0, "artificial_viscosity": {"alpha": -0.1}}})
        }),
        ("scheme.wcsph.artificial_viscosity.beta", "negative", |v| {
            v["scheme"] =
                json!({"wcsph": {"sound_speed": 10.0, "artificial_viscosity": {"alpha": 0.1, "beta": -2.0}}})
        }),
        ("scheme.wcsph.artificial_viscosity.alpha", "at most 10", |v| {
            v["scheme"] = json!({"wcsph": {"sound_speed": 10.0, "artificial_viscosity": {"alpha": 50.0}}})
        }),
        ("scheme.wcsph.density_diffusion", "negative", |v| {
            v["scheme"] = json!({"wcsph": {"sound_speed": 10.0, "density_diffusion": -0.1}})
        }),
        ("scheme.wcsph.density_diffusion", "at most 1", |v| {
            v["scheme"] = json!({"wcsph": {"sound_speed": 10.0, "density_diffusion": 3.0}})
        }),
        ("scheme.wcsph.continuity", "", |v| {
            v["scheme"] = json!({"wcsph": {"sound_speed": 10.0, "continuity": "exact"}})
        }),
        ("scheme.wcsph.c0", "unknown field", |v| {
            v["scheme"] = json!({"wcsph": {"sound_speed": 10.0, "c0": 1.0}})
        }),
        // Time.
        ("time.end", "positive", |v| v["time"]["end"] = json!(0)),
        ("time.end", "positive", |v| v["time"]["end"] = json!(-0.008)),
        ("time.step.fixed", "positive", |v| v["time"]["step"]["fixed"] = json!(0)),
        ("time.step.fixed", "positive", |v| v["time"]["step"]["fixed"] = json!(-2e-5)),
        ("time.step.fixed", "must not exceed time.end", |v| v["time"]["step"]["fixed"] = json!(0.01)),
        ("time.step.fixed", "steps", |v| v["time"]["step"]["fixed"] = json!(1e-18)),
        ("time.step.adaptive.cfl", "at most 1", |v| {
            v["time"]["step"] = json!({"adaptive": {"cfl": 2.0, "max": 1e-4}})
        }),
        ("time.step.adaptive.max", "positive", |v| v["time"]["step"] = json!({"adaptive": {"max": 0.0}})),
        ("time.step.adaptive.viscous", "positive", |v| {
            v["time"]["step"] = json!({"adaptive": {"viscous": -0.2, "max": 1e-4}})
        }),
        ("time.step", "", |v| v["time"]["step"] = json!({"fixed": 2e-5, "adaptive": {"max": 1e-4}})),
        // Vectors and matrices of the wrong size.
        ("body_force", "2 components", |v| v["body_force"] = json!([0.0, 0.0, -9.81])),
        ("body_force[1]", "", |v| v["body_force"] = json!([0.0, "NaN"])),
        ("bodies[0].shape.circle.center", "2 components", |v| {
            v["bodies"][0]["shape"]["circle"]["center"] = json!([])
        }),
        ("bodies[0].shape.circle.radius", "positive", |v| {
            v["bodies"][0]["shape"]["circle"]["radius"] = json!(-1.0)
        }),
        ("bodies[0].velocity.affine.gradient", "2 rows", |v| {
            v["bodies"][0]["velocity"]["affine"]["gradient"] = json!([[1.0, 0.0], [0.0, 1.0], [0.0, 0.0]])
        }),
        ("bodies[0].velocity.affine.gradient[1]", "2 components", |v| {
            v["bodies"][0]["velocity"]["affine"]["gradient"] = json!([[1.0, 0.0], [0.0]])
        }),
        ("bodies[0].velocity.affine.offset", "2 components", |v| {
            v["bodies"][0]["velocity"]["affine"]["offset"] = json!([0.0, 0.0, 0.0])
        }),
        ("bodies[0].pressure.quadratic.hessian", "2 rows", |v| {
            v["bodies"][0]["pressure"]["quadratic"]["hessian"] = json!([])
        }),
        ("bodies[0].pressure.quadratic.hessian[0]", "2 components", |v| {
            v["bodies"][0]["pressure"]["quadratic"]["hessian"] = json!([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
        }),
        ("bodies[0].pressure.quadratic.center", "2 components", |v| {
            v["bodies"][0]["pressure"]["quadratic"]["center"] = json!([0.0])
        }),
        ("bodies[0].pressure.hydrostatic.surface_point", "2 components", |v| {
            v["bodies"][0]["pressure"] = json!({"hydrostatic": {"surface_point": [1.0]}})
        }),
        ("probes[1].pressure_at.point", "2 components", |v| {
            v["probes"][1]["pressure_at"]["point"] = json!([0.0])
        }),
        ("probes[0].ellipse_axes", "2D", |v| {
            v["dimension"] = json!(3);
            v["body_force"] = json!([]);
            v["bodies"] =
                json!([{"role": "fluid", "shape": {"sphere": {"center": [0.0, 0.0, 0.0], "radius": 0.2}}}]);
            v["probes"] = json!([{"ellipse_axes": {}}]);
        }),
        ("probes[0].young_laplace", "2D", |v| {
            v["dimension"] = json!(3);
            v["body_force"] = json!([]);
            v["bodies"] =
                json!([{"role": "fluid", "shape": {"sphere": {"center": [0.0, 0.0, 0.0], "radius": 0.2}}}]);
            v["probes"] = json!([{"young_laplace": {}}]);
        }),
        // Shapes: wrong dimension, no particles, min ≥ max, too far out.
        ("bodies[0].shape.sphere", "3D shape", |v| {
            v["bodies"][0]["shape"] = json!({"sphere": {"center": [0.0, 0.0, 0.0], "radius": 1.0}})
        }),
        ("bodies[0].shape.rectangle.max[0]", "no particle", |v| {
            v["bodies"] = json!([rect([0.0, 0.0], [0.01, 1.0])])
        }),
        ("bodies[0].shape.rectangle.max[1]", "no particle", |v| {
            v["bodies"] = json!([rect([0.0, 1.0], [1.0, 0.0])])
        }),
        ("bodies[0].shape.rectangle.max[0]", "no particle", |v| {
            v["bodies"] = json!([rect([1.0, 0.0], [1.0, 1.0])])
        }),
        ("bodies[0].shape.circle.radius", "no particle", |v| {
            v["bodies"][0]["shape"]["circle"]["radius"] = json!(0.01)
        }),
        ("bodies[0].shape.circle.center[0]", "origin", |v| {
            v["bodies"][0]["shape"]["circle"]["center"] = json!([1e30, 0.0])
        }),
        ("bodies[0].role", "", |v| v["bodies"][0]["role"] = json!("solid")),
        ("boundaries.wall_model", "must be dummy", |v| v["bodies"][0]["role"] = json!("wall")),
        ("bodies[0].velocity", "at rest", |v| {
            v["bodies"][0]["role"] = json!("wall");
            v["boundaries"] = json!({"wall_model": "dummy"});
        }),
        ("bodies", "no fluid particle", |v| {
            v["bodies"][0] =
                json!({"role": "wall", "shape": {"circle": {"center": [0.0, 0.0], "radius": 1.0}}});
            v["boundaries"] = json!({"wall_model": "dummy"});
        }),
        ("bodies", "at least one", |v| v["bodies"] = json!([])),
        ("dx", "particles", |v| v["dx"] = json!(1e-9)),
        // Overlapping bodies: the later body is named.
        ("bodies[1].shape", "overlaps bodies[0]", |v| {
            v["bodies"] = json!([rect([0.0, 0.0], [1.0, 1.0]), rect([0.5, 0.5], [1.5, 1.5])])
        }),
        ("bodies[2].shape", "overlaps bodies[0]", |v| {
            v["bodies"] = json!([
                rect([0.0, 0.0], [1.0, 1.0]),
                rect([2.0, 0.0], [3.0, 1.0]),
                rect([0.0, 0.0], [1.0, 1.0])
            ])
        }),
        // Non-finite initial fields.
        ("bodies[0].velocity", "finite", |v| {
            v["bodies"][0]["velocity"]["affine"] =
                json!({"gradient": [[1e308, 0.0], [0.0, 0.0]], "offset": [1e308, 0.0]})
        }),
        ("bodies[0].pressure", "finite", |v| {
            v["bodies"][0]["pressure"]["quadratic"]["value"] = json!(1.7e308);
            v["bodies"][0]["pressure"]["quadratic"]["hessian"] = json!([[1e308, 0.0], [0.0, 1e308]]);
        }),
        // Periodic axes.
        ("boundaries.periodic[0].axis", "axis of the scene", |v| {
            v["boundaries"] = json!({"periodic": [{"axis": 2, "min": -2.0, "max": 2.0}]})
        }),
        ("boundaries.periodic[0].axis", "", |v| {
            v["boundaries"] = json!({"periodic": [{"axis": -1, "min": -2.0, "max": 2.0}]})
        }),
        (
            "boundaries.periodic[1].axis",
            "twice",
            |v| v["boundaries"] = json!({"periodic": [{"axis": 0, "min": -2.0, "max": 2.0}, {"axis": 0, "min": -2.0, "max": 2.0}]}),
        ),
        ("boundaries.periodic[0].max", "must exceed min", |v| {
            v["boundaries"] = json!({"periodic": [{"axis": 0, "min": 2.0, "max": 2.0}]})
        }),
        ("boundaries.periodic[0].max", "kernel support", |v| {
            v["boundaries"] = json!({"periodic": [{"axis": 0, "min": 0.0, "max": 0.1}]})
        }),
        ("bodies[0].shape", "longer than the period", |v| {
            v["boundaries"] = json!({"periodic": [{"axis": 1, "min": 0.0, "max": 1.0}]})
        }),
        // Unknown fields, wrong types, missing fields.
        ("kernel.support", "unknown field", |v| v["kernel"]["support"] = json!(2.0)),
        ("bodies[0].colour", "unknown field", |v| v["bodies"][0]["colour"] = json!("blue")),
        ("bodies[0].shape.circle.centre", "unknown field", |v| {
            v["bodies"][0]["shape"]["circle"]["centre"] = json!([0.0, 0.0])
        }),
        ("time", "missing field", |v| {
            v["time"].as_object_mut().map(|m| m.remove("end"));
        }),
        ("output.probe_every", "at least 1", |v| v["output"]["probe_every"] = json!(0)),
        ("output.vtk_every", "", |v| v["output"]["vtk_every"] = json!(-1)),
        ("output.snapshot_times[1]", "larger than the time before", |v| {
            v["output"]["snapshot_times"] = json!([0.004, 0.002])
        }),
        ("output.snapshot_times[0]", "not be negative", |v| v["output"]["snapshot_times"] = json!([-0.001])),
        ("output.snapshot_times[0]", "exceed time.end", |v| v["output"]["snapshot_times"] = json!([0.5])),
        ("output.snapshot_times", "at most 100", |v| {
            v["output"]["snapshot_times"] = json!((0..101).map(|i| i as f64 * 1e-5).collect::<Vec<_>>())
        }),
        ("output.snapshot_times[0]", "", |v| v["output"]["snapshot_times"] = json!(["soon"])),
        ("bodies[0].jitter.fraction", "[0, 0.5)", |v| {
            v["bodies"][0]["jitter"] = json!({"fraction": 0.5, "seed": 1})
        }),
        ("bodies[0].jitter.fraction", "[0, 0.5)", |v| {
            v["bodies"][0]["jitter"] = json!({"fraction": -0.1, "seed": 1})
        }),
        ("bodies[0].jitter.seed", "", |v| v["bodies"][0]["jitter"] = json!({"fraction": 0.1, "seed": -3})),
        ("bodies[0].jitter.amplitude", "unknown field", |v| {
            v["bodies"][0]["jitter"] = json!({"fraction": 0.1, "seed": 1, "amplitude": 2})
        }),
        ("bodies[0].packing", "needs a circle", |v| {
            v["bodies"][0]["shape"] = json!({"rectangle": {"min": [-0.5, -0.5], "max": [0.5, 0.5]}});
            v["bodies"][0]["packing"] = json!("rings");
        }),
        ("bodies[0].packing", "", |v| v["bodies"][0]["packing"] = json!("hexagonal")),
        ("name", "empty", |v| v["name"] = json!("  ")),
        ("name", "", |v| v["name"] = json!(42)),
        ("probes[0]", "", |v| v["probes"] = json!([{"vorticity": {}}])),
        ("scene", "JSON object", |v| *v = json!([1, 2, 3])),
        ("scene", "JSON object", |v| *v = json!("elliptical_drop")),
    ];
    let mut failures = Vec::new();
    for (field, rule, edit) in cases {
        let Some(msg) = any_error_of(edit) else {
            failures.push(format!("expected `{field}` ({rule}): the scene was accepted"));
            continue;
        };
        if !msg.contains(&format!("`{field}`")) || !msg.contains(rule) {
            failures.push(format!("expected `{field}` ({rule}): {msg}"));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn out_of_range_numbers_name_the_field() {
    for (from, to, field) in [
        ("\"dx\": 0.02", "\"dx\": 1e999", "dx"),
        ("\"density\": 1000.0", "\"density\": -1e999", "fluid.density"),
        ("\"end\": 0.008", "\"end\": NaN", "time"),
    ] {
        assert!(common::DROP.contains(from), "{from}");
        let e = Scene::from_json(&common::DROP.replace(from, to)).expect_err("rejected").to_string();
        assert!(e.contains(field), "{field}: {e}");
    }
}
