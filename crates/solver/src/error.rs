//! Error types: [`SceneError`] for bad input, [`SolverError`] for runs that go wrong.

use std::fmt::Display;

/// A scene that cannot be run: names the field, the value and the rule it breaks.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SceneError {
    /// A value breaks a rule.
    #[error("scene field `{field}` = {value}: {rule}")]
    Invalid {
        /// Field path, e.g. `bodies[0].shape.circle.radius`.
        field: String,
        /// The offending value as written.
        value: String,
        /// The rule it breaks.
        rule: String,
    },
    /// The JSON does not match the schema (wrong type, unknown field, syntax).
    #[error("scene field `{field}`: {reason}")]
    Parse {
        /// Field path where parsing stopped.
        field: String,
        /// What serde reported.
        reason: String,
    },
    /// The scene file could not be read.
    #[error("cannot read scene file `{path}`: {reason}")]
    Io {
        /// The path.
        path: String,
        /// The operating system's reason.
        reason: String,
    },
}

impl SceneError {
    /// A rule violation of `field` by `value`.
    pub fn new(field: impl Into<String>, value: impl Display, rule: impl Into<String>) -> Self {
        SceneError::Invalid { field: field.into(), value: value.to_string(), rule: rule.into() }
    }

    /// A schema mismatch at `field`.
    pub fn parse(field: impl Into<String>, reason: impl Into<String>) -> Self {
        SceneError::Parse { field: field.into(), reason: reason.into() }
    }
}

/// What tripped a guard.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum Cause {
    /// A position, velocity or pressure became NaN or infinite.
    #[error("non-finite {quantity} at particle {particle}")]
    NonFinite {
        /// `position`, `velocity` or `pressure`.
        quantity: &'static str,
        /// Particle id (index in the initial particle order).
        particle: usize,
    },
    /// A particle left the region around the initial bounding box.
    #[error("particle {particle} escaped to {position:?}")]
    Escape {
        /// Particle id.
        particle: usize,
        /// Its position \[m\].
        position: Vec<f64>,
    },
    /// The pressure Poisson solver did not converge.
    #[error(
        "PPE solver {solver} did not converge: relative residual {residual:.3e} after {iterations} iterations"
    )]
    PpeNoConvergence {
        /// Solver name.
        solver: &'static str,
        /// Relative residual reached.
        residual: f64,
        /// Iterations done.
        iterations: usize,
    },
    /// The PPE matrix is not usable (not positive definite, singular factorisation).
    #[error("PPE solver {solver} failed: {reason}")]
    PpeBreakdown {
        /// Solver name.
        solver: &'static str,
        /// Reason.
        reason: String,
    },
    /// The adaptive time step fell below its floor.
    #[error("time step {dt:.3e} s below the floor {floor:.3e} s")]
    DtFloor {
        /// The step \[s\].
        dt: f64,
        /// The floor \[s\].
        floor: f64,
    },
}

/// A run that went unstable: the stage, step and time where a guard tripped, and why.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("diverged in stage `{stage}` at step {step} (t = {time:.6e} s): {cause}")]
pub struct SolverError {
    /// Stage that tripped (or `guard` for the end-of-step checks).
    pub stage: &'static str,
    /// Step number (1-based: the step being taken).
    pub step: usize,
    /// Time at the start of the step \[s\].
    pub time: f64,
    /// What tripped.
    pub cause: Cause,
}
