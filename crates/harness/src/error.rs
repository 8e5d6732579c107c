//! The harness error type.

use std::path::PathBuf;

/// Why the harness could not do its job (a failed *check* is not an error: it is a result).
#[derive(Debug, thiserror::Error)]
pub enum HarnessError {
    /// Reading or writing a file failed.
    #[error("{}: {source}", path.display())]
    Io {
        /// The file or directory.
        path: PathBuf,
        /// The I/O error.
        #[source]
        source: std::io::Error,
    },
    /// A JSON file did not parse or did not match its schema.
    #[error("{}: {source}", path.display())]
    Json {
        /// The file.
        path: PathBuf,
        /// The parse error.
        #[source]
        source: serde_json::Error,
    },
    /// A case file is inconsistent (a check names no metric, an empty sweep, ...).
    #[error("case `{case}`: {message}")]
    Case {
        /// Case name.
        case: String,
        /// What is wrong.
        message: String,
    },
    /// The effective scene of a run was rejected by the solver.
    #[error("case `{case}`, run `{run}`: invalid scene: {source}")]
    Scene {
        /// Case name.
        case: String,
        /// Run slug.
        run: String,
        /// The solver's scene error.
        #[source]
        source: meniscus::SceneError,
    },
    /// The analytical reference could not be evaluated.
    #[error("case `{case}`: reference: {source}")]
    Reference {
        /// Case name.
        case: String,
        /// The reference crate's error.
        #[source]
        source: meniscus_reference::ReferenceError,
    },
    /// The Slurm executor could not submit or follow its runs (see [`crate::slurm`]).
    #[error("slurm: {message}")]
    Slurm {
        /// What went wrong, naming the option, command or task.
        message: String,
    },
    /// A plot could not be drawn.
    #[error("plot {file}: {message}")]
    Plot {
        /// Figure file name.
        file: String,
        /// The backend's message.
        message: String,
    },
    /// No case matched the names asked for.
    #[error("unknown case `{0}` (no validation/{0}.json)")]
    UnknownCase(String),
}

/// Result type of the harness.
pub type Result<T> = std::result::Result<T, HarnessError>;

impl HarnessError {
    /// Shorthand for a case-file error.
    pub fn case(case: &str, message: impl Into<String>) -> Self {
        HarnessError::Case { case: case.to_string(), message: message.into() }
    }
}
