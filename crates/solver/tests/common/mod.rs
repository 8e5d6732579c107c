//! Shared helpers of the integration tests.
#![allow(dead_code)]

use meniscus::Scene;

/// The DESIGN.md elliptical-drop scene (the contract's fixed point).
pub const DROP: &str = include_str!("../../../../validation/scenes/elliptical_drop.json");

/// The drop scene with `edit` applied to its JSON value.
pub fn drop_scene(edit: impl FnOnce(&mut serde_json::Value)) -> Scene {
    let mut v: serde_json::Value = serde_json::from_str(DROP).expect("scene JSON");
    edit(&mut v);
    Scene::from_json(&v.to_string()).expect("valid scene")
}

/// The `poiseuille_periodic` case file (CASES.md): its `scene` is the quick tier's channel.
const PERIODIC_CHANNEL_CASE: &str = include_str!("../../../../validation/poiseuille_periodic.json");

/// The periodic channel scene of `validation/poiseuille_periodic.json` (Re = 40, D/36) with
/// `edit` applied to its JSON value.
pub fn periodic_channel_scene(edit: impl FnOnce(&mut serde_json::Value)) -> Scene {
    let case: serde_json::Value = serde_json::from_str(PERIODIC_CHANNEL_CASE).expect("case JSON");
    let mut v = case["scene"].clone();
    edit(&mut v);
    Scene::from_json(&v.to_string()).expect("valid scene")
}
