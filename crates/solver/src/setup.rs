//! The particles of a scene at t = 0, as the particle schemes (ISPH, WCSPH) start from
//! them: the bodies seeded on the lattice (or rings) and jittered, positions wrapped into
//! periodic axes, the open boundaries' buffers, dummy wall layers; and the shared
//! [`State`] around them.

use crate::error::SceneError;
use crate::neighbours::Domain;
use crate::scene::{Role, Scene, WallModel, lattice};
use crate::stages::dummy::dummy_layers;
use crate::stages::open_boundary::{OpenSetup, Openings};
use crate::state::{Particles, State, Vector};

/// The initial state of `scene` for a kernel of `support` \[m\] and smoothing length `h`
/// \[m\], and its open boundaries when it has an inflow and an outflow.
pub fn particle_state<const D: usize>(
    scene: &Scene,
    h: f64,
    support: f64,
) -> Result<(State<D>, Option<OpenSetup>), SceneError> {
    let g = Vector::<D>::from_fn(|i, _| scene.body_force.get(i).copied().unwrap_or(0.0));
    let mut particles = Particles::<D>::default();
    let mut body_start = Vec::with_capacity(scene.bodies.len());
    for (i, body) in scene.bodies.iter().enumerate() {
        body_start.push(particles.x.len());
        if body.role == Role::Wall {
            return Err(SceneError::new(
                format!("bodies[{i}].role"),
                "wall",
                "wall bodies are not supported yet by the ISPH runner",
            ));
        }
        for seed in lattice::seed_body::<D>(body, scene.dx, scene.fluid.density, &g) {
            particles.fluid += 1;
            particles.id.push(particles.x.len() as u32);
            particles.x.push(seed.x);
            particles.u.push(seed.u);
            particles.p.push(seed.p);
        }
    }
    if particles.is_empty() {
        return Err(SceneError::new("bodies", scene.bodies.len(), "hold no particle"));
    }
    for (i, wall) in scene.boundaries.walls.iter().enumerate() {
        let side = if wall.fluid_side == crate::scene::Side::Above { 1.0 } else { -1.0 };
        if let Some(x) = particles.x.iter().find(|x| side * (x[wall.axis] - wall.position) <= 0.0) {
            return Err(SceneError::new(
                format!("boundaries.walls[{i}].position"),
                wall.position,
                format!("leaves fluid particles behind the wall (one at {:?})", x.as_slice()),
            ));
        }
    }
    let mut domain = Domain::<D>::default();
    for axis in &scene.boundaries.periodic {
        domain.periodic[axis.axis] = Some((axis.min, axis.max));
    }
    for x in &mut particles.x {
        domain.wrap(x);
    }
    check_seeds(&particles, &body_start, scene.dx, domain)?;
    for (i, body) in scene.bodies.iter().enumerate() {
        if let Some(jitter) = &body.jitter {
            let end = body_start.get(i + 1).copied().unwrap_or(particles.fluid);
            lattice::apply_jitter(&mut particles.x[body_start[i]..end], scene.dx, jitter);
        }
    }
    for x in &mut particles.x {
        domain.wrap(x);
    }
    let open = match (&scene.boundaries.inflow, &scene.boundaries.outflow) {
        (Some(i), Some(o)) => {
            let openings = Openings::new(i, o, scene.dx, support);
            let (inlet, link) = openings.seed(&mut particles)?;
            Some(OpenSetup { openings, inlet, next_id: particles.fluid as u32, link })
        }
        _ => None,
    };
    let buffer = particles.total() - particles.fluid;
    if scene.boundaries.wall_model == WallModel::Dummy && !scene.boundaries.walls.is_empty() {
        let depth = 2.0 * scene.h();
        for x in dummy_layers(&scene.boundaries.walls, &domain, &particles.x, scene.dx, depth) {
            particles.x.push(x);
            particles.u.push(Vector::zeros());
            particles.p.push(0.0);
        }
    }
    let n = particles.len();
    particles.x_old.reserve(n);
    particles.u_old.reserve(n);
    particles.div_r = vec![0.0; n];
    particles.free_surface = vec![false; n];
    let state = State {
        particles,
        neighbours: Default::default(),
        pairs: Vec::new(),
        volume: scene.dx.powi(D as i32),
        density: scene.fluid.density,
        dx: scene.dx,
        h,
        domain,
        mirrors: Default::default(),
        buffer,
        flux: Default::default(),
        inlet: open.as_ref().map(|o| o.link.clone()).unwrap_or_default(),
        solve: Default::default(),
    };
    Ok((state, open))
}

/// Rejects initial particles that cannot be run: a non-finite initial velocity or pressure
/// (an affine or quadratic field overflowing), and particles closer than Δx/2 to each other
/// (overlapping bodies). `body_start[i]` is the index of body i's first particle.
fn check_seeds<const D: usize>(
    p: &Particles<D>,
    body_start: &[usize],
    dx: f64,
    domain: Domain<D>,
) -> Result<(), SceneError> {
    let body_of = |a: usize| body_start.partition_point(|&s| s <= a).saturating_sub(1);
    let show = |v: &Vector<D>| {
        let parts: Vec<String> = v.iter().map(|x| format!("{x:.4e}")).collect();
        format!("({})", parts.join(", "))
    };
    if let Some(a) = (0..p.len()).find(|&a| !p.u[a].iter().all(|v| v.is_finite())) {
        return Err(SceneError::new(
            format!("bodies[{}].velocity", body_of(a)),
            format!("u = {} at x = {}", show(&p.u[a]), show(&p.x[a])),
            "must give a finite initial velocity at every particle",
        ));
    }
    if let Some(a) = (0..p.len()).find(|&a| !p.p[a].is_finite()) {
        return Err(SceneError::new(
            format!("bodies[{}].pressure", body_of(a)),
            format!("p = {} at x = {}", p.p[a], show(&p.x[a])),
            "must give a finite initial pressure at every particle",
        ));
    }
    let mut list = crate::neighbours::NeighbourList::default();
    crate::neighbours::CellSearch::new(0.5 * dx, domain).build(&p.x, &mut list);
    let close = (0..p.len()).flat_map(|a| list.of(a).iter().map(move |&b| (a, b as usize)));
    // The pair whose later body comes first: that body is the one that overlaps.
    if let Some((a, b)) = close.min_by_key(|&(a, b)| (body_of(a.max(b)), a.max(b), a.min(b))) {
        let (i, j) = (body_of(a.max(b)), body_of(a.min(b)));
        let x = show(&p.x[a.max(b)]);
        return Err(if i == j {
            SceneError::new(
                format!("bodies[{i}].shape"),
                format!("particles at {x}"),
                "places particles closer than dx/2 to each other (the shape wraps onto itself \
                 across a periodic boundary)",
            )
        } else {
            SceneError::new(
                format!("bodies[{i}].shape"),
                format!("a particle at {x}"),
                format!("overlaps bodies[{j}] (particles closer than dx/2); bodies must not overlap"),
            )
        });
    }
    Ok(())
}

