//! Project tasks as a library: what the `cargo xtask` binary runs that tests call too.
//!
//! [`deps`] builds the module graph of a crate from its sources and finds import cycles
//! (`cargo xtask deps`); the harness's structure test calls it on `crates/harness/src`.

pub mod deps;
