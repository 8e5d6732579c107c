//! Scene files: schema ([`schema`]), every scene rule ([`validate()`], including those on
//! the seeded particles) and particle generation on the cell-centred lattice
//! ([`lattice`], [`seeding`]).

pub mod lattice;
pub mod schema;
pub mod seeding;
mod validate;
mod validate_boundaries;
mod validate_seeds;

pub use schema::*;
pub use validate::validate;

use crate::error::SceneError;
use std::path::Path;

impl Scene {
    /// Parses a scene from JSON text and checks every value.
    ///
    /// Errors name the field path (`fluid.density`), the value and the rule; unknown
    /// fields and wrong types are errors too.
    pub fn from_json(text: &str) -> Result<Scene, SceneError> {
        // serde would also read a struct from an array (`[name, dimension, ...]`), with
        // errors naming `[0]`: a scene is an object.
        let start = text.trim_start().chars().next();
        if start.is_some_and(|c| c != '{') {
            return Err(SceneError::parse(
                "scene",
                "a scene file must be a JSON object `{ \"name\": ..., ... }`",
            ));
        }
        let de = &mut serde_json::Deserializer::from_str(text);
        let scene: Scene = serde_path_to_error::deserialize(de).map_err(|e| {
            let path = e.path().to_string();
            let field = if path.is_empty() || path == "." { "scene".to_string() } else { path };
            SceneError::parse(field, e.into_inner().to_string())
        })?;
        validate(&scene)?;
        Ok(scene)
    }

    /// Reads and parses a scene file (see [`Scene::from_json`]).
    pub fn from_path(path: &Path) -> Result<Scene, SceneError> {
        let text = std::fs::read_to_string(path)
            .map_err(|e| SceneError::Io { path: path.display().to_string(), reason: e.to_string() })?;
        Scene::from_json(&text)
    }

    /// Smoothing length h = h_over_dx · dx \[m\].
    pub fn h(&self) -> f64 {
        self.kernel.h_over_dx * self.dx
    }

    /// Whether the scene has walls: `boundaries.walls` planes or wall bodies (`role: wall`,
    /// always dummy particles).
    pub fn has_walls(&self) -> bool {
        !self.boundaries.walls.is_empty() || self.bodies.iter().any(|b| b.role == Role::Wall)
    }
}
