//! OTM as a [`Scheme`]: the scene's body meshed at `dx` ([`super::mesh`]), the material
//! points as the shared [`State`]'s particles (positions, velocities `Σ N_a v_a`,
//! pressures, volumes in [`State::volumes`]: what the probes, frames and guards read), the
//! nodes in the scheme's own data; one stage, `otm_step` ([`super::step::Body::step`]).
//!
//! A 2D scene is a plane body (a circle or a rectangle). A 3D scene is a ball solved in
//! its (r, z) section about the z axis through its centre ([`Geometry::Axisymmetric`],
//! Zhou 2021 §2.3.3): the material points are stored at `(x_c + r, y_c, z)`, each the ring
//! it traces ([`State::axis`]), and the scene's initial fields are read on the half-plane
//! y = y_c, x ≥ x_c (their r and z components: they must be axisymmetric).
//!
//! The time step ([`Otm::stable_step`]) is `min(α_c h/(c₀ + |v|_max), α_d ρ h²/μ,
//! the capillary limit, max)` over the nodes, h = dx ([`crate::time_step`]). The
//! profiler's save and restore cover the particles only: the nodes are not restored (the
//! benches do not step OTM scenes).

use super::lme::LmeParams;
use super::mesh::{Mesh, Point, disc, half_disc, rectangle};
use super::step::{Body, Geometry, OtmParams, Period, Plane};
use crate::error::{Cause, SceneError};
use crate::fields::{ColumnMut, ColumnRef, Field, Fields};
use crate::kernel::{Kernel, Scaled};
use crate::scene::lattice::{initial_pressure, initial_velocity};
use crate::scene::{Scene, Scheme as SceneScheme, Shape, Side};
use crate::scheme::{Adaptive, Composed, Scheme};
use crate::stage::{Stage, StepContext};
use crate::state::{Particles, State, Vector};

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

/// Where the body's plane lies in the scene: a plane body's (x, y) is the scene's (2D); an
/// axisymmetric body's (r, z) is `(axis[0] + r, axis[1], z)` (3D).
#[derive(Debug, Clone, Copy)]
struct Placement {
    geometry: Geometry,
    axis: [f64; 2],
}

impl Placement {
    /// The body-plane point `p` as the scene's `D`-vector \[m\].
    fn lift<const D: usize>(&self, p: &Point) -> Vector<D> {
        match self.geometry {
            Geometry::Plane => Vector::<D>::from_fn(|i, _| p[i]),
            Geometry::Axisymmetric => {
                Vector::<D>::from_fn(|i, _| [self.axis[0] + p[0], self.axis[1], p[1]][i])
            }
        }
    }

    /// The body-plane vector `v` as the scene's (`(v_r, 0, v_z)` axisymmetric).
    fn lift_vector<const D: usize>(&self, v: &Point) -> Vector<D> {
        match self.geometry {
            Geometry::Plane => Vector::<D>::from_fn(|i, _| v[i]),
            Geometry::Axisymmetric => Vector::<D>::from_fn(|i, _| [v[0], 0.0, v[1]][i]),
        }
    }

    /// The scene's vector `v` at a body-plane point as the body's (the (r, z) components
    /// on the half-plane y = y_c, axisymmetric).
    fn lower<const D: usize>(&self, v: &Vector<D>) -> Point {
        match self.geometry {
            Geometry::Plane => Point::new(v[0], v[1]),
            Geometry::Axisymmetric => Point::new(v[0], v[2]),
        }
    }
}

/// The mesh of the scene's (validated) body and where it lies.
fn mesh_of(scene: &Scene) -> Result<(Mesh, Placement), SceneError> {
    let dx = scene.dx;
    let err = |e: super::mesh::MeshError| {
        SceneError::new(format!("bodies[0].shape ({})", e.field), e.value, e.rule)
    };
    let plane = Placement { geometry: Geometry::Plane, axis: [0.0; 2] };
    match &scene.bodies[0].shape {
        Shape::Circle { center, radius } => {
            Ok((disc(Point::new(center[0], center[1]), *radius, dx).map_err(err)?, plane))
        }
        Shape::Rectangle { min, max } => {
            Ok((rectangle(Point::new(min[0], min[1]), Point::new(max[0], max[1]), dx).map_err(err)?, plane))
        }
        Shape::Sphere { center, radius } => Ok((
            half_disc(Point::new(0.0, center[2]), *radius, dx).map_err(err)?,
            Placement { geometry: Geometry::Axisymmetric, axis: [center[0], center[1]] },
        )),
        _ => Err(SceneError::new(
            "bodies[0].shape",
            "not a circle, rectangle or sphere",
            "the otm scheme meshes circles and rectangles (2D) and spheres (3D, axisymmetric)",
        )),
    }
}

impl<const D: usize> Scheme<D> for Otm {
    type Own = OtmData<D>;

    fn build<K: Kernel>(scene: &Scene, kernel: Scaled<K, D>) -> Result<Composed<D, Self>, SceneError> {
        let SceneScheme::Otm(opts) = &scene.scheme else {
            return Err(SceneError::new("scheme", scene.scheme.key(), "must be `otm` for the OTM scheme"));
        };
        let (mesh, place) = mesh_of(scene)?;
        let gravity = Vector::<D>::from_fn(|i, _| scene.body_force.get(i).copied().unwrap_or(0.0));
        let params = OtmParams {
            density: scene.fluid.density,
            sound_speed: opts.sound_speed,
            viscosity: scene.fluid.viscosity,
            surface_tension: scene.fluid.surface_tension,
            gravity: place.lower(&gravity),
            lme: LmeParams { gamma: opts.locality, ..LmeParams::default() },
            support_tolerance: 1e-6,
        };
        let mut body = match opts.quadrature {
            Some(q) => Body::with_quadrature(&mesh, scene.dx, params, place.geometry, q),
            None => Body::new(&mesh, scene.dx, params, place.geometry),
        };
        body.integration = opts.integration;
        body.density = opts.density;
        // Walls (validated: the body on the fluid side): planes the nodes do not cross, those
        // on a plane held there at rest (no slip). In 3D the plane is normal to the axis.
        for w in &scene.boundaries.walls {
            let axis = if place.geometry == Geometry::Axisymmetric { 1 } else { w.axis };
            let side = if w.fluid_side == Side::Above { 1.0 } else { -1.0 };
            body.walls.push(Plane { axis, position: w.position, side });
        }
        for a in 0..body.nodes.len() {
            body.held[a] = body.walls.iter().any(|w| w.touches(&body.nodes[a], scene.dx));
        }
        if let Some(pd) = scene.boundaries.periodic.first() {
            let period = Period { axis: pd.axis, min: pd.min, length: pd.max - pd.min };
            body = body.with_period(period).map_err(|e| {
                SceneError::new("boundaries.periodic[0]", format!("[{}, {}]", pd.min, pd.max), e)
            })?;
        }
        let field = &scene.bodies[0];
        for (v, x) in body.velocity.iter_mut().zip(&mesh.nodes) {
            *v = place.lower(&initial_velocity::<D>(field, &place.lift::<D>(x)));
        }
        for &a in &body.axis {
            body.velocity[a][0] = 0.0;
        }
        // The initial pressure through the equation of state: each point's mass is that of
        // the density ρ₀ + p/c₀² over its area.
        for p in 0..body.points.len() {
            let pressure =
                initial_pressure::<D>(field, &place.lift::<D>(&body.points[p]), params.density, &gravity);
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
        let n = body.points.len();
        let particles = Particles::<D> {
            fluid: n,
            id: (0..n as u32).collect(),
            x: body.points.iter().map(|x| place.lift::<D>(x)).collect(),
            u: body
                .points
                .iter()
                .map(|x| {
                    place.lift_vector::<D>(&place.lower(&initial_velocity::<D>(field, &place.lift::<D>(x))))
                })
                .collect(),
            p: body.pressure.clone(),
            ..Default::default()
        };
        let mut state = crate::setup::state_of(particles, scene, kernel.h);
        // The probes weigh each point by its own volume; the mean stands for the rest.
        state.volumes = body.volume.clone();
        state.volume = body.area() / n as f64;
        state.axis = (place.geometry == Geometry::Axisymmetric).then_some(place.axis);
        outline(&body, &place, &mut state.outline);
        let stages: Vec<Box<dyn Stage<D, OtmData<D>>>> = vec![Box::new(OtmStep { place })];
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

/// The plane body's boundary polyline as the state's outline (none axisymmetric: the
/// probes' outline is 2D).
fn outline<const D: usize>(body: &Body, place: &Placement, out: &mut Vec<Vector<D>>) {
    out.clear();
    if place.geometry == Geometry::Plane {
        out.extend(body.boundary.iter().map(|&a| place.lift::<D>(&body.nodes[a])));
    }
}

/// The OTM step of the body, then its material points copied into the particles.
#[derive(Debug)]
struct OtmStep {
    place: Placement,
}

impl<const D: usize> Stage<D, OtmData<D>> for OtmStep {
    fn name(&self) -> &'static str {
        "otm_step"
    }

    fn run(&mut self, state: &mut State<D>, own: &mut OtmData<D>, ctx: &StepContext) -> Result<(), Cause> {
        let Some(body) = own.body.as_mut() else { return Ok(()) };
        body.step(ctx.dt).map_err(super::step::OtmError::cause)?;
        let p = &mut state.particles;
        for (x, px) in p.x.iter_mut().zip(&body.points) {
            *x = self.place.lift::<D>(px);
        }
        p.p.copy_from_slice(&body.pressure);
        for (u, v) in p.u.iter_mut().zip(body.point_velocities()) {
            *u = self.place.lift_vector::<D>(&v);
        }
        state.volumes.copy_from_slice(&body.volume);
        outline(body, &self.place, &mut state.outline);
        Ok(())
    }
}
