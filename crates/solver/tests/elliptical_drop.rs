//! Elliptical-drop acceptance at dx = 0.04 (issue "Projection ISPH solver core"):
//! particle count, y semi-axis error over the history, kinetic-energy drift, and the
//! centre pressure of the tuned preset, all against `meniscus-reference`.

mod common;

use meniscus_reference::elliptical_drop::EllipticalDrop;
use serde_json::json;

struct Errors {
    particles: usize,
    b_max: f64,
    a_max: f64,
    /// The centre pressure over its reference, averaged over the last quarter of the run,
    /// minus 1: the pressure oscillates (at dx = 0.04 its final sample is 1.4 % off and the
    /// last quarter swings to 14 %), so one sample is a draw.
    pc_late: f64,
    ke_drift: f64,
}

/// The larger of `a` and `b`, NaN when either is (a NaN sample must not vanish from a max).
fn sticky_max(a: f64, b: f64) -> f64 {
    if a.is_nan() || b.is_nan() { f64::NAN } else { a.max(b) }
}

fn measure(edit: impl FnOnce(&mut serde_json::Value)) -> Errors {
    let scene = common::drop_scene(|v| {
        v["dx"] = json!(0.04);
        edit(v);
    });
    let report = meniscus::run(&scene, &mut meniscus::Quiet).expect("scene builds");
    assert!(report.error.is_none(), "diverged: {:?}", report.error);
    let probes = &report.probes;
    let exact =
        EllipticalDrop::new(1.0, 100.0, 1000.0).expect("valid").states_at(&probes.t).expect("integrates");
    let rel_max = |name: &str, pick: fn(&meniscus_reference::elliptical_drop::DropState) -> f64| {
        let series = probes.get("ellipse_axes", name).expect("ellipse probe");
        series.iter().zip(&exact).map(|(v, e)| ((v - pick(e)) / pick(e)).abs()).fold(0.0, sticky_max)
    };
    let p = probes.get("pressure_at", "p").expect("pressure probe");
    let e = probes.get("kinetic_energy", "e").expect("energy probe");
    let t = &probes.t;
    let late_from = t[t.len() - 1] * 0.75;
    let late: Vec<f64> = t
        .iter()
        .zip(p.iter().zip(&exact))
        .filter(|(ti, _)| **ti >= late_from)
        .map(|(_, (p, e))| p / e.pc)
        .collect();
    Errors {
        particles: report.summary.particles,
        b_max: rel_max("b_moment", |s| s.b),
        a_max: rel_max("a_moment", |s| s.a),
        pc_late: (late.iter().sum::<f64>() / late.len() as f64 - 1.0).abs(),
        ke_drift: e.iter().map(|v| ((v - e[0]) / e[0]).abs()).fold(0.0, sticky_max),
    }
}

#[test]
fn paper_preset_meets_the_dx_0_04_acceptance() {
    let e = measure(|_| {});
    assert_eq!(e.particles, 1976);
    assert!(e.b_max <= 0.02, "b error {:.4}", e.b_max);
    assert!(e.a_max <= 0.02, "a error {:.4}", e.a_max);
    assert!(e.ke_drift <= 0.02, "kinetic energy drift {:.4}", e.ke_drift);
}

#[test]
fn tuned_preset_is_accurate_in_pressure_too() {
    let e = measure(|v| {
        v["scheme"]["isph"]["divergence"] = json!("corrected");
        v["scheme"]["isph"]["shifting"] = json!({"fickian": {"coefficient": 2.0}});
    });
    assert!(e.b_max <= 0.02, "b error {:.4}", e.b_max);
    assert!(e.ke_drift <= 0.02, "kinetic energy drift {:.4}", e.ke_drift);
    assert!(e.pc_late <= 0.05, "centre pressure error over the last quarter {:.4}", e.pc_late);
}
