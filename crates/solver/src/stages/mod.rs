//! Stages shared by every scheme: reordering, walls (mirror and dummy particles), open
//! boundaries (inflow/outflow buffers), neighbour search with the pair cache, free-surface
//! detection, surface tension (forces, or the Young–Laplace free-surface pressure), the
//! free-surface pressure extrapolated to the surface.

pub mod boundary_links;
pub mod dummy;
pub mod free_surface;
pub mod neighbours;
pub mod open_boundary;
pub mod reorder;
pub mod shifting;
pub mod surface_extrapolation;
pub mod surface_tension;
pub mod walls;
pub mod young_laplace;
