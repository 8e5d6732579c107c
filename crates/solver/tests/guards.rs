//! Runs that go wrong stop with a diagnosis, keep their probes, and never panic.

mod common;

use meniscus::Cause;
use serde_json::json;

#[test]
fn a_time_step_far_beyond_the_cfl_limit_diverges_with_a_named_cause() {
    let scene = common::drop_scene(|v| {
        v["dx"] = json!(0.04);
        v["time"] = json!({"end": 0.1, "step": {"fixed": 2e-2}});
        v["output"]["probe_every"] = json!(1);
    });
    let report = meniscus::run(&scene, &mut meniscus::Quiet).expect("scene builds");
    let err = report.error.as_ref().expect("the run must diverge");
    assert_eq!(report.summary.status, meniscus::Status::Diverged);
    assert!(report.summary.error.as_deref().is_some_and(|m| m.contains("step")));
    assert!(err.step >= 1 && err.time < 0.1);
    assert!(
        matches!(
            err.cause,
            Cause::Escape { .. }
                | Cause::Overstep { .. }
                | Cause::NonFinite { .. }
                | Cause::Clumping { .. }
                | Cause::PpeNoConvergence { .. }
        ),
        "{err}"
    );
    // The message names the step, the time, the stage and the particle.
    let msg = err.to_string();
    assert!(msg.starts_with(&format!("diverged at step {} (t = ", err.step)), "{msg}");
    assert!(msg.contains(&format!("in stage `{}`", err.stage)), "{msg}");
    if err.stage == "guard" {
        assert!(msg.contains("particle "), "{msg}");
    }
    // The last good state is the start of the failing step: finite, one particle per id.
    let good = report.last_good.as_ref().expect("a diverged run keeps its last good state");
    assert_eq!(good.step, report.summary.steps);
    assert_eq!(good.step + 1, err.step);
    assert!((good.time - err.time).abs() <= 1e-15);
    assert_eq!(good.x.len(), report.summary.particles);
    assert!(good.x.iter().chain(&good.u).flatten().chain(&good.p).all(|v| v.is_finite()));
    // The probes recorded before the divergence are kept, one sample per finished step.
    assert_eq!(report.probes.t.len(), report.summary.steps + 1);
    assert!(report.probes.get("kinetic_energy", "e").is_some_and(|e| e.iter().all(|v| v.is_finite())));
}

#[test]
fn adaptive_time_step_respects_qiu_limits_and_reaches_the_end() {
    let scene = common::drop_scene(|v| {
        v["dx"] = json!(0.04);
        v["time"] = json!({"end": 0.008, "step": {"adaptive": {"max": 1e-4}}});
    });
    let report = meniscus::run(&scene, &mut meniscus::Quiet).expect("scene builds");
    assert!(report.error.is_none(), "{:?}", report.error);
    assert!(report.last_good.is_none(), "only a diverged run has a last good state");
    assert!((report.summary.t_end - 0.008).abs() < 1e-12);
    // dt <= 0.2 h / u_max with u_max >= 100 m/s gives at least 0.008 / 1.2e-4 steps.
    assert!(report.summary.steps >= 67, "{} steps", report.summary.steps);
    let b = report.probes.get("ellipse_axes", "b_moment").expect("probe");
    assert!((b[b.len() - 1] - 1.9993).abs() < 0.04, "b = {}", b[b.len() - 1]);
}

#[test]
fn a_fractional_last_step_is_shorter_never_longer() {
    let scene = common::drop_scene(|v| {
        v["dx"] = json!(0.04);
        v["time"] = json!({"end": 5e-5, "step": {"fixed": 2e-5}});
    });
    let report = meniscus::run(&scene, &mut meniscus::Quiet).expect("scene builds");
    assert!(report.error.is_none());
    assert_eq!(report.summary.steps, 3);
    assert!((report.summary.t_end - 5e-5).abs() < 1e-18);
}

#[test]
fn a_fast_rigid_translation_is_not_an_overstep() {
    // 100 m/s for 2 ms a step: each particle moves 0.2 m, beyond the 0.12 m support, but
    // all together; the overstep guard looks at neighbours' relative motion only.
    let scene = common::drop_scene(|v| {
        v["dx"] = json!(0.04);
        v["bodies"][0]["velocity"] =
            json!({"affine": {"gradient": [[0.0, 0.0], [0.0, 0.0]], "offset": [100.0, 0.0]}});
        v["bodies"][0]["pressure"] = json!("zero");
        v["time"] = json!({"end": 0.01, "step": {"fixed": 2e-3}});
    });
    let report = meniscus::run(&scene, &mut meniscus::Quiet).expect("scene builds");
    assert!(report.error.is_none(), "{:?}", report.error);
    assert_eq!(report.summary.steps, 5);
}

#[test]
fn an_overstep_next_to_mirror_walls_is_a_typed_error() {
    // Mirror particles are neighbours too; the guard compares fluid neighbours only.
    let v = json!({
        "name": "channel", "dimension": 2, "dx": 0.01,
        "kernel": { "kind": "cubic_spline", "h_over_dx": 1.5 },
        "fluid": { "density": 1000.0, "viscosity": 1e-3 },
        "body_force": [1.0, 0.0],
        "bodies": [ { "role": "fluid", "shape": { "rectangle": { "min": [0.0, 0.0], "max": [0.1, 0.2] } } } ],
        "boundaries": {
            "periodic": [ { "axis": 0, "min": 0.0, "max": 0.1 } ],
            "walls": [ { "axis": 1, "position": 0.0, "fluid_side": "above" },
                       { "axis": 1, "position": 0.2, "fluid_side": "below" } ]
        },
        "scheme": { "isph": { "ppe": { "solver": "bicgstab", "tolerance": 1e-6, "max_iterations": 2000 },
                              "free_surface_threshold": 1.5 } },
        "time": { "end": 50.0, "step": { "fixed": 10.0 } },
        "probes": [ { "kinetic_energy": {} } ]
    });
    let scene = meniscus::Scene::from_json(&v.to_string()).expect("valid scene");
    let report = meniscus::run(&scene, &mut meniscus::Quiet).expect("scene builds");
    let err = report.error.as_ref().expect("the run must diverge");
    assert!(matches!(err.cause, Cause::Overstep { .. }), "{err}");
}

#[test]
fn an_adaptive_step_below_its_floor_is_a_typed_error_at_the_first_step() {
    // A strain of 1e10 1/s on a 1 m drop: the CFL step 0.2 h/u_max ≈ 6e-13 s is below the
    // floor 1e-9 × t_end = 1e-9 s.
    let scene = common::drop_scene(|v| {
        v["dx"] = json!(0.1);
        v["bodies"][0]["velocity"]["affine"]["gradient"] = json!([[-1e10, 0.0], [0.0, 1e10]]);
        v["time"] = json!({"end": 1.0, "step": {"adaptive": {"max": 1e-4}}});
    });
    let report = meniscus::run(&scene, &mut meniscus::Quiet).expect("scene builds");
    let err = report.error.as_ref().expect("the step is below its floor");
    assert_eq!((err.stage, err.step, err.time), ("time_step", 1, 0.0));
    let Cause::DtFloor { dt, floor } = err.cause else { panic!("{err}") };
    assert!(dt < floor && (floor - 1e-9).abs() < 1e-24, "{err}");
    assert_eq!(report.summary.status, meniscus::Status::Diverged);
    assert_eq!(report.summary.steps, 0);
    let msg = err.to_string();
    assert!(msg.contains("time_step") && msg.contains("floor"), "{msg}");
    assert!(report.last_good.is_some(), "the initial state is the last good state");
}

#[test]
fn a_ppe_that_does_not_converge_is_a_typed_error_naming_the_solver_and_residual() {
    // One BiCGSTAB iteration cannot reach a relative residual of 1e-12.
    let scene = common::drop_scene(|v| {
        v["dx"] = json!(0.1);
        v["scheme"]["isph"]["ppe"] = json!({"solver": "bicgstab", "tolerance": 1e-12, "max_iterations": 1});
    });
    let report = meniscus::run(&scene, &mut meniscus::Quiet).expect("scene builds");
    let err = report.error.as_ref().expect("the PPE cannot converge");
    assert_eq!(err.step, 1, "{err}");
    let Cause::PpeNoConvergence { solver, residual, iterations } = &err.cause else { panic!("{err}") };
    assert_eq!((*solver, *iterations), ("bicgstab", 1), "{err}");
    assert!(residual.is_finite() && *residual > 1e-12, "{err}");
    let msg = err.to_string();
    assert!(msg.contains(err.stage) && msg.contains("max_iterations"), "{msg}");
    assert!(report.last_good.is_some());
}
