//! # Meniscus solver
//!
//! Particle methods for viscous free-surface and channel flows: projection ISPH
//! (Qiu 2013, Acta Phys. Sin. 62:124702, with the errata of CASES.md) and weakly
//! compressible SPH ([`wcsph`]), dimension-generic
//! (`const D: usize`) over `nalgebra::SVector<f64, D>`.
//!
//! A [`scene::Scene`] (JSON) describes a run; [`run::AnySimulation`] builds it through its
//! scheme ([`scheme::Scheme`]: the particles, the scheme's own data and the step's stage
//! list, a stage the scene does not need not built; [`registry`] maps the scene's scheme
//! to its implementation) and steps it to the end time, returning a [`run::RunReport`]
//! with `summary.json` and `probes.json` content. Units are SI throughout.

pub mod boundary_map;
pub mod error;
pub mod fields;
pub mod frame;
pub mod guard;
pub mod isph;
pub mod kernel;
pub mod linalg;
pub mod mps;
pub mod neighbours;
pub mod operators;
pub mod otm;
pub mod ppe;
pub mod probes;
pub mod profile;
pub mod registry;
pub mod run;
pub mod scene;
pub mod scheme;
pub mod setup;
pub mod stage;
pub mod stages;
pub mod state;
pub mod steady;
pub mod time_step;
pub mod warm_pool;
pub mod wcsph;

pub use error::{Cause, SceneError, SolverError};
pub use frame::Frame;
pub use probes::ProbeRecord;
pub use run::{AnySimulation, Observer, Quiet, RunReport, Status, Summary, run};
pub use scene::Scene;

/// The solver's fingerprint: SHA-256 (hex) of its sources, manifest, the workspace's
/// `Cargo.toml` and `Cargo.lock` and the compiler's version (`build.rs`). Two builds with
/// the same fingerprint (and no other compiler flags) give the same runs.
pub const SOLVER_FINGERPRINT: &str = env!("MENISCUS_SOLVER_FINGERPRINT");

/// `<package version> (solver <fingerprint>)`: what `meniscus --version` prints.
pub const VERSION: &str = env!("MENISCUS_VERSION");
