//! # Meniscus solver
//!
//! Particle methods for viscous free-surface and channel flows: projection ISPH
//! (Qiu 2013, Acta Phys. Sin. 62:124702, with the errata of CASES.md) and weakly
//! compressible SPH ([`wcsph`]), dimension-generic
//! (`const D: usize`) over `nalgebra::SVector<f64, D>`.
//!
//! A [`scene::Scene`] (JSON) describes a run; [`run::AnySimulation`] builds the particles
//! and the step's stage list from it (a stage the scene does not need is not built) and
//! steps it to the end time, returning a [`run::RunReport`] with `summary.json` and
//! `probes.json` content. Units are SI throughout.

pub mod error;
pub mod isph;
pub mod kernel;
pub mod krylov;
pub mod neighbours;
pub mod ppe;
pub mod probes;
pub mod profile;
pub mod run;
pub mod scene;
pub mod stage;
pub mod stages;
pub mod state;
pub mod two_level;
pub mod warm_pool;
pub mod wcsph;

pub use error::{Cause, SceneError, SolverError};
pub use probes::ProbeRecord;
pub use run::{AnySimulation, Frame, Observer, Quiet, RunReport, Status, Summary, run};
pub use scene::Scene;
