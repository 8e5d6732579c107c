//! Analytical and semi-analytical reference solutions for the Meniscus validation cases.
//!
//! Every function takes its physical parameters explicitly (SI units, no case constants
//! baked in), validates them and returns a typed [`ReferenceError`] instead of panicking.
//! The formulas, their sources and the published reference values are collected in
//! `REFERENCES.md` (section numbers are quoted in each item's documentation).
//!
//! | module | reference |
//! |---|---|
//! | [`elliptical_drop`] | inviscid elliptical drop, Monaghan 1994 / Colagrossi 2005 (§1) |
//! | [`rotating_square`] | initial pressure of the rotating square patch, Colagrossi 2005 (§2) |
//! | [`poiseuille`] | plane Poiseuille flow, steady and start-up, Morris et al. 1997 (§3a, §3b) |
//! | [`entrance_length`] | laminar development length, Durst et al. 2005 (§3c) |
//! | [`entrance_flow`] | developing channel flow from a uniform inlet, Bodoia & Osterle 1961 (§3c) |
//! | [`pipe`] | Hagen–Poiseuille pipe flow, steady and start-up (§3d) |
//! | [`capillarity`] | Laplace pressure, capillary oscillation and damping of drops (§4) |
//! | [`impact`] | drop impact on a wall: early spreading, maximum spread correlations (CASES.md) |
//! | [`taylor_green`] | 2D periodic Taylor–Green vortex |

pub mod capillarity;
pub mod elliptical_drop;
pub mod entrance_flow;
pub mod entrance_length;
mod error;
pub mod impact;
pub mod pipe;
pub mod poiseuille;
pub mod rotating_square;
pub mod taylor_green;

pub use error::ReferenceError;

/// Result type of this crate.
pub type Result<T> = std::result::Result<T, ReferenceError>;
