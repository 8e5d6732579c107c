//! # Meniscus validation harness
//!
//! A *case* (`validation/<case>.json`, [`case`]) is data: a scene template, a sweep
//! (spacings per tier and named presets, each a JSON merge patch on the template), the
//! analytical reference, the metrics to tabulate and the acceptance checks. The harness
//! expands a case into runs ([`sweep`]), runs them in-process through the `meniscus`
//! solver ([`runner`], which the stability envelope and the work-precision study use too)
//! with every finished run cached atomically ([`cache`]), computes metrics against
//! `meniscus-reference` ([`metrics`]), fits observed orders ([`fit`]), evaluates the checks
//! ([`checks`]) and writes `reports/<case>/results.json` and `reports/summary.json`
//! ([`results`], DESIGN.md "Results files"). Plotting and HTML ([`report`]) is a separate
//! pass that reads only JSON, so `cargo xtask report` re-renders without running anything;
//! it also writes `reports/summary.md`, and with a previous `reports/` directory as a
//! baseline ([`baseline`]) marks what got better or worse beyond a stated noise band.
//!
//! The entry points used by `cargo xtask` are [`validate::validate`], [`stability::run`],
//! [`work_precision::run`] and [`report::render`].

pub mod baseline;
pub mod cache;
pub mod case;
pub mod checks;
pub mod error;
pub mod fit;
pub mod io;
pub mod metrics;
pub mod numbers;
pub mod patch;
pub mod progress;
pub mod provenance;
pub mod report;
pub mod results;
pub mod runner;
pub mod slurm;
pub mod snapshots;
pub mod stability;
pub mod sweep;
pub mod tier;
pub mod validate;
pub mod work_precision;

pub use case::Case;
pub use error::{HarnessError, Result};
pub use tier::Tier;
pub use validate::{Outcome, ValidateOptions, validate};
