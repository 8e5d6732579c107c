//! Stages shared by every scheme: neighbour search with the pair cache, free-surface
//! detection.

pub mod free_surface;
pub mod neighbours;
