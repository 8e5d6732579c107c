//! Every rule of a parsed scene (the seeded particles' in [`super::validate_seeds`]): each
//! names the field, the value and the rule. Building a scene that passes cannot fail.

use super::schema::*;
use crate::error::SceneError;

/// Checks every rule of `scene`; the first violation is returned.
pub fn validate(scene: &Scene) -> Result<(), SceneError> {
    let d = scene.dimension;
    if d != 2 && d != 3 {
        return Err(SceneError::new("dimension", d, "must be 2 or 3"));
    }
    if scene.name.trim().is_empty() {
        return Err(SceneError::new("name", "\"\"", "must not be empty"));
    }
    positive("dx", scene.dx)?;
    positive("kernel.h_over_dx", scene.kernel.h_over_dx)?;
    if scene.kernel.h_over_dx < 1.0 {
        return Err(SceneError::new(
            "kernel.h_over_dx",
            scene.kernel.h_over_dx,
            "must be at least 1 (the kernel support must reach the nearest neighbours)",
        ));
    }
    if scene.kernel.h_over_dx > 4.0 {
        return Err(SceneError::new(
            "kernel.h_over_dx",
            scene.kernel.h_over_dx,
            "must be at most 4 (wider kernels are not supported)",
        ));
    }
    positive("fluid.density", scene.fluid.density)?;
    non_negative("fluid.viscosity", scene.fluid.viscosity)?;
    non_negative("fluid.surface_tension", scene.fluid.surface_tension)?;
    positive("fluid.surface_tension_threshold", scene.fluid.surface_tension_threshold)?;
    if scene.fluid.surface_tension_threshold >= 1.0 {
        return Err(SceneError::new(
            "fluid.surface_tension_threshold",
            scene.fluid.surface_tension_threshold,
            "must be below 1 (|∇c| is about 0.3/h at a free surface; Xu 2016 uses 0.01)",
        ));
    }
    if !scene.body_force.is_empty() {
        vector("body_force", &scene.body_force, d)?;
    }
    if scene.bodies.is_empty() {
        return Err(SceneError::new("bodies", "[]", "must contain at least one body"));
    }
    for (i, body) in scene.bodies.iter().enumerate() {
        validate_body(&format!("bodies[{i}]"), body, d, scene.dx)?;
    }
    let estimate: f64 = scene.bodies.iter().map(|b| shape_measure(&b.shape) / scene.dx.powi(d as i32)).sum();
    if estimate > MAX_PARTICLES {
        return Err(SceneError::new(
            "dx",
            scene.dx,
            format!("gives about {estimate:.3e} particles; at most {MAX_PARTICLES:.0e} are supported"),
        ));
    }
    for (i, axis) in scene.boundaries.periodic.iter().enumerate() {
        let f = format!("boundaries.periodic[{i}]");
        if axis.axis >= d {
            return Err(SceneError::new(
                format!("{f}.axis"),
                axis.axis,
                "must be an axis of the scene (0..dimension)",
            ));
        }
        if scene.boundaries.periodic[..i].iter().any(|a| a.axis == axis.axis) {
            return Err(SceneError::new(
                format!("{f}.axis"),
                axis.axis,
                "is periodic twice (list each axis once)",
            ));
        }
        finite(&format!("{f}.min"), axis.min)?;
        finite(&format!("{f}.max"), axis.max)?;
        if axis.max <= axis.min {
            return Err(SceneError::new(
                format!("{f}.max"),
                axis.max,
                format!("must exceed min = {}", axis.min),
            ));
        }
        let support = 2.0 * scene.h();
        if axis.max - axis.min < 2.0 * support {
            return Err(SceneError::new(
                format!("{f}.max"),
                axis.max,
                format!(
                    "the period max − min = {:e} m must be at least twice the kernel support 2h = {support:e} m \
                     (the minimum-image convention sees one image of each neighbour)",
                    axis.max - axis.min
                ),
            ));
        }
        for (j, body) in scene.bodies.iter().enumerate() {
            let span = shape_span(&body.shape, axis.axis);
            if span > (axis.max - axis.min) * (1.0 + 1e-9) {
                return Err(SceneError::new(
                    format!("bodies[{j}].shape"),
                    format!("{span:e} m along axis {}", axis.axis),
                    format!(
                        "is longer than the period {:e} m of {f} (its particles would wrap onto each other)",
                        axis.max - axis.min
                    ),
                ));
            }
        }
    }
    match &scene.scheme {
        Scheme::Isph(o) => validate_isph(o, d)?,
        Scheme::Wcsph(o) => validate_wcsph(o)?,
        Scheme::Mps(o) => validate_mps(o, scene)?,
        Scheme::Otm(o) => validate_otm(o, scene)?,
    }
    validate_young_laplace(scene)?;
    positive("time.end", scene.time.end)?;
    match scene.time.step {
        TimeStep::Fixed(dt) => {
            positive("time.step.fixed", dt)?;
            if dt > scene.time.end {
                return Err(SceneError::new(
                    "time.step.fixed",
                    dt,
                    format!("must not exceed time.end = {}", scene.time.end),
                ));
            }
            let steps = scene.time.end / dt;
            if steps > MAX_STEPS {
                return Err(SceneError::new(
                    "time.step.fixed",
                    dt,
                    format!("gives {steps:.3e} steps to time.end; at most {MAX_STEPS:.0e} are supported"),
                ));
            }
        }
        TimeStep::Adaptive { cfl, viscous, max } => {
            positive("time.step.adaptive.cfl", cfl)?;
            positive("time.step.adaptive.viscous", viscous)?;
            positive("time.step.adaptive.max", max)?;
            if cfl > 1.0 {
                return Err(SceneError::new("time.step.adaptive.cfl", cfl, "must be at most 1"));
            }
        }
    }
    if let Some(steady) = &scene.time.steady {
        validate_steady(steady, scene)?;
    }
    for (i, probe) in scene.probes.iter().enumerate() {
        if let Probe::PressureAt { point } = probe {
            vector(&format!("probes[{i}].pressure_at.point"), point, d)?;
        }
        if let Probe::MeanPressure { center, radius } = probe {
            vector(&format!("probes[{i}].mean_pressure.center"), center, d)?;
            positive(&format!("probes[{i}].mean_pressure.radius"), *radius)?;
        }
        if let Probe::PressureGradient { center, radius } = probe {
            vector(&format!("probes[{i}].pressure_gradient.center"), center, d)?;
            positive(&format!("probes[{i}].pressure_gradient.radius"), *radius)?;
        }
        if let Probe::YoungLaplace { above: Some(y) } = probe {
            finite(&format!("probes[{i}].young_laplace.above"), *y)?;
        }
        if let Probe::Spread { axis, position, layer } = probe {
            let key = format!("probes[{i}].spread");
            if *axis >= d {
                return Err(SceneError::new(
                    format!("{key}.axis"),
                    axis,
                    format!("must be below the dimension {d}"),
                ));
            }
            finite(&format!("{key}.position"), *position)?;
            if let Some(layer) = layer {
                positive(&format!("{key}.layer"), *layer)?;
            }
        }
        // Shape probes of one dimension: the ellipse in 2D, the ellipsoid in 3D.
        let only = match probe {
            Probe::EllipseAxes {} => Some((2, "is defined for 2D scenes only")),
            Probe::EllipsoidAxes {} => Some((3, "is defined for 3D scenes only (ellipse_axes in 2D)")),
            Probe::YoungLaplace { .. } => {
                Some((2, "is defined for 2D scenes only (the outline is traced in x–y)"))
            }
            _ => None,
        };
        if let Some((want, rule)) = only
            && d != want
        {
            return Err(SceneError::new(format!("probes[{i}].{}", probe.kind_name()), "{}", rule));
        }
    }
    if scene.output.probe_every == 0 {
        return Err(SceneError::new("output.probe_every", 0, "must be at least 1"));
    }
    super::validate_boundaries::validate(scene)?;
    // Last: the rules on the seeded particles, which the ones above make safe to seed.
    super::validate_seeds::validate_seeds(scene)
}

/// Largest particle count a scene may ask for (memory: about 1 kB per particle).
const MAX_PARTICLES: f64 = 5e7;

/// Largest cylinder radius over Δx: its cross-section is scanned on a `(2R/Δx)²` grid,
/// about [`MAX_PARTICLES`] points at this radius.
const MAX_CYLINDER_RADIUS_OVER_DX: f64 = 3500.0;

/// Largest number of fixed steps (the adaptive step's floor, 1e-9 of the end time, gives
/// the same bound): beyond it `t + Δt` would lose Δt to rounding.
const MAX_STEPS: f64 = 1e9;

/// Shape coordinates must lie within this many Δx of the origin: further out, double
/// precision (16 digits) cannot resolve the particle spacing to better than 1e-6 Δx.
const MAX_COORDINATE_OVER_DX: f64 = 1e9;

/// Extent of a shape along `axis` \[m\].
fn shape_span(shape: &Shape, axis: usize) -> f64 {
    match shape {
        Shape::Circle { radius, .. } | Shape::Sphere { radius, .. } => 2.0 * radius,
        Shape::Rectangle { min, max } | Shape::Box { min, max } => {
            max.get(axis).copied().unwrap_or(0.0) - min.get(axis).copied().unwrap_or(0.0)
        }
        Shape::Cylinder { axis: along, radius, length, .. } => {
            if axis == *along {
                *length
            } else {
                2.0 * radius
            }
        }
    }
}

/// Checks that every coordinate of `v` lies within [`MAX_COORDINATE_OVER_DX`] Δx of the origin.
fn near_origin(field: &str, v: &[f64], dx: f64) -> Result<(), SceneError> {
    let limit = MAX_COORDINATE_OVER_DX * dx;
    for (k, x) in v.iter().enumerate() {
        if x.abs() > limit {
            return Err(SceneError::new(
                format!("{field}[{k}]"),
                x,
                format!(
                    "must lie within 1e9 dx = {limit:e} m of the origin (further out, double precision \
                     cannot resolve the particle spacing)"
                ),
            ));
        }
    }
    Ok(())
}

/// Area (2D) or volume (3D) of a validated shape \[m^D\].
fn shape_measure(shape: &Shape) -> f64 {
    match shape {
        Shape::Circle { radius, .. } => std::f64::consts::PI * radius * radius,
        Shape::Sphere { radius, .. } => 4.0 / 3.0 * std::f64::consts::PI * radius.powi(3),
        Shape::Rectangle { min, max } | Shape::Box { min, max } => {
            min.iter().zip(max).map(|(a, b)| (b - a).max(0.0)).product()
        }
        Shape::Cylinder { radius, length, inner_radius, .. } => {
            std::f64::consts::PI * (radius * radius - inner_radius * inner_radius) * length
        }
    }
}

fn validate_isph(o: &IsphOptions, d: usize) -> Result<(), SceneError> {
    validate_ppe("scheme.isph.ppe", &o.ppe)?;
    let t = o.free_surface_threshold(d);
    positive("scheme.isph.free_surface_threshold", t)?;
    if t >= d as f64 {
        return Err(SceneError::new(
            "scheme.isph.free_surface_threshold",
            t,
            "must be below the dimension (div r is about D in the bulk)",
        ));
    }
    let alpha = o.density_relaxation;
    if !(alpha.is_finite() && (0.0..=1.0).contains(&alpha)) {
        return Err(SceneError::new(
            "scheme.isph.density_relaxation",
            alpha,
            "must lie in [0, 1] (0: off; 0.01–0.1 relaxes a density drift over 10–100 steps)",
        ));
    }
    if o.viscosity == ViscousIntegration::Implicit && o.viscous_operator != ViscousOperator::ShaoLo {
        return Err(SceneError::new(
            "scheme.isph.viscous_operator",
            o.viscous_operator.scene_name(),
            format!(
                "is explicit only: the implicit viscous solve uses the {} operator",
                ViscousOperator::ShaoLo.scene_name()
            ),
        ));
    }
    validate_shifting("scheme.isph.shifting", o.shifting)?;
    if o.free_surface_pressure == FreeSurfacePressure::Extrapolated {
        if o.pressure_gradient == PressureGradient::Symmetric {
            return Err(SceneError::new("scheme.isph.free_surface_pressure", "extrapolated", NOT_SYMMETRIC));
        }
        if o.pressure_gradient != PressureGradient::Corrected && o.divergence != Divergence::Corrected {
            return Err(SceneError::new(
                "scheme.isph.free_surface_pressure",
                "extrapolated",
                "needs the kernel-gradient correction (scheme.isph.divergence or pressure_gradient = \"corrected\"): the plain gradient sees about half of ∂p/∂n on a surface row",
            ));
        }
    }
    Ok(())
}

/// The linear-solver rules of a PPE's options at `field`.
fn validate_ppe(field: &str, ppe: &PpeOptions) -> Result<(), SceneError> {
    let f = format!("{field}.tolerance");
    positive(&f, ppe.tolerance)?;
    if ppe.tolerance >= 1.0 {
        return Err(SceneError::new(f, ppe.tolerance, "must be below 1 (a relative residual)"));
    }
    if ppe.max_iterations == 0 {
        return Err(SceneError::new(format!("{field}.max_iterations"), 0, "must be at least 1"));
    }
    if ppe.coarse_refresh == 0 {
        return Err(SceneError::new(format!("{field}.coarse_refresh"), 0, "must be at least 1"));
    }
    Ok(())
}

/// The OTM scheme runs one fluid body (in 2D a circle or a rectangle meshed at `dx`, in
/// 3D a sphere solved axisymmetric) with plane walls and periodic axes; wall bodies and
/// open boundaries are not built for it.
fn validate_otm(o: &OtmOptions, scene: &Scene) -> Result<(), SceneError> {
    positive("scheme.otm.sound_speed", o.sound_speed)?;
    if !(o.locality.is_finite() && o.locality > 0.0 && o.locality <= 10.0) {
        return Err(SceneError::new(
            "scheme.otm.locality",
            o.locality,
            "must lie in (0, 10] (the LME locality γ, β = γ / dx²; 0.8 to 4 is usual, 1.5 the default: \
             above 10 a point's support holds hardly more than its own triangle)",
        ));
    }
    let not_yet = |field: &str, value: &str| {
        Err(SceneError::new(
            field,
            value,
            "is not supported by the otm scheme (one fluid body; plane walls and periodic axes only)",
        ))
    };
    if scene.bodies.iter().any(|b| b.role == Role::Wall) {
        return not_yet("bodies", "a wall body (the otm scheme's walls are planes)");
    }
    if scene.boundaries.inflow.is_some() || scene.boundaries.outflow.is_some() {
        return not_yet("boundaries.inflow", "open boundaries");
    }
    if scene.bodies.len() != 1 {
        return Err(SceneError::new(
            "bodies",
            format!("{} bodies", scene.bodies.len()),
            "the otm scheme meshes exactly one fluid body",
        ));
    }
    let body = &scene.bodies[0];
    if scene.dimension == 3 {
        if !matches!(body.shape, Shape::Sphere { .. }) {
            return Err(SceneError::new(
                "bodies[0].shape",
                "not a sphere",
                "the otm scheme runs a 3D scene axisymmetric, about the z axis through a sphere's centre",
            ));
        }
        if let Some(i) = (0..2).find(|&i| scene.body_force[i] != 0.0) {
            return Err(SceneError::new(
                format!("body_force[{i}]"),
                scene.body_force[i],
                "must be 0 for the otm scheme in 3D (axisymmetric about z: gravity along z only)",
            ));
        }
        if o.integration != Integration::Point {
            return Err(SceneError::new(
                "scheme.otm.integration",
                o.integration.key(),
                "must be `point` in 3D (the consistent integration is of the plane weak form, not the axisymmetric one)",
            ));
        }
        if o.density != Density::Material {
            return Err(SceneError::new(
                "scheme.otm.density",
                o.density.key(),
                "must be `material` in 3D (the nodal projection is not built for the axisymmetric rings)",
            ));
        }
    } else if !matches!(body.shape, Shape::Circle { .. } | Shape::Rectangle { .. }) {
        return Err(SceneError::new(
            "bodies[0].shape",
            "not a circle or rectangle",
            "the otm scheme's mesher triangulates a circle or a rectangle",
        ));
    }
    if body.jitter.is_some() {
        return not_yet("bodies[0].jitter", "a jittered lattice");
    }
    validate_otm_boundaries(o, scene)
}

/// The otm scheme's nodal boundary conditions: a wall is a plane the body lies on the
/// fluid side of (its nodes on the plane are held at rest, others once they reach it; in
/// 3D, axisymmetric, a plane normal to z); a periodic axis is a rectangle's extent (its
/// two edges merged), and a periodic body has no free surface to carry surface tension.
fn validate_otm_boundaries(o: &OtmOptions, scene: &Scene) -> Result<(), SceneError> {
    let b = &scene.boundaries;
    // The body's extent on each axis.
    let (lo, hi): (Vec<f64>, Vec<f64>) = match &scene.bodies[0].shape {
        Shape::Rectangle { min, max } => (min.to_vec(), max.to_vec()),
        Shape::Circle { center, radius } | Shape::Sphere { center, radius } => {
            (center.iter().map(|c| c - radius).collect(), center.iter().map(|c| c + radius).collect())
        }
        _ => return Ok(()),
    };
    let tol = 1e-9 * scene.dx;
    for (i, w) in b.walls.iter().enumerate() {
        if scene.dimension == 3 && w.axis != 2 {
            return Err(SceneError::new(
                format!("boundaries.walls[{i}].axis"),
                w.axis,
                "must be 2 for the otm scheme in 3D (axisymmetric about z: a wall normal to z)",
            ));
        }
        let inside = match w.fluid_side {
            Side::Above => lo[w.axis] >= w.position - tol,
            Side::Below => hi[w.axis] <= w.position + tol,
        };
        if !inside {
            return Err(SceneError::new(
                format!("boundaries.walls[{i}].position"),
                w.position,
                format!(
                    "cuts the body ({} to {} m on axis {}): the otm scheme's body lies on the wall's fluid side",
                    lo[w.axis], hi[w.axis], w.axis
                ),
            ));
        }
    }
    if b.periodic.is_empty() {
        return Ok(());
    }
    if !matches!(scene.bodies[0].shape, Shape::Rectangle { .. }) {
        return Err(SceneError::new(
            "boundaries.periodic",
            "on a body that is not a rectangle",
            "the otm scheme's periodic axis is a rectangle's extent",
        ));
    }
    if b.periodic.len() > 1 {
        return Err(SceneError::new(
            "boundaries.periodic",
            format!("{} axes", b.periodic.len()),
            "the otm scheme takes one periodic axis",
        ));
    }
    let on = |a: f64, b: f64| (a - b).abs() <= 1e-9 * scene.dx.max(a.abs());
    let p = &b.periodic[0];
    if !(on(p.min, lo[p.axis]) && on(p.max, hi[p.axis])) {
        return Err(SceneError::new(
            "boundaries.periodic[0]",
            format!("[{}, {}] on axis {}", p.min, p.max, p.axis),
            "must be the rectangle's extent on that axis for the otm scheme (its nodes on the two edges are merged)",
        ));
    }
    // The support radius dx √(ln 10⁶ / γ) (`otm::lme::LmeParams::cutoff`).
    let support = scene.dx * (1e6f64.ln() / o.locality).sqrt();
    if p.max - p.min <= 2.0 * support {
        return Err(SceneError::new(
            "boundaries.periodic[0]",
            p.max - p.min,
            "must exceed twice the otm shape functions' support (a node's nearest image must be unique)",
        ));
    }
    if scene.fluid.surface_tension > 0.0 {
        return Err(SceneError::new(
            "fluid.surface_tension",
            scene.fluid.surface_tension,
            "must be 0 for the otm scheme with a periodic axis (no closed free surface to carry it)",
        ));
    }
    Ok(())
}

/// The rules of the MPS options (MPS.md) and of what the MPS step does not have.
fn validate_mps(o: &MpsOptions, scene: &Scene) -> Result<(), SceneError> {
    validate_ppe("scheme.mps.ppe", &o.ppe)?;
    let r = o.radii();
    for (name, re) in
        [("number_density", r.number_density), ("gradient", r.gradient), ("laplacian", r.laplacian)]
    {
        let f = format!("scheme.mps.radii.{name}");
        finite(&f, re)?;
        if re <= 1.0 {
            return Err(SceneError::new(
                f,
                re,
                "must exceed 1 (a radius in units of l0 = dx: the weight must reach the nearest neighbours)",
            ));
        }
        if re > 6.0 {
            return Err(SceneError::new(f, re, "must be at most 6 (MPS uses 2.1 to 4.1)"));
        }
    }
    if !(o.gamma.is_finite() && (0.0..=1.0).contains(&o.gamma)) {
        return Err(SceneError::new(
            "scheme.mps.gamma",
            o.gamma,
            "must lie in [0, 1] (the weight of the number-density term of the PPE source; Lan prints 0.99, others use 0.01)",
        ));
    }
    non_negative("scheme.mps.compressibility", o.compressibility)?;
    validate_shifting("scheme.mps.shifting", o.shifting)?;
    if let Some(beta) = o.free_surface.beta
        && !(beta.is_finite() && beta > 0.0 && beta < 1.0)
    {
        return Err(SceneError::new(
            "scheme.mps.free_surface.beta",
            beta,
            "must lie in (0, 1) (surface where n* < β n0; 0.97 in 2D, 0.98 in 3D)",
        ));
    }
    if scene.fluid.surface_tension > 0.0 {
        return Err(SceneError::new(
            "fluid.surface_tension",
            scene.fluid.surface_tension,
            "must be 0 with the mps scheme (it has no surface-tension model)",
        ));
    }
    if let Some(i) = scene.bodies.iter().position(|b| b.role == Role::Wall) {
        return Err(SceneError::new(
            format!("bodies[{i}].role"),
            "wall",
            "is not an mps wall: the mps scheme lays its own wall particles behind `boundaries.walls` planes (MPS.md)",
        ));
    }
    if scene.boundaries.wall_model == WallModel::Dummy && !scene.boundaries.walls.is_empty() {
        return Err(SceneError::new(
            "boundaries.wall_model",
            "dummy",
            "is not an mps wall: the mps scheme lays its own wall particles (MPS.md); leave wall_model unset",
        ));
    }
    Ok(())
}

/// The coefficient rules of a shifting law at `field` (`scheme.isph.shifting` or
/// `scheme.wcsph.shifting`).
fn validate_shifting(field: &str, shifting: Shifting) -> Result<(), SceneError> {
    match shifting {
        Shifting::None => {}
        Shifting::Xu { coefficient, .. } => {
            let f = format!("{field}.xu.coefficient");
            positive(&f, coefficient)?;
            if coefficient > 1.0 {
                return Err(SceneError::new(f, coefficient, "must be at most 1 (Xu 2009 uses 0.01–0.1)"));
            }
        }
        Shifting::Fickian { coefficient } => {
            let f = format!("{field}.fickian.coefficient");
            positive(&f, coefficient)?;
            if coefficient > 10.0 {
                return Err(SceneError::new(f, coefficient, "must be at most 10 (Lind 2012 uses 1–6)"));
            }
        }
    }
    Ok(())
}

fn validate_wcsph(o: &WcsphOptions) -> Result<(), SceneError> {
    positive("scheme.wcsph.sound_speed", o.sound_speed)?;
    validate_shifting("scheme.wcsph.shifting", o.shifting)?;
    finite("scheme.wcsph.gamma", o.gamma)?;
    if !(1.0..=10.0).contains(&o.gamma) {
        return Err(SceneError::new(
            "scheme.wcsph.gamma",
            o.gamma,
            "must lie in 1..=10 (the Tait exponent; 7 for water)",
        ));
    }
    if let Some(av) = o.artificial_viscosity {
        non_negative("scheme.wcsph.artificial_viscosity.alpha", av.alpha)?;
        non_negative("scheme.wcsph.artificial_viscosity.beta", av.beta)?;
        if av.alpha > 10.0 {
            return Err(SceneError::new(
                "scheme.wcsph.artificial_viscosity.alpha",
                av.alpha,
                "must be at most 10 (Monaghan 1992 uses about 1)",
            ));
        }
        if av.beta > 10.0 {
            return Err(SceneError::new(
                "scheme.wcsph.artificial_viscosity.beta",
                av.beta,
                "must be at most 10 (Monaghan 1992 uses about 2)",
            ));
        }
    }
    if let Some(delta) = o.density_diffusion {
        non_negative("scheme.wcsph.density_diffusion", delta)?;
        if delta > 1.0 {
            return Err(SceneError::new(
                "scheme.wcsph.density_diffusion",
                delta,
                "must be at most 1 (Molteni & Colagrossi 2009 use 0.1)",
            ));
        }
    }
    Ok(())
}

fn validate_body(f: &str, body: &Body, d: usize, dx: f64) -> Result<(), SceneError> {
    match &body.shape {
        Shape::Circle { center, radius } | Shape::Sphere { center, radius } => {
            let kind = if matches!(body.shape, Shape::Circle { .. }) { "circle" } else { "sphere" };
            let want = if kind == "circle" { 2 } else { 3 };
            if d != want {
                return Err(SceneError::new(
                    format!("{f}.shape.{kind}"),
                    kind,
                    format!("is a {want}D shape but the scene is {d}D"),
                ));
            }
            vector(&format!("{f}.shape.{kind}.center"), center, d)?;
            near_origin(&format!("{f}.shape.{kind}.center"), center, dx)?;
            positive(&format!("{f}.shape.{kind}.radius"), *radius)?;
            if *radius > MAX_COORDINATE_OVER_DX * dx {
                return Err(SceneError::new(
                    format!("{f}.shape.{kind}.radius"),
                    radius,
                    "must be at most 1e9 dx (double precision cannot resolve the particle spacing)",
                ));
            }
            if *radius < 0.5 * dx {
                return Err(SceneError::new(
                    format!("{f}.shape.{kind}.radius"),
                    radius,
                    "holds no particle (must be at least dx/2)",
                ));
            }
        }
        Shape::Rectangle { min, max } | Shape::Box { min, max } => {
            let kind = if matches!(body.shape, Shape::Rectangle { .. }) { "rectangle" } else { "box" };
            let want = if kind == "rectangle" { 2 } else { 3 };
            if d != want {
                return Err(SceneError::new(
                    format!("{f}.shape.{kind}"),
                    kind,
                    format!("is a {want}D shape but the scene is {d}D"),
                ));
            }
            vector(&format!("{f}.shape.{kind}.min"), min, d)?;
            vector(&format!("{f}.shape.{kind}.max"), max, d)?;
            near_origin(&format!("{f}.shape.{kind}.min"), min, dx)?;
            near_origin(&format!("{f}.shape.{kind}.max"), max, dx)?;
            for k in 0..d {
                if max[k] - min[k] < dx * (1.0 - 1e-9) {
                    return Err(SceneError::new(
                        format!("{f}.shape.{kind}.max[{k}]"),
                        max[k],
                        "holds no particle (max − min must be at least dx)",
                    ));
                }
            }
        }
        Shape::Cylinder { center, axis: along, radius, length, inner_radius } => {
            let f = format!("{f}.shape.cylinder");
            if d != 3 {
                return Err(SceneError::new(&f, "cylinder", format!("is a 3D shape but the scene is {d}D")));
            }
            vector(&format!("{f}.center"), center, d)?;
            near_origin(&format!("{f}.center"), center, dx)?;
            if *along >= d {
                return Err(SceneError::new(
                    format!("{f}.axis"),
                    along,
                    "must be an axis of the scene (0..dimension)",
                ));
            }
            positive(&format!("{f}.radius"), *radius)?;
            positive(&format!("{f}.length"), *length)?;
            if *length > MAX_COORDINATE_OVER_DX * dx {
                return Err(SceneError::new(
                    format!("{f}.length"),
                    length,
                    "must be at most 1e9 dx (double precision cannot resolve the particle spacing)",
                ));
            }
            if *length < dx * (1.0 - 1e-9) {
                return Err(SceneError::new(
                    format!("{f}.length"),
                    length,
                    "holds no particle (must be at least dx)",
                ));
            }
            if !(inner_radius.is_finite() && *inner_radius >= 0.0) {
                return Err(SceneError::new(
                    format!("{f}.inner_radius"),
                    inner_radius,
                    "must be finite and not negative",
                ));
            }
            // The lattice cross-section scans a (2R/Δx)² grid whatever the shell's thickness.
            if *radius > MAX_CYLINDER_RADIUS_OVER_DX * dx {
                return Err(SceneError::new(
                    format!("{f}.radius"),
                    radius,
                    format!(
                        "must be at most {MAX_CYLINDER_RADIUS_OVER_DX} dx (its cross-section is seeded on a (2R/dx)^2 grid)"
                    ),
                ));
            }
            if *radius - *inner_radius < 0.5 * dx {
                return Err(SceneError::new(
                    format!("{f}.radius"),
                    radius,
                    format!(
                        "holds no particle (must exceed inner_radius = {inner_radius:e} m by at least dx/2)"
                    ),
                ));
            }
        }
    }
    if let InitialVelocity::Affine { gradient, offset } = &body.velocity {
        matrix(&format!("{f}.velocity.affine.gradient"), gradient, d)?;
        vector(&format!("{f}.velocity.affine.offset"), offset, d)?;
    }
    match &body.pressure {
        InitialPressure::Zero => {}
        InitialPressure::Quadratic { center, value, hessian } => {
            vector(&format!("{f}.pressure.quadratic.center"), center, d)?;
            finite(&format!("{f}.pressure.quadratic.value"), *value)?;
            matrix(&format!("{f}.pressure.quadratic.hessian"), hessian, d)?;
        }
        InitialPressure::Hydrostatic { surface_point } => {
            vector(&format!("{f}.pressure.hydrostatic.surface_point"), surface_point, d)?;
        }
    }
    Ok(())
}

/// `time.steady`: a probe of the scene, a window of which two fit before the end, a
/// positive tolerance and a start before the end.
fn validate_steady(steady: &SteadyStop, scene: &Scene) -> Result<(), SceneError> {
    let keys = probe_keys(&scene.probes);
    if !keys.contains(&steady.probe) {
        return Err(SceneError::new(
            "time.steady.probe",
            &steady.probe,
            format!("must be the output key of one of the scene's probes ({})", keys.join(", ")),
        ));
    }
    positive("time.steady.window", steady.window)?;
    if 2.0 * steady.window >= scene.time.end {
        return Err(SceneError::new(
            "time.steady.window",
            steady.window,
            format!("must be less than half of time.end = {} (two windows are compared)", scene.time.end),
        ));
    }
    positive("time.steady.tolerance", steady.tolerance)?;
    non_negative("time.steady.after", steady.after)?;
    if steady.after >= scene.time.end {
        return Err(SceneError::new(
            "time.steady.after",
            steady.after,
            format!("must be less than time.end = {}", scene.time.end),
        ));
    }
    Ok(())
}

fn finite(field: &str, v: f64) -> Result<(), SceneError> {
    if v.is_finite() { Ok(()) } else { Err(SceneError::new(field, v, "must be finite")) }
}

fn positive(field: &str, v: f64) -> Result<(), SceneError> {
    finite(field, v)?;
    if v > 0.0 { Ok(()) } else { Err(SceneError::new(field, v, "must be positive")) }
}

fn non_negative(field: &str, v: f64) -> Result<(), SceneError> {
    finite(field, v)?;
    if v >= 0.0 { Ok(()) } else { Err(SceneError::new(field, v, "must not be negative")) }
}

fn vector(field: &str, v: &[f64], d: usize) -> Result<(), SceneError> {
    if v.len() != d {
        return Err(SceneError::new(
            field,
            format!("{v:?}"),
            format!("must have {d} components (the scene's dimension)"),
        ));
    }
    for (k, x) in v.iter().enumerate() {
        finite(&format!("{field}[{k}]"), *x)?;
    }
    Ok(())
}

fn matrix(field: &str, m: &[Vec<f64>], d: usize) -> Result<(), SceneError> {
    if m.len() != d {
        return Err(SceneError::new(
            field,
            format!("{m:?}"),
            format!("must have {d} rows (the scene's dimension)"),
        ));
    }
    for (i, row) in m.iter().enumerate() {
        vector(&format!("{field}[{i}]"), row, d)?;
    }
    Ok(())
}

/// The rule of a non-zero free-surface pressure (Young–Laplace, extrapolated) on the
/// pressure gradient: the symmetric form adds `2 p_a Σ V ∇W`, an outward push on surface
/// particles whose pressure is not zero.
const NOT_SYMMETRIC: &str = "needs scheme.isph.pressure_gradient = \"difference\" or \"corrected\" (the symmetric gradient pushes surface particles with p ≠ 0 outward)";

/// `fluid.surface_tension_model: young_laplace` sets the free-surface pressure of the
/// projection, so it needs the ISPH scheme and the difference (or corrected) pressure gradient (the
/// symmetric form adds `2 p_a Σ V ∇W`, an outward push on surface particles whose pressure
/// is not zero).
fn validate_young_laplace(scene: &Scene) -> Result<(), SceneError> {
    if scene.fluid.surface_tension_model != SurfaceTensionModel::YoungLaplace
        || scene.fluid.surface_tension <= 0.0
    {
        return Ok(());
    }
    match &scene.scheme {
        Scheme::Isph(o) if o.pressure_gradient != PressureGradient::Symmetric => Ok(()),
        Scheme::Isph(_) => {
            Err(SceneError::new("fluid.surface_tension_model", "young_laplace", NOT_SYMMETRIC))
        }
        Scheme::Wcsph(_) | Scheme::Mps(_) | Scheme::Otm(_) => Err(SceneError::new(
            "fluid.surface_tension_model",
            "young_laplace",
            "is for the projection scheme (isph) only: it sets the free-surface Dirichlet pressure",
        )),
    }
}
