//! The scene rules that need the seeded particles: a body must seed particles, no particle
//! may start behind a wall, initial fields must be finite, bodies must not overlap, and
//! open boundaries must border the fluid. Checked by [`super::validate()`] on the particles
//! the set-up will start from ([`super::seeding`]), so a scene that validates builds.

use super::schema::{InitialPressure, InitialVelocity, Role, Scene, Shape, Side, WallModel};
use super::seeding::{self, Seeds};
use crate::error::SceneError;
use crate::neighbours::Domain;
/// Vector type of the seeds.
type Vector<const D: usize> = nalgebra::SVector<f64, D>;

/// The rules of this module for `scene` (dimension 2 or 3, already checked).
pub fn validate_seeds(scene: &Scene) -> Result<(), SceneError> {
    match scene.dimension {
        2 => check::<2>(scene),
        _ => check::<3>(scene),
    }
}

fn check<const D: usize>(scene: &Scene) -> Result<(), SceneError> {
    pipes_and_wall_bodies(scene)?;
    let mut seeds = seeding::seed_bodies::<D>(scene);
    if seeds.x.is_empty() {
        return Err(SceneError::new("bodies", scene.bodies.len(), "hold no fluid particle"));
    }
    walls_clear_of_fluid(scene, &seeds.x)?;
    for (i, wall) in scene.boundaries.walls.iter().enumerate() {
        let side = if wall.fluid_side == Side::Above { 1.0 } else { -1.0 };
        if let Some(x) = seeds.x.iter().find(|x| side * (x[wall.axis] - wall.position) <= 0.0) {
            return Err(SceneError::new(
                format!("boundaries.walls[{i}].position"),
                wall.position,
                format!("leaves fluid particles behind the wall (one at {:?})", x.as_slice()),
            ));
        }
    }
    check_seeds(&seeds, scene.dx, seeding::domain::<D>(scene))?;
    seeding::jitter(scene, &mut seeds);
    if let (Some(inflow), Some(outflow)) = (&scene.boundaries.inflow, &scene.boundaries.outflow) {
        let (k, dx) = (inflow.axis, scene.dx);
        let (lo, hi) = seeds
            .x
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), x| (lo.min(x[k]), hi.max(x[k])));
        if lo <= inflow.position || lo > inflow.position + dx {
            return Err(SceneError::new(
                "boundaries.inflow.position",
                inflow.position,
                format!(
                    "must lie within Δx upstream of the fluid's first particles (at {lo:.6e}), so that the buffer continues the lattice"
                ),
            ));
        }
        if hi >= outflow.position || hi < outflow.position - dx {
            return Err(SceneError::new(
                "boundaries.outflow.position",
                outflow.position,
                format!("must lie within Δx downstream of the fluid's last particles (at {hi:.6e})"),
            ));
        }
    }
    Ok(())
}

/// The rules of pipes and wall bodies: a cylinder (a pipe's fluid, or the inside of its
/// wall shell) wider than the kernel support; wall bodies (`role: wall`) are dummy
/// particles at rest, so `wall_model` must be `dummy` and the body has no initial velocity,
/// pressure or jitter.
fn pipes_and_wall_bodies(scene: &Scene) -> Result<(), SceneError> {
    let support = 2.0 * scene.h();
    for (i, body) in scene.bodies.iter().enumerate() {
        if let Shape::Cylinder { radius, inner_radius, .. } = body.shape {
            let (name, r) =
                if body.role == Role::Wall { ("inner_radius", inner_radius) } else { ("radius", radius) };
            if r > 0.0 && r <= support {
                return Err(SceneError::new(
                    format!("bodies[{i}].shape.cylinder.{name}"),
                    r,
                    format!(
                        "must exceed the kernel support 2h = {support:e} m (a pipe this narrow has no interior)"
                    ),
                ));
            }
        }
        if body.role != Role::Wall {
            continue;
        }
        if scene.boundaries.wall_model != WallModel::Dummy {
            return Err(SceneError::new(
                "boundaries.wall_model",
                "mirror",
                format!(
                    "must be dummy: bodies[{i}] is a wall body, whose particles are dummy particles (Adami 2012)"
                ),
            ));
        }
        if body.velocity != InitialVelocity::Zero {
            return Err(SceneError::new(
                format!("bodies[{i}].velocity"),
                "affine",
                "must be absent: walls are at rest",
            ));
        }
        if body.pressure != InitialPressure::Zero {
            return Err(SceneError::new(
                format!("bodies[{i}].pressure"),
                "set",
                "must be absent: a wall's pressure is extrapolated from the fluid every step",
            ));
        }
        if body.jitter.is_some() {
            return Err(SceneError::new(
                format!("bodies[{i}].jitter"),
                "set",
                "must be absent on a wall body",
            ));
        }
    }
    Ok(())
}

/// Rejects a wall body that holds no particle, and one whose particles come closer than
/// Δx/2 to a fluid particle (`fluid`, seeded and wrapped, not jittered): a wall that
/// overlaps the fluid.
fn walls_clear_of_fluid<const D: usize>(scene: &Scene, fluid: &[Vector<D>]) -> Result<(), SceneError> {
    let walls = seeding::seed_walls::<D>(scene);
    for (i, body) in scene.bodies.iter().enumerate() {
        if body.role == Role::Wall && !walls.iter().any(|w| w.1 == i) {
            return Err(SceneError::new(
                format!("bodies[{i}].shape"),
                "wall body",
                "holds no particle at this dx",
            ));
        }
    }
    if walls.is_empty() {
        return Ok(());
    }
    let all: Vec<Vector<D>> = fluid.iter().copied().chain(walls.iter().map(|w| w.0)).collect();
    let mut list = crate::neighbours::NeighbourList::default();
    crate::neighbours::CellSearch::new(0.5 * scene.dx, seeding::domain::<D>(scene)).build_rows(
        &all,
        fluid.len(),
        &mut list,
    );
    let hit = (0..fluid.len())
        .find_map(|a| list.of(a).iter().find(|&&b| b as usize >= fluid.len()).map(|&b| (a, b)));
    if let Some((a, b)) = hit {
        let (x, body) = walls[b as usize - fluid.len()];
        let show = |v: &Vector<D>| v.iter().map(|c| format!("{c:.4e}")).collect::<Vec<_>>().join(", ");
        return Err(SceneError::new(
            format!("bodies[{body}].shape"),
            format!("a wall particle at ({})", show(&x)),
            format!(
                "overlaps the fluid (within dx/2 of the fluid particle at ({})); a wall body's particles must keep dx/2 from the fluid's",
                show(&fluid[a])
            ),
        ));
    }
    Ok(())
}

/// Rejects initial particles that cannot be run: a non-finite initial velocity or pressure
/// (an affine or quadratic field overflowing), and particles closer than Δx/2 to each other
/// (overlapping bodies). `body_start[i]` is the index of body i's first particle.
fn check_seeds<const D: usize>(p: &Seeds<D>, dx: f64, domain: Domain<D>) -> Result<(), SceneError> {
    let body_of = |a: usize| p.body_of(a);
    let show = |v: &Vector<D>| {
        let parts: Vec<String> = v.iter().map(|x| format!("{x:.4e}")).collect();
        format!("({})", parts.join(", "))
    };
    if let Some(a) = (0..p.x.len()).find(|&a| !p.u[a].iter().all(|v| v.is_finite())) {
        return Err(SceneError::new(
            format!("bodies[{}].velocity", body_of(a)),
            format!("u = {} at x = {}", show(&p.u[a]), show(&p.x[a])),
            "must give a finite initial velocity at every particle",
        ));
    }
    if let Some(a) = (0..p.x.len()).find(|&a| !p.p[a].is_finite()) {
        return Err(SceneError::new(
            format!("bodies[{}].pressure", body_of(a)),
            format!("p = {} at x = {}", p.p[a], show(&p.x[a])),
            "must give a finite initial pressure at every particle",
        ));
    }
    let mut list = crate::neighbours::NeighbourList::default();
    crate::neighbours::CellSearch::new(0.5 * dx, domain).build(&p.x, &mut list);
    let close = (0..p.x.len()).flat_map(|a| list.of(a).iter().map(move |&b| (a, b as usize)));
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
