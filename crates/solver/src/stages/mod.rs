//! Stages shared by every scheme: reordering, walls, neighbour search with the pair cache,
//! free-surface detection.

pub mod free_surface;
pub mod neighbours;
pub mod reorder;
pub mod walls;
