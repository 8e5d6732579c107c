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
///
/// Every variant names the particle (by its id: the index in the initial particle order,
/// as in the VTK frames) and, for the end-of-step guards, how many other particles tripped
/// the same check, so that a user can find the spot in `frames/last_good.vtu`.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum Cause {
    /// A position, velocity or pressure became NaN or infinite.
    #[error("particle {particle} has a non-finite {quantity}{}", others_note(*others))]
    NonFinite {
        /// `position`, `velocity` or `pressure`.
        quantity: &'static str,
        /// Particle id (index in the initial particle order).
        particle: usize,
        /// Number of other particles with a non-finite value at the same step.
        others: usize,
    },
    /// A particle left the region around the initial bounding box.
    #[error(
        "particle {particle} escaped to {} m, outside the guard box {} .. {} m (the initial bounding box enlarged by 4 times its size, or by twice the distance the fastest initial particle could have coasted){}",
        point(position), point(lo), point(hi), others_note(*others)
    )]
    Escape {
        /// Particle id.
        particle: usize,
        /// Its position \[m\].
        position: Vec<f64>,
        /// Lower corner of the guard box \[m\].
        lo: Vec<f64>,
        /// Upper corner of the guard box \[m\].
        hi: Vec<f64>,
        /// Number of other particles outside the box at the same step.
        others: usize,
    },
    /// Two fluid neighbours move farther than the kernel support relative to each other in one
    /// step: the neighbour lists cannot follow them (a fixed step far beyond the CFL limit,
    /// or velocities blowing up).
    #[error(
        "particle {particle} at {} m and its neighbour {neighbour} move at {speed:.4e} m/s relative to each other: {:.4e} m in the step of {dt:.4e} s, farther than the kernel support {support:.4e} m, so the neighbour lists cannot follow them (if the flow is that fast, lower time.step or use an adaptive step; velocities that grew over a few steps point to an instability instead, which a shorter step need not cure: the probes up to this step show it){}",
        point(position), speed * dt, others_note(*others)
    )]
    Overstep {
        /// Particle id.
        particle: usize,
        /// Its position \[m\].
        position: Vec<f64>,
        /// Id of the fluid neighbour it moves fastest against.
        neighbour: usize,
        /// Their relative speed \[m/s\].
        speed: f64,
        /// The step \[s\].
        dt: f64,
        /// The kernel support radius \[m\].
        support: f64,
        /// Number of other particles with such a neighbour at the same step.
        others: usize,
    },
    /// A fluid particle has far more neighbours than a particle of the initial lattice:
    /// particles clumped together (pressure collapse, particle penetration).
    #[error(
        "particle {particle} at {} m has {count} neighbours, more than the limit {limit} (4 times the {bulk} of a particle of the initial lattice): particles are clumping{}",
        point(position), others_note(*others)
    )]
    Clumping {
        /// Particle id.
        particle: usize,
        /// Its position \[m\].
        position: Vec<f64>,
        /// Its neighbour count (particles within the kernel support).
        count: usize,
        /// The largest count allowed.
        limit: usize,
        /// Neighbour count of a particle inside the initial lattice.
        bulk: usize,
        /// Number of other particles over the limit at the same step.
        others: usize,
    },
    /// The pressure Poisson solver did not converge.
    #[error(
        "PPE solver {solver} did not converge: relative residual {residual:.3e} after {iterations} iterations (scheme.isph.ppe.max_iterations); a solver that needed far fewer iterations in earlier steps points to a degenerated particle distribution"
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
    /// An MPS inlet found too few ghost particles to refill the gap behind its pushing
    /// plate (the outflow lagged the inflow by the whole reserve: the fluid compressed).
    #[error(
        "the inlet needs {needed} ghost particles for its next column but {ghosts} are left: the outflow lags the inflow by the whole reserve ({reserve} columns), so the fluid in the channel has compressed"
    )]
    GhostsExhausted {
        /// Particles of one inlet column.
        needed: usize,
        /// Ghosts left.
        ghosts: usize,
        /// Columns of ghosts in reserve at the start.
        reserve: usize,
    },
    /// An OTM body failed: a material point left its nodes' hull, or the nodal map folded
    /// its volume (`crate::otm::step::OtmError`, as text).
    #[error("material point {point}: {reason}")]
    Otm {
        /// The material point's index.
        point: usize,
        /// What failed.
        reason: String,
    },
    /// The adaptive time step fell below its floor.
    #[error(
        "time step {dt:.3e} s fell below the floor {floor:.3e} s (1e-9 of time.end): the flow is too fast or too viscous for the adaptive step"
    )]
    DtFloor {
        /// The step \[s\].
        dt: f64,
        /// The floor \[s\].
        floor: f64,
    },
}

/// `(x, y)` with four significant digits.
fn point(v: &[f64]) -> String {
    let parts: Vec<String> = v.iter().map(|x| format!("{x:.4e}")).collect();
    format!("({})", parts.join(", "))
}

/// ` (and N other particles)` when N > 0.
fn others_note(others: usize) -> String {
    match others {
        0 => String::new(),
        1 => " (and 1 other particle)".to_string(),
        n => format!(" (and {n} other particles)"),
    }
}

/// A run that went unstable: the stage, step and time where a guard tripped, and why.
///
/// Displayed as `diverged at step 812 (t = 4.210e-3 s) in stage `guard`: particle 5123
/// escaped to …`; the step is the one being taken, the time the time at its start.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("diverged at step {step} (t = {time:.4e} s) in stage `{stage}`: {cause}")]
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
