//! A scheme that does nothing new is one module: here a test-only scheme wrapping the
//! weakly compressible one. It implements `Scheme` (its build, its own data, its time-step
//! rule) and runs through the same driver with no other edit; to make a scene select it,
//! `registry::compose` gets one line (ARCHITECTURE.md, "Adding a scheme").

mod common;

use meniscus::kernel::{Kernel, Scaled};
use meniscus::run::Simulation;
use meniscus::scheme::{Adaptive, Composed, Scheme};
use meniscus::state::State;
use meniscus::wcsph::{WcFields, Wcsph};
use meniscus::{Quiet, Scene, SceneError};
use serde_json::json;

/// WCSPH under another name.
#[derive(Debug)]
struct Wrapped(Wcsph);

impl<const D: usize> Scheme<D> for Wrapped {
    type Own = WcFields<D>;

    fn build<K: Kernel>(scene: &Scene, kernel: Scaled<K, D>) -> Result<Composed<D, Self>, SceneError> {
        let Composed { scheme, state, own, stages } = <Wcsph as Scheme<D>>::build(scene, kernel)?;
        Ok(Composed { scheme: Wrapped(scheme), state, own, stages })
    }

    fn stable_step(&self, rule: Adaptive, state: &State<D>, own: &WcFields<D>) -> f64 {
        self.0.stable_step(rule, state, own)
    }
}

#[test]
fn a_wrapped_scheme_runs_through_the_driver_as_the_scheme_it_wraps() {
    let scene = common::drop_scene(|v| {
        v["dx"] = json!(0.05);
        v["scheme"] =
            json!({"wcsph": {"sound_speed": 1000.0, "artificial_viscosity": {"alpha": 0.1, "beta": 0.0}}});
        v["time"] = json!({"end": 2e-4, "step": {"adaptive": {"cfl": 0.25, "viscous": 0.125, "max": 1e-4}}});
    });
    let reference = meniscus::run(&scene, &mut Quiet).expect("the scene builds");
    let mut sim = Simulation::<2>::with_scheme::<Wrapped>(&scene).expect("the wrapped scheme builds");
    assert_eq!(sim.stage_names(), meniscus::AnySimulation::new(&scene).expect("builds").stage_names());
    let wrapped = sim.run(&mut Quiet);
    assert!(wrapped.error.is_none() && reference.error.is_none());
    assert!(wrapped.summary.steps > 5, "{} steps", wrapped.summary.steps);
    assert_eq!(wrapped.summary.steps, reference.summary.steps);
    assert_eq!(wrapped.probes, reference.probes, "the same probes, bit for bit");
    assert_eq!(wrapped.final_frame, reference.final_frame);
    // The frames show the scheme's own declared fields.
    let names: Vec<&str> = wrapped.final_frame.scalars.iter().map(|(n, _)| n.as_str()).collect();
    assert_eq!(names, ["div_r", "density"]);
}
