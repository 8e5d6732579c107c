//! The boundary stages of the periodic channel: mirror particles rebuilt at r* (`walls`,
//! fluid particles per second) and the backward-Euler viscous predictor
//! (`viscosity_implicit`, particles per second). Scenes without walls build no `walls`
//! stage and are skipped; the implicit predictor is benched on every scene.

use crate::{Per, bench_stage};
use criterion::Criterion;
use meniscus_benches::with_implicit_viscosity;

/// The `walls` stage (mirror walls only).
pub(crate) fn walls(c: &mut Criterion) {
    bench_stage(c, "walls", "stage", "walls", Per::Particle, true, Clone::clone);
}

/// The `viscosity_implicit` stage: (I − Δt ν L) u* = uⁿ + Δt g, Jacobi-CG per component.
pub(crate) fn implicit_viscosity(c: &mut Criterion) {
    bench_stage(
        c,
        "viscosity_implicit",
        "stage",
        "viscosity_implicit",
        Per::Particle,
        true,
        with_implicit_viscosity,
    );
}
