//! OTM as a [`Scheme`]: the scene's body meshed at `dx` ([`super::mesh`]), the material
//! points as the shared [`State`]'s particles (positions, velocities `Σ N_a v_a`,
//! pressures: what the probes, frames and guards read), the nodes in the scheme's own
//! data; one stage, `otm_step` ([`super::step::Body::step`]).
//!
//! The time step ([`Otm::stable_step`]) is `min(α_c h/(c₀ + |v|_max), α_d ρ h²/μ,
//! the capillary limit, max)` over the nodes, h = dx ([`crate::time_step`]). The
//! profiler's save and restore cover the particles only: the nodes are not restored (the
//! benches do not step OTM scenes).

use super::lme::LmeParams;
use super::mesh::{Mesh, Point, disc, rectangle};
use super::step::{Body, OtmParams};
use crate::error::{Cause, SceneError};
use crate::fields::{ColumnMut, ColumnRef, Field, Fields};
use crate::kernel::{Kernel, Scaled};
use crate::scene::lattice::{initial_pressure, initial_velocity};
use crate::scene::{Scene, Scheme as SceneScheme, Shape};
use crate::scheme::{Adaptive, Composed, Scheme};
use crate::stage::{Stage, StepContext};
use crate::state::{State, Vector};

/// The OTM scheme's own data: its body (nodes and material points). No per-particle array
/// is declared: the points' data lives in the body, in its own order (no reorder).
#[derive(Debug, Clone, Default)]
pub struct OtmData<const D: usize> {
    /// The body (none before `build`).
    pub body: Option<Body>,
}

impl<const D: usize> Fields<D> for OtmData<D> {
    fn visit(&self, _: &mut dyn FnMut(Field<ColumnRef<'_, D>>)) {}
    fn visit_mut(&mut self, _: &mut dyn FnMut(Field<ColumnMut<'_, D>>)) {}
}

/// The optimal-transportation meshfree scheme (its parameters).
#[derive(Debug)]
pub struct Otm;

/// A 2D point as the scheme's `D`-vector (`D` is 2 for every OTM scene).
fn lift<const D: usize>(p: &Point) -> Vector<D> {
    Vector::<D>::from_fn(|i, _| p[i])
}

/// The mesh of the scene's (validated) body.
fn mesh_of(scene: &Scene) -> Result<Mesh, SceneError> {
    let dx = scene.dx;
    let err = |e: super::mesh::MeshError| {
        SceneError::new(format!("bodies[0].shape ({})", e.field), e.value, e.rule)
    };
    match &scene.bodies[0].shape {
        Shape::Circle { center, radius } => disc(Point::new(center[0], center[1]), *radius, dx).map_err(err),
        Shape::Rectangle { min, max } => {
            rectangle(Point::new(min[0], min[1]), Point::new(max[0], max[1]), dx).map_err(err)
        }
        _ => Err(SceneError::new(
            "bodies[0].shape",
            "not a circle or rectangle",
            "the otm scheme meshes circles and rectangles",
        )),
    }
}

impl<const D: usize> Scheme<D> for Otm {
    type Own = OtmData<D>;

    fn build<K: Kernel>(scene: &Scene, kernel: Scaled<K, D>) -> Result<Composed<D, Self>, SceneError> {
        let SceneScheme::Otm(opts) = &scene.scheme else {
            return Err(SceneError::new("scheme", scene.scheme.key(), "must be `otm` for the OTM scheme"));
        };
        if D != 2 {
            return Err(SceneError::new("dimension", D, "the otm scheme runs 2D scenes"));
        }
        let mesh = mesh_of(scene)?;
        let params = OtmParams {
            density: scene.fluid.density,
            sound_speed: opts.sound_speed,
            viscosity: scene.fluid.viscosity,
            surface_tension: scene.fluid.surface_tension,
            gravity: Point::new(
                scene.body_force.first().copied().unwrap_or(0.0),
                scene.body_force.get(1).copied().unwrap_or(0.0),
            ),
            lme: LmeParams { gamma: opts.locality, ..LmeParams::default() },
            support_tolerance: 1e-6,
        };
        let mut body = Body::new(&mesh, scene.dx, params);
        let field = &scene.bodies[0];
        for (v, x) in body.velocity.iter_mut().zip(&mesh.nodes) {
            *v = initial_velocity::<2>(field, x);
        }
        // The initial pressure through the equation of state: each point's mass is that of
        // the density ρ₀ + p/c₀² over its area.
        for p in 0..body.points.len() {
            let pressure = initial_pressure::<2>(field, &body.points[p], params.density, &params.gravity);
            let density = params.density + pressure / (params.sound_speed * params.sound_speed);
            if density.is_nan() || density <= 0.0 {
                return Err(SceneError::new(
                    "bodies[0].pressure",
                    format!("{pressure:e} Pa at ({:e}, {:e}) m", body.points[p].x, body.points[p].y),
                    "gives a non-positive density ρ₀ + p/c₀² through the otm equation of state",
                ));
            }
            body.pressure[p] = pressure;
            body.mass[p] = body.volume[p] * density;
        }
        let mut state = crate::setup::fluid_state::<D>(scene, kernel.h);
        let n = body.points.len();
        let p = &mut state.particles;
        p.fluid = n;
        p.id = (0..n as u32).collect();
        p.x = body.points.iter().map(lift::<D>).collect();
        p.u = body.points.iter().map(|x| lift::<D>(&initial_velocity::<2>(field, x))).collect();
        p.p = body.pressure.clone();
        p.div_r = vec![0.0; n];
        p.free_surface = vec![false; n];
        // The probes' particle mass is ρ × volume: the points' mean area (the triangles of
        // the mesh, about dx²/2), not dx².
        state.volume = body.area() / n as f64;
        let stages: Vec<Box<dyn Stage<D, OtmData<D>>>> = vec![Box::new(OtmStep)];
        Ok(Composed { scheme: Otm, state, own: OtmData { body: Some(body) }, stages })
    }

    fn stable_step(&self, rule: Adaptive, _state: &State<D>, own: &OtmData<D>) -> f64 {
        own.body.as_ref().map_or(rule.max, |b| {
            let OtmParams { density, surface_tension, .. } = b.params;
            b.stable_step(rule.cfl, rule.viscous)
                .min(crate::time_step::capillary(density, b.h, surface_tension))
                .min(rule.max)
        })
    }
}

/// The OTM step of the body, then its material points copied into the particles.
#[derive(Debug)]
struct OtmStep;

impl<const D: usize> Stage<D, OtmData<D>> for OtmStep {
    fn name(&self) -> &'static str {
        "otm_step"
    }

    fn run(&mut self, state: &mut State<D>, own: &mut OtmData<D>, ctx: &StepContext) -> Result<(), Cause> {
        let Some(body) = own.body.as_mut() else { return Ok(()) };
        body.step(ctx.dt).map_err(super::step::OtmError::cause)?;
        let p = &mut state.particles;
        for (x, px) in p.x.iter_mut().zip(&body.points) {
            *x = lift::<D>(px);
        }
        p.p.copy_from_slice(&body.pressure);
        for (u, v) in p.u.iter_mut().zip(body.point_velocities()) {
            *u = lift::<D>(&v);
        }
        Ok(())
    }
}
