//! Results do not depend on the thread count (NUMERICS.md "Determinism").

mod common;

use serde_json::json;

fn run_with(threads: usize) -> meniscus::RunReport {
    let scene = common::drop_scene(|v| {
        v["dx"] = json!(0.05);
        v["time"]["end"] = json!(1e-3);
        v["probes"] = json!([{"ellipse_axes": {}}, {"pressure_at": {"point": [0.0, 0.0]}},
                             {"kinetic_energy": {}}, {"momentum": {}}, {"disorder": {}}, {"solver": {}}]);
    });
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().expect("pool");
    pool.install(|| meniscus::run(&scene, &mut meniscus::Quiet).expect("scene builds"))
}

#[test]
fn one_and_two_threads_give_identical_probes() {
    let a = run_with(1);
    let b = run_with(2);
    assert!(a.error.is_none() && b.error.is_none());
    assert_eq!(a.summary.threads, 1);
    assert_eq!(b.summary.threads, 2);
    // Compared as JSON so that bit-identical NaNs would compare equal too.
    let json = |r: &meniscus::RunReport| serde_json::to_string(&r.probes).expect("serialisable");
    assert_eq!(json(&a), json(&b), "probe series differ between 1 and 2 threads");
    assert_eq!(a.final_frame, b.final_frame);
}

#[test]
fn wcsph_with_surface_tension_is_thread_independent() {
    let run = |threads: usize| {
        let scene = common::drop_scene(|v| {
            v["dx"] = json!(0.05);
            v["time"] = json!({"end": 1e-3, "step": {"adaptive": {"cfl": 0.25, "max": 1e-4}}});
            v["fluid"]["surface_tension"] = json!(1000.0);
            v["scheme"] = json!({"wcsph": {"sound_speed": 1000.0, "artificial_viscosity": {"alpha": 0.1},
                                           "density_diffusion": 0.1}});
            v["probes"] = json!([{"ellipse_axes": {}}, {"pressure_at": {"point": [0.0, 0.0]}},
                                 {"max_speed": {}}, {"drop_shape": {}}]);
        });
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().expect("pool");
        pool.install(|| meniscus::run(&scene, &mut meniscus::Quiet).expect("scene builds"))
    };
    let (a, b) = (run(1), run(2));
    assert!(a.error.is_none() && b.error.is_none(), "{:?}", a.error);
    let json = |r: &meniscus::RunReport| serde_json::to_string(&r.probes).expect("serialisable");
    assert_eq!(json(&a), json(&b), "WCSPH probe series differ between 1 and 2 threads");
    assert_eq!(a.final_frame, b.final_frame);
}
