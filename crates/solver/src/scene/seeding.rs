//! The fluid particles of a scene at t = 0, as both the validation (the rules that need
//! them) and the schemes' set-up compute them: every body seeded ([`lattice::seed_body`]),
//! wrapped into the periodic axes, then jittered where a body asks for it.

use super::lattice;
use super::schema::{Role, Scene};
use crate::neighbours::Domain;
use nalgebra::SVector;

/// The seeded fluid particles of a scene.
#[derive(Debug, Clone, Default)]
pub struct Seeds<const D: usize> {
    /// Positions \[m\].
    pub x: Vec<SVector<f64, D>>,
    /// Velocities \[m/s\].
    pub u: Vec<SVector<f64, D>>,
    /// Pressures \[Pa\].
    pub p: Vec<f64>,
    /// Index of each body's first particle.
    pub body_start: Vec<usize>,
}

impl<const D: usize> Seeds<D> {
    /// The body of particle `a`.
    pub fn body_of(&self, a: usize) -> usize {
        self.body_start.partition_point(|&s| s <= a).saturating_sub(1)
    }
}

/// The periodicity of `scene`.
pub fn domain<const D: usize>(scene: &Scene) -> Domain<D> {
    let mut domain = Domain::<D>::default();
    for axis in &scene.boundaries.periodic {
        domain.periodic[axis.axis] = Some((axis.min, axis.max));
    }
    domain
}

/// Every fluid body of `scene` seeded (lattice or rings) and wrapped into the periodic axes,
/// not yet jittered. A wall body holds no fluid: its range in `body_start` is empty.
pub fn seed_bodies<const D: usize>(scene: &Scene) -> Seeds<D> {
    let g = SVector::<f64, D>::from_fn(|i, _| scene.body_force.get(i).copied().unwrap_or(0.0));
    let domain = domain::<D>(scene);
    let mut seeds = Seeds::<D>::default();
    for body in &scene.bodies {
        seeds.body_start.push(seeds.x.len());
        if body.role == Role::Wall {
            continue;
        }
        for seed in lattice::seed_body::<D>(body, scene.dx, scene.fluid.density, &g) {
            let mut x = seed.x;
            domain.wrap(&mut x);
            seeds.x.push(x);
            seeds.u.push(seed.u);
            seeds.p.push(seed.p);
        }
    }
    seeds
}

/// The particles of the wall bodies (`role: wall`), in body order, wrapped into the
/// periodic axes: the dummy wall particles (Adami, Hu & Adams 2012) of a wall of any shape.
/// With each particle, the index of its body.
pub fn seed_walls<const D: usize>(scene: &Scene) -> Vec<(SVector<f64, D>, usize)> {
    let domain = domain::<D>(scene);
    let mut out = Vec::new();
    for (i, body) in scene.bodies.iter().enumerate().filter(|(_, b)| b.role == Role::Wall) {
        for mut x in lattice::seed_points::<D>(body, scene.dx) {
            domain.wrap(&mut x);
            out.push((x, i));
        }
    }
    out
}

/// Applies each body's `jitter` (if any) to its particles and wraps them again.
pub fn jitter<const D: usize>(scene: &Scene, seeds: &mut Seeds<D>) {
    let domain = domain::<D>(scene);
    let n = seeds.x.len();
    for (i, body) in scene.bodies.iter().enumerate() {
        if let Some(jitter) = &body.jitter {
            let end = seeds.body_start.get(i + 1).copied().unwrap_or(n);
            lattice::apply_jitter(&mut seeds.x[seeds.body_start[i]..end], scene.dx, jitter);
        }
    }
    for x in &mut seeds.x {
        domain.wrap(x);
    }
}
