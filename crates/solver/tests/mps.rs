//! The MPS scheme (MPS.md): its scene rules, its wall particles, its particle count, and
//! results that do not depend on the thread count.

mod common;

use meniscus::profile::Stepper;
use meniscus::{Scene, SceneError};
use serde_json::{Value, json};

/// MPS options as the cases use them (Lan's weight and radii, γ = 0.01).
fn mps() -> Value {
    json!({"gamma": 0.01, "ppe": {"solver": "cg", "tolerance": 1e-6, "max_iterations": 2000}})
}

/// The periodic channel (Re 40, D/36) with MPS, edited by `edit`.
fn channel(edit: impl FnOnce(&mut Value)) -> Scene {
    common::periodic_channel_scene(|v| {
        v["scheme"] = json!({"mps": mps()});
        v["output"] = json!({"probe_every": 10});
        edit(v);
    })
}

fn error_of(edit: impl FnOnce(&mut Value)) -> SceneError {
    let mut v: Value = serde_json::from_str(common::DROP).expect("scene JSON");
    v["scheme"] = json!({"mps": mps()});
    edit(&mut v);
    Scene::from_json(&v.to_string()).expect_err("scene should be rejected")
}

/// Every bad MPS input names its field: a radius below l0, γ outside [0, 1], options of
/// another scheme inside `mps` (and MPS options inside `isph` or `wcsph`), the physics and
/// boundaries MPS does not have.
#[test]
fn bad_mps_input_names_the_field() {
    type Edit = Box<dyn FnOnce(&mut Value)>;
    let radii = |l: f64| json!({"number_density": 2.1, "gradient": 2.1, "laplacian": l});
    let cases: Vec<(&str, Edit)> = vec![
        ("scheme.mps.gamma", Box::new(|v| v["scheme"]["mps"]["gamma"] = json!(1.5))),
        ("scheme.mps.gamma", Box::new(|v| v["scheme"]["mps"]["gamma"] = json!(-0.01))),
        ("scheme.mps.radii.laplacian", Box::new(move |v| v["scheme"]["mps"]["radii"] = radii(0.9))),
        ("scheme.mps.radii.laplacian", Box::new(move |v| v["scheme"]["mps"]["radii"] = radii(1.0))),
        ("scheme.mps.compressibility", Box::new(|v| v["scheme"]["mps"]["compressibility"] = json!(-1e-9))),
        (
            "scheme.mps.free_surface.beta",
            Box::new(|v| v["scheme"]["mps"]["free_surface"]["beta"] = json!(1.2)),
        ),
        ("scheme.mps.ppe.tolerance", Box::new(|v| v["scheme"]["mps"]["ppe"]["tolerance"] = json!(0.0))),
        (
            "scheme.mps.shifting.xu.coefficient",
            Box::new(|v| v["scheme"]["mps"]["shifting"] = json!({"xu": {"coefficient": 2.0}})),
        ),
        // An ISPH option inside `mps`, and MPS options inside `isph` and `wcsph`.
        ("free_surface_threshold", Box::new(|v| v["scheme"]["mps"]["free_surface_threshold"] = json!(1.5))),
        (
            "gamma",
            Box::new(|v| {
                v["scheme"] = json!({"isph": {"ppe": {"solver": "cg", "tolerance": 1e-3, "max_iterations": 100},
                                              "free_surface_threshold": 1.5, "gamma": 0.01}})
            }),
        ),
        (
            "radii",
            Box::new(move |v| v["scheme"] = json!({"wcsph": {"sound_speed": 100.0, "radii": radii(4.1)}})),
        ),
        ("fluid.surface_tension", Box::new(|v| v["fluid"]["surface_tension"] = json!(0.07))),
    ];
    for (field, edit) in cases {
        let msg = error_of(edit).to_string();
        assert!(msg.contains(field), "message `{msg}` does not name `{field}`");
    }
    let dummy =
        common::periodic_channel_scene(|v| v["scheme"] = json!({"isph": v["scheme"]["isph"].clone()}));
    assert!(dummy.boundaries.walls.len() == 2);
    let mut v: Value = serde_json::to_value(&dummy).expect("serialisable");
    v["scheme"] = json!({"mps": mps()});
    v["boundaries"]["wall_model"] = json!("dummy");
    let msg = Scene::from_json(&v.to_string()).expect_err("dummy walls with mps").to_string();
    assert!(msg.contains("boundaries.wall_model"), "{msg}");
}

/// The wall layers cover the Laplacian radius behind each wall (four layers for 4.1 l0,
/// three for the classic 3.1), and the number of particles never changes in a periodic
/// channel: asserted after every step.
#[test]
fn wall_layers_cover_the_laplacian_and_the_count_is_kept() {
    for (weight, layers) in [("lan", 4), ("classic", 3)] {
        let scene = channel(|v| {
            v["scheme"]["mps"]["weight"] = json!(weight);
            v["time"]["end"] = json!(200.0);
        });
        let mut stepper = Stepper::<2>::new(&scene).expect("builds");
        let (fluid, total) = (stepper.state().particles.fluid, stepper.state().particles.total());
        // 18 columns in the period, `layers` rows behind each of the two walls.
        assert_eq!(total - fluid, 2 * 18 * layers, "{weight}");
        for _ in 0..40 {
            stepper.step_once().expect("steps");
            let p = &stepper.state().particles;
            assert_eq!((p.fluid, p.total()), (fluid, total), "{weight}: particle count changed");
        }
    }
}

/// MPS gives bit-identical probes and frames with one and two threads, with walls and
/// shifting (the periodic channel) and with a free surface (the drop).
#[test]
fn mps_is_thread_independent() {
    let run = |scene: &Scene, threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().expect("pool");
        pool.install(|| meniscus::run(scene, &mut meniscus::Quiet).expect("scene builds"))
    };
    let channel = channel(|v| {
        v["scheme"]["mps"]["shifting"] = json!({"xu": {"coefficient": 0.02}});
        v["scheme"]["mps"]["ppe"]["preconditioner"] = json!("two_level");
        v["time"]["end"] = json!(2000.0);
    });
    let drop = common::drop_scene(|v| {
        v["dx"] = json!(0.05);
        v["time"]["end"] = json!(1e-3);
        v["scheme"] = json!({"mps": {"weight": "classic", "gamma": 0.01, "divergence": "corrected",
                                     "pressure_gradient": "minimum", "clip_negative_pressure": true,
                                     "ppe": {"solver": "cg", "tolerance": 1e-3, "max_iterations": 500}}});
        v["probes"] = json!([{"ellipse_axes": {}}, {"pressure_at": {"point": [0.0, 0.0]}}, {"solver": {}}]);
    });
    for scene in [channel, drop] {
        let (a, b) = (run(&scene, 1), run(&scene, 2));
        assert!(a.error.is_none() && b.error.is_none(), "{:?}", a.error);
        let json = |r: &meniscus::RunReport| serde_json::to_string(&r.probes).expect("serialisable");
        assert_eq!(json(&a), json(&b), "{}: probes differ between 1 and 2 threads", scene.name);
        assert_eq!(a.final_frame, b.final_frame);
    }
}
