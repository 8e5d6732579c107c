//! Shared fixtures for the criterion benches: the elliptical-drop scene at a given spacing.

use meniscus::Scene;

/// The DESIGN.md elliptical-drop scene at spacing `dx`, ending after `steps` steps.
pub fn drop_scene(dx: f64, steps: usize) -> Scene {
    let text = include_str!("../../validation/scenes/elliptical_drop.json");
    let mut scene = Scene::from_json(text).expect("the committed scene is valid");
    scene.dx = dx;
    if let meniscus::scene::TimeStep::Fixed(dt) = scene.time.step {
        scene.time.end = dt * steps as f64;
    }
    scene
}
