//! The particles of a scene at t = 0, as the particle schemes start from them: the bodies
//! seeded on the lattice (or rings) and jittered, positions wrapped into periodic axes, the
//! open boundaries' buffers, dummy wall particles (layers behind wall planes, and wall
//! bodies); and the shared [`State`] around them.

use crate::scene::{Scene, WallModel, seeding};
use crate::stages::dummy::dummy_layers;
use crate::stages::open_boundary::{OpenSetup, Openings};
use crate::state::{InletLink, Particles, State, Vector};

/// The initial state of a (validated) `scene` for a kernel of `support` \[m\] and
/// smoothing length `h` \[m\], and its open boundaries when it has an inflow and an
/// outflow. The scene rules on the seeded particles are the validation's
/// ([`crate::scene::validate`]), so building a validated scene cannot fail.
pub fn particle_state<const D: usize>(scene: &Scene, h: f64, support: f64) -> (State<D>, Option<OpenSetup>) {
    let mut particles = fluid_particles::<D>(scene);
    let domain = seeding::domain::<D>(scene);
    let open = match (&scene.boundaries.inflow, &scene.boundaries.outflow) {
        (Some(i), Some(o)) => {
            let openings = Openings::new(i, o, scene.dx, support);
            let (inlet, link) = openings.seed(&mut particles);
            Some(OpenSetup { openings, inlet, next_id: particles.fluid as u32, link })
        }
        _ => None,
    };
    let buffer = particles.total() - particles.fluid;
    if scene.boundaries.wall_model == WallModel::Dummy && scene.has_walls() {
        let depth = 2.0 * scene.h();
        let planes = dummy_layers(&scene.boundaries.walls, &domain, &particles.x, scene.dx, depth);
        let bodies = seeding::seed_walls::<D>(scene).into_iter().map(|(x, _)| x);
        for x in planes.into_iter().chain(bodies) {
            particles.x.push(x);
            particles.u.push(Vector::zeros());
            particles.p.push(0.0);
        }
    }
    let inlet = open.as_ref().map(|o| o.link.clone()).unwrap_or_default();
    (state_around(particles, scene, h, buffer, inlet), open)
}

/// The initial state of a (validated) `scene` with its fluid only (smoothing length `h`
/// \[m\]): for a scheme that lays its own boundary particles (MPS) after the fluid.
pub fn fluid_state<const D: usize>(scene: &Scene, h: f64) -> State<D> {
    state_around(fluid_particles::<D>(scene), scene, h, 0, Default::default())
}

/// The shared state around fluid `particles` placed by a scheme of its own (OTM's material
/// points): no open boundary.
pub fn state_of<const D: usize>(particles: Particles<D>, scene: &Scene, h: f64) -> State<D> {
    state_around(particles, scene, h, 0, Default::default())
}

/// The scene's bodies seeded, jittered and wrapped into periodic axes, ids in seeding order.
fn fluid_particles<const D: usize>(scene: &Scene) -> Particles<D> {
    let mut seeds = seeding::seed_bodies::<D>(scene);
    seeding::jitter(scene, &mut seeds);
    let fluid = seeds.x.len();
    Particles::<D> {
        fluid,
        id: (0..fluid as u32).collect(),
        x: seeds.x,
        u: seeds.u,
        p: seeds.p,
        ..Default::default()
    }
}

/// The shared state around `particles` (`buffer` open-boundary buffer particles after the
/// fluid, `inlet` their pressure link).
fn state_around<const D: usize>(
    mut particles: Particles<D>,
    scene: &Scene,
    h: f64,
    buffer: usize,
    inlet: InletLink,
) -> State<D> {
    let n = particles.len();
    particles.x_old.reserve(n);
    particles.u_old.reserve(n);
    particles.div_r = vec![0.0; n];
    particles.free_surface = vec![false; n];
    State {
        particles,
        neighbours: Default::default(),
        pairs: Vec::new(),
        volume: scene.dx.powi(D as i32),
        volumes: Vec::new(),
        axis: None,
        density: scene.fluid.density,
        dx: scene.dx,
        h,
        domain: seeding::domain::<D>(scene),
        mirrors: Default::default(),
        buffer,
        flux: Default::default(),
        inlet,
        links: Default::default(),
        moments: Vec::new(),
        solve: Default::default(),
        outline: Vec::new(),
    }
}
