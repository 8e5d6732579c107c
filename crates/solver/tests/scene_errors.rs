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
