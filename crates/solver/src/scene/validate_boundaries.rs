//! Value checks of walls, inflow/outflow, velocity and radial profiles and probe times (split from `validate` to keep
//! each file about one part of the scene). Every rule names the field, the value and the
//! rule.

use super::schema::*;
use crate::error::SceneError;

/// Checks `boundaries.walls`, `boundaries.inflow`/`outflow`, the `velocity_profile` and
/// `radial_profile` probes, `output.probe_times`, `output.snapshot_times` and the bodies' `jitter` and `packing`.
pub(super) fn validate(scene: &Scene) -> Result<(), SceneError> {
    let d = scene.dimension;
    open_boundaries(scene)?;
    for (i, wall) in scene.boundaries.walls.iter().enumerate() {
        let f = format!("boundaries.walls[{i}]");
        axis(&format!("{f}.axis"), wall.axis, d)?;
        if scene.boundaries.periodic.iter().any(|p| p.axis == wall.axis) {
            return Err(SceneError::new(
                format!("{f}.axis"),
                wall.axis,
                "is also a periodic axis (a wall and a period cannot share an axis)",
            ));
        }
        finite(&format!("{f}.position"), wall.position)?;
    }
    for (i, probe) in scene.probes.iter().enumerate() {
        if let Probe::VelocityProfile { axis: a, component, range, bins, slab } = probe {
            let f = format!("probes[{i}].velocity_profile");
            axis(&format!("{f}.axis"), *a, d)?;
            axis(&format!("{f}.component"), *component, d)?;
            ordered(&format!("{f}.range"), range)?;
            profile_bins(&f, *bins, (range[1] - range[0]) / scene.dx)?;
            if let Some(slab) = slab {
                axis(&format!("{f}.slab.axis"), slab.axis, d)?;
                ordered(&format!("{f}.slab.range"), &slab.range)?;
            }
        }
        if let Probe::RadialProfile { axis: a, center, radius, component, bins } = probe {
            let f = format!("probes[{i}].radial_profile");
            if d != 3 {
                return Err(SceneError::new(
                    f,
                    "radial_profile",
                    format!("is a 3D probe but the scene is {d}D"),
                ));
            }
            axis(&format!("{f}.axis"), *a, d)?;
            axis(&format!("{f}.component"), *component, d)?;
            if center.len() != d {
                return Err(SceneError::new(
                    format!("{f}.center"),
                    format!("{} components", center.len()),
                    format!("must have {d} components"),
                ));
            }
            for (k, c) in center.iter().enumerate() {
                finite(&format!("{f}.center[{k}]"), *c)?;
            }
            finite(&format!("{f}.radius"), *radius)?;
            if *radius <= 0.0 {
                return Err(SceneError::new(format!("{f}.radius"), radius, "must be positive"));
            }
            profile_bins(&f, *bins, radius / scene.dx)?;
        }
    }
    let mut last = 0.0;
    for (i, &t) in scene.output.probe_times.iter().enumerate() {
        let f = format!("output.probe_times[{i}]");
        finite(&f, t)?;
        if t <= last {
            return Err(SceneError::new(f, t, "must be positive and larger than the time before it"));
        }
        if t > scene.time.end {
            return Err(SceneError::new(f, t, "must not exceed time.end"));
        }
        last = t;
    }
    if scene.output.snapshot_times.len() > MAX_SNAPSHOTS {
        return Err(SceneError::new(
            "output.snapshot_times",
            format!("{} times", scene.output.snapshot_times.len()),
            format!("must hold at most {MAX_SNAPSHOTS} times (each keeps a copy of every particle)"),
        ));
    }
    for (i, &t) in scene.output.snapshot_times.iter().enumerate() {
        let f = format!("output.snapshot_times[{i}]");
        finite(&f, t)?;
        if t < 0.0 {
            return Err(SceneError::new(f, t, "must not be negative"));
        }
        if i > 0 && t <= scene.output.snapshot_times[i - 1] {
            return Err(SceneError::new(f, t, "must be larger than the time before it"));
        }
        if t > scene.time.end {
            return Err(SceneError::new(f, t, "must not exceed time.end"));
        }
    }
    for (i, body) in scene.bodies.iter().enumerate() {
        let ringed = matches!((d, &body.shape), (2, Shape::Circle { .. }) | (3, Shape::Cylinder { .. }));
        if body.packing == Packing::Rings && !ringed {
            return Err(SceneError::new(
                format!("bodies[{i}].packing"),
                "rings",
                "needs a circle in a 2D scene or a cylinder in a 3D scene (concentric rings fill a disc)",
            ));
        }
        if let (Packing::Rings, Shape::Cylinder { inner_radius, .. }) = (body.packing, &body.shape)
            && *inner_radius > 0.0
            && *inner_radius < scene.dx
        {
            return Err(SceneError::new(
                format!("bodies[{i}].shape.cylinder.inner_radius"),
                inner_radius,
                "must be 0 or at least dx with rings (the rings continue those of a disc of this radius)",
            ));
        }
        if body.packing == Packing::Shells && !(d == 3 && matches!(body.shape, Shape::Sphere { .. })) {
            return Err(SceneError::new(
                format!("bodies[{i}].packing"),
                "shells",
                "needs a sphere in a 3D scene (concentric spherical shells fill a ball)",
            ));
        }
        if let Some(j) = &body.jitter {
            let f = format!("bodies[{i}].jitter.fraction");
            finite(&f, j.fraction)?;
            if !(0.0..0.5).contains(&j.fraction) {
                return Err(SceneError::new(
                    f,
                    j.fraction,
                    "must be in [0, 0.5) (a fraction of dx; at 0.5 two neighbours could meet)",
                ));
            }
        }
    }
    Ok(())
}

/// An inflow needs an outflow on the same axis downstream of it (and the reverse), a
/// positive inflow speed, a non-periodic axis and mirror walls (dummy wall layers are laid
/// once over the initial fluid and would not cover the buffers).
fn open_boundaries(scene: &Scene) -> Result<(), SceneError> {
    let b = &scene.boundaries;
    let (inflow, outflow) = match (&b.inflow, &b.outflow) {
        (None, None) => return Ok(()),
        (Some(_), None) => {
            return Err(SceneError::new(
                "boundaries.outflow",
                "absent",
                "is required with an inflow (the mass entering must be able to leave)",
            ));
        }
        (None, Some(_)) => {
            return Err(SceneError::new("boundaries.inflow", "absent", "is required with an outflow"));
        }
        (Some(i), Some(o)) => (i, o),
    };
    if matches!(scene.scheme, Scheme::Wcsph(_)) {
        return Err(SceneError::new(
            "boundaries.inflow",
            "present",
            "is supported by the isph and mps schemes only (the wcsph step has no buffer stages yet)",
        ));
    }
    axis("boundaries.inflow.axis", inflow.axis, scene.dimension)?;
    finite("boundaries.inflow.position", inflow.position)?;
    finite("boundaries.inflow.velocity", inflow.velocity)?;
    if inflow.velocity <= 0.0 {
        return Err(SceneError::new(
            "boundaries.inflow.velocity",
            inflow.velocity,
            "must be positive (the flow enters towards +axis)",
        ));
    }
    if outflow.axis != inflow.axis {
        return Err(SceneError::new(
            "boundaries.outflow.axis",
            outflow.axis,
            "must equal boundaries.inflow.axis",
        ));
    }
    finite("boundaries.outflow.position", outflow.position)?;
    if outflow.position <= inflow.position {
        return Err(SceneError::new(
            "boundaries.outflow.position",
            outflow.position,
            "must lie downstream of (above) boundaries.inflow.position",
        ));
    }
    if b.periodic.iter().any(|p| p.axis == inflow.axis) {
        return Err(SceneError::new(
            "boundaries.inflow.axis",
            inflow.axis,
            "is also a periodic axis (a flow cannot both enter and wrap around)",
        ));
    }
    if b.walls.iter().any(|w| w.axis == inflow.axis) {
        return Err(SceneError::new(
            "boundaries.inflow.axis",
            inflow.axis,
            "is also the normal of a wall (walls must run along the flow)",
        ));
    }
    if let Some(i) = scene.bodies.iter().position(|body| body.role == Role::Wall) {
        return Err(SceneError::new(
            format!("bodies[{i}].role"),
            "wall",
            "is not supported with inflow/outflow yet (wall bodies are dummy particles; use mirror wall planes)",
        ));
    }
    if b.wall_model == WallModel::Dummy && scene.has_walls() {
        return Err(SceneError::new(
            "boundaries.wall_model",
            "dummy",
            "is not supported with inflow/outflow yet (use mirror walls)",
        ));
    }
    Ok(())
}

/// A profile probe's bin count at `f`: `bins`, or one per Δx over an extent of `rows` Δx,
/// must be 1 to 999 (three-digit keys).
fn profile_bins(f: &str, bins: Option<usize>, rows: f64) -> Result<(), SceneError> {
    let n = bins.unwrap_or(rows.round() as usize);
    if (1..=999).contains(&n) {
        return Ok(());
    }
    let rule =
        if bins.is_some() { "must be between 1 and 999" } else { "(one per Δx) must be between 1 and 999" };
    Err(SceneError::new(format!("{f}.bins"), n, rule))
}

/// Most snapshot times a scene may ask for.
const MAX_SNAPSHOTS: usize = 100;

fn finite(field: &str, v: f64) -> Result<(), SceneError> {
    if v.is_finite() { Ok(()) } else { Err(SceneError::new(field, v, "must be finite")) }
}

fn axis(field: &str, a: usize, d: usize) -> Result<(), SceneError> {
    if a < d { Ok(()) } else { Err(SceneError::new(field, a, "must be an axis of the scene (0..dimension)")) }
}

fn ordered(field: &str, r: &[f64; 2]) -> Result<(), SceneError> {
    finite(&format!("{field}[0]"), r[0])?;
    finite(&format!("{field}[1]"), r[1])?;
    if r[1] > r[0] {
        Ok(())
    } else {
        Err(SceneError::new(format!("{field}[1]"), r[1], "must exceed range[0]"))
    }
}
